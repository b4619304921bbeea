//! Crossing a non-smooth point of a branch in the parameter.
//!
//! At a grazing the branch has a corner: on the side with the new impact the orbit moves like
//! the square root of the distance to the grazing parameter, so its tangent there is
//! perpendicular to the parameter axis, and the arclength corrector (which searches the plane
//! normal to the old tangent) cannot reach it. When the step falls to its floor, the
//! continuation tries natural-parameter steps instead: Newton's method at fixed
//! `p_b = p_a ± δ` (δ growing from 1e-6 to 1e-2 of the range) from the last state. If an orbit
//! converges there, a change of its event sequence is located by bisection in the parameter
//! (Newton at the midpoint from the state on either side), and the branch goes on from it.

use nalgebra::DVector;

use super::corrector::Problem;
use super::locate::{MAX_LOCATE, StepPoint};
use crate::model::ChainParams;
use crate::orbits::shooting::newton;

/// Parameter steps tried, as fractions of the range: 1e-6 · 4^k.
const TRIES: i32 = 8;

/// The converged orbit at parameter `p` from state `z`, as a step point.
fn orbit_at<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
    arclength: f64,
) -> Option<StepPoint> {
    let params = (problem.family)(p);
    let c = newton(
        &params,
        z.clone(),
        problem.period,
        problem.phase,
        &problem.options.shooting,
    )
    .ok()?;
    let ev = problem.evaluate(&problem.point(&c.z, p)).ok()?;
    let described = problem.describe(&ev, arclength)?;
    Some(StepPoint {
        theta: 0.0,
        ev,
        described,
    })
}

/// A natural-parameter step from `current` in the parameter's `direction` (±1), within
/// `[lo, hi]`: the orbit found and its tangent.
pub(crate) fn bridge<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    current: &StepPoint,
    direction: f64,
    (lo, hi): (f64, f64),
) -> Option<(StepPoint, DVector<f64>)> {
    let dim = problem.dim();
    let p_a = current.described.point.parameter;
    let z_a = problem.state(&current.ev.u);
    for k in 0..TRIES {
        let delta = 1e-6 * 4f64.powi(k) * problem.p_scale;
        let p_b = (p_a + direction * delta).clamp(lo, hi);
        if p_b == p_a {
            return None;
        }
        let arclength = current.described.point.arclength + delta / problem.p_scale;
        if let Some(point) = orbit_at(problem, &z_a, p_b, arclength) {
            let mut along = DVector::zeros(dim + 1);
            along[dim] = direction;
            let tangent = problem.tangent(&point.ev, &along)?;
            return Some((point, tangent));
        }
    }
    None
}

/// Where the event sequence changes between `a` and `b` (orbits at two parameters), by
/// bisection in the parameter: the last orbit with `a`'s sequence, the first with another,
/// and the precision in the parameter.
pub(crate) fn locate_change_in_parameter<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    a: &StepPoint,
    b: &StepPoint,
) -> (StepPoint, StepPoint, f64) {
    let tol = problem.options.location_tolerance;
    let (mut a, mut b) = (a.clone(), b.clone());
    let parameter = |s: &StepPoint| s.described.point.parameter;
    // The far end of the bracket: b's parameter, or closer where no orbit converged.
    let mut p_b = parameter(&b);
    for _ in 0..MAX_LOCATE {
        if (p_b - parameter(&a)).abs() <= tol {
            break;
        }
        let p = 0.5 * (parameter(&a) + p_b);
        let s = 0.5 * (a.described.point.arclength + b.described.point.arclength);
        match orbit_at(problem, &problem.state(&a.ev.u), p, s) {
            Some(c) if c.described.signature == a.described.signature => a = c,
            _ => match orbit_at(problem, &problem.state(&b.ev.u), p, s) {
                Some(c) if c.described.signature == b.described.signature => {
                    b = c;
                    p_b = p;
                }
                // Neither side's orbit reaches the midpoint: the change is at or before it.
                _ => p_b = p,
            },
        }
    }
    let precision = (p_b - parameter(&a)).abs();
    (a, b, precision)
}
