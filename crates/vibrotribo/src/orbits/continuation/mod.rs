//! Pseudo-arclength continuation of periodic orbits in a scalar parameter, with detection
//! and location of their bifurcations.
//!
//! The branch `{(z, p): φ(PT; z, p) = z}` is followed in the scaled unknowns `u = (ẑ, p̂)`
//! (state in L and L·ω, parameter in units of the range): from a point `u₀` with unit
//! tangent `t₀` (the null vector of the Jacobian `[Φ − I | ∂φ/∂p]`, oriented along the
//! previous one), predict `u₀ + ds·t₀` and correct by Newton's method on
//! `φ(z; p) = z, t₀ᵀ(u − u₀ − ds·t₀) = 0`, which passes folds (the parameter may turn back).
//! The step grows after easy corrections and halves after failures, down to a floor.
//!
//! Between consecutive points the continuation looks for
//!
//! - sign changes of the test functions of the multipliers λ_i: `det(Φ − I)` (fold if the
//!   tangent's parameter component turns, else branch point), `det(Φ + I)` (period
//!   doubling), `Π_{i<j}(λ_iλ_j − 1)` (Neimark–Sacker when the critical pair is complex, not
//!   two real multipliers with product 1), located by the Illinois method along the step;
//! - changes of the event sequence over a period (chatter sequences counted as one entry),
//!   located by bisection: grazing (an impact appears or disappears with closing speed → 0),
//!   sticking onset or end, or another change. Φ is discontinuous there, so the smooth test
//!   functions are only searched on either side of it.
//!
//! At a grazing, sticking onset or loss, or chatter onset the branch has a corner (the map
//! has Nordmark's square-root singularity at a grazing): when the step falls to its floor the
//! continuation crosses it in the parameter (natural-parameter
//! Newton steps forward, the edge of the old event sequence located by bisection, and the
//! orbit with the new sequence sought on both sides of it). The point is recorded as a
//! bifurcation with the orbits on both sides, and a [`Crossing`]: a persistence (the branch
//! goes on) or a non-smooth fold (the branch turns back onto the orbit with the new sequence),
//! and, at a grazing, the [`NordmarkScenario`] the square-root map predicts from the dominant
//! multiplier of the orbit without the impact. A branch that finds no orbit with the new
//! sequence on either side ends with [`BranchEnd::Grazing`] if one of its gap minima is
//! vanishing, else [`BranchEnd::StepFloor`] with the corrector's residuals. A doubled branch
//! that comes back to its parent at another period doubling (a bubble) ends
//! [`BranchEnd::Collapsed`] and is followed once.
//!
//! Internally a branch is represented on a section t ≡ θ (mod T) kept away from the orbit's
//! events (an impact crossing the section would make the stroboscopic map jump); points are
//! reported at t ≡ 0.
//!
//! Every location stops at [`ContinuationOptions::location_tolerance`] in the parameter. At
//! a period doubling the doubled branch is started along the eigenvector of the multiplier
//! −1 (the pitchfork of the doubled map), made orthogonal to the parent branch's tangent so
//! that the corrector cannot slide back along the parent, and followed in turn ([`cascade`]
//! and [`feigenbaum_ratios`] read the cascade off the result), to
//! [`ContinuationOptions::doubling_depth`] levels. Every loop is bounded: points per branch,
//! branches, corrector iterations, location steps and the step floor.

mod branch;
mod cascade;
mod corrector;
mod cross;
mod detect;
mod locate;
mod nordmark;
mod onto;
mod phase;
mod segments;
mod switch;
mod types;
pub(in crate::orbits) use types::check_path;

pub use branch::continue_orbit;
pub use cascade::{cascade, feigenbaum_ratios};
pub use types::{
    Bifurcation, BifurcationKind, Branch, BranchEnd, BranchPoint, Continuation, ContinuationOptions,
    Crossing, CrossingKind, NordmarkScenario,
};
