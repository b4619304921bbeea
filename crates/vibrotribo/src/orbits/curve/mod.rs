//! Bifurcation curves in two parameters: a fold, period doubling, Neimark–Sacker or grazing
//! point of a branch followed in a second parameter.
//!
//! # The defining system
//!
//! A point of a curve is a periodic orbit together with its two parameters, `u = (z, p₁, p₂)`,
//! solving 2N + 1 equations:
//!
//! ```text
//! φ(PT; z, p₁, p₂) − z = 0,         g(z, p₁, p₂) = 0,
//! ```
//!
//! with the condition g of the kind ([`CurveKind`]):
//!
//! ```text
//! fold:             λ − 1      (λ the real multiplier nearest +1)
//! period doubling:  λ + 1      (λ the real multiplier nearest −1)
//! Neimark–Sacker:   |λ| − 1    (λ the complex multiplier nearest the unit circle)
//! grazing:          d_min / L  (d_min the smallest smooth local minimum of the contact's gap)
//! ```
//!
//! A multiplier is used rather than `det(Φ ∓ I)` so that g is of order one whatever the
//! other multipliers are; it is smooth wherever the critical multiplier is simple. The
//! system is continued by pseudo-arclength in `(p₁, p₂)`: a predictor along the tangent (the
//! null vector of the Jacobian), a Newton corrector on the plane orthogonal to it. The
//! state columns of the Jacobian are the exact monodromy matrix `Φ(PT)`; the parameter
//! columns and the condition's row are forward differences of the exact flow.
//!
//! A grazing curve is computed on the chain whose grazing contact is widened by L while the
//! impact-free orbit has no impact there: the widened orbit is the true orbit wherever
//! `d_min ≥ 0` and is smooth through `d_min = 0`, where the true map has its square-root
//! singularity. At a solution the two coincide: the orbit touches the contact with zero
//! closing speed.
//!
//! # Codimension-two points
//!
//! Along the curve the event sequence of the orbit is watched: where it changes, the orbit
//! grazes another contact (or starts sticking), the smooth curve meets a grazing curve and
//! ends there ([`Codim2Kind::Grazing`]); the point is located by bisection along the step.
//! The other conditions' test functions `det(Φ − I)`, `det(Φ + I)` and the bialternate
//! product `Π_{i<j}(λ_iλ_j − 1)` are watched for a change of sign: there the curve meets
//! the curve of the other kind (a fold meeting a period doubling, a grazing orbit with a
//! multiplier at −1, …, [`Codim2Kind::Meets`]), located the same way, and goes on.

mod system;
mod types;

use nalgebra::DVector;

pub use types::{Codim2Kind, Codim2Point, Curve, CurveEnd, CurveError, CurveKind, CurveOptions, CurvePoint};

use super::floquet::TestFunctions;
use super::map::{Scale, evaluate};
use crate::dynamics::{Event, EventKind, Simulator};
use crate::error::ParamError;
use crate::model::{ChainParams, ChainState};
use crate::sensitivity::{state_from_vector, state_vector};
use system::{Eval, System};

/// Where a curve starts: an orbit at (or near) the bifurcation.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveStart {
    /// Section state at t ≡ 0 (mod T) of the orbit: positions, m, and velocities, m/s.
    pub state: ChainState,
    /// Period of the orbit, in excitation periods.
    pub period: u32,
    /// The first parameter at the orbit.
    pub parameter: f64,
    /// Grazing curves: the contact that grazes, 0-based (ignored otherwise). The start orbit
    /// should be the one on the side without the grazing impact.
    pub contact: Option<usize>,
}

/// Bisection steps allowed to locate one point along a step.
const MAX_BISECTIONS: usize = 60;

/// Follows the bifurcation of `kind` through `start` in the second parameter of `family`
/// (`family(p₁, p₂)`), from `from2` towards `to2`: first the defining system is solved at
/// `p₂ = from2` for the state and p₁ near the start, then continued by pseudo-arclength.
pub fn continue_curve<F: Fn(f64, f64) -> ChainParams>(
    family: F,
    kind: CurveKind,
    start: &CurveStart,
    from2: f64,
    to2: f64,
    options: &CurveOptions,
) -> Result<Curve, CurveError> {
    options.validate()?;
    if start.period == 0 {
        return Err(ParamError::invalid("period", 0.0, "must be at least 1").into());
    }
    if !(from2.is_finite() && to2.is_finite()) || from2 == to2 {
        return Err(ParamError::invalid("to2", to2, "the range must be finite and not empty").into());
    }
    if !start.parameter.is_finite() {
        return Err(CurveError::Start {
            start: start.parameter,
        });
    }
    let params0 = family(start.parameter, from2);
    params0.validate().map_err(CurveError::Param)?;
    let contact = match (kind, start.contact) {
        (CurveKind::Grazing, None) => {
            return Err(ParamError::invalid("contact", f64::NAN, "a grazing curve needs its contact").into());
        }
        (CurveKind::Grazing, Some(k)) if k >= params0.contact_count() => {
            return Err(ParamError::invalid("contact", k as f64, "no such contact").into());
        }
        (_, k) => k.unwrap_or(0),
    };
    let scale = Scale::of(&params0);
    let z0 = DVector::from_iterator(
        2 * params0.len(),
        start
            .state
            .positions
            .iter()
            .chain(&start.state.velocities)
            .copied(),
    );
    let sim = &options.shooting.sim;
    let first = evaluate(
        &params0,
        &z0,
        start.period,
        0.0,
        sim,
        &options.shooting.sensitivity,
    )
    .map_err(|_| no_start(kind, start.period, system::Failure::simulation()))?;
    let impacts_at_contact = first
        .events
        .iter()
        .filter(|e| e.kind == EventKind::Impact && e.contact == contact)
        .count();
    let margin = if kind == CurveKind::Grazing && impacts_at_contact == 0 {
        scale.length
    } else {
        0.0
    };
    let duration = f64::from(start.period) * params0.period();
    let theta = quiet_phase(&first.events, duration);
    let system = System {
        family: &family,
        kind,
        contact,
        margin,
        period: start.period,
        n: params0.len(),
        phase_fraction: theta / params0.period(),
        scale,
        p_scale: [0.1 * start.parameter.abs().max(1e-12), (to2 - from2).abs()],
        options,
    };
    let z_theta = carry(
        &system.params(&system.point(&z0, start.parameter, from2)),
        &z0,
        theta,
        sim,
    )
    .ok_or_else(|| no_start(kind, start.period, system::Failure::simulation()))?;
    let u0 = system.point(&z_theta, start.parameter, from2);
    let d = system.dim();
    let fix2 = DVector::from_fn(d + 2, |i, _| if i == d + 1 { 1.0 } else { 0.0 });
    let (ev0, _) = system
        .correct(&u0, &fix2, u0[d + 1])
        .map_err(|f| no_start(kind, start.period, f))?;
    let direction = if to2 > from2 { 1.0 } else { -1.0 };
    Ok(follow(&system, ev0, &fix2 * direction, to2))
}

fn no_start(kind: CurveKind, period: u32, f: system::Failure) -> CurveError {
    CurveError::NoStart {
        kind,
        period,
        reason: f.reason,
        residuals: f.residuals,
    }
}

/// The middle of the longest stretch without events of an orbit of `duration` s, s.
fn quiet_phase(events: &[Event], duration: f64) -> f64 {
    let mut times: Vec<f64> = events.iter().map(|e| e.time.rem_euclid(duration)).collect();
    if times.is_empty() {
        return 0.0;
    }
    times.sort_by(f64::total_cmp);
    let mut best = (
        times[0] + duration - times[times.len() - 1],
        times[times.len() - 1],
    );
    for w in times.windows(2) {
        if w[1] - w[0] > best.0 {
            best = (w[1] - w[0], w[0]);
        }
    }
    (best.1 + 0.5 * best.0).rem_euclid(duration)
}

/// The state at t = `theta` of the flow from `z` at t = 0.
fn carry(
    params: &ChainParams,
    z: &DVector<f64>,
    theta: f64,
    sim: &crate::SimOptions,
) -> Option<DVector<f64>> {
    let mut s = Simulator::new_at(params, 0.0, &state_from_vector(z.as_slice()), sim.clone()).ok()?;
    s.run_until(theta, &mut ()).ok()?;
    Some(state_vector(&s.state()))
}

/// One pseudo-arclength step: from `base` along `tangent` by `ds`.
struct Step<'s> {
    base: &'s DVector<f64>,
    tangent: &'s DVector<f64>,
    ds: f64,
}

impl Step<'_> {
    fn at<F: Fn(f64, f64) -> ChainParams>(
        &self,
        system: &System<'_, F>,
        theta: f64,
    ) -> Result<Eval, system::Failure> {
        let pred = self.base + self.tangent * (theta * self.ds);
        system
            .correct(&pred, self.tangent, self.tangent.dot(&pred))
            .map(|r| r.0)
    }
}

/// Bisection along `step` between `a` (θ = 0) and `b` (θ = 1) for where `same(ev)` (true at
/// `a`) stops holding: the last point where it holds, the first found where it does not, and
/// the bracket's width in the scaled parameters.
fn bisect<F: Fn(f64, f64) -> ChainParams>(
    system: &System<'_, F>,
    step: &Step<'_>,
    a: &Eval,
    b: &Eval,
    same: impl Fn(&Eval) -> bool,
) -> (Eval, Eval, f64) {
    let d = system.dim();
    let width = |a: &Eval, b: &Eval| (a.u[d] - b.u[d]).abs() + (a.u[d + 1] - b.u[d + 1]).abs();
    let (mut a, mut b) = (a.clone(), b.clone());
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..MAX_BISECTIONS {
        if width(&a, &b) <= system.options.location_tolerance {
            break;
        }
        let mid = 0.5 * (lo + hi);
        match step.at(system, mid) {
            Ok(c) if same(&c) => {
                a = c;
                lo = mid;
            }
            Ok(c) => {
                b = c;
                hi = mid;
            }
            Err(_) => hi = mid,
        }
    }
    let precision = width(&a, &b);
    (a, b, precision)
}

/// The test functions of the conditions other than the curve's own, with the kind each
/// detects.
fn other_tests(kind: CurveKind, ev: &Eval) -> Vec<(CurveKind, f64)> {
    let t = TestFunctions::of(&ev.multipliers);
    [
        (CurveKind::Fold, t.fold),
        (CurveKind::PeriodDoubling, t.flip),
        (CurveKind::NeimarkSacker, t.neimark_sacker),
    ]
    .into_iter()
    .filter(|(k, _)| *k != kind)
    .collect()
}

/// Whether the multipliers hold a complex pair on the unit circle (to 1e-3).
fn has_complex_pair_on_circle(ev: &Eval) -> bool {
    ev.multipliers
        .iter()
        .any(|l| l.im > 1e-6 && (l.norm() - 1.0).abs() < 1e-3)
}

/// The contact whose impact count differs between two points, if exactly one impact
/// changed and no sticking did.
fn grazing_contact(before: &[(EventKind, usize)], after: &[(EventKind, usize)]) -> Option<usize> {
    let count = |s: &[(EventKind, usize)], e: (EventKind, usize)| s.iter().filter(|x| **x == e).count();
    let sticks_same = before
        .iter()
        .chain(after)
        .filter(|e| e.0 == EventKind::Stick)
        .all(|e| count(before, *e) == count(after, *e));
    let contacts = before.iter().chain(after).map(|e| e.1).max()?;
    let changed: Vec<usize> = (0..=contacts)
        .filter(|&k| count(before, (EventKind::Impact, k)) != count(after, (EventKind::Impact, k)))
        .collect();
    (sticks_same && changed.len() == 1).then(|| changed[0])
}

/// Pseudo-arclength continuation of the system from `ev0` in the direction `previous`.
fn follow<F: Fn(f64, f64) -> ChainParams>(
    system: &System<'_, F>,
    ev0: Eval,
    previous: DVector<f64>,
    to2: f64,
) -> Curve {
    let options = system.options;
    let d = system.dim();
    let target = to2 / system.p_scale[1];
    let ahead = |u: &DVector<f64>| (u[d + 1] - target) * previous[d + 1] > 0.0;
    let mut curve = Curve {
        kind: system.kind,
        contact: (system.kind == CurveKind::Grazing).then_some(system.contact),
        period: system.period,
        points: vec![system.describe(&ev0, 0.0)],
        codim2: Vec::new(),
        end: CurveEnd::MaxPoints,
    };
    let signature0 = system.signature(&ev0);
    let mut current = ev0;
    let mut arclength = 0.0;
    let mut ds = options.initial_step;
    let mut tangent = match system.tangent(&current, &previous) {
        Ok(t) => t,
        Err(f) => {
            curve.end = step_floor(system, &current, f);
            return curve;
        }
    };
    while curve.points.len() < options.max_points {
        let step = Step {
            base: &current.u,
            tangent: &tangent,
            ds,
        };
        let next = match step.at(system, 1.0) {
            Ok(ev) => ev,
            Err(f) => {
                if ds * 0.5 < options.min_step {
                    curve.end = step_floor(system, &current, f);
                    return curve;
                }
                ds *= 0.5;
                continue;
            }
        };
        // The orbit grazes, sticks or chatters: the curve meets a grazing curve and ends.
        let signature = system.signature(&next);
        if signature != signature0 {
            let (a, b, precision) = bisect(system, &step, &current, &next, |e| {
                system.signature(e) == signature0
            });
            let kind = match grazing_contact(&signature0, &system.signature(&b)) {
                Some(contact) => Codim2Kind::Grazing { contact },
                None => Codim2Kind::SequenceChange,
            };
            let s = arclength + (&a.u - &current.u).norm();
            let point = system.describe(&a, s);
            curve.codim2.push(Codim2Point {
                kind,
                point: point.clone(),
                precision,
            });
            if a.u != current.u {
                curve.points.push(point);
            }
            curve.end = CurveEnd::SequenceChange;
            return curve;
        }
        // Another condition holds between the two points: the curves meet.
        for ((kind, t0), (_, t1)) in other_tests(system.kind, &current)
            .into_iter()
            .zip(other_tests(system.kind, &next))
        {
            if t0.signum() == t1.signum() || t0 == 0.0 {
                continue;
            }
            let sign = t0.signum();
            let (a, _, precision) = bisect(system, &step, &current, &next, |e| {
                other_tests(system.kind, e)
                    .iter()
                    .any(|(k, t)| *k == kind && t.signum() == sign)
            });
            if kind == CurveKind::NeimarkSacker && !has_complex_pair_on_circle(&a) {
                continue;
            }
            let s = arclength + (&a.u - &current.u).norm();
            curve.codim2.push(Codim2Point {
                kind: Codim2Kind::Meets { kind },
                point: system.describe(&a, s),
                precision,
            });
        }
        if ahead(&next.u) {
            // Past the end of the range: the last point on it.
            let fix2 = DVector::from_fn(d + 2, |i, _| if i == d + 1 { 1.0 } else { 0.0 });
            if let Ok((last, _)) = system.correct(&next.u, &fix2, target) {
                let s = arclength + (&last.u - &current.u).norm();
                curve.points.push(system.describe(&last, s));
            }
            curve.end = CurveEnd::RangeEnd { parameter2: to2 };
            return curve;
        }
        arclength += (&next.u - &current.u).norm();
        curve.points.push(system.describe(&next, arclength));
        tangent = match system.tangent(&next, &tangent) {
            Ok(t) => t,
            Err(f) => {
                curve.end = step_floor(system, &next, f);
                return curve;
            }
        };
        current = next;
        ds = (ds * 1.5).min(options.max_step);
    }
    curve
}

fn step_floor<F: Fn(f64, f64) -> ChainParams>(
    system: &System<'_, F>,
    at: &Eval,
    f: system::Failure,
) -> CurveEnd {
    let (parameter, parameter2) = system.parameters(&at.u);
    if f.degenerate {
        CurveEnd::Degenerate {
            parameter,
            parameter2,
        }
    } else {
        CurveEnd::StepFloor {
            parameter,
            parameter2,
            reason: f.reason,
        }
    }
}
