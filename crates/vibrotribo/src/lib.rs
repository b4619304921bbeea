//! # vibrotribo
//!
//! Exact, event-driven simulation of vibro-impact triboelectric energy harvesters: a chain of
//! N ≥ 2 masses on springs and dampers, driven through a common base, that collide with
//! their neighbours (Nonlinear Dynamics 2018, "Nonlinear dynamics and triboelectric energy
//! harvesting from a three-degree-of-freedom vibro-impact oscillator", generalised).
//!
//! ## A short tour
//!
//! - [`ChainParams`] holds the physical parameters (SI units; [`Default`] is the paper's
//!   default case) and validates them; [`SimOptions`] the numerical settings.
//! - [`Simulator`] advances the chain exactly: between events every mass or stuck cluster is
//!   a linear oscillator with a closed-form solution, and events (impacts, sticking, release,
//!   chatter accumulation points) are zeros of explicit functions of time, located by a
//!   certified search that cannot step over a grazing contact. See [`dynamics`].
//! - An [`Observer`] watches a run: [`EventLog`] keeps the events, [`Trajectory`] keeps the
//!   exact flow for evaluation at any time, [`UniformSampler`] samples it on a grid.
//! - [`sensitivity`] differentiates the non-smooth flow exactly (state-transition matrix with
//!   saltation matrices at impacts, sticking, release and chatter jumps) and in parameters.
//!   Matrices are [`nalgebra`]'s, re-exported here.
//! - [`orbits`] finds periodic orbits by shooting (stable or not), their Floquet multipliers,
//!   and continues them in a parameter through folds, period doublings (cascades included),
//!   Neimark–Sacker points, grazings and the onset of sticking.
//! - [`lyapunov`] computes all 2N Lyapunov exponents through impacts, sticking and chatter
//!   from the same state-transition matrix, with a batch-means error bar.
//! - [`attractors`] finds the attractors that starts end on (by their stroboscopic sets),
//!   their basin fractions and powers, and follows them across a parameter.
//!
//! ```
//! use vibrotribo::{ChainParams, ChainState, EventKind, EventLog, SimOptions, Simulator};
//!
//! let params = ChainParams::default();
//! let mut sim = Simulator::new(&params, &ChainState::at_rest(params.len()), SimOptions::default())?;
//! let mut log = EventLog::default();
//! sim.run_until(10.0 * params.period(), &mut log)?;
//! let impacts = log.events.iter().filter(|e| e.event.kind == EventKind::Impact).count();
//! assert!(impacts > 10);
//! # Ok::<(), vibrotribo::SimError>(())
//! ```
#![warn(missing_docs)]

pub mod analysis;
pub mod attractors;
#[cfg(feature = "config")]
pub mod branch;
#[cfg(feature = "config")]
pub mod config;
pub mod coupling;
pub mod dynamics;
pub mod electrical;
mod error;
pub mod excitation;
pub mod lyapunov;
pub mod model;
pub mod orbits;
mod random;
#[cfg(feature = "config")]
pub mod report;
pub mod sensitivity;
pub mod study;
#[cfg(feature = "config")]
pub mod sweep;

pub use nalgebra;

pub use dynamics::{
    ContactStatus, Event, EventKind, EventLog, Flow, Observer, RunEnd, Segment, Simulator, StateView,
    Trajectory, UniformSampler,
};
pub use error::{ParamError, SimError};
pub use model::{
    ChainParams, ChainState, Excitation, ForcePolynomial, Frequency, NondimGroups, SimOptions, Stop,
    StopFrame, StopSide, Stops,
};
