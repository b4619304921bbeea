//! The response from rest of one oscillator to a polynomial force, as a power series.
//!
//! A cluster driven by a polynomial force per unit mass `φ(τ) = Σ_k a_k τᵏ` (τ = t − t₀) moves,
//! on top of its harmonic and homogeneous parts, by the response from rest
//!
//! ```text
//! r'' + 2α r' + ω_n² r = φ(τ),      r(0) = r'(0) = 0.
//! ```
//!
//! It equals `p(t) + h_p(τ)` with `p` the polynomial particular solution and `h_p` the
//! homogeneous solution that cancels `p`'s initial values, but that sum cancels badly on a
//! short flow: a force term `a_j τʲ` puts terms up to `j!/ω_nʲ · a_j/ω_n²` into `p(t₀)`, while
//! `r` itself is of order `a_j τʲ⁺²/((j+1)(j+2))`, so the sum loses `j!/(ω_n τ)ʲ⁺²` of its
//! digits. Its Taylor series about t₀, from the recurrence
//!
//! ```text
//! (k+2)(k+1) r_{k+2} = a_k − 2α (k+1) r_{k+1} − ω_n² r_k,      r₀ = r₁ = 0,
//! ```
//!
//! has no such cancellation while `Λτ` (Λ = 2α + ω_n) is a few units; the oscillator uses it up
//! to [`SERIES_REACH`] and the closed form beyond, where the amplification `j!/(ω_n τ)ʲ` of a
//! force of degree ≤ 12 is at most about one.
//!
//! The series is summed in scaled terms `s_k = r_k τᵏ` until a bound of its tail falls below
//! the rounding of its terms: once the force's coefficients are used up the recurrence is
//! homogeneous, `|s_{j+2}| ≤ c_j max(|s_{j+1}|, |s_j|)` with `c_j = 2α|τ|/(j+2) +
//! ω_n²τ²/((j+2)(j+1))` falling in j, so with `c = c_j < 1` the tail after `s_{j+1}` is below
//! `2c/(1 − c)` times the larger of the last two terms (and that of `Σ k s_k` below
//! `2c((j+4)/(1 − c) + 2c/(1 − c)²)` times it).

use super::oscillator::Oscillator;
use super::poly::{INV, Poly, RECIPROCALS};

/// Largest `Λ|τ|` (Λ = 2α + ω_n, 1/s) at which the response is summed as a series (module
/// docs): there its terms grow to at most about `e^6/√(12π) ≈ 65` times the sum's scale.
pub(crate) const SERIES_REACH: f64 = 6.0;

/// Most terms of the series (never reached within [`SERIES_REACH`]: about 40 suffice).
const MAX_TERMS: usize = RECIPROCALS - 3;

/// The response from rest at one time (module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Response {
    /// r, m.
    pub r: f64,
    /// r', m/s.
    pub rd: f64,
    /// Sum of the magnitudes of the terms `r` is summed from, m (for rounding estimates).
    pub mag: f64,
    /// The same for `r'`, m/s.
    pub mag_d: f64,
}

/// The response from rest at `tau` to the force per unit mass `force` (about the flow's start,
/// m/s²), for the constants α, 1/s, and ω_n², 1/s², by its Taylor series (module docs). Valid
/// for `Λ|τ| ≤` [`SERIES_REACH`] (beyond it the sum is still right but loses digits).
pub(crate) fn series(force: &Poly, alpha: f64, wn2: f64, tau: f64) -> Response {
    if tau == 0.0 || force.is_zero() {
        return Response::default();
    }
    let a = &force.c[..force.len];
    let xa = 2.0 * alpha * tau;
    let xw2 = wn2 * tau * tau;
    let (mut s_prev, mut s) = (0.0, 0.0);
    let mut tau_pow = tau * tau;
    let (mut sum, mut dsum, mut mag, mut dmag) = (0.0, 0.0, 0.0, 0.0);
    let rel = 0.25 * f64::EPSILON;
    for k in 0..MAX_TERMS {
        // s_{k+2} from s_{k+1} = s and s_k = s_prev.
        let mut num = -(xa * (k + 1) as f64 * s + xw2 * s_prev);
        if k < a.len() {
            num += a[k] * tau_pow;
            tau_pow *= tau;
        }
        let next = num * (INV[k + 2] * INV[k + 1]);
        let weight = (k + 2) as f64;
        sum += next;
        dsum += weight * next;
        mag += next.abs();
        dmag += weight * next.abs();
        s_prev = s;
        s = next;
        if k + 1 >= a.len() {
            // From s_{k+3} on the recurrence is homogeneous (module docs), j = k + 1: the tail
            // tests `2c/(1 − c)·m ≤ rel·mag` and its derivative's, multiplied out.
            let c = (xa.abs() + xw2 * INV[k + 2]) * INV[k + 3];
            if c < 0.5 {
                let one_c = 1.0 - c;
                let m2c = 2.0 * c * s.abs().max(s_prev.abs());
                if m2c <= rel * mag * one_c
                    && m2c * ((k + 4) as f64 * one_c + 2.0 * c) <= rel * dmag * one_c * one_c
                {
                    break;
                }
            }
        }
    }
    Response {
        r: sum,
        rd: dsum / tau,
        mag,
        mag_d: dmag / tau.abs(),
    }
}

/// The polynomial force's part of an oscillator's flow.
impl Oscillator {
    /// Whether a polynomial external force drives this flow.
    #[inline]
    pub(crate) fn is_driven(&self) -> bool {
        !self.force.is_zero()
    }

    /// The response from rest to the polynomial force at time `t` (zero without one): its
    /// power series while `(2α + ω_n)|t − t0|` ≤ [`SERIES_REACH`], beyond that the particular
    /// polynomial plus the homogeneous solution that cancels its initial values, well
    /// conditioned there (see [`super::response`]).
    #[inline]
    pub(crate) fn response(&self, t: f64) -> Response {
        if self.force.is_zero() {
            return Response::default();
        }
        let tau = t - self.t0;
        if (2.0 * self.alpha + self.wn2.sqrt()) * tau.abs() <= SERIES_REACH {
            return series(&self.force, self.alpha, self.wn2, tau);
        }
        let p = self.force.particular(1.0, 2.0 * self.alpha, self.wn2);
        let (p0, p1) = (p.c[0], p.c[1]);
        let (pv, pd) = p.value_and_rate(t);
        let (c, s) = self.propagator(tau);
        let (hc, hs) = (p0 * c, (p1 + self.alpha * p0) * s);
        let (dc, ds) = (p1 * c, (self.wn2 * p0 + self.alpha * p1) * s);
        Response {
            r: pv - (hc + hs),
            rd: pd - (dc - ds),
            mag: p.magnitude_at(t) + hc.abs() + hs.abs(),
            mag_d: p.derivative().magnitude_at(t) + dc.abs() + ds.abs(),
        }
    }

    /// The force per unit mass about `t`, its coefficients `φ⁽ᵏ⁾(t)/k!`, m/s² per sᵏ (zero
    /// without a force).
    #[inline]
    pub(crate) fn force_taylor(&self, t: f64) -> Poly {
        if self.force.is_zero() {
            Poly::ZERO
        } else {
            self.force.shifted(t)
        }
    }

    /// The free motion `u = h + r` at time `t`: the homogeneous part plus the response from
    /// rest to the polynomial force (which solves `u'' + 2αu' + ω_n²u = f/M`), as
    /// `(u, u', magnitude of u's terms, magnitude of u''s terms)`. Without a force it is
    /// [`homogeneous_with_magnitude`](Self::homogeneous_with_magnitude).
    #[inline]
    pub(crate) fn free_with_magnitude(&self, t: f64) -> (f64, f64, f64, f64) {
        let free = self.homogeneous_with_magnitude(t);
        if self.force.is_zero() {
            return free;
        }
        let r = self.response(t);
        (free.0 + r.r, free.1 + r.rd, free.2 + r.mag, free.3 + r.mag_d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::oscillator::{Forcing, OscConstants};

    /// The series against the closed form `p + h_p` where the closed form is well conditioned
    /// (a long flow), and against the exact response to a constant force, for every damping
    /// regime.
    #[test]
    fn series_matches_closed_forms() {
        // Constant force a on an undamped oscillator: r = a(1 − cos ω τ)/ω².
        let (w, a) = (40.0f64, 3.0);
        let f = Poly::new(0.0, &[a]);
        for tau in [1e-6, 1e-3, 0.05, 0.1, 0.15] {
            let r = series(&f, 0.0, w * w, tau);
            let exact = a * (1.0 - (w * tau).cos()) / (w * w);
            let exact_d = a * (w * tau).sin() / w;
            // 1 − cos loses digits near 0: compare with the stable 2 sin²(x/2).
            let stable = 2.0 * a * ((0.5 * w * tau).sin()).powi(2) / (w * w);
            // Within a few ulps of the size of the terms summed, which is the value itself
            // on short flows (all terms of one sign until ωτ ~ 1).
            assert!(
                (r.r - stable).abs() <= 8.0 * f64::EPSILON * r.mag,
                "{tau}: {} vs {stable} ({exact})",
                r.r
            );
            assert!((r.rd - exact_d).abs() <= 8.0 * f64::EPSILON * r.mag_d, "{tau}");
            if w * tau < 1.0 {
                assert!((r.r - stable).abs() <= 4.0 * f64::EPSILON * stable, "{tau}");
                assert!((r.rd - exact_d).abs() <= 4.0 * f64::EPSILON * exact_d, "{tau}");
            }
        }
        // A ramp on a damped oscillator: r = a(τ − 2α/ω²) /ω² + e^{−ατ}(…), checked through
        // the ODE residual of the series with finite differences of r'.
        let f = Poly::new(0.0, &[0.5, -20.0, 300.0, 1e3, -4e4, 1e5, 2e6]);
        for (alpha, wn2) in [(0.0, 1600.0), (0.3, 1600.0), (40.0, 1600.0), (60.0, 1600.0)] {
            let lam = 2.0 * alpha + f64::sqrt(wn2);
            for x in [0.01, 0.3, 1.0, 3.0, SERIES_REACH] {
                let tau = x / lam;
                let h = 1e-4 * tau;
                let at = |t: f64| series(&f, alpha, wn2, t);
                let (rm, r0, rp) = (at(tau - h), at(tau), at(tau + h));
                let acc = (rp.rd - rm.rd) / (2.0 * h);
                let residual = acc + 2.0 * alpha * r0.rd + wn2 * r0.r - f.value(tau);
                let scale = f.magnitude_at(tau);
                assert!(
                    residual.abs() <= 1e-6 * scale,
                    "α {alpha}, x {x}: residual {residual:e} of {scale:e}"
                );
                let vel = (rp.r - rm.r) / (2.0 * h);
                assert!((vel - r0.rd).abs() <= 1e-7 * r0.mag_d, "α {alpha}, x {x}");
            }
        }
    }

    /// The response to a polynomial force is summed as a series up to `Λτ = SERIES_REACH`
    /// and from the particular polynomial beyond: the two formulas agree at the switch, in
    /// every damping regime, and on a short flow the series keeps its digits where the
    /// particular polynomial's would cancel (the response of a constant force is
    /// `2a sin²(ωτ/2)/ω²` undamped).
    #[test]
    fn the_response_is_continuous_where_its_formula_changes() {
        let forcing = Forcing::new(0.05, 30.0);
        let f = Poly::new(0.0, &[0.3, -2.0, 5.0, 40.0, -100.0, 300.0, 900.0]);
        for c in [0.0, 0.3, 2.0 * (0.1f64 * 100.0).sqrt(), 20.0] {
            let k = OscConstants {
                mass: 0.1,
                damping: c,
                stiffness: 100.0,
                force: 0.0,
                poly: f,
            };
            let osc = Oscillator::new(k, &forcing, 0.0, 0.0, 0.0).unwrap();
            let lam = 2.0 * osc.alpha + osc.wn2.sqrt();
            let tau = SERIES_REACH / lam;
            let series = series(&osc.force, osc.alpha, osc.wn2, tau);
            let closed = osc.response(tau.next_up());
            assert!(
                (series.r - closed.r).abs() <= 1e-12 * series.mag.max(closed.mag),
                "c = {c}: {} vs {}",
                series.r,
                closed.r
            );
            assert!(
                (series.rd - closed.rd).abs() <= 1e-12 * series.mag_d.max(closed.mag_d),
                "c = {c}"
            );
        }
        let k = OscConstants {
            mass: 0.1,
            damping: 0.0,
            stiffness: 100.0,
            force: 0.0,
            poly: Poly::new(0.0, &[0.7]),
        };
        let osc = Oscillator::new(k, &forcing, 0.0, 0.0, 0.0).unwrap();
        let w = (100.0f64 / 0.1).sqrt();
        for tau in [1e-7, 1e-4, 1e-2] {
            let exact = 2.0 * 7.0 * (0.5 * w * tau).sin().powi(2) / (w * w);
            let r = osc.response(tau);
            assert!(
                (r.r - exact).abs() <= 4.0 * f64::EPSILON * exact,
                "τ = {tau}: {} vs {exact}",
                r.r
            );
        }
    }
}
