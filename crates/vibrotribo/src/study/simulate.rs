//! [`simulate`]: one run of a chain and its harvester, the library's single entry point that
//! wires the event-driven mechanics, the charge solver, the statistics and the samples
//! together.

use std::ops::ControlFlow;

use thiserror::Error;

use super::observer::{ElectricalSample, RunObserver, Sample};
use super::settings::{ElectricalFailure, RunSpec, Sampling};
use crate::analysis::RunStats;
use crate::coupling::{ChargeHost, CoupledChain, Coupling, CouplingError, CouplingOptions, CouplingStats};
use crate::dynamics::{BaseDisplacement, driven_chain};
use crate::dynamics::{Event, Flow, Observer, RunEnd, Simulator, StateView, Verdict};
use crate::electrical::breakdown::BreakdownMargin;
use crate::electrical::{
    ChargeSolver, ElectricalError, ElectricalSamples, PeriodStats, PowerSummary, SolverStats, power_curve,
};
use crate::error::{ParamError, SimError};
use crate::excitation::BaseMotionError;
use crate::model::ChainState;

/// A run could not be carried out, or failed on the way.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum StudyError {
    /// The parameters are invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The mechanics stopped.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The charge solver stopped.
    #[error("charge solver: {0}")]
    Electrical(ElectricalError),
    /// The base motion cannot drive this run, or not this study (the combination and the
    /// reason named).
    #[error("base motion: {0}")]
    BaseMotion(BaseMotionError),
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// All the periods asked for were simulated.
    Completed,
    /// An observer stopped it at a period's end.
    Stopped,
    /// It failed; the results cover the periods before the failure.
    Failed(StudyError),
}

/// What the harvester delivered in a run.
#[derive(Debug, Clone, PartialEq)]
pub struct ElectricalOutcome {
    /// Per excitation period (from the harvester's start on).
    pub periods: Vec<PeriodStats>,
    /// Average power and related figures after the transient (`None` if no complete period
    /// after it).
    pub power: Option<PowerSummary>,
    /// The worst air-breakdown ratio after the transient (if checked).
    pub breakdown: Option<BreakdownMargin>,
    /// Storage capacitor voltage at the end, V (rectifier).
    pub storage_voltage: Option<f64>,
    /// Energy that left the transducer through its terminals since the charge solver started,
    /// J: ∫V·I dt
    /// ([`ChargeSolver::terminal_energy`](crate::electrical::ChargeSolver::terminal_energy));
    /// for the rectifier, the energy of `periods` plus the bridge's losses.
    pub terminal_energy_j: f64,
    /// First time the storage voltage reached the target, s (rectifier with a target).
    pub time_to_target: Option<f64>,
    /// The solver's work counters.
    pub solver: SolverStats,
    /// The coupled run's work counters (two-way coupling only).
    pub coupling: Option<CouplingStats>,
    /// The solver's failure, if it failed while the mechanics went on
    /// ([`ElectricalFailure::KeepMechanics`]).
    pub solver_error: Option<ElectricalError>,
    /// Excitation period, s.
    pub period: f64,
}

impl ElectricalOutcome {
    /// The running average power `P_a(N)`, W, N = 1, 2, … periods (seed eq. 14).
    pub fn power_curve(&self) -> Vec<f64> {
        power_curve(&self.periods, self.period)
    }

    /// The batch-means standard error of the average power over the complete periods from
    /// period `transient` on (counted from t = 0), W: their powers in 10 consecutive batches
    /// ([`batch_means_se`](crate::analysis::batch_means_se)). About 0 for a periodic motion;
    /// for a non-periodic one, the sampling error of the average over a finite window.
    pub fn average_power_se(&self, transient: u64) -> Option<f64> {
        let powers: Vec<f64> = self
            .periods
            .iter()
            .filter(|p| p.index >= transient as i64 && p.is_complete(self.period))
            .map(|p| p.energy_j / self.period)
            .collect();
        crate::analysis::batch_means_se(&powers, 10)
    }

    /// Average power and related figures over the complete periods after the first
    /// `transient` of the harvester's ([`summarize`](crate::electrical::summarize)).
    pub fn power_after(&self, transient: usize) -> Option<PowerSummary> {
        crate::electrical::summarize(&self.periods, self.period, transient)
    }
}

/// The results of [`simulate`].
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutcome {
    /// Complete excitation periods simulated.
    pub periods: u64,
    /// How the run ended.
    pub ending: Ending,
    /// Event statistics (impacts per period and contact, sticking, chatter, closing speeds).
    pub stats: RunStats,
    /// What the harvester delivered (with a harvester).
    pub electrical: Option<ElectricalOutcome>,
    /// State at the end, at `t = periods·T` (or where the run failed).
    pub final_state: ChainState,
    /// Time at the end, s.
    pub final_time: f64,
}

impl RunOutcome {
    /// The failure, if the run failed.
    pub fn failure(&self) -> Option<&StudyError> {
        match &self.ending {
            Ending::Failed(e) => Some(e),
            _ => None,
        }
    }
}

/// Runs `spec`: the chain from its initial state for `spec.periods` excitation periods, the
/// charge of its harvester solved alongside (from the harvester's start period on), event
/// statistics kept, and `observer` shown the flow, the events, the samples (if it wants
/// them) and every period's end, where it may stop the run.
///
/// Invalid parameters are an error; a failure on the way (an event limit, a charge solver
/// failure that [`ElectricalFailure::StopRun`] makes fatal) ends the run with
/// [`Ending::Failed`] and results for the periods before it.
///
/// ```
/// use vibrotribo::study::{RunSpec, simulate};
/// use vibrotribo::ChainParams;
///
/// let outcome = simulate(&RunSpec::new(ChainParams::default(), 20), &mut ())?;
/// assert_eq!(outcome.periods, 20);
/// assert!(outcome.stats.events > 0);
/// # Ok::<(), vibrotribo::study::StudyError>(())
/// ```
pub fn simulate<O: RunObserver + ?Sized>(spec: &RunSpec, observer: &mut O) -> Result<RunOutcome, StudyError> {
    let end = spec.periods as f64 * spec.chain.period();
    let sim = Simulator::driven(
        &spec.chain,
        &spec.initial,
        spec.options.clone(),
        spec.base_motion.as_ref(),
        end,
    )
    .map_err(StudyError::from_sim)?;
    let base = sim.base_displacement().cloned();
    let chain = driven_chain(&spec.chain, spec.base_motion.as_deref());
    let chain = &*chain;
    let period = chain.period();
    let transient_time = spec.transient_periods as f64 * period;
    let solver = match &spec.harvester {
        Some(h) => {
            let mut s = ChargeSolver::for_chain(&h.params, chain, h.options.clone())?;
            if spec.breakdown_check {
                s = s.with_breakdown_check(transient_time);
            }
            if observer.wants_samples() {
                s = match spec.sampling {
                    Some(Sampling::PerPeriod(per)) => s.with_periodic_sampling(per)?,
                    Some(Sampling::Uniform { start, step }) => s.with_sampling(start, step)?,
                    None => s,
                };
            }
            Some(s)
        }
        None => None,
    };
    let samples = match spec.sampling {
        Some(grid) if observer.wants_samples() => Some(SampleGrid {
            base,
            ..SampleGrid::new(grid, period, chain)
        }),
        _ => None,
    };
    let mut rec = Recorder {
        user: observer,
        stats: RunStats::new(chain.contact_count(), period, spec.transient_periods),
        solver,
        electrical_from: spec
            .harvester
            .as_ref()
            .map_or(0.0, |h| h.start_period as f64 * period),
        stop_on_electrical_failure: spec
            .harvester
            .as_ref()
            .is_some_and(|h| h.on_failure == ElectricalFailure::StopRun),
        samples,
        solver_driven: false,
        pending: ElectricalSamples::default(),
    };
    let mut done = 0;
    let mut ending = Ending::Completed;
    let two_way = spec
        .harvester
        .as_ref()
        .filter(|h| h.params.coupling == Coupling::TwoWay);
    let mut mechanics = Mechanics::Plain(Box::new(sim));
    for p in 1..=spec.periods {
        if let (Some(h), Mechanics::Plain(plain)) = (two_way, &mechanics)
            && plain.time() >= rec.electrical_from
        {
            // From the harvester's start on, the charges act on the masses.
            let options = CouplingOptions {
                position_tolerance: h.params.coupling_tolerance,
                ..CouplingOptions::default()
            };
            let coupled = match CoupledChain::new((**plain).clone(), &h.params, options) {
                Ok(c) => c,
                Err(e) => return Err(coupling_error(e)),
            };
            mechanics = Mechanics::Coupled(Box::new(coupled));
            rec.solver_driven = true;
        }
        match mechanics.run_until(p as f64 * period, &mut rec) {
            Ok(RunEnd::Reached) => {}
            Ok(RunEnd::Stopped { .. }) => {
                ending = Ending::Stopped;
                break;
            }
            Err(StudyError::Sim(SimError::Observer(message))) => {
                // The charge solver is the observer that stops a run; its own error says more
                // than the engine's message about it.
                ending = Ending::Failed(match rec.electrical_error() {
                    Some(e) => StudyError::Electrical(e),
                    None => StudyError::Sim(SimError::Observer(message)),
                });
                break;
            }
            Err(e) => {
                ending = Ending::Failed(e);
                break;
            }
        }
        done = p;
        let state = mechanics.state();
        let view = StateView {
            time: mechanics.time(),
            positions: &state.positions,
            velocities: &state.velocities,
        };
        if rec.user.period(p, &view).is_break() {
            if p < spec.periods {
                ending = Ending::Stopped;
            }
            break;
        }
    }
    let electrical = rec.solver.as_ref().map(|s| ElectricalOutcome {
        periods: s.periods().to_vec(),
        power: s.summary(
            spec.transient_periods
                .saturating_sub(spec.harvester.as_ref().map_or(0, |h| h.start_period)) as usize,
        ),
        breakdown: s.breakdown_margin().copied(),
        storage_voltage: s.storage_voltage(),
        terminal_energy_j: s.terminal_energy(),
        time_to_target: s.time_to_target(),
        solver: s.stats(),
        coupling: match &mechanics {
            Mechanics::Coupled(c) => Some(c.stats()),
            Mechanics::Plain(_) => None,
        },
        solver_error: s.status().err(),
        period,
    });
    Ok(RunOutcome {
        periods: done,
        ending,
        stats: rec.stats,
        electrical,
        final_state: mechanics.state(),
        final_time: mechanics.time(),
    })
}

/// The mechanical half of the samples: grid times inside each piece of flow.
struct SampleGrid {
    grid: Sampling,
    period: f64,
    next: u64,
    x: Vec<f64>,
    v: Vec<f64>,
    d: Vec<f64>,
    gaps: Vec<f64>,
    /// The base displacement when it is not the chain's harmonic.
    base: Option<BaseDisplacement>,
}

impl SampleGrid {
    fn new(grid: Sampling, period: f64, chain: &crate::ChainParams) -> Self {
        let n = chain.len();
        SampleGrid {
            grid,
            period,
            next: 0,
            x: vec![0.0; n],
            v: vec![0.0; n],
            d: vec![0.0; n - 1],
            gaps: chain.gaps.clone(),
            base: None,
        }
    }

    /// Time of sample j (the charge solver's grid uses the same formula).
    fn time(&self, j: u64) -> f64 {
        match self.grid {
            Sampling::PerPeriod(per) => 0.0 + self.period * (j as f64 / per as f64),
            Sampling::Uniform { start, step } => start + step * (j as f64 / 1.0),
        }
    }

    /// Emits the samples inside `flow` to `user`, the electrical ones taken from `electrical`
    /// (the charge solver's samples of the same grid, recorded for this flow).
    fn emit<O: RunObserver + ?Sized>(
        &mut self,
        flow: &Flow<'_>,
        electrical: Option<&ElectricalSamples>,
        user: &mut O,
    ) -> usize {
        let mut cursor = 0;
        loop {
            let t = self.time(self.next);
            if t > flow.t_end {
                break;
            }
            if t < flow.t_start {
                self.next += 1;
                continue;
            }
            flow.state_at(t, &mut self.x, &mut self.v);
            let base = self
                .base
                .as_ref()
                .map_or_else(|| flow.base_at(t).0, |b| b.displacement(t));
            for (k, d) in self.d.iter_mut().enumerate() {
                *d = self.gaps[k] - (self.x[k + 1] - self.x[k]);
            }
            // Electrical samples before this one have no mechanical sample: pass over them.
            if let Some(s) = electrical {
                while s.times.get(cursor).is_some_and(|&ts| ts < t) {
                    cursor += 1;
                }
            }
            let e = electrical.filter(|s| s.times.get(cursor).is_some_and(|&ts| ts == t));
            let sample = e.map(|s| {
                let i = cursor;
                ElectricalSample {
                    charge_c: s.charge_c[i],
                    current_a: s.current_a[i],
                    voltage_v: s.voltage_v[i],
                    capacitance_f: s.capacitance_f[i],
                    voc_v: s.voc_v[i],
                    storage_voltage_v: s.storage_voltage_v.get(i).copied(),
                }
            });
            if sample.is_some() {
                cursor += 1;
            }
            user.sample(&Sample {
                index: self.next,
                time: t,
                positions: &self.x,
                velocities: &self.v,
                base,
                gaps: &self.d,
                electrical: sample,
            });
            self.next += 1;
        }
        cursor
    }
}

/// The observer of the simulator inside [`simulate`].
struct Recorder<'o, O: ?Sized> {
    user: &'o mut O,
    stats: RunStats,
    solver: Option<ChargeSolver>,
    electrical_from: f64,
    stop_on_electrical_failure: bool,
    samples: Option<SampleGrid>,
    /// Two-way coupling: the coupled run advances the solver; `flow` must not.
    solver_driven: bool,
    /// Electrical samples taken from the solver and not yet matched to a piece of flow (a
    /// coupled window's samples arrive before its pieces are reported).
    pending: ElectricalSamples,
}

impl<O: RunObserver + ?Sized> Recorder<'_, O> {
    fn electrical_error(&self) -> Option<ElectricalError> {
        self.solver.as_ref().and_then(|s| s.status().err())
    }
}

impl<O: RunObserver + ?Sized> Observer for Recorder<'_, O> {
    fn flow(&mut self, flow: &Flow<'_>) {
        if let Some(s) = &mut self.solver
            && flow.t_start >= self.electrical_from
            && !self.solver_driven
        {
            s.flow(flow);
        }
        self.user.flow(flow);
        if let Some(grid) = &mut self.samples {
            let electrical = match self.solver.as_mut() {
                Some(s) => {
                    self.pending.append(s.take_samples());
                    Some(&self.pending)
                }
                None => None,
            };
            let used = grid.emit(flow, electrical, &mut *self.user);
            self.pending.drain_front(used);
        }
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.stats.event(event, state);
        self.user.event(event, state);
    }

    fn proceed(&mut self) -> Verdict {
        match &mut self.solver {
            Some(s) if self.stop_on_electrical_failure => s.proceed(),
            _ => Ok(ControlFlow::Continue(())),
        }
    }
}

impl<O: RunObserver + ?Sized> ChargeHost for Recorder<'_, O> {
    fn charge_solver(&mut self) -> &mut ChargeSolver {
        self.solver.as_mut().expect("a coupled run has a harvester")
    }
}

/// The mechanics of a run: the plain engine, or (two-way coupling, once the harvester is
/// connected) the engine coupled to the charge solver.
enum Mechanics {
    Plain(Box<Simulator>),
    Coupled(Box<CoupledChain>),
}

impl Mechanics {
    fn run_until<O: RunObserver + ?Sized>(
        &mut self,
        t: f64,
        rec: &mut Recorder<'_, O>,
    ) -> Result<RunEnd, StudyError> {
        match self {
            Mechanics::Plain(sim) => Ok(sim.run_until(t, rec)?),
            Mechanics::Coupled(c) => c.run_until(t, rec).map_err(coupling_error),
        }
    }

    fn state(&self) -> ChainState {
        match self {
            Mechanics::Plain(sim) => sim.state(),
            Mechanics::Coupled(c) => c.state(),
        }
    }

    fn time(&self) -> f64 {
        match self {
            Mechanics::Plain(sim) => sim.time(),
            Mechanics::Coupled(c) => c.time(),
        }
    }
}

/// A coupled run's failure as a run's.
fn coupling_error(e: CouplingError) -> StudyError {
    match e {
        CouplingError::Sim(e) => StudyError::Sim(e),
        CouplingError::Electrical(e) => StudyError::Electrical(e),
        other => StudyError::Param(ParamError::Conflict {
            name: "harvester.coupling".into(),
            message: other.to_string(),
        }),
    }
}

impl StudyError {
    /// The engine's error as a run's: a base motion that cannot drive the run is told as such.
    pub fn from_sim(e: SimError) -> Self {
        match e {
            SimError::BaseMotion(b) => StudyError::BaseMotion(b),
            other => StudyError::Sim(other),
        }
    }
}

// Not `#[from]`: that would also make the inner error the `source()`, which the message
// already shows (a failure's chain printed it twice).
impl From<BaseMotionError> for StudyError {
    fn from(e: BaseMotionError) -> Self {
        StudyError::BaseMotion(e)
    }
}

impl From<ElectricalError> for StudyError {
    fn from(e: ElectricalError) -> Self {
        StudyError::Electrical(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_charge_solver_failure_is_told_once() {
        let inner = ElectricalError::StepSizeUnderflow { t: 0.0, h: 1e-17 };
        let text = inner.to_string();
        let e = StudyError::from(inner);
        let mut chain = String::new();
        let mut cause: Option<&dyn std::error::Error> = Some(&e);
        while let Some(c) = cause {
            chain.push_str(&format!(": {c}"));
            cause = c.source();
        }
        assert_eq!(chain.matches(&text).count(), 1, "{chain}");
        assert!(chain.starts_with(": charge solver: "), "{chain}");
    }
}
