//! The JSON API's handlers: each reads its request, hands the work to a blocking thread, and
//! answers JSON (or a stream of JSON lines); a malformed request gets 400 with the reason.

use std::sync::Arc;

use axum::Json;
use axum::body::Bytes;
use axum::extract::{Path, State};
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use serde::Deserialize;

use super::assets;
use super::branches::{BranchRequest, branches as continue_branches};
use super::cancel::Lane;
use super::error::ApiError;
use super::grid::{GridJob, GridKind, GridRequest};
use super::memory::release_soon;
use super::request::{Overrides, body, configure};
use super::run_view::{RunRequest, run_view};
use super::schema::schema;
use vibrotribo::config::Config;

/// What every handler shares: the server's configuration and the lanes of its requests.
pub struct AppState {
    /// The configuration the server was started with (file and `--set`).
    pub base: Config,
    /// Its file, if any.
    pub path: Option<String>,
    /// Its `--set` overrides.
    pub set: Vec<String>,
    /// Run-view requests: a newer one stops an older one.
    pub runs: Lane,
    /// Orbit-diagram requests.
    pub orbits: Lane,
    /// Power-map requests.
    pub maps: Lane,
    /// Basin (initial-condition grid) requests.
    pub basins: Lane,
    /// Continuation requests.
    pub continuations: Lane,
}

/// The shared state.
pub type Shared = Arc<AppState>;

/// `GET /`: the page.
pub async fn index() -> Html<&'static str> {
    Html(assets::INDEX_HTML)
}

/// `GET /assets/NAME`: an embedded asset.
pub async fn asset(Path(name): Path<String>) -> Response {
    match assets::asset(&name) {
        Some((kind, text)) => ([(header::CONTENT_TYPE, kind)], text).into_response(),
        None => not_found().await,
    }
}

/// Any other path: 404 with the reason.
pub async fn not_found() -> Response {
    ApiError {
        status: StatusCode::NOT_FOUND,
        message: "no such page or API endpoint (see GET /api/schema)".into(),
    }
    .into_response()
}

/// `GET /api/schema`: every configuration key with unit, allowed values, default and value.
pub async fn get_schema(State(state): State<Shared>) -> Response {
    Json(schema(&state.base, state.path.clone(), state.set.clone())).into_response()
}

/// A request that carries only overrides.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetRequest {
    /// The overrides of the server's configuration.
    #[serde(default)]
    pub set: Overrides,
}

/// `POST /api/check`: whether the overrides make a valid configuration (200 `{"ok": true}`),
/// or 400 with the engine's error.
pub async fn check(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    let request: SetRequest = body(&bytes)?;
    configure(&state.base, &request.set)?;
    Ok(Json(serde_json::json!({"ok": true})).into_response())
}

/// `POST /api/toml`: the configuration with the overrides as a TOML file (what
/// `vibrotribo simulate FILE` runs to the same numbers).
pub async fn toml(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    let request: SetRequest = body(&bytes)?;
    let config = configure(&state.base, &request.set)?;
    let text = ::toml::to_string(config.table()).map_err(ApiError::failed)?;
    Ok((
        [
            (header::CONTENT_TYPE, "application/toml; charset=utf-8"),
            (
                header::CONTENT_DISPOSITION,
                "attachment; filename=\"vibrotribo.toml\"",
            ),
        ],
        text,
    )
        .into_response())
}

/// `POST /api/run`: the run view (see [`run_view`]); a newer run request stops this one (409).
pub async fn run(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    let request: RunRequest = body(&bytes)?;
    let (ticket, _guard) = state.runs.take(request.seq)?;
    let shared = Arc::clone(&state);
    let view = tokio::task::spawn_blocking(move || run_view(&shared.base, &request, ticket)).await;
    // The view is serialised (and freed) first; a superseded one is freed here.
    let response = view.map_err(ApiError::failed)?.map(|v| Json(v).into_response());
    release_soon();
    response
}

/// `POST /api/orbit` (one axis), `POST /api/map` and `POST /api/basins` (two axes): the
/// grid's points streamed as JSON lines. The request's generation is taken on arrival, before
/// its grid is checked, so that it supersedes every request that arrived before it.
async fn grid(state: &Shared, bytes: &[u8], lane: &Lane, kind: GridKind) -> Result<Response, ApiError> {
    let request: GridRequest = body(bytes)?;
    let (ticket, guard) = lane.take(request.seq)?;
    let shared = Arc::clone(state);
    let job = tokio::task::spawn_blocking(move || GridJob::new(&shared.base, &request, kind))
        .await
        .map_err(ApiError::failed)??;
    Ok(job.stream(ticket, guard))
}

/// `POST /api/orbit`: the orbit diagram over one parameter, as `vibrotribo sweep` computes it.
pub async fn orbit(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    grid(&state, &bytes, &state.orbits, GridKind::Orbit).await
}

/// `POST /api/map`: average power (and motion) on a two-parameter grid, as `vibrotribo map`
/// computes it.
pub async fn map(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    grid(&state, &bytes, &state.maps, GridKind::Map).await
}

/// `POST /api/basins`: a grid over two initial-condition keys (`run.initial_positions[i]`,
/// `run.initial_velocities[i]`), each start fingerprinted and, when all have run, classified
/// into attractors as `vibrotribo basins` does.
pub async fn basins(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    grid(&state, &bytes, &state.basins, GridKind::Basins).await
}

/// `POST /api/branches`: the periodic orbits continued over a parameter range, as
/// `vibrotribo continue` computes them (see [`branches`]); a newer request stops this one
/// (409) between its steps.
pub async fn branches(State(state): State<Shared>, bytes: Bytes) -> Result<Response, ApiError> {
    let request: BranchRequest = body(&bytes)?;
    let (ticket, _guard) = state.continuations.take(request.seq)?;
    let shared = Arc::clone(&state);
    let view = tokio::task::spawn_blocking(move || continue_branches(&shared.base, &request, &ticket)).await;
    let response = view.map_err(ApiError::failed)?.map(|v| Json(v).into_response());
    release_soon();
    response
}
