//! Nordmark's normal form of the stroboscopic map near a grazing, linearised at the edge
//! orbit: where it puts the orbits with the new impact, and Newton's method for them with
//! the square root built in.

use nalgebra::{DMatrix, DVector};

use super::corrector::{Problem, rounding_floor};
use super::cross::{NEAR_GRAZING, PENETRATIONS, sequence};
use super::locate::StepPoint;
use crate::dynamics::EventKind;
use crate::model::ChainParams;
use crate::orbits::gaps::{gap_gradient, gap_minima};
use crate::orbits::map::evaluate;
use crate::orbits::shooting::solve_scaled;

/// Penetration, in the length unit, at which the square-root term of the map is measured.
const PROBE_PENETRATION: f64 = 1e-10;

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
pub(super) struct SquareRootModel {
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
    /// Per grazing minimum: the closing speed of its impact per √m of penetration, √(2a)
    /// (a the gap's deceleration at the minimum), m^½/s.
    kappas: Vec<f64>,
    /// The contact of the first grazing minimum.
    contact: usize,
    length: f64,
}

/// Gap minima within this factor of the smallest (plus a floor) graze together.
const TOGETHER: f64 = 10.0;

impl SquareRootModel {
    /// The model at `edge`, with `behind` (an orbit of the same sequence a little before it)
    /// for the rates α; `None` if the edge is not a grazing without the impacts.
    pub(super) fn new<F: Fn(f64) -> ChainParams>(
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
        let mut kappas = Vec::new();
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
            let speed = image
                .events
                .iter()
                .filter(|ev| ev.kind == EventKind::Impact && ev.contact == m.contact)
                .map(|ev| ev.velocity_before)
                .fold(f64::INFINITY, f64::min);
            if !(speed.is_finite() && speed > 0.0) {
                return None;
            }
            kappas.push(speed / eta.sqrt());
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
            kappas,
            contact: grazing[0].contact,
            length,
        })
    }

    /// The predicted fixed points at `p* + dp` that strike a nonempty set of the grazing
    /// minima (all together first).
    pub(super) fn guesses(&self, dp: f64) -> Vec<DVector<f64>> {
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

    /// Whether the edge grazes one gap minimum only (the case [`solve`](Self::solve) covers).
    pub(super) fn is_single(&self) -> bool {
        self.gaps.len() == 1
    }

    /// The orbit at `p` with the event sequence `keep` that strikes the one grazing minimum,
    /// by Newton's method on `F(z) = φ(z) − z` with the square root of the normal form built
    /// in: at an iterate `z_k` whose flow strikes with speed `v_k`, so `w_k = v_k/κ = √(−h)`,
    /// the smooth part of the Jacobian is `Q = Φ − I + E cᵀ/(2w_k)`, and the step `Δz` with
    /// the new root `s = √(w_k² − cᵀΔz)` solves `QΔz + E(s − w_k) = −F(z_k)`: a quadratic in
    /// s, its positive root nearest `w_k`. Plain Newton's method on F alone converges only
    /// within a penetration of order v² of the orbit (the map's derivative grows like 1/v),
    /// which just past a grazing is below any predictor's accuracy. `None` if the edge
    /// grazed more than one minimum, or the iteration leaves `keep` or does not converge.
    pub(super) fn solve<F: Fn(f64) -> ChainParams>(
        &self,
        problem: &Problem<'_, F>,
        z0: &DVector<f64>,
        p: f64,
        arclength: f64,
        keep: &[(EventKind, usize)],
    ) -> Option<StepPoint> {
        let ([e], [c], [kappa]) = (self.e.as_slice(), self.c.as_slice(), self.kappas.as_slice()) else {
            return None;
        };
        let params = (problem.family)(p);
        let opts = &problem.options.shooting;
        let end = problem.end(&params);
        let contact = self.contact;
        let dim = z0.len();
        let mut z = z0.clone();
        let mut last = f64::INFINITY;
        for _ in 0..MODEL_ITERATIONS {
            let eval = evaluate(
                &params,
                &z,
                problem.period,
                problem.phase,
                &opts.sim,
                &opts.sensitivity,
            )
            .ok()?;
            if sequence(&eval.events, end) != keep {
                return None;
            }
            let f = eval.residual(&z);
            let r = problem.scale.norm(&f);
            let phi = eval.stm.as_ref().ok()?;
            let n = problem.n;
            let scaled = DMatrix::from_fn(dim, dim, |i, j| {
                phi[(i, j)] * problem.scale.of_component(j, n) / problem.scale.of_component(i, n)
            });
            let floor = rounding_floor(&scaled);
            if r <= opts.tolerance.max(floor) {
                let ev = problem.evaluate(&problem.point(&z, p)).ok()?;
                let described = problem.describe(&ev, arclength)?;
                return (described.signature == keep).then_some(StepPoint {
                    theta: 0.0,
                    ev,
                    described,
                });
            }
            // The first steps may overshoot a little while w settles; divergence is not that.
            if r > 10.0 * last {
                return None;
            }
            last = r;
            let v = eval
                .events
                .iter()
                .filter(|ev| ev.kind == EventKind::Impact && ev.contact == contact && ev.time < end)
                .map(|ev| ev.velocity_before)
                .fold(f64::INFINITY, f64::min);
            let w = v / kappa;
            if !(w.is_finite() && w > 0.0) {
                return None;
            }
            let q = phi - DMatrix::identity(dim, dim) + e * c.transpose() / (2.0 * w);
            let a0 = solve_scaled(&q, &(e * w - &f), &problem.scale)?;
            let a1 = solve_scaled(&q, e, &problem.scale)?;
            let (ca0, ca1) = (c.dot(&a0), c.dot(&a1));
            let disc = ca1 * ca1 + 4.0 * (w * w - ca0);
            if disc < 0.0 {
                return None;
            }
            let s = [0.5 * (ca1 + disc.sqrt()), 0.5 * (ca1 - disc.sqrt())]
                .into_iter()
                .filter(|s| *s > 0.0)
                .min_by(|a, b| (a - w).abs().total_cmp(&(b - w).abs()))?;
            z += a0 - a1 * s;
        }
        None
    }
}

/// Iterations of [`SquareRootModel::solve`].
const MODEL_ITERATIONS: usize = 40;
