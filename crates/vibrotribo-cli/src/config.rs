//! The configuration of a command: a TOML file and `--set key=value` overrides, read by the
//! library ([`vibrotribo::config::Config`]), which owns the keys and names them in its errors.

use anyhow::{Context, Result};
use vibrotribo::config::{Config, apply_overrides};
use vibrotribo::excitation::WorkBudget;

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
        self.load_within(false)
    }

    /// [`load`](Self::load) with the base motion built within the documented limit
    /// ([`vibrotribo::excitation::MAX_PIECE_EVALUATIONS`]) unless `allow_large`, stopped by
    /// SIGINT/SIGTERM ([`Interrupted`](crate::progress::Interrupted): nothing was written).
    pub fn load_within(&self, allow_large: bool) -> Result<Config> {
        let budget = WorkBudget {
            allow_large,
            stop: crate::progress::stop_flag(),
        };
        let loaded = (|| -> Result<Config> {
            let mut config = match &self.config {
                Some(path) => Config::from_path_within(path, &budget)?,
                None => Config::default(),
            };
            config.set_budget(budget.clone());
            apply_overrides(&mut config, &self.set).context("--set")?;
            Ok(config)
        })();
        let config = match loaded {
            Err(_) if crate::progress::interrupted() => {
                return Err(crate::progress::Interrupted {
                    what: "while building the base motion; nothing was written".into(),
                }
                .into());
            }
            other => other?,
        };
        // Every command simulates: refuse base motions that cannot drive the chain, naming why.
        config.check_runnable()?;
        Ok(config)
    }
}

/// `config` with the numeric `key` set to `value` (sweeps and maps).
pub fn with(config: &Config, key: &str, value: f64) -> Result<Config> {
    Ok(config.with(key, toml::Value::Float(value))?)
}
