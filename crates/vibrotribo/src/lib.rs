//! # vibrotribo
//!
//! Exact, event-driven simulation of vibro-impact triboelectric energy harvesters: a chain of
//! masses on springs and dampers, driven through a common base, that collide with their
//! neighbours and with optional rigid stops (N ≥ 2 masses, or a single mass against a stop),
//! with a triboelectric generator on the contacts (Nonlinear Dynamics 2018, "Nonlinear
//! dynamics and triboelectric energy harvesting from a three-degree-of-freedom vibro-impact
//! oscillator", generalised). The model's equations and conventions are in `docs/MODEL.md`,
//! the user guide in `docs/guide/`.
//!
//! ## A short tour
//!
//! The data flow one way: parameters → engine → run → analyses → output.
//!
//! - **Parameters.** [`ChainParams`] holds the physical parameters (SI units; [`Default`] is
//!   the paper's default case, [`Stops`] the optional rigid stops) and validates them;
//!   [`SimOptions`] the numerical settings. [`config`] reads a TOML configuration (or
//!   overrides of its keys) into the library's types, naming the key at fault in every error,
//!   and writes the configuration reference.
//! - **Base motion.** [`excitation`] describes base motions other than the sine (multisines,
//!   chirps, band-limited noise, records) as interpolants with stated error bounds.
//! - **Engine.** [`Simulator`] advances the chain exactly: between events every mass or stuck
//!   cluster is a linear oscillator with a closed-form solution, and events (impacts,
//!   sticking, release, chatter accumulation points) are zeros of explicit functions of time,
//!   located by a certified search that cannot step over a grazing contact. See [`dynamics`].
//!   An [`Observer`] watches a run: [`EventLog`] keeps the events, [`Trajectory`] keeps the
//!   exact flow for evaluation at any time, [`UniformSampler`] samples it on a grid.
//! - **Harvester.** [`electrical`] has the transducers, the loads (resistor, rectifier, open,
//!   short), the Radau IIA charge solver and the ngspice cross-checks; [`coupling`] lets the
//!   electrostatic force act back on the masses (two-way coupling).
//! - **Runs.** [`study`] is the run layer every front end uses: one entry point that takes a
//!   run's description (chain, base motion, harvester, initial state) and observers and
//!   returns typed results, and the studies built on it (a sweep point with its settling and
//!   motion label, load studies, chirp experiments). [`sweep`] runs grids of points in
//!   parallel and returns their results in columns; [`report`] summarises a run and holds the
//!   manifests of the command line's output directories ([`report::manifest`]), from which
//!   Python's results state their settings.
//! - **Analyses.** [`analysis`] has Poincaré sections, period detection, power spectra and
//!   fits. [`sensitivity`] differentiates the non-smooth flow exactly (state-transition
//!   matrix with saltation matrices at impacts, sticking, release and chatter jumps) and in
//!   parameters; matrices are [`nalgebra`]'s, re-exported here. [`orbits`] finds periodic
//!   orbits by shooting (stable or not), their Floquet multipliers, and continues them in a
//!   parameter through folds, period doublings (cascades included), Neimark–Sacker points,
//!   grazings and the onset of sticking; [`branch`] runs that continuation from a
//!   configuration and a key (what `vibrotribo continue` and Python's `continue_` call), and
//!   [`curve`] follows a located fold, period doubling, Neimark–Sacker point or grazing in a
//!   second key; [`bifmap`] finds a device's fold, doubling, Neimark–Sacker and grazing
//!   curves in a plane of two keys from seed branches. Long searches stop through
//!   [`orbits::Cancel`]. [`lyapunov`] computes all 2N Lyapunov exponents
//!   through impacts, sticking and chatter, with a batch-means error bar. [`attractors`]
//!   finds the attractors that starts end on (by their stroboscopic sets), their basin
//!   fractions and powers, and follows them across a parameter.
//! - **Figures of merit.** [`merit`] has the triboelectric figures of merit of a run: the
//!   cycle for maximised energy output (CMEO), `FOM_S`, the breakdown-limited maximum and the
//!   run's own energy per cycle against them.
//! - **Design.** [`optimize`] maximises average power, expected power over random starts or
//!   power per mass over any numeric configuration keys, under air-breakdown and
//!   displacement constraints (argmin's particle swarm, then Nelder–Mead). [`response`] gives
//!   the power against frequency from up and down sweeps and the branches between them, or
//!   against the centre of a random input's band, with the peak and the half-power bandwidth.
//!
//! The engine alone, ten periods of the paper's default case:
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
//!
//! A configuration, as the command line and Python read it, with one key overridden:
//!
//! ```
//! use vibrotribo::config::Config;
//!
//! let config = Config::default().with("excitation.omega_ratio", 0.6.into())?;
//! assert!((config.chain().omega_ratio() - 0.6).abs() < 1e-12);
//! # Ok::<(), vibrotribo::config::ConfigError>(())
//! ```
#![warn(missing_docs)]

pub mod analysis;
pub mod attractors;
#[cfg(feature = "config")]
pub mod bifmap;
#[cfg(feature = "config")]
pub mod branch;
#[cfg(feature = "config")]
pub mod config;
pub mod coupling;
pub mod curve;
pub mod dynamics;
pub mod electrical;
mod error;
pub mod excitation;
pub mod lyapunov;
pub mod merit;
pub mod model;
#[cfg(feature = "config")]
pub mod optimize;
pub mod orbits;
mod random;
#[cfg(feature = "config")]
pub mod report;
#[cfg(feature = "config")]
pub mod response;
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
