//! Event functions as explicit functions of time, with derivatives and rigorous bounds.
//!
//! Every event function of the chain (a gap `d_k(t)`, a contact force `N_j(t)`) is, between
//! events, a linear combination of
//!
//! - a constant,
//! - one harmonic `f_c cos ωt + f_s sin ωt` at the excitation frequency,
//! - homogeneous parts `a h(t) + b h'(t)` of at most two oscillators,
//! - with external force polynomials (see [`super::forces`]), a polynomial in time.
//!
//! [`Signal::jet`] returns the value and first four derivatives at a time, and bounds
//! `B_n ≥ sup_{t ≤ s ≤ H} |f^{(n)}(s)|`, n = 2..5, up to the horizon H of the search (for all
//! the future of the current flow when there is no polynomial part; `B₅` is infinite when
//! there is one).
//! The bounds come from an energy argument: any solution `g` of `g'' + 2αg' + ω_n² g = 0` with
//! α ≥ 0 has non-increasing `E = g'² + ω_n² g²`, and every derivative of `g` is again such a
//! solution, so `|g^{(n)}(s)| ≤ √(g^{(n)}(t)² + g^{(n+1)}(t)²/ω_n²)` for all s ≥ t. The
//! harmonic part contributes `R ωⁿ` with R its amplitude. A polynomial part with Taylor
//! coefficients `b_k = P⁽ᵏ⁾(t)/k!` about t contributes, by the triangle inequality on its own
//! (finite) Taylor expansion, `Σ_{k≥n} |b_k| k!/(k−n)! (H − t)^{k−n}` on `[t, H]`. These
//! bounds make the root search of [`super::roots`] certified: it can never step over a zero.

use super::observer::ClusterFlow;
use super::oscillator::{Oscillator, Phase};
use super::poly::{Poly, falling};

/// `a·h + b·h'` of the oscillator with index `osc`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Term {
    pub osc: usize,
    pub a: f64,
    pub b: f64,
}

/// An explicit event function of time (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Signal {
    pub constant: f64,
    /// Magnitude of the pieces that were summed into `constant` (for rounding noise).
    pub constant_mag: f64,
    pub fc: f64,
    pub fs: f64,
    /// Sum of the amplitudes of the harmonic pieces (for rounding noise).
    pub forced_mag: f64,
    pub terms: [Term; 2],
    pub nterms: usize,
    /// Polynomial part (external forces; zero if none).
    pub poly: Poly,
}

/// Value, derivatives and bounds of a [`Signal`] at one time.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Jet {
    /// f, f', f'', f'''.
    pub d: [f64; 4],
    /// `bound[n] ≥ sup_{s≥t} |f^{(n)}(s)|` for n = 2..=4, the orders the search's lower bounds
    /// use (`bound[0]` and `bound[1]` are not computed: zero).
    pub bound: [f64; 5],
    /// Rounding noise of `d[n]`: values below it in magnitude are indistinguishable from 0.
    pub noise: [f64; 4],
    /// f⁗, for the quartic model that places a zero just ahead (`roots::root_within_model`).
    pub d4: f64,
    /// `≥ sup_{s≥t} |f⁽⁵⁾(s)|`; infinite (no such model) for signals with a polynomial part.
    pub bound5: f64,
}

/// Relative rounding allowance used for noise estimates.
const NOISE: f64 = 32.0 * f64::EPSILON;

impl Signal {
    /// Adds `coef × (oscillator's forced part + mean)` and `coef × homogeneous part`.
    pub fn add_oscillator(&mut self, osc_index: usize, osc: &Oscillator, a: f64, b: f64, omega: f64) {
        // a·s + b·s' with s = mean + pc cos + ps sin + h.
        self.add_constant(a * osc.mean);
        // s' forced = ω(ps cos − pc sin).
        self.add_harmonic(a * osc.pc + b * omega * osc.ps, a * osc.ps - b * omega * osc.pc);
        // The homogeneous part and a polynomial force's response from rest are evaluated
        // through the oscillator at each time (see `jet`).
        self.terms[self.nterms] = Term { osc: osc_index, a, b };
        self.nterms += 1;
    }

    /// Adds `a × q(t)` for a polynomial `q`.
    pub fn add_polynomial(&mut self, q: &Poly, a: f64) {
        self.poly.add_scaled(q, a);
    }

    /// The function with the opposite sign (same rounding noise).
    pub fn negated(&self) -> Signal {
        let mut s = *self;
        s.constant = -s.constant;
        s.fc = -s.fc;
        s.fs = -s.fs;
        for term in &mut s.terms[..s.nterms] {
            term.a = -term.a;
            term.b = -term.b;
        }
        for c in &mut s.poly.c {
            *c = -*c;
        }
        s
    }

    /// Adds a constant.
    pub fn add_constant(&mut self, c: f64) {
        self.constant += c;
        self.constant_mag += c.abs();
    }

    /// Adds `c cos ωt + s sin ωt`.
    pub fn add_harmonic(&mut self, c: f64, s: f64) {
        self.fc += c;
        self.fs += s;
        // √(c² + s²) rather than `hypot`, which guards against overflow at magnitudes no
        // motion here reaches and costs several times more; the amplitude is an allowance.
        self.forced_mag += (c * c + s * s).sqrt();
    }

    /// Amplitude of the harmonic part, `√(f_c² + f_s²)` (the same at every time: computed
    /// once per search and passed to [`jet`](Self::jet)).
    pub fn harmonic_amplitude(&self) -> f64 {
        // Within an ulp of `hypot` (no overflow at these magnitudes); the bounds it enters
        // carry a relative safety margin of 1e-9.
        (self.fc * self.fc + self.fs * self.fs).sqrt()
    }

    /// Value, derivatives and bounds at time `t` (phase `ph` of `t`), the bounds valid up to
    /// the horizon `horizon` ≥ t, s, of the search; `amp` is
    /// [`harmonic_amplitude`](Self::harmonic_amplitude).
    #[inline]
    pub fn jet(
        &self,
        t: f64,
        ph: Phase,
        clusters: &[ClusterFlow],
        omega: f64,
        horizon: f64,
        amp: f64,
    ) -> Jet {
        let f0 = self.fc * ph.cos + self.fs * ph.sin;
        let f1 = omega * (self.fs * ph.cos - self.fc * ph.sin);
        let w2 = omega * omega;
        let mut d = [self.constant + f0, f1, -w2 * f0, -w2 * f1];
        let mut d4 = w2 * w2 * f0;
        let mut bound = [0.0; 5];
        let mut mag = [
            self.constant_mag + self.forced_mag,
            self.forced_mag * omega,
            self.forced_mag * w2,
            self.forced_mag * w2 * omega,
        ];
        let mut wn = omega;
        for b in bound.iter_mut().skip(2) {
            wn *= omega;
            *b = amp * wn;
        }
        let mut bound5 = amp * wn * omega;
        for term in &self.terms[..self.nterms] {
            let osc = &clusters[term.osc].oscillator;
            if osc.is_driven() {
                add_driven_term(term, osc, t, horizon, &mut d, &mut bound, &mut mag);
                bound5 = f64::INFINITY;
                continue;
            }
            let (h, h1, mag_h, mag_h1) = osc.homogeneous_with_magnitude(t);
            let two_a = 2.0 * osc.alpha;
            let wn2 = osc.wn2;
            // g = a h + b h' solves the homogeneous ODE; g_{n+2} = −2α g_{n+1} − ω_n² g_n.
            let h2 = -two_a * h1 - wn2 * h;
            let mut g = [0.0; 7];
            g[0] = term.a * h + term.b * h1;
            g[1] = term.a * h1 + term.b * h2;
            for n in 2..7 {
                g[n] = -two_a * g[n - 1] - wn2 * g[n - 2];
            }
            let inv_wn2 = 1.0 / wn2;
            // Magnitudes of what is summed, carried through the same recursion.
            let (aa, bb) = (term.a.abs(), term.b.abs());
            let mut m = [0.0; 4];
            m[0] = aa * mag_h + bb * mag_h1;
            m[1] = aa * mag_h1 + bb * (two_a * mag_h1 + wn2 * mag_h);
            for n in 2..4 {
                m[n] = two_a * m[n - 1] + wn2 * m[n - 2];
            }
            for n in 0..4 {
                d[n] += g[n];
                mag[n] += m[n];
            }
            let energy_bound = |n: usize| {
                let up = (g[n] * g[n] + g[n + 1] * g[n + 1] * inv_wn2).sqrt();
                let down = (g[n] * g[n] + wn2 * g[n - 1] * g[n - 1]).sqrt();
                up.min(down)
            };
            for (n, b) in bound.iter_mut().enumerate().skip(2) {
                *b += energy_bound(n);
            }
            d4 += g[4];
            bound5 += energy_bound(5);
        }
        if !self.poly.is_zero() {
            self.add_poly_jet(t, horizon, &mut d, &mut bound, &mut mag);
            bound5 = f64::INFINITY;
        }
        Jet {
            d,
            bound,
            noise: mag.map(|m| NOISE * m),
            d4,
            bound5,
        }
    }

    /// The polynomial part's derivatives at `t`, their rounding sizes, and the bounds of its
    /// derivatives on `[t, horizon]` (module docs).
    #[cold]
    fn add_poly_jet(&self, t: f64, horizon: f64, d: &mut [f64; 4], bound: &mut [f64; 5], mag: &mut [f64; 4]) {
        let len = self.poly.len;
        let (b, babs) = self.poly.taylor_at(t);
        let span = (horizon - t).max(0.0);
        for n in 0..4 {
            if n < len {
                let f = falling(n, n);
                d[n] += f * b[n];
                mag[n] += f * babs[n];
            }
        }
        for (n, bn) in bound.iter_mut().enumerate().skip(2) {
            // Σ_{k≥n} |b_k| k!/(k−n)! span^{k−n}, by Horner in span.
            let mut acc = 0.0;
            for k in (n..len).rev() {
                acc = acc * span + falling(k, n) * b[k].abs();
            }
            *bn += acc;
        }
    }
}

/// `a·u + b·u'` of a term whose oscillator is driven by a polynomial force per unit mass φ:
/// `u = h + r` (homogeneous part plus the response from rest) obeys
/// `u'' + 2αu' + ω_n²u = φ`, so `G = a·u + b·u'` obeys the same equation with the forcing
/// `F = aφ + bφ'`, and so does each derivative `G⁽ⁿ⁾` with `F⁽ⁿ⁾`. The derivatives at `t` follow
/// from that recurrence. The bounds on `[t, H]` extend the energy argument of the module docs:
/// for `g'' + 2αg' + ω_n²g = F` with α ≥ 0, `E = g'² + ω_n²g²` has `d√E/ds ≤ |F|`, so
/// `√E(s) ≤ √E(t) + ∫_t^s |F|`, and `∫_t^H |F⁽ⁿ⁾| ≤ (H − t)·Σ_{k≥n} |F_k| k!/(k−n)! (H − t)^{k−n}`
/// with `F_k` the Taylor coefficients of F about t.
#[cold]
fn add_driven_term(
    term: &Term,
    osc: &Oscillator,
    t: f64,
    horizon: f64,
    d: &mut [f64; 4],
    bound: &mut [f64; 5],
    mag: &mut [f64; 4],
) {
    let (u, u1, mag_u, mag_u1) = osc.free_with_magnitude(t);
    let phi = osc.force_taylor(t);
    let len = phi.len;
    let (a, b) = (term.a, term.b);
    // F's Taylor coefficients about t: F_k = a φ_k + b (k+1) φ_{k+1}, and their sizes.
    let mut fk = [0.0; super::poly::TERMS];
    let mut fk_abs = [0.0; super::poly::TERMS];
    for k in 0..len {
        let next = if k + 1 < len {
            (k + 1) as f64 * phi.c[k + 1]
        } else {
            0.0
        };
        fk[k] = a * phi.c[k] + b * next;
        fk_abs[k] = (a * phi.c[k]).abs() + (b * next).abs();
    }
    // F⁽ⁿ⁾(t) = n! F_n.
    const FACTORIAL: [f64; 4] = [1.0, 1.0, 2.0, 6.0];
    let f_at = |n: usize| if n < len { FACTORIAL[n] * fk[n] } else { 0.0 };
    let f_mag = |n: usize| if n < len { FACTORIAL[n] * fk_abs[n] } else { 0.0 };
    let two_a = 2.0 * osc.alpha;
    let wn2 = osc.wn2;
    // φ(t) (c[0] of the shifted force; 0 for none).
    let phi0 = phi.c[0];
    let u2 = phi0 - two_a * u1 - wn2 * u;
    let mut g = [0.0; 6];
    g[0] = a * u + b * u1;
    g[1] = a * u1 + b * u2;
    for n in 2..6 {
        g[n] = -two_a * g[n - 1] - wn2 * g[n - 2] + f_at(n - 2);
    }
    let (aa, bb) = (a.abs(), b.abs());
    let mut m = [0.0; 4];
    m[0] = aa * mag_u + bb * mag_u1;
    m[1] = aa * mag_u1 + bb * (two_a * mag_u1 + wn2 * mag_u + phi0.abs());
    for n in 2..4 {
        m[n] = two_a * m[n - 1] + wn2 * m[n - 2] + f_mag(n - 2);
    }
    for n in 0..4 {
        d[n] += g[n];
        mag[n] += m[n];
    }
    // ∫_t^H |F⁽ⁿ⁾| for n = 0..=4: Horner in span over the coefficients of the n-th derivative
    // of Σ|F_k|xᵏ, each derived from the last.
    let span = (horizon - t).max(0.0);
    let mut integral = [0.0; 5];
    let mut deriv = fk.map(f64::abs);
    for (n, slot) in integral.iter_mut().enumerate() {
        if n >= len {
            break;
        }
        let terms = &deriv[..len - n];
        *slot = span * terms.iter().rev().fold(0.0, |acc, &c| acc * span + c);
        for k in 0..len - n - 1 {
            deriv[k] = (k + 1) as f64 * deriv[k + 1];
        }
    }
    let inv_wn = 1.0 / wn2.sqrt();
    for n in 2..5 {
        let up = (g[n] * g[n] + g[n + 1] * g[n + 1] / wn2).sqrt() + integral[n] * inv_wn;
        let down = (g[n] * g[n] + wn2 * g[n - 1] * g[n - 1]).sqrt() + integral[n - 1];
        bound[n] += up.min(down);
    }
}
