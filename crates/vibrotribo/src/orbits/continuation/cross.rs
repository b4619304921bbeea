//! Continuing a branch through a change of its event sequence: grazing, sticking onset or
//! loss, chatter onset.
//!
//! Across such a point the stroboscopic map is continuous but not differentiable: at a
//! grazing it has a square-root singularity (Nordmark's map `P(z) = P_s(z) + E√(−h(z)) + …`,
//! h the gap minimum of the smooth flow), so the branch has a corner and the arclength
//! corrector, which searches the plane normal to the old tangent, cannot turn it. When the
//! step falls to its floor the branch is crossed in the parameter instead:
//!
//! 1. **Forward**: Newton's method at fixed `p_a + σδ` (σ the branch's direction, δ growing
//!    from 1e-6 to 1.6e-2 of the range by factors of 4) from the last orbit. An orbit with the
//!    same sequence farther on hands the branch back to the arclength continuation; one with
//!    a new sequence is a persistence, located by bisection in the parameter.
//! 2. **The edge**: where no orbit converges any more, the last parameter `p*` with the old
//!    sequence is found by bisection to the location tolerance.
//! 3. **Both sides**: orbits with the new sequence are sought at `p* + σε` (persistence: the
//!    branch goes on) and, if none is found there, at `p* − σε` (non-smooth fold: the two
//!    orbits meet at `p*` and the branch turns back), ε from 1e-6 to 1e-3 of the range, first
//!    where the linearised square-root map (`SquareRootModel`) puts them, then from the edge
//!    orbit moved along the gradient `c = ∂h/∂z` of the grazing gap (by `−η c/|c|²`, so that
//!    the flow from it strikes the contact with a penetration η of 1e-12 … 1e-6 of the length
//!    unit, or `+η c/|c|²` to lift a slow impact off), with the gap and its gradient taken
//!    from the edge's flow and again from the flow at the new parameter (on a non-smooth
//!    fold's side the clearance grows linearly in the distance, beyond those penetrations).
//!    Newton's method is held to the event sequence of its starting point, so that it cannot
//!    fall onto the old orbit; on the square-root branch it converges from the side of small
//!    penetration (the map is convex there), which is why the guesses start shallow. The
//!    branch then goes on along the new sequence by natural steps away from the point before
//!    the arclength takes over; past a grazing of one gap minimum they are solved by Newton's
//!    method with the square root of the normal form built in ([`SquareRootModel::solve`]),
//!    since there the orbit's largest multiplier grows like the inverse of its impact speed.
//!
//! Feigin's rule for the square-root map (the new orbit has a multiplier that grows like the
//! inverse of its impact speed) says which of the two happens: `det(Φ − I)` keeps its sign
//! across a persistence and changes it across a non-smooth fold; the kind recorded is the
//! one found.

use nalgebra::DVector;

use super::corrector::{Problem, rounding_floor};
use super::locate::{MAX_LOCATE, StepPoint};
use super::nordmark::SquareRootModel;
use super::segments::{Impact, shoot};
use super::types::{Branch, CrossingKind};
use crate::dynamics::{EventKind, Simulator};
use crate::model::ChainParams;
use crate::orbits::gaps::{gap_gradient, smallest_gap_minimum};
use crate::orbits::map::{chatter_bounces, evaluate, signature};
use crate::orbits::shooting::newton_within;
use crate::sensitivity::{Sensitivity, state_from_vector, state_vector};

/// Parameter steps of the forward search, as fractions of the range: 1e-6 · 4^k.
const FORWARD_TRIES: i32 = 8;

/// Distances from the edge at which the new orbit is sought, fractions of the range.
const SIDE_STEPS: [f64; 4] = [1e-6, 1e-5, 1e-4, 1e-3];

/// Orbits of the branches followed before tried as guesses at a crossing: the nearest chords.
const KNOWN_GUESSES: usize = 4;

/// Penetrations (or lifts) of the guesses moved along the gap gradient, in the length unit.
pub(super) const PENETRATIONS: [f64; 4] = [1e-12, 1e-10, 1e-8, 1e-6];

/// Most natural steps taken along the new sequence past a grazing of one minimum (each twice
/// the last).
const ONWARD_STEPS: i32 = 24;

/// Natural steps taken along the new sequence after a crossing without a square-root model
/// of one grazing minimum (each four times the last).
const FEW_ONWARD_STEPS: i32 = 5;

/// How far from the point the natural steps past a grazing go, as a fraction of the range.
const ONWARD_REACH: f64 = 2e-2;

/// A gap minimum below this fraction of the length unit is taken as grazing.
pub(super) const NEAR_GRAZING: f64 = 1e-4;

/// The change of sequence crossed.
pub(crate) struct Crossed {
    /// The last orbit with the old sequence.
    pub before: StepPoint,
    /// The first orbit with the new sequence.
    pub after: StepPoint,
    /// Orbits farther along the new sequence, by natural steps away from the point.
    pub onward: Vec<StepPoint>,
    /// Accuracy of the point in the parameter.
    pub precision: f64,
    /// The slowest impact (contact, closing speed in m/s) of the orbit with the old sequence
    /// a little behind the edge, where it was found.
    pub behind_speed: Option<(usize, f64)>,
    pub kind: CrossingKind,
    /// Tangent of the branch at the last of `onward` (or `after`), oriented the way it goes
    /// on.
    pub tangent: DVector<f64>,
}

/// What a crossing attempt found.
pub(crate) enum Bridged {
    /// An orbit with the same sequence farther on, and its tangent.
    Same(Box<StepPoint>, DVector<f64>),
    /// A change of sequence, crossed.
    Crossed(Box<Crossed>),
}

/// Tries to take the branch past `current` in the parameter's `direction` (±1), within
/// `[lo, hi]` (module docs).
///
/// `came_from`: the parameter of the last change crossed and the sequence before it; the
/// branch does not cross back onto that sequence there. `known`: the branches followed
/// before, whose orbits near the edge are tried last as orbits with the new sequence (the
/// branch may land on one of them: see [`runs_onto`](super::onto::runs_onto)).
pub(crate) fn cross<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    current: &StepPoint,
    direction: f64,
    (lo, hi): (f64, f64),
    came_from: Option<(f64, &[(EventKind, usize)])>,
    known: &[Branch],
) -> Option<Bridged> {
    let parameter = |s: &StepPoint| s.described.point.parameter;
    let signature = &current.described.signature;
    let arclength = |p: f64| arclength_at(problem, current, p);
    let (ok, precision) = match edge(problem, current, direction, (lo, hi))? {
        Edge::Open(ok) => {
            let t = problem.tangent(&ok.ev, &along(problem, direction))?;
            return Some(Bridged::Same(Box::new(ok), t));
        }
        Edge::At { ok, precision } => (ok, precision),
    };
    // 3. The new sequence on either side of the edge: first where the square-root map puts
    // it, then from the generic guesses.
    let back =
        parameter(&ok) - direction * (1e-6 * problem.p_scale).max(10.0 * problem.options.location_tolerance);
    let behind = orbit_keeping(
        problem,
        &problem.state(&ok.ev.u),
        back,
        arclength(back),
        signature,
    );
    let model = behind
        .as_ref()
        .and_then(|b| SquareRootModel::new(problem, &ok, b));
    let behind_speed = behind.and_then(|b| b.described.point.min_closing_speed);
    let edge_guesses = guesses(problem, &ok, parameter(&ok));
    let sequences = new_sequences(problem, &ok);
    // The persistence side first, at every distance: a symmetric orbit that grazes two
    // contacts at once may also meet orbits striking only one of them at a fold. Orbits
    // shot with a prescribed impact sequence only where no guess of the first pass leads to
    // one, on either side.
    for prescribed_pass in [false, true] {
        for (sigma, kind) in [
            (direction, CrossingKind::Persistence),
            (-direction, CrossingKind::NonSmoothFold),
        ] {
            for step in SIDE_STEPS {
                let eps = (step * problem.p_scale).max(10.0 * problem.options.location_tolerance);
                let p = parameter(&ok) + sigma * eps;
                if p < lo || p > hi {
                    continue;
                }
                let fresh = |o: &StepPoint| {
                    o.described.signature != *signature
                        && !came_from.is_some_and(|(q, s)| {
                            o.described.signature == s && (p - q).abs() < 1e-3 * problem.p_scale
                        })
                };
                let beyond =
                    |z: &DVector<f64>| orbit_beyond(problem, z, p, arclength(p), signature).filter(&fresh);
                let found = if prescribed_pass {
                    sequences
                        .iter()
                        .filter_map(|impacts| prescribed(problem, &ok, impacts, p))
                        .find_map(|z| confirmed(problem, &z, p, arclength(p), signature).filter(&fresh))
                } else {
                    // From the edge's flow first; only then from the flow at p (the clearance a
                    // fold's side opens taken into account), whose gap and gradient cost
                    // evaluations of their own.
                    let predicted = model.as_ref().map_or_else(Vec::new, |m| m.guesses(sigma * eps));
                    predicted
                        .iter()
                        .chain(&edge_guesses)
                        .find_map(&beyond)
                        .or_else(|| guesses(problem, &ok, p).iter().skip(1).find_map(&beyond))
                        .or_else(|| known_guesses(problem, known, &ok, p).iter().find_map(&beyond))
                };
                if let Some(o) = found {
                    return crossed(
                        problem,
                        (ok, o),
                        model.as_ref(),
                        (precision, behind_speed),
                        (sigma, kind),
                        (lo, hi),
                    );
                }
            }
        }
    }
    None
}

/// How far the old sequence goes from `current` in the parameter's `direction`.
enum Edge {
    /// Past every forward try (or to the range end): the last orbit reached.
    Open(StepPoint),
    /// It ends next to `ok`, its last orbit, located to `precision`.
    At { ok: StepPoint, precision: f64 },
}

/// The arclength at `p` of an orbit reached from `current` by natural steps.
fn arclength_at<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, current: &StepPoint, p: f64) -> f64 {
    current.described.point.arclength + (p - current.described.point.parameter).abs() / problem.p_scale
}

/// Steps 1 and 2 of [`cross`] (module docs): forward as far as the old sequence goes (at
/// most 1.6e-2 of the range), then its edge by bisection. `None` if not even the first
/// step leaves `current` (at the range end).
fn edge<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    current: &StepPoint,
    direction: f64,
    (lo, hi): (f64, f64),
) -> Option<Edge> {
    let parameter = |s: &StepPoint| s.described.point.parameter;
    let signature = &current.described.signature;
    let arclength = |p: f64| arclength_at(problem, current, p);
    let mut ok = current.clone();
    let mut bad = None;
    for k in 0..FORWARD_TRIES {
        let p = (parameter(current) + direction * 1e-6 * 4f64.powi(k) * problem.p_scale).clamp(lo, hi);
        if p == parameter(&ok) {
            break;
        }
        match orbit_keeping(problem, &problem.state(&ok.ev.u), p, arclength(p), signature) {
            Some(o) => ok = o,
            None => {
                bad = Some(p);
                break;
            }
        }
    }
    let Some(mut p_bad) = bad else {
        return (parameter(&ok) != parameter(current)).then_some(Edge::Open(ok));
    };
    for _ in 0..MAX_LOCATE {
        if (p_bad - parameter(&ok)).abs() <= problem.options.location_tolerance {
            break;
        }
        let p = 0.5 * (parameter(&ok) + p_bad);
        match orbit_keeping(problem, &problem.state(&ok.ev.u), p, arclength(p), signature) {
            Some(o) => ok = o,
            None => p_bad = p,
        }
    }
    let precision = (p_bad - parameter(&ok)).abs();
    Some(Edge::At { ok, precision })
}

/// The orbit at `p` with the event sequence `keep`, from `z` (Newton's method held to it).
pub(super) fn orbit_keeping<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
    arclength: f64,
    keep: &[(EventKind, usize)],
) -> Option<StepPoint> {
    let params = (problem.family)(p);
    let end = problem.end(&params);
    let c = newton_within(
        &params,
        z.clone(),
        problem.period,
        problem.phase,
        &problem.options.shooting,
        |e| sequence(&e.events, end) == keep,
    )
    .ok()?;
    let ev = problem.evaluate(&problem.point(&c.z, p)).ok()?;
    let described = problem.describe(&ev, arclength)?;
    (described.signature == keep).then_some(StepPoint {
        theta: 0.0,
        ev,
        described,
    })
}

/// The event sequence of an evaluation over one period (events before `end`).
pub(super) fn sequence(events: &[crate::dynamics::Event], end: f64) -> Vec<(EventKind, usize)> {
    let events: Vec<_> = events.iter().filter(|ev| ev.time < end).copied().collect();
    signature(&events)
}

/// The orbit at `p` with another event sequence than `old`, from `z`: Newton's method held to
/// the sequence of the flow from `z` (near a non-smooth fold the orbit with the old sequence
/// lies as close, and an unconstrained iteration may fall onto it).
fn orbit_beyond<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
    arclength: f64,
    old: &[(EventKind, usize)],
) -> Option<StepPoint> {
    let target = flow_sequence(problem, z, p)?;
    if target == old {
        return None;
    }
    orbit_keeping(problem, z, p, arclength, &target)
}

/// The orbit at `p` from `z` with the event sequence of the flow from `z` (Newton's method
/// held to it).
pub(super) fn orbit_following<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
    arclength: f64,
) -> Option<StepPoint> {
    orbit_keeping(problem, z, p, arclength, &flow_sequence(problem, z, p)?)
}

/// The event sequence over the problem's period of the flow from `z` at `p`.
fn flow_sequence<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
) -> Option<Vec<(EventKind, usize)>> {
    let params = (problem.family)(p);
    let opts = &problem.options.shooting;
    let first = evaluate(
        &params,
        z,
        problem.period,
        problem.phase,
        &opts.sim,
        &opts.sensitivity,
    )
    .ok()?;
    let end = problem.end(&params);
    Some(sequence(&first.events, end))
}

/// A unit vector along the parameter, signed.
fn along<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, direction: f64) -> DVector<f64> {
    let mut v = DVector::zeros(problem.dim() + 1);
    v[problem.dim()] = direction;
    v
}

fn crossed<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    (before, after): (StepPoint, StepPoint),
    model: Option<&SquareRootModel>,
    (precision, behind_speed): (f64, Option<(usize, f64)>),
    (direction, kind): (f64, CrossingKind),
    (lo, hi): (f64, f64),
) -> Option<Bridged> {
    // Past a grazing of one minimum the steps start at the point and double; elsewhere (no
    // square-root model, or several minima grazing together) they start at `after` and grow
    // fourfold, from the last orbit.
    let single = model.filter(|m| m.is_single());
    let keep = after.described.signature.clone();
    let p_edge = before.described.point.parameter;
    let p_after = after.described.point.parameter;
    let first = (p_after - p_edge).abs();
    let (origin, factor, steps) = match single {
        Some(_) => (p_edge, 2f64, ONWARD_STEPS),
        None => (p_after, 4f64, FEW_ONWARD_STEPS),
    };
    let mut onward: Vec<StepPoint> = Vec::new();
    for k in 1..=steps {
        let p = origin + direction * first * factor.powi(k);
        if p <= lo || p >= hi || (single.is_some() && (p - p_edge).abs() > ONWARD_REACH * problem.p_scale) {
            break;
        }
        let last = onward.last().unwrap_or(&after);
        let (z1, p1) = (problem.state(&last.ev.u), last.described.point.parameter);
        let s = last.described.point.arclength + (p - p1).abs() / problem.p_scale;
        let found = match single {
            Some(m) => {
                let previous = match onward.len() {
                    0 => &before,
                    n if n >= 2 => &onward[n - 2],
                    _ => &after,
                };
                let (z0, p0) = (problem.state(&previous.ev.u), previous.described.point.parameter);
                let predicted = &z1 + (&z1 - &z0) * ((p - p1) / (p1 - p0));
                orbit_keeping(problem, &predicted, p, s, &keep)
                    .or_else(|| m.solve(problem, &predicted, p, s, &keep))
                    .or_else(|| orbit_keeping(problem, &z1, p, s, &keep))
            }
            None => orbit_keeping(problem, &z1, p, s, &keep),
        };
        match found {
            Some(o) => onward.push(o),
            None => break,
        }
    }
    let tangent = problem.tangent(&onward.last().unwrap_or(&after).ev, &along(problem, direction))?;
    Some(Bridged::Crossed(Box::new(Crossed {
        before,
        after,
        onward,
        precision,
        behind_speed,
        kind,
        tangent,
    })))
}

/// Initial states at the parameter `p` for the orbit with the new sequence near the edge orbit
/// `edge`: the orbit itself, and the orbit moved along the gradient of the gap that grazes (a
/// gap minimum near zero: moved into contact) or of the slowest impact (moved out of contact).
/// The gap and its gradient are those of the flow at `p`, so that the move makes up for the
/// clearance the parameter step opened (on a non-smooth fold's side it grows linearly in the
/// step, faster than the penetrations tried).
fn guesses<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    edge: &StepPoint,
    p: f64,
) -> Vec<DVector<f64>> {
    let z = problem.state(&edge.ev.u);
    let mut out = vec![z.clone()];
    let params = (problem.family)(p);
    let opts = &problem.options.shooting;
    let length = problem.scale.length;
    let end = problem.end(&params);
    // (contact, time, +1 to move into contact or −1 out of it, gap now in m)
    let mut targets = Vec::new();
    if let Some(m) = smallest_gap_minimum(&params, &z, problem.period, problem.phase, &opts.sim)
        && m.gap < NEAR_GRAZING * length
    {
        targets.push((m.contact, m.time, 1.0, m.gap));
    }
    let events = &edge.ev.eval.events;
    let bounces = chatter_bounces(events);
    if let Some(e) = events
        .iter()
        .zip(&bounces)
        .filter(|(e, b)| e.kind == EventKind::Impact && !**b && e.time < end)
        .map(|(e, _)| e)
        .min_by(|a, b| a.velocity_before.total_cmp(&b.velocity_before))
    {
        // Just before the impact: the gap's gradient there is that of the smooth flow's
        // minimum to first order.
        let before = e.time - 1e-9 * params.period();
        targets.push((e.contact, before, -1.0, 0.0));
    }
    let n = problem.n;
    let s = |i: usize| problem.scale.of_component(i, n);
    for (contact, time, into, gap) in targets {
        let Some(c) = gap_gradient(
            &params,
            &z,
            problem.phase,
            contact,
            time,
            &opts.sim,
            &opts.sensitivity,
        ) else {
            continue;
        };
        // The smallest move (in the scaled norm) that changes the gap by one metre.
        let norm2: f64 = (0..c.len()).map(|i| (c[i] * s(i)).powi(2)).sum();
        if !(norm2 > 0.0 && norm2.is_finite()) {
            continue;
        }
        let unit = DVector::from_fn(c.len(), |i, _| c[i] * s(i) * s(i) / norm2);
        for eta in PENETRATIONS {
            let change = if into > 0.0 {
                -(gap + eta * length)
            } else {
                eta * length
            };
            out.push(&z + &unit * change);
        }
    }
    out
}

/// Initial states at the parameter `p`, on the problem's section, from the branches followed
/// before (of the problem's period): each chord between two consecutive points whose
/// parameters bracket `p`, interpolated there, carried from t ≡ 0 to the section by the flow
/// at `p`; the [`KNOWN_GUESSES`] nearest the edge orbit `edge` (at t ≡ 0, in the scaled
/// state), nearest first.
fn known_guesses<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    branches: &[Branch],
    edge: &StepPoint,
    p: f64,
) -> Vec<DVector<f64>> {
    let here = state_vector(&edge.described.point.state);
    let mut near: Vec<(f64, DVector<f64>)> = branches
        .iter()
        .filter(|b| b.period == problem.period)
        .flat_map(|b| b.points.windows(2))
        .filter(|w| w[0].parameter != w[1].parameter && (w[0].parameter - p) * (w[1].parameter - p) <= 0.0)
        .map(|w| {
            let z = w[0].towards(&w[1], (p - w[0].parameter) / (w[1].parameter - w[0].parameter));
            (problem.scale.norm(&(&z - &here)), z)
        })
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0));
    let params = (problem.family)(p);
    let sim = &problem.options.shooting.sim;
    near.into_iter()
        .take(KNOWN_GUESSES)
        .filter_map(|(_, z)| {
            if problem.phase == 0.0 {
                return Some(z);
            }
            let mut run =
                Simulator::new_at(&params, 0.0, &state_from_vector(z.as_slice()), sim.clone()).ok()?;
            run.run_until(problem.phase, &mut None::<Sensitivity>).ok()?;
            Some(state_vector(&run.state()))
        })
        .collect()
}

/// The impact sequences the orbit with the new sequence may have next to the edge orbit
/// `edge`, each with the edge's times as guesses: the edge's impacts with the grazing gap's
/// minimum added as an impact (if it is near zero), and without its slowest impact. None if
/// the edge orbit sticks or chatters (only sequences of impacts are prescribed).
fn new_sequences<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, edge: &StepPoint) -> Vec<Vec<Impact>> {
    let Some(impacts) = impacts_of(problem, edge) else {
        return Vec::new();
    };
    let params = (problem.family)(edge.described.point.parameter);
    let mut out = Vec::new();
    let z = problem.state(&edge.ev.u);
    let sim = &problem.options.shooting.sim;
    if let Some(m) = smallest_gap_minimum(&params, &z, problem.period, problem.phase, sim)
        && m.gap < NEAR_GRAZING * problem.scale.length
    {
        let mut added = impacts.clone();
        let at = added.partition_point(|i| i.time < m.time);
        added.insert(
            at,
            Impact {
                contact: m.contact,
                time: m.time,
            },
        );
        out.push(added);
    }
    let speeds = edge.ev.eval.events.iter().map(|e| e.velocity_before);
    if let Some(slowest) = speeds
        .take(impacts.len())
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(i, _)| i)
    {
        let mut lost = impacts;
        lost.remove(slowest);
        out.push(lost);
    }
    out
}

/// The orbit at `p` with the event sequence of the flow from `z` (a start state shot with a
/// prescribed impact sequence), if that is not `old`: by Newton's method held to it, or where
/// that stops above its tolerance, by Newton's method at the fixed parameter with the
/// corrector's acceptance. Next to a grazing the map's derivative grows like the inverse of
/// the slow impact's speed, and so does the rounding its residual cannot fall below
/// ([`rounding_floor`]), which the shooting's own tolerance does not allow for.
fn confirmed<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
    arclength: f64,
    old: &[(EventKind, usize)],
) -> Option<StepPoint> {
    if let Some(o) = orbit_beyond(problem, z, p, arclength, old) {
        return Some(o);
    }
    let keep = flow_sequence(problem, z, p).filter(|s| s != old)?;
    let params = (problem.family)(p);
    let end = problem.end(&params);
    // Not the corrector at a fixed parameter: it requires the residual to halve from the
    // second iteration on, which next to a grazing, with the map's rounding amplified, it
    // need not (with it the impact oscillator's period-8 grazing at Ω = 2.6985671 is not
    // crossed). Here any decrease goes on, within the same acceptance.
    let dim = problem.dim();
    let mut u = problem.point(z, p);
    let mut last = f64::INFINITY;
    for _ in 0..CONFIRM_ITERATIONS {
        let ev = problem.evaluate(&u).ok()?;
        if sequence(&ev.eval.events, end) != keep {
            return None;
        }
        let r = ev.residual.amax();
        if r <= problem
            .options
            .corrector_tolerance
            .max(rounding_floor(&ev.jacobian))
        {
            let described = problem.describe(&ev, arclength)?;
            return (described.signature == keep).then_some(StepPoint {
                theta: 0.0,
                ev,
                described,
            });
        }
        if r >= last {
            return None;
        }
        last = r;
        let step = ev
            .jacobian
            .columns(0, dim)
            .into_owned()
            .lu()
            .solve(&(-&ev.residual))?;
        for i in 0..dim {
            u[i] += step[i];
        }
    }
    None
}

/// Newton iterations of [`confirmed`] at the fixed parameter.
const CONFIRM_ITERATIONS: usize = 8;

/// The impacts of the orbit `point` over one period of the problem, in time order; `None` if
/// it has events of other kinds (sticking, chatter).
fn impacts_of<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, point: &StepPoint) -> Option<Vec<Impact>> {
    let params = (problem.family)(point.described.point.parameter);
    let end = problem.end(&params);
    point
        .ev
        .eval
        .events
        .iter()
        .filter(|e| e.time < end)
        .map(|e| {
            (e.kind == EventKind::Impact).then_some(Impact {
                contact: e.contact,
                time: e.time,
            })
        })
        .collect()
}

/// The start state at `p` of an orbit with the impacts `impacts` near the edge orbit `edge`,
/// by multiple shooting in the impact times ([`segments`](super::segments)), if that orbit
/// tends to the edge orbit: shot again a sixteenth as far from the edge, it is at most half
/// as far from the edge orbit (an orbit born at the edge moves like the distance, or its
/// square root; a distant orbit with that sequence does not come nearer).
fn prescribed<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    edge: &StepPoint,
    impacts: &[Impact],
    p: f64,
) -> Option<DVector<f64>> {
    let p_edge = edge.described.point.parameter;
    let z_edge = problem.state(&edge.ev.u);
    let at = |p: f64, z: &DVector<f64>, impacts: &[Impact]| {
        let params = (problem.family)(p);
        let duration = problem.duration(&params);
        shoot(
            &params,
            z,
            impacts,
            (problem.phase, duration),
            &problem.scale,
            &problem.options.shooting.sim,
        )
    };
    let (z, found) = at(p, &z_edge, impacts)?;
    let (z_near, _) = at(p_edge + (p - p_edge) / 16.0, &z, &found)?;
    let distance = |z: &DVector<f64>| problem.scale.norm(&(z - &z_edge));
    (distance(&z_near) <= 0.5 * distance(&z)).then_some(z)
}
