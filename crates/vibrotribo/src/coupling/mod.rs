//! Two-way electromechanical coupling: the electrostatic force of the charges on the plates
//! acts back on the masses (docs/MODEL.md §2; the energy, voltage and forces are derived in
//! [`electrical::energy`](crate::electrical::Electrostatics)).
//!
//! ## The coupled system
//!
//! The force on each gap at constant charge, `G_k = −(a_k Q + b_k)²/(2ε₀S)`, depends on the
//! transferred charge Q only, not on the gaps. Between events the masses are therefore linear
//! oscillators driven by a force that is a known function of time once Q(t) is known, and Q
//! follows the circuit equation driven by the gaps. The two form one smooth nonlinear system.
//!
//! ## Method: windows and waveform relaxation
//!
//! Time is cut into windows `[t₀, t₀ + h]` that never contain an event inside (a window ends
//! at the first impact, stick, release or chatter point, or at a period's end). On a window:
//!
//! 1. the charge is guessed as a polynomial of degree 6 in time (extrapolated from the last
//!    window, a constant after an event);
//! 2. the engine runs the mechanics exactly under the force polynomials that guess implies
//!    (closed-form particular solution of a polynomial forcing; events found by the same
//!    certified search as always);
//! 3. the charge solver (the same Radau solver as in one-way mode, with its own error control)
//!    advances the charge over the gaps of that motion, sampled at the window's 7
//!    Chebyshev–Lobatto points;
//! 4. if the sampled charge differs from the guess by more than the window's charge tolerance,
//!    the window is redone from its start with the new charge as the guess (the solver is
//!    rewound, [`ChargeSolver::checkpoint`]); if the interpolant's own error estimate exceeds
//!    it, the window is shortened.
//!
//! The **charge tolerance** of a window of length h is the charge error whose force error,
//! acting over the window, moves a mass by at most [`CouplingOptions::position_tolerance`]
//! (δx ≤ |∂G/∂Q| h² mean|δQ|/m) or changes its velocity by at most that tolerance times the
//! excitation frequency; the interpolant's error estimate bounds the mean charge error over
//! the window (a transient much shorter than the window, such as the charge's relaxation over
//! R·C right after an impact, is not resolved pointwise, and need not be: only its integral
//! reaches the masses). The accepted motion is thus the exact flow of the chain under a
//! force that differs from the true electrostatic force of the computed charge by less than
//! that, and the charge is the solver's solution (to its own tolerance) for the accepted
//! motion.
//!
//! In open circuit the charge is constant, the force is constant between events, and the
//! flow is the closed form with a constant force: the coupling adds nothing but the force.

mod driver;
mod window;

pub use driver::{ChargeHost, CoupledChain, CouplingError, CouplingStats, SolverOnly};

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Whether the charges act back on the masses (`harvester.coupling`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(Serialize, Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum Coupling {
    /// The paper's model: the motion drives the circuit, the circuit does not act on the
    /// motion.
    #[default]
    OneWay,
    /// The electrostatic force of the charges acts on the plates (needs
    /// `voc_model = "exact"`).
    TwoWay,
}

impl Coupling {
    /// The configuration name (`"one_way"`, `"two_way"`).
    pub fn as_str(self) -> &'static str {
        match self {
            Coupling::OneWay => "one_way",
            Coupling::TwoWay => "two_way",
        }
    }
}

/// Numerical settings of the coupled integration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CouplingOptions {
    /// The displacement error, m, that the charge representation of a window may cause (see the
    /// module docs). Default 1e-11 m (2·10⁻⁹ of the paper's 5 mm gaps; on the default case the
    /// average power then agrees with a run at 1e-13 m to 2·10⁻⁹ relative).
    pub position_tolerance: f64,
    /// Longest window, in excitation periods. Default 1/16.
    pub max_window_periods: f64,
    /// Most relaxation sweeps of one window before it is halved. Default 12.
    pub max_iterations: u32,
}

impl Default for CouplingOptions {
    fn default() -> Self {
        CouplingOptions {
            position_tolerance: 1e-11,
            max_window_periods: 1.0 / 16.0,
            max_iterations: 12,
        }
    }
}
