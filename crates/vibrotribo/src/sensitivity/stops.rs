//! Saltation at impacts against a body of infinite mass: a rigid stop, or a cluster stuck to
//! one (which moves with the stop, `ẋ = Y'`, `v̇ = Ÿ`, and whose rows of Φ are zero).
//!
//! Let C be the free cluster that meets it, σ = +1 if C lies below the contact and −1 above,
//! `V_C = Σ_C m_i v_i / M_C`, and `Y(t)` the motion of the infinite side. The closing speed is
//! `v_c = σ (V_C − Y')`, and Newton's law with the other mass infinite is
//!
//! ```text
//! v_i⁺ = v_i − (1 + r)(V_C − Y'(t))     (i ∈ C),
//! ```
//!
//! an affine reset `g(z, t)` with linear part `G` (`δv_i⁺ = δv_i − (1 + r) δV_C`) and explicit
//! time dependence `∂g/∂t = (1 + r) Ÿ` on C's velocities. The event function is the gap: at a
//! stop's own contact `h = gap − x₁ + Y` (upper) or `gap + x_N − Y` (lower), so `∂h/∂t = ±Y'`;
//! between masses `h = δ_k − (x_{k+1} − x_k)` as always (the stuck side's motion enters through
//! its field). With `D = ∇h·f⁻ + ∂h/∂t = −v_c`, the perturbed event time is `δτ = −∇h·δz⁻/D`
//! and
//!
//! ```text
//! S = G + (f⁺ − G f⁻ − ∂g/∂t) ∇hᵀ / D.
//! ```
//!
//! A stick to the stop (plastic, r = 0, f⁺ the stop's field on C) maps every perturbation of C
//! onto the stop's motion: C's rows of S Φ vanish. The chatter accumulation time of a jump
//! that starts at such an impact (rebound `u = r v_c`, closing acceleration
//! `a = σ (a_C⁺ − Ÿ)` after it) is `t_acc = τ + 2u/((1 − r) a)`; its gradient follows as in
//! the module docs of [`super`], with the explicit time dependence of `Y'` and `Ÿ` added.

use nalgebra::DMatrix;

use super::field::{ChainField, Cluster};
use crate::dynamics::ClusterFlow;
use crate::model::StopSide;

/// An impact of the free cluster `free` against an infinite side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WallImpact {
    pub free: Cluster,
    /// +1 if the free cluster lies below the contact, −1 above.
    pub sigma: f64,
    /// The stop whose motion the infinite side follows.
    pub side: StopSide,
    /// Closing speed just before, m/s (> 0).
    pub closing: f64,
    /// `∇h` on the positions: (mass, coefficient) pairs (one or two).
    pub grad: [(usize, f64); 2],
    pub grad_len: usize,
    /// `∂h/∂t`, m/s.
    pub h_t: f64,
}

impl WallImpact {
    /// The impact at contact `k` if one of its sides has infinite mass (`clusters`: the
    /// partition before it; `x`, `v` the state just before, at time `t`), else `None`.
    pub fn classify(
        field: &ChainField,
        clusters: &[ClusterFlow],
        k: usize,
        v: &[f64],
        t: f64,
    ) -> Option<WallImpact> {
        let n = field.len();
        let find = |i: usize| &clusters[clusters.partition_point(|c| c.last < i)];
        let (free_flow, sigma, side, grad, grad_len, h_t) = if k + 1 < n {
            let (up, low) = (find(k), find(k + 1));
            let grad = [(k, 1.0), (k + 1, -1.0)];
            match (up.stop, low.stop) {
                (Some(side), None) => (low, 1.0, side, grad, 2, 0.0),
                (None, Some(side)) => (up, -1.0, side, grad, 2, 0.0),
                _ => return None,
            }
        } else if k + 1 == n {
            let y = field.wall(StopSide::Lower, t);
            (
                find(n - 1),
                -1.0,
                StopSide::Lower,
                [(n - 1, 1.0), (0, 0.0)],
                1,
                -y[1],
            )
        } else {
            let y = field.wall(StopSide::Upper, t);
            (find(0), 1.0, StopSide::Upper, [(0, -1.0), (0, 0.0)], 1, y[1])
        };
        let free = field.cluster_of_flow(free_flow);
        let vel: f64 = free.members().map(|i| field.masses[i] * v[i]).sum::<f64>() / free.mass;
        let yd = field.wall(side, t)[1];
        Some(WallImpact {
            free,
            sigma,
            side,
            closing: sigma * (vel - yd),
            grad,
            grad_len,
            h_t,
        })
    }

    fn grad(&self) -> &[(usize, f64)] {
        &self.grad[..self.grad_len]
    }

    /// `∇h·z` on the positions of a 2N-vector.
    fn grad_dot(&self, z: &[f64]) -> f64 {
        self.grad().iter().map(|&(i, c)| c * z[i]).sum()
    }

    /// `G z`: C's velocities lose `(1 + r) δV_C`.
    fn reset(&self, field: &ChainField, r: f64, z: &mut [f64]) {
        let n = field.len();
        let dv: f64 = self
            .free
            .members()
            .map(|i| field.masses[i] / self.free.mass * z[n + i])
            .sum();
        for i in self.free.members() {
            z[n + i] -= (1.0 + r) * dv;
        }
    }
}

/// `Φ ← S Φ` for an impact against an infinite side with restitution `r` (0 when C sticks to
/// it or starts a chatter jump), at time `t`; `scratch` holds 2 × 2N entries.
#[allow(clippy::too_many_arguments)]
pub(crate) fn apply_wall_impact(
    phi: &mut DMatrix<f64>,
    field: &ChainField,
    imp: &WallImpact,
    r: f64,
    t: f64,
    f_pre: &[f64],
    f_post: &[f64],
    scratch: &mut [f64],
) {
    let n = field.len();
    let dim = 2 * n;
    let (row, d) = scratch.split_at_mut(dim);
    let d = &mut d[..dim];
    for (col, rw) in row.iter_mut().enumerate() {
        *rw = imp.grad().iter().map(|&(i, c)| c * phi[(i, col)]).sum();
    }
    for column in phi.as_mut_slice().chunks_exact_mut(dim) {
        imp.reset(field, r, column);
    }
    d.copy_from_slice(f_pre);
    imp.reset(field, r, d);
    let ydd = field.wall(imp.side, t)[2];
    for i in imp.free.members() {
        d[n + i] += (1.0 + r) * ydd;
    }
    let denom = imp.grad_dot(f_pre) + imp.h_t;
    for (di, fp) in d.iter_mut().zip(f_post) {
        *di = (fp - *di) / denom;
    }
    for col in 0..dim {
        let rw = row[col];
        if rw != 0.0 {
            for (i, di) in d.iter().enumerate() {
                phi[(i, col)] += di * rw;
            }
        }
    }
}

/// `out = ∇τ`, the gradient of the impact time with respect to the state just before it:
/// `δτ = −∇h·δz⁻ / D`, `D = ∇h·f⁻ + ∂h/∂t`.
pub(crate) fn wall_impact_time_row(imp: &WallImpact, f_pre: &[f64], out: &mut [f64]) {
    let denom = imp.grad_dot(f_pre) + imp.h_t;
    out.fill(0.0);
    for &(i, c) in imp.grad() {
        out[i] -= c / denom;
    }
}

/// The gradient of the chatter accumulation time `t_acc = τ + 2 r v_c / ((1 − r) a)` of a jump
/// that starts at this impact, with respect to the state `z⁻` just before it (module docs);
/// `x`, `v` the state just before at time `t`. Writes 2N entries into `out`, uses `tmp`
/// (3 × 2N).
#[allow(clippy::too_many_arguments)]
pub(crate) fn wall_chatter_time_row(
    field: &ChainField,
    imp: &WallImpact,
    r: f64,
    t: f64,
    x: &[f64],
    v: &[f64],
    f_pre: &[f64],
    out: &mut [f64],
    tmp: &mut [f64],
) {
    let n = field.len();
    let dim = 2 * n;
    let c = &imp.free;
    let sigma = imp.sigma;
    let (tau, rest) = tmp.split_at_mut(dim);
    let (vc_row, a_row) = rest.split_at_mut(dim);
    let a_row = &mut a_row[..dim];
    wall_impact_time_row(imp, f_pre, tau);
    let wall = field.wall(imp.side, t);
    let (s, vel) = field.coordinates(c, x, v);
    let vel_after = vel - (1.0 + r) * (vel - wall[1]);
    let a_c = field.accel(c, s, vel_after, t);
    let a = sigma * (a_c - wall[2]);
    let vc = imp.closing;
    vc_row.fill(0.0);
    a_row.fill(0.0);
    for i in c.members() {
        let w = field.masses[i] / c.mass;
        vc_row[n + i] = sigma * w;
        a_row[i] = -sigma * c.stiffness * w / c.mass;
        a_row[n + i] = sigma * r * c.damping * w / c.mass;
    }
    let vc_t = -sigma * wall[2];
    let a_t = sigma * (field.accel_rate(c, t) - c.damping / c.mass * (1.0 + r) * wall[2] - wall[3]);
    let vc_f: f64 = vc_row.iter().zip(f_pre).map(|(q, f)| q * f).sum::<f64>() + vc_t;
    let a_f: f64 = a_row.iter().zip(f_pre).map(|(q, f)| q * f).sum::<f64>() + a_t;
    let remaining = 2.0 * r * vc / ((1.0 - r) * a);
    for i in 0..dim {
        let dvc = vc_row[i] + vc_f * tau[i];
        let da = a_row[i] + a_f * tau[i];
        out[i] = tau[i] + remaining * (dvc / vc - da / a);
    }
}

/// Whether contact `k` is closed in the partition `clusters` of `n` masses: between masses,
/// both in one cluster; at a stop, the adjacent cluster stuck to it.
pub(crate) fn is_closed(clusters: &[ClusterFlow], n: usize, k: usize) -> bool {
    let find = |i: usize| &clusters[clusters.partition_point(|c| c.last < i)];
    if k + 1 < n {
        find(k).last > k
    } else if k + 1 == n {
        find(n - 1).stop == Some(StopSide::Lower)
    } else {
        find(0).stop == Some(StopSide::Upper)
    }
}

/// The gap of open stop contact `k` (`k ≥ N − 1`) at state `x`, time `t`, m (infinite if
/// the chain has no such stop).
pub(crate) fn stop_gap(field: &ChainField, k: usize, x: &[f64], t: f64) -> f64 {
    let n = field.len();
    let side = if k + 1 == n {
        StopSide::Lower
    } else {
        StopSide::Upper
    };
    let Some(stop) = field.stops.get(side) else {
        return f64::INFINITY;
    };
    let y = field.wall(side, t)[0];
    match side {
        StopSide::Upper => stop.gap - (x[0] - y),
        StopSide::Lower => stop.gap - (y - x[n - 1]),
    }
}
