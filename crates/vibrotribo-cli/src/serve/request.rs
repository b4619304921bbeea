//! Reading an API request: its JSON body, and the configuration it asks for (the server's
//! base configuration with the request's `set` overrides applied exactly as `--set` applies
//! them on the command line).

use serde::de::DeserializeOwned;
use serde_json::{Map, Value};
use vibrotribo::config::{Config, apply_overrides};

use super::error::ApiError;

/// Overrides `{"key": value, …}` in order; a value is the text `--set key=TEXT` takes (a JSON
/// string is that text, any other JSON value is written as JSON, which reads the same).
pub type Overrides = Map<String, Value>;

/// The JSON body `bytes` read as a `T`; a 400 naming the problem otherwise.
pub fn body<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, ApiError> {
    serde_json::from_slice(bytes).map_err(|e| ApiError::bad(format!("malformed request: {e}")))
}

/// The overrides as `--set` assignments `key=value`.
pub fn assignments(set: &Overrides) -> Vec<String> {
    set.iter()
        .map(|(key, value)| match value {
            Value::String(text) => format!("{key}={text}"),
            other => format!("{key}={other}"),
        })
        .collect()
}

/// `base` with the overrides applied and checked as every command checks its
/// configuration; a 400 with the engine's error otherwise.
pub fn configure(base: &Config, set: &Overrides) -> Result<Config, ApiError> {
    let mut config = base.clone();
    apply_overrides(&mut config, &assignments(set)).map_err(ApiError::bad)?;
    config.check_runnable().map_err(ApiError::bad)?;
    Ok(config)
}
