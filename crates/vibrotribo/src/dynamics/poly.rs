//! Polynomials in time of bounded degree, for the external forces on the masses and the
//! particular solutions they drive (see [`super::forces`]).
//!
//! A [`Poly`] is `p(t) = Σ_j c_j (t − t_ref)^j`, j < [`TERMS`], stored inline (no
//! allocation, `Copy`) so that an [`Oscillator`](super::Oscillator) can carry one.

/// Highest degree of an external force polynomial.
pub(crate) const MAX_DEGREE: usize = 12;

/// Coefficients of a polynomial of degree [`MAX_DEGREE`].
pub(crate) const TERMS: usize = MAX_DEGREE + 1;

/// `p(t) = Σ_j c_j (t − t_ref)^j` (module docs). The unit of `c_j` is that of `p` per `s^j`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Poly {
    /// Reference time t_ref, s.
    pub t_ref: f64,
    /// Coefficients c_j; those from `len` on are zero.
    pub c: [f64; TERMS],
    /// Number of coefficients in use (degree + 1); 0 for the zero polynomial.
    pub len: usize,
}

impl Default for Poly {
    fn default() -> Self {
        Poly::ZERO
    }
}

impl Poly {
    /// The zero polynomial.
    pub const ZERO: Poly = Poly {
        t_ref: 0.0,
        c: [0.0; TERMS],
        len: 0,
    };

    /// `Σ_j coefs[j] (t − t_ref)^j` (`coefs.len() ≤ TERMS`, checked by the caller).
    pub fn new(t_ref: f64, coefs: &[f64]) -> Self {
        let mut p = Poly { t_ref, ..Poly::ZERO };
        p.c[..coefs.len()].copy_from_slice(coefs);
        p.len = coefs.len();
        p.trim();
        p
    }

    /// Whether this is the zero polynomial.
    #[inline]
    pub fn is_zero(&self) -> bool {
        self.len == 0
    }

    /// Drops trailing zero coefficients.
    fn trim(&mut self) {
        while self.len > 0 && self.c[self.len - 1] == 0.0 {
            self.len -= 1;
        }
    }

    /// `p(t)` and `p'(t)` (Horner).
    #[inline]
    pub fn value_and_rate(&self, t: f64) -> (f64, f64) {
        let x = t - self.t_ref;
        let (mut p, mut d) = (0.0, 0.0);
        for &c in self.c[..self.len].iter().rev() {
            d = d * x + p;
            p = p * x + c;
        }
        (p, d)
    }

    /// `p(t)`.
    #[inline]
    pub fn value(&self, t: f64) -> f64 {
        let x = t - self.t_ref;
        self.c[..self.len].iter().rev().fold(0.0, |acc, &c| acc * x + c)
    }

    /// `Σ_j |c_j| |t − t_ref|^j`: the size of the terms `p(t)` is summed from, in the unit of p.
    pub fn magnitude_at(&self, t: f64) -> f64 {
        let x = (t - self.t_ref).abs();
        self.c[..self.len]
            .iter()
            .rev()
            .fold(0.0, |acc, &c| acc * x + c.abs())
    }

    /// The same polynomial about `t_new`: coefficients `p⁽ʲ⁾(t_new)/j!` (Taylor shift by
    /// repeated synthetic division; exact for `t_new == t_ref`).
    pub fn shifted(&self, t_new: f64) -> Poly {
        let d = t_new - self.t_ref;
        let mut p = *self;
        p.t_ref = t_new;
        if d != 0.0 {
            shift(&mut p.c[..p.len], d);
        }
        p
    }

    /// `p'`.
    pub fn derivative(&self) -> Poly {
        let mut p = Poly {
            t_ref: self.t_ref,
            ..Poly::ZERO
        };
        if self.len > 1 {
            for j in 1..self.len {
                p.c[j - 1] = j as f64 * self.c[j];
            }
            p.len = self.len - 1;
        }
        p
    }

    /// `self += a·other`. A zero `self` takes `other`'s reference; otherwise `other` is
    /// shifted to `self`'s if they differ.
    pub fn add_scaled(&mut self, other: &Poly, a: f64) {
        if other.is_zero() || a == 0.0 {
            return;
        }
        if self.is_zero() {
            self.t_ref = other.t_ref;
        }
        let o = if other.t_ref == self.t_ref {
            *other
        } else {
            other.shifted(self.t_ref)
        };
        for j in 0..o.len {
            self.c[j] += a * o.c[j];
        }
        self.len = self.len.max(o.len);
        self.trim();
    }

    /// The polynomial p with `M p'' + C p' + K p = self` (`k > 0`): from the top coefficient
    /// down, `K p_j = f_j − C (j+1) p_{j+1} − M (j+2)(j+1) p_{j+2}`.
    pub fn particular(&self, m: f64, c: f64, k: f64) -> Poly {
        let mut p = Poly {
            t_ref: self.t_ref,
            len: self.len,
            ..Poly::ZERO
        };
        for j in (0..self.len).rev() {
            let mut r = self.c[j];
            if j + 1 < self.len {
                r -= c * (j + 1) as f64 * p.c[j + 1];
            }
            if j + 2 < self.len {
                r -= m * ((j + 2) * (j + 1)) as f64 * p.c[j + 2];
            }
            p.c[j] = r / k;
        }
        p
    }

    /// Taylor coefficients about `t`, `b_k = p⁽ᵏ⁾(t)/k!`, and those of `|p|` (the same
    /// shift of `|c_j|` by `|t − t_ref|`, the size of the terms each is summed from).
    pub fn taylor_at(&self, t: f64) -> ([f64; TERMS], [f64; TERMS]) {
        let d = t - self.t_ref;
        let mut b = self.c;
        let mut a = self.c.map(f64::abs);
        if d != 0.0 {
            shift(&mut b[..self.len], d);
            shift(&mut a[..self.len], d.abs());
        }
        (b, a)
    }
}

/// `c ← coefficients of p(x + d)` in place (repeated synthetic division).
fn shift(c: &mut [f64], d: f64) {
    let n = c.len();
    for i in 0..n.saturating_sub(1) {
        for j in (i..n - 1).rev() {
            c[j] += d * c[j + 1];
        }
    }
}

/// `j!/(j − n)!` for `j ≥ n` (the factor of `x^{j−n}` in the n-th derivative of `x^j`).
#[inline]
pub(crate) fn falling(j: usize, n: usize) -> f64 {
    ((j - n + 1)..=j).fold(1.0, |acc, i| acc * i as f64)
}

/// Most Taylor terms with tabulated reciprocals.
pub(crate) const RECIPROCALS: usize = 64;

/// `1/j` for `j` in `0..RECIPROCALS` (`1/0` unused).
pub(crate) static INV: [f64; RECIPROCALS] = {
    let mut t = [0.0; RECIPROCALS];
    let mut j = 1;
    while j < RECIPROCALS {
        t[j] = 1.0 / j as f64;
        j += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shift_matches_direct_evaluation() {
        let p = Poly::new(0.3, &[1.0, -2.0, 0.5, 3.0, -0.25]);
        let q = p.shifted(1.1);
        for t in [-1.0, 0.0, 0.7, 2.5] {
            let direct = p.value(t);
            assert!((q.value(t) - direct).abs() <= 1e-12 * p.magnitude_at(t), "{t}");
            let (_, r1) = p.value_and_rate(t);
            let (_, r2) = q.value_and_rate(t);
            assert!((r1 - r2).abs() <= 1e-11 * (1.0 + r1.abs()));
        }
        let (b, _) = p.taylor_at(1.1);
        assert_eq!(b, q.c);
    }

    /// `M p'' + C p' + K p = f` checked by finite differences of the evaluated polynomial.
    #[test]
    fn particular_solves_its_ode() {
        let f = Poly::new(2.0, &[0.4, -1.5, 2.0, 0.3, -0.7, 0.05, 0.01]);
        let (m, c, k) = (0.12, 0.3, 140.0);
        let p = f.particular(m, c, k);
        for t in [1.9, 2.0, 2.3] {
            let h = 1e-4;
            let (_, d1) = p.value_and_rate(t);
            let (_, dp) = p.value_and_rate(t + h);
            let (_, dm) = p.value_and_rate(t - h);
            let d2 = (dp - dm) / (2.0 * h);
            let lhs = m * d2 + c * d1 + k * p.value(t);
            assert!(
                (lhs - f.value(t)).abs() < 1e-7 * f.magnitude_at(t),
                "{lhs} vs {}",
                f.value(t)
            );
        }
    }
}
