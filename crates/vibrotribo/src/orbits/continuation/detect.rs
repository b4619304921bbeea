//! What happens inside one continuation step: the smooth bifurcations (located by their test
//! functions), a change of the event sequence (located by bisection), and the forks the
//! branch leaves behind (period doublings and branch points to be followed).

use nalgebra::{Complex, DVector};

use super::corrector::Problem;
use super::locate::{Located, Step, StepPoint, classify, locate_change, locate_root};
use super::switch::{Fork, Found, Seed, branch_test, second_direction};
use super::types::{Bifurcation, BifurcationKind, Branch, CrossingKind, NordmarkScenario};
use crate::model::ChainParams;
use crate::orbits::floquet::real_eigenvector;
use crate::sensitivity::state_vector;

/// What [`detect`] found that ends a branch.
#[derive(Default)]
pub(super) struct Ending {
    /// A period doubling at the deepest level.
    pub cascade: Option<f64>,
    /// A doubled branch back on the branch of half its period (at the other end of a
    /// period-doubling bubble).
    pub rejoin: Option<f64>,
    /// A branch point already found on another branch: (its parameter, that branch).
    pub meets: Option<(f64, usize)>,
}

/// A branch point found on a branch already followed.
pub(super) struct KnownBranchPoint {
    pub branch: usize,
    pub parameter: f64,
    /// Its state at t ≡ 0 (mod T), m and m/s.
    pub state: DVector<f64>,
}

/// Two branch points are one if their parameters agree to this fraction of the range and
/// their states to this many units (each is located to the location tolerance in the
/// parameter, and along a pitchfork's new branch the state moves like the square root of
/// the parameter).
const SAME_BRANCH_POINT: f64 = 1e-4;
const SAME_BRANCH_POINT_STATE: f64 = 1e-2;

/// What the branch is and knows while its steps are searched.
pub(super) struct Context<'a> {
    pub seed: &'a Seed,
    /// Branch points on the branches followed before this one (its own origin excluded).
    pub known: &'a [KnownBranchPoint],
}

/// A sign change of `det(Φ + I)` in a step that [`detect`] could not certify as a period
/// doubling ([`certified_doubling`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct Unlocated {
    /// The parameters of the locator's final bracket's ends.
    pub bracket: (f64, f64),
}

/// A real multiplier within this distance of −1 at a located period doubling (located to
/// the location tolerance in the parameter, the multiplier is far closer on a smooth
/// branch).
const DOUBLING_MULTIPLIER: f64 = 1e-3;

/// Finds and locates what happens between `base` and `target` (a step from `base`), and
/// appends it to `branch` in order along it, with the forks to follow in `forks`. A sign
/// change of `det(Φ + I)` that cannot be certified as a period doubling leaves `branch`,
/// `forks` and `ending` as they were and is returned as [`Unlocated`]: the step is not to be
/// taken.
#[allow(clippy::too_many_arguments)]
pub(super) fn detect<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    step: &Step<'_>,
    base: &StepPoint,
    target: &StepPoint,
    (t_base, t_target): (&DVector<f64>, &DVector<f64>),
    context: &Context<'_>,
    branch: &mut Branch,
    forks: &mut Vec<Found>,
    ending: &mut Ending,
) -> Result<(), Unlocated> {
    let mut found: Vec<(f64, Bifurcation, Option<Found>)> = Vec::new();
    // What ends the branch, written to `ending` once the whole step is certified.
    let (mut cascade_end, mut meets) = (None, None);
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
            crossing_point(problem, &left, &right, precision, None, kind),
            None,
        ));
        // The multipliers may jump across the change; look for smooth crossings on either
        // side of it only.
        intervals = vec![(base.clone(), left), (right, target.clone())];
    }
    let dim = problem.dim();
    let t0 = step.tangent;
    for (a, b) in &intervals {
        let (ta, tb) = (&a.described.tests, &b.described.tests);
        let turned = t_base[dim] * t_target[dim] < 0.0;
        let fold_change = ta.fold * tb.fold < 0.0;
        // A branch point changes the sign of det([J; t0ᵀ]), a fold that of det(Φ − I) and of
        // the tangent's parameter part: one of each in a step leaves det(Φ − I) as it was. A
        // change of det([J; t0ᵀ]) alone is the step's tangent turning past a corner.
        let mut bp = None;
        if branch_test(a, t0) * branch_test(b, t0) < 0.0
            && fold_change != turned
            && let Some(l) = locate_root(problem, step, a, b, |p| branch_test(p, t0))
            && has_multiplier_at_one(&l.point.described.point.multipliers)
        {
            let fork = branch_point(problem, context, &l, t0, &mut meets);
            found.push((l.point.theta, bifurcation(BifurcationKind::BranchPoint, &l), fork));
            bp = Some(l.point);
        }
        if turned {
            // With a branch point in the same step, the fold is on the side of it where
            // det(Φ − I) changes sign.
            let (a, b) = match &bp {
                Some(c) if ta.fold * c.described.tests.fold < 0.0 => (a, c),
                Some(c) => (c, b),
                None => (a, b),
            };
            if a.described.tests.fold * b.described.tests.fold < 0.0
                && let Some(l) = locate_root(problem, step, a, b, |p| p.described.tests.fold)
            {
                found.push((l.point.theta, bifurcation(BifurcationKind::Fold, &l), None));
            }
        }
        if ta.flip * tb.flip < 0.0
            && let Some(l) = locate_root(problem, step, a, b, |p| p.described.tests.flip)
        {
            if !certified_doubling(problem, &l) {
                return Err(Unlocated { bracket: l.bracket });
            }
            let b = bifurcation(BifurcationKind::PeriodDoubling, &l);
            let doubling = if context.seed.depth < problem.options.doubling_depth {
                doubling(problem, &l, t_base)
            } else {
                cascade_end.get_or_insert(l.point.described.point.parameter);
                None
            };
            found.push((l.point.theta, b, doubling));
        }
        if ta.neimark_sacker * tb.neimark_sacker < 0.0
            && let Some(l) = locate_root(problem, step, a, b, |p| p.described.tests.neimark_sacker)
            && let Some(angle) = neimark_sacker_angle(&l.point.described.point.multipliers)
        {
            let kind = BifurcationKind::NeimarkSacker { angle };
            found.push((l.point.theta, bifurcation(kind, &l), None));
        }
    }
    if let Some(p) = cascade_end {
        ending.cascade.get_or_insert(p);
    }
    if let Some(m) = meets {
        ending.meets.get_or_insert(m);
    }
    found.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, bif, fork) in found {
        let index = branch.bifurcations.len();
        branch.bifurcations.push(bif);
        if let Some(mut f) = fork {
            f.bifurcation = index;
            forks.push(f);
        }
    }
    Ok(())
}

/// Whether the located sign change `l` of `det(Φ + I)` is a period doubling: its bracket
/// is within the location tolerance in the parameter (or the test vanishes at the point),
/// and the orbit there has a real multiplier within [`DOUBLING_MULTIPLIER`] of −1. A step
/// that jumps onto another branch, or over a point where a multiplier passes through
/// infinity, changes the sign of the test without either.
fn certified_doubling<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, l: &Located) -> bool {
    let located = l.precision <= problem.options.location_tolerance || l.point.described.tests.flip == 0.0;
    located
        && l.point
            .described
            .point
            .multipliers
            .iter()
            .any(|m| m.im.abs() <= 1e-9 * m.norm() && (m.re + 1.0).abs() < DOUBLING_MULTIPLIER)
}

/// The doubled branch's start at the period doubling `l`: along the eigenvector of the
/// multiplier −1, with the parameter stationary.
fn doubling<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    l: &Located,
    tangent: &DVector<f64>,
) -> Option<Found> {
    let dim = problem.dim();
    let phi = l.point.ev.eval.stm.as_ref().ok()?;
    let e = real_eigenvector(phi, -1.0)?;
    let n = dim / 2;
    let mut direction = DVector::from_fn(dim + 1, |i, _| {
        if i < dim {
            e[i] / problem.scale.of_component(i, n)
        } else {
            0.0
        }
    });
    direction.normalize_mut();
    Some(Found {
        fork: Fork::Doubling,
        bifurcation: 0,
        phase: problem.phase,
        u: l.point.ev.u.clone(),
        direction,
        tangent: tangent.clone(),
    })
}

/// The fork at the branch point `l` (the step's tangent `t0`), unless the branch point was
/// already found on another branch (then the branch meets that one there, and ends: its
/// parameter and that branch are written to `meets`), or branch points are not followed this
/// deep.
fn branch_point<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    context: &Context<'_>,
    l: &Located,
    t0: &DVector<f64>,
    meets: &mut Option<(f64, usize)>,
) -> Option<Found> {
    let point = &l.point.described.point;
    let z = state_vector(&point.state);
    let same = context.known.iter().find(|k| {
        (k.parameter - point.parameter).abs() <= SAME_BRANCH_POINT * problem.p_scale
            && problem.scale.norm(&(&k.state - &z)) <= SAME_BRANCH_POINT_STATE
    });
    if let Some(k) = same {
        meets.get_or_insert((point.parameter, k.branch));
        return None;
    }
    if context.seed.branch_depth >= problem.options.branch_point_depth {
        return None;
    }
    let direction = second_direction(&l.point.ev, t0)?;
    Some(Found {
        fork: Fork::BranchPoint,
        bifurcation: 0,
        phase: problem.phase,
        u: l.point.ev.u.clone(),
        direction,
        tangent: t0.clone(),
    })
}

/// Whether a real multiplier lies within 1e-3 of +1 (at a located branch point).
fn has_multiplier_at_one(multipliers: &[Complex<f64>]) -> bool {
    multipliers
        .iter()
        .any(|m| m.im.abs() <= 1e-9 * m.norm() && (m.re - 1.0).abs() < 1e-3)
}

/// The argument of the critical pair at a sign change of the Neimark–Sacker test: the pair
/// whose product is closest to 1 must be complex (a conjugate pair on the unit circle); two
/// real multipliers with product 1 are a neutral saddle, not a bifurcation.
fn neimark_sacker_angle(m: &[Complex<f64>]) -> Option<f64> {
    let mut closest: Option<(f64, usize, usize)> = None;
    for i in 0..m.len() {
        for j in i + 1..m.len() {
            let d = (m[i] * m[j] - Complex::new(1.0, 0.0)).norm();
            if closest.is_none_or(|c| d < c.0) {
                closest = Some((d, i, j));
            }
        }
    }
    let (_, i, j) = closest?;
    (m[i].im.abs() > 1e-9 * m[i].norm() && (m[i] - m[j].conj()).norm() <= 1e-6 * m[i].norm())
        .then(|| m[i].arg().abs())
}

fn bifurcation(kind: BifurcationKind, l: &Located) -> Bifurcation {
    Bifurcation {
        kind,
        parameter: l.point.described.point.parameter,
        precision: l.precision,
        point: l.point.described.point.clone(),
        after: None,
        child: None,
        other_child: None,
        crossing: None,
    }
}

/// A change of the event sequence crossed between `before` and `after`: its kind, and for a
/// grazing what the square-root map predicts from the multipliers of the orbit without the
/// impact. `behind_speed`: the slowest impact (contact, m/s) of the old orbit a little behind
/// the edge `before`, where known; an impact that does not vanish at the edge makes the point
/// a `sequence_change`, not a grazing.
pub(super) fn crossing_point<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    before: &StepPoint,
    after: &StepPoint,
    precision: f64,
    behind_speed: Option<(usize, f64)>,
    crossing: CrossingKind,
) -> Bifurcation {
    let mut kind = classify(&before.described, &after.described, problem.scale.speed);
    // An impact that disappears at a grazing has a closing speed falling to zero at the edge
    // (linearly in the parameter): from the orbit behind the edge its speed extrapolates to
    // zero within the distance between the two, where the edge is located far closer. One
    // that is still as fast as its change over that distance is not vanishing there: the edge
    // is where the old orbit was lost, and the orbit found beyond is of another family.
    if let (
        BifurcationKind::Grazing {
            contact,
            appears: false,
        },
        Some((c_b, v_b)),
        Some((c_e, v_e)),
    ) = (kind, behind_speed, before.described.point.min_closing_speed)
        && c_b == contact
        && c_e == contact
        && v_e > (v_b - v_e).abs()
    {
        kind = BifurcationKind::SequenceChange;
    }
    // An orbit born (or lost) at a grazing is continuous with the grazing orbit: it moves
    // from it like the distance in the parameter, or its square root. One farther from the
    // edge orbit than the square root of that distance (both in their scales) is an orbit of
    // another family that has the new sequence.
    if matches!(kind, BifurcationKind::Grazing { .. }) {
        let step =
            (after.described.point.parameter - before.described.point.parameter).abs() / problem.p_scale;
        let distance = problem
            .scale
            .norm(&(problem.state(&after.ev.u) - problem.state(&before.ev.u)));
        if distance > step.sqrt() {
            kind = BifurcationKind::SequenceChange;
        }
    }
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
        other_child: None,
        crossing: Some(super::types::Crossing {
            kind: crossing,
            nordmark,
        }),
    }
}
