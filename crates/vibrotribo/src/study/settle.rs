//! Adaptive settling of a sweep point: run in blocks until the stroboscopic returns repeat,
//! finishing a geometric approach to a periodic orbit off by Newton shooting.
//!
//! After each block of excitation periods (mechanics only), the trailing stroboscopic
//! positions are tested for a period exactly as the recorded window will be
//! ([`PointOptions::period_options`]). If they repeat, the motion has settled. If not, the
//! return distances at the closest candidate period p are fitted by a geometric decay
//! ([`fit_convergence`]); where they shrink beyond doubt and would need more than another
//! block to reach the tolerance, the periodic orbit of period p is sought by Newton shooting
//! from the current state ([`find_periodic_orbit`]) and accepted only if it is stable and the
//! current state is within the distance the geometric tail still has to travel (four times
//! `d/(1 − r^p)`): the run is then continued from the orbit. Distances that do not shrink
//! end the settling once the fixed transient (`transient_periods`) has passed, so an
//! irregular motion costs no more than before; the cap ends it otherwise.

use super::observer::Mechanics;
use super::point::{PointError, PointOptions};
use super::settings::RunSpec;
use super::simulate::{Ending, StudyError, simulate};
use crate::analysis::{
    Convergence, Periodicity, StroboscopicOptions, StroboscopicSection, amplitude, converging_lag,
    detect_period,
};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::orbits::{ShootingOptions, find_periodic_orbit};

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
}

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
            cap_periods: 2000,
            block: 50,
            shoot: true,
        }
    }
}

/// How the settling before a recorded window ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SettleEnding {
    /// A fixed transient ([`SettleMode::Fixed`]).
    Fixed,
    /// The returns repeated within the period tolerance.
    Repeated,
    /// Newton shooting finished a geometric approach to a stable periodic orbit.
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
    /// After [`SettleEnding::Shot`]: the orbit's period and Newton residual.
    pub shot: Option<(u32, f64)>,
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

/// At most this many Newton attempts per point.
const MAX_SHOTS: u32 = 3;

/// Settles `params` from `initial` (see the module docs of `study/settle.rs`): runs `sim_options`'
/// mechanics in blocks until the period test of `options` passes on the trailing returns,
/// Newton shooting finishes a geometric approach, the returns prove irregular after
/// `options.transient_periods`, or `auto.cap_periods` is reached.
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
    loop {
        let len = if done == 0 {
            block.max(needed as u64)
        } else {
            block
        }
        .min(auto.cap_periods.saturating_sub(done))
        .max(1);
        let mut spec = RunSpec::new(params.clone(), len);
        spec.initial = state.clone();
        spec.options = sim_options.clone();
        spec.transient_periods = 0;
        let strobe = StroboscopicSection::new(
            n,
            params.period(),
            StroboscopicOptions {
                phase_time: 0.0,
                transient_periods: 1,
            },
        )
        .expect("valid stroboscopic options");
        let mut watch = Mechanics::new(strobe);
        let outcome = simulate(&spec, &mut watch)?;
        match outcome.ending {
            Ending::Failed(StudyError::Sim(e)) => return Err(e.into()),
            Ending::Failed(e) => return Err(PointError::Study(e)),
            Ending::Completed | Ending::Stopped => {}
        }
        done += len;
        state = outcome.final_state;
        history.extend_from_slice(&watch.inner.positions);
        states.extend(section_states(
            &watch.inner.positions,
            &watch.inner.velocities,
            params,
        ));
        let keep = needed.max(block as usize) + popts.max_period;
        if history.len() > keep * n {
            history.drain(..history.len() - keep * n);
            states.drain(..states.len() - keep * 2 * n);
        }
        let samples = history.len() / n;
        let end = |ending, fit, fit_period| Settled {
            periods: done,
            state: state.clone(),
            ending,
            convergence: fit,
            fit_period,
            shot: None,
        };
        if samples >= needed {
            let tail = &history[(samples - needed) * n..];
            match detect_period(tail, n, &popts) {
                Ok(Periodicity::Periodic { .. }) => {
                    return Ok(end(SettleEnding::Repeated, last_fit, fit_period));
                }
                Ok(Periodicity::NonPeriodic { closest_period, .. }) => fit_period = closest_period,
                Err(_) => {}
            }
            // The fit reads every sample kept (the test's window or a block, and p more).
            let scale = amplitude(tail);
            let max_lag = popts.max_period.min(samples / 3).max(1);
            (fit_period, last_fit) = converging_lag(&states, 2 * n, max_lag, scale, fit_period);
            if let Some(fit) = last_fit.filter(Convergence::converging) {
                let more = fit.samples_needed(options.period_tolerance).unwrap_or(0.0);
                if auto.shoot && shots < MAX_SHOTS && more > block as f64 {
                    shots += 1;
                    if let Some(s) = shoot(params, &state, sim_options, fit_period, &fit, scale) {
                        return Ok(Settled {
                            state: s.0,
                            shot: Some((fit_period as u32, s.1)),
                            ..end(SettleEnding::Shot, last_fit, fit_period)
                        });
                    }
                }
            } else if done >= options.transient_periods {
                return Ok(end(SettleEnding::Irregular, last_fit, fit_period));
            }
        }
        if done >= auto.cap_periods {
            return Ok(end(SettleEnding::Cap, last_fit, fit_period));
        }
    }
}

/// The stable periodic orbit of period `p` near `state`, if Newton shooting finds one and
/// `state` lies within the geometric tail of `fit` from it (positions relative to `scale`):
/// its state and Newton residual.
fn shoot(
    params: &ChainParams,
    state: &ChainState,
    sim_options: &SimOptions,
    p: usize,
    fit: &Convergence,
    scale: f64,
) -> Option<(ChainState, f64)> {
    let orbit = find_periodic_orbit(
        params,
        state,
        p as u32,
        &ShootingOptions {
            sim: sim_options.clone(),
            ..ShootingOptions::default()
        },
    )
    .ok()?;
    let q = fit.rate().powi(p as i32);
    let distance = state
        .positions
        .iter()
        .zip(&orbit.state.positions)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale;
    (orbit.stable && distance <= 4.0 * fit.distance / (1.0 - q)).then_some((orbit.state, orbit.residual))
}
