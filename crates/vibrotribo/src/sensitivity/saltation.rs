//! The Jacobian of the flow between events and the saltation matrices at events, applied in
//! place to a state-transition matrix Φ (2N × 2N, rows and columns `[x₁ … x_N, v₁ … v_N]`).
//! The derivations are in the [module docs](super).

use nalgebra::DMatrix;

use super::field::{ChainField, Cluster};
use crate::dynamics::ClusterFlow;

/// `Φ ← J Φ` for the flow of `clusters` from `t_a` to `t_b`: each cluster's 2 × 2
/// propagator Jacobian acting on its mass-weighted coordinate and velocity, copied to every
/// member (which also projects Φ onto the cluster's constraint subspace).
pub(crate) fn propagate(
    phi: &mut DMatrix<f64>,
    field: &ChainField,
    clusters: &[ClusterFlow],
    t_a: f64,
    t_b: f64,
) {
    let n = field.len();
    for cf in clusters {
        let osc = &cf.oscillator;
        // The homogeneous part is time-invariant, so J(t_b, t_a) is the propagator over
        // t_b − t_a, whatever the oscillator's start (a piece of flow split in parts).
        let j = if osc.start_time() == t_a {
            osc.state_jacobian(t_b)
        } else {
            osc.state_jacobian(osc.start_time() + (t_b - t_a))
        };
        let c = field.cluster(cf.first, cf.last);
        for col in 0..2 * n {
            let (s, v) = if c.first == c.last {
                (phi[(c.first, col)], phi[(n + c.first, col)])
            } else {
                let (mut s, mut v) = (0.0, 0.0);
                for i in c.members() {
                    let w = field.masses[i] / c.mass;
                    s += w * phi[(i, col)];
                    v += w * phi[(n + i, col)];
                }
                (s, v)
            };
            let (s1, v1) = (j[0][0] * s + j[0][1] * v, j[1][0] * s + j[1][1] * v);
            for i in c.members() {
                phi[(i, col)] = s1;
                phi[(n + i, col)] = v1;
            }
        }
    }
}

/// An impact at contact `k` between the clusters `upper` (holding mass k) and `lower`
/// (holding mass k + 1), read from the state just before it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Impact {
    pub k: usize,
    pub upper: Cluster,
    pub lower: Cluster,
    /// Closing speed `V_L − V_U` just before, m/s (> 0).
    pub closing: f64,
}

impl Impact {
    /// Reduced mass `M_U M_L / (M_U + M_L)`, kg.
    fn reduced_mass(&self) -> f64 {
        self.upper.mass * self.lower.mass / (self.upper.mass + self.lower.mass)
    }

    /// `row · (w_L − w_U)` on the velocity entries of a 2N-vector: the closing speed of a
    /// perturbation.
    fn closing_of(&self, field: &ChainField, z: &[f64]) -> f64 {
        let n = field.len();
        let mut d = 0.0;
        for i in self.lower.members() {
            d += field.masses[i] / self.lower.mass * z[n + i];
        }
        for i in self.upper.members() {
            d -= field.masses[i] / self.upper.mass * z[n + i];
        }
        d
    }
}

/// Applies the velocity reset Jacobian R of a Newton impact with restitution `mu` to a
/// 2N-vector: `v_U += (1+μ) M_L/(M_U+M_L) ΔV`, `v_L −= (1+μ) M_U/(M_U+M_L) ΔV` with
/// `ΔV = (w_L − w_U)·v` (positions unchanged). With μ = 0 this is the plastic merge.
fn reset(field: &ChainField, imp: &Impact, mu: f64, z: &mut [f64]) {
    let n = field.len();
    let total = imp.upper.mass + imp.lower.mass;
    let dv = imp.closing_of(field, z);
    let up = (1.0 + mu) * imp.lower.mass / total * dv;
    let down = (1.0 + mu) * imp.upper.mass / total * dv;
    for i in imp.upper.members() {
        z[n + i] += up;
    }
    for i in imp.lower.members() {
        z[n + i] -= down;
    }
}

/// `Φ ← S Φ` with the impact saltation matrix
/// `S = R + (f⁺ − R f⁻) ∇dᵀ / (∇d · f⁻)`, `∇d = e_{x_k} − e_{x_{k+1}}`, `∇d · f⁻ = −v_c`.
/// `mu` is the restitution of the reset (0 when the two sides merge: a plastic stick or the
/// start of a chatter jump); `f_pre`, `f_post` the vector fields just before and after.
/// `scratch` holds 2N + 2N entries.
pub(crate) fn apply_impact(
    phi: &mut DMatrix<f64>,
    field: &ChainField,
    imp: &Impact,
    mu: f64,
    f_pre: &[f64],
    f_post: &[f64],
    scratch: &mut [f64],
) {
    let n = field.len();
    let dim = 2 * n;
    let (row, d) = scratch.split_at_mut(dim);
    let d = &mut d[..dim];
    // ∇dᵀΦ.
    for (col, r) in row.iter_mut().enumerate() {
        *r = phi[(imp.k, col)] - phi[(imp.k + 1, col)];
    }
    // R Φ, column by column.
    for column in phi.as_mut_slice().chunks_exact_mut(dim) {
        reset(field, imp, mu, column);
    }
    // d = (f⁺ − R f⁻) / (∇d·f⁻).
    d.copy_from_slice(f_pre);
    reset(field, imp, mu, d);
    let denom = f_pre[imp.k] - f_pre[imp.k + 1];
    for (di, fp) in d.iter_mut().zip(f_post) {
        *di = (fp - *di) / denom;
    }
    for col in 0..dim {
        let r = row[col];
        if r != 0.0 {
            for (i, di) in d.iter().enumerate() {
                phi[(i, col)] += di * r;
            }
        }
    }
}

/// The state just before an event and the field there.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Before<'a> {
    /// Time, s.
    pub t: f64,
    /// Positions, m.
    pub x: &'a [f64],
    /// Velocities, m/s.
    pub v: &'a [f64],
    /// The vector field f⁻ (2N).
    pub f: &'a [f64],
}

/// `out = ∇t_imp`, the gradient of the impact time with respect to the state just before the
/// impact (at the nominal time): `δt = −∇d·δz / (∇d·f⁻) = (δx_k − δx_{k+1}) / v_c`.
pub(crate) fn impact_time_row(imp: &Impact, out: &mut [f64]) {
    out.fill(0.0);
    out[imp.k] = 1.0 / imp.closing;
    out[imp.k + 1] = -1.0 / imp.closing;
}

/// The gradient of the chatter accumulation time `t_acc` scheduled at an impact (see the
/// module docs), with respect to the state `z⁻` just before the impact, at time `t`:
///
/// ```text
/// t_acc = τ + 2u / ((1 − μ) a),   u = μ v_c,   a = a_L⁺ − a_U⁺,
/// ```
///
/// with τ the impact time, v_c the closing speed and a_U⁺, a_L⁺ the two sides' free
/// accelerations after the Newton impact, all taken at τ from the state there,
/// `z⁻ + δz⁻ + f⁻ δτ`, with `pre` the state just before. Writes the row into `out` (2N)
/// using `tmp` (3 × 2N).
pub(crate) fn chatter_time_row(
    field: &ChainField,
    imp: &Impact,
    pre: &Before<'_>,
    out: &mut [f64],
    tmp: &mut [f64],
) {
    let Before { t, x, v, f: f_pre } = *pre;
    let n = field.len();
    let dim = 2 * n;
    let mu = field.restitution;
    let (u_c, l_c) = (&imp.upper, &imp.lower);
    let (tau, rest) = tmp.split_at_mut(dim);
    let (vc_row, a_row) = rest.split_at_mut(dim);
    let a_row = &mut a_row[..dim];
    impact_time_row(imp, tau);
    // Closing speed as a functional of δz at the impact: (w_L − w_U) on the velocities.
    vc_row.fill(0.0);
    for i in l_c.members() {
        vc_row[n + i] = field.masses[i] / l_c.mass;
    }
    for i in u_c.members() {
        vc_row[n + i] = -field.masses[i] / u_c.mass;
    }
    // Post-impact accelerations and the functional δa of δz at the impact.
    let vc = imp.closing;
    let impulse = (1.0 + mu) * imp.reduced_mass() * vc;
    let (s_u, v_u) = field.coordinates(u_c, x, v);
    let (s_l, v_l) = field.coordinates(l_c, x, v);
    let a_u = field.accel(u_c, s_u, v_u + impulse / u_c.mass, t);
    let a_l = field.accel(l_c, s_l, v_l - impulse / l_c.mass, t);
    let a = a_l - a_u;
    let a_t = field.accel_rate(l_c, t) - field.accel_rate(u_c, t);
    a_row.fill(0.0);
    for i in l_c.members() {
        let w = field.masses[i] / l_c.mass;
        a_row[i] = -l_c.stiffness * w / l_c.mass;
        a_row[n + i] = -l_c.damping * w / l_c.mass;
    }
    for i in u_c.members() {
        let w = field.masses[i] / u_c.mass;
        a_row[i] = u_c.stiffness * w / u_c.mass;
        a_row[n + i] = u_c.damping * w / u_c.mass;
    }
    // The impulse moves with the closing speed: δV_U⁺ = δV_U + (1+μ)m δv_c/M_U and
    // δV_L⁺ = δV_L − (1+μ)m δv_c/M_L, so a_L⁺ − a_U⁺ gains (1+μ)m (C_L/M_L² + C_U/M_U²) δv_c.
    let via_vc = (1.0 + mu)
        * imp.reduced_mass()
        * (l_c.damping / (l_c.mass * l_c.mass) + u_c.damping / (u_c.mass * u_c.mass));
    for (ar, vr) in a_row.iter_mut().zip(vc_row.iter()) {
        *ar += via_vc * vr;
    }
    // Carry both functionals from δz at τ to δz⁻: q·(δz⁻ + f⁻ δτ) = (q + (q·f⁻) ∇τ)·δz⁻; the
    // accelerations also depend on time explicitly (a_t δτ).
    let vc_f: f64 = vc_row.iter().zip(f_pre).map(|(q, f)| q * f).sum();
    let a_f: f64 = a_row.iter().zip(f_pre).map(|(q, f)| q * f).sum::<f64>() + a_t;
    let remaining = 2.0 * mu * vc / ((1.0 - mu) * a);
    // δt_acc = δτ + remaining (δu/u − δa/a), δu/u = δv_c/v_c.
    for i in 0..dim {
        let dvc = vc_row[i] + vc_f * tau[i];
        let da = a_row[i] + a_f * tau[i];
        out[i] = tau[i] + remaining * (dvc / vc - da / a);
    }
}

/// `Φ ← Φ + (f⁻ − f⁺) ∇t_accᵀ`: at a chatter accumulation point where the two sides release,
/// the state is continuous but the field jumps from the merged cluster's (`f_pre`) to the
/// split clusters' (`f_post`) at a time `t_acc` that depends on the initial state through
/// `row` (its gradient with respect to the initial state).
pub(crate) fn apply_time_shift(phi: &mut DMatrix<f64>, f_pre: &[f64], f_post: &[f64], row: &[f64]) {
    for (col, r) in row.iter().enumerate() {
        if *r != 0.0 {
            for (i, (a, b)) in f_pre.iter().zip(f_post).enumerate() {
                phi[(i, col)] += (a - b) * r;
            }
        }
    }
}
