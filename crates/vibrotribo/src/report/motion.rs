//! The motion of a run or a sweep point as `summary.json` (and the explorer's grid) states
//! it: [`MotionRecord`], written and read through that one type.

use serde::{Deserialize, Serialize};

use crate::study::{LabelSource, Motion, MotionReport, SettleEnding};

/// The orbit Newton shooting finished the settling on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NewtonRecord {
    /// Its period, in excitation periods.
    pub period: u32,
    /// Its residual, relative.
    pub residual: f64,
}

/// A stable orbit near the run that the run does not approach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CoexistingRecord {
    /// Its period, in excitation periods.
    pub period: u32,
    /// Its largest Floquet multiplier modulus, dimensionless.
    pub max_abs_multiplier: f64,
}

/// summary.json's `motion` object: the kind of motion after the transient, how the settling
/// before it ended and what the label rests on (see [`MotionReport`]). Non-finite numbers are
/// written `null`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MotionRecord {
    /// The kind of motion.
    pub motion: Motion,
    /// The period, in excitation periods (0 unless periodic).
    pub period: usize,
    /// Relative mismatch of the period test at `residual_period` (`None`: too few periods).
    pub residual: Option<f64>,
    /// The period the residual is measured at.
    pub residual_period: usize,
    /// Periods run before the recorded window.
    pub settle_periods: u64,
    /// How the settling ended.
    pub settle_ending: SettleEnding,
    /// Decay factor per excitation period of the return distances, dimensionless.
    pub settle_rate: Option<f64>,
    /// For a settling motion: periods still needed at that rate.
    pub settle_periods_needed: Option<f64>,
    /// The orbit Newton shooting finished the settling on.
    pub newton: Option<NewtonRecord>,
    /// The largest Lyapunov exponent, 1/s.
    pub lyapunov_max_1_s: Option<f64>,
    /// Its spread, 1/s.
    pub lyapunov_spread_1_s: Option<f64>,
    /// How closely the stroboscopic section closes into a curve, dimensionless.
    pub section_curve_ratio: Option<f64>,
    /// How a periodic label was reached.
    pub label_source: Option<LabelSource>,
    /// A stable orbit near the run that the run does not approach.
    pub coexisting: Option<CoexistingRecord>,
    /// Why no Lyapunov exponent was computed, in words (absent when one was, or none was
    /// needed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lyapunov_skipped: Option<String>,
}

impl MotionRecord {
    /// The record of `m`.
    pub fn of(m: &MotionReport) -> Self {
        let finite = |x: f64| x.is_finite().then_some(x);
        MotionRecord {
            motion: m.motion,
            period: if m.motion == Motion::Periodic {
                m.residual_period
            } else {
                0
            },
            residual: finite(m.residual),
            residual_period: m.residual_period,
            settle_periods: m.settle_periods,
            settle_ending: m.settle_ending,
            settle_rate: m.rate.and_then(finite),
            settle_periods_needed: m.periods_needed.and_then(finite),
            newton: m.shot.map(|(period, residual)| NewtonRecord { period, residual }),
            lyapunov_max_1_s: m.lyapunov.map(|l| l.0).and_then(finite),
            lyapunov_spread_1_s: m.lyapunov.map(|l| l.1).and_then(finite),
            section_curve_ratio: m.curve_ratio.and_then(finite),
            label_source: m.label_source,
            coexisting: m.coexisting.map(|(period, r)| CoexistingRecord {
                period,
                max_abs_multiplier: r,
            }),
            lyapunov_skipped: m.lyapunov_skipped.map(|s| s.to_string()),
        }
    }
}
