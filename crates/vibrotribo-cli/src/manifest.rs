//! The manifests of output directories, each a serde type of the library
//! ([`vibrotribo::report::manifest`], re-exported here) written and read through that one
//! type, and what a directory holds, told by its manifest's `command` (its [`Kind`]).
//!
//! A grid job's manifest (`sweep.json`, `map.json`) is its settings; the job machinery
//! ([`crate::job`]) adds the progress keys `complete`, `done` and `rows` when it writes it,
//! and the types ignore them when they read it. `plot DIR` draws a directory by its kind
//! (`plots.rs`).

use std::path::Path;

use anyhow::{Context, Result};
use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

mod kind;

pub use kind::{kind_of, shard_kind};
pub use vibrotribo::report::manifest::*;

/// Reads the manifest `path` as `T`; the error names the file and the key at fault.
pub fn read<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not a valid manifest", path.display()))
}

/// Reads the manifest of the `kind` directory `dir` as `T`.
pub fn read_of<T: DeserializeOwned>(dir: &Path, kind: Kind) -> Result<T> {
    read(&dir.join(kind.manifest()))
}

/// Writes the manifest `manifest` to `path` (pretty JSON, atomically).
pub fn write<T: Serialize>(path: &Path, manifest: &T) -> Result<()> {
    crate::output::write_json(path, &to_value(manifest)?)
}

/// The manifest of a directory as the JSON value the job machinery writes.
pub fn to_value<T: Serialize>(manifest: &T) -> Result<Value> {
    serde_json::to_value(manifest).context("cannot write the manifest")
}

/// The configuration a manifest's `settings` records.
pub fn config_of(settings: &Value) -> Result<vibrotribo::config::Config> {
    let table: toml::Table =
        serde_json::from_value(settings.clone()).context("the recorded settings are not a table")?;
    Ok(vibrotribo::config::Config::from_table(table)?)
}
