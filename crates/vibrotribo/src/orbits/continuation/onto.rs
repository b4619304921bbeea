//! Whether a branch, past a change of its event sequence, has run onto a branch followed
//! before.
//!
//! Two smooth branches of one period meet only at a branch point (found by the detector); past
//! a grazing or another change of sequence a branch can also land on a branch followed before,
//! as where a grazing joins the two asymmetric orbits of a pitchfork to their symmetric
//! parent. From there on it would repeat that branch, so it ends there.

use nalgebra::DVector;

use super::corrector::Problem;
use super::cross::orbit_keeping;
use super::locate::StepPoint;
use super::types::{Branch, BranchPoint};
use crate::model::ChainParams;
use crate::sensitivity::state_vector;

/// Largest distance of a point from a chord of a branch followed before, as a fraction of the
/// chord's length, for the chord to be a candidate. A chord between two points whose tangents
/// turn by at most ~25° (the corrector's limit) departs from the curve by at most about 6 % of
/// its length.
const ON_CHORD: f64 = 0.1;

/// Largest distance, in the scaled state, between the point and the orbit Newton's method
/// finds from the candidate chord for the two to be one orbit (both are converged far below).
const SAME_ORBIT: f64 = 1e-6;

/// Where `x` projects on the chord from `a` to `b`: the fraction `s` of the way along it (not
/// clamped), and the distance from `x` to the chord's nearest point (within its ends).
pub(super) fn chord(a: &DVector<f64>, b: &DVector<f64>, x: &DVector<f64>) -> (f64, f64) {
    let d = b - a;
    let s = d.dot(&(x - a)) / d.norm_squared().max(f64::MIN_POSITIVE);
    (s, (a + d * s.clamp(0.0, 1.0) - x).norm())
}

/// The branch followed before (of `branches`) that `point` lies on, if any.
///
/// A candidate is a chord between two consecutive points of a branch with the period, impacts
/// and sticking of `point`, inside which `point` projects within [`ON_CHORD`] of the chord's
/// length (in the scaled state and parameter). It is confirmed by Newton's method, held to the
/// event sequence of `point`, from the chord's state at the parameter of `point`: it must
/// converge to `point` itself (within [`SAME_ORBIT`]).
pub(super) fn runs_onto<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    branches: &[Branch],
    point: &StepPoint,
) -> Option<usize> {
    let me = &point.described.point;
    let at = |q: &BranchPoint| problem.point(&state_vector(&q.state), q.parameter);
    let x = at(me);
    // Points are reported at t ≡ 0 (mod PT): the confirmation runs on that section.
    let section = problem.with_phase(0.0);
    let z = state_vector(&me.state);
    let confirms = |a: &BranchPoint, b: &BranchPoint, s: f64| {
        let guess = a.towards(b, s);
        orbit_keeping(
            &section,
            &guess,
            me.parameter,
            me.arclength,
            &point.described.signature,
        )
        .is_some_and(|o| problem.scale.norm(&(state_vector(&o.described.point.state) - &z)) <= SAME_ORBIT)
    };
    branches.iter().position(|b| {
        b.period == problem.period
            && b.points.windows(2).any(|w| {
                if !(w[0].alike(me) && w[1].alike(me)) {
                    return false;
                }
                let (a, b) = (at(&w[0]), at(&w[1]));
                let length = (&b - &a).norm();
                let (s, distance) = chord(&a, &b, &x);
                length > 0.0
                    && (0.0..=1.0).contains(&s)
                    && distance <= ON_CHORD * length
                    && confirms(&w[0], &w[1], s)
            })
    })
}
