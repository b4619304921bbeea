//! The `[harvester]` configuration table (triboelectric transducer and load).

use anyhow::{Result, bail};
use toml::Table;

/// `[harvester]` keys accepted in configuration files and `--set`.
pub const HARVESTER_KEYS: &[&str] = &[];

/// The current value of an array key of `[harvester]`, defaults filled in.
pub fn materialize_array(_table: &Table, name: &str) -> Result<Vec<f64>> {
    bail!("`harvester.{name}` is not an array parameter")
}
