//! The event-driven simulator.
//!
//! The chain is a sequence of *clusters* (maximal groups of masses whose contacts are closed).
//! Between events every cluster follows its closed-form [`Oscillator`], so the simulator never
//! time-steps: it finds the earliest zero of the explicit event functions (gap of each open
//! contact, contact force of each closed one, accumulation time of each pending chatter) with
//! the certified search of [`super::roots`], jumps there, and applies the event by the
//! contact laws of [`super::contact`] (impacts, chatter jumps, sticking, release, resting
//! contacts).
//!
//! Work is bounded: at most [`SimOptions::max_events_per_period`] events per period, after
//! which the run ends with [`SimError::EventLimit`].

use std::ops::ControlFlow;

use std::sync::Arc;

use super::base::{BaseDisplacement, BaseDrive, driven_chain};
use super::contact::Closure;
use super::forces::ExternalForces;
use super::observer::{ClusterFlow, Event, EventKind, Flow, Observer, StateView};
use super::oscillator::{Forcing, OscConstants, Oscillator, Phase};
use crate::error::{ParamError, SimError};
use crate::excitation::BaseMotion;
use crate::model::{ChainParams, ChainState, ForcePolynomial, SimOptions};

mod apply;

/// How [`Simulator::run_until`] ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RunEnd {
    /// The requested time was reached.
    Reached,
    /// An observer stopped the run at time `t`, s ([`Observer::proceed`]); the simulator
    /// stands there and can go on.
    Stopped {
        /// Time, s.
        t: f64,
    },
}

/// Whether a contact is open or closed, as seen from outside the simulator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ContactStatus {
    /// The two sides are apart or merely touching (resting against each other with no
    /// contact force).
    Open,
    /// The two sides are stuck together (same cluster).
    Stuck,
    /// A chatter sequence is being jumped over: the two sides move together until its
    /// accumulation time, where they stick or release.
    Chatter,
}

/// What the search found next.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Pending {
    /// Gap zero at contact k; `at_start` if found at the very start of the search.
    Impact {
        contact: usize,
        at_start: bool,
    },
    Release(usize),
    ChatterEnd(usize),
    /// The force of a resting contact rose above its band: it sticks.
    Press(usize),
    /// The force of a resting contact fell below minus its band: it parts.
    Part(usize),
}

/// Constants of one cluster.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct ClusterConsts {
    pub(super) mass: f64,
    pub(super) damping: f64,
    pub(super) stiffness: f64,
    /// F₀ = −Σ k_i o_i + Σ F_i (the constant external forces), N.
    pub(super) force: f64,
}

/// Event-driven exact simulator of an N-mass vibro-impact chain.
///
/// ```
/// use vibrotribo::{ChainParams, ChainState, EventLog, SimOptions, Simulator};
///
/// let params = ChainParams::default();
/// let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
/// let mut log = EventLog::default();
/// sim.run_until(5.0 * params.period(), &mut log)?;
/// assert!(!log.events.is_empty());
/// # Ok::<(), vibrotribo::SimError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Simulator {
    pub(super) params: std::sync::Arc<ChainParams>,
    pub(super) options: SimOptions,
    pub(super) forcing: Forcing,
    /// The external forces on the masses.
    pub(super) forces: ExternalForces,
    /// G_i = Σ_{j<i} δ_j: position offset of mass i inside a cluster, relative to its top.
    pub(super) offsets: Vec<f64>,
    pub(super) t: f64,
    /// The forcing phase at `t` (computed once per time, shared by every search and event
    /// handler that starts there).
    pub(super) phase_now: Phase,
    period_index: u64,
    events_in_period: usize,
    pub(super) clusters: Vec<ClusterFlow>,
    pub(super) consts: Vec<ClusterConsts>,
    pub(super) closure: Vec<Closure>,
    /// State at `t` (kept current).
    pub(super) x: Vec<f64>,
    pub(super) v: Vec<f64>,
    /// Per contact: closing speed of its last impact and the running count of impacts with
    /// decreasing speed (the current chatter sequence).
    pub(super) last_speed: Vec<f64>,
    pub(super) sequence: Vec<u32>,
    // Rounding-level tolerances, refreshed at every event from the state's scale.
    pub(super) pos_tol: f64,
    pub(super) vel_tol: f64,
    pub(super) acc_tol: f64,
    /// The largest `Oscillator::magnitude` of the current clusters, m.
    pub(super) term_scale: f64,
    // Scratch for per-event work (no allocation per event).
    pub(super) scratch_first_speed: Vec<f64>,
    pub(super) scratch_lambda: Vec<f64>,
    pub(super) scratch_q: Vec<f64>,
    pub(super) scratch_active: Vec<bool>,
    pub(super) scratch_candidate: Vec<bool>,
    scratch_events: Vec<Event>,
    pub(super) scratch_resting: Vec<bool>,
    /// Per contact: the gap search starts no earlier than this (see `handle`).
    pub(super) search_from: Vec<f64>,
    /// Scratch for the race of the event searches (`search.rs`).
    pub(super) scratch_racers: Vec<super::roots::Racer>,
    /// Whether a run that stops without an event re-anchors the clusters' flows there (the
    /// default). A caller that installs new forces before every run (which rebuilds anyway)
    /// turns it off: the flows stay valid past a stop, anchored where they started.
    rebuild_at_stops: bool,
    /// The interval forces of a base motion other than the chain's harmonic (`None`: the
    /// chain's harmonic drives the base).
    drive: Option<BaseDrive>,
}

/// A touch found at the start of a search that changes nothing moves that contact's next
/// search this fraction of a period ahead, so that rounding-level degeneracies (e.g. the
/// gap of a just-released contact, with all derivatives at rounding level) cannot spin.
const NUDGE: f64 = 1e-14;

impl Simulator {
    /// A simulator at time 0 in `initial` state. Contacts that start closed with zero relative
    /// velocity stick if their contact force is compressive.
    pub fn new(params: &ChainParams, initial: &ChainState, options: SimOptions) -> Result<Self, SimError> {
        Self::new_at(params, 0.0, initial, options)
    }

    /// A simulator at time `t0` ≥ 0, s, in `initial` state (the base motion's phase is that of
    /// `t0`); otherwise as [`new`](Self::new).
    pub fn new_at(
        params: &ChainParams,
        t0: f64,
        initial: &ChainState,
        options: SimOptions,
    ) -> Result<Self, SimError> {
        params.validate()?;
        params.validate_state_at(initial, t0)?;
        options.validate()?;
        crate::error::check(
            "start time",
            t0,
            t0.is_finite() && t0 >= 0.0,
            "must be finite and not negative",
        )?;
        let n = params.len();
        // Contacts: N − 1 between masses, and the two stops' if the chain has any.
        let nc = params.contact_count();
        let mut offsets = vec![0.0; n];
        for i in 1..n {
            offsets[i] = offsets[i - 1] + params.gaps[i - 1];
        }
        let forcing = Forcing::new(params.excitation.amplitude, params.omega());
        let phase_now = forcing.phase(t0);
        let mut sim = Simulator {
            forcing,
            forces: ExternalForces::new(params),
            params: std::sync::Arc::new(params.clone()),
            options,
            offsets,
            t: t0,
            phase_now,
            period_index: (t0 / params.period()).floor() as u64,
            events_in_period: 0,
            clusters: Vec::with_capacity(n),
            consts: Vec::with_capacity(n),
            closure: vec![Closure::Open; nc],
            x: initial.positions.clone(),
            v: initial.velocities.clone(),
            last_speed: vec![f64::INFINITY; nc],
            sequence: vec![0; nc],
            pos_tol: 0.0,
            vel_tol: 0.0,
            acc_tol: 0.0,
            term_scale: 0.0,
            scratch_first_speed: vec![f64::NAN; nc],
            scratch_lambda: vec![0.0; nc],
            scratch_q: vec![0.0; nc],
            scratch_active: vec![false; nc],
            scratch_candidate: vec![false; nc],
            scratch_events: Vec::new(),
            scratch_resting: vec![false; nc],
            search_from: vec![f64::NEG_INFINITY; nc],
            scratch_racers: Vec::with_capacity(nc),
            rebuild_at_stops: true,
            drive: None,
        };
        sim.refresh_tolerances();
        // Start with closed contacts where the masses touch with equal velocity and press.
        sim.settle(None, false);
        sim.scratch_events.clear();
        sim.rebuild()?;
        Ok(sim)
    }

    /// A simulator at time 0 in `initial` state with its base moving as `base` (`None`: the
    /// chain's own harmonic `A sin ωt`) over `[0, end]`, s: the chain's harmonic amplitude
    /// is that of a one-harmonic multisine that is exactly the chain's harmonic, and 0 under
    /// any other motion, which drives the masses as the forces `k_i y + c_i y'` of each of
    /// its intervals. Forces set with
    /// [`set_external_forces`](Self::set_external_forces) add to these.
    ///
    /// Errors ([`SimError::BaseMotion`]) if `base` cannot drive `params` (rigid stops moving
    /// with the base under another motion) or ends before `end`; otherwise as
    /// [`new`](Self::new).
    ///
    /// ```
    /// use std::sync::Arc;
    /// use vibrotribo::excitation::{BaseMotion, Harmonic};
    /// use vibrotribo::{ChainParams, ChainState, EventLog, SimOptions, Simulator};
    ///
    /// let params = ChainParams::default();
    /// let w = params.omega();
    /// // Two harmonics: the chain's own and a third of it at 1.5 ω.
    /// let base = Arc::new(BaseMotion::Harmonics(vec![
    ///     Harmonic { amplitude: params.excitation.amplitude, omega: w, phase: 0.0 },
    ///     Harmonic { amplitude: params.excitation.amplitude / 3.0, omega: 1.5 * w, phase: 0.3 },
    /// ]));
    /// let end = 5.0 * params.period();
    /// let mut sim = Simulator::driven(&params, &ChainState::at_rest(3), SimOptions::default(), Some(&base), end)?;
    /// sim.run_until(end, &mut EventLog::default())?;
    /// # Ok::<(), vibrotribo::SimError>(())
    /// ```
    pub fn driven(
        params: &ChainParams,
        initial: &ChainState,
        options: SimOptions,
        base: Option<&Arc<BaseMotion>>,
        end: f64,
    ) -> Result<Self, SimError> {
        let Some(base) = base else {
            return Self::new(params, initial, options);
        };
        let drive = BaseDrive::new(params, base, end)?;
        let mut sim = Self::new(&driven_chain(params, Some(base)), initial, options)?;
        sim.drive = drive;
        Ok(sim)
    }

    /// The base displacement the engine runs on as interval forces (`None`: the chain's
    /// harmonic drives the base).
    pub fn base_displacement(&self) -> Option<&BaseDisplacement> {
        self.drive.as_ref().map(BaseDrive::displacement)
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// The parameters being simulated.
    pub fn params(&self) -> &ChainParams {
        &self.params
    }

    /// Makes `self` a copy of `other`, reusing its buffers (a clone without allocations, for
    /// callers that copy a simulator many times: two-way coupling's trials).
    pub(crate) fn assign_from(&mut self, other: &Simulator) {
        // Destructured so that a new field cannot be forgotten here.
        let Simulator {
            params,
            options,
            forcing,
            forces,
            offsets,
            t,
            phase_now,
            period_index,
            events_in_period,
            clusters,
            consts,
            closure,
            x,
            v,
            last_speed,
            sequence,
            pos_tol,
            vel_tol,
            acc_tol,
            term_scale,
            scratch_first_speed,
            scratch_lambda,
            scratch_q,
            scratch_active,
            scratch_candidate,
            scratch_events,
            scratch_resting,
            search_from,
            // Scratch of the event search, empty between searches: nothing to copy.
            scratch_racers: _,
            rebuild_at_stops,
            drive,
        } = other;
        self.params = params.clone();
        self.options = options.clone();
        self.forcing = *forcing;
        self.forces.assign_from(forces);
        self.offsets.clone_from(offsets);
        self.t = *t;
        self.phase_now = *phase_now;
        self.period_index = *period_index;
        self.events_in_period = *events_in_period;
        self.clusters.clone_from(clusters);
        self.consts.clone_from(consts);
        self.closure.clone_from(closure);
        self.x.clone_from(x);
        self.v.clone_from(v);
        self.last_speed.clone_from(last_speed);
        self.sequence.clone_from(sequence);
        self.pos_tol = *pos_tol;
        self.vel_tol = *vel_tol;
        self.acc_tol = *acc_tol;
        self.term_scale = *term_scale;
        self.scratch_first_speed.clone_from(scratch_first_speed);
        self.scratch_lambda.clone_from(scratch_lambda);
        self.scratch_q.clone_from(scratch_q);
        self.scratch_active.clone_from(scratch_active);
        self.scratch_candidate.clone_from(scratch_candidate);
        self.scratch_events.clone_from(scratch_events);
        self.scratch_resting.clone_from(scratch_resting);
        self.search_from.clone_from(search_from);
        self.rebuild_at_stops = *rebuild_at_stops;
        match (&mut self.drive, drive) {
            (Some(mine), Some(theirs)) => mine.assign_from(theirs),
            (mine, theirs) => mine.clone_from(theirs),
        }
    }

    /// Whether [`run_until`](Self::run_until) re-anchors the flows where it stops without an
    /// event (on by default; see the field).
    pub(crate) fn set_rebuild_at_stops(&mut self, on: bool) {
        self.rebuild_at_stops = on;
    }

    /// Excitation period T, s.
    pub fn period(&self) -> f64 {
        self.forcing.period
    }

    pub(crate) fn forcing(&self) -> &Forcing {
        &self.forcing
    }

    pub(crate) fn offsets(&self) -> &[f64] {
        &self.offsets
    }

    /// Positions, m, and velocities, m/s, at the current time.
    pub fn state(&self) -> ChainState {
        ChainState {
            positions: self.x.clone(),
            velocities: self.v.clone(),
        }
    }

    /// Sets time-polynomial external forces on the masses from the current time on, until the
    /// next call: mass i feels `forces[i]` (N, positive along x, docs/MODEL.md) on top of its
    /// constant force [`ChainParams::forces`] and of the forces of a base motion
    /// ([`driven`](Self::driven)). One polynomial per mass, of degree at most
    /// [`MAX_FORCE_DEGREE`](crate::model::MAX_FORCE_DEGREE), or none (an empty slice) to
    /// return to the constant forces only. The polynomials are meant to be evaluated from
    /// [`time`](Self::time) on; a later [`run_until`](Self::run_until) follows them exactly.
    ///
    /// Every cluster's closed-form flow is rebuilt at the current time with the state
    /// continuous: no event is logged and no observer is called.
    ///
    /// Errors (naming `forces`, `forces[i].t_ref` or `forces[i].coefficients[j]`) on a wrong
    /// number of polynomials, a degree above 8 or a value that is not finite; the simulator is
    /// then unchanged.
    ///
    /// ```
    /// use vibrotribo::{ChainParams, ChainState, EventLog, ForcePolynomial, SimOptions, Simulator};
    ///
    /// let params = ChainParams::default();
    /// let mut sim = Simulator::new(&params, &ChainState::at_rest(3), SimOptions::default())?;
    /// // A force on the middle mass rising by 0.5 N/s from now.
    /// let t = sim.time();
    /// let f = [ForcePolynomial::zero(), ForcePolynomial::new(t, vec![0.0, 0.5]), ForcePolynomial::zero()];
    /// sim.set_external_forces(&f)?;
    /// sim.run_until(t + params.period(), &mut EventLog::default())?;
    /// sim.clear_external_forces()?;
    /// # Ok::<(), vibrotribo::SimError>(())
    /// ```
    pub fn set_external_forces(&mut self, forces: &[ForcePolynomial]) -> Result<(), SimError> {
        self.forces.set_polynomials(forces, self.x.len(), self.t)?;
        self.rebuild()
    }

    /// Removes the time-polynomial forces of [`set_external_forces`](Self::set_external_forces)
    /// (the constant ones of [`ChainParams::forces`] stay), with the same rebuild.
    pub fn clear_external_forces(&mut self) -> Result<(), SimError> {
        self.set_external_forces(&[])
    }

    /// The external force on mass `i` (0-based) at time `t`, N: its constant force and its
    /// current polynomial (which holds from the last [`set_external_forces`](Self::set_external_forces) on).
    pub fn external_force(&self, i: usize, t: f64) -> f64 {
        self.forces.at(i, t).0
    }

    /// Contact force of each closed (stuck or chattering) contact at the current time, N,
    /// compressive positive (the function whose zero releases it); `None` for an open or
    /// resting contact. Indexed like [`contact_status`](Self::contact_status).
    pub fn contact_forces(&self) -> Vec<Option<f64>> {
        let w = self.forcing.omega;
        (0..self.closure.len())
            .map(|k| match self.closure[k] {
                Closure::Stuck | Closure::Chatter { .. } if !self.absent(k) => {
                    let sig = self.force_signal(k);
                    let amp = sig.harmonic_amplitude();
                    Some(sig.jet(self.t, self.phase_now, &self.clusters, w, self.t, amp).d[0])
                }
                _ => None,
            })
            .collect()
    }

    /// Status of each contact (index k: between mass k and k+1, 0-based; with stops, N − 1 is
    /// the lower stop and N the upper one, see [`ChainParams::contact_count`]).
    pub fn contact_status(&self) -> Vec<ContactStatus> {
        self.closure
            .iter()
            .map(|c| match c {
                Closure::Open => ContactStatus::Open,
                Closure::Stuck => ContactStatus::Stuck,
                Closure::Chatter { .. } => ContactStatus::Chatter,
                Closure::Resting => ContactStatus::Open,
            })
            .collect()
    }

    /// Runs to time `t_end`, s, reporting flow and events to `observer`, which may stop the run
    /// early or fail it ([`Observer::proceed`]). Under a base motion other than the chain's
    /// harmonic the run stops at every interval end of the motion and sets the next
    /// interval's forces there (no event, no observer call).
    pub fn run_until<O: Observer + ?Sized>(
        &mut self,
        t_end: f64,
        observer: &mut O,
    ) -> Result<RunEnd, SimError> {
        if self.drive.is_none() {
            return self.run_span(t_end, observer);
        }
        let n = self.x.len();
        loop {
            let t = self.t;
            let Some(drive) = self.drive.as_mut() else {
                return self.run_span(t_end, observer);
            };
            let (forces, stop) = drive.at(t, t_end);
            let changed = match forces {
                Some(f) => {
                    self.forces.set_base(f, n, t)?;
                    true
                }
                None => false,
            };
            if changed {
                self.rebuild()?;
            }
            match self.run_span(stop, observer)? {
                RunEnd::Reached if stop < t_end => {}
                end => return Ok(end),
            }
        }
    }

    /// [`run_until`](Self::run_until) on one stretch of the base forces.
    fn run_span<O: Observer + ?Sized>(&mut self, t_end: f64, observer: &mut O) -> Result<RunEnd, SimError> {
        if t_end.is_nan() || t_end < self.t {
            return Err(SimError::Backwards {
                requested: t_end,
                current: self.t,
            });
        }
        let period = self.forcing.period;
        while self.t < t_end {
            let boundary = (self.period_index + 1) as f64 * period;
            let stop = t_end.min(boundary);
            let next = self.next_event(stop)?;
            let t_next = next.map_or(stop, |(te, _)| te.max(self.t));
            self.emit_flow(t_next, observer);
            self.advance_state(t_next);
            // A stop asked for after a piece of flow takes effect once the event that ends it
            // is applied, so that the simulator stands in a consistent state.
            let halt = Self::verdict(observer.proceed(), self.t)?.is_some();
            match next {
                None => {
                    if stop >= boundary {
                        self.period_index += 1;
                        self.events_in_period = 0;
                    }
                    if self.rebuild_at_stops {
                        self.rebuild()?;
                    }
                    if halt {
                        return Ok(RunEnd::Stopped { t: self.t });
                    }
                }
                Some((_, what)) => {
                    self.handle(what)?;
                    let events = std::mem::take(&mut self.scratch_events);
                    let view = StateView {
                        time: self.t,
                        positions: &self.x,
                        velocities: &self.v,
                    };
                    for e in &events {
                        observer.event(e, &view);
                    }
                    self.events_in_period += events.len().max(1);
                    self.scratch_events = events;
                    self.scratch_events.clear();
                    if self.events_in_period > self.options.max_events_per_period {
                        return Err(SimError::EventLimit {
                            t: self.t,
                            events: self.events_in_period,
                            limit: self.options.max_events_per_period,
                        });
                    }
                    if Self::verdict(observer.proceed(), self.t)?.is_some() || halt {
                        return Ok(RunEnd::Stopped { t: self.t });
                    }
                }
            }
        }
        Ok(RunEnd::Reached)
    }

    /// What an observer's verdict means for the run: go on (`None`), stop, or fail.
    fn verdict(v: super::observer::Verdict, t: f64) -> Result<Option<RunEnd>, SimError> {
        match v {
            Ok(ControlFlow::Continue(())) => Ok(None),
            Ok(ControlFlow::Break(())) => Ok(Some(RunEnd::Stopped { t })),
            Err(e) => Err(SimError::Observer(e.to_string())),
        }
    }

    fn emit_flow<O: Observer + ?Sized>(&self, t_end: f64, observer: &mut O) {
        observer.flow(&Flow {
            t_start: self.t,
            t_end,
            clusters: &self.clusters,
            offsets: &self.offsets,
            gaps: &self.params.gaps,
            forcing: &self.forcing,
        });
    }

    /// A stored piece of this simulator's flow as a [`Flow`] (the chain's offsets, gaps and
    /// forcing are this simulator's).
    pub(crate) fn flow_of<'a>(&'a self, segment: &'a super::observer::Segment) -> Flow<'a> {
        Flow {
            t_start: segment.t_start,
            t_end: segment.t_end,
            clusters: &segment.clusters,
            offsets: &self.offsets,
            gaps: &self.params.gaps,
            forcing: &self.forcing,
        }
    }

    /// Moves the clock to `t` and evaluates every mass there (no event applied).
    fn advance_state(&mut self, t: f64) {
        let ph = self.forcing.phase(t);
        self.phase_now = ph;
        for c in &self.clusters {
            let (s, v) = c.oscillator.state(t, ph);
            let base = self.offsets[c.first];
            for i in c.first..=c.last {
                self.x[i] = s + (self.offsets[i] - base);
                self.v[i] = v;
            }
        }
        self.t = t;
    }

    /// The forcing phase at `t`: the stored one at the current time, else computed.
    #[inline]
    pub(in crate::dynamics) fn phase_at(&self, t: f64) -> Phase {
        if t == self.t {
            self.phase_now
        } else {
            self.forcing.phase(t)
        }
    }

    /// Index of the cluster containing mass `i`.
    pub(in crate::dynamics) fn cluster_of(&self, i: usize) -> usize {
        self.clusters.partition_point(|c| c.last < i)
    }

    pub(in crate::dynamics) fn push_event(
        &mut self,
        kind: EventKind,
        contact: usize,
        before: f64,
        after: f64,
        seq: u32,
    ) {
        self.scratch_events.push(Event {
            time: self.t,
            kind,
            contact,
            velocity_before: before,
            velocity_after: after,
            sequence_impacts: seq,
        });
    }
}

/// Validates and builds the initial state for a run: `positions`/`velocities` default to rest.
pub fn initial_state(
    params: &ChainParams,
    positions: Option<&[f64]>,
    velocities: Option<&[f64]>,
) -> Result<ChainState, ParamError> {
    let n = params.len();
    let state = ChainState {
        positions: positions.map_or_else(|| vec![0.0; n], <[f64]>::to_vec),
        velocities: velocities.map_or_else(|| vec![0.0; n], <[f64]>::to_vec),
    };
    params.validate_state(&state)?;
    Ok(state)
}
