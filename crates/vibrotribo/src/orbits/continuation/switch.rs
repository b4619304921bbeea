//! Starting branches: the first orbit, and the switch onto a branch that leaves another one
//! at a period doubling or a branch point.
//!
//! At a period doubling the doubled branch leaves along the eigenvector of the multiplier −1
//! with the parameter stationary (the pitchfork of the doubled map); its two halves are the
//! same orbit shifted by P periods, so one is followed. At a branch point (a real multiplier
//! at +1 where the branch does not turn: a symmetry-breaking pitchfork, or a transcritical
//! crossing) the Jacobian `J = [Φ − I | ∂φ/∂p]` has a two-dimensional null space spanned by
//! the parent's tangent `t` and a second vector `φ₂`: the null vector of `[J; tᵀ]` (its
//! right singular vector of the smallest singular value). The new branch leaves along `±φ₂`,
//! and both halves are followed (at a symmetry-breaking pitchfork they are mirror images of
//! each other, two different orbits).
//!
//! In both cases the first step is taken along the new direction made orthogonal to the
//! parent's tangent, and the corrector searches the plane normal to it, so that it cannot
//! slide back along the parent branch; a point that lies on the parent after all (the orbit
//! of half the period, or a point of the parent branch itself) is refused and a step of
//! another length tried.

use nalgebra::DVector;

use super::super::error::NewtonFailure;
use super::corrector::{Evaluated, Failure, Problem};
use super::cross::orbit_following;
use super::locate::{Step, StepPoint};
use crate::model::ChainParams;

/// How a branch leaves its parent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Fork {
    /// At a period doubling, with twice the parent's period.
    Doubling,
    /// At a branch point, with the parent's period.
    BranchPoint,
}

/// Where a branch starts.
pub(super) enum Start {
    /// A converged orbit: state and parameter.
    Orbit(DVector<f64>, f64),
    /// A fork of the parent at the scaled point `u`, leaving along `direction` (scaled).
    Switch {
        fork: Fork,
        u: DVector<f64>,
        direction: DVector<f64>,
        /// The parent branch's unit tangent there (scaled).
        parent: DVector<f64>,
    },
}

/// A branch to be followed.
pub(super) struct Seed {
    pub period: u32,
    /// Section phase of `start`, s.
    pub phase: f64,
    /// Period doublings between the first branch and this one.
    pub depth: u32,
    /// Branch points between the first branch and this one.
    pub branch_depth: u32,
    /// Where it was born: (parent branch, bifurcation), and whether it is the second branch
    /// that leaves a branch point.
    pub parent: Option<(usize, usize, bool)>,
    pub start: Start,
}

impl Seed {
    /// Whether the branch has twice the period of a branch it may fall back onto.
    pub fn doubled(&self) -> bool {
        self.depth > 0
    }
}

/// A fork found on a branch, to be followed.
pub(super) struct Found {
    pub fork: Fork,
    pub bifurcation: usize,
    /// Section phase of `u`, s.
    pub phase: f64,
    pub u: DVector<f64>,
    /// The direction of the new branch (scaled, unit).
    pub direction: DVector<f64>,
    /// The branch's unit tangent at the point (scaled).
    pub tangent: DVector<f64>,
}

pub(super) fn failure_of(reason: NewtonFailure) -> Failure {
    Failure {
        reason,
        non_smooth: None,
        residuals: Vec::new(),
    }
}

pub(super) fn failure(ev: &Evaluated) -> Failure {
    Failure {
        reason: NewtonFailure::Singular,
        non_smooth: None,
        residuals: vec![ev.residual.amax()],
    }
}

/// The first point of a branch and its tangent.
pub(super) fn start<F: Fn(f64) -> ChainParams>(
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
        Start::Switch {
            fork,
            u,
            direction,
            parent,
        } => {
            // A step too short may fall back onto the parent, one too long leave the
            // corrector's reach: from 1/16 of the first step up to 64 times it, then down
            // to 1/1024 of it (deep in a cascade the doubled branches are small).
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
                    Ok(p) if !on_parent(problem, *fork, u, parent, &p) => {
                        let away = &p.ev.u - u;
                        let t = problem.tangent(&p.ev, &away).ok_or_else(|| failure(&p.ev))?;
                        return Ok((StepPoint { theta: 0.0, ..p }, t));
                    }
                    Ok(p) => last = Some(failure(&p.ev)),
                    Err(f) => last = Some(f),
                }
            }
            if *fork == Fork::Doubling
                && let Some(found) = doubled_at_fixed_parameter(problem, u, direction)
            {
                return Ok(found);
            }
            Err(last.unwrap_or_else(|| failure_of(NewtonFailure::Iterations)))
        }
    }
}

/// Distances from the period doubling in the parameter at which [`doubled_at_fixed_parameter`]
/// seeks the doubled orbit, fractions of the range (the nearest first: deep in a cascade the
/// doubled branches turn within a short distance).
const FIXED_PARAMETER_STEPS: [f64; 6] = [1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4];

/// Moves along the eigenvector of the multiplier −1 from which it is sought (scaled units,
/// the smallest first).
const EIGENVECTOR_MOVES: [f64; 5] = [1e-6, 1e-5, 1e-4, 1e-3, 1e-2];

/// The first orbit of a doubled branch found at a fixed parameter, for a doubling where no
/// arclength step reached it: Newton's method on the doubled map at `p* ± δ` (on the
/// pitchfork's side, the doubled orbit lies `√(δ/|c|)` along the eigenvector from the parent,
/// `c` unknown), from the parent's state moved along the eigenvector, held to the event
/// sequence of the flow from the guess (next to a grazing the map is not smooth across it).
/// An orbit that is the parent (of half the period) or lies farther from the fork than twice
/// the move it started from is refused. The branch goes on from the orbit found, away from
/// the fork.
fn doubled_at_fixed_parameter<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    u: &DVector<f64>,
    direction: &DVector<f64>,
) -> Option<(StepPoint, DVector<f64>)> {
    let dim = problem.dim();
    let mut v = direction.clone();
    v[dim] = 0.0;
    let v = v.try_normalize(0.0)?;
    let p0 = problem.parameter(u);
    for delta in FIXED_PARAMETER_STEPS {
        for sigma in [1.0, -1.0] {
            let p = p0 + sigma * delta * problem.p_scale;
            for eps in EIGENVECTOR_MOVES {
                if problem.options.shooting.cancel.requested() {
                    return None;
                }
                let guess = problem.state(&(u + &v * eps));
                let Some(found) = orbit_following(problem, &guess, p, 0.0) else {
                    continue;
                };
                let away = &found.ev.u - u;
                if collapsed(problem, &found) || away.rows(0, dim).norm() > 2.0 * eps {
                    continue;
                }
                let Some(t) = problem.tangent(&found.ev, &away) else {
                    continue;
                };
                return Some((found, t));
            }
        }
    }
    None
}

/// Whether the first point `p` of a branch leaving the fork at `u` fell back onto the
/// parent: for a doubled branch, the orbit of half the period; at a branch point, a point
/// whose displacement from the fork lies more along the parent's tangent than across it.
fn on_parent<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    fork: Fork,
    u: &DVector<f64>,
    parent: &DVector<f64>,
    p: &StepPoint,
) -> bool {
    match fork {
        Fork::Doubling => collapsed(problem, p),
        Fork::BranchPoint => {
            let d = &p.ev.u - u;
            let along = parent.dot(&d);
            (&d - parent * along).norm() <= along.abs()
        }
    }
}

/// The direction of the second branch through a branch point: the unit null vector of
/// `[J; tᵀ]` at `ev` (J the scaled Jacobian `[Φ − I | ∂φ/∂p]`, `t` the parent's unit
/// tangent), orthogonal to `t`.
pub(super) fn second_direction(ev: &Evaluated, tangent: &DVector<f64>) -> Option<DVector<f64>> {
    let dim = ev.jacobian.nrows();
    let mut a = ev.jacobian.clone().insert_row(dim, 0.0);
    for j in 0..=dim {
        a[(dim, j)] = tangent[j];
    }
    let svd = nalgebra::SVD::try_new(a, false, true, f64::EPSILON, 10_000)?;
    let v_t = svd.v_t?;
    let (k, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))?;
    let e = v_t.row(k).transpose();
    let across = &e - tangent * tangent.dot(&e);
    (across.norm() > 1e-6).then(|| across.normalize())
}

/// The branch-point test of a step with unit tangent `t0` at one of its points:
/// `det([J; t0ᵀ])`, which changes sign where the null space of J grows (a branch point) and
/// not at a fold.
pub(super) fn branch_test(p: &StepPoint, t0: &DVector<f64>) -> f64 {
    let dim = p.ev.jacobian.nrows();
    let mut a = p.ev.jacobian.clone().insert_row(dim, 0.0);
    for j in 0..=dim {
        a[(dim, j)] = t0[j];
    }
    a.determinant()
}

/// For an orbit of even period 2P: how far its state after P periods is from its section
/// state, in the units (0 when it is in fact of period P).
pub(super) fn cycle_amplitude<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, p: &StepPoint) -> f64 {
    let half = (problem.period / 2) as usize;
    let sections = &p.ev.eval.sections;
    match (sections.first(), sections.get(half)) {
        (Some(a), Some(b)) if problem.period.is_multiple_of(2) => problem.scale.norm(&(b - a)),
        _ => f64::INFINITY,
    }
}

/// Whether an orbit of a doubled branch (period 2P) is in fact of period P: its state after
/// P periods equals its section state to 1e-7 of the units.
pub(super) fn collapsed<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, p: &StepPoint) -> bool {
    cycle_amplitude(problem, p) < 1e-7
}

/// Whether a step of a doubled branch (period 2P) went through the branch of period P onto
/// the other half of its pitchfork: the new point is nearer the old point's state after P
/// periods (the same orbit, shifted by P periods) than the old point itself.
pub(super) fn flipped<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    a: &StepPoint,
    b: &StepPoint,
) -> bool {
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
