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
//!    unit, or `+η c/|c|²` to lift a slow impact off). Newton's method is held to the event
//!    sequence of its starting point, so that it cannot fall onto the old orbit; on the
//!    square-root branch it converges from the side of small penetration (the map is convex
//!    there), which is why the guesses start shallow. The branch then goes on along the new
//!    sequence by a few natural steps away from the point before the arclength takes over.
//!
//! Feigin's rule for the square-root map (the new orbit has a multiplier that grows like the
//! inverse of its impact speed) says which of the two happens: `det(Φ − I)` keeps its sign
//! across a persistence and changes it across a non-smooth fold; the kind recorded is the
//! one found.

use nalgebra::{DMatrix, DVector};

use super::corrector::Problem;
use super::locate::{MAX_LOCATE, StepPoint};
use super::types::CrossingKind;
use crate::dynamics::EventKind;
use crate::model::ChainParams;
use crate::orbits::gaps::{gap_gradient, gap_minima, smallest_gap_minimum};
use crate::orbits::map::{chatter_bounces, evaluate, signature};
use crate::orbits::shooting::newton_within;

/// Parameter steps of the forward search, as fractions of the range: 1e-6 · 4^k.
const FORWARD_TRIES: i32 = 8;

/// Distances from the edge at which the new orbit is sought, fractions of the range.
const SIDE_STEPS: [f64; 4] = [1e-6, 1e-5, 1e-4, 1e-3];

/// Penetrations (or lifts) of the guesses moved along the gap gradient, in the length unit.
const PENETRATIONS: [f64; 4] = [1e-12, 1e-10, 1e-8, 1e-6];

/// Penetration, in the length unit, at which the square-root term of the map is measured.
const PROBE_PENETRATION: f64 = 1e-10;

/// Natural steps taken along the new sequence after a crossing (each four times the last).
const ONWARD_STEPS: i32 = 5;

/// A gap minimum below this fraction of the length unit is taken as grazing.
const NEAR_GRAZING: f64 = 1e-4;

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
/// branch does not cross back onto that sequence there.
pub(crate) fn cross<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    current: &StepPoint,
    direction: f64,
    (lo, hi): (f64, f64),
    came_from: Option<(f64, &[(EventKind, usize)])>,
) -> Option<Bridged> {
    let parameter = |s: &StepPoint| s.described.point.parameter;
    let signature = &current.described.signature;
    let s0 = current.described.point.arclength;
    let arclength = |p: f64| s0 + (p - parameter(current)).abs() / problem.p_scale;
    // 1. Forward, as far as the old sequence goes (at most 1.6e-2 of the range).
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
        if parameter(&ok) == parameter(current) {
            return None;
        }
        let t = problem.tangent(&ok.ev, &along(problem, direction))?;
        return Some(Bridged::Same(Box::new(ok), t));
    };
    // 2. The edge of the old sequence.
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
    // 3. The new sequence on either side of the edge: first where the square-root map puts
    // it, then from the generic guesses.
    let generic = guesses(problem, &ok);
    let back =
        parameter(&ok) - direction * (1e-6 * problem.p_scale).max(10.0 * problem.options.location_tolerance);
    let model = orbit_keeping(
        problem,
        &problem.state(&ok.ev.u),
        back,
        arclength(back),
        signature,
    )
    .and_then(|behind| SquareRootModel::new(problem, &ok, &behind));
    // The persistence side first, at every distance: a symmetric orbit that grazes two
    // contacts at once may also meet orbits striking only one of them at a fold.
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
            let predicted = model.as_ref().map_or_else(Vec::new, |m| m.guesses(sigma * eps));
            for z in predicted.iter().chain(&generic) {
                if let Some(o) = orbit_beyond(problem, z, p, arclength(p), signature)
                    && o.described.signature != *signature
                    && !came_from.is_some_and(|(q, s)| {
                        o.described.signature == s && (p - q).abs() < 1e-3 * problem.p_scale
                    })
                {
                    return crossed(problem, ok, o, precision, sigma, kind, (lo, hi));
                }
            }
        }
    }
    None
}

/// The orbit at `p` with the event sequence `keep`, from `z` (Newton's method held to it).
fn orbit_keeping<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    z: &DVector<f64>,
    p: f64,
    arclength: f64,
    keep: &[(EventKind, usize)],
) -> Option<StepPoint> {
    let params = (problem.family)(p);
    let end = problem.phase + f64::from(problem.period) * params.period();
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
fn sequence(events: &[crate::dynamics::Event], end: f64) -> Vec<(EventKind, usize)> {
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
    let end = problem.phase + f64::from(problem.period) * params.period();
    let target = sequence(&first.events, end);
    if target == old {
        return None;
    }
    orbit_keeping(problem, z, p, arclength, &target)
}

/// A unit vector along the parameter, signed.
fn along<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, direction: f64) -> DVector<f64> {
    let mut v = DVector::zeros(problem.dim() + 1);
    v[problem.dim()] = direction;
    v
}

fn crossed<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    before: StepPoint,
    after: StepPoint,
    precision: f64,
    direction: f64,
    kind: CrossingKind,
    (lo, hi): (f64, f64),
) -> Option<Bridged> {
    // Away from the point along the new sequence by natural steps growing fourfold (near a
    // non-smooth fold the other orbit lies within the arclength corrector's reach).
    let keep = after.described.signature.clone();
    let p0 = after.described.point.parameter;
    let first = (p0 - before.described.point.parameter).abs();
    let mut onward: Vec<StepPoint> = Vec::new();
    for k in 1..=ONWARD_STEPS {
        let p = p0 + direction * first * 4f64.powi(k);
        if p <= lo || p >= hi {
            break;
        }
        let last = onward.last().unwrap_or(&after);
        let s = last.described.point.arclength + (p - last.described.point.parameter).abs() / problem.p_scale;
        match orbit_keeping(problem, &problem.state(&last.ev.u), p, s, &keep) {
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
        kind,
        tangent,
    })))
}

/// Initial states for the orbit with the new sequence near the edge orbit `edge`: the orbit
/// itself, and the orbit moved along the gradient of the gap that grazes (a gap minimum near
/// zero: moved into contact) or of the slowest impact (moved out of contact).
fn guesses<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, edge: &StepPoint) -> Vec<DVector<f64>> {
    let z = problem.state(&edge.ev.u);
    let mut out = vec![z.clone()];
    let p = edge.described.point.parameter;
    let params = (problem.family)(p);
    let opts = &problem.options.shooting;
    let length = problem.scale.length;
    let end = problem.phase + f64::from(problem.period) * params.period();
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

/// The map near a grazing of the edge orbit `z*` at `p*`, approached without the impacts
/// (Nordmark's normal form, linearised, with one term per grazing gap minimum j, several when
/// a symmetric orbit grazes two contacts at once): `P(z, p) = z* + A(z − z*) + b Δp +
/// Σ_j E_j √(−h_j(z, p))` over the minima the flow strikes (`h_j < 0`), with
/// `h_j(z, p) = g_j + c_jᵀ(z − z*) + d_j Δp` the gap minimum of the smooth flow. A fixed
/// point striking the set S has `z − z* = (I − A)⁻¹(b Δp + Σ_S E_k w_k)`, `w_k = √(−h_k)`, so
/// `w_j² + Σ_S β_jk w_k + g_j + α_j Δp = 0` (j ∈ S) with `β_jk = c_jᵀ(I − A)⁻¹E_k` and
/// `α_j = dg_j/dp` along the branch without the impacts. For one minimum this is Feigin's
/// rule: for β > 0 the root w > 0 lies on the side where that branch would penetrate (a
/// persistence), for β < 0 on its own side (a non-smooth fold).
struct SquareRootModel {
    z: DVector<f64>,
    inverse: DMatrix<f64>,
    b: DVector<f64>,
    /// Per grazing minimum: g_j, α_j, E_j, c_j.
    gaps: Vec<f64>,
    alphas: Vec<f64>,
    e: Vec<DVector<f64>>,
    c: Vec<DVector<f64>>,
    /// Moves of the state that change one gap minimum by a metre and leave the others.
    units: Vec<DVector<f64>>,
    length: f64,
}

/// Gap minima within this factor of the smallest (plus a floor) graze together.
const TOGETHER: f64 = 10.0;

impl SquareRootModel {
    /// The model at `edge`, with `behind` (an orbit of the same sequence a little before it)
    /// for the rates α; `None` if the edge is not a grazing without the impacts.
    fn new<F: Fn(f64) -> ChainParams>(
        problem: &Problem<'_, F>,
        edge: &StepPoint,
        behind: &StepPoint,
    ) -> Option<Self> {
        let p = edge.described.point.parameter;
        let params = (problem.family)(p);
        let opts = &problem.options.shooting;
        let length = problem.scale.length;
        let z = problem.state(&edge.ev.u);
        let minima = gap_minima(&params, &z, problem.period, problem.phase, &opts.sim);
        let smallest = minima.iter().map(|m| m.gap).fold(f64::INFINITY, f64::min);
        if smallest.is_nan() || smallest >= NEAR_GRAZING * length {
            return None;
        }
        let grazing: Vec<_> = minima
            .into_iter()
            .filter(|m| m.gap <= TOGETHER * smallest.max(0.0) + 1e-12 * length)
            .take(3)
            .collect();
        let p_b = behind.described.point.parameter;
        let before = gap_minima(
            &(problem.family)(p_b),
            &problem.state(&behind.ev.u),
            problem.period,
            problem.phase,
            &opts.sim,
        );
        let period = params.period();
        let mut alphas = Vec::new();
        let mut c = Vec::new();
        for m in &grazing {
            // The same minimum behind: same contact, nearest in time.
            let b = before
                .iter()
                .filter(|b| b.contact == m.contact && (b.time - m.time).abs() < 0.05 * period)
                .min_by(|x, y| (x.time - m.time).abs().total_cmp(&(y.time - m.time).abs()))?;
            alphas.push((m.gap - b.gap) / (p - p_b));
            c.push(gap_gradient(
                &params,
                &z,
                problem.phase,
                m.contact,
                m.time,
                &opts.sim,
                &opts.sensitivity,
            )?);
        }
        let a = edge.ev.eval.stm.as_ref().ok()?;
        let dim = z.len();
        let inverse = (DMatrix::identity(dim, dim) - a).try_inverse()?;
        let n = problem.n;
        let s = |i: usize| problem.scale.of_component(i, n);
        let b = DVector::from_fn(dim, |i, _| edge.ev.jacobian[(i, dim)] * s(i) / problem.p_scale);
        // Directions that move one gap minimum by a metre and leave the others (minimum
        // norm in the scaled units): U = D²Cᵀ(C D² Cᵀ)⁻¹.
        let k = grazing.len();
        let cs = DMatrix::from_fn(k, dim, |j, i| c[j][i] * s(i));
        let gram = (&cs * cs.transpose()).try_inverse()?;
        let units: Vec<DVector<f64>> = (0..k)
            .map(|j| {
                let col = cs.transpose() * gram.column(j);
                DVector::from_fn(dim, |i, _| col[i] * s(i))
            })
            .collect();
        // E_j from one evaluation of the map at a state whose flow penetrates minimum j by η
        // and clears the others by η.
        let eta = PROBE_PENETRATION * length;
        let mut e = Vec::new();
        for (j, m) in grazing.iter().enumerate() {
            let mut dz = &units[j] * -(m.gap + eta);
            for (l, other) in grazing.iter().enumerate() {
                if l != j {
                    dz += &units[l] * (eta - other.gap.min(0.0));
                }
            }
            let probe = &z + &dz;
            let image = evaluate(
                &params,
                &probe,
                problem.period,
                problem.phase,
                &opts.sim,
                &opts.sensitivity,
            )
            .ok()?;
            let struck = image
                .events
                .iter()
                .any(|ev| ev.kind == EventKind::Impact && ev.contact == m.contact);
            if !struck {
                return None;
            }
            e.push((image.image - &edge.ev.eval.image - a * dz) / eta.sqrt());
        }
        Some(SquareRootModel {
            z,
            inverse,
            b,
            gaps: grazing.iter().map(|m| m.gap).collect(),
            alphas,
            e,
            c,
            units,
            length,
        })
    }

    /// The predicted fixed points at `p* + dp` that strike a nonempty set of the grazing
    /// minima (all together first).
    fn guesses(&self, dp: f64) -> Vec<DVector<f64>> {
        let k = self.gaps.len();
        let mut sets: Vec<u32> = (1..(1u32 << k)).collect();
        sets.sort_by_key(|s| std::cmp::Reverse(s.count_ones()));
        let mut out = Vec::new();
        for set in sets {
            let Some(z) = self.strike(set, dp) else { continue };
            // The prediction, and the same pressed a little deeper into the contacts in case
            // its flow misses them (the penetration is second order in Δp).
            let press: DVector<f64> = (0..k)
                .filter(|j| set & (1 << j) != 0)
                .fold(DVector::zeros(z.len()), |acc, j| acc - &self.units[j]);
            out.push(z.clone());
            for eta in PENETRATIONS {
                out.push(&z + &press * (eta * self.length));
            }
        }
        out
    }

    /// The fixed point striking the minima in `set` (a bit mask), by Newton's method on the
    /// small system for w from its linear solution; `None` unless every w > 0.
    fn strike(&self, set: u32, dp: f64) -> Option<DVector<f64>> {
        let idx: Vec<usize> = (0..self.gaps.len()).filter(|j| set & (1 << j) != 0).collect();
        let m = idx.len();
        let beta = DMatrix::from_fn(m, m, |r, q| {
            self.c[idx[r]].dot(&(&self.inverse * &self.e[idx[q]]))
        });
        let rhs = DVector::from_fn(m, |r, _| -(self.gaps[idx[r]] + self.alphas[idx[r]] * dp));
        let mut w = beta.clone().lu().solve(&rhs)?;
        for _ in 0..30 {
            let f = DVector::from_fn(m, |r, _| w[r] * w[r]) + &beta * &w - &rhs;
            let j = &beta + DMatrix::from_diagonal(&(&w * 2.0));
            let step = j.lu().solve(&f)?;
            w -= step;
        }
        if w.iter().any(|v| v.is_nan() || *v <= 0.0) {
            return None;
        }
        let mut kick = &self.b * dp;
        for (r, &j) in idx.iter().enumerate() {
            kick += &self.e[j] * w[r];
        }
        Some(&self.z + &self.inverse * kick)
    }
}
