//! Errors of the periodic-orbit solvers.

use crate::error::{ParamError, SimError};
use crate::sensitivity::NonSmoothPoint;
use thiserror::Error;

/// Why Newton's method stopped without a periodic orbit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum NewtonFailure {
    /// The iteration limit was reached.
    Iterations,
    /// No damped step (down to the smallest damping factor) reduced the residual: the
    /// iteration is not converging to an orbit near here.
    LineSearch,
    /// `Φ − I` is singular to working precision (a Floquet multiplier at +1: a fold).
    Singular,
    /// The flow map is not differentiable at the current iterate (grazing or simultaneous
    /// impacts), so no Newton step can be taken from it.
    NonSmooth,
    /// The simulation from the iterate failed (an interpenetrating state, the event limit).
    Simulation,
}

impl std::fmt::Display for NewtonFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            NewtonFailure::Iterations => "the iteration limit was reached",
            NewtonFailure::LineSearch => "no damped Newton step reduced the residual",
            NewtonFailure::Singular => "Φ − I is singular (a multiplier at +1)",
            NewtonFailure::NonSmooth => "the flow map is not differentiable at the iterate",
            NewtonFailure::Simulation => "the simulation from the iterate failed",
        })
    }
}

/// A periodic orbit could not be found or analysed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum OrbitError {
    /// A period of zero excitation periods was asked for.
    #[error("the period must be at least 1 excitation period, got 0")]
    ZeroPeriod,
    /// An option or parameter is invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A simulation failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The orbit found passes a point where the flow map is not differentiable (grazing or
    /// simultaneous impacts): its monodromy matrix and multipliers do not exist.
    #[error("the orbit passes a non-differentiable point: {0}")]
    NonSmooth(NonSmoothPoint),
    /// Newton's method did not converge: no periodic orbit near the initial state, or one it
    /// cannot reach. `residuals` is the scaled residual `max_i |φ(z) − z|_i / scale_i` at each
    /// accepted iterate.
    #[error(
        "no periodic orbit of period {period} found: {reason} after {} iterations; residuals [{}]",
        residuals.len().saturating_sub(1),
        list(residuals)
    )]
    NoConvergence {
        /// Period asked for, in excitation periods.
        period: u32,
        /// Why Newton's method stopped.
        reason: NewtonFailure,
        /// Residual history.
        residuals: Vec<f64>,
    },
    /// No period could be read off the transient (see
    /// [`detect_period`](crate::analysis::detect_period)); give the period explicitly.
    #[error(
        "the motion after the transient is not periodic with a period up to {max_period} \
         (closest {closest_period}, mismatch {mismatch:.2e}); give the period explicitly"
    )]
    NotPeriodic {
        /// Largest period tried.
        max_period: usize,
        /// The period that came closest.
        closest_period: usize,
        /// Its relative mismatch.
        mismatch: f64,
    },
    /// The eigenvalues of the monodromy matrix could not be computed (the Schur iteration did
    /// not converge, or the matrix is not finite).
    #[error("the Floquet multipliers could not be computed")]
    Eigenvalues,
    /// The caller asked the search to stop ([`ShootingOptions::cancel`](super::ShootingOptions::cancel)).
    #[error("the search for a periodic orbit was stopped")]
    Cancelled,
}

/// `1.0e-3, 2.5e-5, …`
fn list(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| format!("{v:.2e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

// Not `#[from]`: that would also make the inner error the `source()`, which the message
// already shows (a failure's chain printed it twice).
impl From<NonSmoothPoint> for OrbitError {
    fn from(e: NonSmoothPoint) -> Self {
        OrbitError::NonSmooth(e)
    }
}
