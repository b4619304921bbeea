//! A configuration's branch of periodic orbits: the first orbit found after a transient from
//! the configured initial state (or near a given guess), then followed in a configuration key
//! by pseudo-arclength continuation ([`continue_orbit`]).
//!
//! This is the one entry point that every door to continuation (the command line's
//! `continue`, Python's `continue_`) calls with the same [`BranchOptions`], so that the same
//! configuration gives the same branch, bit for bit.

use std::ops::ControlFlow;

use thiserror::Error;

use crate::config::{Config, ConfigError, Param};
use crate::orbits::{
    Continuation, ContinuationOptions, OrbitError, PeriodicOrbit, ShootingOptions, continue_orbit,
    periodic_orbit_from_transient,
};
use crate::study::{ElectricalOutcome, Harvester, StudyError, power_on_orbit, power_on_periodic_state};
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
///
/// The key is resolved once ([`Param`]), so that each value is set in the document's types
/// directly rather than written and read back as TOML; a key that cannot apply to `config`
/// gives the invalid chain at every value.
pub fn config_family(config: &Config, key: &str) -> impl Fn(f64) -> ChainParams {
    let param = Param::new(config, key).ok();
    move |v: f64| match &param {
        Some(p) => chain_with(config, &[(p, v)]),
        None => invalid_chain(config),
    }
}

/// The chain of `config` with `values` set, or [`invalid_chain`] where they make an invalid
/// configuration.
pub(crate) fn chain_with(config: &Config, values: &[(&Param, f64)]) -> ChainParams {
    config
        .with_values(values)
        .map_or_else(|_| invalid_chain(config), |c| c.chain().clone())
}

/// The chain of `config` with not-a-number masses, which fails its validation.
pub(crate) fn invalid_chain(config: &Config) -> ChainParams {
    ChainParams {
        masses: vec![f64::NAN; config.chain().len()],
        ..config.chain().clone()
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

/// Periods of the harvester simulated along an orbit of a branch before its power is
/// averaged (the charge settles onto its periodic cycle).
pub const BRANCH_POWER_WARMUP: u32 = 2;
/// Periods of the orbit the power on a branch point is averaged over.
pub const BRANCH_POWER_PERIODS: u32 = 2;
/// Periods of the harvester simulated along a periodic orbit found by `periodic` before its
/// power is averaged.
pub const ORBIT_POWER_WARMUP: u32 = 2;
/// Periods of a periodic orbit its power is averaged over.
pub const ORBIT_POWER_PERIODS: u32 = 4;

/// The harvester of `config` (its transducer, load and charge solver settings).
fn harvester_of(config: &Config) -> Harvester {
    Harvester::new(config.harvester().clone(), config.charge_options().clone())
}

/// The average power of `config`'s harvester on every point of every branch of `c`
/// (continued in `key`), W: the orbit of each point run for [`BRANCH_POWER_WARMUP`] +
/// [`BRANCH_POWER_PERIODS`] of its periods with the charge solved alongside (NaN where the
/// charge solver failed). `each` is called after every point and may stop the computation
/// (the powers computed so far are returned).
pub fn branch_powers(
    config: &Config,
    key: &str,
    c: &Continuation,
    mut each: impl FnMut() -> ControlFlow<()>,
) -> Vec<Vec<f64>> {
    let family = config_family(config, key);
    let harvester = harvester_of(config);
    let mut out = Vec::with_capacity(c.branches.len());
    for b in &c.branches {
        let mut powers = Vec::with_capacity(b.points.len());
        for p in &b.points {
            powers.push(
                power_on_periodic_state(
                    &family(p.parameter),
                    &p.state,
                    b.period,
                    &harvester,
                    config.sim_options(),
                    BRANCH_POWER_WARMUP,
                    BRANCH_POWER_PERIODS,
                )
                .ok()
                .and_then(|e| e.power.map(|s| s.average_power_w))
                .unwrap_or(f64::NAN),
            );
            if each().is_break() {
                out.push(powers);
                return out;
            }
        }
        out.push(powers);
    }
    out
}

/// The harvester of `config` run along the periodic orbit `orbit` of its chain:
/// [`ORBIT_POWER_WARMUP`] periods of the orbit, then [`ORBIT_POWER_PERIODS`] averaged over.
/// `None` for a single mass (no gap between masses to harvest from).
pub fn orbit_power(config: &Config, orbit: &PeriodicOrbit) -> Result<Option<ElectricalOutcome>, StudyError> {
    if config.chain().len() < 2 {
        return Ok(None);
    }
    power_on_orbit(
        orbit,
        &harvester_of(config),
        config.sim_options(),
        ORBIT_POWER_WARMUP,
        ORBIT_POWER_PERIODS,
    )
    .map(Some)
}
