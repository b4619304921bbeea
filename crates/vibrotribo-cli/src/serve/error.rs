//! The API's error answer: an HTTP status and a JSON body `{"error": "…"}` naming the problem.

use axum::Json;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use serde::Serialize;

/// An error answer of the API.
#[derive(Debug)]
pub struct ApiError {
    /// The HTTP status (400 for a bad request, 409 for a request superseded by a newer one,
    /// 422 for a run that failed).
    pub status: StatusCode,
    /// The reason, as the command line would say it.
    pub message: String,
}

#[derive(Serialize)]
struct Body<'a> {
    error: &'a str,
}

impl ApiError {
    /// 400: the request or a value in it is malformed or refused.
    pub fn bad(e: impl std::fmt::Display) -> Self {
        ApiError {
            status: StatusCode::BAD_REQUEST,
            message: e.to_string(),
        }
    }

    /// 400 from an error with its chain of causes (`anyhow`'s `{:#}`).
    pub fn bad_chain(e: &anyhow::Error) -> Self {
        Self::bad(format!("{e:#}"))
    }

    /// 422: the request was valid but its computation failed.
    pub fn failed(e: impl std::fmt::Display) -> Self {
        ApiError {
            status: StatusCode::UNPROCESSABLE_ENTITY,
            message: e.to_string(),
        }
    }

    /// 409: a newer request of the same kind stopped this one.
    pub fn superseded() -> Self {
        ApiError {
            status: StatusCode::CONFLICT,
            message: "stopped: superseded by a newer request (or the server is stopping)".into(),
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.status, Json(Body { error: &self.message })).into_response()
    }
}

impl From<super::cancel::Outdated> for ApiError {
    fn from(_: super::cancel::Outdated) -> Self {
        ApiError {
            status: StatusCode::CONFLICT,
            message: "outdated: a request sent after this one (a higher seq) is already being answered"
                .into(),
        }
    }
}
