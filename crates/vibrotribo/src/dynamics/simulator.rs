//! The event-driven simulator.
//!
//! The chain is a sequence of *clusters* (maximal groups of masses whose contacts are closed).
//! Between events every cluster follows its closed-form [`Oscillator`], so the simulator never
//! time-steps: it finds the earliest zero of the explicit event functions (gap of each open
//! contact, contact force of each closed one, accumulation time of each pending chatter) with
//! the certified search of [`super::roots`], jumps there, and applies the event:
//!
//! - **Impact** (gap reaches zero while closing): Newton's restitution law between the two
//!   clusters that meet, with momentum conserved (seed eqs. 7–8 with m_p, m_q the cluster
//!   masses). *Simultaneous impacts* (several contacts closed and approaching at the same
//!   instant, or a cluster struck while touching a third body) are resolved by applying
//!   pairwise impacts, always to the contact with the largest closing speed (ties: lowest
//!   index), until no closed contact approaches. This is deterministic, converges for μ < 1
//!   and reproduces Newton's cradle for μ = 1.
//! - **Chatter**: after an impact with rebound speed u under a closing relative acceleration
//!   a, the remaining geometric sequence of impacts lasts `T∞ = 2u / ((1 − μ) a)` (Budd & Dux
//!   1994). Once the error of assuming a constant over that time is below
//!   [`SimOptions::chatter_tolerance`] periods, the two sides are merged and the simulator
//!   jumps to the accumulation time, where they stick or release.
//! - **Sticking**: contacts at zero gap with zero relative velocity carry forces λ ≥ 0 given
//!   by the linear complementarity problem `w = q + Wλ ≥ 0, λ ≥ 0, wᵀλ = 0` (q: gap
//!   accelerations of the free masses; W: the tridiagonal Delassus matrix of the chain, an
//!   M-matrix), solved exactly by Chandrasekaran's monotone active-set method. Inside a
//!   cluster this gives the corrected contact force of docs/MODEL.md §1,
//!   `N_j = Σ_{i≤j} m_i (a_G − a_i)`, not the paper's eqs. 9–10 (whose factor ½ is exact only
//!   for equal masses).
//! - **Release**: a closed contact opens when its force falls to zero.
//! - **Resting**: a contact at zero gap and zero relative velocity whose LCP force and gap
//!   acceleration are both zero to within rounding (`|w| ≤` the acceleration tolerance) is
//!   *resting*: touching with no force, as in a resting stack, Newton's cradle or masses with
//!   equal k/m that travel together. It is neither a stick nor an impact, so it logs no event;
//!   its two sides move as one cluster (their relative motion is then zero by construction,
//!   not by cancellation of two flows), and its force is watched instead of its gap: it
//!   becomes an ordinary stuck contact (a `Stick`) when the force rises above a band of a few
//!   times the rounding level, and parts silently when the force falls below minus that band
//!   (the hysteresis keeps the two decisions apart). An impact passes through resting contacts
//!   pairwise, as through open touching ones. Any touching contact that stays open has its
//!   rounding-level relative velocity removed (momentum-conserving), so that the exact flow
//!   does not carry the rounding of an impact elsewhere into a slow, spurious approach.
//!
//! Work is bounded: at most [`SimOptions::max_events_per_period`] events per period, after
//! which the run ends with [`SimError::EventLimit`].

use std::ops::ControlFlow;

use super::observer::{ClusterFlow, Event, EventKind, Flow, Observer, StateView};
use super::oscillator::{Forcing, OscConstants, Oscillator};
use super::roots::{Found, Stall, first_root};
use super::signal::Signal;
use crate::error::{ParamError, SimError};
use crate::model::{ChainParams, ChainState, SimOptions};

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

#[derive(Debug, Clone, Copy, PartialEq)]
enum Closure {
    Open,
    Stuck,
    Chatter { t_acc: f64, impacts: u32 },
    // Touching with zero force (see the module docs): one cluster, but no event.
    Resting,
}

impl Closure {
    /// Whether the two sides move as one cluster.
    fn is_closed(self) -> bool {
        !matches!(self, Closure::Open)
    }

    /// Whether the contact carries a compressive force (it entered by a `Stick` and leaves
    /// by a `Release`).
    fn presses(self) -> bool {
        matches!(self, Closure::Stuck | Closure::Chatter { .. })
    }
}

/// What the search found next.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Pending {
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
struct ClusterConsts {
    mass: f64,
    damping: f64,
    stiffness: f64,
    /// F₀ = −Σ k_i o_i, N.
    force: f64,
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
    params: ChainParams,
    options: SimOptions,
    forcing: Forcing,
    /// G_i = Σ_{j<i} δ_j: position offset of mass i inside a cluster, relative to its top.
    offsets: Vec<f64>,
    t: f64,
    period_index: u64,
    events_in_period: usize,
    clusters: Vec<ClusterFlow>,
    consts: Vec<ClusterConsts>,
    closure: Vec<Closure>,
    /// State at `t` (kept current).
    x: Vec<f64>,
    v: Vec<f64>,
    /// Per contact: closing speed of its last impact and the running count of impacts with
    /// decreasing speed (the current chatter sequence).
    last_speed: Vec<f64>,
    sequence: Vec<u32>,
    // Rounding-level tolerances, refreshed at every event from the state's scale.
    pos_tol: f64,
    vel_tol: f64,
    acc_tol: f64,
    /// The largest `Oscillator::magnitude` of the current clusters, m.
    term_scale: f64,
    // Scratch for per-event work (no allocation per event).
    scratch_first_speed: Vec<f64>,
    scratch_lambda: Vec<f64>,
    scratch_q: Vec<f64>,
    scratch_active: Vec<bool>,
    scratch_candidate: Vec<bool>,
    scratch_events: Vec<Event>,
    scratch_resting: Vec<bool>,
    /// Per contact: the gap search starts no earlier than this (see `handle`).
    search_from: Vec<f64>,
}

/// Relative rounding allowance for position and velocity tolerances.
const TOL: f64 = 64.0 * f64::EPSILON;

/// Relative allowance for the acceleration tolerance of the sticking decision. It is kept
/// well above the rounding noise of the contact-force event function, so that a contact that
/// sticks carries a force its release search can tell from zero (no stick/release ping-pong).
const ACC_TOL: f64 = 4096.0 * f64::EPSILON;

/// A touch found at the start of a search that changes nothing moves that contact's next
/// search this fraction of a period ahead, so that rounding-level degeneracies (e.g. the
/// gap of a just-released contact, with all derivatives at rounding level) cannot spin.
const NUDGE: f64 = 1e-14;

/// The force band of a resting contact, in multiples of the force that corresponds to the
/// acceleration tolerance: a contact rests while `|w| ≤ acc_tol`, and its force must leave
/// `±REST_BAND` times that before it sticks or parts, so that the next contact decision sees
/// it clearly pressing or clearly separating.
const REST_BAND: f64 = 4.0;

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
        params.validate_state(initial)?;
        options.validate()?;
        crate::error::check(
            "start time",
            t0,
            t0.is_finite() && t0 >= 0.0,
            "must be finite and not negative",
        )?;
        let n = params.len();
        let mut offsets = vec![0.0; n];
        for i in 1..n {
            offsets[i] = offsets[i - 1] + params.gaps[i - 1];
        }
        let mut sim = Simulator {
            forcing: Forcing::new(params.excitation.amplitude, params.omega()),
            params: params.clone(),
            options,
            offsets,
            t: t0,
            period_index: (t0 / params.period()).floor() as u64,
            events_in_period: 0,
            clusters: Vec::with_capacity(n),
            consts: Vec::with_capacity(n),
            closure: vec![Closure::Open; n - 1],
            x: initial.positions.clone(),
            v: initial.velocities.clone(),
            last_speed: vec![f64::INFINITY; n - 1],
            sequence: vec![0; n - 1],
            pos_tol: 0.0,
            vel_tol: 0.0,
            acc_tol: 0.0,
            term_scale: 0.0,
            scratch_first_speed: vec![f64::NAN; n - 1],
            scratch_lambda: vec![0.0; n - 1],
            scratch_q: vec![0.0; n - 1],
            scratch_active: vec![false; n - 1],
            scratch_candidate: vec![false; n - 1],
            scratch_events: Vec::new(),
            scratch_resting: vec![false; n - 1],
            search_from: vec![f64::NEG_INFINITY; n - 1],
        };
        sim.refresh_tolerances();
        // Start with closed contacts where the masses touch with equal velocity and press.
        sim.settle(None, false);
        sim.scratch_events.clear();
        sim.rebuild()?;
        Ok(sim)
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// The parameters being simulated.
    pub fn params(&self) -> &ChainParams {
        &self.params
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

    /// Status of each contact (index k: between mass k and k+1, 0-based).
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
    /// early or fail it ([`Observer::proceed`]).
    pub fn run_until<O: Observer + ?Sized>(
        &mut self,
        t_end: f64,
        observer: &mut O,
    ) -> Result<RunEnd, SimError> {
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
                    self.rebuild()?;
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

    /// Moves the clock to `t` and evaluates every mass there (no event applied).
    fn advance_state(&mut self, t: f64) {
        let ph = self.forcing.phase(t);
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

    /// Rounding-level tolerances for positions, velocities and accelerations, from the scale
    /// of the current state, or of the terms the clusters' closed forms sum it from where
    /// those are larger (near resonance, mid-transient), since they set its rounding.
    fn refresh_tolerances(&mut self) {
        let p = &self.params;
        let wn2_max = p
            .masses
            .iter()
            .zip(&p.stiffness)
            .map(|(m, k)| k / m)
            .fold(0.0, f64::max);
        let xmax = self.x.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let vmax = self.v.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let length =
            xmax.max(self.term_scale) + self.offsets[self.offsets.len() - 1] + p.excitation.amplitude + 1e-9;
        let omega = self.forcing.omega;
        let speed = vmax + (p.excitation.amplitude * omega) + wn2_max.sqrt() * length;
        let accel = wn2_max * length + speed * wn2_max.sqrt() + p.excitation.amplitude * omega * omega;
        self.pos_tol = TOL * length;
        self.vel_tol = TOL * speed;
        self.acc_tol = ACC_TOL * accel;
    }

    /// Rebuilds clusters and their oscillators at the current time from the mass states and
    /// the contact closures. Merged masses take the momentum-weighted (centre-of-mass)
    /// velocity and position, so internal impulses conserve momentum exactly.
    fn rebuild(&mut self) -> Result<(), SimError> {
        let n = self.x.len();
        for (k, from) in self.search_from.iter_mut().enumerate() {
            // A nudge lasts until something happens at the contact or beyond it in time.
            if *from <= self.t || self.closure[k].is_closed() {
                *from = f64::NEG_INFINITY;
            }
        }
        self.clusters.clear();
        self.consts.clear();
        self.term_scale = 0.0;
        let mut first = 0;
        for i in 0..n {
            let ends = i == n - 1 || !self.closure[i].is_closed();
            if !ends {
                continue;
            }
            let last = i;
            let base = self.offsets[first];
            let mut k = ClusterConsts::default();
            let mut momentum = 0.0;
            let mut moment = 0.0;
            for j in first..=last {
                let m = self.params.masses[j];
                let o = self.offsets[j] - base;
                k.mass += m;
                k.damping += self.params.damping[j];
                k.stiffness += self.params.stiffness[j];
                k.force -= self.params.stiffness[j] * o;
                momentum += m * self.v[j];
                moment += m * (self.x[j] - o);
            }
            let s = moment / k.mass;
            let vs = momentum / k.mass;
            for j in first..=last {
                self.x[j] = s + (self.offsets[j] - base);
                self.v[j] = vs;
            }
            let osc = Oscillator::new(
                OscConstants {
                    mass: k.mass,
                    damping: k.damping,
                    stiffness: k.stiffness,
                    force: k.force,
                },
                &self.forcing,
                self.t,
                s,
                vs,
            )
            .map_err(|_| SimError::UndampedResonance {
                first: first + 1,
                last: last + 1,
            })?;
            self.term_scale = self.term_scale.max(osc.magnitude());
            self.clusters.push(ClusterFlow {
                first,
                last,
                oscillator: osc,
            });
            self.consts.push(k);
            first = i + 1;
        }
        self.refresh_tolerances();
        Ok(())
    }

    /// Index of the cluster containing mass `i`.
    fn cluster_of(&self, i: usize) -> usize {
        self.clusters.partition_point(|c| c.last < i)
    }

    /// Gap of open contact k as a [`Signal`]: d_k = δ_k + o_k^U + s_U − s_L.
    fn gap_signal(&self, k: usize) -> Signal {
        let u = self.cluster_of(k);
        let l = u + 1;
        debug_assert_eq!(self.clusters[l].first, k + 1);
        let w = self.forcing.omega;
        let mut sig = Signal::default();
        sig.add_constant(self.params.gaps[k]);
        sig.add_constant(self.offsets[k] - self.offsets[self.clusters[u].first]);
        sig.add_oscillator(u, &self.clusters[u].oscillator, 1.0, 0.0, w);
        sig.add_oscillator(l, &self.clusters[l].oscillator, -1.0, 0.0, w);
        sig
    }

    /// Contact force of closed contact j (N, compressive positive) as a [`Signal`]:
    /// `N_j = Σ_{i∈G, i≤j} m_i (a_G − a_i)`, written as
    /// `e₀ + e₁ (s − y) + e₂ (s' − y')` for the cluster coordinate s.
    fn force_signal(&self, j: usize) -> Signal {
        let g = self.cluster_of(j);
        let c = &self.clusters[g];
        let kc = &self.consts[g];
        let base = self.offsets[c.first];
        let (mut mj, mut cj, mut kj, mut fj) = (0.0, 0.0, 0.0, 0.0);
        for i in c.first..=j {
            mj += self.params.masses[i];
            cj += self.params.damping[i];
            kj += self.params.stiffness[i];
            fj += self.params.stiffness[i] * (self.offsets[i] - base);
        }
        let r = mj / kc.mass;
        let e1 = kj - r * kc.stiffness;
        let e2 = cj - r * kc.damping;
        // Σ_G k_i o_i = −F₀.
        let e0 = fj + r * kc.force;
        let w = self.forcing.omega;
        let a = self.forcing.amplitude;
        let mut sig = Signal::default();
        sig.add_constant(fj);
        sig.add_constant(r * kc.force);
        debug_assert!((sig.constant - e0).abs() <= 1e-12 * sig.constant_mag.max(1e-300));
        sig.add_oscillator(g, &c.oscillator, e1, e2, w);
        // − e₁ y − e₂ y' with y = A sin ωt, y' = Aω cos ωt.
        sig.add_harmonic(-e2 * a * w, -e1 * a);
        sig
    }

    /// The earliest event in `(t, stop]`, if any.
    fn next_event(&self, stop: f64) -> Result<Option<(f64, Pending)>, SimError> {
        let mut best: Option<(f64, Pending)> = None;
        let mut horizon = stop;
        let w = self.forcing.omega;
        for k in 0..self.closure.len() {
            if let Closure::Chatter { t_acc, .. } = self.closure[k]
                && t_acc < horizon
            {
                horizon = t_acc.max(self.t);
                best = Some((horizon, Pending::ChatterEnd(k)));
            }
            let (sig, start) = match self.closure[k] {
                Closure::Open => (self.gap_signal(k), self.t.max(self.search_from[k])),
                Closure::Resting => {
                    if let Some(found) = self.resting_event(k, horizon)? {
                        horizon = found.0;
                        best = Some(found);
                    }
                    continue;
                }
                _ => (self.force_signal(k), self.t),
            };
            let eval = |t: f64| sig.jet(t, self.forcing.phase(t), &self.clusters, w);
            match first_root(eval, start, horizon) {
                Ok(Found::Root(te)) if te < horizon => {
                    horizon = te.max(self.t);
                    let what = match self.closure[k] {
                        Closure::Open => Pending::Impact {
                            contact: k,
                            at_start: te <= start,
                        },
                        _ => Pending::Release(k),
                    };
                    best = Some((horizon, what));
                }
                Ok(_) => {}
                Err(stall) => return Err(self.stalled(k, stall)),
            }
        }
        Ok(best)
    }

    /// The earliest event of resting contact k before `horizon`, if any: its force falls to
    /// minus its band (it parts) or rises to plus its band (it sticks).
    #[cold]
    fn resting_event(&self, k: usize, horizon: f64) -> Result<Option<(f64, Pending)>, SimError> {
        let band = self.rest_band(k);
        let mut part = self.force_signal(k);
        part.add_constant(band);
        let mut press = part.negated();
        press.add_constant(2.0 * band);
        let w = self.forcing.omega;
        let mut best = None;
        let mut horizon = horizon;
        for (sig, what) in [(part, Pending::Part(k)), (press, Pending::Press(k))] {
            let eval = |t: f64| sig.jet(t, self.forcing.phase(t), &self.clusters, w);
            match first_root(eval, self.t, horizon) {
                Ok(Found::Root(te)) if te < horizon => {
                    horizon = te.max(self.t);
                    best = Some((horizon, what));
                }
                Ok(_) => {}
                Err(stall) => return Err(self.stalled(k, stall)),
            }
        }
        Ok(best)
    }

    /// The error for a search of contact k that could not separate a zero from its start.
    #[cold]
    fn stalled(&self, k: usize, stall: Stall) -> SimError {
        SimError::Stalled {
            t: stall.t,
            what: match self.closure[k] {
                Closure::Open => format!("the gap of contact {}", k + 1),
                _ => format!("the contact force of contact {}", k + 1),
            },
        }
    }

    /// The force band of resting contact k, N: [`REST_BAND`] times the acceleration tolerance
    /// times the reduced mass of the two parts of its cluster (the force that makes their
    /// relative acceleration equal to the tolerance).
    fn rest_band(&self, k: usize) -> f64 {
        let c = &self.clusters[self.cluster_of(k)];
        let upper: f64 = self.params.masses[c.first..=k].iter().sum();
        let lower: f64 = self.params.masses[k + 1..=c.last].iter().sum();
        REST_BAND * self.acc_tol * upper * lower / (upper + lower)
    }

    fn handle(&mut self, what: Pending) -> Result<(), SimError> {
        self.refresh_tolerances();
        // Contacts struck at this event (none unless it is an impact).
        self.scratch_first_speed.fill(f64::NAN);
        match what {
            Pending::Impact { contact, at_start } => {
                let struck = self.resolve_impacts(contact)?;
                // A touch at the search start with no closing speed is the rounding of the
                // event function (as for the gap of a just-released contact), not a new
                // contact state: only a contact that presses beyond rounding closes there.
                let quiet = at_start && !struck;
                let stuck = self.settle(None, quiet);
                if quiet && stuck.is_empty() {
                    // A rounding-level touch at the search start that changes nothing: not an
                    // event. Search this contact again from a hair later.
                    self.scratch_events.clear();
                    let nudge = (NUDGE * self.forcing.period).max(8.0 * f64::EPSILON * self.t.abs());
                    self.search_from[contact] = self.t + nudge;
                }
            }
            Pending::Release(j) => {
                self.closure[j] = Closure::Open;
                self.sequence[j] = 0;
                self.last_speed[j] = f64::INFINITY;
                self.push_event(EventKind::Release, j, 0.0, 0.0, 0);
                self.settle(Some(j), false);
            }
            Pending::Press(j) => {
                self.closure[j] = Closure::Stuck;
                self.sequence[j] = 0;
                self.last_speed[j] = f64::INFINITY;
                self.push_event(EventKind::Stick, j, 0.0, 0.0, 0);
            }
            Pending::Part(j) => {
                self.closure[j] = Closure::Open;
                self.settle(Some(j), false);
            }
            Pending::ChatterEnd(j) => {
                let impacts = match self.closure[j] {
                    Closure::Chatter { impacts, .. } => impacts,
                    _ => 0,
                };
                self.push_event(EventKind::Chatter, j, 0.0, 0.0, impacts);
                // The accumulation point: stick if the contact presses, else release.
                self.closure[j] = Closure::Stuck;
                let was_open_before = self.settle(None, false);
                if !was_open_before.contains(&j) {
                    // settle() logged nothing for j: it stays closed, now as a stuck contact.
                    self.push_event(EventKind::Stick, j, 0.0, 0.0, 0);
                }
                self.sequence[j] = 0;
                self.last_speed[j] = f64::INFINITY;
            }
        }
        self.project_contacts();
        self.rebuild()
    }

    /// Removes rounding-level overlap at open contacts: at an event located to within an ulp
    /// of time, a fast closing speed still leaves the gap slightly negative (v × ulp(t)). The
    /// two clusters are pushed apart to zero gap about their common centre of mass (a shift of
    /// order 1e-15 m; momentum is untouched).
    fn project_contacts(&mut self) {
        for _sweep in 0..3 {
            let mut moved = false;
            for k in 0..self.closure.len() {
                if self.closure[k].is_closed() {
                    continue;
                }
                let gap = self.gap(k);
                if gap >= 0.0 {
                    continue;
                }
                debug_assert!(gap > -1e6 * self.pos_tol, "overlap {gap:e} at contact {k}");
                let up = self.cluster_range(k);
                let low = self.cluster_range(k + 1);
                let (mu, ml) = (self.range_mass(up), self.range_mass(low));
                let overlap = -gap;
                for i in up.0..=up.1 {
                    self.x[i] += overlap * ml / (mu + ml);
                }
                for i in low.0..=low.1 {
                    self.x[i] -= overlap * mu / (mu + ml);
                }
                // Rounding of the shift itself: make the lower side exact.
                let residual = self.gap(k);
                if residual < 0.0 {
                    for i in low.0..=low.1 {
                        self.x[i] += residual;
                    }
                }
                moved = true;
            }
            if !moved {
                break;
            }
        }
    }

    fn push_event(&mut self, kind: EventKind, contact: usize, before: f64, after: f64, seq: u32) {
        self.scratch_events.push(Event {
            time: self.t,
            kind,
            contact,
            velocity_before: before,
            velocity_after: after,
            sequence_impacts: seq,
        });
    }

    /// Current gap at contact k, m (negative: overlap).
    #[inline]
    fn gap(&self, k: usize) -> f64 {
        self.params.gaps[k] - (self.x[k + 1] - self.x[k])
    }

    /// Total mass and range of the cluster containing mass `i`, following the current
    /// closures (clusters may have been merged since the last rebuild).
    fn cluster_range(&self, i: usize) -> (usize, usize) {
        let mut first = i;
        while first > 0 && self.closure[first - 1].is_closed() {
            first -= 1;
        }
        let mut last = i;
        while last + 1 < self.x.len() && self.closure[last].is_closed() {
            last += 1;
        }
        (first, last)
    }

    fn range_mass(&self, (first, last): (usize, usize)) -> f64 {
        self.params.masses[first..=last].iter().sum()
    }

    /// Applies pairwise cluster impacts until no closed contact approaches, logs one impact
    /// per contact struck (and a grazing touch of speed 0 at `trigger` if it was reached with
    /// no closing speed), then replaces each geometric chatter tail by its accumulation point
    /// where it is safe to. Returns whether any impulse was applied. Resting contacts take
    /// part as the open touching contacts they are (Newton's cradle); they stay resting if
    /// nothing is struck, and are decided again by [`settle`](Self::settle) otherwise.
    fn resolve_impacts(&mut self, trigger: usize) -> Result<bool, SimError> {
        let mu = self.params.restitution;
        let ncont = self.closure.len();
        for (closure, resting) in self.closure.iter_mut().zip(self.scratch_resting.iter_mut()) {
            *resting = *closure == Closure::Resting;
            if *resting {
                *closure = Closure::Open;
            }
        }
        let mut iterations = 0;
        loop {
            let mut best: Option<(usize, f64)> = None;
            for k in 0..ncont {
                if self.closure[k].is_closed() {
                    continue;
                }
                let gap = self.gap(k);
                // The trigger is at zero gap by the search's verdict.
                if gap > self.pos_tol && k != trigger {
                    continue;
                }
                let vc = self.v[k + 1] - self.v[k];
                if vc > self.vel_tol {
                    if self.scratch_first_speed[k].is_nan() {
                        self.scratch_first_speed[k] = vc;
                    }
                    if best.is_none_or(|(_, b)| vc > b) {
                        best = Some((k, vc));
                    }
                }
            }
            let Some((k, vc)) = best else { break };
            iterations += 1;
            if iterations > self.options.max_impact_iterations {
                return Err(SimError::ImpactIteration {
                    t: self.t,
                    iterations,
                });
            }
            let up = self.cluster_range(k);
            let low = self.cluster_range(k + 1);
            let mu_mass = self.range_mass(up);
            let ml_mass = self.range_mass(low);
            let impulse = (1.0 + mu) * vc * mu_mass * ml_mass / (mu_mass + ml_mass);
            for i in up.0..=up.1 {
                self.v[i] += impulse / mu_mass;
            }
            for i in low.0..=low.1 {
                self.v[i] -= impulse / ml_mass;
            }
        }
        let struck = iterations > 0;
        if !struck {
            for (closure, &resting) in self.closure.iter_mut().zip(&self.scratch_resting) {
                if resting {
                    *closure = Closure::Resting;
                }
            }
        }
        if self.scratch_first_speed[trigger].is_nan() {
            // Reached with no closing speed: a grazing touch, logged as an impact of speed 0.
            self.scratch_first_speed[trigger] = 0.0;
        }
        for k in 0..ncont {
            let before = self.scratch_first_speed[k];
            if before.is_nan() {
                continue;
            }
            let after = -(self.v[k + 1] - self.v[k]);
            if before > 0.0 {
                if before < self.last_speed[k] {
                    self.sequence[k] += 1;
                } else {
                    self.sequence[k] = 1;
                }
                self.last_speed[k] = before;
            }
            self.push_event(EventKind::Impact, k, before, after, 0);
        }
        if mu < 1.0 {
            for k in 0..ncont {
                let before = self.scratch_first_speed[k];
                if before > 0.0 && !self.closure[k].is_closed() {
                    self.try_chatter_jump(k);
                }
            }
        }
        Ok(struck)
    }

    /// Free acceleration, m/s², and its rate, m/s³, of the cluster occupying `range` (its
    /// members share velocity; x of its top mass is the cluster coordinate).
    fn cluster_accel(&self, (first, last): (usize, usize)) -> (f64, f64) {
        let ph = self.forcing.phase(self.t);
        let (y, yd) = self.forcing.base(ph);
        let ydd = -self.forcing.omega * self.forcing.omega * y;
        let base = self.offsets[first];
        let (mut m, mut c, mut k, mut f) = (0.0, 0.0, 0.0, 0.0);
        for i in first..=last {
            m += self.params.masses[i];
            c += self.params.damping[i];
            k += self.params.stiffness[i];
            f -= self.params.stiffness[i] * (self.offsets[i] - base);
        }
        let s = self.x[first];
        let v = self.v[first];
        let a = (-c * (v - yd) - k * (s - y) + f) / m;
        let j = (-c * (a - ydd) - k * (v - yd)) / m;
        (a, j)
    }

    /// After an impact at open contact k: if the rebound is the start of a chatter tail whose
    /// constant-acceleration limit is accurate to the tolerance, merge the two sides and
    /// schedule the accumulation point.
    fn try_chatter_jump(&mut self, k: usize) {
        let mu = self.params.restitution;
        let u = -(self.v[k + 1] - self.v[k]);
        if u <= self.vel_tol {
            return; // zero rebound: settle() decides.
        }
        let up = self.cluster_range(k);
        let low = self.cluster_range(k + 1);
        let (au, ju) = self.cluster_accel(up);
        let (al, jl) = self.cluster_accel(low);
        // d'' = a_U − a_L; closing acceleration a = −d''.
        let a = al - au;
        let jerk = (ju - jl).abs();
        if a <= self.acc_tol {
            return;
        }
        let flight = 2.0 * u / a;
        let remaining = flight / (1.0 - mu);
        // First-order effect of the changing acceleration on the remaining flights
        // Σ τ_n² j/a, with a safety factor of 4 (checked against an independent bounce-by-bounce
        // integration in tests/special_cases.rs).
        let error = 4.0 * jerk / a * flight * flight / (1.0 - mu * mu);
        // Resolving the next bounce individually cannot time it better than the gap's
        // rounding (about two ulps of the positions) over the rebound speed; below that, the
        // jump is the more accurate choice.
        let rounding = 2.0 * f64::EPSILON * (self.pos_tol / TOL) / u;
        let tolerance = (self.options.chatter_tolerance * self.forcing.period).max(rounding);
        if error <= tolerance && jerk * remaining <= 0.1 * a {
            self.closure[k] = Closure::Chatter {
                t_acc: self.t + remaining,
                impacts: self.sequence[k],
            };
            // Merge now (momentum-conserving) so that later checks see the new cluster.
            self.merge_range(self.cluster_range(k));
        }
    }

    /// Gives the masses of `range` their common centre-of-mass velocity and consistent
    /// positions.
    fn merge_range(&mut self, (first, last): (usize, usize)) {
        let base = self.offsets[first];
        let (mut m, mut p, mut q) = (0.0, 0.0, 0.0);
        for i in first..=last {
            let mi = self.params.masses[i];
            m += mi;
            p += mi * self.v[i];
            q += mi * (self.x[i] - (self.offsets[i] - base));
        }
        for i in first..=last {
            self.v[i] = p / m;
            self.x[i] = q / m + (self.offsets[i] - base);
        }
    }

    /// Decides which contacts at zero gap and zero relative velocity are closed, by the
    /// contact LCP (see module docs): stuck where the force is compressive, resting where the
    /// force and the gap acceleration are both zero within rounding, open where the gap
    /// accelerates apart. Logs a `Stick` for each contact that starts pressing and a `Release`
    /// for each that stops; returns the contacts that were logged. `exclude` is a contact that
    /// has just released and must not close again at once.
    ///
    /// A touching contact left open has its rounding-level relative velocity removed, the two
    /// sides taking their common centre-of-mass velocity. A `quiet` settle (after a touch that
    /// changed nothing, see `handle`) decides sticking and release as always, but starts no
    /// resting contact and adjusts no velocity.
    fn settle(&mut self, exclude: Option<usize>, quiet: bool) -> Vec<usize> {
        let n = self.x.len();
        let ncont = n - 1;
        let (y, yd) = self.forcing.base(self.forcing.phase(self.t));
        let mut any = false;
        for k in 0..ncont {
            let cand = if Some(k) == exclude {
                false
            } else if self.closure[k].is_closed() {
                true
            } else {
                // A contact struck at this instant touches by the impact's verdict: its gap is
                // the event time's rounding times the closing speed, which can exceed the
                // rounding of the positions.
                let touching = self.gap(k) <= self.pos_tol || !self.scratch_first_speed[k].is_nan();
                touching && (self.v[k + 1] - self.v[k]).abs() <= self.vel_tol
            };
            self.scratch_candidate[k] = cand;
            any |= cand;
        }
        if !any {
            return Vec::new();
        }
        // Free accelerations and gap accelerations q_k = a_k − a_{k+1}.
        let p = &self.params;
        let free =
            |i: usize| (-p.damping[i] * (self.v[i] - yd) - p.stiffness[i] * (self.x[i] - y)) / p.masses[i];
        for k in 0..ncont {
            self.scratch_q[k] = free(k) - free(k + 1);
            self.scratch_lambda[k] = 0.0;
            self.scratch_active[k] = false;
        }
        // Chandrasekaran: grow the active set by every candidate with w < 0; at most ncont rounds.
        for _ in 0..=ncont {
            let mut added = false;
            for k in 0..ncont {
                if self.scratch_candidate[k] && !self.scratch_active[k] && self.gap_accel(k) < -self.acc_tol {
                    self.scratch_active[k] = true;
                    added = true;
                }
            }
            if !added {
                break;
            }
            self.solve_active_forces();
        }
        let mut logged = Vec::new();
        for k in 0..ncont {
            let before = self.closure[k];
            let after = if self.scratch_active[k] {
                if before.presses() { before } else { Closure::Stuck }
            } else if self.scratch_candidate[k]
                && (!quiet || before == Closure::Resting)
                && self.gap_accel(k) <= self.acc_tol
            {
                Closure::Resting
            } else {
                Closure::Open
            };
            self.closure[k] = after;
            if after.presses() && !before.presses() {
                self.sequence[k] = 0;
                self.last_speed[k] = f64::INFINITY;
                self.push_event(EventKind::Stick, k, 0.0, 0.0, 0);
                logged.push(k);
            } else if before.presses() && !after.presses() {
                self.push_event(EventKind::Release, k, 0.0, 0.0, 0);
                logged.push(k);
            }
        }
        if !quiet {
            self.equalize_touching();
        }
        logged
    }

    /// Gives each group of masses joined by touching contacts (closed ones, and open ones with
    /// a rounding-level relative velocity, the candidates of [`settle`](Self::settle)) that
    /// contains an open one their common centre-of-mass velocity, if they differ: a plastic
    /// impulse of rounding size (momentum kept, energy never gained). The whole group at once:
    /// equalizing one contact after another, or merging a closed cluster in it later, would
    /// leave a rounding-level relative velocity across the open contact again.
    fn equalize_touching(&mut self) {
        let ncont = self.closure.len();
        let mut first = 0;
        let mut open = false;
        for k in 0..=ncont {
            if k < ncont && (self.closure[k].is_closed() || self.scratch_candidate[k]) {
                open |= !self.closure[k].is_closed();
                continue;
            }
            let v = &mut self.v[first..=k];
            if open && v.iter().any(|&vi| vi != v[0]) {
                let m = &self.params.masses[first..=k];
                let total: f64 = m.iter().sum();
                let momentum: f64 = m.iter().zip(v.iter()).map(|(m, v)| m * v).sum();
                v.fill(momentum / total);
            }
            first = k + 1;
            open = false;
        }
    }

    /// w_k = q_k + (Wλ)_k for the chain's tridiagonal Delassus matrix W.
    fn gap_accel(&self, k: usize) -> f64 {
        let m = &self.params.masses;
        let lam = &self.scratch_lambda;
        let mut w = self.scratch_q[k] + lam[k] * (1.0 / m[k] + 1.0 / m[k + 1]);
        if k > 0 {
            w -= lam[k - 1] / m[k];
        }
        if k + 1 < lam.len() {
            w -= lam[k + 1] / m[k + 1];
        }
        w
    }

    /// Solves `W_AA λ_A = −q_A` on each run of consecutive active contacts (Thomas algorithm).
    fn solve_active_forces(&mut self) {
        let m = &self.params.masses;
        let ncont = self.scratch_q.len();
        let mut k = 0;
        while k < ncont {
            if !self.scratch_active[k] {
                self.scratch_lambda[k] = 0.0;
                k += 1;
                continue;
            }
            let start = k;
            while k < ncont && self.scratch_active[k] {
                k += 1;
            }
            // Forward sweep on [start, k): diag b_j = 1/m_j + 1/m_{j+1}, sub a_j = −1/m_j,
            // super c_j = −1/m_{j+1}. Store modified super in lambda temporarily via a
            // small local buffer.
            let len = k - start;
            let mut cprime = [0.0f64; 64];
            let mut dprime = [0.0f64; 64];
            let mut heap_c;
            let mut heap_d;
            let (cp, dp): (&mut [f64], &mut [f64]) = if len <= 64 {
                (&mut cprime[..len], &mut dprime[..len])
            } else {
                heap_c = vec![0.0; len];
                heap_d = vec![0.0; len];
                (&mut heap_c[..], &mut heap_d[..])
            };
            for (idx, j) in (start..k).enumerate() {
                let b = 1.0 / m[j] + 1.0 / m[j + 1];
                let a = -1.0 / m[j];
                let c = -1.0 / m[j + 1];
                let rhs = -self.scratch_q[j];
                if idx == 0 {
                    cp[0] = c / b;
                    dp[0] = rhs / b;
                } else {
                    let denom = b - a * cp[idx - 1];
                    cp[idx] = c / denom;
                    dp[idx] = (rhs - a * dp[idx - 1]) / denom;
                }
            }
            for idx in (0..len).rev() {
                let val = if idx + 1 < len {
                    dp[idx] - cp[idx] * self.scratch_lambda[start + idx + 1]
                } else {
                    dp[idx]
                };
                self.scratch_lambda[start + idx] = val.max(0.0);
            }
        }
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
