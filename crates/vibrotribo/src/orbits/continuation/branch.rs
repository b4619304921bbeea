//! Following branches: the predictor–corrector loop, detection of bifurcations in each step,
//! and the switch onto period-doubled branches.

use std::collections::VecDeque;

use nalgebra::DVector;

use super::corrector::{Failure, Problem};
use super::cross::{Bridged, cross};
use super::locate::{Located, Step, StepPoint, classify, locate_change, locate_root};
use super::phase::{move_section, too_close};
use super::types::{
    Bifurcation, BifurcationKind, Branch, BranchEnd, BranchPoint, Continuation, ContinuationOptions,
    Crossing, CrossingKind, NordmarkScenario,
};
use crate::error::ParamError;
use crate::model::{ChainParams, ChainState};
use crate::orbits::error::OrbitError;
use crate::orbits::floquet::real_eigenvector;
use crate::orbits::gaps::smallest_gap_minimum;
use crate::orbits::map::Scale;
use crate::orbits::shooting::find_periodic_orbit;
use crate::sensitivity::state_vector;

/// A branch that cannot go on ends at a grazing if a gap minimum is below this fraction of
/// the length unit L.
const GRAZING_GAP: f64 = 1e-4;

/// Where a branch starts.
enum Start {
    /// A converged orbit: state and parameter.
    Orbit(DVector<f64>, f64),
    /// A period doubling of the parent at the scaled point `u`, with the critical
    /// eigenvector `direction` (scaled, zero in the parameter).
    Doubling {
        u: DVector<f64>,
        direction: DVector<f64>,
        /// The parent branch's unit tangent there (scaled).
        parent: DVector<f64>,
    },
}

struct Seed {
    period: u32,
    /// Section phase of `start`, s.
    phase: f64,
    depth: u32,
    parent: Option<(usize, usize)>,
    start: Start,
}

/// A period doubling found on a branch, to be followed.
struct Doubling {
    bifurcation: usize,
    /// Section phase of `u`, s.
    phase: f64,
    u: DVector<f64>,
    direction: DVector<f64>,
    /// The branch's unit tangent at the point (scaled).
    tangent: DVector<f64>,
}

/// Pseudo-arclength continuation of the periodic orbit of period `period` near `guess` at
/// parameter `from`, for the family `family` (any scalar that changes [`ChainParams`],
/// called `name`), towards `to`; see the [module docs](crate::orbits::continuation).
///
/// The first orbit is found by [`find_periodic_orbit`] at `from`. Every branch is followed
/// until it leaves `[min(from, to), max(from, to)]` or ends otherwise ([`BranchEnd`]).
///
/// ```no_run
/// use vibrotribo::orbits::{ContinuationOptions, continue_orbit};
/// use vibrotribo::{ChainParams, ChainState, Frequency, SimOptions, Simulator};
///
/// let family = |omega: f64| {
///     let mut p = ChainParams::default();
///     p.excitation.frequency = Frequency::OmegaRatio(omega);
///     p
/// };
/// let mut sim = Simulator::new(&family(0.7), &ChainState::at_rest(3), SimOptions::default())?;
/// sim.run_until(100.0 * family(0.7).period(), &mut ())?;
/// let result = continue_orbit("omega_ratio", family, 0.7, 0.8, &sim.state(), 1, &ContinuationOptions::default())?;
/// for b in &result.branches[0].bifurcations {
///     println!("{:?} at Ω = {}", b.kind, b.parameter);
/// }
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn continue_orbit<F>(
    name: &str,
    family: F,
    from: f64,
    to: f64,
    guess: &ChainState,
    period: u32,
    options: &ContinuationOptions,
) -> Result<Continuation, OrbitError>
where
    F: Fn(f64) -> ChainParams,
{
    options.validate()?;
    if period == 0 {
        return Err(OrbitError::ZeroPeriod);
    }
    for (what, v) in [("from", from), ("to", to)] {
        if !v.is_finite() {
            return Err(ParamError::invalid(what, v, "must be a finite number").into());
        }
    }
    if from == to {
        return Err(ParamError::invalid("to", to, "must differ from `from`").into());
    }
    let params = family(from);
    let orbit = find_periodic_orbit(&params, guess, period, &options.shooting)?;
    let scale = Scale::of(&params);
    let (lo, hi) = (from.min(to), from.max(to));
    let mut branches: Vec<Branch> = Vec::new();
    let mut queue = VecDeque::from([Seed {
        period,
        phase: 0.0,
        depth: 0,
        parent: None,
        start: Start::Orbit(state_vector(&orbit.state), from),
    }]);
    let mut complete = true;
    while let Some(seed) = queue.pop_front() {
        if options.shooting.cancel.requested() {
            complete = false;
            break;
        }
        let problem = Problem {
            family: &family,
            period: seed.period,
            n: params.len(),
            phase: 0.0,
            scale,
            p_scale: hi - lo,
            options,
        };
        let direction = if to > from { 1.0 } else { -1.0 };
        let (mut branch, doublings) = follow(&problem, &seed, (lo, hi), direction);
        complete &= !matches!(branch.end, BranchEnd::Stopped { .. });
        let index = branches.len();
        // A doubled branch that came back to its parent at another period doubling was
        // followed from both ends: drop the seed at the other end.
        if let BranchEnd::Collapsed { parameter } = branch.end {
            let near = 1e-3 * (hi - lo);
            queue.retain(|s| {
                let Some((b, k)) = s.parent else { return true };
                let other = &mut branches[b].bifurcations[k];
                let same = s.period == branch.period && (other.parameter - parameter).abs() <= near;
                if same {
                    other.child = Some(index);
                }
                !same
            });
        }
        for d in doublings {
            if index + 1 + queue.len() >= options.max_branches {
                break;
            }
            branch.bifurcations[d.bifurcation].child = Some(index + 1 + queue.len());
            queue.push_back(Seed {
                period: 2 * seed.period,
                phase: d.phase,
                depth: seed.depth + 1,
                parent: Some((index, d.bifurcation)),
                start: Start::Doubling {
                    u: d.u,
                    direction: d.direction,
                    parent: d.tangent,
                },
            });
        }
        branches.push(branch);
    }
    if !complete {
        // Period doublings whose branches were not followed have no child.
        let followed = branches.len();
        for b in &mut branches {
            for bif in &mut b.bifurcations {
                bif.child = bif.child.filter(|c| *c < followed);
            }
        }
    }
    Ok(Continuation {
        parameter: name.to_string(),
        branches,
        complete,
    })
}

/// The end of a branch stopped by the caller after the point `current`.
fn stopped(current: &StepPoint) -> BranchEnd {
    BranchEnd::Stopped {
        parameter: current.described.point.parameter,
    }
}

/// The first point of a branch and its tangent.
fn start<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    seed: &Seed,
    direction: f64,
) -> Result<(StepPoint, DVector<f64>), Failure> {
    let dim = problem.dim();
    match &seed.start {
        Start::Orbit(z, p) => {
            let u = problem.point(z, *p);
            let ev = problem.evaluate(&u)?;
            let mut along = DVector::zeros(dim + 1);
            along[dim] = direction;
            let t = problem.tangent(&ev, &along).ok_or_else(|| failure(&ev))?;
            let described = problem.describe(&ev, 0.0).ok_or_else(|| failure(&ev))?;
            Ok((
                StepPoint {
                    theta: 0.0,
                    ev,
                    described,
                },
                t,
            ))
        }
        Start::Doubling { u, direction, parent } => {
            // The pitchfork of the doubled map: its new branch leaves along the critical
            // eigenvector with the parameter stationary. The step and the corrector's plane
            // are taken orthogonal to the parent branch's tangent, so that the corrector
            // cannot slide along the parent branch (which crosses a plane normal to the
            // eigenvector alone a short way off when the doubled branch is flat). A step too
            // short may still fall back onto the orbit of the parent's period, one too long
            // leave the corrector's reach: from 1/16 of the first step up to 64 times it, then
            // down to 1/1024 of it (deep in a cascade the doubled branches are small).
            let across = direction - parent * parent.dot(direction);
            let direction = if across.norm() > 1e-3 {
                across.normalize()
            } else {
                direction.clone()
            };
            let direction = &direction;
            let mut last = None;
            for k in [-2, -1, 0, 1, 2, 3, -3, -4, -5] {
                let ds = problem.options.initial_step * 4f64.powi(k);
                let step = Step {
                    base: u,
                    tangent: direction,
                    ds,
                    s0: 0.0,
                };
                match step.at(problem, 1.0) {
                    Ok(p) if !collapsed(problem, &p) => {
                        let away = &p.ev.u - u;
                        let t = problem.tangent(&p.ev, &away).ok_or_else(|| failure(&p.ev))?;
                        return Ok((StepPoint { theta: 0.0, ..p }, t));
                    }
                    Ok(p) => last = Some(failure(&p.ev)),
                    Err(f) => last = Some(f),
                }
            }
            Err(last.unwrap_or_else(|| failure_of(super::super::error::NewtonFailure::Iterations)))
        }
    }
}

fn failure_of(reason: super::super::error::NewtonFailure) -> Failure {
    Failure {
        reason,
        non_smooth: None,
        residuals: Vec::new(),
    }
}

fn failure(ev: &super::corrector::Evaluated) -> Failure {
    Failure {
        reason: super::super::error::NewtonFailure::Singular,
        non_smooth: None,
        residuals: vec![ev.residual.amax()],
    }
}

/// For an orbit of even period 2P: how far its state after P periods is from its section
/// state, in the units (0 when it is in fact of period P).
fn cycle_amplitude<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, p: &StepPoint) -> f64 {
    let half = (problem.period / 2) as usize;
    let sections = &p.ev.eval.sections;
    match (sections.first(), sections.get(half)) {
        (Some(a), Some(b)) if problem.period.is_multiple_of(2) => problem.scale.norm(&(b - a)),
        _ => f64::INFINITY,
    }
}

/// Whether an orbit of a doubled branch (period 2P) is in fact of period P: its state after
/// P periods equals its section state to 1e-7 of the units.
fn collapsed<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, p: &StepPoint) -> bool {
    cycle_amplitude(problem, p) < 1e-7
}

/// Whether a step of a doubled branch (period 2P) went through the branch of period P onto
/// the other half of its pitchfork: the new point is nearer the old point's state after P
/// periods (the same orbit, shifted by P periods) than the old point itself.
fn flipped<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, a: &StepPoint, b: &StepPoint) -> bool {
    let half = (problem.period / 2) as usize;
    let (Some(za), Some(shifted), Some(zb)) = (
        a.ev.eval.sections.first(),
        a.ev.eval.sections.get(half),
        b.ev.eval.sections.first(),
    ) else {
        return false;
    };
    problem.period.is_multiple_of(2)
        && problem.scale.norm(&(zb - shifted)) < 0.5 * problem.scale.norm(&(zb - za))
}

/// What [`detect`] found that ends a branch.
#[derive(Default)]
struct Ending {
    /// A period doubling at the deepest level.
    cascade: Option<f64>,
    /// A doubled branch back on the branch of half its period (at the other end of a
    /// period-doubling bubble).
    rejoin: Option<f64>,
}

/// Follows one branch from its seed.
fn follow<F: Fn(f64) -> ChainParams>(
    base: &Problem<'_, F>,
    seed: &Seed,
    (lo, hi): (f64, f64),
    direction: f64,
) -> (Branch, Vec<Doubling>) {
    let opts = base.options;
    let mut branch = Branch {
        period: seed.period,
        parent: seed.parent,
        points: Vec::new(),
        bifurcations: Vec::new(),
        end: BranchEnd::MaxPoints,
    };
    let mut doublings = Vec::new();
    // The section the branch is represented on (see `phase`).
    let mut problem = base.with_phase(seed.phase);
    let seed_parameter = match &seed.start {
        Start::Orbit(_, p) => *p,
        Start::Doubling { u, .. } => problem.parameter(u),
    };
    let (mut current, mut t) = match start(&problem, seed, direction) {
        Ok(s) => s,
        Err(f) => {
            branch.end = match seed.start {
                Start::Orbit(..) => step_floor(seed_parameter, f),
                Start::Doubling { .. } => BranchEnd::SwitchFailed {
                    parameter: seed_parameter,
                },
            };
            return (branch, doublings);
        }
    };
    branch.points.push(current.described.point.clone());
    let mut ds = opts.initial_step;
    // The sequence before the last change crossed by `cross` (not to be crossed back onto).
    let mut last_crossed: Option<Vec<(crate::dynamics::EventKind, usize)>> = None;
    // Every pass adds a point or halves the step; halvings between two points are bounded
    // by log2(initial/min), so this bound is never reached by a healthy branch.
    let passes = opts.max_points * 64;
    for _ in 0..passes {
        if opts.shooting.cancel.requested() {
            branch.end = stopped(&current);
            return (branch, doublings);
        }
        if too_close(&problem, &current)
            && let Some((phase, point, tangent)) = move_section(&problem, &current, &t)
        {
            problem = problem.with_phase(phase);
            (current, t) = (point, tangent);
        }
        if branch.points.len() >= opts.max_points {
            branch.end = BranchEnd::MaxPoints;
            return (branch, doublings);
        }
        let step = Step {
            base: &current.ev.u,
            tangent: &t,
            ds,
            s0: current.described.point.arclength,
        };
        let next = step.at(&problem, 1.0).and_then(|p| {
            let tn = problem.tangent(&p.ev, &t).ok_or_else(|| failure(&p.ev))?;
            Ok((p, tn))
        });
        let (new, t_new) = match next {
            // A tangent turning by more than ~25° in one step: the step is too long.
            Ok((p, tn))
                if (tn.dot(&t) >= 0.9 || ds <= 2.0 * opts.min_step)
                    && !falls_back(&branch, last_crossed.as_deref(), &current, &p, problem.p_scale) =>
            {
                (p, tn)
            }
            result => {
                ds *= 0.5;
                if ds >= opts.min_step {
                    continue;
                }
                // A search stopped by the caller is not a corner of the branch.
                if opts.shooting.cancel.requested() {
                    branch.end = stopped(&current);
                    return (branch, doublings);
                }
                // A corner the arclength corrector cannot turn (grazing): step across in
                // the parameter, the way the branch was going.
                let before = branch
                    .points
                    .iter()
                    .rev()
                    .map(|q| q.parameter)
                    .find(|q| *q != current.described.point.parameter);
                let progress = before.map_or(t[problem.dim()], |q| current.described.point.parameter - q);
                let came_from = branch.bifurcations.last().and_then(|b| {
                    let before = b.crossing.and(last_crossed.as_deref())?;
                    Some((b.parameter, before))
                });
                match cross(&problem, &current, progress.signum(), (lo, hi), came_from) {
                    Some(Bridged::Same(target, t_new)) => {
                        let target = *target;
                        branch.points.push(target.described.point.clone());
                        let p = target.described.point.parameter;
                        if p <= lo || p >= hi {
                            branch.end = BranchEnd::RangeEnd { parameter: p };
                            return (branch, doublings);
                        }
                        current = target;
                        t = t_new;
                        ds = opts.initial_step;
                        continue;
                    }
                    Some(Bridged::Crossed(c)) => {
                        last_crossed = Some(c.before.described.signature.clone());
                        branch.bifurcations.push(crossing_point(
                            &problem,
                            &c.before,
                            &c.after,
                            c.precision,
                            c.kind,
                        ));
                        branch.points.push(c.after.described.point.clone());
                        branch
                            .points
                            .extend(c.onward.iter().map(|o| o.described.point.clone()));
                        let last = c.onward.into_iter().last().unwrap_or(c.after);
                        let p = last.described.point.parameter;
                        if p <= lo || p >= hi {
                            branch.end = BranchEnd::RangeEnd { parameter: p };
                            return (branch, doublings);
                        }
                        current = last;
                        t = c.tangent;
                        ds = opts.initial_step;
                        continue;
                    }
                    None if opts.shooting.cancel.requested() => {
                        branch.end = stopped(&current);
                        return (branch, doublings);
                    }
                    None => {}
                }
                let parameter = current.described.point.parameter;
                let z = problem.state(&current.ev.u);
                let params = (problem.family)(parameter);
                let sim = &opts.shooting.sim;
                branch.end = match smallest_gap_minimum(&params, &z, problem.period, problem.phase, sim) {
                    Some(m) if m.gap < GRAZING_GAP * problem.scale.length => BranchEnd::Grazing {
                        parameter,
                        contact: m.contact,
                        gap: m.gap,
                    },
                    _ => step_floor(
                        parameter,
                        match result {
                            Ok((p, _)) => failure(&p.ev),
                            Err(f) => f,
                        },
                    ),
                };
                return (branch, doublings);
            }
        };
        let base_point = StepPoint {
            theta: 0.0,
            ..current.clone()
        };
        // Leaving the range: end exactly at its bound.
        let p_new = new.described.point.parameter;
        let bound = if p_new > hi {
            Some(hi)
        } else if p_new < lo {
            Some(lo)
        } else {
            None
        };
        let target = match bound {
            Some(b) => match locate_root(&problem, &step, &base_point, &new, |d| d.point.parameter - b) {
                Some(l) => l.point,
                None => new,
            },
            None => new,
        };
        let mut ending = Ending::default();
        if seed.depth > 0 && flipped(&problem, &base_point, &target) {
            let closer = if cycle_amplitude(&problem, &base_point) < cycle_amplitude(&problem, &target) {
                &base_point
            } else {
                &target
            };
            ending.rejoin = Some(closer.described.point.parameter);
        }
        detect(
            &problem,
            &step,
            &base_point,
            &target,
            (&t, &t_new),
            seed,
            &mut branch,
            &mut doublings,
            &mut ending,
        );
        branch.points.push(target.described.point.clone());
        if let Some(k) = closes(&problem, &branch, ds) {
            branch.end = BranchEnd::Closed {
                parameter: branch.points[k].parameter,
            };
            return (branch, doublings);
        }
        if seed.depth > 0 && collapsed(&problem, &target) {
            ending.rejoin.get_or_insert(target.described.point.parameter);
        }
        if let Some(parameter) = ending.rejoin {
            branch.end = BranchEnd::Collapsed { parameter };
            return (branch, doublings);
        }
        if let Some(b) = bound {
            branch.end = BranchEnd::RangeEnd { parameter: b };
            return (branch, doublings);
        }
        if let Some(parameter) = ending.cascade {
            branch.end = BranchEnd::CascadeDepth { parameter };
            return (branch, doublings);
        }
        ds = match target.ev.iterations {
            0..=2 => (ds * 1.5).min(opts.max_step),
            3..=4 => ds,
            _ => (ds * 0.7).max(opts.min_step),
        };
        current = StepPoint { theta: 0.0, ..target };
        t = t_new;
    }
    branch.end = BranchEnd::MaxPoints;
    (branch, doublings)
}

/// Whether a step from `current` to `new` goes back onto the sequence the branch left at its
/// last crossing (`left`), near it: two orbits meet at a non-smooth fold, and a step from one
/// may land on the other.
fn falls_back(
    branch: &Branch,
    left: Option<&[(crate::dynamics::EventKind, usize)]>,
    current: &StepPoint,
    new: &StepPoint,
    p_scale: f64,
) -> bool {
    let (Some(left), Some(last)) = (left, branch.bifurcations.last()) else {
        return false;
    };
    last.crossing.is_some()
        && new.described.signature != current.described.signature
        && new.described.signature == left
        && (new.described.point.parameter - last.parameter).abs() < 1e-2 * p_scale
}

/// Points a branch must have before it can be found closed.
const CLOSED_MIN_POINTS: usize = 8;

/// The earlier point the branch's newest point is back at (within a step `ds` in the scaled
/// units of the state and the parameter), if any: from there on the branch repeats itself.
/// A smooth solution curve can only come back to its first point (a closed curve); one with
/// corners (non-smooth points crossed by [`cross`]) can also run into a loop further on.
fn closes<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, branch: &Branch, ds: f64) -> Option<usize> {
    let n = branch.points.len();
    if n < CLOSED_MIN_POINTS {
        return None;
    }
    let distance = |a: &BranchPoint, b: &BranchPoint| {
        let za = state_vector(&a.state);
        let zb = state_vector(&b.state);
        problem
            .scale
            .norm(&(za - zb))
            .max((a.parameter - b.parameter).abs() / problem.p_scale)
    };
    let (last, before) = (&branch.points[n - 1], &branch.points[n - 2]);
    // The same orbit has the same impacts: two branches meeting at a non-smooth fold do not.
    let same =
        |old: &BranchPoint| old.impacts_per_period == last.impacts_per_period && old.sticks == last.sticks;
    // Arriving: the newest point is within a step of an old one and nearer it than the one
    // before (so that a branch that merely moves slowly is not taken for closed).
    branch.points[..n - CLOSED_MIN_POINTS]
        .iter()
        .position(|old| same(old) && distance(last, old) < ds && distance(last, old) < distance(before, old))
}

fn step_floor(parameter: f64, f: Failure) -> BranchEnd {
    BranchEnd::StepFloor {
        parameter,
        reason: f.reason,
        non_smooth: f.non_smooth,
        residuals: f.residuals,
    }
}

/// Finds and locates what happens between `base` and `target` (a step from `base`), and
/// appends it to `branch` in order along it.
#[allow(clippy::too_many_arguments)]
fn detect<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    step: &Step<'_>,
    base: &StepPoint,
    target: &StepPoint,
    (t_base, t_target): (&DVector<f64>, &DVector<f64>),
    seed: &Seed,
    branch: &mut Branch,
    doublings: &mut Vec<Doubling>,
    ending: &mut Ending,
) {
    let mut found: Vec<(f64, Bifurcation, Option<Doubling>)> = Vec::new();
    let mut intervals = vec![(base.clone(), target.clone())];
    if base.described.signature != target.described.signature {
        let (left, right, precision) = locate_change(problem, step, base, target);
        // The step went through the change: the parameter went on the way the branch was
        // going (persistence) or turned back at it (non-smooth fold).
        let dim = problem.dim();
        let onward = (right.described.point.parameter - left.described.point.parameter) * t_base[dim];
        let kind = if onward >= 0.0 {
            CrossingKind::Persistence
        } else {
            CrossingKind::NonSmoothFold
        };
        found.push((
            left.theta,
            crossing_point(problem, &left, &right, precision, kind),
            None,
        ));
        // The multipliers may jump across the change; look for smooth crossings on either
        // side of it only.
        intervals = vec![(base.clone(), left), (right, target.clone())];
    }
    let dim = problem.dim();
    for (a, b) in &intervals {
        let (ta, tb) = (&a.described.tests, &b.described.tests);
        if ta.fold * tb.fold < 0.0
            && let Some(l) = locate_root(problem, step, a, b, |d| d.tests.fold)
        {
            let turned = t_base[dim] * t_target[dim] < 0.0;
            let kind = if turned {
                BifurcationKind::Fold
            } else {
                BifurcationKind::BranchPoint
            };
            found.push((l.point.theta, bifurcation(kind, &l), None));
        }
        if ta.flip * tb.flip < 0.0
            && let Some(l) = locate_root(problem, step, a, b, |d| d.tests.flip)
        {
            let b = bifurcation(BifurcationKind::PeriodDoubling, &l);
            let doubling = if seed.depth < problem.options.doubling_depth {
                l.point
                    .ev
                    .eval
                    .stm
                    .as_ref()
                    .ok()
                    .and_then(|phi| real_eigenvector(phi, -1.0))
                    .map(|e| {
                        let n = dim / 2;
                        let mut direction = DVector::from_fn(dim + 1, |i, _| {
                            if i < dim {
                                e[i] / problem.scale.of_component(i, n)
                            } else {
                                0.0
                            }
                        });
                        direction.normalize_mut();
                        Doubling {
                            bifurcation: 0,
                            phase: problem.phase,
                            u: l.point.ev.u.clone(),
                            direction,
                            tangent: t_base.clone(),
                        }
                    })
            } else {
                ending.cascade.get_or_insert(l.point.described.point.parameter);
                None
            };
            found.push((l.point.theta, b, doubling));
        }
        if ta.neimark_sacker * tb.neimark_sacker < 0.0
            && let Some(l) = locate_root(problem, step, a, b, |d| d.tests.neimark_sacker)
        {
            // The pair whose product is closest to 1 must be complex (a conjugate pair on the
            // unit circle); two real multipliers with product 1 are a neutral saddle, not a
            // bifurcation.
            let m = &l.point.described.point.multipliers;
            let mut closest: Option<(f64, usize, usize)> = None;
            for i in 0..m.len() {
                for j in i + 1..m.len() {
                    let d = (m[i] * m[j] - nalgebra::Complex::new(1.0, 0.0)).norm();
                    if closest.is_none_or(|c| d < c.0) {
                        closest = Some((d, i, j));
                    }
                }
            }
            if let Some((_, i, j)) = closest
                && m[i].im.abs() > 1e-9 * m[i].norm()
                && (m[i] - m[j].conj()).norm() <= 1e-6 * m[i].norm()
            {
                let kind = BifurcationKind::NeimarkSacker {
                    angle: m[i].arg().abs(),
                };
                found.push((l.point.theta, bifurcation(kind, &l), None));
            }
        }
    }
    found.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, bif, doubling) in found {
        let index = branch.bifurcations.len();
        branch.bifurcations.push(bif);
        if let Some(mut d) = doubling {
            d.bifurcation = index;
            doublings.push(d);
        }
    }
}

fn bifurcation(kind: BifurcationKind, l: &Located) -> Bifurcation {
    Bifurcation {
        kind,
        parameter: l.point.described.point.parameter,
        precision: l.precision,
        point: l.point.described.point.clone(),
        after: None,
        child: None,
        crossing: None,
    }
}

/// A change of the event sequence crossed between `before` and `after`: its kind, and for a
/// grazing what the square-root map predicts from the multipliers of the orbit without the
/// impact.
fn crossing_point<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    before: &StepPoint,
    after: &StepPoint,
    precision: f64,
    crossing: CrossingKind,
) -> Bifurcation {
    let kind = classify(&before.described, &after.described, problem.scale.speed);
    let nordmark = match kind {
        BifurcationKind::Grazing { appears, .. } => {
            let free = if appears { before } else { after };
            Some(NordmarkScenario::of(&free.described.point.multipliers))
        }
        _ => None,
    };
    Bifurcation {
        kind,
        parameter: before.described.point.parameter,
        precision,
        point: before.described.point.clone(),
        after: Some(after.described.point.clone()),
        child: None,
        crossing: Some(Crossing {
            kind: crossing,
            nordmark,
        }),
    }
}
