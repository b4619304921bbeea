//! Locating bifurcations inside one continuation step.
//!
//! A step goes from the converged point `u₀` along the tangent `t₀` by `ds`; every point
//! of it is parametrised by θ ∈ [0, 1]: the corrector from `u₀ + θ ds t₀` on the plane
//! `t₀ᵀ(u − u₀ − θ ds t₀) = 0`. A smooth test function that changes sign over the step is
//! located by the Illinois (modified regula falsi) method in θ; a change of the event
//! sequence by bisection in θ. Both stop when the bracket's precision in the parameter,
//! `|p(θ_b) − p(θ_a)| + p_s (ds |θ_b − θ_a|)²` (the second term covers a turning point, where
//! p is quadratic in θ), is below the tolerance, or after [`MAX_LOCATE`] evaluations.

use nalgebra::DVector;

use super::corrector::{Described, Evaluated, Failure, Problem};
use super::types::BifurcationKind;
use crate::dynamics::EventKind;
use crate::model::ChainParams;

/// Most corrector solves spent on locating one point.
pub(crate) const MAX_LOCATE: usize = 80;

/// A converged point of a step, at θ.
#[derive(Debug, Clone)]
pub(crate) struct StepPoint {
    pub theta: f64,
    pub ev: Evaluated,
    pub described: Described,
}

/// One continuation step, from `base` along `tangent` by `ds`.
pub(crate) struct Step<'s> {
    pub base: &'s DVector<f64>,
    pub tangent: &'s DVector<f64>,
    pub ds: f64,
    /// Arclength at `base`.
    pub s0: f64,
}

impl Step<'_> {
    /// The corrected point at θ.
    pub fn at<F: Fn(f64) -> ChainParams>(
        &self,
        problem: &Problem<'_, F>,
        theta: f64,
    ) -> Result<StepPoint, Failure> {
        let u_pred = self.base + self.tangent * (theta * self.ds);
        let ev = problem.correct(&u_pred, self.tangent)?;
        let described = problem
            .describe(&ev, self.s0 + theta * self.ds)
            .ok_or_else(|| Failure {
                reason: super::super::error::NewtonFailure::Singular,
                non_smooth: None,
                residuals: Vec::new(),
            })?;
        Ok(StepPoint { theta, ev, described })
    }

    /// The corrected point at θ between two corrected points `a` and `b` of this step,
    /// predicted on the chord between them (which lies in the plane of θ, as both lie in
    /// theirs). Next to a branch point the corrector's Jacobian is nearly singular and
    /// Newton's method converges only from close by: the chord's error shrinks with the
    /// square of the bracket, the tangent line's does not.
    pub fn between<F: Fn(f64) -> ChainParams>(
        &self,
        problem: &Problem<'_, F>,
        theta: f64,
        a: &StepPoint,
        b: &StepPoint,
    ) -> Result<StepPoint, Failure> {
        let width = b.theta - a.theta;
        if width == 0.0 {
            return self.at(problem, theta);
        }
        let s = (theta - a.theta) / width;
        let u_pred = &a.ev.u + (&b.ev.u - &a.ev.u) * s;
        let ev = problem.correct(&u_pred, self.tangent)?;
        let described = problem
            .describe(&ev, self.s0 + theta * self.ds)
            .ok_or_else(|| Failure {
                reason: super::super::error::NewtonFailure::Singular,
                non_smooth: None,
                residuals: Vec::new(),
            })?;
        Ok(StepPoint { theta, ev, described })
    }

    fn precision(&self, p_scale: f64, a: &StepPoint, b: &StepPoint) -> f64 {
        let dtheta = self.ds * (b.theta - a.theta).abs();
        (b.described.point.parameter - a.described.point.parameter).abs() + p_scale * dtheta * dtheta
    }
}

/// A located point and the precision of its parameter.
#[derive(Debug, Clone)]
pub(crate) struct Located {
    pub point: StepPoint,
    pub precision: f64,
    /// The parameters of the final bracket's ends.
    pub bracket: (f64, f64),
}

/// The zero of `f` between `a` and `b` (where it changes sign) by the Illinois method. Where
/// the corrector fails from the step's tangent line inside the bracket (next to a branch
/// point the corrector's Jacobian is nearly singular), it starts from the chord between the
/// bracket's ends ([`Step::between`]); where that fails too, the bracket reached so far is
/// the answer, with its precision.
pub(crate) fn locate_root<F, G>(
    problem: &Problem<'_, F>,
    step: &Step<'_>,
    a: &StepPoint,
    b: &StepPoint,
    f: G,
) -> Option<Located>
where
    F: Fn(f64) -> ChainParams,
    G: Fn(&StepPoint) -> f64,
{
    let tol = problem.options.location_tolerance;
    let (mut a, mut b) = (a.clone(), b.clone());
    let (mut fa, mut fb) = (f(&a), f(&b));
    if fa * fb > 0.0 {
        return None;
    }
    for _ in 0..MAX_LOCATE {
        if fa == 0.0 || fb == 0.0 || step.precision(problem.p_scale, &a, &b) <= tol {
            break;
        }
        let mut theta = b.theta - fb * (b.theta - a.theta) / (fb - fa);
        let (lo, hi) = (a.theta.min(b.theta), a.theta.max(b.theta));
        if !(theta > lo && theta < hi) {
            theta = 0.5 * (lo + hi);
        }
        let Ok(c) = step
            .at(problem, theta)
            .or_else(|_| step.between(problem, theta, &a, &b))
        else {
            break;
        };
        let fc = f(&c);
        if fc * fb < 0.0 {
            a = b;
            fa = fb;
        } else {
            fa *= 0.5;
        }
        b = c;
        fb = fc;
    }
    let precision = step.precision(problem.p_scale, &a, &b);
    let bracket = (a.described.point.parameter, b.described.point.parameter);
    let point = if fa.abs() < fb.abs() { a } else { b };
    Some(Located {
        point,
        precision,
        bracket,
    })
}

/// Where the event sequence changes between `a` (before) and `b` (after), by bisection:
/// the last point with `a`'s sequence, the first point found with another (or `b` itself if
/// none closer converged), and the precision in the parameter.
pub(crate) fn locate_change<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    step: &Step<'_>,
    a: &StepPoint,
    b: &StepPoint,
) -> (StepPoint, StepPoint, f64) {
    let tol = problem.options.location_tolerance;
    let (mut a, mut b) = (a.clone(), b.clone());
    // θ of the bracket's far end: b's, or closer where the corrector failed.
    let mut theta_b = b.theta;
    let dim = problem.dim();
    // The parameter at θ on the predictor line (for an end where no orbit converged).
    let predicted = |theta: f64| (step.base[dim] + theta * step.ds * step.tangent[dim]) * problem.p_scale;
    let precision = |a: &StepPoint, b: &StepPoint, theta_b: f64| {
        let p_b = if theta_b == b.theta {
            b.described.point.parameter
        } else {
            predicted(theta_b)
        };
        let dtheta = step.ds * (theta_b - a.theta).abs();
        (p_b - a.described.point.parameter).abs() + problem.p_scale * dtheta * dtheta
    };
    for _ in 0..MAX_LOCATE {
        if precision(&a, &b, theta_b) <= tol {
            break;
        }
        let theta = 0.5 * (a.theta + theta_b);
        match step.at(problem, theta) {
            Ok(c) if c.described.signature == a.described.signature => a = c,
            Ok(c) => {
                theta_b = c.theta;
                b = c;
            }
            // No orbit, or a non-differentiable one: the change is at or before it.
            Err(_) => theta_b = theta,
        }
    }
    let precision = precision(&a, &b, theta_b);
    (a, b, precision)
}

/// What kind of change leads from the sequence of `before` to that of `after` (module docs
/// of [`super`]): sticking if the sticks differ, grazing if impacts differ at a contact whose
/// new impact is the slowest of its side and slower than 1 % of the speed unit L·ω.
pub(crate) fn classify(before: &Described, after: &Described, speed_unit: f64) -> BifurcationKind {
    let count =
        |d: &Described, kind: EventKind, k: usize| d.signature.iter().filter(|e| **e == (kind, k)).count();
    let contacts = before.point.impacts_per_period.len();
    for k in 0..contacts {
        let (s0, s1) = (
            count(before, EventKind::Stick, k),
            count(after, EventKind::Stick, k),
        );
        if s0 != s1 {
            return BifurcationKind::Sticking {
                contact: k,
                onset: s1 > s0,
            };
        }
    }
    for k in 0..contacts {
        let (i0, i1) = (
            count(before, EventKind::Impact, k),
            count(after, EventKind::Impact, k),
        );
        if i0 == i1 {
            continue;
        }
        let side = if i1 > i0 { after } else { before };
        if let Some((contact, speed)) = side.point.min_closing_speed
            && contact == k
            && speed < 1e-2 * speed_unit
        {
            return BifurcationKind::Grazing {
                contact: k,
                appears: i1 > i0,
            };
        }
    }
    BifurcationKind::SequenceChange
}
