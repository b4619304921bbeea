//! What kind of motion a recorded window shows: periodic, still settling, quasi-periodic or
//! chaotic.
//!
//! [`classify`] reads the recorded window of a sweep point:
//!
//! - **periodic**: the stroboscopic positions repeat with a period p ≤ the largest tested
//!   ([`PointOptions::period_options`]), within the period tolerance, and the return
//!   distances at no proper divisor of p are still shrinking ([`contracting_divisor`]); the
//!   residual is the test's relative mismatch. [`MotionReport::label_source`] says whether
//!   the run reached the orbit (`reached`) or Newton shooting finished the approach after
//!   the run was seen going there (`shot`).
//! - **settling**: not periodic, or periodic at p while the returns at a divisor d of p
//!   still shrink (a slow spiral onto an orbit of period d), or the return distances at some
//!   lag p ≤ the largest tested period shrink geometrically beyond doubt ([`converging_lag`],
//!   [`Convergence::converging`](crate::analysis::Convergence::converging)): the motion is still
//!   approaching an orbit; the rate per period and the periods still needed to reach the
//!   tolerance are reported. A motion whose largest Lyapunov exponent is negative beyond its
//!   error bar is settling too (onto an orbit the window cannot show as periodic), with the
//!   rate `exp(λ₁T)`.
//! - **chaotic**: the largest Lyapunov exponent over the recorded window is positive beyond
//!   three batch-means standard errors.
//! - **quasiperiodic**: the largest exponent is within three standard errors of 0. The
//!   section's [`closed_curve_ratio`] is reported beside it: below
//!   [`CLOSED_CURVE_RATIO`](crate::analysis::CLOSED_CURVE_RATIO) the section points lie on
//!   a closed curve, the section of a two-torus; above it the window is a cloud (a torus of
//!   higher dimension, or chaos too weak to show in the window).
//!
//! - **undetermined**: too short a window to tell (no period test, no converging fit, and
//!   no Lyapunov exponent with an error bar), or a run whose masses feel the harvester
//!   (two-way coupling) that is neither periodic nor converging: the exponent of the
//!   mechanics alone does not describe it.
//!
//! A stable orbit that Newton shooting found during the settling but the run did not
//! approach, and that the recorded window is not on, is reported as
//! [`MotionReport::coexisting`].
//!
//! The Lyapunov exponent is computed only for a point that is neither periodic nor settling
//! (over the recorded window when the settling already found the motion irregular, else by
//! a run of the same length from the final state), so periodic points cost nothing extra.
//!
//! That run carries 2N tangent vectors and folds them by a QR decomposition every period:
//! about (2N)³ operations a period ([`classify_cost`]). A run costlier than
//! [`MAX_CLASSIFY_WORK`] (a chain of a few hundred masses) is not made unless the budget
//! allows large jobs: the motion is then `undetermined`, and
//! [`MotionReport::lyapunov_skipped`] says why. The run polls the budget's stop flag at
//! every period's end.

use std::cmp::Ordering;
use std::ops::ControlFlow;

use super::lyapunov::lyapunov_spectrum;
use super::observer::RunObserver;
use super::point::{PointOptions, PointResult};
use super::settings::RunSpec;
use super::settle::{SettleEnding, Settled, ShotOrbit, section_states};
use super::simulate::Ending;
use crate::StateView;
use crate::analysis::{Periodicity, amplitude, closed_curve_ratio, contracting_divisor, converging_lag};
use crate::excitation::WorkBudget;
use crate::lyapunov::{LyapunovOptions, LyapunovSpectrum};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::orbits::Cancel;
use crate::sensitivity::length_scale;

/// The kind of motion of a recorded window (see the module docs of `study/motion.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum Motion {
    /// Repeats with a period.
    Periodic,
    /// Still converging.
    Settling,
    /// Largest Lyapunov exponent indistinguishable from 0.
    Quasiperiodic,
    /// Largest Lyapunov exponent positive beyond its error bar.
    Chaotic,
    /// Too short a window to tell.
    Undetermined,
}

impl Motion {
    /// `periodic`, `settling`, `quasiperiodic`, `chaotic` or `undetermined`.
    pub fn as_str(self) -> &'static str {
        match self {
            Motion::Periodic => "periodic",
            Motion::Settling => "settling",
            Motion::Quasiperiodic => "quasiperiodic",
            Motion::Chaotic => "chaotic",
            Motion::Undetermined => "undetermined",
        }
    }
}

/// How a periodic label was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum LabelSource {
    /// The run itself repeats within the period tolerance.
    Reached,
    /// Newton shooting finished the run's approach, after the run was seen approaching the
    /// orbit at the rate of its multipliers.
    Shot,
}

impl LabelSource {
    /// `reached` or `shot`.
    pub fn as_str(self) -> &'static str {
        match self {
            LabelSource::Reached => "reached",
            LabelSource::Shot => "shot",
        }
    }
}

impl std::fmt::Display for Motion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A point's motion and how it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionReport {
    /// The kind of motion.
    pub motion: Motion,
    /// Periods run before the recorded window.
    pub settle_periods: u64,
    /// How the settling ended.
    pub settle_ending: SettleEnding,
    /// Relative mismatch of the period test at the detected (or closest) period
    /// ([`Periodicity`]); NaN with too few recorded periods.
    pub residual: f64,
    /// The period the residual is measured at (the detected one, or the closest candidate).
    pub residual_period: usize,
    /// Decay factor per excitation period of the return distances (< 1: converging): from
    /// the geometric fit of the recorded window where that converges, else from the
    /// settling's last fit, or `exp(λ₁T)` for a motion settling by its Lyapunov exponent.
    pub rate: Option<f64>,
    /// For a settling motion: periods still needed at that rate before a recorded window
    /// would show the period (the return distance down to the tolerance, then the window
    /// the period test reads).
    pub periods_needed: Option<f64>,
    /// After Newton shooting finished the settling: the orbit's period and residual.
    pub shot: Option<(u32, f64)>,
    /// The largest Lyapunov exponent and its batch-means standard error, 1/s, where
    /// computed.
    pub lyapunov: Option<(f64, f64)>,
    /// The recorded section's [`closed_curve_ratio`] (scaled positions and velocities), for
    /// a quasi-periodic or chaotic motion.
    pub curve_ratio: Option<f64>,
    /// For a periodic motion: whether the run reached the orbit or shooting finished it.
    pub label_source: Option<LabelSource>,
    /// A stable orbit found near the run during the settling that the run did not approach
    /// and the recorded window is not on: its minimal period and largest multiplier modulus
    /// (over that period).
    pub coexisting: Option<(u32, f64)>,
    /// Why the Lyapunov exponent a non-periodic, non-converging window needs was not
    /// computed (the motion is then `undetermined`).
    pub lyapunov_skipped: Option<LyapunovSkipped>,
}

/// Most tangent-space work, (2N)³ × periods ([`classify_cost`]), the classification's
/// Lyapunov run does unless large jobs are allowed: 10¹¹, about a minute on one core (a chain
/// of about 100 masses over the default window).
pub const MAX_CLASSIFY_WORK: f64 = 1e11;

/// The tangent-space work of a classifying Lyapunov run of a chain of `masses` masses over
/// `periods` periods: (2N)³ per period, the QR of its 2N × 2N basis (the state-transition
/// matrices of its events cost as much again or more).
pub fn classify_cost(masses: usize, periods: u64) -> f64 {
    (2.0 * masses as f64).powi(3) * periods as f64
}

/// Why a classification computed no Lyapunov exponent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LyapunovSkipped {
    /// Its cost ([`classify_cost`]) is above [`MAX_CLASSIFY_WORK`] and large jobs were not
    /// allowed.
    Costly {
        /// Tangent directions, 2N.
        dimension: usize,
        /// Periods of the run.
        periods: u64,
    },
    /// The budget's stop flag was set during the run.
    Stopped,
}

impl std::fmt::Display for LyapunovSkipped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            LyapunovSkipped::Costly { dimension, periods } => write!(
                f,
                "the Lyapunov exponent of {dimension} tangent directions over {periods} periods would cost \
                 about {:.1e} operations, more than the limit of {MAX_CLASSIFY_WORK:.0e} (allow large jobs, \
                 --allow-large, to compute it)",
                (dimension as f64).powi(3) * periods as f64
            ),
            LyapunovSkipped::Stopped => f.write_str("the Lyapunov run was stopped by a signal"),
        }
    }
}

/// A run observer that stops the run at a period's end once the budget's flag is set or the
/// cancel hook asks.
struct Poll<'a>(&'a WorkBudget, &'a Cancel);

impl RunObserver for Poll<'_> {
    fn period(&mut self, _periods: u64, _state: &StateView<'_>) -> ControlFlow<()> {
        if self.0.stopped() || self.1.requested() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// Error bars a Lyapunov exponent must clear to count as nonzero.
const SIGMAS: f64 = 3.0;

/// A recorded window: its stroboscopic samples (t = nT, row-major like
/// [`PointResult::strobe`]), the period test's verdict on them and the state at its end.
#[derive(Debug, Clone, Copy)]
pub struct Window<'a> {
    /// Positions x_i, m.
    pub positions: &'a [f64],
    /// Velocities, m/s.
    pub velocities: &'a [f64],
    /// The period test's verdict (`None`: too few samples).
    pub periodicity: Option<Periodicity>,
    /// State at the window's end (where a Lyapunov run starts).
    pub final_state: &'a ChainState,
    /// Whether the harvester's forces act on the masses (two-way coupling): the exponent of
    /// the mechanics alone does not describe such a run, and none is computed for it.
    pub coupled: bool,
}

impl<'a> Window<'a> {
    /// The recorded window of a sweep point.
    pub fn of(result: &'a PointResult) -> Self {
        Window {
            positions: &result.strobe,
            velocities: &result.strobe_velocities,
            periodicity: result.periodicity,
            final_state: &result.final_state,
            coupled: false,
        }
    }
}

/// Classifies a recorded `window` of `params` (see the module docs of `study/motion.rs`); `settled` is
/// the adaptive settling before it, `None` after a fixed transient of
/// `options.transient_periods`; `spectrum` the Lyapunov spectrum over the window if one was
/// computed. Without one, a window that is neither periodic nor settling gets the spectrum
/// over `options.recorded_periods` periods from its final state (mechanics only), within
/// `budget` ([`MAX_CLASSIFY_WORK`] unless it allows large jobs; stopped by its flag or by
/// `options.cancel`).
pub fn classify(
    params: &ChainParams,
    sim_options: &SimOptions,
    options: &PointOptions,
    window: Window<'_>,
    settled: Option<&Settled>,
    spectrum: Option<&LyapunovSpectrum>,
    budget: &WorkBudget,
) -> MotionReport {
    let n = params.len();
    let test_window = options.period_options().samples_needed() as f64;
    let mut report = MotionReport {
        motion: Motion::Settling,
        settle_periods: settled.map_or(options.transient_periods, |s| s.periods),
        settle_ending: settled.map_or(SettleEnding::Fixed, |s| s.ending),
        residual: f64::NAN,
        residual_period: 0,
        rate: settled
            .and_then(|s| s.convergence)
            .filter(|c| c.converging())
            .map(|c| c.rate()),
        periods_needed: None,
        shot: settled.and_then(|s| s.shot),
        lyapunov: None,
        curve_ratio: None,
        label_source: None,
        coexisting: None,
        lyapunov_skipped: None,
    };
    let scale = amplitude(window.positions);
    report.coexisting = settled
        .and_then(|s| s.rejected.as_ref())
        .filter(|o| !window_on(window.positions, n, o, scale))
        .map(|o| (o.period, o.spectral_radius));
    let tolerance = options.period_tolerance;
    let states: Vec<f64> = section_states(window.positions, window.velocities, params).collect();
    let (closest, mismatch) = match window.periodicity {
        Some(Periodicity::Periodic { period, mismatch }) => {
            if let Some((d, fit)) = contracting_divisor(&states, 2 * n, period, scale) {
                // A slow spiral onto an orbit of period d, nearly closing after period/d turns.
                report.residual = lag_mismatch(window.positions, n, d, scale);
                report.residual_period = d;
                report.rate = Some(fit.rate());
                report.periods_needed = fit.samples_needed(tolerance).map(|p| p + test_window);
                return report;
            }
            report.motion = Motion::Periodic;
            report.residual = mismatch;
            report.residual_period = period;
            report.label_source = Some(match report.settle_ending {
                SettleEnding::Shot => LabelSource::Shot,
                _ => LabelSource::Reached,
            });
            return report;
        }
        Some(Periodicity::NonPeriodic {
            closest_period,
            mismatch,
        }) => (closest_period, mismatch),
        None => (1, f64::NAN),
    };
    report.residual = mismatch;
    report.residual_period = closest;
    let max_lag = options
        .period_options()
        .max_period
        .min(states.len() / (6 * n))
        .max(1);
    if let (_, Some(fit)) = converging_lag(&states, 2 * n, max_lag, scale, closest)
        && fit.converging()
    {
        report.rate = Some(fit.rate());
        report.periods_needed = fit.samples_needed(tolerance).map(|p| p + test_window);
        return report;
    }
    if window.coupled && spectrum.is_none() {
        // Not periodic, not converging, and no exponent of the coupled run to go by.
        report.motion = Motion::Undetermined;
        return report;
    }
    let spectrum = match spectrum {
        Some(s) => Some(s.clone()),
        None => {
            let periods = WARMUP + options.recorded_periods;
            if classify_cost(n, periods) > MAX_CLASSIFY_WORK && !budget.allow_large {
                report.motion = Motion::Undetermined;
                report.lyapunov_skipped = Some(LyapunovSkipped::Costly {
                    dimension: 2 * n,
                    periods,
                });
                return report;
            }
            let mut spec = RunSpec::new(params.clone(), periods);
            spec.initial = window.final_state.clone();
            spec.options = sim_options.clone();
            spec.transient_periods = WARMUP;
            let run = lyapunov_spectrum(
                &spec,
                &LyapunovOptions::default(),
                &mut Poll(budget, &options.cancel),
            )
            .ok();
            if run.as_ref().is_some_and(|r| r.outcome.ending == Ending::Stopped) {
                report.motion = Motion::Undetermined;
                report.lyapunov_skipped = Some(LyapunovSkipped::Stopped);
                return report;
            }
            run.and_then(|r| r.spectrum.ok())
        }
    };
    report.curve_ratio = section_curve_ratio(params, window);
    let Some(s) = spectrum else {
        // No period could be averaged (every one met a grazing or simultaneous impact): the
        // section's shape is all there is to go by.
        report.motion = match report.curve_ratio {
            Some(r) if r < crate::analysis::CLOSED_CURVE_RATIO => Motion::Quasiperiodic,
            _ => Motion::Chaotic,
        };
        return report;
    };
    let (largest, se) = (s.largest(), s.largest_spread());
    report.lyapunov = Some((largest, se));
    if window.periodicity.is_none() && !se.is_finite() {
        // Neither a period test nor an error bar: the window is too short to tell.
        report.motion = Motion::Undetermined;
        return report;
    }
    report.motion = match exponent_sign(largest, se) {
        Ordering::Greater => Motion::Chaotic,
        Ordering::Less => {
            let per_period = largest * params.period();
            report.rate = Some(per_period.exp());
            report.periods_needed = (mismatch.is_finite() && mismatch > 0.0)
                .then(|| ((tolerance / mismatch).ln() / per_period).max(0.0) + test_window);
            Motion::Settling
        }
        Ordering::Equal => Motion::Quasiperiodic,
    };
    report
}

/// The sign of a largest Lyapunov exponent `largest` (1/s) told apart from 0 by its
/// standard error `se` (1/s): `Greater` or `Less` only beyond 3 (`SIGMAS`) errors, `Equal`
/// within them (a non-finite error counts as 0). The rule behind `chaotic`,
/// `quasiperiodic` and a contracting (settling) window.
pub fn exponent_sign(largest: f64, se: f64) -> Ordering {
    let se = if se.is_finite() { se } else { 0.0 };
    if largest - SIGMAS * se > 0.0 {
        Ordering::Greater
    } else if largest + SIGMAS * se < 0.0 {
        Ordering::Less
    } else {
        Ordering::Equal
    }
}

/// How close (relative to the amplitude, in the largest coordinate) a recorded sample must
/// come to an orbit's section state for the window to count as on that orbit.
const ON_ORBIT: f64 = 1e-2;

/// Whether the stroboscopic `positions` (`n` per sample) come within [`ON_ORBIT`] (relative
/// to `scale`) of the orbit's section state: a window on the orbit passes through it once
/// every orbit period.
fn window_on(positions: &[f64], n: usize, orbit: &ShotOrbit, scale: f64) -> bool {
    positions.chunks_exact(n).any(|x| {
        x.iter()
            .zip(&orbit.state.positions)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            <= ON_ORBIT * scale
    })
}

/// The period test's relative mismatch at lag `p` over the whole window: the largest
/// coordinate difference of samples `p` apart over `scale`.
fn lag_mismatch(positions: &[f64], n: usize, p: usize, scale: f64) -> f64 {
    let rows: Vec<&[f64]> = positions.chunks_exact(n).collect();
    let worst = (p..rows.len())
        .flat_map(|j| rows[j].iter().zip(rows[j - p]).map(|(a, b)| (a - b).abs()))
        .fold(f64::NAN, f64::max);
    worst / scale
}

/// Periods the tangent vectors of a classifying Lyapunov run align over before averaging.
pub(super) const WARMUP: u64 = 20;

/// The [`closed_curve_ratio`] of the recorded section, positions over L = Σδ + A and
/// velocities over L·ω.
fn section_curve_ratio(params: &ChainParams, window: Window<'_>) -> Option<f64> {
    let n = params.len();
    let l = length_scale(params);
    let v = l * params.omega();
    let points: Vec<f64> = window
        .positions
        .chunks_exact(n)
        .zip(window.velocities.chunks_exact(n))
        .flat_map(|(x, u)| {
            x.iter()
                .map(|x| x / l)
                .chain(u.iter().map(|u| u / v))
                .collect::<Vec<_>>()
        })
        .collect();
    closed_curve_ratio(&points, 2 * n)
}
