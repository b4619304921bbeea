//! Triboelectric transducers, electrical loads and the charge solver (seed Sect. 3,
//! eqs. 11–14; docs/MODEL.md §2).
//!
//! ## Model
//!
//! The transducer moves a charge `Q` between its electrodes; its terminal voltage is
//! (seed eq. 11)
//!
//! ```text
//! V = −Q/C + V_oc
//! ```
//!
//! with, for the paper's freestanding mode (seed eqs. 12–13, [`Freestanding`]),
//!
//! ```text
//! C = ε₀S / (d₀ + D₁ + D₂),   d₀ = d₁/ε_r1 + d₂/ε_r2,
//! V_oc = 2σD₂/ε₀  (paper)     or     V_oc = σ(D₂ − D₁)/ε₀  (Gauss's law, moving outer plates)
//! ```
//!
//! and for the two-plate contact-separation mode ([`ContactSeparation`])
//! `C = ε₀S/(d₀ + D)`, `V_oc = σD/ε₀`. The gaps D come from the mechanical simulation.
//!
//! Loads ([`Load`]): a resistor (`R dQ/dt = V`, the paper's), a full-wave diode bridge
//! charging a storage capacitor (optionally with a resistor across it; diodes of SPICE's
//! level-1 law with series resistance, [`Diode`]), and the open- and short-circuit limits.
//! The initial charge is the electrostatic equilibrium `Q(0) = C(0)·V_oc(0)` unless given.
//!
//! Average power over N periods after a transient (seed eq. 14):
//! `P_a = R ∫ I² dt / (N T)`, see [`summarize`] and [`power_curve`].
//!
//! ## Pieces
//!
//! - [`HarvesterParams`]: the `[harvester]` table, validated with key names.
//! - [`ChargeSolver`]: Radau IIA with error control (7 stages for the resistor, 3 for the
//!   rectifier), an [`Observer`](crate::Observer) of the simulator, or driven by any
//!   [`GapWaveform`] (e.g. [`PwlGaps`]).
//! - [`load_sweep`]: average power against load resistance on a recorded trajectory, with
//!   the optimum refined.
//! - `spice` (cargo feature `spice`, on by default): ngspice netlists of the same circuit for
//!   cross-checking.

pub mod breakdown;
mod diode;
mod energy;
mod params;
mod radau;
mod solver;
#[cfg(feature = "spice")]
pub mod spice;
mod sweep;
mod table;
mod transducer;
mod waveform;

pub use diode::{BridgeCurrents, Diode};
pub use energy::{Electrostatics, NoFieldEnergy};
pub use params::{
    BOLTZMANN_OVER_CHARGE, EPSILON_0, HarvesterParams, Load, LoadKind, Rectifier, TransducerMode, VocModel,
};
pub use solver::{
    ChargeCheckpoint, ChargeMoments, ChargeOptions, ChargeSolver, ElectricalSamples, PeriodStats,
    PowerSummary, SolverStats, power_curve, summarize,
};
pub use sweep::{LoadPoint, LoadSweep, best_load, check_resistances, load_sweep, log_spaced};
pub use table::HarvesterTable;
pub use transducer::{ContactSeparation, Freestanding, Transducer, TransducerState};
pub use waveform::{GapWaveform, PwlGaps, PwlPiece};

use crate::error::ParamError;
use thiserror::Error;

/// The charge solver could not continue.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ElectricalError {
    /// The parameters are invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The step size fell below rounding level (the waveform is not smooth where it was
    /// promised to be, or the circuit is pathological).
    #[error("charge solver step size underflow at t = {t:.12} s (h = {h:e} s)")]
    StepSizeUnderflow {
        /// Time, s.
        t: f64,
        /// Step size, s.
        h: f64,
    },
    /// More steps within one excitation period than
    /// [`ChargeOptions::max_steps_per_period`] allows.
    #[error("charge solver step limit reached at t = {t:.9} s: more than {limit} steps in one period")]
    StepLimit {
        /// Time, s.
        t: f64,
        /// The configured limit.
        limit: u64,
    },
    /// A call of [`ChargeSolver::advance`] did not start where the previous one ended.
    #[error(
        "charge solver input is not contiguous: expected an interval starting at t = {expected} s, got {got} s"
    )]
    Discontiguous {
        /// Where the solver stands, s.
        expected: f64,
        /// Where the new interval starts, s.
        got: f64,
    },
    /// An interval ends before it starts (or a time is not finite).
    #[error("cannot advance the charge solver backwards: from t = {current} s to t = {requested} s")]
    Backwards {
        /// Requested end, s.
        requested: f64,
        /// Start, s.
        current: f64,
    },
    /// The gaps gave a non-positive or non-finite capacitance (a negative gap below −d₀, or
    /// NaN).
    #[error("gaps at t = {t} s give no valid capacitance (gap below −d0, or not finite)")]
    InvalidGaps {
        /// Time, s.
        t: f64,
    },
    /// A trajectory to replay holds no flow.
    #[error("the trajectory holds no flow to replay")]
    EmptyTrajectory,
    /// The gaps of a piece of flow change too fast for the charge solver's expansion: the
    /// chain's rate bound Λ (its damping rate 2α plus its natural frequency, 1/s) over the
    /// piece asks for more sub-pieces than memory allows. Refused before any allocation.
    #[error(
        "the charge solver cannot follow the gaps from t = {t_start:.6e} s to {t_end:.6e} s: the chain's rate \
         {rate:.3e} 1/s (damping rate plus natural frequency) needs {sub_pieces:.3e} sub-pieces, more than \
         its expansion of {limit:.3e} coefficients allows; such heavily damped or stiff chains are beyond it \
         (run --mechanics-only)"
    )]
    TooFine {
        /// Start of the piece, s.
        t_start: f64,
        /// End of the piece, s.
        t_end: f64,
        /// The rate bound Λ, 1/s.
        rate: f64,
        /// The sub-pieces it would need.
        sub_pieces: f64,
        /// The most coefficients allowed.
        limit: f64,
    },
}
