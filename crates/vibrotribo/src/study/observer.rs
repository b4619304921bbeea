//! What watches a run of [`simulate`](super::simulate): the exact flow and the events (as a
//! [`dynamics` observer](crate::Observer) sees them), samples on a time grid with the
//! electrical quantities beside the mechanical ones, and a checkpoint after every period
//! where the run can be stopped.

use std::ops::ControlFlow;

use crate::dynamics::{Event, Flow, Observer, StateView};

/// The electrical quantities at one sample time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElectricalSample {
    /// Charge moved between the electrodes Q, C.
    pub charge_c: f64,
    /// Current I = dQ/dt, A.
    pub current_a: f64,
    /// Terminal (load) voltage V, V.
    pub voltage_v: f64,
    /// Transducer capacitance C, F.
    pub capacitance_f: f64,
    /// Open-circuit voltage V_oc, V.
    pub voc_v: f64,
    /// Storage capacitor voltage, V (rectifier only).
    pub storage_voltage_v: Option<f64>,
}

/// One sample of a run: the state of the chain, the base and the gaps at one grid time, and
/// the electrical quantities where the charge is solved.
#[derive(Debug, Clone, Copy)]
pub struct Sample<'a> {
    /// Index j of the sample on its grid.
    pub index: u64,
    /// Time, s.
    pub time: f64,
    /// Positions x_i, m.
    pub positions: &'a [f64],
    /// Velocities, m/s (just before an event at this very time).
    pub velocities: &'a [f64],
    /// Base displacement y, m.
    pub base: f64,
    /// Gaps d_k, m.
    pub gaps: &'a [f64],
    /// The electrical quantities (`None` without a harvester, or before its start).
    pub electrical: Option<ElectricalSample>,
}

/// Watches a run of [`simulate`](super::simulate). Every method has a default; an observer
/// that wants samples says so with [`wants_samples`](Self::wants_samples).
pub trait RunObserver {
    /// Each interval of exact flow, in time order.
    fn flow(&mut self, _flow: &Flow<'_>) {}
    /// Each event, with the state just after it.
    fn event(&mut self, _event: &Event, _state: &StateView<'_>) {}
    /// Whether [`sample`](Self::sample) is to be called (on the run's
    /// [`sampling`](super::RunSpec::sampling) grid).
    fn wants_samples(&self) -> bool {
        false
    }
    /// Each sample of the run's grid, in time order.
    fn sample(&mut self, _sample: &Sample<'_>) {}
    /// After each complete excitation period, with the number of periods done and the state
    /// at `t = periods·T`: whether the run goes on. A checkpoint: the run can stop here with
    /// consistent results.
    fn period(&mut self, _periods: u64, _state: &StateView<'_>) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

impl RunObserver for () {}

impl<O: RunObserver + ?Sized> RunObserver for &mut O {
    fn flow(&mut self, flow: &Flow<'_>) {
        (**self).flow(flow)
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        (**self).event(event, state)
    }
    fn wants_samples(&self) -> bool {
        (**self).wants_samples()
    }
    fn sample(&mut self, sample: &Sample<'_>) {
        (**self).sample(sample)
    }
    fn period(&mut self, periods: u64, state: &StateView<'_>) -> ControlFlow<()> {
        (**self).period(periods, state)
    }
}

impl<A: RunObserver, B: RunObserver> RunObserver for (A, B) {
    fn flow(&mut self, flow: &Flow<'_>) {
        self.0.flow(flow);
        self.1.flow(flow);
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.0.event(event, state);
        self.1.event(event, state);
    }
    fn wants_samples(&self) -> bool {
        self.0.wants_samples() || self.1.wants_samples()
    }
    fn sample(&mut self, sample: &Sample<'_>) {
        self.0.sample(sample);
        self.1.sample(sample);
    }
    fn period(&mut self, periods: u64, state: &StateView<'_>) -> ControlFlow<()> {
        let a = self.0.period(periods, state);
        let b = self.1.period(periods, state);
        if a.is_break() || b.is_break() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// A [`dynamics` observer](crate::Observer) (a [`Trajectory`](crate::Trajectory), an
/// [`EventLog`](crate::EventLog), a Poincaré section…) watching a run of
/// [`simulate`](super::simulate), from time `from`, s, on (flows that start earlier are not
/// passed; events are passed from `from` on).
#[derive(Debug, Clone)]
pub struct Mechanics<O> {
    /// The observer.
    pub inner: O,
    /// Start of what it sees, s.
    pub from: f64,
}

impl<O> Mechanics<O> {
    /// `inner` watching the whole run.
    pub fn new(inner: O) -> Self {
        Mechanics { inner, from: 0.0 }
    }

    /// `inner` watching from time `from`, s, on.
    pub fn starting_at(inner: O, from: f64) -> Self {
        Mechanics { inner, from }
    }
}

impl<O: Observer> RunObserver for Mechanics<O> {
    fn flow(&mut self, flow: &Flow<'_>) {
        if flow.t_start >= self.from {
            self.inner.flow(flow);
        }
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        if event.time >= self.from {
            self.inner.event(event, state);
        }
    }
}

/// Stops a run after the period in which `stop` first returns true (checked at each period's
/// end; e.g. an interrupt flag), and counts the periods done.
pub struct Checkpoint<F> {
    /// Asked at the end of every period.
    pub stop: F,
}

impl<F: FnMut(u64) -> bool> RunObserver for Checkpoint<F> {
    fn period(&mut self, periods: u64, _state: &StateView<'_>) -> ControlFlow<()> {
        if (self.stop)(periods) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}
