//! Analyses of simulated motion: Poincaré sections, periodicity, spectra, fits
//! (seed Sect. 4; docs/MODEL.md §3).

//!
//! Two kinds of tool live here:
//!
//! - **Observers** that watch a run ([`Observer`](crate::Observer)):
//!   [`StroboscopicSection`] samples the exact flow at `t = t₀ + nT` (the stroboscopic
//!   Poincaré map behind the paper's orbit diagrams, Figs. 7, 12, 14, 18, 20), and
//!   [`ImpactSection`] records the state and closing speed at every impact (the impact map).
//! - **Functions on series** that the observers (or the electrical solver) produce:
//!   [`detect_period`] finds the period of a stroboscopic series, [`welch_psd`] the power
//!   spectral density of a uniformly sampled signal, [`fit_quadratic`] the least-squares
//!   parabola (the paper's optimal mass ratio `R_mo = 11.43Ω² − 28.46Ω + 18.03`, Sect. 4.3).
//!   The paper's running average power `P_a(N) = Σ_{n≤N} E_n / (N T)` is computed by the
//!   electrical solver ([`power_curve`](crate::electrical::power_curve),
//!   [`summarize`](crate::electrical::summarize)).
//!
//! Every function validates its input and returns an [`AnalysisError`] instead of panicking
//! on empty, too short or non-finite data.

mod bandwidth;
mod fit;
mod period;
mod poincare;
mod settle;
mod spectrum;
mod stats;

pub use bandwidth::{Bandwidth, envelope, half_power_bandwidth};
pub use fit::{QuadraticFit, fit_quadratic};
pub use period::{PeriodOptions, Periodicity, detect_period};
pub use poincare::{ImpactPoint, ImpactSection, StroboscopicOptions, StroboscopicSection};
pub use settle::{
    CLOSED_CURVE_RATIO, Convergence, amplitude, batch_means_se, closed_curve_ratio, contracting_divisor,
    converging_lag, fit_convergence, return_distances,
};
pub use spectrum::{Detrend, Psd, WelchOptions, Window, welch_psd};
pub use stats::RunStats;

use crate::error::{ParamError, check_positive};
use thiserror::Error;

/// An analysis could not be carried out on the data or options given.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// An option is out of range (the name is the option's field name).
    #[error(transparent)]
    Option(#[from] ParamError),
    /// The input holds no data.
    #[error("{what} is empty")]
    Empty {
        /// Which input.
        what: &'static str,
    },
    /// The input holds a NaN or an infinity.
    #[error("{what} has the non-finite value {value} at index {index}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Index of the first offending value (in the flattened data).
        index: usize,
        /// The value.
        value: f64,
    },
    /// The input is shorter than the analysis needs.
    #[error("{what} has {got} samples, the analysis needs at least {needed}")]
    TooShort {
        /// Which input.
        what: &'static str,
        /// Samples needed.
        needed: usize,
        /// Samples given.
        got: usize,
    },
    /// Two inputs that must agree in length do not, or a flattened series is not a whole
    /// number of rows.
    #[error("{what}: expected {expected}, got {got}")]
    LengthMismatch {
        /// What was compared.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A fit has no unique solution.
    #[error("degenerate fit: {0}")]
    Degenerate(&'static str),
}

/// The first non-finite value of `data`, as an error naming `what`.
fn check_finite(what: &'static str, data: &[f64], index_offset: usize) -> Result<(), AnalysisError> {
    match data.iter().position(|v| !v.is_finite()) {
        Some(i) => Err(AnalysisError::NonFinite {
            what,
            index: index_offset + i,
            value: data[i],
        }),
        None => Ok(()),
    }
}

/// An `InvalidParameter`-style error for option `name`.
fn invalid(name: &str, value: f64, reason: &'static str) -> AnalysisError {
    AnalysisError::Option(ParamError::invalid(name, value, reason))
}

/// Compensated (Neumaier) running sum, for long sums of terms of mixed size.
#[derive(Debug, Clone, Copy, Default)]
struct Sum {
    sum: f64,
    compensation: f64,
}

impl Sum {
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        if self.sum.abs() >= x.abs() {
            self.compensation += (self.sum - t) + x;
        } else {
            self.compensation += (x - t) + self.sum;
        }
        self.sum = t;
    }

    fn value(&self) -> f64 {
        self.sum + self.compensation
    }
}
