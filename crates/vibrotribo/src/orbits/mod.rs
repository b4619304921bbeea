//! Periodic orbits of the forced chain, their Floquet multipliers, and their continuation
//! in a parameter.
//!
//! # Shooting
//!
//! A periodic orbit of period P (in excitation periods T = 2π/ω) is a fixed point of the
//! P-fold stroboscopic map on the section t ≡ 0 (mod T),
//!
//! ```text
//! F(z) = φ(PT; z) − z = 0,     z = [x₁ … x_N, v₁ … v_N],
//! ```
//!
//! where φ is the exact non-smooth flow from t = 0 ([`Simulator`](crate::Simulator)).
//! [`find_periodic_orbit`] solves it by Newton's method with the exact Jacobian
//! `∂F/∂z = Φ(PT) − I` from [`sensitivity`](crate::sensitivity), in scaled units
//! (positions in L = Σδ + A, velocities in L·ω), damped by backtracking: the step
//! `z + λΔ` is accepted for the largest λ = 1, ½, ¼, … whose scaled residual
//! `max_i |F_i| / scale_i` decreases (Armijo). Newton does not care about stability, so
//! unstable orbits converge as well as stable ones. Convergence is at residual ≤ 1e-12 by
//! default; failure is an [`OrbitError::NoConvergence`] with the residual history.
//!
//! The Floquet multipliers are the eigenvalues of the monodromy matrix Φ(PT)
//! ([`floquet_multipliers`]); the orbit is stable when all lie inside the unit circle. A
//! contact that sticks somewhere on the orbit contributes two zero multipliers (while it is
//! stuck Φ projects the gap and relative-velocity directions away, and nothing restores
//! them). Newton's method reports an orbit through a non-differentiable point (grazing or
//! simultaneous impacts) as [`OrbitError::NonSmooth`] and `period = 0` as
//! [`OrbitError::ZeroPeriod`]. [`PeriodicOrbit::replay`] runs the orbit again with any
//! observer attached: the hook for its average power.
//!
//! # Continuation
//!
//! [`continue_orbit`] follows an orbit in a scalar parameter given as a closure
//! `Fn(f64) -> ChainParams` (any combination of frequency, amplitude, masses, gaps,
//! restitution, …) by pseudo-arclength continuation, locates folds, period doublings (and
//! follows the doubled branches, so a cascade is followed to a chosen depth),
//! Neimark–Sacker points, grazings and the onset of sticking, and marks why every branch
//! ends; the method is described in [`continuation`].
//!
//! # Rigid stops
//!
//! Chains with rigid stops ([`Stops`](crate::Stops)) need nothing special here: their
//! impacts, sticking and chatter against a stop enter the monodromy matrix through the
//! saltation matrices of `sensitivity` (a gap `h` with explicit time dependence
//! `∂h/∂t = ±Y'`, a reset of one cluster only), and the single-mass impact oscillator's
//! (1,1) orbits, multipliers and period doubling agree with their closed form
//! (`tests/suite/stops.rs`). The grazing gap minimum watched during continuation (a branch
//! approaching a new impact) includes the stops' gaps: the textbook orbit that never touches
//! the stop meets it where its steady amplitude equals the gap.

mod cancel;
pub mod continuation;
pub mod curve;
mod error;
mod floquet;
mod gaps;
mod map;
mod shooting;

pub use cancel::Cancel;
pub use continuation::{
    Bifurcation, BifurcationKind, Branch, BranchEnd, BranchPoint, Continuation, ContinuationOptions,
    Crossing, CrossingKind, NordmarkScenario, cascade, continue_orbit, feigenbaum_ratios,
};
pub use error::{NewtonFailure, OrbitError};
pub use floquet::floquet_multipliers;
pub use shooting::{PeriodicOrbit, ShootingOptions, find_periodic_orbit, periodic_orbit_from_transient};
