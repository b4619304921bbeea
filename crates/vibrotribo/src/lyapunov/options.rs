//! Settings of a Lyapunov spectrum.

use crate::error::{ParamError, check, check_positive};
use crate::sensitivity::SensitivityOptions;

/// Settings of [`LyapunovObserver`](super::LyapunovObserver) and
/// [`lyapunov_spectrum`](crate::study::lyapunov_spectrum).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LyapunovOptions {
    /// Seed of the random orthonormal basis the tangent vectors start from. The exponents do
    /// not depend on it beyond their spread. Default 1.
    pub seed: u64,
    /// The tangent vectors are re-orthonormalised at every excitation period's end, and
    /// earlier, after a piece of flow, once an entry of the block's state-transition matrix
    /// exceeds `max_growth` in magnitude, or once the block lasts `ln(max_growth)/max_i(c_i/m_i)`
    /// (the longest time over which no direction can contract by more than `max_growth`; a
    /// longer piece of flow is taken in parts): every block's Φ then keeps the digits of its
    /// most contracting directions. Dimensionless. Default 1e6.
    pub max_growth: f64,
    /// Number of consecutive batches of periods whose exponents give the spread (the
    /// batch-means standard error, [`LyapunovSpectrum::spread`](super::LyapunovSpectrum)).
    /// At least 2; fewer periods than batches give one period per batch. Default 10.
    pub batches: usize,
    /// Grazing and simultaneous-impact thresholds of the state-transition matrix.
    pub sensitivity: SensitivityOptions,
}

impl Default for LyapunovOptions {
    fn default() -> Self {
        LyapunovOptions {
            seed: 1,
            max_growth: 1e6,
            batches: 10,
            sensitivity: SensitivityOptions::default(),
        }
    }
}

impl LyapunovOptions {
    /// Checks the options, naming the field at fault.
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "max_growth",
            self.max_growth,
            self.max_growth.is_finite() && self.max_growth > 1.0,
            "must be a finite number above 1",
        )?;
        check(
            "batches",
            self.batches as f64,
            self.batches >= 2,
            "must be at least 2",
        )?;
        check_positive("sensitivity.grazing_speed", self.sensitivity.grazing_speed)?;
        check_positive("sensitivity.contact_gap", self.sensitivity.contact_gap)
    }
}
