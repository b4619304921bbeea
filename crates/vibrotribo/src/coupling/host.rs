//! Who a coupled run reports to ([`ChargeHost`]: the observer that owns the charge solver) and
//! the observer of one trial window ([`Trial`]).

use std::ops::ControlFlow;

use crate::dynamics::{Event, Flow, Observer, Segment, StateView, Verdict};
use crate::electrical::ChargeSolver;

/// What a coupled run reports to: an [`Observer`] of the accepted motion that also owns the
/// charge solver the run advances. Its `flow` must not advance that solver again.
pub trait ChargeHost: Observer {
    /// The charge solver (advanced by the coupled run, which also rewinds it).
    fn charge_solver(&mut self) -> &mut ChargeSolver;
}

/// A [`ChargeHost`] that only holds the solver (no other observer).
#[derive(Debug, Clone)]
pub struct SolverOnly(pub ChargeSolver);

impl Observer for SolverOnly {}

impl ChargeHost for SolverOnly {
    fn charge_solver(&mut self) -> &mut ChargeSolver {
        &mut self.0
    }
}

/// The observer of a trial window: advances the host's solver over the flow, records the
/// flow and events for the host, and stops at the first event.
pub(super) struct Trial<'a, H: ?Sized> {
    pub host: &'a mut H,
    pub segments: &'a mut Vec<Segment>,
    pub events: &'a mut Vec<(Event, Vec<f64>, Vec<f64>)>,
}

impl<H: ChargeHost + ?Sized> Observer for Trial<'_, H> {
    fn flow(&mut self, flow: &Flow<'_>) {
        self.host.charge_solver().flow(flow);
        self.segments.push(flow.to_segment());
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.events
            .push((*event, state.positions.to_vec(), state.velocities.to_vec()));
    }

    fn proceed(&mut self) -> Verdict {
        let _ = self.host.charge_solver().proceed()?;
        if self.events.is_empty() {
            Ok(ControlFlow::Continue(()))
        } else {
            Ok(ControlFlow::Break(()))
        }
    }
}
