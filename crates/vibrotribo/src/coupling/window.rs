//! The charge over one window as a polynomial, and the electrostatic forces it implies.
//!
//! The charge is sampled at the `n + 1` Chebyshev–Lobatto points of the window
//! `[t₀, t₀ + h]` (both ends included) and represented by its interpolant of degree `n`
//! ([`DEGREE`]). Its Chebyshev coefficients give the error estimate
//! ([`ChargePolynomial::error_estimate`]) and, through the monomial basis in
//! `τ = t − t₀`, the force polynomials the engine integrates in closed form; with them the rules
//! a window's length and its forces follow (length from an error estimate, rounding
//! amplified by a force polynomial, its impulse and first moment).

/// Degree of the charge polynomial on a window.
pub(crate) const DEGREE: usize = 6;

/// Number of sample points of a window.
pub(crate) const NODES: usize = DEGREE + 1;

/// Degree of a gap force polynomial (quadratic in the charge).
pub(crate) const FORCE_DEGREE: usize = 2 * DEGREE;

/// The sample times of a window `[t0, t0 + h]` in increasing order (the first is `t0`, the
/// last `t0 + h`), s.
pub(crate) fn nodes(t0: f64, h: f64) -> [f64; NODES] {
    let mut t = [0.0; NODES];
    for (j, tj) in t.iter_mut().enumerate() {
        *tj = if j == 0 {
            t0
        } else if j == DEGREE {
            t0 + h
        } else {
            t0 + 0.5 * h * (1.0 - (std::f64::consts::PI * j as f64 / DEGREE as f64).cos())
        };
    }
    t
}

/// The interpolant of values at the [`nodes`] of a window of length `h`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChargePolynomial {
    /// Length of the window, s.
    pub h: f64,
    /// Chebyshev coefficients in `s = 2τ/h − 1` (`f = Σ a_k T_k(s)`, no halving), C.
    cheb: [f64; NODES],
    /// Monomial coefficients in `τ = t − t₀`, C/sʲ.
    pub mono: [f64; NODES],
    /// Error estimate of the untruncated interpolant plus the coefficients dropped by
    /// [`truncated`](Self::truncated), C (0 if not truncated).
    dropped: f64,
}

impl ChargePolynomial {
    /// The interpolant of `values` (C) at the nodes of a window of length `h` (s).
    pub fn new(values: &[f64; NODES], h: f64) -> Self {
        let n = DEGREE;
        // The nodes are s_j = −cos(πj/n) = cos(π(n − j)/n): with i = n − j, the standard
        // Chebyshev–Lobatto points x_i = cos(πi/n) carry f_i = values[n − i].
        let mut cheb = [0.0; NODES];
        for (k, ck) in cheb.iter_mut().enumerate() {
            let mut sum = 0.0;
            for i in 0..=n {
                let w = if i == 0 || i == n { 0.5 } else { 1.0 };
                sum += w * values[n - i] * (std::f64::consts::PI * (i * k) as f64 / n as f64).cos();
            }
            *ck = 2.0 * sum / n as f64;
        }
        cheb[0] *= 0.5;
        cheb[n] *= 0.5;
        Self::from_chebyshev(cheb, h, 0.0)
    }

    /// The same polynomial cut to degree `degree` (its Chebyshev series truncated, a near-best
    /// approximation); the dropped coefficients join the error estimate.
    pub fn truncated(&self, degree: usize) -> Self {
        if degree >= DEGREE {
            return *self;
        }
        let mut cheb = self.cheb;
        let dropped: f64 = cheb[degree + 1..].iter().map(|c| c.abs()).sum();
        for c in &mut cheb[degree + 1..] {
            *c = 0.0;
        }
        Self::from_chebyshev(cheb, self.h, self.error_estimate() + dropped)
    }

    fn from_chebyshev(cheb: [f64; NODES], h: f64, dropped: f64) -> Self {
        // Monomials in s by the recurrence T_{k+1} = 2s T_k − T_{k−1}.
        let mut in_s = [0.0; NODES];
        let (mut tm, mut tk) = ([0.0; NODES], [0.0; NODES]);
        tm[0] = 1.0; // T_0
        tk[1] = 1.0; // T_1
        for (k, &ck) in cheb.iter().enumerate() {
            let tcur = if k == 0 { tm } else { tk };
            for j in 0..NODES {
                in_s[j] += ck * tcur[j];
            }
            if k >= 1 {
                let mut next = [0.0; NODES];
                for j in 0..NODES - 1 {
                    next[j + 1] += 2.0 * tk[j];
                }
                for j in 0..NODES {
                    next[j] -= tm[j];
                }
                tm = tk;
                tk = next;
            }
        }
        // s = 2τ/h − 1: Σ b_k (aτ − 1)^k with a = 2/h, expanded binomially.
        let a = 2.0 / h;
        let mut mono = [0.0; NODES];
        for (k, &bk) in in_s.iter().enumerate() {
            let mut binom = 1.0;
            for (j, mj) in mono.iter_mut().enumerate().take(k + 1) {
                // C(k, j) a^j (−1)^(k−j)
                let sign = if (k - j) % 2 == 0 { 1.0 } else { -1.0 };
                *mj += bk * binom * a.powi(j as i32) * sign;
                binom = binom * (k - j) as f64 / (j + 1) as f64;
            }
        }
        ChargePolynomial {
            h,
            cheb,
            mono,
            dropped,
        }
    }

    /// A constant charge `q` (C) on a window of length `h` (s).
    pub fn constant(q: f64, h: f64) -> Self {
        let mut cheb = [0.0; NODES];
        cheb[0] = q;
        let mut mono = [0.0; NODES];
        mono[0] = q;
        ChargePolynomial {
            h,
            cheb,
            mono,
            dropped: 0.0,
        }
    }

    /// The estimated interpolation error, C: twice the last two Chebyshev coefficients, each
    /// times the decay per degree seen from two degrees below (the square root of their ratio,
    /// at most 1; two degrees, so that a function of one parity, whose every other
    /// coefficient vanishes, is still judged by its own decay). For a function that is not
    /// resolved the coefficients do not decay and the estimate is the last ones' size.
    pub fn error_estimate(&self) -> f64 {
        if self.dropped > 0.0 {
            return self.dropped;
        }
        let tail = |k: usize| {
            let (a, b) = (self.cheb[k].abs(), self.cheb[k - 2].abs());
            if a == 0.0 {
                0.0
            } else {
                a * (a / b).sqrt().min(1.0)
            }
        };
        2.0 * tail(DEGREE).max(tail(DEGREE - 1))
    }

    /// The charge at `τ = t − t₀`, s, C.
    pub fn at(&self, tau: f64) -> f64 {
        self.mono.iter().rev().fold(0.0, |acc, &c| acc * tau + c)
    }

    /// Its values at the nodes of a window of length `h` starting `shift` (s) after this one's
    /// start (a prediction by extrapolation when the new window starts at this one's end).
    pub fn values_at_nodes(&self, shift: f64, h: f64) -> [f64; NODES] {
        let t = nodes(shift, h);
        t.map(|tau| self.at(tau))
    }
}

/// The force polynomial `c₀ + c₁Q(τ) + c₂Q(τ)²` (N, coefficients in τ = t − t₀, N/sʲ) of a gap
/// force quadratic in the charge.
pub(crate) fn force_polynomial(q: &ChargePolynomial, c: [f64; 3]) -> [f64; FORCE_DEGREE + 1] {
    let mut f = [0.0; FORCE_DEGREE + 1];
    for (i, &qi) in q.mono.iter().enumerate() {
        f[i] += c[1] * qi;
        for (j, &qj) in q.mono.iter().enumerate() {
            f[i + j] += c[2] * qi * qj;
        }
    }
    f[0] += c[0];
    f
}

/// Drops the highest terms of a force polynomial (N/sʲ) whose combined effect on a window of
/// length `h` (s) is below `negligible` newtons (`Σ |f_j| h^j`), returning the degree kept.
pub(crate) fn significant_degree(f: &[f64], h: f64, negligible: f64) -> usize {
    let mut dropped = 0.0;
    let mut degree = f.len() - 1;
    while degree > 0 {
        let term = f[degree].abs() * h.powi(degree as i32);
        if dropped + term > negligible {
            break;
        }
        dropped += term;
        degree -= 1;
    }
    degree
}

/// The factor by which a window's length can change for its error `estimate` (C) to meet
/// `tol` (C) if the estimate goes as the length to the power `order` (callers apply a safety
/// factor of 0.8); infinite for a zero estimate.
pub(crate) fn length_ratio(tol: f64, estimate: f64, order: f64) -> f64 {
    if estimate > 0.0 {
        (tol / estimate).powf(1.0 / order)
    } else {
        f64::INFINITY
    }
}

/// How far the engine may amplify the rounding of the force polynomial `f(τ) = Σ f_j τʲ` (N,
/// N/sʲ) on a window of length `h`, s, in N: Σ_{j≥1} |f_j| hʲ · max(j!/xʲ, 1) with
/// x = max(ω_n h, `series_x`). Where the engine sums a term's response from its particular
/// polynomial (from ω_n τ ≥ `series_x` on; a power series before), that polynomial carries
/// terms up to j!/(ω_n τ)ʲ times the term's static effect, which the homogeneous part then
/// cancels (see `CoupledChain::fit`).
pub(crate) fn amplified_rounding(f: &[f64], h: f64, omega_n: f64, series_x: f64) -> f64 {
    let x = (omega_n * h).max(series_x);
    let mut amplified = 0.0;
    let mut factorial = 1.0;
    for (j, fj) in f.iter().enumerate().skip(1) {
        factorial *= j as f64;
        let effect = fj.abs() * h.powi(j as i32);
        amplified += effect * (factorial / x.powi(j as i32)).max(1.0);
    }
    amplified
}

/// `[∫₀ʰ f, ∫₀ʰ τ f]` of the polynomial `f(τ) = Σ f_j τʲ`.
pub(crate) fn polynomial_moments(f: &[f64], h: f64) -> [f64; 2] {
    let (mut i0, mut i1) = (0.0, 0.0);
    let mut p = h;
    for (j, fj) in f.iter().enumerate() {
        i0 += fj * p / (j + 1) as f64;
        i1 += fj * p * h / (j + 2) as f64;
        p *= h;
    }
    [i0, i1]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A polynomial of the interpolant's degree is reproduced exactly (to rounding), at the
    /// nodes and between them, and its error estimate vanishes.
    #[test]
    fn polynomials_of_the_degree_are_exact() {
        let h = 3.7e-3;
        let p = |tau: f64| 1e-7 * (0.3 - 2.0 * tau / h + 0.7 * (tau / h).powi(3) - 0.2 * (tau / h).powi(6));
        let values = nodes(0.0, h).map(p);
        let q = ChargePolynomial::new(&values, h);
        for k in 0..=20 {
            let tau = h * k as f64 / 20.0;
            assert!(
                (q.at(tau) - p(tau)).abs() < 1e-13 * 1e-7,
                "{tau}: {} vs {}",
                q.at(tau),
                p(tau)
            );
        }
        // A polynomial of degree 4 has no Chebyshev coefficients above 4: the estimate is
        // at rounding level.
        let p4 = |tau: f64| 1e-7 * (0.3 - 2.0 * tau / h + 0.9 * (tau / h).powi(4));
        let q4 = ChargePolynomial::new(&nodes(0.0, h).map(p4), h);
        assert!(q4.error_estimate() < 1e-15 * 1e-7, "{}", q4.error_estimate());
    }

    /// For a smooth function the estimate bounds the true error between the nodes, and the
    /// error falls as h⁷.
    #[test]
    fn the_error_estimate_bounds_the_error_of_a_sine() {
        let w = 2.0 * std::f64::consts::PI / 0.1;
        for h in [0.1 / 4.0, 0.1 / 8.0, 0.1 / 16.0] {
            let f = |tau: f64| (w * (tau + 0.013)).sin();
            let q = ChargePolynomial::new(&nodes(0.0, h).map(f), h);
            let worst = (0..=400)
                .map(|k| {
                    let tau = h * k as f64 / 400.0;
                    (q.at(tau) - f(tau)).abs()
                })
                .fold(0.0, f64::max);
            assert!(
                worst <= q.error_estimate(),
                "h = {h}: error {worst} above estimate {}",
                q.error_estimate()
            );
            assert!(
                q.error_estimate() < 100.0 * worst.max(1e-16),
                "estimate far too pessimistic at h = {h}"
            );
        }
    }

    /// A transient far shorter than the window (the charge right after an impact when R·C is
    /// far below the window) is not resolved pointwise, but what the force's error does to the
    /// masses is its integral: the estimate bounds the mean absolute error over the window
    /// always, and the pointwise error once the transient spans a good part of the window.
    #[test]
    fn an_unresolved_transient_is_flagged() {
        let h = 1e-3;
        for width in [h / 3.0, h / 10.0, h / 50.0, h / 300.0] {
            let f = |tau: f64| 1e-7 * (1.0 + 0.01 * (-tau / width).exp());
            let q = ChargePolynomial::new(&nodes(0.0, h).map(f), h);
            let errors: Vec<f64> = (0..=20000)
                .map(|k| {
                    let tau = h * k as f64 / 20000.0;
                    (q.at(tau) - f(tau)).abs()
                })
                .collect();
            let mean = errors.iter().sum::<f64>() / errors.len() as f64;
            let worst = errors.iter().copied().fold(0.0, f64::max);
            let est = q.error_estimate();
            assert!(
                mean <= est,
                "width {width}: mean error {mean} above estimate {est}"
            );
            if width >= h / 10.0 {
                assert!(worst <= est, "width {width}: error {worst} above estimate {est}");
            }
        }
    }

    /// The force polynomial is the quadratic of the charge polynomial, pointwise.
    #[test]
    fn force_polynomial_is_the_quadratic_of_the_charge() {
        let h = 1e-3;
        let q = ChargePolynomial::new(&nodes(0.0, h).map(|t| 1e-7 * (1.0 + 300.0 * t).cos()), h);
        let c = [-0.13, 1.7e6, -5.6e12];
        let f = force_polynomial(&q, c);
        for k in 0..=10 {
            let tau = h * k as f64 / 10.0;
            let qv = q.at(tau);
            let direct = c[0] + c[1] * qv + c[2] * qv * qv;
            let poly = f.iter().rev().fold(0.0, |acc, &x| acc * tau + x);
            assert!((direct - poly).abs() < 1e-12 * direct.abs(), "{direct} vs {poly}");
        }
        assert!(significant_degree(&f, h, 1e-30) >= DEGREE);
        assert_eq!(significant_degree(&f, h, 1.0), 0);
    }
}
