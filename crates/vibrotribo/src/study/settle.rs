//! Adaptive settling of a sweep point: run in blocks until the stroboscopic returns repeat,
//! finishing a geometric approach to a periodic orbit off by Newton shooting.
//!
//! After each block of excitation periods (mechanics only), the trailing stroboscopic
//! positions are tested for a period exactly as the recorded window will be
//! ([`PointOptions::period_options`]). If they repeat, the motion has settled. If not, the
//! return distances at the closest candidate period p are fitted by a geometric decay
//! ([`fit_convergence`]); where they shrink beyond doubt and would need more than another
//! block to reach the tolerance, the periodic orbit of period p is sought by Newton shooting
//! from the current state ([`find_periodic_orbit`]) and accepted only if it is stable, the
//! current state is within the distance the geometric tail still has to travel (four times
//! `d/(1 − r^p)`), and the run is going there: the run's own state, simulated on for K·p
//! periods, with K the smallest count of orbit periods over which the orbit's largest
//! multiplier modulus ρ predicts a fourfold shrink (ρ^K ≤ 1/4), must end within 2·ρ^K of
//! its starting distance from the orbit (in the section states the fit reads). The recorded
//! window then starts on the orbit, at the period the settling reached; its period is the
//! orbit's minimal one (the smallest divisor d of p with `φ_d(z) = z` within the period
//! tolerance). A stable orbit the run does not approach is kept as a coexisting orbit and
//! the settling goes on from the run's state. A confirmation that would overrun the cap is
//! not tried.
//!
//! A window that repeats at lag p is taken as settled only if no proper divisor d of p has
//! return distances that are still shrinking geometrically ([`contracting_divisor`]): a slow
//! spiral onto an orbit of period d that nearly closes after p/d turns is still settling.
//! Distances that do not shrink end the settling once the fixed transient
//! (`transient_periods`) has passed, so an irregular motion costs no more than before; the
//! cap ends it otherwise.

use super::observer::{Checkpoint, Mechanics};
use super::point::{PointError, PointOptions};
use super::settings::RunSpec;
use super::simulate::{Ending, StudyError, simulate};
use crate::analysis::{
    Convergence, Periodicity, StroboscopicOptions, StroboscopicSection, amplitude, contracting_divisor,
    converging_lag, detect_period,
};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::orbits::{Cancel, PeriodicOrbit, ShootingOptions, find_periodic_orbit};

/// How long a sweep point runs before its recorded window.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum SettleMode {
    /// A fixed transient of [`PointOptions::transient_periods`] periods.
    #[default]
    Fixed,
    /// Until the motion repeats (see the module docs of `study/settle.rs`).
    Auto(AutoSettle),
}

impl SettleMode {
    /// `"fixed"` or `"auto"`.
    pub fn as_str(&self) -> &'static str {
        match self {
            SettleMode::Fixed => "fixed",
            SettleMode::Auto(_) => "auto",
        }
    }

    /// This mode with at most `cap` periods before the recorded window if it is
    /// [`SettleMode::Auto`].
    pub fn with_cap(self, cap: u64) -> Self {
        match self {
            SettleMode::Auto(a) => SettleMode::Auto(AutoSettle {
                cap_periods: cap,
                ..a
            }),
            SettleMode::Fixed => SettleMode::Fixed,
        }
    }
}

impl std::str::FromStr for SettleMode {
    type Err = UnknownSettleMode;

    /// `auto` ([`SettleMode::Auto`] with the default [`AutoSettle`]) or `fixed`.
    fn from_str(s: &str) -> Result<Self, UnknownSettleMode> {
        match s {
            "auto" => Ok(SettleMode::Auto(AutoSettle::default())),
            "fixed" => Ok(SettleMode::Fixed),
            other => Err(UnknownSettleMode(other.to_string())),
        }
    }
}

/// A settle mode's name is neither `auto` nor `fixed`.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown settle mode {0:?}: expected auto or fixed")]
pub struct UnknownSettleMode(
    /// The name given.
    pub String,
);

/// The default of [`AutoSettle::cap_periods`]: the most periods a point settles, 2000.
pub const DEFAULT_SETTLE_CAP: u64 = 2000;

/// Settings of [`SettleMode::Auto`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoSettle {
    /// Most periods run before the recorded window. Default 2000.
    pub cap_periods: u64,
    /// Periods between two checks. Default 50.
    pub block: u64,
    /// Whether a geometric approach to a periodic orbit is finished by Newton shooting.
    /// Default true.
    pub shoot: bool,
}

impl Default for AutoSettle {
    fn default() -> Self {
        AutoSettle {
            cap_periods: DEFAULT_SETTLE_CAP,
            block: 50,
            shoot: true,
        }
    }
}

/// How the settling before a recorded window ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum SettleEnding {
    /// A fixed transient ([`SettleMode::Fixed`]).
    Fixed,
    /// The returns repeated within the period tolerance.
    Repeated,
    /// Newton shooting finished a geometric approach to a stable periodic orbit, and the
    /// run's own state was seen approaching it at the rate its multipliers predict.
    Shot,
    /// The returns did not shrink (once the fixed transient had passed).
    Irregular,
    /// The cap was reached.
    Cap,
}

impl SettleEnding {
    /// `fixed`, `repeated`, `shot`, `irregular` or `cap`.
    pub fn as_str(self) -> &'static str {
        match self {
            SettleEnding::Fixed => "fixed",
            SettleEnding::Repeated => "repeated",
            SettleEnding::Shot => "shot",
            SettleEnding::Irregular => "irregular",
            SettleEnding::Cap => "cap",
        }
    }
}

/// Where the settling left the point.
#[derive(Debug, Clone, PartialEq)]
pub struct Settled {
    /// Periods run before the recorded window.
    pub periods: u64,
    /// The state to record from (at t = periods·T; on the shot orbit after
    /// [`SettleEnding::Shot`]).
    pub state: ChainState,
    /// How it ended.
    pub ending: SettleEnding,
    /// The last geometric fit of the return distances (per period), if one was made.
    pub convergence: Option<Convergence>,
    /// The candidate period the fit was made at.
    pub fit_period: usize,
    /// After [`SettleEnding::Shot`]: the orbit's minimal period and Newton residual.
    pub shot: Option<(u32, f64)>,
    /// The last stable orbit Newton shooting found near the run that the run, simulated
    /// on, did not approach (a coexisting attractor).
    pub rejected: Option<ShotOrbit>,
}

/// A stable periodic orbit found by Newton shooting.
#[derive(Debug, Clone, PartialEq)]
pub struct ShotOrbit {
    /// Minimal period, in excitation periods.
    pub period: u32,
    /// Largest Floquet multiplier modulus of the orbit taken over `period` excitation periods.
    pub spectral_radius: f64,
    /// The orbit's state at the section t ≡ 0 (mod T).
    pub state: ChainState,
}

/// The section states `[x_1 … x_N, v_1/ω_1 … v_N/ω_N]`, m, of stroboscopic samples
/// (positions and velocities row-major), one row per sample, with ω_i = √(k_i/m_i) each
/// mass's own natural frequency (so that a free mass's decaying oscillation has a nearly
/// constant norm between its decays): what the geometric fit reads.
pub(super) fn section_states<'a>(
    positions: &'a [f64],
    velocities: &'a [f64],
    params: &'a ChainParams,
) -> impl Iterator<Item = f64> + 'a {
    let n = params.len();
    positions
        .chunks_exact(n)
        .zip(velocities.chunks_exact(n))
        .flat_map(move |(x, v)| {
            x.iter().copied().chain(
                v.iter()
                    .enumerate()
                    .map(move |(i, v)| v / (params.stiffness[i] / params.masses[i]).sqrt()),
            )
        })
}

/// Runs the mechanics of `params` from `state` for `periods` excitation periods: the
/// stroboscopic samples at t = T, 2T, … (from the start) and the final state; stopped by
/// `cancel` at a period's end ([`PointError::Stopped`], counting this run's periods).
pub(super) fn strobe_run(
    params: &ChainParams,
    sim_options: &SimOptions,
    state: &ChainState,
    periods: u64,
    cancel: &Cancel,
) -> Result<(StroboscopicSection, ChainState), PointError> {
    let mut spec = RunSpec::new(params.clone(), periods);
    spec.initial = state.clone();
    spec.options = sim_options.clone();
    spec.transient_periods = 0;
    let strobe = StroboscopicSection::new(
        params.len(),
        params.period(),
        StroboscopicOptions {
            phase_time: 0.0,
            transient_periods: 1,
        },
    )?;
    let mut watch = (
        Mechanics::new(strobe),
        Checkpoint {
            stop: |_| cancel.requested(),
        },
    );
    let outcome = simulate(&spec, &mut watch)?;
    match outcome.ending {
        Ending::Failed(StudyError::Sim(e)) => Err(e.into()),
        Ending::Failed(e) => Err(PointError::Study(e)),
        Ending::Stopped => Err(PointError::Stopped {
            periods: outcome.periods,
        }),
        Ending::Completed => Ok((watch.0.inner, outcome.final_state)),
    }
}

/// At most this many Newton attempts per point.
const MAX_SHOTS: u32 = 3;

/// Newton iterations a shot may take. It starts within the geometric tail of a stable orbit,
/// where Newton's method on a smooth map converges quadratically in a few iterations; one
/// that needs more is not near the orbit the fit sees (or meets a map that is not smooth
/// there), and the run settles on its own instead.
const SHOT_ITERATIONS: usize = 10;

/// Smallest damping factor of a shot's line search (see [`SHOT_ITERATIONS`]).
const SHOT_MIN_DAMPING: f64 = 1.0 / 32.0;

/// Settles `params` from `initial` (see the module docs of `study/settle.rs`): runs `sim_options`'
/// mechanics in blocks until the period test of `options` passes on the trailing returns,
/// Newton shooting finishes a geometric approach, the returns prove irregular after
/// `options.transient_periods`, or `auto.cap_periods` is reached. `options.cancel` is polled
/// at every period and Newton iteration: when it asks, the settling stops with
/// [`PointError::Stopped`], counting the periods it ran.
pub fn settle(
    params: &ChainParams,
    initial: &ChainState,
    sim_options: &SimOptions,
    options: &PointOptions,
    auto: &AutoSettle,
) -> Result<Settled, PointError> {
    let n = params.len();
    let popts = options.period_options();
    let needed = popts.samples_needed();
    let block = auto.block.max(1);
    let mut history: Vec<f64> = Vec::new();
    let mut states: Vec<f64> = Vec::new();
    let mut state = initial.clone();
    let mut done = 0u64;
    let mut shots = 0;
    let mut last_fit = None;
    let mut fit_period = 1;
    let mut rejected = None;
    loop {
        let len = if done == 0 {
            block.max(needed as u64)
        } else {
            block
        }
        .min(auto.cap_periods.saturating_sub(done))
        .max(1);
        let (strobe, last) =
            strobe_run(params, sim_options, &state, len, &options.cancel).map_err(|e| e.after(done))?;
        done += len;
        state = last;
        history.extend_from_slice(&strobe.positions);
        states.extend(section_states(&strobe.positions, &strobe.velocities, params));
        let keep = needed.max(block as usize) + popts.max_period;
        if history.len() > keep * n {
            history.drain(..history.len() - keep * n);
            states.drain(..states.len() - keep * 2 * n);
        }
        let samples = history.len() / n;
        let end = |ending, fit, fit_period, rejected: &Option<ShotOrbit>| Settled {
            periods: done,
            state: state.clone(),
            ending,
            convergence: fit,
            fit_period,
            shot: None,
            rejected: rejected.clone(),
        };
        if samples >= needed {
            let tail = &history[(samples - needed) * n..];
            let scale = amplitude(tail);
            match detect_period(tail, n, &popts) {
                Ok(Periodicity::Periodic { period, .. }) => {
                    match contracting_divisor(&states, 2 * n, period, scale) {
                        // A slow spiral onto an orbit of period d: still settling.
                        Some((d, _)) => fit_period = d,
                        None => return Ok(end(SettleEnding::Repeated, last_fit, fit_period, &rejected)),
                    }
                }
                Ok(Periodicity::NonPeriodic { closest_period, .. }) => fit_period = closest_period,
                Err(_) => {}
            }
            // The fit reads every sample kept (the test's window or a block, and p more).
            let max_lag = popts.max_period.min(samples / 3).max(1);
            (fit_period, last_fit) = converging_lag(&states, 2 * n, max_lag, scale, fit_period);
            if let Some(fit) = last_fit.filter(Convergence::converging) {
                let more = fit.samples_needed(options.period_tolerance).unwrap_or(0.0);
                if auto.shoot && shots < MAX_SHOTS && more > block as f64 {
                    shots += 1;
                    let shot = Shot {
                        params,
                        sim_options,
                        scale,
                        tolerance: options.period_tolerance,
                        cancel: &options.cancel,
                    };
                    let budget = auto.cap_periods.saturating_sub(done);
                    match shot
                        .try_orbit(&state, fit_period, &fit, budget)
                        .map_err(|e| e.after(done))?
                    {
                        Verdict::Confirmed(orbit, residual) => {
                            return Ok(Settled {
                                shot: Some((orbit.period, residual)),
                                state: orbit.state,
                                ..end(SettleEnding::Shot, last_fit, fit_period, &rejected)
                            });
                        }
                        Verdict::Elsewhere(orbit) => rejected = Some(orbit),
                        Verdict::Unknown => {}
                    }
                }
            } else if done >= options.transient_periods {
                return Ok(end(SettleEnding::Irregular, last_fit, fit_period, &rejected));
            }
        }
        if done >= auto.cap_periods {
            return Ok(end(SettleEnding::Cap, last_fit, fit_period, &rejected));
        }
    }
}

/// What Newton shooting and the run's own continuation say about an orbit.
enum Verdict {
    /// A stable orbit the run approaches at the predicted rate, with its minimal period and
    /// its Newton residual.
    Confirmed(ShotOrbit, f64),
    /// A stable orbit the run, simulated on, does not approach.
    Elsewhere(ShotOrbit),
    /// No stable orbit near the run, or none that could be checked within the cap.
    Unknown,
}

/// The settings a shot needs: the chain, the simulator's options, the amplitude the
/// distances are measured against, the period tolerance and the hook that stops it.
pub(super) struct Shot<'a> {
    pub(super) params: &'a ChainParams,
    pub(super) sim_options: &'a SimOptions,
    pub(super) scale: f64,
    pub(super) tolerance: f64,
    pub(super) cancel: &'a Cancel,
}

impl Shot<'_> {
    /// Seeks the stable periodic orbit of period `p` near `state` within the geometric tail
    /// of `fit` (see the module docs), then checks that `state`, simulated on for at most
    /// `budget` periods, approaches it at the rate of its multipliers.
    fn try_orbit(
        &self,
        state: &ChainState,
        p: usize,
        fit: &Convergence,
        budget: u64,
    ) -> Result<Verdict, PointError> {
        let Some(orbit) = self.shoot(state, p as u32)? else {
            return Ok(Verdict::Unknown);
        };
        let q = fit.rate().powi(p as i32);
        if self.distance(state, &orbit.state) > 4.0 * fit.distance / (1.0 - q) {
            return Ok(Verdict::Unknown);
        }
        Ok(match self.approaches(state, &orbit, budget)? {
            None => Verdict::Unknown,
            Some(true) => Verdict::Confirmed(self.minimal(&orbit)?, orbit.residual),
            Some(false) => Verdict::Elsewhere(self.minimal(&orbit)?),
        })
    }

    /// The periodic orbit of period `p` that Newton shooting from `state` converges to within
    /// [`SHOT_ITERATIONS`] (`None` where it does not); a stop asked meanwhile is
    /// [`PointError::Stopped`].
    pub(super) fn shoot(&self, state: &ChainState, p: u32) -> Result<Option<PeriodicOrbit>, PointError> {
        let found = find_periodic_orbit(
            self.params,
            state,
            p,
            &ShootingOptions {
                sim: self.sim_options.clone(),
                max_iterations: SHOT_ITERATIONS,
                min_damping: SHOT_MIN_DAMPING,
                cancel: self.cancel.clone(),
                ..ShootingOptions::default()
            },
        );
        if self.cancel.requested() {
            return Err(PointError::Stopped { periods: 0 });
        }
        Ok(found.ok())
    }

    /// Whether `state`, simulated on, approaches the stable `orbit` at the rate of its
    /// multipliers: over K orbit periods, K the smallest count over which the largest
    /// multiplier modulus ρ predicts a fourfold shrink (ρ^K ≤ 1/4), its distance to the orbit
    /// (in the section states the fit reads) must shrink to 2·ρ^K of what it was (or below
    /// a hundredth of the period tolerance). `None` for an orbit that is not stable, or where
    /// the check would take more than `budget` periods.
    pub(super) fn approaches(
        &self,
        state: &ChainState,
        orbit: &PeriodicOrbit,
        budget: u64,
    ) -> Result<Option<bool>, PointError> {
        let rho = orbit.spectral_radius();
        if !orbit.stable || rho.is_nan() || rho <= 0.0 {
            return Ok(None);
        }
        let k = ((0.25f64).ln() / rho.ln()).ceil().max(1.0);
        let periods = k * f64::from(orbit.period);
        if periods > budget as f64 {
            return Ok(None);
        }
        let ends = self.run_states(state, periods as u64)?;
        let Some(last) = ends.last() else {
            return Ok(None);
        };
        let (start, end) = (
            self.distance(state, &orbit.state),
            self.distance(last, &orbit.state),
        );
        Ok(Some(
            end <= (2.0 * rho.powf(k) * start).max(0.01 * self.tolerance),
        ))
    }

    /// The orbit at its minimal period: the smallest divisor d of its period whose d-period
    /// return `φ_d(z)` is within the period tolerance of z (relative to the amplitude), its
    /// multiplier modulus taken over d periods.
    pub(super) fn minimal(&self, orbit: &PeriodicOrbit) -> Result<ShotOrbit, PointError> {
        let p = orbit.period;
        let returns = self.run_states(&orbit.state, u64::from(p))?;
        let d = (1..p)
            .filter(|d| p.is_multiple_of(*d))
            .find(|&d| {
                let r = &returns[d as usize - 1];
                let worst = r
                    .positions
                    .iter()
                    .zip(&orbit.state.positions)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                worst / self.scale <= self.tolerance
            })
            .unwrap_or(p);
        Ok(ShotOrbit {
            period: d,
            spectral_radius: orbit.spectral_radius().powf(f64::from(d) / f64::from(p)),
            state: orbit.state.clone(),
        })
    }

    /// The states of a run from `state` at the ends of its first `periods` excitation periods.
    fn run_states(&self, state: &ChainState, periods: u64) -> Result<Vec<ChainState>, PointError> {
        let n = self.params.len();
        let (s, _) = strobe_run(self.params, self.sim_options, state, periods, self.cancel)?;
        Ok(s.positions
            .chunks_exact(n)
            .zip(s.velocities.chunks_exact(n))
            .map(|(x, v)| ChainState {
                positions: x.to_vec(),
                velocities: v.to_vec(),
            })
            .collect())
    }

    /// Distance between two states in the section states the fit reads (positions and
    /// velocities over each mass's natural frequency), relative to the amplitude.
    fn distance(&self, a: &ChainState, b: &ChainState) -> f64 {
        let sa: Vec<f64> = section_states(&a.positions, &a.velocities, self.params).collect();
        let sb: Vec<f64> = section_states(&b.positions, &b.velocities, self.params).collect();
        sa.iter()
            .zip(&sb)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
            / self.scale
    }
}
