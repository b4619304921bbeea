//! A configuration's branch of periodic orbits: the first orbit found after a transient from
//! the configured initial state (or near a given guess), then followed in a configuration key
//! by pseudo-arclength continuation ([`continue_orbit`]).
//!
//! This is the one entry point that every door to continuation (the command line's
//! `continue`, Python's `continue_`) calls with the same [`BranchOptions`], so that the same
//! configuration gives the same branch, bit for bit.

use thiserror::Error;

use crate::config::{Config, ConfigError};
use crate::orbits::{
    Continuation, ContinuationOptions, OrbitError, ShootingOptions, continue_orbit,
    periodic_orbit_from_transient,
};
use crate::{ChainParams, ChainState};

/// How a configuration's branch is started and followed.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchOptions {
    /// Excitation periods simulated at the start value from the configured initial state
    /// before shooting for the first orbit (default 200).
    pub transient: u32,
    /// Period of the first orbit, in excitation periods (default `None`: detected after the
    /// transient).
    pub period: Option<u32>,
    /// The continuation's numerical settings (defaults: [`ContinuationOptions::default`]);
    /// the shooting's simulator settings are replaced by the configuration's
    /// ([`Config::sim_options`]).
    pub continuation: ContinuationOptions,
}

impl Default for BranchOptions {
    fn default() -> Self {
        BranchOptions {
            transient: 200,
            period: None,
            continuation: ContinuationOptions::default(),
        }
    }
}

/// Why a configuration's branch could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum BranchError {
    /// An end of the range makes an invalid configuration.
    #[error("{key} = {value}")]
    Value {
        /// The continued key.
        key: String,
        /// The value at fault.
        value: f64,
        /// Why the configuration is invalid.
        #[source]
        source: ConfigError,
    },
    /// No periodic orbit was found at the start of the range.
    #[error("no periodic orbit found at {key} = {value}")]
    FirstOrbit {
        /// The continued key.
        key: String,
        /// The start value.
        value: f64,
        /// Why shooting failed.
        #[source]
        source: OrbitError,
    },
    /// The continuation failed.
    #[error(transparent)]
    Continuation(#[from] OrbitError),
}

/// The chain of `config` with `key` set to each value: a value that makes an invalid
/// configuration gives a chain that fails its validation (not-a-number masses), so that a
/// corrector evaluating it fails and the branch ends there.
pub fn config_family(config: &Config, key: &str) -> impl Fn(f64) -> ChainParams {
    let n = config.chain().len();
    move |v: f64| match config.with(key, toml::Value::Float(v)) {
        Ok(c) => c.chain().clone(),
        Err(_) => ChainParams {
            masses: vec![f64::NAN; n],
            ..config.chain().clone()
        },
    }
}

/// The shooting settings of `options` with the simulator settings of `config`.
fn shooting_of(config: &Config, options: &ShootingOptions) -> ShootingOptions {
    ShootingOptions {
        sim: config.sim_options().clone(),
        ..options.clone()
    }
}

/// The branch of periodic orbits of `config` in `key` from `from` towards `to`: the first
/// orbit near `guess` (a state and its period in excitation periods), or, without one, the
/// orbit found after `options.transient` periods from the configured initial state at
/// `from`. Both ends must make valid configurations.
pub fn continue_config(
    config: &Config,
    key: &str,
    from: f64,
    to: f64,
    guess: Option<(ChainState, u32)>,
    options: &BranchOptions,
) -> Result<Continuation, BranchError> {
    let at = |value: f64| {
        config
            .with(key, toml::Value::Float(value))
            .map_err(|source| BranchError::Value {
                key: key.to_string(),
                value,
                source,
            })
    };
    let start = at(from)?;
    at(to)?;
    let continuation = ContinuationOptions {
        shooting: shooting_of(config, &options.continuation.shooting),
        ..options.continuation.clone()
    };
    let (state, period) = match guess {
        Some(g) => g,
        None => {
            let first = periodic_orbit_from_transient(
                start.chain(),
                start.initial_state(),
                options.transient,
                options.period,
                &continuation.shooting,
            )
            .map_err(|source| BranchError::FirstOrbit {
                key: key.to_string(),
                value: from,
                source,
            })?;
            (first.state, first.period)
        }
    };
    let family = config_family(config, key);
    Ok(continue_orbit(
        key,
        family,
        from,
        to,
        &state,
        period,
        &continuation,
    )?)
}
