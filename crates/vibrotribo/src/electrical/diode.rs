//! The bridge diodes: SPICE's level-1 junction law with series resistance, and the full-wave
//! bridge of four identical diodes.
//!
//! ## Diode
//!
//! A junction at voltage `v_j` carries (SPICE level 1 without capacitances or breakdown)
//!
//! ```text
//! i = I_s (exp(v_j/(n V_T)) − 1)              v_j ≥ −3 n V_T
//! i = −I_s (1 + (3 n V_T / (e v_j))³)         v_j < −3 n V_T   (SPICE's reverse tail)
//! ```
//!
//! in series with R_s: the terminal voltage is `v = v_j + i R_s`; an optional leakage
//! conductance G_p sits across the whole diode (`i_total = i + G_p v`). In the forward branch the
//! current is explicit through the Wright ω function (ω(x) = W(eˣ), the solution of
//! ω + ln ω = x): `i + I_s = (nV_T/R_s) ω(ln(I_s R_s/(nV_T)) + (v + I_s R_s)/(nV_T))`. The two
//! branches join with continuous value and slope. ngspice reproduces this law exactly with
//! `.model d D(IS=I_s N=n RS=R_s)` at `temp = tnom = V_T q/k`, a resistor 1/G_p across each
//! diode, and apart from its `gmin` (1e-12 S across each junction).
//!
//! ## Bridge
//!
//! Diodes D1 (a→p), D2 (b→p), D3 (n→a), D4 (n→b) connect the transducer terminals a, b to the
//! storage node p and ground n. With identical diodes the floating node sits exactly at
//! `v_a = (V + V_s)/2` (then D1 and D4 carry the same voltage `(V − V_s)/2`, D2 and D3 the same
//! `−(V + V_s)/2`, and Kirchhoff's current law holds), so the bridge is explicit:
//!
//! ```text
//! I     = i((V − V_s)/2) − i(−(V + V_s)/2)      current out of the transducer
//! I_out = i((V − V_s)/2) + i(−(V + V_s)/2)      current into the storage node
//! ```

/// Series-resistance diode (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Diode {
    /// Saturation current I_s, A.
    pub saturation_current: f64,
    /// Ideality (emission) factor n, dimensionless.
    pub ideality: f64,
    /// Thermal voltage V_T, V.
    pub thermal_voltage: f64,
    /// Series resistance R_s, Ω (positive).
    pub series_resistance: f64,
    /// Leakage conductance G_p across the diode, S (≥ 0).
    pub parallel_conductance: f64,
}

/// Current and conductance of a diode or a bridge at one operating point.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BridgeCurrents {
    /// Current out of the transducer's terminal a, A.
    pub current: f64,
    /// ∂current/∂V, S.
    pub current_dv: f64,
    /// ∂current/∂V_s, S.
    pub current_dvs: f64,
    /// Current into the storage node, A.
    pub output: f64,
    /// ∂output/∂V, S.
    pub output_dv: f64,
    /// ∂output/∂V_s, S.
    pub output_dvs: f64,
}

impl Diode {
    /// Current i, A, and conductance di/dv, S, at terminal voltage `v`, V.
    pub fn current(&self, v: f64) -> (f64, f64) {
        DiodeLaw::new(self).current(v)
    }

    /// The full-wave bridge of four of these diodes at transducer voltage `v` and storage
    /// voltage `vs`, V (see the module docs).
    pub fn bridge(&self, v: f64, vs: f64) -> BridgeCurrents {
        DiodeLaw::new(self).bridge(v, vs)
    }
}

/// A [`Diode`] with the constants of its law computed once (the charge solver evaluates the
/// bridge at every stage of every Newton iteration).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DiodeLaw {
    is: f64,
    rs: f64,
    gp: f64,
    /// n·V_T and its inverse.
    a: f64,
    inv_a: f64,
    /// `ln(I_s R_s/(nV_T)) + I_s R_s/(nV_T)`: the forward branch's ω argument is `x0 + v/(nV_T)`.
    x0: f64,
    /// nV_T/R_s.
    a_over_rs: f64,
    /// The terminal voltage where the junction voltage is −3nV_T: below it the reverse tail
    /// applies.
    v_tail: f64,
    /// 3nV_T/e.
    tail_k: f64,
}

impl DiodeLaw {
    pub(crate) fn new(d: &Diode) -> Self {
        let is = d.saturation_current;
        let a = d.ideality * d.thermal_voltage;
        let rs = d.series_resistance;
        DiodeLaw {
            is,
            rs,
            gp: d.parallel_conductance,
            a,
            inv_a: 1.0 / a,
            x0: (is * rs / a).ln() + is * rs / a,
            a_over_rs: a / rs,
            v_tail: -3.0 * a + is * ((-3.0f64).exp() - 1.0) * rs,
            tail_k: 3.0 * a / std::f64::consts::E,
        }
    }

    /// n·V_T, V.
    pub(crate) fn thermal_scale(&self) -> f64 {
        self.a
    }

    /// Series resistance R_s of one diode, Ω.
    pub(crate) fn series_resistance(&self) -> f64 {
        self.rs
    }

    /// Current i, A, and conductance di/dv, S, at terminal voltage `v`, V.
    #[inline]
    pub(crate) fn current(&self, v: f64) -> (f64, f64) {
        let (is, rs, gp) = (self.is, self.rs, self.gp);
        if v >= self.v_tail {
            // Forward branch, explicit through ω.
            let w = wright_omega(self.x0 + v * self.inv_a);
            let i = self.a_over_rs * w - is;
            return (i + gp * v, w / ((1.0 + w) * rs) + gp);
        }
        // Reverse tail: solve vj + R_s i(vj) = v (i ≈ −I_s, so R_s i is tiny and one Newton
        // step from vj = v + I_s R_s is exact to rounding; the second evaluates there).
        let k = self.tail_k;
        let mut vj = v + is * rs;
        let mut i = 0.0;
        let mut g = 0.0;
        for _ in 0..2 {
            let arg = (k / vj).powi(3);
            i = -is * (1.0 + arg);
            g = 3.0 * is * arg / vj;
            let f = vj + rs * i - v;
            vj -= f / (1.0 + rs * g);
        }
        (i + gp * v, g / (1.0 + rs * g) + gp)
    }

    /// The bridge's two junction voltages, in units of n·V_T, at transducer voltage `v` and
    /// storage voltage `vs`, V: those of diodes with terminal voltages `(V − V_s)/2` and
    /// `−(V + V_s)/2`, less the drop `i·R_s` on their series resistance. (Far into conduction
    /// the terminal voltage moves by kilovolts while the junction moves by a few n·V_T.)
    #[inline]
    pub(crate) fn junction_exponents(&self, v: f64, vs: f64) -> [f64; 2] {
        let junction = |vd: f64| {
            let (i, _) = self.current(vd);
            (vd - (i - self.gp * vd) * self.rs) * self.inv_a
        };
        [junction(0.5 * (v - vs)), junction(-0.5 * (v + vs))]
    }

    /// The full-wave bridge at transducer voltage `v` and storage voltage `vs`, V.
    #[inline]
    pub(crate) fn bridge(&self, v: f64, vs: f64) -> BridgeCurrents {
        let (i_s, g_s) = self.current(0.5 * (v - vs));
        let (i_r, g_r) = self.current(-0.5 * (v + vs));
        BridgeCurrents {
            current: i_s - i_r,
            current_dv: 0.5 * (g_s + g_r),
            current_dvs: 0.5 * (g_r - g_s),
            output: i_s + i_r,
            output_dv: 0.5 * (g_s - g_r),
            output_dvs: -0.5 * (g_s + g_r),
        }
    }
}

/// Wright ω function: the real solution w of `w + ln w = x` (ω(x) = W₀(eˣ)), to full precision.
pub(crate) fn wright_omega(x: f64) -> f64 {
    if x < -10.0 {
        // ω = z − z² + 3z³/2 − 8z⁴/3 + …, z = eˣ: the next term is below 6e-17 of ω here (and
        // ω is 0 once eˣ underflows).
        let z = x.exp();
        return z * (1.0 - z * (1.0 - z * (1.5 - z * (8.0 / 3.0))));
    }
    let mut w = if x < -2.0 {
        let e = x.exp();
        e * (1.0 - e + 1.5 * e * e)
    } else if x < 1.0 {
        (1.0 + x.exp()).ln()
    } else {
        x - x.ln()
    };
    // Fritsch–Shafer–Crowley iteration (fourth order).
    for _ in 0..6 {
        let r = x - w - w.ln();
        let wp1 = 1.0 + w;
        let q = wp1 * (wp1 + 2.0 / 3.0 * r);
        let next = w * (1.0 + r / wp1 * (q - 0.5 * r) / (q - r));
        let done = (next - w).abs() <= 4.0 * f64::EPSILON * next;
        w = next;
        if done {
            break;
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wright_omega_solves_its_equation() {
        let mut x = -60.0;
        while x < 2000.0 {
            let w = wright_omega(x);
            let res = w + w.ln() - x;
            assert!(
                res.abs() <= 8.0 * f64::EPSILON * x.abs().max(1.0),
                "x = {x}, w = {w}, residual {res:e}"
            );
            x += 0.37;
        }
    }

    fn diode() -> Diode {
        Diode {
            saturation_current: 2.52e-9,
            ideality: 1.752,
            thermal_voltage: 0.025_864,
            series_resistance: 0.568,
            parallel_conductance: 0.0,
        }
    }

    #[test]
    fn diode_satisfies_junction_law_with_series_resistance() {
        let d = diode();
        let a = d.ideality * d.thermal_voltage;
        for &v in &[-50.0, -1.0, -0.2, -0.1, 0.0, 0.3, 0.6, 0.8, 1.0, 5.0, 100.0] {
            let (i, g) = d.current(v);
            let vj = v - i * d.series_resistance;
            let law = if vj >= -3.0 * a {
                d.saturation_current * ((vj / a).exp() - 1.0)
            } else {
                -d.saturation_current * (1.0 + (3.0 * a / (std::f64::consts::E * vj)).powi(3))
            };
            assert!(
                (i - law).abs() <= 1e-12 * law.abs().max(d.saturation_current),
                "v = {v}: i = {i:e}, law {law:e}"
            );
            // Conductance against a central difference.
            let h = 1e-6 * v.abs().max(0.01);
            let fd = (d.current(v + h).0 - d.current(v - h).0) / (2.0 * h);
            assert!(
                (g - fd).abs() <= 1e-5 * g.abs().max(1e-12),
                "v = {v}: g = {g:e}, fd {fd:e}"
            );
        }
    }

    #[test]
    fn bridge_conserves_current_and_rectifies() {
        let d = diode();
        for &(v, vs) in &[(5.0, 2.0), (-5.0, 2.0), (0.3, 2.0), (-40.0, 10.0)] {
            let b = d.bridge(v, vs);
            // KCL at the floating node with v_a = (v + vs)/2.
            let va = 0.5 * (v + vs);
            let i1 = d.current(va - vs).0;
            let i2 = d.current(va - v - vs).0;
            let i3 = d.current(-va).0;
            let i4 = d.current(v - va).0;
            assert!((i1 + i2 - i3 - i4).abs() <= 1e-15 * (i1.abs() + i2.abs() + i3.abs() + i4.abs()));
            assert!((b.current - (i1 - i3)).abs() <= 1e-15 * b.current.abs().max(1e-9));
            if v.abs() > vs + 2.0 {
                assert!(b.output > 0.0 && b.current.signum() == v.signum());
            }
        }
    }
}
