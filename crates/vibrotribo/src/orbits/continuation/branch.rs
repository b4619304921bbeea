//! Following branches: the predictor–corrector loop, and the queue of branches born at
//! period doublings and branch points.

use std::collections::VecDeque;

use super::corrector::{Failure, Problem};
use super::cross::{Bridged, cross};
use super::detect::{Context, Ending, KnownBranchPoint, crossing_point, detect};
use super::locate::{Step, StepPoint, locate_root};
use super::onto::{chord, runs_onto};
use super::phase::{move_section, too_close};
use super::switch::{Fork, Found, Seed, Start, collapsed, cycle_amplitude, failure, flipped, start};
use super::types::{BifurcationKind, Branch, BranchEnd, BranchPoint, Continuation, ContinuationOptions};
use crate::error::ParamError;
use crate::model::{ChainParams, ChainState};
use crate::orbits::error::OrbitError;
use crate::orbits::gaps::smallest_gap_minimum;
use crate::orbits::map::Scale;
use crate::orbits::shooting::find_periodic_orbit;
use crate::sensitivity::state_vector;

/// A branch that cannot go on ends at a grazing if a gap minimum is below this fraction of
/// the length unit L.
const GRAZING_GAP: f64 = 1e-4;

/// Least distance from an edge, in multiples of the edge's precision, of the branch point
/// whose slowest impact says whether an impact lost at the edge vanishes there: an impact
/// vanishing like the square root of the distance to an edge within the precision still
/// extrapolates to zero within that distance from ten precisions away.
const BEHIND_PRECISIONS: f64 = 10.0;

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
        branch_depth: 0,
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
        let known = known_branch_points(&branches, seed.parent);
        let context = Context {
            seed: &seed,
            known: &known,
        };
        let index = branches.len();
        let (branch, forks) = match follow(&problem, &context, (lo, hi), direction, &branches) {
            Followed::New(branch, forks) => (*branch, forks),
            // The branch leaving a branch point was followed already, from its other end.
            Followed::Known(other) => {
                link(&mut branches, seed.parent, other);
                continue;
            }
        };
        link(&mut branches, seed.parent, index);
        complete &= !matches!(branch.end, BranchEnd::Stopped { .. });
        // A doubled branch that came back to its parent at another period doubling was
        // followed from both ends: drop the seed at the other end.
        if let BranchEnd::Collapsed { parameter } = branch.end {
            let near = 1e-3 * (hi - lo);
            queue.retain(|s| {
                let Some((b, k, _)) = s.parent else { return true };
                let other = &mut branches[b].bifurcations[k];
                let same = s.period == branch.period && (other.parameter - parameter).abs() <= near;
                if same {
                    other.child = Some(index);
                }
                !same
            });
        }
        for f in forks {
            let signs: &[f64] = match f.fork {
                Fork::Doubling => &[1.0],
                Fork::BranchPoint => &[1.0, -1.0],
            };
            for (j, sign) in signs.iter().enumerate() {
                if index + 1 + queue.len() >= options.max_branches {
                    break;
                }
                queue.push_back(fork_seed(&seed, index, &f, *sign, j == 1));
            }
        }
        branches.push(branch);
    }
    Ok(Continuation {
        parameter: name.to_string(),
        branches,
        complete,
    })
}

/// The seed of the branch leaving the fork `f` of branch `index` (followed from `seed`)
/// along `sign` times its direction; `second`: the other half at a branch point.
fn fork_seed(seed: &Seed, index: usize, f: &Found, sign: f64, second: bool) -> Seed {
    let (period, depth, branch_depth) = match f.fork {
        Fork::Doubling => (2 * seed.period, seed.depth + 1, seed.branch_depth),
        Fork::BranchPoint => (seed.period, seed.depth, seed.branch_depth + 1),
    };
    Seed {
        period,
        phase: f.phase,
        depth,
        branch_depth,
        parent: Some((index, f.bifurcation, second)),
        start: Start::Switch {
            fork: f.fork,
            u: f.u.clone(),
            direction: &f.direction * sign,
            parent: f.tangent.clone(),
        },
    }
}

/// Records `child` as the branch born at the parent's fork.
fn link(branches: &mut [Branch], parent: Option<(usize, usize, bool)>, child: usize) {
    let Some((b, k, second)) = parent else { return };
    let Some(f) = branches.get_mut(b).and_then(|b| b.bifurcations.get_mut(k)) else {
        return;
    };
    if second {
        f.other_child = Some(child);
    } else {
        f.child = Some(child);
    }
}

/// The branch points on the branches followed so far, but the one `parent` names (where the
/// next branch is born).
fn known_branch_points(branches: &[Branch], parent: Option<(usize, usize, bool)>) -> Vec<KnownBranchPoint> {
    let mut out = Vec::new();
    for (i, b) in branches.iter().enumerate() {
        for (k, f) in b.bifurcations.iter().enumerate() {
            if f.kind == BifurcationKind::BranchPoint && parent.is_none_or(|(pb, pk, _)| (pb, pk) != (i, k)) {
                out.push(KnownBranchPoint {
                    branch: i,
                    parameter: f.parameter,
                    state: state_vector(&f.point.state),
                });
            }
        }
    }
    out
}

/// What following a seed gave.
enum Followed {
    /// A branch, and the forks on it to follow.
    New(Box<Branch>, Vec<Found>),
    /// The branch leaving a branch point is this branch already followed.
    Known(usize),
}

/// The slowest impact (contact, closing speed in m/s) of the branch's last point on the
/// sequence of the edge orbit `edge` that lies at least [`BEHIND_PRECISIONS`] times the
/// edge's `precision` behind it (and within 1e-3 of the range `p_scale`): where no orbit of
/// that sequence converges at the fixed distance behind the edge that a crossing tries, the
/// branch's own points are such orbits.
fn behind_speed(
    points: &[BranchPoint],
    edge: &StepPoint,
    precision: f64,
    p_scale: f64,
) -> Option<(usize, f64)> {
    let e = &edge.described.point;
    points
        .iter()
        .rev()
        .take_while(|q| (q.parameter - e.parameter).abs() <= 1e-3 * p_scale)
        .find(|q| q.alike(e) && (q.parameter - e.parameter).abs() >= BEHIND_PRECISIONS * precision)?
        .min_closing_speed
}

/// The branch followed before (of `branches`, but the parent) that the first point `first`
/// of a branch leaving the branch point `fork` lies on: nearer a chord between two of its
/// consecutive points than a quarter of its distance from the branch point, in the units of
/// the state and the parameter's range.
fn followed_before<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    branches: &[Branch],
    parent: usize,
    fork: &BranchPoint,
    first: &BranchPoint,
) -> Option<usize> {
    let point = |q: &BranchPoint| problem.point(&state_vector(&q.state), q.parameter);
    let x = point(first);
    let reach = (&x - point(fork)).norm();
    branches.iter().enumerate().position(|(i, b)| {
        i != parent
            && b.period == problem.period
            && b.points
                .windows(2)
                .any(|w| chord(&point(&w[0]), &point(&w[1]), &x).1 < 0.25 * reach)
    })
}

/// The end of a branch stopped by the caller after the point `current`.
fn stopped(current: &StepPoint) -> BranchEnd {
    BranchEnd::Stopped {
        parameter: current.described.point.parameter,
    }
}

/// Follows one branch from its seed (`branches`: those followed before).
fn follow<F: Fn(f64) -> ChainParams>(
    base: &Problem<'_, F>,
    context: &Context<'_>,
    (lo, hi): (f64, f64),
    direction: f64,
    branches: &[Branch],
) -> Followed {
    let seed = context.seed;
    let opts = base.options;
    let mut branch = Branch {
        period: seed.period,
        parent: seed.parent.map(|(b, k, _)| (b, k)),
        points: Vec::new(),
        bifurcations: Vec::new(),
        end: BranchEnd::MaxPoints,
    };
    let mut doublings = Vec::new();
    // The section the branch is represented on (see `phase`).
    let mut problem = base.with_phase(seed.phase);
    let seed_parameter = match &seed.start {
        Start::Orbit(_, p) => *p,
        Start::Switch { u, .. } => problem.parameter(u),
    };
    let (mut current, mut t) = match start(&problem, seed, direction) {
        Ok(s) => s,
        Err(f) => {
            branch.end = match seed.start {
                Start::Orbit(..) => step_floor(seed_parameter, f),
                Start::Switch { .. } => BranchEnd::SwitchFailed {
                    parameter: seed_parameter,
                },
            };
            return Followed::New(Box::new(branch), doublings);
        }
    };
    if let (
        Start::Switch {
            fork: Fork::BranchPoint,
            ..
        },
        Some((b, k, _)),
    ) = (&seed.start, seed.parent)
        && let Some(fork) = branches.get(b).and_then(|p| p.bifurcations.get(k))
        && let Some(other) = followed_before(&problem, branches, b, &fork.point, &current.described.point)
    {
        return Followed::Known(other);
    }
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
            return Followed::New(Box::new(branch), doublings);
        }
        if too_close(&problem, &current)
            && let Some((phase, point, tangent)) = move_section(&problem, &current, &t)
        {
            problem = problem.with_phase(phase);
            (current, t) = (point, tangent);
        }
        if branch.points.len() >= opts.max_points {
            branch.end = BranchEnd::MaxPoints;
            return Followed::New(Box::new(branch), doublings);
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
                    return Followed::New(Box::new(branch), doublings);
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
                match cross(
                    &problem,
                    &current,
                    progress.signum(),
                    (lo, hi),
                    came_from,
                    branches,
                ) {
                    Some(Bridged::Same(target, t_new)) => {
                        let target = *target;
                        branch.points.push(target.described.point.clone());
                        let p = target.described.point.parameter;
                        if p <= lo || p >= hi {
                            branch.end = BranchEnd::RangeEnd { parameter: p };
                            return Followed::New(Box::new(branch), doublings);
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
                            c.behind_speed.or_else(|| {
                                behind_speed(&branch.points, &c.before, c.precision, problem.p_scale)
                            }),
                            c.kind,
                        ));
                        // The orbits past the change, up to the first on a branch followed before.
                        for o in std::iter::once(&c.after).chain(&c.onward) {
                            branch.points.push(o.described.point.clone());
                            if let Some(other) = runs_onto(&problem, branches, o) {
                                branch.end = BranchEnd::RunsOnto {
                                    parameter: o.described.point.parameter,
                                    branch: other,
                                };
                                return Followed::New(Box::new(branch), doublings);
                            }
                        }
                        let last = c.onward.last().unwrap_or(&c.after).clone();
                        let p = last.described.point.parameter;
                        if p <= lo || p >= hi {
                            branch.end = BranchEnd::RangeEnd { parameter: p };
                            return Followed::New(Box::new(branch), doublings);
                        }
                        current = last;
                        t = c.tangent;
                        ds = opts.initial_step;
                        continue;
                    }
                    None if opts.shooting.cancel.requested() => {
                        branch.end = stopped(&current);
                        return Followed::New(Box::new(branch), doublings);
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
                return Followed::New(Box::new(branch), doublings);
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
            Some(b) => match locate_root(&problem, &step, &base_point, &new, |d| {
                d.described.point.parameter - b
            }) {
                Some(l) => l.point,
                None => new,
            },
            None => new,
        };
        let mut ending = Ending::default();
        if seed.doubled() && flipped(&problem, &base_point, &target) {
            let closer = if cycle_amplitude(&problem, &base_point) < cycle_amplitude(&problem, &target) {
                &base_point
            } else {
                &target
            };
            ending.rejoin = Some(closer.described.point.parameter);
        }
        let detected = detect(
            &problem,
            &step,
            &base_point,
            &target,
            (&t, &t_new),
            context,
            &mut branch,
            &mut doublings,
            &mut ending,
        );
        // A multiplier crossing −1 that could not be located: a shorter step, down to the
        // floor.
        if let Err(u) = detected {
            ds *= 0.5;
            if ds >= opts.min_step {
                continue;
            }
            branch.end = BranchEnd::Unlocated {
                parameter: current.described.point.parameter,
                between: u.bracket,
            };
            return Followed::New(Box::new(branch), doublings);
        }
        branch.points.push(target.described.point.clone());
        if let Some((k, back)) = closes(&problem, &branch, ds) {
            let parameter = branch.points[k].parameter;
            branch.end = if back {
                BranchEnd::Retraced { parameter }
            } else {
                BranchEnd::Closed { parameter }
            };
            return Followed::New(Box::new(branch), doublings);
        }
        if seed.doubled() && collapsed(&problem, &target) {
            ending.rejoin.get_or_insert(target.described.point.parameter);
        }
        if let Some(parameter) = ending.rejoin {
            branch.end = BranchEnd::Collapsed { parameter };
            return Followed::New(Box::new(branch), doublings);
        }
        if let Some((parameter, branch_index)) = ending.meets {
            branch.end = BranchEnd::Rejoined {
                parameter,
                branch: branch_index,
            };
            return Followed::New(Box::new(branch), doublings);
        }
        if let Some(b) = bound {
            branch.end = BranchEnd::RangeEnd { parameter: b };
            return Followed::New(Box::new(branch), doublings);
        }
        if let Some(parameter) = ending.cascade {
            branch.end = BranchEnd::CascadeDepth { parameter };
            return Followed::New(Box::new(branch), doublings);
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
    Followed::New(Box::new(branch), doublings)
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

/// The earlier point the branch's newest point is back at (the nearest within a step `ds`
/// in the scaled units of the state and the parameter), if any, and whether it arrives going the other way
/// (its last step against the branch's step from that point): from there on the branch
/// repeats itself, forwards or in reverse. A smooth solution curve can only come back to its
/// first point (a closed curve); one with corners (non-smooth points crossed by [`cross`])
/// can also run into a loop further on, or back along its own path.
fn closes<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    branch: &Branch,
    ds: f64,
) -> Option<(usize, bool)> {
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
    // Arriving: the newest point is within a step of an old one and nearer it than the one
    // before (so that a branch that merely moves slowly is not taken for closed).
    // The nearest such point: where a fold has brought the branch past the same parameter
    // twice, its two stretches there are both within a step.
    let (k, _) = branch.points[..n - CLOSED_MIN_POINTS]
        .iter()
        .enumerate()
        .filter(|(_, old)| {
            old.alike(last) && distance(last, old) < ds && distance(last, old) < distance(before, old)
        })
        .min_by(|a, b| distance(last, a.1).total_cmp(&distance(last, b.1)))?;
    let scaled = |a: &BranchPoint| problem.point(&state_vector(&a.state), a.parameter);
    let arriving = scaled(last) - scaled(before);
    let onward = scaled(&branch.points[k + 1]) - scaled(&branch.points[k]);
    Some((k, arriving.dot(&onward) < 0.0))
}

fn step_floor(parameter: f64, f: Failure) -> BranchEnd {
    BranchEnd::StepFloor {
        parameter,
        reason: f.reason,
        non_smooth: f.non_smooth,
        residuals: f.residuals,
    }
}
