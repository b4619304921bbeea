//! Radau IIA collocation methods with S = 3 or 7 stages (order 2S − 1, stage order S,
//! stiffly accurate, L-stable) with Hairer's embedded error estimate of order S (Hairer &
//! Wanner, *Solving ODEs II*, Sect. IV.8, codes RADAU5 and RADAU), and the small dense solves
//! their stage systems need.

/// Coefficients of `S`-stage Radau IIA (S = 3 or 7) and of its error estimate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tableau<const S: usize> {
    /// Nodes c₁ … c_S = 1.
    pub c: [f64; S],
    /// Runge–Kutta matrix A (its last row is the weight vector b).
    pub a: [[f64; S]; S],
    /// γ₀ = 1/λ with λ the real eigenvalue of A⁻¹.
    pub gamma0: f64,
    /// Weights of the stage increments in the error estimate (RADAU5's DD1..DD3 for S = 3):
    /// `γ₀ (h f₀ + Σ ddᵢ Zᵢ)` is the difference to the embedded method of order S on the
    /// nodes {0, c₁, …, c_S}.
    pub dd: [f64; S],
    /// `Aᵀ·dd`: the estimate's `Σ ddᵢ Zᵢ` for a quadrature component `Z = hA·p` is
    /// `h Σⱼ (Aᵀdd)ⱼ pⱼ`.
    pub dd_a: [f64; S],
    /// `|A|ᵀ·|dd|`, for the rounding noise of that sum.
    pub dd_a_abs: [f64; S],
    /// `Σ |ddᵢ|`.
    pub dd_abs_sum: f64,
    /// Denominators of the Lagrange basis on the nodes {0, c₁, …, c_S} for the increments.
    lagrange_den: [f64; S],
    /// The same basis as polynomials: `ℓᵢ(θ) = Σⱼ increment_basis[i][j] θ^(j+1)` (ℓᵢ(0) = 0),
    /// the monomial form of [`dense_weights`](Self::dense_weights), for integrating an
    /// interpolant.
    pub increment_basis: [[f64; S]; S],
}

impl<const S: usize> Tableau<S> {
    pub fn new() -> Self {
        match S {
            3 => Self::from_coefficients(&C3, |i, j| A3[i][j], GAMMA0_3, &DD3),
            7 => Self::from_coefficients(&C7, |i, j| A7[i][j], GAMMA0_7, &DD7),
            _ => panic!("Radau IIA with {S} stages is not tabulated"),
        }
    }

    fn from_coefficients(c: &[f64], a: impl Fn(usize, usize) -> f64, gamma0: f64, dd: &[f64]) -> Self {
        let c: [f64; S] = std::array::from_fn(|i| c[i]);
        let lagrange_den =
            std::array::from_fn(|i| (0..S).filter(|&j| j != i).fold(c[i], |d, j| d * (c[i] - c[j])));
        let a: [[f64; S]; S] = std::array::from_fn(|i| std::array::from_fn(|j| a(i, j)));
        let dd: [f64; S] = std::array::from_fn(|i| dd[i]);
        let increment_basis = std::array::from_fn(|i| {
            // θ·Π_{j≠i}(θ − c_j)/den_i, from p = 1 multiplied out factor by factor (p[m]: θ^m).
            let mut p = [0.0; S];
            p[0] = 1.0;
            let mut degree = 0;
            for (j, cj) in c.iter().enumerate() {
                if j == i {
                    continue;
                }
                for m in (0..=degree + 1).rev() {
                    let lower = if m > 0 { p[m - 1] } else { 0.0 };
                    p[m] = lower - cj * p[m];
                }
                degree += 1;
            }
            // The extra factor θ shifts p up by one: coefficient m of p is that of θ^(m+1).
            p.map(|pm| pm / lagrange_den[i])
        });
        Tableau {
            c,
            a,
            gamma0,
            dd,
            dd_a: std::array::from_fn(|j| (0..S).map(|i| a[i][j] * dd[i]).sum()),
            dd_a_abs: std::array::from_fn(|j| (0..S).map(|i| (a[i][j] * dd[i]).abs()).sum()),
            dd_abs_sum: dd.iter().map(|d| d.abs()).sum(),
            lagrange_den,
            increment_basis,
        }
    }

    /// The stage system of a linear equation `y' = −k(t)·y + …` whose stage values of `h·k` are
    /// `hk`: the matrix `I + A·diag(hk)` and the right-hand side `rhs(i, (A·hk)ᵢ)` of each row
    /// (`(A·hk)ᵢ` is stage i's response to a unit start value), dimensionless. Inlined: the
    /// resistor's trial step builds one per trial.
    #[inline(always)]
    pub fn stage_system(&self, hk: &[f64; S], rhs: impl Fn(usize, f64) -> f64) -> ([[f64; S]; S], [f64; S]) {
        let mut m = [[0.0; S]; S];
        let mut b = [0.0; S];
        for i in 0..S {
            let mut row_sum = 0.0;
            for j in 0..S {
                let v = self.a[i][j] * hk[j];
                m[i][j] = v;
                row_sum += v;
            }
            m[i][i] += 1.0;
            b[i] = rhs(i, row_sum);
        }
        (m, b)
    }

    /// Weights `ℓᵢ(θ)` of the stage increments in the collocation polynomial at
    /// `t₀ + θh`: `y(t₀ + θh) = y₀ + Σᵢ ℓᵢ(θ) Zᵢ`.
    #[inline]
    pub fn dense_weights(&self, theta: f64) -> [f64; S] {
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

// Coefficients computed with 60-digit arithmetic (mpmath): nodes are the zeros of
// P_S(2x − 1) − P_{S−1}(2x − 1), aᵢⱼ = ∫₀^{cᵢ} ℓⱼ, γ₀ = 1/(real eigenvalue of A⁻¹), and
// dd = A⁻ᵀ(b̂ − b)/γ₀ with b̂ the weights on {c₁ … c_S} that, with γ₀ at 0, integrate
// polynomials of degree < S exactly.
/// Radau IIA with 3 stages (order 5).
const C3: [f64; 3] = [0.1550510257216822, 0.6449489742783178, 1.0];
const A3: [[f64; 3]; 3] = [
    [0.1968154772236604, -0.06553542585019839, 0.02377097434822015],
    [0.3944243147390873, 0.2920734116652285, -0.04154875212599793],
    [0.37640306270046725, 0.5124858261884216, 0.1111111111111111],
];
const GAMMA0_3: f64 = 0.27488882959567734;
const DD3: [f64; 3] = [-10.048809399827416, 1.382142733160749, -0.3333333333333333];
/// Radau IIA with 7 stages (order 13).
const C7: [f64; 7] = [
    0.029316427159784893,
    0.1480785996684843,
    0.3369846902811543,
    0.5586715187715501,
    0.7692338620300545,
    0.9269456713197411,
    1.0,
];
const A7: [[f64; 7]; 7] = [
    [
        0.03754626499392133,
        -0.0140393345564604,
        0.0103527896007423,
        -0.008158322540275011,
        0.006388413879534685,
        -0.004602326779148656,
        0.0018289425614706437,
    ],
    [
        0.08014759651561897,
        0.08106206398589154,
        -0.021237992120711036,
        0.014000291238817119,
        -0.010234185730090163,
        0.0071534651513645905,
        -0.0028126393724067235,
    ],
    [
        0.0720638469418819,
        0.17106835498388662,
        0.10961456404007211,
        -0.024619871728984055,
        0.014760377043950817,
        -0.009575259396791401,
        0.0036726783971383057,
    ],
    [
        0.07570512581982441,
        0.15409015514217114,
        0.2271077366732024,
        0.11747818703702478,
        -0.023810827153044174,
        0.012709985533661206,
        -0.004608844281289633,
    ],
    [
        0.07391234216319184,
        0.16135560761594242,
        0.2068672415521042,
        0.23700711534269422,
        0.10308679353381345,
        -0.018854139152580447,
        0.0058589009748887914,
    ],
    [
        0.07470556205979623,
        0.1583072238724687,
        0.21415342326720002,
        0.21987784703186003,
        0.19875212168063527,
        0.06926550160550914,
        -0.00811600819772829,
    ],
    [
        0.07449423555601031,
        0.15910211573365074,
        0.21235188950297781,
        0.22355491450728324,
        0.19047493682211558,
        0.1196137446126562,
        0.02040816326530612,
    ],
];
const GAMMA0_7: f64 = 0.11189646530003508;
const DD7: [f64; 7] = [
    -54.374436894128614,
    7.000024004259187,
    -2.355661091987557,
    1.1322890661061344,
    -0.6468913267673587,
    0.38753338537535237,
    -0.14285714285714285,
];

/// Solves `m x = b` in place (b becomes x) by Gaussian elimination without pivoting, for a
/// fixed size `N`. Meant for the resistor's stage matrices `I + hA·diag(k)`, k ≥ 0: they are
/// nonsingular for Radau IIA (its BN-stability), and elimination without pivoting keeps their
/// growth factor below 2 from h·k = 1e-3 to 1e9 with k varying 20× between stages (see the
/// test). Returns false on a zero or non-finite pivot.
#[inline]
pub(crate) fn solve_unpivoted<const N: usize>(m: &mut [[f64; N]; N], b: &mut [f64; N]) -> bool {
    solve_unpivoted_many(m, std::array::from_mut(b))
}

/// [`solve_unpivoted`] for `K` right-hand sides at once: one elimination of `m`, each
/// solution bit for bit the one a solve of its own gives (the same operations in the same
/// order: the elimination's multipliers are kept below the diagonal and applied to each
/// right-hand side afterwards).
#[inline]
pub(crate) fn solve_unpivoted_many<const N: usize, const K: usize>(
    m: &mut [[f64; N]; N],
    b: &mut [[f64; N]; K],
) -> bool {
    // Reciprocals of the pivots, reused by the back substitution (no division on its chain).
    let mut inv_diag = [0.0; N];
    for col in 0..N {
        let inv = 1.0 / m[col][col];
        if !(inv != 0.0 && inv.is_finite()) {
            return false;
        }
        inv_diag[col] = inv;
        let pivot = m[col];
        for row in m.iter_mut().skip(col + 1) {
            let f = row[col] * inv;
            row[col] = f;
            for j in col + 1..N {
                row[j] -= f * pivot[j];
            }
        }
    }
    for bk in b.iter_mut() {
        for col in 0..N {
            let bc = bk[col];
            for r in col + 1..N {
                bk[r] -= m[r][col] * bc;
            }
        }
        for col in (0..N).rev() {
            let mut s = bk[col];
            for k in col + 1..N {
                s -= m[col][k] * bk[k];
            }
            bk[col] = s * inv_diag[col];
        }
    }
    true
}

/// Solves `m x = b` in place (b becomes x) by Gaussian elimination with partial pivoting,
/// for a fixed size `N` (loops the compiler can unroll). Returns false if the matrix is
/// singular.
#[inline]
pub(crate) fn solve_fixed<const N: usize>(m: &mut [[f64; N]; N], b: &mut [f64; N]) -> bool {
    for col in 0..N {
        let mut piv = col;
        let mut best = m[col][col].abs();
        for (r, row) in m.iter().enumerate().skip(col + 1) {
            if row[col].abs() > best {
                best = row[col].abs();
                piv = r;
            }
        }
        if !(best > 0.0 && best.is_finite()) {
            return false;
        }
        m.swap(piv, col);
        b.swap(piv, col);
        let (done, rest) = m.split_at_mut(col + 1);
        let pivot = &done[col];
        let inv = 1.0 / pivot[col];
        let bc = b[col];
        for (row, br) in rest.iter_mut().zip(b[col + 1..].iter_mut()) {
            let f = row[col] * inv;
            // Sweep the whole row: entries left of the diagonal are never read again.
            for (x, p) in row.iter_mut().zip(pivot) {
                *x -= f * p;
            }
            *br -= f * bc;
        }
    }
    for col in (0..N).rev() {
        let mut s = b[col];
        for k in col + 1..N {
            s -= m[col][k] * b[k];
        }
        b[col] = s / m[col][col];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_tableau<const S: usize>() {
        let t = Tableau::<S>::new();
        // Collocation: Σⱼ aᵢⱼ cⱼ^(k−1) = cᵢ^k / k for k = 1..S.
        for i in 0..S {
            for k in 1..=S as i32 {
                let s: f64 = (0..S).map(|j| t.a[i][j] * t.c[j].powi(k - 1)).sum();
                let want = t.c[i].powi(k) / k as f64;
                assert!((s - want).abs() < 1e-15, "S = {S}, row {i}, k {k}: {s} vs {want}");
            }
        }
        // The last row is the Radau quadrature: exact to degree 2S − 2.
        for k in 1..=(2 * S - 1) as i32 {
            let s: f64 = (0..S).map(|j| t.a[S - 1][j] * t.c[j].powi(k - 1)).sum();
            assert!(
                (s - 1.0 / k as f64).abs() < 1e-15,
                "S = {S}, quadrature degree {}",
                k - 1
            );
        }
        // The error estimate γ₀(h f₀ + Σ ddᵢ Zᵢ) vanishes on polynomial solutions of degree ≤ S:
        // for y = t^k, h = 1: f₀ = [k = 1], Zᵢ = cᵢ^k.
        for k in 1..=S as i32 {
            let f0 = if k == 1 { 1.0 } else { 0.0 };
            let e: f64 = f0 + (0..S).map(|i| t.dd[i] * t.c[i].powi(k)).sum::<f64>();
            assert!(e.abs() < 1e-12, "S = {S}, degree {k}: estimate {e}");
        }
        // ... and not on degree S + 1.
        let k = S as i32 + 1;
        let e: f64 = (0..S).map(|i| t.dd[i] * t.c[i].powi(k)).sum::<f64>();
        assert!(e.abs() > 1e-6, "S = {S}: the estimate must see degree S + 1");
        // γ₀ is the inverse of a real eigenvalue of A⁻¹: det(A − γ₀ I) = 0.
        let mut m = t.a;
        for (i, row) in m.iter_mut().enumerate() {
            row[i] -= t.gamma0;
        }
        let mut b = [1.0; S];
        assert!(!solve_fixed(&mut m, &mut b) || b.iter().any(|x| x.abs() > 1e10));
        // The basis polynomials are the dense weights (to the conditioning of the monomial
        // form: 1.5e-12 at worst for S = 7 on [0, 1]; the product form is the exact one).
        for theta in [0.0, 0.13, 0.5, 0.87, 1.0, 1.4] {
            let w = t.dense_weights(theta);
            for (i, (basis, wi)) in t.increment_basis.iter().zip(w).enumerate() {
                let p = basis.iter().rev().fold(0.0, |acc, c| acc * theta + c) * theta;
                assert!(
                    (p - wi).abs() < 1e-10 * (1.0 + wi.abs()),
                    "S = {S}, ℓ_{i}({theta}): {p} against {wi}"
                );
            }
        }
        // Dense weights reproduce the nodes.
        for i in 0..S {
            let w = t.dense_weights(t.c[i]);
            for (j, wj) in w.iter().enumerate() {
                assert!((wj - if i == j { 1.0 } else { 0.0 }).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn tableaus_are_collocation_with_embedded_estimates() {
        check_tableau::<3>();
        check_tableau::<7>();
    }

    /// The resistor's stage matrices need no pivoting: over a wide range of h·k, with k
    /// varying between stages, the unpivoted solution is as accurate as the pivoted one.
    #[test]
    fn stage_matrices_solve_without_pivoting() {
        let tab = Tableau::<7>::new();
        // A small deterministic generator (xorshift) for the stage rates.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst: f64 = 0.0;
        for _ in 0..20_000 {
            let hk0 = 10f64.powf(-3.0 + 12.0 * uniform());
            let hk: [f64; 7] = std::array::from_fn(|_| hk0 * (3.0 * (uniform() - 0.5)).exp());
            let m: [[f64; 7]; 7] = std::array::from_fn(|i| {
                std::array::from_fn(|j| tab.a[i][j] * hk[j] + if i == j { 1.0 } else { 0.0 })
            });
            let x: [f64; 7] = std::array::from_fn(|_| uniform() - 0.5);
            let b: [f64; 7] = std::array::from_fn(|i| (0..7).map(|j| m[i][j] * x[j]).sum());
            let (mut m1, mut b1, mut m2, mut b2) = (m, b, m, b);
            assert!(solve_unpivoted(&mut m1, &mut b1));
            assert!(solve_fixed(&mut m2, &mut b2));
            // Residuals relative to |m|·|x|.
            let residual = |y: &[f64; 7]| {
                (0..7)
                    .map(|i| {
                        let r: f64 = b[i] - (0..7).map(|j| m[i][j] * y[j]).sum::<f64>();
                        let s: f64 = (0..7).map(|j| (m[i][j] * y[j]).abs()).sum();
                        r.abs() / s
                    })
                    .fold(0.0, f64::max)
            };
            let (r1, r2) = (residual(&b1), residual(&b2));
            worst = worst.max(r1 / r2.max(f64::EPSILON));
        }
        assert!(
            worst < 16.0,
            "unpivoted residual up to {worst} times the pivoted one"
        );
    }

    #[test]
    fn dense_solve_matches_known_solution() {
        let mut m = [[2.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 4.0]];
        let x = [1.0, -2.0, 0.5];
        let mut b = [0.0; 3];
        for i in 0..3 {
            b[i] = (0..3).map(|j| m[i][j] * x[j]).sum();
        }
        assert!(solve_fixed(&mut m, &mut b));
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-15);
        }
    }
}
