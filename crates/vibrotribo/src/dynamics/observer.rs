//! What a simulation reports: events, the exact flow between them, and observers.
//!
//! The [`Simulator`](super::Simulator) calls an [`Observer`] with every piece of flow (a time
//! interval on which each cluster follows one closed-form oscillator) and every event. An
//! analysis (a Poincaré section, an impact map, the electrical solver) is an observer; a
//! bifurcation diagram is a sweep with such an observer attached. All methods have no-op
//! defaults.

use std::ops::ControlFlow;

use super::oscillator::{Forcing, Oscillator};

/// What happened at an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum EventKind {
    /// Two clusters met with a closing velocity and rebounded (Newton's law, seed eqs. 7–8
    /// generalised to clusters). A closing speed of zero is a grazing touch.
    Impact,
    /// A contact closed with zero relative velocity under compressive contact force: the
    /// two sides move on as one cluster.
    Stick,
    /// A stuck contact's force fell to zero: the cluster splits there.
    Release,
    /// A chatter sequence (infinitely many impacts of geometrically falling velocity) was
    /// replaced by its accumulation point (Budd & Dux); a `Stick` or `Release` follows at the
    /// same time.
    Chatter,
}

impl EventKind {
    /// Lower-case name as written in `events.csv`: `impact`, `stick`, `release`, `chatter`.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::Impact => "impact",
            EventKind::Stick => "stick",
            EventKind::Release => "release",
            EventKind::Chatter => "chatter",
        }
    }
}

/// One event of the simulation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Time, s.
    pub time: f64,
    /// What happened.
    pub kind: EventKind,
    /// Contact index k, 0-based: contact k is the gap between mass k and mass k+1 (so the
    /// paper's contact "m1–m2" is 0 here and 1 in files); with rigid stops, N − 1 is the lower
    /// stop and N the upper one ([`ChainParams::contact`](crate::ChainParams::contact)).
    pub contact: usize,
    /// For an impact, the closing speed just before it (≥ 0), m/s; 0 otherwise.
    pub velocity_before: f64,
    /// For an impact, the opening speed just after it, m/s (μ × the closing speed for an
    /// isolated impact); 0 otherwise.
    pub velocity_after: f64,
    /// For a `Chatter` event: impacts resolved one by one in this sequence before the jump to
    /// its accumulation point; 0 otherwise.
    pub sequence_impacts: u32,
}

/// Positions and velocities of all masses at one instant, borrowed from the simulator.
#[derive(Debug, Clone, Copy)]
pub struct StateView<'a> {
    /// Time, s.
    pub time: f64,
    /// Positions x_i, m.
    pub positions: &'a [f64],
    /// Velocities x_i', m/s.
    pub velocities: &'a [f64],
}

/// A contiguous group of masses moving as one body (a single mass, or masses stuck together).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClusterFlow {
    /// First (top) mass, 0-based.
    pub first: usize,
    /// Last (bottom) mass, 0-based, inclusive.
    pub last: usize,
    /// Closed-form motion of the cluster's top mass.
    pub oscillator: Oscillator,
    /// The rigid stop the cluster is stuck to, if any (its motion is then the stop's,
    /// [`Oscillator::is_prescribed`]).
    pub stop: Option<crate::model::StopSide>,
}

/// The exact motion of the whole chain on `[t_start, t_end]`, between two events.
#[derive(Debug, Clone, Copy)]
pub struct Flow<'a> {
    /// Start of the interval, s.
    pub t_start: f64,
    /// End of the interval, s.
    pub t_end: f64,
    pub(crate) clusters: &'a [ClusterFlow],
    pub(crate) offsets: &'a [f64],
    pub(crate) gaps: &'a [f64],
    pub(crate) forcing: &'a Forcing,
}

impl Flow<'_> {
    /// Number of masses.
    pub fn len(&self) -> usize {
        self.offsets.len()
    }

    /// Always false (a chain has at least two masses).
    pub fn is_empty(&self) -> bool {
        self.offsets.is_empty()
    }

    /// The clusters (top to bottom) during this interval.
    pub fn clusters(&self) -> &[ClusterFlow] {
        self.clusters
    }

    /// Positions, m, and velocities, m/s, of all masses at time `t` (meant for
    /// `t ∈ [t_start, t_end]`; the closed form extends beyond but ignores events there).
    pub fn state_at(&self, t: f64, positions: &mut [f64], velocities: &mut [f64]) {
        let ph = self.forcing.phase(t);
        for c in self.clusters {
            let (s, v) = c.oscillator.state(t, ph);
            let base = self.offsets[c.first];
            for i in c.first..=c.last {
                positions[i] = s + (self.offsets[i] - base);
                velocities[i] = v;
            }
        }
    }

    /// Gaps d_k, m, and their rates d_k', m/s, at time `t` (length N − 1 each).
    pub fn gaps_at(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        let n = self.len();
        let mut x = [0.0; 64];
        let mut v = [0.0; 64];
        if n <= 64 {
            self.state_at(t, &mut x[..n], &mut v[..n]);
            fill_gaps(self.gaps, &x[..n], &v[..n], gaps, rates);
        } else {
            let mut x = vec![0.0; n];
            let mut v = vec![0.0; n];
            self.state_at(t, &mut x, &mut v);
            fill_gaps(self.gaps, &x, &v, gaps, rates);
        }
    }

    /// Base displacement y, m, and velocity y', m/s, at time `t`.
    pub fn base_at(&self, t: f64) -> (f64, f64) {
        self.forcing.base(self.forcing.phase(t))
    }

    /// An owned copy, for storing the trajectory.
    pub fn to_segment(&self) -> Segment {
        Segment {
            t_start: self.t_start,
            t_end: self.t_end,
            clusters: self.clusters.to_vec(),
        }
    }
}

fn fill_gaps(delta: &[f64], x: &[f64], v: &[f64], gaps: &mut [f64], rates: &mut [f64]) {
    for k in 0..delta.len() {
        gaps[k] = delta[k] - (x[k + 1] - x[k]);
        rates[k] = -(v[k + 1] - v[k]);
    }
}

/// An owned piece of flow (see [`Flow`]); a [`Trajectory`] is a sequence of them.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Start of the interval, s.
    pub t_start: f64,
    /// End of the interval, s.
    pub t_end: f64,
    /// The clusters and their closed-form motion.
    pub clusters: Vec<ClusterFlow>,
}

/// An observer's failure, which ends the run (see [`Observer::proceed`]).
pub type ObserverError = Box<dyn std::error::Error + Send + Sync>;

/// What an observer says after a piece of flow or an event: go on, stop the run
/// (`Ok(ControlFlow::Break(()))`), or fail it (`Err`).
pub type Verdict = Result<ControlFlow<()>, ObserverError>;

/// Receives the output of a simulation. Every method has a no-op default.
pub trait Observer {
    /// Called with each interval of exact flow, in time order, before the event that ends it.
    fn flow(&mut self, _flow: &Flow<'_>) {}
    /// Called after each event with the state just after it.
    fn event(&mut self, _event: &Event, _state: &StateView<'_>) {}
    /// Asked after every piece of flow and every batch of events: whether the run goes on.
    /// `Break` stops [`Simulator::run_until`](super::Simulator::run_until) there (it returns
    /// [`RunEnd::Stopped`](super::RunEnd::Stopped)); `Err` fails the run with
    /// [`SimError::Observer`](crate::SimError::Observer). Default: go on.
    fn proceed(&mut self) -> Verdict {
        Ok(ControlFlow::Continue(()))
    }
}

impl Observer for () {}

impl<O: Observer + ?Sized> Observer for &mut O {
    fn flow(&mut self, flow: &Flow<'_>) {
        (**self).flow(flow)
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        (**self).event(event, state)
    }
    fn proceed(&mut self) -> Verdict {
        (**self).proceed()
    }
}

impl<O: Observer + ?Sized> Observer for Box<O> {
    fn flow(&mut self, flow: &Flow<'_>) {
        (**self).flow(flow)
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        (**self).event(event, state)
    }
    fn proceed(&mut self) -> Verdict {
        (**self).proceed()
    }
}

/// An optional observer: `None` observes nothing.
impl<O: Observer> Observer for Option<O> {
    fn flow(&mut self, flow: &Flow<'_>) {
        if let Some(o) = self {
            o.flow(flow)
        }
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        if let Some(o) = self {
            o.event(event, state)
        }
    }
    fn proceed(&mut self) -> Verdict {
        match self {
            Some(o) => o.proceed(),
            None => Ok(ControlFlow::Continue(())),
        }
    }
}

impl<O: Observer> Observer for Vec<O> {
    fn flow(&mut self, flow: &Flow<'_>) {
        for o in self.iter_mut() {
            o.flow(flow)
        }
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        for o in self.iter_mut() {
            o.event(event, state)
        }
    }
    fn proceed(&mut self) -> Verdict {
        for o in self.iter_mut() {
            if let v @ (Err(_) | Ok(ControlFlow::Break(()))) = o.proceed() {
                return v;
            }
        }
        Ok(ControlFlow::Continue(()))
    }
}

macro_rules! tuple_observer {
    ($($name:ident $idx:tt),+) => {
        impl<$($name: Observer),+> Observer for ($($name,)+) {
            fn flow(&mut self, flow: &Flow<'_>) {
                $(self.$idx.flow(flow);)+
            }
            fn event(&mut self, event: &Event, state: &StateView<'_>) {
                $(self.$idx.event(event, state);)+
            }
            fn proceed(&mut self) -> Verdict {
                $(
                    if let v @ (Err(_) | Ok(ControlFlow::Break(()))) = self.$idx.proceed() {
                        return v;
                    }
                )+
                Ok(ControlFlow::Continue(()))
            }
        }
    };
}
tuple_observer!(A 0);
tuple_observer!(A 0, B 1);
tuple_observer!(A 0, B 1, C 2);
tuple_observer!(A 0, B 1, C 2, D 3);
tuple_observer!(A 0, B 1, C 2, D 3, E 4);
tuple_observer!(A 0, B 1, C 2, D 3, E 4, F 5);

/// One logged event with the state at it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoggedEvent {
    /// The event.
    pub event: Event,
    /// Positions x_i at the event, m.
    pub positions: Vec<f64>,
    /// Velocities x_i' just after the event, m/s.
    pub velocities: Vec<f64>,
}

/// Records every event with the state at it.
#[derive(Debug, Clone, Default)]
pub struct EventLog {
    /// The events in time order.
    pub events: Vec<LoggedEvent>,
}

impl Observer for EventLog {
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.events.push(LoggedEvent {
            event: *event,
            positions: state.positions.to_vec(),
            velocities: state.velocities.to_vec(),
        });
    }
}

/// Records the exact trajectory (every segment of flow) for dense evaluation at any time.
#[derive(Debug, Clone)]
pub struct Trajectory {
    segments: Vec<Segment>,
    offsets: Vec<f64>,
    gaps: Vec<f64>,
    forcing: Forcing,
}

impl Trajectory {
    /// An empty trajectory for the chain simulated by `sim`.
    pub fn new(sim: &super::Simulator) -> Self {
        Trajectory {
            segments: Vec::new(),
            offsets: sim.offsets().to_vec(),
            gaps: sim.params().gaps.clone(),
            forcing: *sim.forcing(),
        }
    }

    /// An empty trajectory for a simulation of `chain` (the same as [`new`](Self::new) on
    /// a simulator of it).
    pub fn for_chain(chain: &crate::ChainParams) -> Self {
        let mut offsets = vec![0.0; chain.len()];
        for i in 1..offsets.len() {
            offsets[i] = offsets[i - 1] + chain.gaps[i - 1];
        }
        Trajectory {
            segments: Vec::new(),
            offsets,
            gaps: chain.gaps.clone(),
            forcing: Forcing::new(chain.excitation.amplitude, chain.omega()),
        }
    }

    /// The recorded segments in time order.
    pub fn segments(&self) -> &[Segment] {
        &self.segments
    }

    /// Number of gaps (contacts), N − 1 for a chain of N masses.
    pub fn gap_count(&self) -> usize {
        self.gaps.len()
    }

    /// Time span covered, s.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((self.segments.first()?.t_start, self.segments.last()?.t_end))
    }

    /// The flow piece containing `t` (the later one at an event time), if recorded.
    pub fn flow_at(&self, t: f64) -> Option<Flow<'_>> {
        let idx = self.segments.partition_point(|s| s.t_end <= t);
        let seg = self
            .segments
            .get(idx)
            .or_else(|| self.segments.last().filter(|s| s.t_end == t))?;
        if t < seg.t_start {
            return None;
        }
        Some(Flow {
            t_start: seg.t_start,
            t_end: seg.t_end,
            clusters: &seg.clusters,
            offsets: &self.offsets,
            gaps: &self.gaps,
            forcing: &self.forcing,
        })
    }

    /// Positions, m, and velocities, m/s, at any recorded time `t`. Returns false if `t` is
    /// outside the recorded span.
    pub fn state_at(&self, t: f64, positions: &mut [f64], velocities: &mut [f64]) -> bool {
        match self.flow_at(t) {
            Some(f) => {
                f.state_at(t, positions, velocities);
                true
            }
            None => false,
        }
    }
}

impl Observer for Trajectory {
    fn flow(&mut self, flow: &Flow<'_>) {
        if flow.t_end > flow.t_start {
            self.segments.push(flow.to_segment());
        }
    }
}

/// Samples the state on a uniform time grid `t_j = t0 + j·dt` (j = 0, 1, …) as the flow goes
/// by, without storing the trajectory.
#[derive(Debug, Clone)]
pub struct UniformSampler {
    t0: f64,
    dt: f64,
    next: u64,
    n: usize,
    /// Sample times, s.
    pub times: Vec<f64>,
    /// Positions, m, flattened row-major (`positions[j*N + i]`).
    pub positions: Vec<f64>,
    /// Velocities, m/s, flattened like `positions`.
    pub velocities: Vec<f64>,
}

impl UniformSampler {
    /// Samples every `dt` seconds from `t0` for a chain of `n` masses.
    pub fn new(n: usize, t0: f64, dt: f64) -> Self {
        UniformSampler {
            t0,
            dt,
            next: 0,
            n,
            times: Vec::new(),
            positions: Vec::new(),
            velocities: Vec::new(),
        }
    }
}

impl Observer for UniformSampler {
    fn flow(&mut self, flow: &Flow<'_>) {
        let n = self.n;
        loop {
            let t = self.t0 + self.next as f64 * self.dt;
            // A grid point at an interval's end is taken there (state continuous; velocity
            // just before the event) and not again at the start of the next interval.
            if t > flow.t_end {
                break;
            }
            if t < flow.t_start {
                self.next += 1;
                continue;
            }
            let at = self.positions.len();
            self.positions.resize(at + n, 0.0);
            self.velocities.resize(at + n, 0.0);
            flow.state_at(t, &mut self.positions[at..], &mut self.velocities[at..]);
            self.times.push(t);
            self.next += 1;
        }
    }
}
