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
//!    Chebyshev–Lobatto points; it also integrates the charge's time moments over the window
//!    (∫Q, ∫Q², ∫τQ, ∫τQ², by each step's collocation quadrature, the one that books the
//!    load's energy; [`ChargeSolver::start_moments`](crate::electrical::ChargeSolver::start_moments)), which give on each mass the impulse
//!    ∫F dτ and the first moment ∫τF dτ of the force of the solver's charge;
//! 4. if the sampled charge differs from the guess by more than the window's charge tolerance,
//!    or the installed force's impulse or first moment differs from the solver's by more than
//!    their tolerances (below), the window is redone from its start (the solver is rewound,
//!    [`ChargeSolver::checkpoint`](crate::electrical::ChargeSolver::checkpoint)) with the new charge as the guess and, on each mass, a
//!    force βτ + γτ² added to the polynomial force so that its impulse and first moment
//!    are those just measured; if the interpolant's own error estimate exceeds the charge
//!    tolerance, the window is shortened.
//!
//! Every trial of a window has at its start the force of the solver's charge there (the
//! force polynomial's constant term is set to it; the correction vanishes at τ = 0). The
//! engine decides the contacts at the window's start (stick, release, a touch) with that
//! force, so every trial and every window from the same instant decides alike. A correction
//! α + βτ that is not zero at τ = 0 would move the start force by up to the layer's size and
//! can make two-way runs of the chatter case loop at a release (release under one trial's
//! force, stick under the next's, at one instant; `notes/coupled-stick-loop.md`).
//!
//! The **charge tolerance** of a window of length h is the charge error whose force error,
//! acting over the window, moves a mass by at most [`CouplingOptions::position_tolerance`]
//! (δx ≤ |∂G/∂Q| h² mean|δQ|/m) or changes its velocity by at most that tolerance times the
//! excitation frequency ω. The **moment tolerances** are the same two bounds on the force
//! error δF = F_installed − F(Q_solver) itself: |∫₀ʰ (h − τ) δF dτ| ≤ m·tol (the displacement
//! it causes at the window's end on a free mass) and |∫₀ʰ δF dτ| ≤ m·ω·tol (the velocity).
//!
//! ## What is guaranteed
//!
//! On every accepted window and every mass the two moment bounds above hold between the force
//! the mechanics was driven by and the force of the solver's charge (at the solver's stage
//! points), and the solver's charge at the 7 nodes is within the charge tolerance of the
//! polynomial; the charge is the solver's solution (to its own tolerance) for the accepted
//! motion. The bounds are per window: errors of successive windows add up, they are not
//! bounded over a run.
//!
//! The force is **not** matched pointwise. Right after an impact the charge crosses a boundary
//! layer of width R·C (~1 µs for the paper's device at 100 kΩ, against post-impact windows of
//! tens of µs): the polynomial through 7 nodes does not resolve it, and before the moments
//! were matched it did not carry its integral either (the window's test looked at the nodes
//! only), which left a systematic work error at every impact that did not shrink with the
//! tolerance. The correction now carries the layer's impulse and first moment, which
//! is what a window short against the mechanics' time scales passes on to the positions and
//! velocities at its end; the force differs from F(Q) inside the layer (by up to ~5e-5 N on
//! the default case), and the work that difference does beyond its first two moments is of
//! order v''·∫τ²δF, far below the tolerance.
//!
//! Measured on the paper's default case (exact V_oc, 100 kΩ, electrical rtol 1e-10, 20
//! periods; `tests/suite/coupling_checks.rs`): the energy identity W_base = ΔE + D + L + E_load + ΔU
//! closes to −7.5e-10 J at the default tolerance, 6.8e-12 of W = 111 J and 2.9e-7 of the
//! electrical terms E_load + |ΔU| = 2.6 mJ, and the residual shrinks with the tolerance:
//! −9.2e-8, −7.5e-10, 8.7e-11, −1.4e-11 J at 1e-10, 1e-11, 1e-12, 1e-13 m (with the
//! correction α + βτ it was −5.5e-8, 8.6e-10, −1.6e-10, 2.9e-11 J). On the chatter case in
//! its sticking regime (Ω = 0.4, 5 periods) it closes to 7.3e-11 of W, 9.0e-8 of the
//! electrical terms.
//!
//! In open and short circuit no moments are measured (the charge is constant, or the
//! equilibrium charge exactly, with no boundary layer) and only the node tests apply. With a
//! rectifier the moments are integrated as for a resistor, and the balance's electrical term is
//! the energy that left the transducer's terminals, ∫V·I dt
//! ([`ChargeSolver::terminal_energy`](crate::electrical::ChargeSolver::terminal_energy): the
//! storage side's energy plus the bridge's losses): 8.8e-12 of W, 3.4e-7 of the electrical
//! terms on the default case, shrinking with the tolerance as for the resistor.
//!
//! The contact decisions (stick, release) are taken with the window's force. On a window that
//! **decides a contact** (a contact stuck or in a chatter sequence at its start, or a trial
//! ending at a stick, release or chatter point) the force is also matched pointwise at the
//! window's end, where the engine decides: on every mass the installed force there is within
//! the **force tolerance** `K_min·tol` (the weakest spring stretched by the position
//! tolerance; 9e-10 N on `tests/suite/coupling_events.rs`'s four-mass stack) of the force of the
//! solver's charge, wherever a release may hide at its end: a window that only has a contact
//! stuck is tested only where the engine's contact force at its end is within the summed force
//! error on the masses of zero (beyond that its sign is the true force's). Such a window keeps its force polynomial's terms down to a quarter of that
//! force (the displacement bound m·tol/h² alone allows newtons on short windows) and is halved
//! if its end force stays off after three sweeps, down to 1e-9 periods (`CONSTANT_BELOW`),
//! where the window itself bounds the error in time. A release then comes within the force
//! tolerance over the contact force's rate of the zero of the true contact force (≤ 1.5e-11 s
//! in `tests/suite/coupling_events.rs`; it was up to 4.7e-8 s; notes/coupled-event-accuracy.md).
//! After two windows of length zero at one instant the next is not held to the end test (trials
//! that differ in the force's derivatives at the start could undo each other's stick and
//! release there).
//!
//! In open circuit the charge is constant, the force is constant between events, and the
//! flow is the closed form with a constant force: the coupling adds nothing but the force.
//!
//! ## Under any base motion
//!
//! The coupled run drives the same engine as a one-way run, base motion included
//! ([`Simulator::driven`](crate::Simulator::driven)): under a motion other than the sine the
//! engine adds each interval's base forces `k_i y + c_i y'` to the window's electrostatic
//! force polynomial and switches them at the interval ends inside a window, so the windows
//! and their tolerances are those above. `tests/suite/coupling_base_motion.rs` checks the energy
//! identity under band-limited random input (6e-12 of W_base on the default chain) and under
//! a recorded ground acceleration (1.2e-10 of W_base), where the one-way run misses it by the
//! electrical terms (1e-3 and 5e-2 of W_base).

mod driver;
mod host;
mod window;

pub use driver::{CoupledChain, CouplingError, CouplingStats};
pub use host::{ChargeHost, SolverOnly};

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
