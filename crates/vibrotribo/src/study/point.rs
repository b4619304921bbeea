//! One point of a parameter sweep: a run after its transient, condensed into what bifurcation
//! diagrams, impact-velocity diagrams and power curves need (seed Figs. 7, 12, 14, 17, 18,
//! 20, 21).
//!
//! [`run_point`] simulates a chain from a given state for `transient + recorded` excitation
//! periods and returns the stroboscopic samples of every mass at `t = nT` after the transient
//! (the orbit diagram), every impact after the transient with its closing speed (the paper's
//! "bifurcation diagram of V12 / V23"), impacts per period per contact, the detected period,
//! whether chatter, sticking or grazing occurred, the average power of a harvester if one is
//! given, and the final state (for continuation to the next parameter value).

use std::sync::Arc;

use thiserror::Error;

use super::floquet::{FloquetError, floquet};
use super::motion::{Motion, MotionReport, WARMUP as MOTION_WARMUP, Window, classify};
use super::observer::{Checkpoint, Mechanics, RunObserver};
use super::settings::{ElectricalFailure, Harvester, RunSettings, RunSpec};
use super::settle::{AutoSettle, SettleEnding, SettleMode, settle};
use super::simulate::{Ending, StudyError, simulate};
use crate::analysis::{PeriodOptions, Periodicity, StroboscopicOptions, StroboscopicSection, detect_period};
use crate::dynamics::{Event, EventKind, Observer, StateView};
use crate::electrical::{ChargeOptions, ElectricalError, HarvesterParams};
use crate::error::SimError;
use crate::excitation::{BaseMotion, BaseMotionError};
use crate::lyapunov::{LyapunovError, LyapunovObserver, LyapunovOptions, LyapunovSpectrum};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::orbits::Cancel;

/// The default of [`PointOptions::period_tolerance`], 1e-4 (relative).
pub const DEFAULT_PERIOD_TOLERANCE: f64 = 1e-4;

/// Settings of [`run_point`].
#[derive(Debug, Clone, PartialEq)]
pub struct PointOptions {
    /// Periods simulated before anything is recorded. Default 300.
    pub transient_periods: u64,
    /// Periods recorded after the transient. Default 100.
    pub recorded_periods: u64,
    /// Relative tolerance of the period detection ([`PeriodOptions::tolerance`]).
    /// Default 1e-4.
    pub period_tolerance: f64,
    /// An impact slower than this fraction of the base's peak speed A·ω, that is not a bounce
    /// of a chatter sequence (its closing speed is below half the previous rebound speed at
    /// that contact, or it is the first impact there), counts as grazing. Default 1e-3.
    pub grazing_ratio: f64,
    /// Periods before the recorded window at which the charge solver starts from the
    /// electrostatic equilibrium (the circuit forgets its initial charge within a few R·C,
    /// far less than this for all but extreme loads). Default 20.
    pub electrical_warmup_periods: u64,
    /// Also find the periodic orbit of the detected period by shooting from the final state
    /// and report its largest Floquet multiplier modulus
    /// ([`PointResult::max_abs_multiplier`]). Default false.
    pub floquet: bool,
    /// Also compute the Lyapunov spectrum over the recorded periods (the tangent vectors
    /// align during the transient; [`PointResult::lyapunov`]). Default `None`.
    pub lyapunov: Option<LyapunovOptions>,
    /// How long to run before the recorded window: a fixed transient, or until the motion
    /// repeats ([`SettleMode`]). Default [`SettleMode::Fixed`].
    pub settle: SettleMode,
    /// Also classify the motion of the recorded window ([`PointResult::motion`]; may run a
    /// Lyapunov spectrum for a point that is neither periodic nor settling). Default false.
    pub classify: bool,
    /// Polled at every period of the point's runs (the settling, the recorded window, the
    /// classification's Lyapunov run) and at every Newton iteration of its shots: when it
    /// asks, the point stops with [`PointError::Stopped`]. Default: never.
    pub cancel: Cancel,
}

impl Default for PointOptions {
    fn default() -> Self {
        PointOptions {
            transient_periods: 300,
            recorded_periods: 100,
            period_tolerance: DEFAULT_PERIOD_TOLERANCE,
            grazing_ratio: 1e-3,
            electrical_warmup_periods: 20,
            floquet: false,
            lyapunov: None,
            settle: SettleMode::Fixed,
            classify: false,
            cancel: Cancel::never(),
        }
    }
}

impl PointOptions {
    /// The options of the sweep points of a configuration whose `[run]` table is `run`:
    /// `transient` periods before recording (default: `run.transient_periods`) and
    /// `recorded` periods (default: the rest of `run.periods`), the rest at their defaults.
    pub fn from_run(run: &RunSettings, transient: Option<u64>, recorded: Option<u64>) -> Self {
        PointOptions {
            transient_periods: transient.unwrap_or(run.transient()),
            recorded_periods: recorded.unwrap_or(run.periods - run.transient()),
            ..PointOptions::default()
        }
    }

    /// The period-detection settings for `recorded_periods` samples: periods up to
    /// min(64, recorded/2), each checked over the rest of the window.
    pub fn period_options(&self) -> PeriodOptions {
        let recorded = self.recorded_periods.max(2) as usize;
        let max_period = 64.min(recorded / 2).max(1);
        let repeats = (recorded / max_period).saturating_sub(1).max(1);
        PeriodOptions {
            max_period,
            tolerance: self.period_tolerance,
            repeats,
            scale: None,
        }
    }
}

/// One impact after the transient.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactRecord {
    /// Time from the start of the point's run, s.
    pub time: f64,
    /// Contact, 0-based.
    pub contact: usize,
    /// Closing speed just before the impact, m/s.
    pub closing_speed: f64,
}

/// What one sweep point found.
#[derive(Debug, Clone, PartialEq)]
pub struct PointResult {
    /// Period indices n of the stroboscopic samples (t = nT), after the transient.
    pub strobe_periods: Vec<u64>,
    /// Positions at those times, m, flattened (`strobe[j·N + i]`).
    pub strobe: Vec<f64>,
    /// Velocities at those times, m/s, flattened like [`strobe`](Self::strobe).
    pub strobe_velocities: Vec<f64>,
    /// Impacts after the transient.
    pub impacts: Vec<ImpactRecord>,
    /// Mean impacts per period after the transient, per contact.
    pub impacts_per_period: Vec<f64>,
    /// The detected period of the stroboscopic positions (`None` if too few samples).
    pub periodicity: Option<Periodicity>,
    /// Whether a chatter sequence ended in an accumulation-point jump after the transient.
    pub chatter: bool,
    /// Whether any contact stuck after the transient.
    pub sticking: bool,
    /// Whether a grazing impact occurred after the transient (see
    /// [`PointOptions::grazing_ratio`]).
    pub grazing: bool,
    /// Average power after the transient (seed eq. 14), W, if a harvester was given and its
    /// charge solver succeeded.
    pub average_power_w: Option<f64>,
    /// Why the charge solver failed, if it did (the mechanics is still reported).
    pub electrical_error: Option<ElectricalError>,
    /// State at the end of the run (t = (transient + recorded)·T).
    pub final_state: ChainState,
    /// With [`PointOptions::floquet`] and a detected period: the largest modulus of the
    /// Floquet multipliers of the periodic orbit of that period found by shooting from the
    /// final state, where that orbit is the window's own (`Err` with the reason where
    /// shooting failed, e.g. at a grazing point, or converged to an orbit the run is not on;
    /// see the module docs of `study/floquet.rs`).
    pub max_abs_multiplier: Option<Result<f64, FloquetError>>,
    /// The Lyapunov spectrum over the recorded periods, if [`PointOptions::lyapunov`] asked
    /// for it.
    pub lyapunov: Option<Result<LyapunovSpectrum, LyapunovError>>,
    /// Batch-means standard error of [`average_power_w`](Self::average_power_w), W: the
    /// per-period powers of the recorded window in 10 consecutive batches
    /// ([`batch_means_se`](crate::analysis::batch_means_se)); about 0 for a periodic motion, the sampling error of a
    /// non-periodic one.
    pub average_power_se_w: Option<f64>,
    /// The motion of the recorded window, with [`PointOptions::classify`].
    pub motion: Option<MotionReport>,
}

impl PointResult {
    /// Detected period in excitation periods, 0 if non-periodic (or undetermined).
    pub fn period(&self) -> usize {
        self.periodicity.and_then(|p| p.period()).unwrap_or(0)
    }

    /// Total impacts per period after the transient.
    pub fn total_impacts_per_period(&self) -> f64 {
        self.impacts_per_period.iter().sum()
    }

    /// The stroboscopic positions x_i, m, of mass `i` (0-based), one per entry of
    /// [`strobe_periods`](Self::strobe_periods); empty if `i` is not a mass of the chain.
    pub fn position_series(&self, i: usize) -> impl Iterator<Item = f64> + '_ {
        let n = self.strobe.len() / self.strobe_periods.len().max(1);
        self.strobe
            .chunks_exact(n.max(1))
            .filter_map(move |x| x.get(i).copied())
    }
}

/// A sweep point failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum PointError {
    /// The mechanics stopped.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The run could not be set up (or failed otherwise).
    #[error(transparent)]
    Study(#[from] StudyError),
    /// The stroboscopic section could not be set up (a chain without masses, a period that
    /// is not positive and finite).
    #[error(transparent)]
    Analysis(#[from] crate::analysis::AnalysisError),
    /// [`PointOptions::cancel`] asked the point to stop; nothing of it is kept.
    #[error("stopped after {periods} periods")]
    Stopped {
        /// Excitation periods the point had run (settling and recorded window).
        periods: u64,
    },
}

impl PointError {
    /// This error, with `periods` more counted in a [`Stopped`](Self::Stopped) one (the
    /// periods run before the part that stopped).
    pub(super) fn after(self, periods: u64) -> Self {
        match self {
            PointError::Stopped { periods: p } => PointError::Stopped { periods: p + periods },
            e => e,
        }
    }
}

/// Records impacts after the transient and flags grazing.
struct Impacts {
    after: f64,
    grazing_speed: f64,
    last_rebound: Vec<f64>,
    records: Vec<ImpactRecord>,
    grazing: bool,
}

impl Observer for Impacts {
    fn event(&mut self, event: &Event, _state: &StateView<'_>) {
        if event.kind != EventKind::Impact {
            if matches!(
                event.kind,
                EventKind::Stick | EventKind::Release | EventKind::Chatter
            ) {
                self.last_rebound[event.contact] = 0.0;
            }
            return;
        }
        let k = event.contact;
        let v = event.velocity_before;
        if event.time >= self.after {
            self.records.push(ImpactRecord {
                time: event.time,
                contact: k,
                closing_speed: v,
            });
            let chatter_bounce = self.last_rebound[k] > 0.0 && v >= 0.5 * self.last_rebound[k];
            if v < self.grazing_speed && !chatter_bounce {
                self.grazing = true;
            }
        }
        self.last_rebound[k] = event.velocity_after;
    }
}

impl RunObserver for Impacts {
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        Observer::event(self, event, state);
    }
}

/// Runs one sweep point: `params` from `initial` for `transient + recorded` periods (see the
/// module docs), or with [`SettleMode::Auto`] until the motion repeats and then `recorded`
/// periods (after [`electrical_warmup_periods`](PointOptions::electrical_warmup_periods)
/// more; period indices and impact times still count from `initial`). With `harvester`, the
/// charge solver starts `electrical_warmup_periods` before the recorded window and the
/// average power over the recorded periods is reported; a failure of the charge solver is
/// reported beside the motion, which goes on. With [`PointOptions::classify`] the motion is
/// classified ([`PointResult::motion`]).
pub fn run_point(
    params: &ChainParams,
    initial: &ChainState,
    sim_options: &SimOptions,
    harvester: Option<(&HarvesterParams, &ChargeOptions)>,
    options: &PointOptions,
) -> Result<PointResult, PointError> {
    let auto = match &options.settle {
        SettleMode::Fixed => {
            let mut r = record(
                params,
                initial,
                sim_options,
                harvester,
                options,
                (options.transient_periods, 0),
                (options.lyapunov.as_ref(), None),
            )?;
            if options.classify {
                let spectrum = r.lyapunov.as_ref().and_then(|s| s.as_ref().ok());
                r.motion = Some(classify(
                    params,
                    sim_options,
                    options,
                    Window {
                        coupled: two_way(harvester),
                        ..Window::of(&r)
                    },
                    None,
                    spectrum,
                    &crate::excitation::WorkBudget::default(),
                ));
                no_period_while_settling(&mut r);
            }
            return finish(params, sim_options, options, r);
        }
        SettleMode::Auto(a) => a,
    };
    let warmup = options.electrical_warmup_periods.max(MOTION_WARMUP);
    let mut start = initial.clone();
    let mut before = 0u64;
    let mut round = 0;
    loop {
        // A later round settles from where the previous window ended, within what is left
        // of the cap.
        let this = PointOptions {
            transient_periods: options.transient_periods.saturating_sub(before),
            ..options.clone()
        };
        let left = AutoSettle {
            cap_periods: auto.cap_periods.saturating_sub(before).max(1),
            ..*auto
        };
        let mut settled = settle(params, &start, sim_options, &this, &left).map_err(|e| e.after(before))?;
        settled.periods += before;
        // A motion the settling found irregular will need its Lyapunov exponent: take it
        // over the recorded window itself, the warm-up aligning the tangent vectors.
        let irregular = settled.ending == SettleEnding::Irregular
            || (settled.ending == SettleEnding::Cap && !settled.convergence.is_some_and(|c| c.converging()));
        let own = LyapunovOptions::default();
        let lyapunov = options
            .lyapunov
            .as_ref()
            .or((options.classify && irregular).then_some(&own));
        let mut r = record(
            params,
            &settled.state,
            sim_options,
            harvester,
            options,
            (warmup, settled.periods),
            (lyapunov, None),
        )?;
        if options.classify {
            let spectrum = r.lyapunov.as_ref().and_then(|s| s.as_ref().ok());
            r.motion = Some(classify(
                params,
                sim_options,
                options,
                Window {
                    coupled: two_way(harvester),
                    ..Window::of(&r)
                },
                Some(&settled),
                spectrum,
                &crate::excitation::WorkBudget::default(),
            ));
            no_period_while_settling(&mut r);
        }
        if options.lyapunov.is_none() {
            r.lyapunov = None;
        }
        // The settling gave up on returns that did not shrink, but the window converges (a
        // transient that looked irregular): settle again from the window's end.
        let end = settled.periods + warmup + options.recorded_periods;
        let again = settled.ending == SettleEnding::Irregular
            && r.motion.as_ref().is_some_and(|m| m.motion == Motion::Settling)
            && round < MAX_ROUNDS
            && end < auto.cap_periods;
        if !again {
            return finish(params, sim_options, options, r);
        }
        round += 1;
        before = end;
        start = r.final_state;
    }
}

/// The end of a point: with [`PointOptions::floquet`] its orbit's largest multiplier
/// modulus, and a stable orbit the shots found that the run is not on as the motion's
/// coexisting orbit (where the settling found none); a stop asked meanwhile discards it.
fn finish(
    params: &ChainParams,
    sim_options: &SimOptions,
    options: &PointOptions,
    mut r: PointResult,
) -> Result<PointResult, PointError> {
    let periods = r.strobe_periods.last().copied().unwrap_or(0);
    let stopped = || PointError::Stopped { periods };
    if options.floquet {
        // A window settling onto an orbit is not searched: the shots would find that orbit.
        let search = r.motion.as_ref().is_none_or(|m| m.motion != Motion::Settling);
        let f = floquet(params, sim_options, options, &r, search).map_err(|_| stopped())?;
        r.max_abs_multiplier = f.max_abs_multiplier;
        if let (Some(m), Some(o)) = (r.motion.as_mut(), f.coexisting)
            && m.coexisting.is_none()
        {
            m.coexisting = Some((o.period, o.spectral_radius));
        }
    }
    if options.cancel.requested() {
        return Err(stopped());
    }
    Ok(r)
}

/// Whether `harvester`'s forces act on the masses (two-way coupling).
fn two_way(harvester: Option<(&HarvesterParams, &ChargeOptions)>) -> bool {
    harvester.is_some_and(|(h, _)| h.coupling == crate::coupling::Coupling::TwoWay)
}

/// A window the period test passed at p but whose returns at a divisor of p still shrink
/// (a slow spiral, classified settling) has no period: the match at p is the window's
/// artefact, not the orbit's period.
fn no_period_while_settling(r: &mut PointResult) {
    if let (Some(m), Some(Periodicity::Periodic { .. })) = (&r.motion, r.periodicity)
        && m.motion == Motion::Settling
    {
        r.periodicity = Some(Periodicity::NonPeriodic {
            closest_period: m.residual_period,
            mismatch: m.residual,
        });
    }
}

/// [`run_point`] under the base motion `base` (`None`: the chain's harmonic). A base motion
/// that is not periodic with the reference period runs `transient + recorded` periods
/// ([`SettleMode::Fixed`] whatever `options.settle` says: there is no periodic motion to
/// settle to), is not classified and has no period; Floquet multipliers and Lyapunov
/// exponents are refused (they need a periodic map), naming the reason.
pub fn run_point_driven(
    params: &ChainParams,
    initial: &ChainState,
    sim_options: &SimOptions,
    harvester: Option<(&HarvesterParams, &ChargeOptions)>,
    options: &PointOptions,
    base: Option<&Arc<BaseMotion>>,
) -> Result<PointResult, PointError> {
    let Some(base) = base else {
        return run_point(params, initial, sim_options, harvester, options);
    };
    if let BaseMotion::Harmonics(h) = &**base
        && let Some(a) = crate::dynamics::as_chain_harmonic(h, params)
    {
        let mut chain = params.clone();
        chain.excitation.amplitude = a;
        return run_point(&chain, initial, sim_options, harvester, options);
    }
    let refuse = |what: &'static str| {
        Err(PointError::Study(StudyError::BaseMotion(
            BaseMotionError::NotPeriodic {
                what,
                kind: base.kind().as_str(),
            },
        )))
    };
    if options.floquet {
        return refuse("Floquet multipliers");
    }
    if options.lyapunov.is_some() {
        return refuse("Lyapunov exponents");
    }
    record(
        params,
        initial,
        sim_options,
        harvester,
        options,
        (options.transient_periods, 0),
        (None, Some(base)),
    )
}

/// Settling rounds after the first ([`run_point`] with [`SettleMode::Auto`]).
const MAX_ROUNDS: u32 = 3;

/// Runs `params` from `initial` for `transient + recorded` periods and condenses the
/// recorded ones, with `lyapunov` the spectrum over them (under `base`, the base motion, when
/// given); `offset` periods ran before
/// `initial` (added to the period indices and impact times).
fn record(
    params: &ChainParams,
    initial: &ChainState,
    sim_options: &SimOptions,
    harvester: Option<(&HarvesterParams, &ChargeOptions)>,
    options: &PointOptions,
    (transient, offset): (u64, u64),
    (lyapunov, base): (Option<&LyapunovOptions>, Option<&Arc<BaseMotion>>),
) -> Result<PointResult, PointError> {
    let n = params.len();
    let period = params.period();
    let total = transient + options.recorded_periods;
    let warmup = options.electrical_warmup_periods.min(transient);
    let spec = RunSpec {
        chain: params.clone(),
        initial: initial.clone(),
        options: sim_options.clone(),
        harvester: harvester.map(|(h, o)| Harvester {
            params: h.clone(),
            options: o.clone(),
            start_period: transient - warmup,
            on_failure: ElectricalFailure::KeepMechanics,
        }),
        periods: total,
        transient_periods: transient,
        sampling: None,
        breakdown_check: false,
        base_motion: base.cloned(),
    };
    let strobe = StroboscopicSection::new(
        n,
        period,
        StroboscopicOptions {
            phase_time: 0.0,
            transient_periods: transient + 1,
        },
    )?;
    let lyapunov = match lyapunov {
        Some(o) => Some(LyapunovObserver::new(params, transient, o).map_err(StudyError::from)?),
        None => None,
    };
    let mut watch = (
        (
            Mechanics::new(strobe),
            Checkpoint {
                stop: |_| options.cancel.requested(),
            },
        ),
        (
            Mechanics::new(lyapunov),
            Impacts {
                after: transient as f64 * period,
                grazing_speed: options.grazing_ratio * params.excitation.amplitude * params.omega(),
                last_rebound: vec![0.0; params.contact_count()],
                records: Vec::new(),
                grazing: false,
            },
        ),
    );
    let outcome = simulate(&spec, &mut watch)?;
    match outcome.ending {
        Ending::Failed(StudyError::Sim(e)) => return Err(e.into()),
        Ending::Failed(e) => return Err(PointError::Study(e)),
        Ending::Stopped => {
            return Err(PointError::Stopped {
                periods: offset + outcome.periods,
            });
        }
        Ending::Completed => {}
    }
    let (strobe, (lyapunov, impacts)) = (watch.0.0.inner, (watch.1.0.inner, watch.1.1));
    let average_power_se_w = outcome
        .electrical
        .as_ref()
        .and_then(|e| e.average_power_se(transient));
    let (average_power_w, electrical_error) = match &outcome.electrical {
        Some(e) => match &e.power {
            Some(p) if e.solver_error.is_none() => (Some(p.average_power_w), None),
            _ => (None, e.solver_error.clone()),
        },
        None => (None, None),
    };
    let popts = options.period_options();
    // Under a base motion that is not periodic there is no period to detect.
    let periodicity = if base.is_none() && strobe.len() >= popts.samples_needed() {
        detect_period(&strobe.positions, n, &popts).ok()
    } else {
        None
    };
    let stats = &outcome.stats;
    let grazing = impacts.grazing;
    let mut impacts = impacts.records;
    let mut strobe_periods = strobe.indices;
    if offset > 0 {
        let shift = offset as f64 * params.period();
        for i in &mut impacts {
            i.time += shift;
        }
        for j in &mut strobe_periods {
            *j += offset;
        }
    }
    Ok(PointResult {
        strobe_periods,
        strobe: strobe.positions,
        strobe_velocities: strobe.velocities,
        impacts_per_period: stats.impacts_per_period(total),
        impacts,
        periodicity,
        chatter: stats.chatter_sequences > 0,
        sticking: stats.sticks > 0,
        grazing,
        average_power_w,
        electrical_error,
        final_state: outcome.final_state,
        max_abs_multiplier: None,
        lyapunov: lyapunov.map(LyapunovObserver::finish),
        average_power_se_w,
        motion: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Simulator, Trajectory};

    /// Each mass's stroboscopic series is its position at t = nT, n = strobe_periods, read
    /// from a separately recorded trajectory of the same run.
    #[test]
    fn position_series_are_the_positions_at_the_strobe_times() {
        let params = ChainParams::default();
        let options = PointOptions {
            transient_periods: 5,
            recorded_periods: 6,
            ..PointOptions::default()
        };
        let initial = ChainState::at_rest(3);
        let point = run_point(&params, &initial, &SimOptions::default(), None, &options).unwrap();
        let mut sim = Simulator::new(&params, &initial, SimOptions::default()).unwrap();
        let mut traj = Trajectory::new(&sim);
        sim.run_until(11.0 * params.period(), &mut traj).unwrap();
        assert_eq!(point.strobe_periods.len(), 6);
        let (mut x, mut v) = (vec![0.0; 3], vec![0.0; 3]);
        for i in 0..3 {
            let series: Vec<f64> = point.position_series(i).collect();
            assert_eq!(series.len(), point.strobe_periods.len());
            for (&n, got) in point.strobe_periods.iter().zip(series) {
                assert!(traj.state_at(n as f64 * params.period(), &mut x, &mut v));
                assert!(
                    (got - x[i]).abs() < 1e-12,
                    "mass {i}, period {n}: {got} vs {}",
                    x[i]
                );
            }
        }
        assert_eq!(point.position_series(3).count(), 0);
    }
}
