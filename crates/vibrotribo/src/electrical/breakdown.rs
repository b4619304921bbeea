//! Air breakdown across the gaps (Paschen's law): is a computed operating point physical?
//!
//! The electric field in each air gap follows from Gauss's law across the stack (docs/MODEL.md
//! §2). With `Q` the charge of the transducer in the exact form `V = −Q/C + σ(D₂ − D₁)/ε₀`
//! (freestanding mode: top electrode −Q, film −σS, metal +2σS, film −σS, bottom electrode
//! +Q), the gap voltages are
//!
//! ```text
//! V_gap1 = (Q + σS) D₁ / (ε₀S),     V_gap2 = (σS − Q) D₂ / (ε₀S)
//! ```
//!
//! and in contact-separation mode (electrode +Q, film −σS, gap D, metal) `V_gap = (σS − Q)
//! D/(ε₀S)`. A charge computed with the paper's open-circuit law (eq. 13) is first converted
//! to the exact form that gives the same terminal voltage:
//! `Q_exact = Q_paper − σS(D₁ + D₂)/(d₀ + D₁ + D₂)`.
//!
//! Paschen's law gives the breakdown voltage of a gap d in a gas at pressure p,
//! `V_b = B p d / (ln(A p d) − ln ln(1 + 1/γ))`; below the curve's minimum (where the
//! denominator is not positive) no breakdown can start. Defaults are air at one atmosphere:
//! A = 15 /(cm·Torr), B = 365 V/(cm·Torr), γ = 0.01.

use super::params::{EPSILON_0, HarvesterParams, TransducerMode, VocModel};

/// Paschen-law constants of the gas in the gaps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaschenParams {
    /// Gas pressure p, Pa. Default 101 325 Pa.
    pub pressure: f64,
    /// Ionisation constant A, 1/(Pa·m). Default 11.25 (air: 15 /(cm·Torr)).
    pub a: f64,
    /// Constant B, V/(Pa·m). Default 273.8 (air: 365 V/(cm·Torr)).
    pub b: f64,
    /// Secondary emission coefficient γ, dimensionless. Default 0.01.
    pub gamma: f64,
}

impl Default for PaschenParams {
    fn default() -> Self {
        const TORR: f64 = 101_325.0 / 760.0;
        PaschenParams {
            pressure: 101_325.0,
            a: 15.0 / (0.01 * TORR),
            b: 365.0 / (0.01 * TORR),
            gamma: 0.01,
        }
    }
}

impl PaschenParams {
    /// Breakdown voltage of a gap `d`, m, in V; `+∞` where breakdown cannot start (left of
    /// the Paschen minimum, or a closed gap).
    pub fn breakdown_voltage(&self, d: f64) -> f64 {
        PaschenLaw::new(self).breakdown_voltage(d)
    }
}

/// Paschen's law with its constant `ln ln(1 + 1/γ)` computed once (the same values as
/// [`PaschenParams::breakdown_voltage`], bit for bit).
#[derive(Debug, Clone, Copy, PartialEq)]
struct PaschenLaw {
    params: PaschenParams,
    /// `ln ln(1 + 1/γ)`, dimensionless.
    ln_ln_gamma: f64,
}

impl PaschenLaw {
    fn new(params: &PaschenParams) -> Self {
        PaschenLaw {
            params: *params,
            ln_ln_gamma: (1.0 + 1.0 / params.gamma).ln().ln(),
        }
    }

    /// Breakdown voltage of a gap `d`, m, in V (see [`PaschenParams::breakdown_voltage`]).
    #[inline]
    fn breakdown_voltage(&self, d: f64) -> f64 {
        let p = &self.params;
        let pd = p.pressure * d;
        let denominator = (p.a * pd).ln() - self.ln_ln_gamma;
        if d.is_nan() || denominator.is_nan() || d <= 0.0 || denominator <= 0.0 {
            return f64::INFINITY;
        }
        p.b * pd / denominator
    }

    /// An upper bound of `|v| / breakdown_voltage(d)` without a logarithm (see
    /// [`denominator_bound`](Self::denominator_bound)), or `None` where it does not apply (a
    /// gap that is not a positive normal number).
    #[inline]
    fn ratio_bound(&self, v: f64, d: f64) -> Option<f64> {
        let p = &self.params;
        let pd = p.pressure * d;
        let denominator = self.denominator_bound(d)?;
        Some(v.abs() * denominator / (p.b * pd) * (1.0 + 1e-9))
    }

    /// An upper bound, at least 0, of Paschen's denominator `ln(A p d) − ln ln(1 + 1/γ)` as
    /// [`breakdown_voltage`](Self::breakdown_voltage) computes it, without a logarithm, or
    /// `None` where `A p d` is not a positive normal number. With `x = A p d = m·2^e`,
    /// `m ∈ [√½, √2)` and `m = 1 + y`: `ln x ≤ e·ln 2 + y − y²/2 + y³/3` (the cubic's excess
    /// over `ln(1 + y)` has the derivative `y³/(1 + y)`, so its minimum is 0 at y = 0); the
    /// excess is at most 0.006.
    #[inline]
    fn denominator_bound(&self, d: f64) -> Option<f64> {
        Some(self.denominator_bound_unclamped(d)?.max(0.0))
    }

    /// [`denominator_bound`](Self::denominator_bound) before it is clamped at 0.
    #[inline]
    fn denominator_bound_unclamped(&self, d: f64) -> Option<f64> {
        let p = &self.params;
        let pd = p.pressure * d;
        let x = p.a * pd;
        if !(x.is_normal() && x > 0.0 && pd > 0.0) {
            return None;
        }
        let bits = x.to_bits();
        let mut exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
        let mut mantissa = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
        if mantissa > std::f64::consts::SQRT_2 {
            mantissa *= 0.5;
            exponent += 1;
        }
        // Exact (Sterbenz).
        let y = mantissa - 1.0;
        let ln_bound = exponent as f64 * std::f64::consts::LN_2 + y * (1.0 - y * (0.5 - y * (1.0 / 3.0)));
        // Rounding: the computed logarithms (here and in `breakdown_voltage`) are each within
        // a few ulps of their magnitudes; an absolute margin far above that keeps the bound
        // above the computed ratio where the denominator cancels, and a relative one covers
        // the products.
        let margin = 64.0 * f64::EPSILON * (ln_bound.abs() + self.ln_ln_gamma.abs() + 1.0);
        Some(ln_bound - self.ln_ln_gamma + margin)
    }
}

/// Voltages across the air gaps, V (one for contact-separation mode; the second is 0), for
/// the transducer `params` with charge `q`, C, as the charge solver reports it, and gaps
/// `d1`, `d2`, m (`d2` unused in contact-separation mode).
pub fn gap_voltages(params: &HarvesterParams, q: f64, d1: f64, d2: f64) -> [f64; 2] {
    GapField::new(params).voltages(q, d1, d2)
}

/// The constants of [`gap_voltages`], computed once.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GapField {
    mode: TransducerMode,
    voc_model: VocModel,
    /// σS, C.
    sigma_s: f64,
    /// ε₀S, F·m.
    eps_s: f64,
    /// d₀, m.
    d0: f64,
}

impl GapField {
    pub(crate) fn new(params: &HarvesterParams) -> Self {
        let s = params.area;
        GapField {
            mode: params.mode,
            voc_model: params.voc_model,
            sigma_s: params.charge_density * s,
            eps_s: EPSILON_0 * s,
            d0: params.effective_thickness(),
        }
    }

    /// The charges whose fields cross the gaps, C (`ε₀S ×` the field; the second 0 in
    /// contact-separation mode): the gap voltages are these times `dₖ/(ε₀S)`.
    #[inline]
    pub(crate) fn charges(&self, q: f64, d1: f64, d2: f64) -> [f64; 2] {
        let sigma_s = self.sigma_s;
        match self.mode {
            TransducerMode::Freestanding => {
                let q = match self.voc_model {
                    VocModel::Exact => q,
                    VocModel::Paper => q - sigma_s * (d1 + d2) / (self.d0 + d1 + d2),
                };
                [q + sigma_s, sigma_s - q]
            }
            TransducerMode::ContactSeparation => [sigma_s - q, 0.0],
        }
    }

    /// Voltages across the gaps, V (see [`gap_voltages`]).
    #[inline]
    fn voltages(&self, q: f64, d1: f64, d2: f64) -> [f64; 2] {
        let c = self.charges(q, d1, d2);
        match self.mode {
            TransducerMode::Freestanding => [c[0] * d1 / self.eps_s, c[1] * d2 / self.eps_s],
            TransducerMode::ContactSeparation => [c[0] * d1 / self.eps_s, 0.0],
        }
    }
}

/// The worst ratio |V_gap| / V_b over samples of a run.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BreakdownMargin {
    /// Largest |V_gap|/V_b seen (≥ 1 means the air would break down), dimensionless.
    pub worst_ratio: f64,
    /// Time of that sample, s.
    pub time_s: f64,
    /// Which gap (1-based, in the transducer's order).
    pub gap: usize,
    /// The gap's voltage there, V.
    pub gap_voltage_v: f64,
    /// Its width there, m.
    pub gap_m: f64,
}

impl BreakdownMargin {
    /// Folds in one sample: time `t`, s, charge `q`, C, gaps `d1`, `d2`, m.
    pub fn add(
        &mut self,
        params: &HarvesterParams,
        paschen: &PaschenParams,
        t: f64,
        q: f64,
        d1: f64,
        d2: f64,
    ) {
        self.add_with(&GapField::new(params), &PaschenLaw::new(paschen), t, q, d1, d2);
    }

    /// [`add`](Self::add) with the law's constant computed once; a gap whose log-free bound
    /// cannot beat the worst ratio is skipped (it would not change the result).
    fn add_with(&mut self, field: &GapField, law: &PaschenLaw, t: f64, q: f64, d1: f64, d2: f64) {
        let v = field.voltages(q, d1, d2);
        for (k, (&vk, &dk)) in v.iter().zip(&[d1, d2]).enumerate() {
            if self.worst_ratio > 0.0 && law.ratio_bound(vk, dk).is_some_and(|b| b <= self.worst_ratio) {
                continue;
            }
            let ratio = vk.abs() / law.breakdown_voltage(dk);
            if ratio > self.worst_ratio {
                *self = BreakdownMargin {
                    worst_ratio: ratio,
                    time_s: t,
                    gap: k + 1,
                    gap_voltage_v: vk,
                    gap_m: dk,
                };
            }
        }
    }
}

/// The air-breakdown check along a whole solution, kept by the charge solver
/// ([`ChargeSolver::with_breakdown_check`](super::ChargeSolver::with_breakdown_check)): the
/// ratio is evaluated at every stage point of every step and, wherever a point beats the
/// worst so far, maximised over the neighbouring points by golden-section search on the
/// solver's dense output. The result does not depend on any output sampling.
#[derive(Debug, Clone)]
pub(crate) struct BreakdownWatch {
    field: GapField,
    paschen: PaschenLaw,
    /// Gap indices of the chain that the transducer spans (the second may be absent).
    contacts: [Option<usize>; 2],
    /// Start of the checked window, s.
    from: f64,
    /// The worst point so far.
    pub margin: BreakdownMargin,
}

/// How [`BreakdownWatch::may_beat`] reads its points: the transducer's gaps in a row of the
/// chain's gaps, which of them count, and the denominator's tangent `(value at the widest gap,
/// slope)` for each.
struct Points {
    contacts: [usize; 2],
    counted: [bool; 2],
    tangent: [(f64, f64); 2],
}

impl Points {
    /// The largest |c|·denominator over the points with charges `qs`, C, and rows of gaps
    /// `rows`, m (`charges` as [`GapField::charges`]), and whether a charge was NaN (then the
    /// points are observed, as any NaN answers true), without a branch per point: a closed
    /// gap (breakdown cannot start there) or an absent second gap contributes 0.
    #[inline(always)]
    fn top<'a>(
        &self,
        qs: &[f64],
        rows: impl Iterator<Item = &'a [f64]>,
        charges: impl Fn(f64, f64, f64) -> [f64; 2],
    ) -> (f64, bool) {
        let [k0, k1] = self.contacts;
        let mut top = 0.0f64;
        let mut nan = false;
        for (&q, row) in qs.iter().zip(rows) {
            // The rows were checked to hold both gaps.
            let d = [
                row.get(k0).copied().unwrap_or(0.0),
                row.get(k1).copied().unwrap_or(0.0),
            ];
            let c = charges(q, d[0], d[1]);
            for k in 0..2 {
                let (den, slope) = self.tangent[k];
                let den = den + (d[k] * slope - 1.0);
                let open = d[k] > 0.0 && self.counted[k];
                nan |= open && c[k].is_nan();
                let v = c[k].abs() * if den > 0.0 { den } else { 0.0 };
                if open && v > top {
                    top = v;
                }
            }
        }
        (top, nan)
    }
}

/// Golden-section iterations of a refinement: the interval shrinks to 0.618³⁰ ≈ 5e-7 of
/// itself, the ratio at a smooth maximum to ~1e-13 relative.
const REFINE_ITERATIONS: usize = 30;

impl BreakdownWatch {
    /// A watch for the harvester `params` from time `from`, s, on.
    pub fn new(params: &HarvesterParams, from: f64) -> Self {
        let c = params.contact;
        let second = match params.mode {
            TransducerMode::Freestanding => Some(c + 1),
            TransducerMode::ContactSeparation => None,
        };
        BreakdownWatch {
            field: GapField::new(params),
            paschen: PaschenLaw::new(&PaschenParams::default()),
            contacts: [Some(c), second],
            from,
            margin: BreakdownMargin::default(),
        }
    }

    /// Start of the checked window, s.
    pub fn from(&self) -> f64 {
        self.from
    }

    /// Folds in the instant `t`, s, with charge `q`, C, and the chain's gaps `gaps`, m;
    /// true if it is the worst so far.
    pub fn observe(&mut self, t: f64, q: f64, gaps: &[f64]) -> bool {
        if t < self.from {
            return false;
        }
        let d = self.contacts.map(|c| c.map_or(0.0, |k| gaps[k]));
        let before = self.margin.worst_ratio;
        self.margin.add_with(&self.field, &self.paschen, t, q, d[0], d[1]);
        self.margin.worst_ratio > before
    }

    /// Whether any of the instants with charges `charges`, C, and the chain's gaps `gaps`, m
    /// (one row of gaps per instant, as [`observe`](Self::observe) takes them) might beat the worst ratio so far; false only if
    /// none can, so that observing them would change nothing.
    ///
    /// The ratio at gap k is `|Vₖ|/V_b(dₖ) = |cₖ|·(ln(A p dₖ) − ln ln(1 + 1/γ))/(ε₀S·B p)`,
    /// with `cₖ` the charge whose field crosses the gap ([`GapField::charges`]; the gap's
    /// width cancels). The logarithm is bounded once, at the widest gap `D` among the points
    /// ([`PaschenLaw::denominator_bound`]), and at the others by its tangent there,
    /// `ln(A p d) ≤ ln(A p D) + d/D − 1` (ln is concave); with margins for the rounding of the
    /// ratio as [`observe`](Self::observe) computes it. No logarithm, and no division but one
    /// per gap and the charge conversion of the paper's V_oc.
    pub fn may_beat(&self, charges: &[f64], gaps: &[f64]) -> bool {
        let worst = self.margin.worst_ratio;
        let points = charges.len();
        if worst.is_nan() || worst <= 0.0 || points == 0 {
            return true;
        }
        let n = gaps.len() / points;
        if n * points != gaps.len() {
            return true;
        }
        // Rows of a length known at compile time for the usual chains (no division per row).
        match n {
            1 => self.screen(charges, gaps.as_chunks::<1>().0.iter().map(|r| &r[..])),
            2 => self.screen(charges, gaps.as_chunks::<2>().0.iter().map(|r| &r[..])),
            3 => self.screen(charges, gaps.as_chunks::<3>().0.iter().map(|r| &r[..])),
            _ => self.screen(charges, gaps.chunks_exact(n)),
        }
    }

    /// [`may_beat`](Self::may_beat) over `rows`, one row of gaps per charge.
    #[inline(always)]
    fn screen<'a>(&self, charges: &[f64], rows: impl Iterator<Item = &'a [f64]> + Clone) -> bool {
        let worst = self.margin.worst_ratio;
        // Offsets of the transducer's gaps in a point's row; a missing second gap reads the
        // first and is ignored.
        let second = self.contacts[1].is_some();
        let [Some(k0), k1] = self.contacts else {
            return true;
        };
        let k1 = k1.unwrap_or(k0);
        // The widest gaps.
        let mut widest = [0.0f64; 2];
        for row in rows.clone() {
            let (Some(&d0), Some(&d1)) = (row.get(k0), row.get(k1)) else {
                return true;
            };
            if d0.is_nan() || d1.is_nan() {
                return true;
            }
            widest = [widest[0].max(d0), widest[1].max(d1)];
        }
        // The bound of the denominator there, unclamped (the tangent continues it), and the
        // tangent's slope in d.
        let mut tangent = [(0.0, 0.0); 2];
        for k in 0..2 {
            if widest[k] > 0.0 {
                let Some(den) = self.paschen.denominator_bound_unclamped(widest[k]) else {
                    return true;
                };
                // The tangent's own rounding: its term is at most 1 in magnitude.
                tangent[k] = (den + 8.0 * f64::EPSILON, 1.0 / widest[k]);
            }
        }
        let p = &self.paschen.params;
        // |c|·denominator above this may beat the worst.
        let threshold = worst * (self.field.eps_s * p.b * p.pressure) * (1.0 - 4e-9);
        let points = Points {
            contacts: [k0, k1],
            counted: [true, second],
            tangent,
        };
        // The charge law chosen once, not at every point (`GapField::charges`' arms).
        let field = self.field;
        let sigma_s = field.sigma_s;
        let (top, nan) = match (field.mode, field.voc_model) {
            (TransducerMode::Freestanding, VocModel::Exact) => {
                points.top(charges, rows, |q, _, _| [q + sigma_s, sigma_s - q])
            }
            (TransducerMode::Freestanding, VocModel::Paper) => points.top(charges, rows, |q, d1, d2| {
                let q = q - sigma_s * (d1 + d2) / (field.d0 + d1 + d2);
                [q + sigma_s, sigma_s - q]
            }),
            (TransducerMode::ContactSeparation, _) => points.top(charges, rows, |q, _, _| [sigma_s - q, 0.0]),
        };
        nan || top > threshold
    }

    /// Maximises the ratio over `[a, b]`, s, by golden-section search, with `eval(t)` giving
    /// the charge, C, at `t` and filling the gaps, m (None: stop refining).
    pub fn refine<F>(&mut self, a: f64, b: f64, mut eval: F)
    where
        F: FnMut(f64, &mut [f64]) -> Option<f64>,
    {
        let a = a.max(self.from);
        if b.partial_cmp(&a) != Some(std::cmp::Ordering::Greater) {
            return;
        }
        let n = self.contacts.iter().flatten().max().map_or(0, |&k| k + 1);
        let mut gaps = [0.0f64; 64];
        if n > gaps.len() {
            return;
        }
        let paschen = self.paschen;
        let field = self.field;
        let contacts = self.contacts;
        let mut ratio = |t: f64, this: &mut Self| -> Option<f64> {
            let q = eval(t, &mut gaps[..n])?;
            this.observe(t, q, &gaps[..n]);
            let d = contacts.map(|c| c.map_or(0.0, |k| gaps[k]));
            let v = field.voltages(q, d[0], d[1]);
            Some(
                (v[0].abs() / paschen.breakdown_voltage(d[0])).max(if contacts[1].is_some() {
                    v[1].abs() / paschen.breakdown_voltage(d[1])
                } else {
                    0.0
                }),
            )
        };
        const G: f64 = 0.618_033_988_749_895;
        let (mut lo, mut hi) = (a, b);
        let mut x1 = hi - G * (hi - lo);
        let mut x2 = lo + G * (hi - lo);
        let (Some(mut f1), Some(mut f2)) = (ratio(x1, self), ratio(x2, self)) else {
            return;
        };
        for _ in 0..REFINE_ITERATIONS {
            if f1 < f2 {
                lo = x1;
                (x1, f1) = (x2, f2);
                x2 = lo + G * (hi - lo);
                let Some(f) = ratio(x2, self) else { return };
                f2 = f;
            } else {
                hi = x2;
                (x2, f2) = (x1, f1);
                x1 = hi - G * (hi - lo);
                let Some(f) = ratio(x1, self) else { return };
                f1 = f;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paschen_curve_of_air() {
        let p = PaschenParams::default();
        // Textbook values for air at one atmosphere: ~4.5 kV across 1 mm (about 3 MV/m
        // at larger gaps), a minimum near 330 V at p·d ≈ 0.75 Torr·cm (about 10 µm).
        let v1mm = p.breakdown_voltage(1e-3);
        assert!((3.5e3..5.5e3).contains(&v1mm), "{v1mm}");
        let v1cm = p.breakdown_voltage(1e-2);
        assert!((2.8e4..4.0e4).contains(&v1cm), "{v1cm}");
        let minimum = (1..2000)
            .map(|i| p.breakdown_voltage(i as f64 * 1e-7))
            .fold(f64::INFINITY, f64::min);
        assert!((250.0..450.0).contains(&minimum), "{minimum}");
        assert_eq!(p.breakdown_voltage(1e-7), f64::INFINITY);
    }

    /// The log-free bound that lets the watch skip points never undercuts the ratio (or a
    /// skipped point could have been the worst), and is within 10 % of it for gaps of a
    /// millimetre and more (or it would skip nothing).
    #[test]
    fn ratio_bound_is_an_upper_bound() {
        let law = PaschenLaw::new(&PaschenParams::default());
        for i in 0..=4000 {
            let d = 1e-8 * 10f64.powf(8.0 * i as f64 / 4000.0);
            let v = -1.0e4 * (1.0 + (i % 7) as f64);
            let ratio = v.abs() / law.breakdown_voltage(d);
            let bound = law.ratio_bound(v, d).unwrap();
            assert!(
                bound >= ratio,
                "d = {d:e}: bound {bound:e} below the ratio {ratio:e}"
            );
            if d >= 1e-3 {
                assert!(
                    bound <= 1.1 * ratio,
                    "d = {d:e}: bound {bound:e}, ratio {ratio:e}"
                );
            }
            assert_eq!(
                law.breakdown_voltage(d).to_bits(),
                PaschenParams::default().breakdown_voltage(d).to_bits()
            );
        }
        assert_eq!(law.ratio_bound(1.0, 0.0), None);
        assert_eq!(law.ratio_bound(1.0, f64::NAN), None);
    }

    /// The watch's bound never passes over a point that would beat the worst ratio: wherever
    /// it says no point of a step can, every point's ratio, computed from Gauss's and
    /// Paschen's laws directly, is at most the worst. And it is sharp enough to pass over
    /// points a little below the worst when the points are close together, as the stage points
    /// of a step are (or it would save nothing).
    #[test]
    fn step_bound_never_hides_a_worse_point() {
        let paschen = PaschenParams::default();
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut passed_over = 0;
        for mode in [TransducerMode::Freestanding, TransducerMode::ContactSeparation] {
            for voc_model in [VocModel::Paper, VocModel::Exact] {
                let h = HarvesterParams {
                    mode,
                    voc_model,
                    ..HarvesterParams::default()
                };
                let sigma_s = h.charge_density * h.area;
                let n = h.contact + 2;
                for case in 0..4000 {
                    // Seven points of a step: gaps from 0.1 µm to 3 cm (some closed), charges
                    // around ±σS, spread narrowly or widely.
                    let spread = if case % 2 == 0 { 1e-3 } else { 0.5 };
                    let d_mid = 10f64.powf(-7.0 + 5.5 * uniform());
                    let q_mid = sigma_s * (4.0 * uniform() - 2.0);
                    let points: Vec<(f64, Vec<f64>)> = (0..7)
                        .map(|_| {
                            let mut gaps = vec![0.0; n];
                            for g in gaps.iter_mut() {
                                *g = (d_mid * (1.0 + spread * (2.0 * uniform() - 1.0))).max(0.0);
                            }
                            if case % 97 == 0 {
                                gaps[h.contact] = 0.0;
                            }
                            (q_mid * (1.0 + spread * (2.0 * uniform() - 1.0)), gaps)
                        })
                        .collect();
                    let exact = |q: f64, gaps: &[f64]| {
                        let (d1, d2) = (gaps[h.contact], gaps[h.contact + 1]);
                        let v = gap_voltages(&h, q, d1, d2);
                        let r1 = v[0].abs() / paschen.breakdown_voltage(d1);
                        match mode {
                            TransducerMode::Freestanding => {
                                r1.max(v[1].abs() / paschen.breakdown_voltage(d2))
                            }
                            TransducerMode::ContactSeparation => r1,
                        }
                    };
                    let top = points.iter().map(|(q, g)| exact(*q, g)).fold(0.0, f64::max);
                    // Worst ratios so far above, at and below the points' largest.
                    for worst in [
                        top * 1.01,
                        top * (1.0 + 1e-15),
                        top,
                        top * (1.0 - 1e-6),
                        top * 0.999,
                        0.5 * top,
                    ] {
                        if worst.is_nan() || worst <= 0.0 {
                            continue;
                        }
                        let mut watch = BreakdownWatch::new(&h, 0.0);
                        watch.margin.worst_ratio = worst;
                        let charges: Vec<f64> = points.iter().map(|p| p.0).collect();
                        let gaps: Vec<f64> = points.iter().flat_map(|p| p.1.iter().copied()).collect();
                        let may = watch.may_beat(&charges, &gaps);
                        if !may {
                            passed_over += 1;
                            assert!(top <= worst, "{mode:?} {voc_model:?}: hid {top:e} > {worst:e}");
                        }
                        // Observing the points agrees: none beats a worst the bound passed over.
                        let mut check = watch.clone();
                        let beaten = points.iter().any(|(q, g)| check.observe(1.0, *q, g));
                        assert!(
                            may || !beaten,
                            "{mode:?} {voc_model:?}: passed over a worse point"
                        );
                        if worst == top * 1.01 && d_mid >= 1e-4 && spread < 0.01 {
                            assert!(!may, "{mode:?} {voc_model:?}: bound too loose at d = {d_mid:e}");
                        }
                    }
                }
            }
        }
        assert!(passed_over > 1000, "{passed_over}");
    }

    #[test]
    fn gap_voltages_follow_gauss() {
        let h = HarvesterParams {
            voc_model: VocModel::Exact,
            ..HarvesterParams::default()
        };
        let (d1, d2) = (0.004, 0.006);
        let sigma = h.charge_density;
        // Uncharged electrodes: each gap sees the field of the tribo charges alone, σ/ε0.
        let v = gap_voltages(&h, 0.0, d1, d2);
        assert!((v[0] - sigma * d1 / EPSILON_0).abs() < 1e-9 * v[0].abs());
        assert!((v[1] - sigma * d2 / EPSILON_0).abs() < 1e-9 * v[1].abs());
        // The gap voltages and the film drops add up to the terminal voltage of eq. 11
        // (exact form), for any charge.
        let q = 3.7e-8;
        let v = gap_voltages(&h, q, d1, d2);
        let films = -q * h.effective_thickness() / (EPSILON_0 * h.area);
        let terminal =
            -q / (EPSILON_0 * h.area / (h.effective_thickness() + d1 + d2)) + sigma * (d2 - d1) / EPSILON_0;
        // Top to bottom: −(gap 1) drop runs against the metal's field; V = films − V_g1 + V_g2.
        assert!(
            (films - v[0] + v[1] - terminal).abs() < 1e-9 * terminal.abs().max(1.0),
            "{films} {v:?} {terminal}"
        );
    }
}
