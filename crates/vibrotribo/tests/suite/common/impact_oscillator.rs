//! The harmonically forced impact oscillator of the textbooks, in closed form, independent of
//! the engine: `m x'' + c x' + k x = c y' + k y`, `y = A sin ωt`, below a stop at `x = g`
//! fixed in space, with Newton's law `x'⁺ = −r x'⁻` at `x = g` (Shaw & Holmes 1983; di
//! Bernardo, Budd, Champneys & Kowalczyk 2008, ch. 1 and 6).
//!
//! Between impacts `x = x_p + h` with the steady part `x_p = P cos ωt + Q sin ωt`,
//! `[k − mω², cω; −cω, k − mω²][P; Q] = [cAω; kA]`, and the free part
//! `h(τ) = e^{−ζω_nτ}(h₀ cos ω_dτ + (h₁ + ζω_n h₀) sin(ω_dτ)/ω_d)`. A (1,1) orbit (one impact per
//! forcing period) with impact time t₀ and impact speed v > 0 solves
//! `x(t₀ + T) = g`, `x'(t₀ + T) = v` from `x(t₀) = g`, `x'(t₀⁺) = −r v` (Newton's method
//! below). Its Floquet multipliers are the eigenvalues of `S Φ(T)`, Φ the free propagator
//! over one period and S the saltation matrix of the impact,
//! `S = [[−r, 0], [(a⁺ + r a⁻)/v, −r]]`, a∓ the accelerations just before and after; so
//! `det = r² e^{−2ζω_nT}`.
//!
//! With the stop moving with the base (`moving`), the same holds for the relative coordinate
//! `z = x − y`: `m z'' + c z' + k z = m ω² A sin ωt` below `z = g`, `z'⁺ = −r z'⁻`.

#![allow(dead_code)]

/// Parameters of the impact oscillator, SI.
#[derive(Debug, Clone, Copy)]
pub struct ImpactOscillator {
    pub m: f64,
    pub k: f64,
    pub c: f64,
    pub amplitude: f64,
    pub omega: f64,
    pub gap: f64,
    pub r: f64,
    /// The stop moves with the base (the coordinate is then z = x − y).
    pub moving: bool,
}

/// A (1,1) orbit: impact time in [0, T), s, impact speed, m/s, and multipliers (re, im).
#[derive(Debug, Clone, Copy)]
pub struct OneOne {
    pub t0: f64,
    pub speed: f64,
    pub multipliers: [(f64, f64); 2],
}

impl ImpactOscillator {
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega
    }

    fn steady(&self) -> (f64, f64) {
        let (m, k, c, a, w) = (self.m, self.k, self.c, self.amplitude, self.omega);
        let d = k - m * w * w;
        let det = d * d + c * w * c * w;
        if self.moving {
            // [d, cw; −cw, d][P; Q] = [0; mω²A].
            let f = m * w * w * a;
            return (-c * w * f / det, d * f / det);
        }
        // Cramer on [d, cw; −cw, d][P; Q] = [caw; ka].
        let p = (c * a * w * d - c * w * k * a) / det;
        let q = (d * k * a + c * w * c * a * w) / det;
        (p, q)
    }

    /// Steady displacement and velocity at time t.
    pub fn xp(&self, t: f64) -> (f64, f64) {
        let (p, q) = self.steady();
        let (s, c) = (self.omega * t).sin_cos();
        (p * c + q * s, self.omega * (-p * s + q * c))
    }

    /// The free propagator over τ: (h, h') = Φ (h₀, h₁).
    pub fn propagator(&self, tau: f64) -> [[f64; 2]; 2] {
        let wn = (self.k / self.m).sqrt();
        let al = self.c / (2.0 * self.m);
        let wd = (wn * wn - al * al).sqrt();
        let e = (-al * tau).exp();
        let (sn, cs) = (wd * tau).sin_cos();
        let s = sn / wd;
        [[e * (cs + al * s), e * s], [-wn * wn * e * s, e * (cs - al * s)]]
    }

    /// Residual of the (1,1) conditions at (t₀, v).
    fn residual(&self, t0: f64, v: f64) -> [f64; 2] {
        let (p, pd) = self.xp(t0);
        let (h0, h1) = (self.gap - p, -self.r * v - pd);
        let f = self.propagator(self.period());
        let (h, hd) = (f[0][0] * h0 + f[0][1] * h1, f[1][0] * h0 + f[1][1] * h1);
        [p + h - self.gap, pd + hd - v]
    }

    /// The (1,1) conditions reduced to the impact time: the impact speed `v(t₀)` that closes
    /// the velocity condition (linear in v) and the position condition's residual at it, m.
    /// The (1,1) orbits are the roots with v > 0; at a fold two of them meet in a double root.
    pub fn reduced(&self, t0: f64) -> (f64, f64) {
        let (p, pd) = self.xp(t0);
        let h0 = self.gap - p;
        let f = self.propagator(self.period());
        // pd + f10 h0 + f11 (−r v − pd) − v = 0
        let v = (pd + f[1][0] * h0 - f[1][1] * pd) / (1.0 + f[1][1] * self.r);
        let h1 = -self.r * v - pd;
        (p + f[0][0] * h0 + f[0][1] * h1 - self.gap, v)
    }

    /// The extremum of the reduced position residual over impact times in `[a, b]` (golden
    /// section), signed so that it is negative while two (1,1) orbits lie in the window and
    /// positive once they have met: zero at their fold. The window's ends must lie on one
    /// side of zero.
    pub fn fold_function(&self, (mut a, mut b): (f64, f64)) -> f64 {
        let g = |t: f64| self.reduced(t).0;
        let outside = g(a).signum();
        assert_eq!(outside, g(b).signum(), "the window's ends on two sides");
        let golden = 0.5 * (5f64.sqrt() - 1.0);
        for _ in 0..200 {
            let (c, d) = (b - golden * (b - a), a + golden * (b - a));
            if outside * g(c) < outside * g(d) {
                b = d
            } else {
                a = c
            }
        }
        outside * g(0.5 * (a + b))
    }

    /// The (1,1) orbit near the guess (t₀, v) by Newton's method with a central-difference
    /// Jacobian, or `None` if it does not converge to an impact with v > 0.
    pub fn one_one(&self, guess: (f64, f64)) -> Option<OneOne> {
        let (mut t0, mut v) = guess;
        let scale_t = 1e-7 * self.period();
        let scale_v = 1e-7 * v.abs().max(1e-3);
        for _ in 0..60 {
            let f = self.residual(t0, v);
            if f[0].abs() < 1e-15 * self.gap.max(1e-3) && f[1].abs() < 1e-14 * v.abs() {
                break;
            }
            let (a, b) = (self.residual(t0 + scale_t, v), self.residual(t0 - scale_t, v));
            let (c, d) = (self.residual(t0, v + scale_v), self.residual(t0, v - scale_v));
            let j = [
                [(a[0] - b[0]) / (2.0 * scale_t), (c[0] - d[0]) / (2.0 * scale_v)],
                [(a[1] - b[1]) / (2.0 * scale_t), (c[1] - d[1]) / (2.0 * scale_v)],
            ];
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            t0 -= (j[1][1] * f[0] - j[0][1] * f[1]) / det;
            v -= (-j[1][0] * f[0] + j[0][0] * f[1]) / det;
        }
        let f = self.residual(t0, v);
        if !(f[0].abs() < 1e-12 * self.gap.max(1e-3) && f[1].abs() < 1e-11 * v.abs()) || v <= 0.0 {
            return None;
        }
        let t0 = t0.rem_euclid(self.period());
        Some(OneOne {
            t0,
            speed: v,
            multipliers: self.multipliers(t0, v),
        })
    }

    /// Eigenvalues of `S Φ(T)` at the (1,1) orbit (t₀, v).
    pub fn multipliers(&self, t0: f64, v: f64) -> [(f64, f64); 2] {
        let (y, yd) = (
            self.amplitude * (self.omega * t0).sin(),
            self.amplitude * self.omega * (self.omega * t0).cos(),
        );
        let accel = |vel: f64| {
            if self.moving {
                (-self.c * vel - self.k * self.gap + self.m * self.omega * self.omega * y) / self.m
            } else {
                (-self.c * (vel - yd) - self.k * (self.gap - y)) / self.m
            }
        };
        let (am, ap) = (accel(v), accel(-self.r * v));
        let s = [[-self.r, 0.0], [(ap + self.r * am) / v, -self.r]];
        let f = self.propagator(self.period());
        let m = [
            [
                s[0][0] * f[0][0] + s[0][1] * f[1][0],
                s[0][0] * f[0][1] + s[0][1] * f[1][1],
            ],
            [
                s[1][0] * f[0][0] + s[1][1] * f[1][0],
                s[1][0] * f[0][1] + s[1][1] * f[1][1],
            ],
        ];
        let tr = m[0][0] + m[1][1];
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let disc = tr * tr / 4.0 - det;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            [(tr / 2.0 + sq, 0.0), (tr / 2.0 - sq, 0.0)]
        } else {
            let sq = (-disc).sqrt();
            [(tr / 2.0, sq), (tr / 2.0, -sq)]
        }
    }

    /// Trace of `S Φ(T)` plus `1 + det`: zero where a multiplier is −1 (for real ones).
    pub fn doubling_function(&self, orbit: &OneOne) -> f64 {
        let [(a, _), (b, _)] = orbit.multipliers;
        (1.0 + a) * (1.0 + b)
    }
}
