//! A configuration's bifurcation curve in two keys: the bifurcation of a kind located on the
//! branch of periodic orbits near a value of the first key, then continued in the second
//! ([`continue_curve`]).
//!
//! This is the one entry point that every door to two-parameter continuation (the command
//! line's `curve`, Python's `curve`) calls with the same [`CurveConfigOptions`].

use thiserror::Error;

use crate::ChainParams;
use crate::branch::{
    BRANCH_POWER_PERIODS, BRANCH_POWER_WARMUP, BranchError, BranchOptions, chain_with, continue_config,
    invalid_chain,
};
use crate::config::{Config, ConfigError, Param};
use crate::orbits::curve::{Curve, CurveError, CurveKind, CurveOptions, CurveStart, continue_curve};
use crate::orbits::{
    Bifurcation, BifurcationKind, ContinuationOptions, OrbitError, ShootingOptions,
    periodic_orbit_from_transient,
};
use crate::study::{Harvester, power_on_periodic_state};

/// What curve to compute.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveRequest {
    /// The bifurcation followed.
    pub kind: CurveKind,
    /// The first key (the branch's parameter).
    pub key: String,
    /// The bifurcation is the one of `kind` nearest this value of `key`.
    pub near: f64,
    /// The second key.
    pub key2: String,
    /// Start of the second key's range: the bifurcation is located there.
    pub from2: f64,
    /// End of the second key's range.
    pub to2: f64,
    /// Period of the branch, in excitation periods (default `None`: the period of the orbit
    /// found after the transient at `near`).
    pub period: Option<u32>,
}

/// How the branch is found and the curve followed.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveConfigOptions {
    /// Excitation periods simulated at `near` from the configured initial state before
    /// shooting for the first orbit (default 200).
    pub transient: u32,
    /// Half width of the window of the first key searched for the bifurcation, relative to
    /// |near| (default 0.05: `near ± 5 %`).
    pub window: f64,
    /// The curve's numerical settings; the simulator settings are replaced by the
    /// configuration's.
    pub curve: CurveOptions,
}

impl Default for CurveConfigOptions {
    fn default() -> Self {
        CurveConfigOptions {
            transient: 200,
            window: 0.05,
            curve: CurveOptions::default(),
        }
    }
}

/// A configuration's curve with the point it started from.
#[derive(Debug, Clone, PartialEq)]
pub struct ConfigCurve {
    /// The first key, canonical (see [`canonical_key`]).
    pub key: String,
    /// The second key, canonical.
    pub key2: String,
    /// The bifurcation located on the branch at `from2`.
    pub located: Bifurcation,
    /// The curve.
    pub curve: Curve,
}

/// Why a configuration's curve could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CurveConfigError {
    /// A value makes an invalid configuration.
    #[error("{key} = {value}")]
    Value {
        /// The key.
        key: String,
        /// The value at fault.
        value: f64,
        /// Why the configuration is invalid.
        #[source]
        source: ConfigError,
    },
    /// The two keys are one.
    #[error("the two keys must differ (both are {0})")]
    SameKey(String),
    /// The window is not a positive number.
    #[error("the search window must be a positive fraction of |near|, got {0}")]
    Window(f64),
    /// No periodic orbit was found at `near`.
    #[error("no periodic orbit found at {key} = {value}")]
    FirstOrbit {
        /// The first key.
        key: String,
        /// The value.
        value: f64,
        /// Why shooting failed.
        #[source]
        source: OrbitError,
    },
    /// The branch through `near` could not be followed.
    #[error(transparent)]
    Branch(#[from] BranchError),
    /// No bifurcation of the kind on the branch in the window.
    #[error(
        "no {} found on the branch{} in {key} ∈ [{lo}, {hi}] (found: {})",
        kind.name(),
        period.map_or(String::new(), |p| format!(" of period {p}")),
        if found.is_empty() { "none".to_string() } else { found.join(", ") }
    )]
    NotFound {
        /// The kind asked for.
        kind: CurveKind,
        /// The first key.
        key: String,
        /// The window searched.
        lo: f64,
        /// The window searched.
        hi: f64,
        /// The period asked for.
        period: Option<u32>,
        /// The bifurcations found instead: `kind at value (period P)`.
        found: Vec<String>,
    },
    /// The curve could not be started.
    #[error(transparent)]
    Curve(#[from] CurveError),
}

/// The canonical form of a key: the aliases `omega_ratio`, `frequency_hz` and `amplitude`
/// become `excitation.…`, `restitution` becomes `oscillator.restitution`; other keys are
/// returned as given.
pub fn canonical_key(key: &str) -> String {
    match key {
        "omega_ratio" | "frequency_hz" | "amplitude" => format!("excitation.{key}"),
        "restitution" => "oscillator.restitution".into(),
        _ => key.to_string(),
    }
}

/// The chain of `config` with `key = p1` and `key2 = p2`: values that make an invalid
/// configuration give a chain that fails its validation (not-a-number masses), so that the
/// corrector fails there and the curve ends.
///
/// The keys are resolved once ([`Param`]), so that each pair of values is set in the
/// document's types directly rather than written and read back as TOML; a key that cannot
/// apply to `config` gives the invalid chain at every value.
pub fn config_family2(config: &Config, key: &str, key2: &str) -> impl Fn(f64, f64) -> ChainParams {
    let params = Param::new(config, key).ok().zip(Param::new(config, key2).ok());
    move |p1: f64, p2: f64| match &params {
        Some((a, b)) => chain_with(config, &[(a, p1), (b, p2)]),
        None => invalid_chain(config),
    }
}

/// The curve kind a located bifurcation lies on: folds, period doublings, Neimark–Sacker
/// points and grazings; `None` for the others (branch points, sticking, other sequence
/// changes), which no curve follows.
pub fn curve_kind_of(b: &BifurcationKind) -> Option<CurveKind> {
    match b {
        BifurcationKind::Fold => Some(CurveKind::Fold),
        BifurcationKind::PeriodDoubling => Some(CurveKind::PeriodDoubling),
        BifurcationKind::NeimarkSacker { .. } => Some(CurveKind::NeimarkSacker),
        BifurcationKind::Grazing { .. } => Some(CurveKind::Grazing),
        _ => None,
    }
}

/// Where the curve through a bifurcation located on a branch of period `period` starts: its
/// orbit, and for a grazing its contact and the orbit on the side without the grazing
/// impact.
pub fn curve_start_of(located: &Bifurcation, period: u32) -> CurveStart {
    let (orbit, contact) = match located.kind {
        // The side without the grazing impact.
        BifurcationKind::Grazing { contact, appears } => {
            let side = if appears {
                &located.point
            } else {
                located.after.as_ref().unwrap_or(&located.point)
            };
            (side, Some(contact))
        }
        _ => (&located.point, None),
    };
    CurveStart {
        state: orbit.state.clone(),
        period,
        parameter: orbit.parameter,
        contact,
    }
}

/// The bifurcation of `request.kind` nearest `near` on the branch of `config` (with `key2 =
/// from2`) through the orbit found at `near`, followed both ways over the window, and the
/// curve it lies on, continued in `key2` from `from2` to `to2`.
pub fn curve_config(
    config: &Config,
    request: &CurveRequest,
    options: &CurveConfigOptions,
) -> Result<ConfigCurve, CurveConfigError> {
    let key = canonical_key(&request.key);
    let key2 = canonical_key(&request.key2);
    if key == key2 {
        return Err(CurveConfigError::SameKey(key));
    }
    if !(options.window.is_finite() && options.window > 0.0) {
        return Err(CurveConfigError::Window(options.window));
    }
    let value_error = |key: &str, value: f64| {
        let key = key.to_string();
        move |source| CurveConfigError::Value { key, value, source }
    };
    let base = config
        .with(&key2, toml::Value::Float(request.from2))
        .map_err(value_error(&key2, request.from2))?;
    config
        .with(&key2, toml::Value::Float(request.to2))
        .map_err(value_error(&key2, request.to2))?;
    let start = base
        .with(&key, toml::Value::Float(request.near))
        .map_err(value_error(&key, request.near))?;
    let shooting = ShootingOptions {
        sim: config.sim_options().clone(),
        ..options.curve.shooting.clone()
    };
    let first = periodic_orbit_from_transient(
        start.chain(),
        start.initial_state(),
        options.transient,
        request.period,
        &shooting,
    )
    .map_err(|source| CurveConfigError::FirstOrbit {
        key: key.clone(),
        value: request.near,
        source,
    })?;
    let w = options.window * request.near.abs().max(f64::MIN_POSITIVE);
    let (lo, hi) = (request.near - w, request.near + w);
    let branch_options = BranchOptions {
        transient: options.transient,
        period: request.period,
        continuation: ContinuationOptions {
            doubling_depth: 1,
            max_points: 400,
            shooting: shooting.clone(),
            ..ContinuationOptions::default()
        },
    };
    let mut found: Vec<(Bifurcation, u32)> = Vec::new();
    for end in [lo, hi] {
        let guess = Some((first.state.clone(), first.period));
        let c = continue_config(&base, &key, request.near, end, guess, &branch_options)?;
        for b in &c.branches {
            found.extend(b.bifurcations.iter().map(|f| (f.clone(), b.period)));
        }
    }
    let wanted = request.period;
    let best = found
        .iter()
        .filter(|(f, p)| curve_kind_of(&f.kind) == Some(request.kind) && wanted.is_none_or(|w| w == *p))
        .min_by(|a, b| {
            (a.0.parameter - request.near)
                .abs()
                .total_cmp(&(b.0.parameter - request.near).abs())
        })
        .cloned();
    let Some((located, period)) = best else {
        return Err(CurveConfigError::NotFound {
            kind: request.kind,
            key,
            lo,
            hi,
            period: request.period,
            found: found
                .iter()
                .map(|(f, p)| format!("{} at {:.8} (period {p})", f.kind.name(), f.parameter))
                .collect(),
        });
    };
    let curve_start = curve_start_of(&located, period);
    let curve_options = CurveOptions {
        shooting,
        ..options.curve.clone()
    };
    let family = config_family2(config, &key, &key2);
    let curve = continue_curve(
        family,
        request.kind,
        &curve_start,
        request.from2,
        request.to2,
        &curve_options,
    )?;
    Ok(ConfigCurve {
        key,
        key2,
        located,
        curve,
    })
}

/// The average power of `config`'s harvester on every point of `c` (a curve in `key` and
/// `key2`), W: each orbit run for [`BRANCH_POWER_WARMUP`] + [`BRANCH_POWER_PERIODS`] of its
/// periods with the charge solved alongside (NaN where the charge solver failed, and for a
/// single mass, which has no gap between masses to harvest from).
pub fn curve_powers(config: &Config, key: &str, key2: &str, c: &Curve) -> Vec<f64> {
    if config.chain().len() < 2 {
        return vec![f64::NAN; c.points.len()];
    }
    let family = config_family2(config, key, key2);
    let harvester = Harvester::new(config.harvester().clone(), config.charge_options().clone());
    c.points
        .iter()
        .map(|p| {
            power_on_periodic_state(
                &family(p.parameter, p.parameter2),
                &p.state,
                c.period,
                &harvester,
                config.sim_options(),
                BRANCH_POWER_WARMUP,
                BRANCH_POWER_PERIODS,
            )
            .ok()
            .and_then(|e| e.power.map(|s| s.average_power_w))
            .unwrap_or(f64::NAN)
        })
        .collect()
}
