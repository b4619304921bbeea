//! Error types of the library.
//!
//! Every error caused by user input names the parameter at fault, so that a command-line
//! front end can show it as it is.

use thiserror::Error;

/// A parameter failed validation.
///
/// Parameters are named in the library's terms: the path of the field in the structure that
/// was validated (`masses[1]` of [`ChainParams`](crate::ChainParams), `area` of
/// [`HarvesterParams`](crate::electrical::HarvesterParams)). A front end that reads them
/// from a configuration maps the names to its keys with [`ParamError::within`]
/// (`oscillator.masses[1]`, `harvester.area`).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ParamError {
    /// A scalar parameter is out of its admissible range or not finite.
    #[error("invalid {name} = {value}: {reason}")]
    Invalid {
        /// Parameter name (e.g. `masses[1]`).
        name: String,
        /// The offending value.
        value: f64,
        /// Why it is rejected.
        reason: &'static str,
    },
    /// An array parameter has the wrong number of entries.
    #[error("{name} has {got} entries, expected {expected}")]
    Length {
        /// Parameter name.
        name: String,
        /// Required length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// The chain needs at least two masses (one with a rigid stop).
    #[error("the chain needs at least 2 masses, got {0}")]
    TooFewMasses(usize),
    /// The initial positions make two neighbouring masses overlap.
    #[error(
        "initial positions interpenetrate at contact {contact} (between masses {contact} and {}): gap = {gap:.3e} m",
        contact + 1
    )]
    Interpenetration {
        /// 1-based contact index (k is the gap between mass k and k+1).
        contact: usize,
        /// The (negative) gap, m.
        gap: f64,
    },
    /// The initial positions put a mass beyond a rigid stop.
    #[error("initial positions put the {} mass beyond the {} stop: gap = {gap:.3e} m", if matches!(side, crate::model::StopSide::Upper) { "top" } else { "bottom" }, side.as_str())]
    BeyondStop {
        /// Which stop.
        side: crate::model::StopSide,
        /// The (negative) gap to the stop, m.
        gap: f64,
    },
    /// A parameter's value does not fit the others (e.g. a transducer mode that needs more
    /// gaps than the chain has).
    #[error("{name}: {message}")]
    Conflict {
        /// Parameter name.
        name: String,
        /// What does not fit, and what to do about it.
        message: String,
    },
}

impl ParamError {
    /// The same error with its parameter named by `map(name)`: how a configuration layer
    /// turns the library's field paths into its keys. `map` returns `None` to keep a name.
    pub fn renamed(self, map: impl Fn(&str) -> Option<String>) -> Self {
        let rename = |name: String| map(&name).unwrap_or(name);
        match self {
            ParamError::Invalid { name, value, reason } => ParamError::Invalid {
                name: rename(name),
                value,
                reason,
            },
            ParamError::Length { name, expected, got } => ParamError::Length {
                name: rename(name),
                expected,
                got,
            },
            ParamError::Conflict { name, message } => ParamError::Conflict {
                name: rename(name),
                message,
            },
            other => other,
        }
    }

    /// The same error with `prefix` and a dot before its parameter's name
    /// (`area` → `harvester.area`).
    pub fn within(self, prefix: &str) -> Self {
        self.renamed(|n| Some(format!("{prefix}.{n}")))
    }

    /// `name = value` is rejected because it `reason` (e.g. "must be positive").
    pub(crate) fn invalid(name: impl Into<String>, value: f64, reason: &'static str) -> Self {
        ParamError::Invalid {
            name: name.into(),
            value,
            reason,
        }
    }
}

/// `Ok` if `ok`, otherwise [`ParamError::Invalid`] for `name = value` with `reason`.
pub(crate) fn check(
    name: impl Into<String>,
    value: f64,
    ok: bool,
    reason: &'static str,
) -> Result<(), ParamError> {
    if ok {
        Ok(())
    } else {
        Err(ParamError::invalid(name, value, reason))
    }
}

/// Checks that `value` is a finite number.
pub(crate) fn check_finite(name: &str, value: f64) -> Result<(), ParamError> {
    check(name, value, value.is_finite(), "must be a finite number")
}

/// Checks that `value` is finite and positive.
pub(crate) fn check_positive(name: &str, value: f64) -> Result<(), ParamError> {
    check_finite(name, value)?;
    check(name, value, value > 0.0, "must be positive")
}

/// Checks that `value` is finite and not negative.
pub(crate) fn check_non_negative(name: &str, value: f64) -> Result<(), ParamError> {
    check_finite(name, value)?;
    check(name, value, value >= 0.0, "must not be negative")
}

/// A simulation could not continue.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SimError {
    /// The parameters are invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// More events occurred within one excitation period than
    /// [`SimOptions::max_events_per_period`](crate::SimOptions::max_events_per_period) allows.
    /// This is the guard that keeps pathological cases from spinning.
    #[error(
        "event limit reached at t = {t:.9} s: {events} events within one excitation period \
         (limit {limit}); the motion is pathological or the limit too low"
    )]
    EventLimit {
        /// Time at which the limit was reached, s.
        t: f64,
        /// Events counted in the current period.
        events: usize,
        /// The configured limit.
        limit: usize,
    },
    /// The event search could not advance (a root of an event function could not be
    /// separated from the current time).
    #[error("event search stalled at t = {t:.12} s on {what}")]
    Stalled {
        /// Time, s.
        t: f64,
        /// Which event function stalled.
        what: String,
    },
    /// Simultaneous impacts did not settle within the iteration limit.
    #[error("simultaneous impacts at t = {t:.12} s did not settle after {iterations} pairwise impacts")]
    ImpactIteration {
        /// Time, s.
        t: f64,
        /// Pairwise impacts applied.
        iterations: usize,
    },
    /// An undamped cluster is driven exactly at its natural frequency: the response grows
    /// without bound and has no periodic closed form.
    #[error(
        "undamped resonance: the cluster of masses {first}..={last} has natural frequency equal to the excitation frequency"
    )]
    UndampedResonance {
        /// First mass of the cluster (1-based).
        first: usize,
        /// Last mass of the cluster (1-based).
        last: usize,
    },
    /// A cluster's stiffness, damping and mass at the excitation frequency are beyond the
    /// range of double precision: the particular solution's K² or (K − Mω²)² + (Cω)²
    /// overflows (e.g. a stiffness of 1e300 N/m).
    #[error(
        "the cluster of masses {first}..={last} has a stiffness, damping or mass so far from the excitation's \
         scales that its closed-form flow overflows double precision (K² or (K − Mω²)² + (Cω)² is infinite): \
         give oscillator.stiffness, damping and masses within about 1e±100 of each other in SI units"
    )]
    OutOfRange {
        /// First mass of the cluster (1-based).
        first: usize,
        /// Last mass of the cluster (1-based).
        last: usize,
    },
    /// An observer failed the run (see [`Observer::proceed`](crate::Observer::proceed)).
    #[error("{0}")]
    Observer(String),
    /// The base motion cannot drive this chain or this run (the combination and the reason
    /// named).
    #[error("base motion: {0}")]
    BaseMotion(crate::excitation::BaseMotionError),
    /// A requested time lies before the current simulation time.
    #[error("cannot run backwards: requested t = {requested} s, current t = {current} s")]
    Backwards {
        /// Requested end time, s.
        requested: f64,
        /// Current time, s.
        current: f64,
    },
}

// Not `#[from]`: that would also make the inner error the `source()`, which the message
// already shows.
impl From<crate::excitation::BaseMotionError> for SimError {
    fn from(e: crate::excitation::BaseMotionError) -> Self {
        SimError::BaseMotion(e)
    }
}
