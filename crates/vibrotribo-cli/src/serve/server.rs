//! The server: its options, the router, and a clean stop on SIGINT/SIGTERM.

use std::io::Write;
use std::net::SocketAddr;
use std::sync::Arc;

use anyhow::{Context, Result};
use axum::Router;
use axum::routing::{get, post};

use super::api::{self, AppState};
use super::cancel::Lane;
use crate::config::ConfigArgs;

/// Options of `vibrotribo serve`.
#[derive(Debug, clap::Args)]
pub struct ServeArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Port to listen on (0: any free port; the address is printed).
    #[arg(long, default_value_t = 8050)]
    pub port: u16,
    /// Address to listen on; the default serves this machine only.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Open the page in the default browser (`xdg-open`, `open`).
    #[arg(long)]
    pub open: bool,
}

/// The router: the page, its assets and the API.
pub fn router(state: AppState) -> Router {
    Router::new()
        .route("/", get(api::index))
        .route("/assets/{name}", get(api::asset))
        .route("/api/schema", get(api::get_schema))
        .route("/api/check", post(api::check))
        .route("/api/toml", post(api::toml))
        .route("/api/run", post(api::run))
        .route("/api/orbit", post(api::orbit))
        .route("/api/map", post(api::map))
        .route("/api/basins", post(api::basins))
        .route("/api/branches", post(api::branches))
        .fallback(api::not_found)
        .with_state(Arc::new(state))
}

/// Resolves when SIGINT or SIGTERM arrives.
async fn stop_signal() {
    let interrupt = tokio::signal::ctrl_c();
    #[cfg(unix)]
    {
        let mut term = match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(t) => t,
            Err(_) => {
                let _ = interrupt.await;
                return;
            }
        };
        tokio::select! {
            _ = interrupt => {}
            _ = term.recv() => {}
        }
    }
    #[cfg(not(unix))]
    {
        let _ = interrupt.await;
    }
}

/// Opens `url` in the default browser, saying so if it cannot.
fn open_browser(url: &str) {
    let opener = if cfg!(target_os = "macos") {
        "open"
    } else {
        "xdg-open"
    };
    if let Err(e) = std::process::Command::new(opener).arg(url).spawn() {
        eprintln!("vibrotribo serve: cannot open a browser ({opener}: {e}); open {url} yourself");
    }
}

/// Runs `vibrotribo serve` until SIGINT or SIGTERM.
pub fn run(args: &ServeArgs) -> Result<()> {
    let base = args.input.load()?;
    let state = AppState {
        base,
        path: args.input.config.as_ref().map(|p| p.display().to_string()),
        set: args.input.set.clone(),
        runs: Lane::default(),
        orbits: Lane::default(),
        maps: Lane::default(),
        basins: Lane::default(),
        continuations: Lane::default(),
    };
    super::memory::limit_arenas();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        // Computations run on blocking threads; a burst of superseded requests waits for a
        // few threads instead of starting hundreds (each stops at once when its turn comes).
        .max_blocking_threads(16)
        .enable_all()
        .build()
        .context("cannot start the server's runtime")?;
    runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind((args.host.as_str(), args.port))
            .await
            .with_context(|| format!("cannot listen on {}:{}", args.host, args.port))?;
        let addr: SocketAddr = listener.local_addr().context("the listening address")?;
        let url = format!("http://{addr}/");
        println!("vibrotribo serve: listening on {url} (Ctrl-C stops)");
        std::io::stdout().flush().ok();
        if args.open {
            open_browser(&url);
        }
        axum::serve(listener, router(state))
            .with_graceful_shutdown(stop_signal())
            .await
            .context("the server failed")?;
        println!("vibrotribo serve: stopped");
        Ok(())
    })
}
