//! Closed-form flow of one linear oscillator under harmonic base motion.
//!
//! A free mass, or a cluster of masses stuck together (mass M = Σm, damping C = Σc,
//! stiffness K = Σk, and a constant force F₀ from the fixed offsets of its members), obeys
//!
//! ```text
//! M s'' + C s' + K s = F₀ + C y'(t) + K y(t),      y(t) = A sin(ω t)
//! ```
//!
//! with the exact solution `s(t) = s_p(t) + h(t − t₀)`: the steady harmonic part
//! `s_p = F₀/K + P cos ωt + Q sin ωt`, and the homogeneous part written with the
//! damping-regime-independent propagator
//!
//! ```text
//! h(τ)  = e^{−ατ} [ h₀ c(τ) + (h₁ + α h₀) s(τ) ]
//! h'(τ) = e^{−ατ} [ h₁ c(τ) − (ω_n² h₀ + α h₁) s(τ) ]
//! ```
//!
//! where α = C/2M, ω_n² = K/M and (c, s) = (cos ω_d τ, sin(ω_d τ)/ω_d) when under-damped,
//! (1, τ) when critically damped and (cosh βτ, sinh(βτ)/β) when over-damped. The form is
//! continuous across regimes, so near-critical damping loses no accuracy.
//!
//! An external force polynomial in time `f(t)` on the right-hand side (see
//! [`super::forces`]) adds its response from rest `r(t − t₀)` (see [`super::response`]: a
//! power series on short flows, `p(t) + h_p(t − t₀)` with the polynomial particular solution
//! `p` on long ones), so that the homogeneous part keeps the initial conditions of the
//! harmonic motion alone; without one the flow is the harmonic motion's closed form alone.

use super::poly::{INV, Poly, RECIPROCALS};
use crate::error::SimError;

/// The forcing phase at a time: `cos ωt` and `sin ωt`, computed once per time and shared by
/// every oscillator and event function.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Phase {
    pub cos: f64,
    pub sin: f64,
}

/// Harmonic base motion `y = A sin(ωt)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Forcing {
    /// Amplitude A, m.
    pub amplitude: f64,
    /// Angular frequency ω, rad/s.
    pub omega: f64,
    /// Period 2π/ω, s.
    pub period: f64,
}

impl Forcing {
    pub fn new(amplitude: f64, omega: f64) -> Self {
        Forcing {
            amplitude,
            omega,
            period: 2.0 * std::f64::consts::PI / omega,
        }
    }

    /// The phase at time `t`, reduced modulo the period first so that long runs keep full
    /// phase accuracy.
    #[inline]
    pub fn phase(&self, t: f64) -> Phase {
        let reduced = reduce_period(t, self.period);
        let (sin, cos) = (self.omega * reduced).sin_cos();
        Phase { cos, sin }
    }

    /// Base displacement y, m, and velocity y', m/s, at a phase.
    #[inline]
    pub fn base(&self, ph: Phase) -> (f64, f64) {
        (self.amplitude * ph.sin, self.amplitude * self.omega * ph.cos)
    }
}

/// `t.rem_euclid(period)`, bit for bit, without the software `fmod` behind `rem_euclid`
/// (a loop over the quotient's bits, ~8 % of a run's instructions when it was used here).
///
/// For t ≥ 0 the remainder `t − n·period` with `n = ⌊t/period⌋` is exactly representable (as
/// `fmod`'s result always is), so one fused multiply-add with the right `n` returns it exactly.
/// `t/period` may round `n` one off; the remainder then leaves `[0, period)` and `n` is
/// corrected. Negative times (rare: none in a forward run) take `rem_euclid` itself.
#[inline]
pub(crate) fn reduce_period(t: f64, period: f64) -> f64 {
    if !(t > 0.0 && t < 9.0e15 * period && period > 0.0 && period.is_finite()) {
        return t.rem_euclid(period);
    }
    let mut n = (t / period).floor();
    let mut r = (-n).mul_add(period, t);
    if r < 0.0 || r.is_sign_negative() {
        n -= 1.0;
        r = (-n).mul_add(period, t);
    } else if r >= period {
        n += 1.0;
        r = (-n).mul_add(period, t);
    }
    if r >= 0.0 && !r.is_sign_negative() && r < period {
        r
    } else {
        t.rem_euclid(period)
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Regime {
    Under { wd: f64 },
    Critical,
    Over { beta: f64 },
}

/// One linear oscillator with its initial condition at `t0`: the closed-form flow of a free
/// mass or of a stuck cluster.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Oscillator {
    /// Start time of this flow, s.
    pub(crate) t0: f64,
    /// Static offset F₀/K, m.
    pub(crate) mean: f64,
    /// Forced response `P cos ωt + Q sin ωt`: P, m.
    pub(crate) pc: f64,
    /// Forced response: Q, m.
    pub(crate) ps: f64,
    /// Homogeneous part at t0: value, m.
    pub(crate) h0: f64,
    /// Homogeneous part at t0: derivative, m/s.
    pub(crate) h1: f64,
    /// Rounding errors of `h0`, `h1` (exact by TwoSum): near an undamped resonance the
    /// forced part dwarfs the motion, and without them the flow would not start exactly at
    /// its initial state.
    e0: f64,
    e1: f64,
    /// α = C/(2M), 1/s.
    pub(crate) alpha: f64,
    /// ω_n² = K/M, 1/s².
    pub(crate) wn2: f64,
    regime: Regime,
    /// Forcing frequency ω, rad/s.
    omega: f64,
    /// Size of the terms the displacement is summed from, m (see `magnitude`).
    magnitude: f64,
    /// A prescribed motion (a cluster stuck to a rigid stop): no homogeneous part, and a
    /// motion that does not depend on the initial state.
    prescribed: bool,
    /// The polynomial external force per unit mass, `f(t)/M` about `t0`, m/s² (zero if
    /// none); the flow adds its response from rest (module docs).
    pub(crate) force: Poly,
}

/// Mechanical constants of one oscillator (a mass or a stuck cluster).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct OscConstants {
    pub mass: f64,
    pub damping: f64,
    pub stiffness: f64,
    /// Constant force F₀, N.
    pub force: f64,
    /// Polynomial external force f(t), N (zero if none).
    pub poly: Poly,
}

/// The homogeneous part of an [`Oscillator`] at one instant (see `Oscillator::homogeneous`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Homogeneous {
    /// h, m.
    pub h: f64,
    /// h', m/s.
    pub hd: f64,
    /// The propagated rounding error of the initial conditions in h, m, and in h', m/s.
    pub eh: f64,
    pub ehd: f64,
    /// Sums of the magnitudes of the terms of h, m, and of h', m/s.
    pub mag_h: f64,
    pub mag_hd: f64,
}

impl Oscillator {
    /// The flow through state (`s0`, `v0`) at time `t0`.
    #[inline]
    #[cfg(test)]
    pub(crate) fn new(
        k: OscConstants,
        forcing: &Forcing,
        t0: f64,
        s0: f64,
        v0: f64,
    ) -> Result<Self, SimError> {
        Self::new_at_phase(k, forcing, t0, forcing.phase(t0), s0, v0)
    }

    /// [`new`](Self::new) with the forcing phase of `t0` already at hand (`ph` must be
    /// `forcing.phase(t0)`).
    pub(crate) fn new_at_phase(
        k: OscConstants,
        forcing: &Forcing,
        t0: f64,
        ph: Phase,
        s0: f64,
        v0: f64,
    ) -> Result<Self, SimError> {
        let OscConstants {
            mass: m,
            damping: c,
            stiffness: kk,
            force: f0,
            poly: fpoly,
        } = k;
        let w = forcing.omega;
        let a = forcing.amplitude;
        // Particular solution: [D, Cω; −Cω, D] [P; Q] = [C A ω; K A], D = K − Mω².
        let d = kk - m * w * w;
        let cw = c * w;
        let det = d * d + cw * cw;
        let (pc, ps) = if a == 0.0 {
            (0.0, 0.0)
        } else if !(det.is_finite() && (kk * kk).is_finite()) {
            // Beyond double precision (a stiffness of 1e300): not a resonance.
            return Err(SimError::OutOfRange { first: 0, last: 0 });
        } else if det <= 1e-24 * (kk * kk) {
            // Undamped and driven exactly at resonance: no bounded particular solution.
            return Err(SimError::UndampedResonance { first: 0, last: 0 });
        } else {
            (
                (d * c * a * w - cw * kk * a) / det,
                (d * kk * a + cw * c * a * w) / det,
            )
        };
        let alpha = c / (2.0 * m);
        let wn2 = kk / m;
        let disc = alpha * alpha - wn2;
        let regime = if disc < 0.0 {
            Regime::Under { wd: (-disc).sqrt() }
        } else if disc == 0.0 {
            Regime::Critical
        } else {
            Regime::Over { beta: disc.sqrt() }
        };
        let mut osc = Oscillator {
            t0,
            mean: f0 / kk,
            pc,
            ps,
            h0: 0.0,
            h1: 0.0,
            e0: 0.0,
            e1: 0.0,
            alpha,
            wn2,
            regime,
            omega: w,
            magnitude: 0.0,
            prescribed: false,
            force: if fpoly.is_zero() {
                Poly::ZERO
            } else {
                let mut f = fpoly.shifted(t0);
                for cj in &mut f.c[..f.len] {
                    *cj /= m;
                }
                f
            },
        };
        // The response from rest is zero at t0: the homogeneous part takes the initial
        // conditions relative to the harmonic motion alone.
        let (sp, vp) = osc.forced(ph);
        (osc.h0, osc.e0) = two_sum(s0, -sp);
        (osc.h1, osc.e1) = two_sum(v0, -vp);
        osc.magnitude = osc.mean.abs() + osc.pc.abs() + osc.ps.abs() + osc.h0.abs();
        Ok(osc)
    }

    /// The prescribed motion `s(t) = mean + moves · A sin ωt` of a cluster stuck to a rigid
    /// stop (`moves`: 1 for a stop that moves with the base, 0 for one fixed in space), from
    /// `t0`, s. Its homogeneous part is zero (the nominal ω_n = 1/s only keeps the event
    /// functions' bounds finite), and so is its [`state_jacobian`](Self::state_jacobian).
    pub(crate) fn prescribed(forcing: &Forcing, t0: f64, mean: f64, moves: f64) -> Self {
        let ps = moves * forcing.amplitude;
        Oscillator {
            t0,
            mean,
            pc: 0.0,
            ps,
            h0: 0.0,
            h1: 0.0,
            e0: 0.0,
            e1: 0.0,
            alpha: 0.0,
            wn2: 1.0,
            regime: Regime::Under { wd: 1.0 },
            omega: forcing.omega,
            magnitude: mean.abs() + ps.abs(),
            prescribed: true,
            force: Poly::ZERO,
        }
    }

    /// Whether this is the prescribed motion of a cluster stuck to a rigid stop.
    pub fn is_prescribed(&self) -> bool {
        self.prescribed
    }

    /// Forced part of the harmonic base motion (static offset and steady harmonic response)
    /// at phase `ph`: displacement, m, and velocity, m/s. A polynomial force's response is
    /// not in it (see [`response`](Self::response)).
    #[inline]
    pub(crate) fn forced(&self, ph: Phase) -> (f64, f64) {
        let s = self.mean + self.pc * ph.cos + self.ps * ph.sin;
        let v = self.omega * (self.ps * ph.cos - self.pc * ph.sin);
        (s, v)
    }

    /// The external polynomial forcing per unit mass that drives this flow, `f(t)/M`, m/s²
    /// (zero if none).
    pub(crate) fn driving(&self) -> Poly {
        self.force
    }

    /// Homogeneous part at time `t`: `h` and `h'`, the rounding-error initial conditions
    /// propagated by the same flow, and the magnitudes of the terms of `h` and `h'`.
    #[inline(always)]
    pub(super) fn homogeneous(&self, t: f64) -> Homogeneous {
        let (c, s) = self.propagator(t - self.t0);
        let (h0, h1, e0, e1) = (self.h0, self.h1, self.e0, self.e1);
        let (p, q) = (h0 * c, (h1 + self.alpha * h0) * s);
        let (r, u) = (h1 * c, (self.wn2 * h0 + self.alpha * h1) * s);
        Homogeneous {
            h: p + q,
            hd: r - u,
            eh: e0 * c + (e1 + self.alpha * e0) * s,
            ehd: e1 * c - (self.wn2 * e0 + self.alpha * e1) * s,
            mag_h: p.abs() + q.abs(),
            mag_hd: r.abs() + u.abs(),
        }
    }

    /// Homogeneous part at time `t` with the magnitudes of the terms summed for each,
    /// `(h, h', |h₀c| + |(h₁+αh₀)s|, |h₁c| + |(ω_n²h₀+αh₁)s|)`, for rounding estimates.
    #[inline]
    pub(crate) fn homogeneous_with_magnitude(&self, t: f64) -> (f64, f64, f64, f64) {
        let g = self.homogeneous(t);
        (g.h + g.eh, g.hd + g.ehd, g.mag_h, g.mag_hd)
    }

    /// `e^{−ατ}c(τ)` and `e^{−ατ}s(τ)` of the module docs.
    #[inline]
    pub(super) fn propagator(&self, tau: f64) -> (f64, f64) {
        if tau == 0.0 {
            // Every regime's exact value at τ = 0 (what the formulas below round to there),
            // without an exponential and a sine-cosine: every search begins at the start of
            // its flow.
            return (1.0, 0.0);
        }
        let a = self.alpha;
        match self.regime {
            Regime::Under { wd } => {
                let e = (-a * tau).exp();
                let (sn, cs) = (wd * tau).sin_cos();
                (e * cs, e * sn / wd)
            }
            Regime::Critical => {
                let e = (-a * tau).exp();
                (e, e * tau)
            }
            Regime::Over { beta } => {
                let bt = beta * tau;
                if bt < 1.0 {
                    let e = (-a * tau).exp();
                    (e * bt.cosh(), e * bt.sinh() / beta)
                } else {
                    let e1 = (-(a - beta) * tau).exp();
                    let e2 = (-(a + beta) * tau).exp();
                    (0.5 * (e1 + e2), 0.5 * (e1 - e2) / beta)
                }
            }
        }
    }

    /// Displacement, m, and velocity, m/s, at time `t` (phase `ph` must be that of `t`).
    /// At `t0` this returns the initial state to within an ulp, however large the forced
    /// part.
    #[inline]
    pub(crate) fn state(&self, t: f64, ph: Phase) -> (f64, f64) {
        let (sp, vp) = self.forced(ph);
        let g = self.homogeneous(t);
        if self.force.is_zero() {
            return ((sp + g.h) + g.eh, (vp + g.hd) + g.ehd);
        }
        let r = self.response(t);
        (((sp + g.h) + g.eh) + r.r, ((vp + g.hd) + g.ehd) + r.rd)
    }

    /// Size of the terms the displacement is summed from, m: static offset, forced amplitude
    /// (as |P| + |Q|) and initial free displacement. Near resonance or mid-transient it can far
    /// exceed the displacement itself (forced and free parts cancel), and so can the
    /// displacement's rounding.
    pub(crate) fn magnitude(&self) -> f64 {
        self.magnitude
    }

    /// [`magnitude`](Self::magnitude) with the size of the terms of the polynomial force's
    /// response at time `t` added, m (that response grows along the piece).
    pub(crate) fn magnitude_at(&self, t: f64) -> f64 {
        if self.force.is_zero() {
            self.magnitude
        } else {
            self.magnitude + self.response(t).mag
        }
    }

    /// Start time of this flow, s.
    pub fn start_time(&self) -> f64 {
        self.t0
    }

    /// The Jacobian `∂(s, s')(t) / ∂(s, s')(t₀)` of this flow, row-major: the forced part
    /// does not depend on the initial state, so it is the homogeneous propagator's,
    /// `[[c + αs, s], [−ω_n² s, c − αs]]` with `(c, s)` of the module docs (decay included).
    /// Its determinant is `e^{−2α(t − t₀)}` (Liouville).
    #[inline]
    pub(crate) fn state_jacobian(&self, t: f64) -> [[f64; 2]; 2] {
        if self.prescribed {
            return [[0.0; 2]; 2];
        }
        let (c, s) = self.propagator(t - self.t0);
        let a = self.alpha;
        [[c + a * s, s], [-self.wn2 * s, c - a * s]]
    }

    /// A rate Λ, 1/s, that bounds how fast the Taylor coefficients of the motion can grow:
    /// at least ω (the forced part) and 2α + ω_n (every root of `λ² + 2αλ + ω_n² = 0` in all
    /// damping regimes, and the two coefficients of that recurrence). See [`taylor`](Self::taylor).
    pub(crate) fn rate_bound(&self) -> f64 {
        (2.0 * self.alpha + self.wn2.sqrt()).max(self.omega)
    }

    /// Scaled Taylor coefficients of the displacement about `tc` (phase `ph` of `tc`) with
    /// radius `r`, s: `coef[j] = s⁽ʲ⁾(tc) rʲ / j!`, m, for as many `j` as needed to bring the
    /// truncation error on `|t − tc| ≤ r` below `rel` times the size of the motion (static
    /// offset + forced amplitude + `|h(tc)| + r|h'(tc)|`), at most `coef.len()` terms.
    ///
    /// Returns the number of terms written, the truncation bound reached, m, and the
    /// tolerance it was held to, m. The
    /// homogeneous part obeys `h⁽ʲ⁺²⁾ = −2α h⁽ʲ⁺¹⁾ − ω_n² h⁽ʲ⁾`; once `j + 1 ≥ KΛr`
    /// ([`rate_bound`](Self::rate_bound), K = 8) each scaled coefficient is at most
    /// `c = 1/K + 1/K²` of the larger of the two before it, so the tail after `j` is below
    /// `2c/(1 − c)·max(|g_{j−1}|, |g_j|)`. The forced part's terms then fall by K per term,
    /// so its tail is below `K/(K − 1)` times its next term. The first two coefficients are
    /// the values [`state`](Self::state) returns. A polynomial force φ = f/M makes the free
    /// part `u = h + r` (homogeneous part plus the force's response from rest) obey
    /// `u⁽ʲ⁺²⁾ = φ⁽ʲ⁾ − 2α u⁽ʲ⁺¹⁾ − ω_n² u⁽ʲ⁾`: its coefficients come from the same recurrence
    /// with φ's Taylor coefficients about `tc` added, and once those are used up (at least
    /// `len(φ) + 2` terms are written) the recurrence is homogeneous and the tail bound holds
    /// as without a force. The size of the force's effect over the radius,
    /// `Σ_k |φ_k| rᵏ⁺²/((k+1)(k+2))`, joins the size of the motion.
    pub(crate) fn taylor(&self, tc: f64, ph: Phase, r: f64, rel: f64, coef: &mut [f64]) -> (usize, f64, f64) {
        let (sp, vp) = self.forced(ph);
        let Homogeneous { h, hd, eh, ehd, .. } = self.homogeneous(tc);
        let max_terms = coef.len();
        // The free part g_j (homogeneous part plus the force's response) and the forced part
        // F_j = wⱼ·cyc(j) with wⱼ = (ωr)ʲ/j!.
        let (mut g_prev, mut g) = (h + eh, (hd + ehd) * r);
        // The force's terms φ_k r^{k+2} about tc, which enter g_{k+2} (none: len 0).
        let mut drive = [0.0; super::poly::TERMS];
        let drive_len = self.force.len;
        let mut drive_size = 0.0;
        if drive_len > 0 {
            let resp = self.response(tc);
            g_prev += resp.r;
            g += resp.rd * r;
            let b = self.force.shifted(tc);
            let mut rk = r * r;
            for k in 0..drive_len {
                drive[k] = b.c[k] * rk;
                drive_size += drive[k].abs() * INV[k + 1] * INV[k + 2];
                rk *= r;
            }
        }
        // The forced part's scaled coefficients cycle through (A, B, −A, −B)·wⱼ: carry the
        // pair (Fⱼ, Fⱼ₊₁ rotated back) and rotate it by a quarter turn per term.
        let amp_a = self.pc * ph.cos + self.ps * ph.sin;
        let amp_b = self.ps * ph.cos - self.pc * ph.sin;
        // No overflow is possible at these magnitudes: no need for hypot.
        let amp = (self.pc * self.pc + self.ps * self.ps).sqrt();
        let tol = rel * (self.mean.abs() + amp + g_prev.abs() + g.abs() + drive_size);
        // Terms beyond the reciprocal table are never needed (a sub-piece needs about 20).
        let max_terms = max_terms.min(RECIPROCALS - 1);
        if max_terms < 2 || (drive_len > 0 && max_terms < drive_len + 2) {
            return (0, f64::INFINITY, tol);
        }
        if drive_len == 0 {
            coef[0] = (sp + h) + eh;
            coef[1] = ((vp + hd) + ehd) * r;
        } else {
            coef[0] = sp + g_prev;
            coef[1] = vp * r + g;
        }
        let wr = self.omega * r;
        // (p, q) = wⱼ·(cycⱼ, cycⱼ₊₁) with wⱼ = (ωr)ʲ/j!, at j = 1.
        let (mut p, mut q) = (wr * amp_b, -wr * amp_a);
        let mut w = wr;
        let two_ar = 2.0 * self.alpha * r;
        let wn2r2 = self.wn2 * r * r;
        let min_terms = TAIL_K * self.rate_bound() * r;
        // The first term after which the tail is bounded: j ≥ min_terms (j as f64 ≥ min_terms,
        // never for NaN) and j > drive_len.
        let bounded_from = if min_terms <= 0.0 {
            0
        } else if min_terms < RECIPROCALS as f64 {
            min_terms.ceil() as usize
        } else {
            usize::MAX
        }
        .max(drive_len + 1);
        let coef = &mut coef[..max_terms];
        let mut tail = f64::INFINITY;
        let mut n = 2;
        let mut inv_prev = 1.0;
        let forced_scale = FORCED_TAIL * amp;
        for j in 2..coef.len() {
            let inv_j = INV[j];
            let mut g_next = -(two_ar * g + wn2r2 * g_prev * inv_prev) * inv_j;
            if j < drive_len + 2 {
                g_next += drive[j - 2] * inv_j * inv_prev;
            }
            let step = wr * inv_j;
            (p, q) = (q * step, -p * step);
            w *= step;
            coef[j] = p + g_next;
            g_prev = g;
            g = g_next;
            inv_prev = inv_j;
            n = j + 1;
            // Terms 0..=j are written: bound the tail Σ_{i > j} (see the docs).
            if j >= bounded_from {
                let forced_tail = forced_scale * w * wr * INV[j + 1];
                tail = forced_tail + HOMOGENEOUS_TAIL * g.abs().max(g_prev.abs());
                if tail <= tol {
                    break;
                }
            }
        }
        (n, tail, tol)
    }
}

/// Terms of a Taylor expansion are bounded once `j + 1 ≥ TAIL_K·Λr` (see `Oscillator::taylor`).
const TAIL_K: f64 = 8.0;

/// Tail of the homogeneous part over the larger of the last two terms: `2c/(1 − c)`,
/// `c = 1/K + 1/K²`.
const HOMOGENEOUS_TAIL: f64 =
    2.0 * (1.0 / TAIL_K + 1.0 / (TAIL_K * TAIL_K)) / (1.0 - (1.0 / TAIL_K + 1.0 / (TAIL_K * TAIL_K)));

/// Tail of the forced part over its next term: `K/(K − 1)`.
const FORCED_TAIL: f64 = TAIL_K / (TAIL_K - 1.0);

/// `a + b` and its exact rounding error (Knuth's TwoSum): `a + b = s + e` exactly.
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

#[cfg(test)]
mod tests {
    /// `reduce_period` is `rem_euclid` bit for bit, over times from 1e-12 s to 1e7 s, at and
    /// next to multiples of the period, and for the periods of the paper's cases and others.
    #[test]
    fn reduce_period_is_rem_euclid() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let periods = [
            0.6283185307179586,
            2.0 * std::f64::consts::PI / 70.0,
            0.1,
            1.0,
            3.0,
            1e-3,
            7.3e-2,
        ];
        for &period in &periods {
            let check = |t: f64| {
                let (a, b) = (super::reduce_period(t, period), t.rem_euclid(period));
                assert_eq!(
                    a.to_bits(),
                    b.to_bits(),
                    "t = {t:e}, period = {period:e}: {a:e} vs {b:e}"
                );
            };
            for _ in 0..20_000 {
                let t = 10f64.powf(-12.0 + 19.0 * next());
                check(t);
                let k = (1e6 * next()).floor();
                for m in [
                    k * period,
                    (k * period).next_up(),
                    (k * period).next_down(),
                    (k + 0.5) * period,
                ] {
                    check(m);
                }
            }
            for t in [
                0.0,
                -0.0,
                -1e-20,
                -3.0 * period,
                f64::MIN_POSITIVE,
                1e300,
                f64::INFINITY,
                f64::NAN,
            ] {
                let (a, b) = (super::reduce_period(t, period), t.rem_euclid(period));
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "t = {t:e}"
                );
            }
        }
    }

    use super::*;

    /// Near an undamped resonance the forced part is ~1e4 times the motion; the flow must
    /// still start exactly at its initial state.
    #[test]
    fn starts_at_its_initial_state_near_resonance() {
        let k = OscConstants {
            mass: 0.1,
            damping: 0.0,
            stiffness: 100.0,
            force: 0.0,
            poly: Poly::ZERO,
        };
        let wn = (k.stiffness / k.mass).sqrt();
        let forcing = Forcing::new(0.08, wn * (1.0 - 1e-5));
        for (t0, s0, v0) in [(0.37, 0.07146086647170276, 2.697164490916262), (5.1, -0.013, 0.4)] {
            let osc = Oscillator::new(k, &forcing, t0, s0, v0).unwrap();
            let (sp, _) = osc.forced(forcing.phase(t0));
            assert!(sp.abs() > 100.0 * s0.abs(), "not near resonance: {sp}");
            let (s, v) = osc.state(t0, forcing.phase(t0));
            assert!((s - s0).abs() <= 2.0 * f64::EPSILON * s0.abs(), "{s} vs {s0}");
            assert!((v - v0).abs() <= 2.0 * f64::EPSILON * v0.abs(), "{v} vs {v0}");
        }
    }

    /// The closed form satisfies its own ODE: check the residual with finite differences of
    /// the velocity in every damping regime.
    #[test]
    fn residual_small_in_all_regimes() {
        let forcing = Forcing::new(0.05, 30.0);
        for c in [0.0, 0.3, 2.0 * (0.1f64 * 100.0).sqrt(), 20.0] {
            let k = OscConstants {
                mass: 0.1,
                damping: c,
                stiffness: 100.0,
                force: 0.7,
                poly: Poly::ZERO,
            };
            let osc = Oscillator::new(k, &forcing, 0.3, 0.01, -0.2).unwrap();
            let (s0, v0) = osc.state(0.3, forcing.phase(0.3));
            assert!((s0 - 0.01).abs() < 1e-15 && (v0 + 0.2).abs() < 1e-15);
            for &t in &[0.35, 0.5, 1.2] {
                let hstep = 1e-5;
                let (s, v) = osc.state(t, forcing.phase(t));
                let (_, vp) = osc.state(t + hstep, forcing.phase(t + hstep));
                let (_, vm) = osc.state(t - hstep, forcing.phase(t - hstep));
                let acc = (vp - vm) / (2.0 * hstep);
                let ph = forcing.phase(t);
                let (y, yd) = forcing.base(ph);
                let res = k.mass * acc + c * (v - yd) + k.stiffness * (s - y) - k.force;
                assert!(res.abs() < 1e-6, "c = {c}, t = {t}, residual {res}");
            }
        }
    }

    /// With a polynomial external force the closed form still satisfies its ODE (residual by
    /// finite differences), starts at its initial state, and its scaled Taylor coefficients
    /// sum to the closed form inside the radius.
    #[test]
    fn polynomial_forcing_residual_and_taylor() {
        let forcing = Forcing::new(0.05, 30.0);
        let f = Poly::new(0.2, &[0.3, -2.0, 5.0, 40.0, -100.0, 300.0, 900.0]);
        for c in [0.0, 0.3, 20.0] {
            let k = OscConstants {
                mass: 0.1,
                damping: c,
                stiffness: 100.0,
                force: 0.7,
                poly: f,
            };
            let osc = Oscillator::new(k, &forcing, 0.3, 0.01, -0.2).unwrap();
            let (s0, v0) = osc.state(0.3, forcing.phase(0.3));
            assert!((s0 - 0.01).abs() < 1e-15 && (v0 + 0.2).abs() < 1e-15);
            for &t in &[0.32, 0.4, 0.55] {
                let hstep = 1e-5;
                let (s, v) = osc.state(t, forcing.phase(t));
                let (_, vp) = osc.state(t + hstep, forcing.phase(t + hstep));
                let (_, vm) = osc.state(t - hstep, forcing.phase(t - hstep));
                let acc = (vp - vm) / (2.0 * hstep);
                let (y, yd) = forcing.base(forcing.phase(t));
                let res = k.mass * acc + c * (v - yd) + k.stiffness * (s - y) - k.force - f.value(t);
                assert!(res.abs() < 1e-6, "c = {c}, t = {t}, residual {res}");
            }
            let (tc, r) = (0.4, 0.01);
            let mut coef = [0.0; 40];
            let (n, tail, tol) = osc.taylor(tc, forcing.phase(tc), r, 0.25 * f64::EPSILON, &mut coef);
            assert!(tail <= tol && n >= f.len, "{n} terms, tail {tail:e} > {tol:e}");
            for x in [-1.0, -0.3, 0.5, 1.0] {
                let t = tc + x * r;
                let sum = coef[..n].iter().rev().fold(0.0, |acc, &cj| acc * x + cj);
                let (s, _) = osc.state(t, forcing.phase(t));
                assert!(
                    (sum - s).abs() <= 1e-14 * osc.magnitude_at(t),
                    "c = {c}, x = {x}: {sum} vs {s}"
                );
            }
        }
    }
}
