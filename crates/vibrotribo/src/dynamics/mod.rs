//! Exact event-driven mechanics of the chain: closed-form flow, certified event location,
//! impact law, sticking, release and chatter.
//!
//! Entry point: [`Simulator`]. Output goes to an [`Observer`]; ready-made observers are
//! [`EventLog`], [`Trajectory`] (dense output at any time) and [`UniformSampler`].

mod base;
mod contact;
mod forces;
mod observer;
mod oscillator;
pub(crate) mod poly;
mod polyroot;
pub(crate) mod response;
mod roots;
mod search;
mod signal;
mod simulator;
mod taylor;

pub use base::{
    BaseDisplacement, MULTISINE_RELATIVE_TOLERANCE, as_chain_harmonic, check_base_motion, driven_chain,
    is_chain_harmonic, multisine_tolerance,
};
pub use observer::{
    ClusterFlow, Event, EventKind, EventLog, Flow, LoggedEvent, Observer, ObserverError, Segment, StateView,
    Trajectory, UniformSampler, Verdict,
};
pub(crate) use oscillator::Forcing;
pub use oscillator::Oscillator;
pub use simulator::{ContactStatus, RunEnd, Simulator, initial_state};
pub(crate) use taylor::{GapPolynomial, MAX_COEFFICIENTS};
