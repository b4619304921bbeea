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
//! contact stuck over the whole period contributes two zero multipliers (Φ projects the gap
//! and relative-velocity directions away).

mod continuation;
mod error;
mod floquet;
mod gaps;
mod map;
mod shooting;

pub use continuation::{
    Bifurcation, BifurcationKind, Branch, BranchEnd, BranchPoint, Continuation, ContinuationOptions,
    continue_orbit,
};
pub use error::{NewtonFailure, OrbitError};
pub use floquet::floquet_multipliers;
pub use shooting::{PeriodicOrbit, ShootingOptions, find_periodic_orbit, periodic_orbit_from_transient};
