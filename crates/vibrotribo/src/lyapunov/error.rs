//! Errors of a Lyapunov spectrum.

use thiserror::Error;

use crate::sensitivity::NonSmoothPoint;

/// A Lyapunov spectrum could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum LyapunovError {
    /// No period after the transient could be used: the run was too short, stopped before
    /// the transient ended, or every period met a non-differentiable point.
    #[error(
        "no period after the transient could be averaged ({skipped} skipped at non-differentiable points{})",
        first.as_ref().map_or(String::new(), |p| format!("; the first: {p}"))
    )]
    NoPeriods {
        /// Periods after the transient skipped because of a non-differentiable point.
        skipped: u64,
        /// The first non-differentiable point met, if any.
        first: Option<NonSmoothPoint>,
    },
}
