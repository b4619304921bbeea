//! The ideal-switch cycle between two states, the states a run visits (binned by their
//! short-circuit charge) and the search for the CMEO and the breakdown-limited maximum over
//! them.

use crate::electrical::breakdown::{GapField, PaschenParams};
use crate::electrical::{EPSILON_0, HarvesterParams, TransducerMode};

/// One state of the transducer as the cycles see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleState {
    /// Short-circuit charge `Q_sc = C·V_oc`, C.
    pub short_circuit_charge: f64,
    /// Inverse capacitance `1/C`, 1/F.
    pub inverse_capacitance: f64,
    /// The charges, C, at which no air gap of this state breaks down (Paschen's law): from
    /// `allowed.0` to `allowed.1` (±∞ where no gap limits them).
    pub allowed: (f64, f64),
}

impl CycleState {
    /// The state of the transducer `params` at the chain's gaps `gaps`, m (all of them, as
    /// the simulator reports them); `None` where the capacitance is not positive and finite.
    pub fn new(params: &HarvesterParams, gaps: &[f64]) -> Option<Self> {
        let t = params.transducer();
        let c = t.capacitance(gaps);
        let voc = t.open_circuit_voltage(gaps);
        if !(c.is_finite() && c > 0.0 && voc.is_finite()) {
            return None;
        }
        Some(CycleState {
            short_circuit_charge: c * voc,
            inverse_capacitance: 1.0 / c,
            allowed: allowed_charges(params, gaps),
        })
    }

    /// Terminal voltage `V = V_oc − Q/C = (Q_sc − Q)/C` at the charge `q`, C, in V.
    pub fn voltage(&self, q: f64) -> f64 {
        (self.short_circuit_charge - q) * self.inverse_capacitance
    }
}

/// The charges, C, at which no air gap of the transducer `params` at the chain's gaps `gaps`
/// breaks down: the gap voltages are `cₖ(Q)·Dₖ/(ε₀S)` with `cₖ` affine in `Q` of slope ±1
/// (docs/MODEL.md §2), each bounded by Paschen's `V_b(Dₖ)`.
fn allowed_charges(params: &HarvesterParams, gaps: &[f64]) -> (f64, f64) {
    let field = GapField::new(params);
    let paschen = PaschenParams::default();
    let k = params.contact;
    let (d, slopes): ([f64; 2], [f64; 2]) = match params.mode {
        TransducerMode::Freestanding => (
            [
                gaps.get(k).copied().unwrap_or(0.0),
                gaps.get(k + 1).copied().unwrap_or(0.0),
            ],
            [1.0, -1.0],
        ),
        TransducerMode::ContactSeparation => ([gaps.get(k).copied().unwrap_or(0.0), 0.0], [-1.0, 0.0]),
    };
    let at_zero = field.charges(0.0, d[0], d[1]);
    let eps_s = EPSILON_0 * params.area;
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for g in 0..2 {
        if slopes[g] == 0.0 || d[g].is_nan() || d[g] <= 0.0 {
            continue;
        }
        let vb = paschen.breakdown_voltage(d[g]);
        if !vb.is_finite() {
            continue;
        }
        // |slope·Q + c(0)| ≤ w.
        let w = eps_s * vb / d[g];
        let centre = -at_zero[g] * slopes[g];
        lo = lo.max(centre - w);
        hi = hi.min(centre + w);
    }
    (lo, hi)
}

/// Energy, J, delivered by the ideal-switch cycle between the states `a` and `b`:
/// `½ (Q_sc(b) − Q_sc(a))² (1/C(a) + 1/C(b))` (see the [module](super) docs).
pub fn switch_cycle_energy(a: &CycleState, b: &CycleState) -> f64 {
    let dq = b.short_circuit_charge - a.short_circuit_charge;
    0.5 * dq * dq * (a.inverse_capacitance + b.inverse_capacitance)
}

/// The CMEO, J, of a contact-separation transducer `params` whose gap runs over
/// `[x_min, x_max]`, m, in closed form:
/// `σ²S d₀² (x_max − x_min)² (2d₀ + x_min + x_max) / (2ε₀ (d₀ + x_min)² (d₀ + x_max)²)`.
pub fn cmeo_contact_separation(params: &HarvesterParams, x_min: f64, x_max: f64) -> f64 {
    let d0 = params.effective_thickness();
    let (s, sigma) = (params.area, params.charge_density);
    let dx = x_max - x_min;
    let (a, b) = (d0 + x_min, d0 + x_max);
    sigma * sigma * s * d0 * d0 * dx * dx * (2.0 * d0 + x_min + x_max) / (2.0 * EPSILON_0 * a * a * b * b)
}

/// Bins of the short-circuit charge over `[−σS, 2σS]` (it lies in `(−σS, σS)` for the exact
/// freestanding law, `[0, 2σS)` for the paper's, `[0, σS)` in contact-separation mode).
const BINS: usize = 1024;

/// The states a run visits, kept in 1024 bins of their short-circuit charge: per bin the
/// state of the largest `1/C` and those of the smallest and largest `Q_sc` (the candidates of
/// a cycle's switching states: for a given `Q_sc` a larger `1/C` gives more energy), and the
/// charges no state of the bin breaks down at (the intersection of their intervals).
#[derive(Debug, Clone, PartialEq)]
pub struct StateSet {
    /// σS, C (the bins' scale).
    sigma_s: f64,
    bins: Vec<Option<Bin>>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Bin {
    widest: CycleState,
    lowest: CycleState,
    highest: CycleState,
    allowed: (f64, f64),
}

impl StateSet {
    /// An empty set for the transducer `params`.
    pub fn new(params: &HarvesterParams) -> Self {
        StateSet {
            sigma_s: params.charge_density * params.area,
            bins: vec![None; BINS],
        }
    }

    /// Adds one state.
    pub fn add(&mut self, s: CycleState) {
        if !(s.short_circuit_charge.is_finite() && s.inverse_capacitance.is_finite()) {
            return;
        }
        let u = if self.sigma_s > 0.0 {
            (s.short_circuit_charge / self.sigma_s + 1.0) / 3.0
        } else {
            0.0
        };
        let i = ((u * BINS as f64).floor().max(0.0) as usize).min(BINS - 1);
        match &mut self.bins[i] {
            None => {
                self.bins[i] = Some(Bin {
                    widest: s,
                    lowest: s,
                    highest: s,
                    allowed: s.allowed,
                })
            }
            Some(b) => {
                if s.inverse_capacitance > b.widest.inverse_capacitance {
                    b.widest = s;
                }
                if s.short_circuit_charge < b.lowest.short_circuit_charge {
                    b.lowest = s;
                }
                if s.short_circuit_charge > b.highest.short_circuit_charge {
                    b.highest = s;
                }
                b.allowed = (b.allowed.0.max(s.allowed.0), b.allowed.1.min(s.allowed.1));
            }
        }
    }

    /// Whether no state was added.
    pub fn is_empty(&self) -> bool {
        self.bins.iter().all(Option::is_none)
    }

    /// The candidate switching states in order of `Q_sc`, each with its bin's allowed charges.
    fn candidates(&self) -> Vec<(CycleState, (f64, f64))> {
        let mut out = Vec::new();
        for b in self.bins.iter().flatten() {
            let mut three = [b.lowest, b.widest, b.highest];
            three.sort_by(|x, y| x.short_circuit_charge.total_cmp(&y.short_circuit_charge));
            for (j, s) in three.iter().enumerate() {
                if j == 0 || three[j - 1] != *s {
                    out.push((*s, b.allowed));
                }
            }
        }
        out
    }

    /// The CMEO cycle: the largest [`switch_cycle_energy`] over pairs of the states, with the
    /// two states (lower `Q_sc` first); `None` for fewer than two states.
    pub fn cmeo(&self) -> Option<(f64, CycleState, CycleState)> {
        let c = self.candidates();
        let mut best: Option<(f64, CycleState, CycleState)> = None;
        for (i, (a, _)) in c.iter().enumerate() {
            for (b, _) in &c[i + 1..] {
                let e = switch_cycle_energy(a, b);
                if best.as_ref().is_none_or(|x| e > x.0) {
                    best = Some((e, *a, *b));
                }
            }
        }
        best
    }

    /// The breakdown-limited maximum: the largest [`switch_cycle_energy`] over pairs whose
    /// cycle no state between them (in `Q_sc`, both included) breaks down at, with the two
    /// states; `None` where no pair qualifies.
    pub fn breakdown_limited(&self) -> Option<(f64, CycleState, CycleState)> {
        let c = self.candidates();
        let mut best: Option<(f64, CycleState, CycleState)> = None;
        for (i, (a, allowed_a)) in c.iter().enumerate() {
            let qa = a.short_circuit_charge;
            let (mut lo, mut hi) = *allowed_a;
            if !(lo <= qa && qa <= hi) {
                continue;
            }
            for (b, allowed_b) in &c[i + 1..] {
                lo = lo.max(allowed_b.0);
                hi = hi.min(allowed_b.1);
                // The interval only shrinks: once Q_sc(a) leaves it, no later b qualifies.
                if !(lo <= qa && qa <= hi) {
                    break;
                }
                let qb = b.short_circuit_charge;
                if !(lo <= qb && qb <= hi) {
                    continue;
                }
                let e = switch_cycle_energy(a, b);
                if best.as_ref().is_none_or(|x| e > x.0) {
                    best = Some((e, *a, *b));
                }
            }
        }
        best
    }
}

/// The figures of merit of a run (see the [module](super) docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct MeritReport {
    /// Energy per cycle of the cycle for maximised energy output over the run's states, J.
    pub cmeo_energy_per_cycle_j: f64,
    /// Zi et al.'s structural figure of merit `2ε₀E_m/(σ²S x_max)`, dimensionless (`None`
    /// without charge or stroke).
    pub fom_s: Option<f64>,
    /// The stroke `x_max` of `fom_s`, m.
    pub stroke_m: f64,
    /// The largest ideal-switch cycle inside the breakdown boundary, J (`None` where every
    /// cycle breaks down).
    pub breakdown_limited_energy_per_cycle_j: Option<f64>,
    /// The CMEO cycle's switching states: short-circuit charges, C, and terminal voltages
    /// at the start of each switching stroke, V, as the V–Q polygon's four corners
    /// `[(Q_a, 0), (Q_a, V_1), (Q_b, 0), (Q_b, V_2)]` in the order the cycle runs them.
    pub cmeo_cycle_vq: [[f64; 2]; 4],
    /// Cycles of the run per excitation period (counted on `Q_sc`), `None` if not counted.
    pub cycles_per_period: Option<f64>,
    /// The run's energy per cycle, J (`None` without cycles or energy).
    pub energy_per_cycle_j: Option<f64>,
    /// The run's energy per cycle as a fraction of the CMEO, dimensionless.
    pub energy_fraction_of_cmeo: Option<f64>,
}

/// The figures of merit of the transducer `params` over the states `set`, with the stroke
/// `stroke`, m (see [`MeritReport::stroke_m`]); `None` for fewer than two states.
pub fn figures_of_merit(params: &HarvesterParams, set: &StateSet, stroke: f64) -> Option<MeritReport> {
    let (e, a, b) = set.cmeo()?;
    let sigma = params.charge_density;
    let norm = sigma * sigma * params.area * stroke;
    let fom_s = (norm > 0.0 && norm.is_finite()).then(|| 2.0 * EPSILON_0 * e / norm);
    let (qa, qb) = (a.short_circuit_charge, b.short_circuit_charge);
    Some(MeritReport {
        cmeo_energy_per_cycle_j: e,
        fom_s,
        stroke_m: stroke,
        breakdown_limited_energy_per_cycle_j: set.breakdown_limited().map(|x| x.0),
        cmeo_cycle_vq: [[qa, 0.0], [qa, b.voltage(qa)], [qb, 0.0], [qb, a.voltage(qb)]],
        cycles_per_period: None,
        energy_per_cycle_j: None,
        energy_fraction_of_cmeo: None,
    })
}
