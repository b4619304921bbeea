//! The configuration of a command: a TOML file and `--set key=value` overrides, read by the
//! library ([`vibrotribo::config::Config`]), which owns the keys and names them in its errors.

use anyhow::{Context, Result};
use vibrotribo::config::{Config, apply_overrides};

/// The configuration of a command: a TOML file and `--set` overrides.
#[derive(Debug, clap::Args)]
pub struct ConfigArgs {
    /// Configuration file (TOML); the paper's default case if omitted.
    pub config: Option<std::path::PathBuf>,
    /// Override a parameter, e.g. `--set excitation.omega_ratio=0.75`,
    /// `--set oscillator.masses=[0.05,0.15,0.05]`, `--set mass_ratio=3` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl ConfigArgs {
    /// Reads the file (or the defaults) and applies the overrides in order; an error, naming
    /// the reason, for a base motion that cannot drive the chain
    /// ([`Config::check_runnable`]).
    pub fn load(&self) -> Result<Config> {
        let mut config = match &self.config {
            Some(path) => Config::from_path(path)?,
            None => Config::default(),
        };
        apply_overrides(&mut config, &self.set).context("--set")?;
        // Every command simulates: refuse base motions that cannot drive the chain, naming why.
        config.check_runnable()?;
        Ok(config)
    }
}

/// `config` with the numeric `key` set to `value` (sweeps and maps).
pub fn with(config: &Config, key: &str, value: f64) -> Result<Config> {
    Ok(config.with(key, toml::Value::Float(value))?)
}
