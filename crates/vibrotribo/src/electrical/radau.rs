//! The 3-stage Radau IIA collocation method (order 5, stiffly accurate, L-stable) with Hairer's
//! embedded error estimate (Hairer & Wanner, *Solving ODEs II*, Sect. IV.8, code RADAU5), and
//! the small dense solves its stage systems need.

/// Coefficients of 3-stage Radau IIA and of its error estimate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tableau {
    /// Nodes c₁, c₂, c₃ = 1.
    pub c: [f64; 3],
    /// Runge–Kutta matrix A (its last row is the weight vector b).
    pub a: [[f64; 3]; 3],
    /// γ₀ = 1/λ with λ the real eigenvalue of A⁻¹.
    pub gamma0: f64,
    /// Weights of the stage increments in the error estimate (RADAU5's DD1..DD3).
    pub dd: [f64; 3],
    /// Denominators of the Lagrange basis on the nodes {0, c₁, c₂, 1} for the increments.
    lagrange_den: [f64; 3],
}

impl Tableau {
    pub fn new() -> Self {
        let s6 = 6f64.sqrt();
        let c = [(4.0 - s6) / 10.0, (4.0 + s6) / 10.0, 1.0];
        let a = [
            [
                (88.0 - 7.0 * s6) / 360.0,
                (296.0 - 169.0 * s6) / 1800.0,
                (-2.0 + 3.0 * s6) / 225.0,
            ],
            [
                (296.0 + 169.0 * s6) / 1800.0,
                (88.0 + 7.0 * s6) / 360.0,
                (-2.0 - 3.0 * s6) / 225.0,
            ],
            [(16.0 - s6) / 36.0, (16.0 + s6) / 36.0, 1.0 / 9.0],
        ];
        let gamma0 = (6.0 + 81f64.cbrt() - 9f64.cbrt()) / 30.0;
        let dd = [-(13.0 + 7.0 * s6) / 3.0, (-13.0 + 7.0 * s6) / 3.0, -1.0 / 3.0];
        let mut lagrange_den = [0.0; 3];
        for i in 0..3 {
            let mut d = c[i];
            for j in 0..3 {
                if j != i {
                    d *= c[i] - c[j];
                }
            }
            lagrange_den[i] = d;
        }
        Tableau {
            c,
            a,
            gamma0,
            dd,
            lagrange_den,
        }
    }

    /// Weights `ℓᵢ(θ)` of the stage increments in the collocation polynomial at
    /// `t₀ + θh`: `y(t₀ + θh) = y₀ + Σᵢ ℓᵢ(θ) Zᵢ`.
    #[inline]
    pub fn dense_weights(&self, theta: f64) -> [f64; 3] {
        let c = &self.c;
        std::array::from_fn(|i| {
            let num: f64 = c
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != i)
                .fold(theta, |acc, (_, cj)| acc * (theta - cj));
            num / self.lagrange_den[i]
        })
    }
}

/// Solves `m x = b` in place (b becomes x) for the leading `n × n` block, by Gaussian
/// elimination with partial pivoting. Returns false if the matrix is singular.
#[inline]
pub(crate) fn solve_dense<const M: usize>(m: &mut [[f64; M]; M], b: &mut [f64; M], n: usize) -> bool {
    for col in 0..n {
        let mut piv = col;
        let mut best = m[col][col].abs();
        for (r, row) in m.iter().enumerate().take(n).skip(col + 1) {
            if row[col].abs() > best {
                best = row[col].abs();
                piv = r;
            }
        }
        if best == 0.0 || !best.is_finite() {
            return false;
        }
        if piv != col {
            m.swap(piv, col);
            b.swap(piv, col);
        }
        let inv = 1.0 / m[col][col];
        let (top, bottom) = m.split_at_mut(col + 1);
        let pivot = &top[col];
        for (offset, row) in bottom.iter_mut().take(n - col - 1).enumerate() {
            let f = row[col] * inv;
            if f != 0.0 {
                for (x, p) in row[col..n].iter_mut().zip(&pivot[col..n]) {
                    *x -= f * p;
                }
                b[col + 1 + offset] -= f * b[col];
            }
        }
    }
    for col in (0..n).rev() {
        let mut s = b[col];
        for k in col + 1..n {
            s -= m[col][k] * b[k];
        }
        b[col] = s / m[col][col];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tableau_is_collocation() {
        // Radau IIA: Σⱼ aᵢⱼ cⱼ^(k−1) = cᵢ^k / k for k = 1..3.
        let t = Tableau::new();
        for i in 0..3 {
            for k in 1..=3 {
                let s: f64 = (0..3).map(|j| t.a[i][j] * t.c[j].powi(k - 1)).sum();
                assert!((s - t.c[i].powi(k) / k as f64).abs() < 1e-15, "row {i}, k {k}");
            }
        }
        // Dense weights reproduce the nodes.
        for i in 0..3 {
            let w = t.dense_weights(t.c[i]);
            for (j, wj) in w.iter().enumerate() {
                assert!((wj - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn dense_solve_matches_known_solution() {
        let mut m = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        for i in 0..3 {
            b[i] = (0..3).map(|j| m[i][j] * x[j]).sum();
        }
        assert!(solve_dense(&mut m, &mut b, 3));
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-15);
        }
    }
}
