//! Triboelectric transducers: capacitance C and open-circuit voltage V_oc as functions of the
//! gaps (seed eqs. 12–13; docs/MODEL.md §2).
//!
//! Both transducers have an elastance 1/C and an open-circuit voltage that are *linear* in the
//! gaps, so the equilibrium charge `Q_eq = C·V_oc` and its rate `dQ_eq/dt` are explicit
//! functions of the gaps and their rates. The charge solver integrates the deviation
//! `u = Q − Q_eq = −C·V` from equilibrium, which holds the load voltage without cancellation.

use super::params::{EPSILON_0, VocModel};

/// The electrical state of a transducer at one instant, given the gaps and their rates.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TransducerState {
    /// Elastance 1/C, 1/F.
    pub elastance: f64,
    /// Open-circuit voltage V_oc, V.
    pub voc: f64,
    /// Equilibrium (short-circuit) charge `Q_eq = C·V_oc`, C.
    pub equilibrium_charge: f64,
    /// Its rate `dQ_eq/dt`, A: the short-circuit current.
    pub equilibrium_current: f64,
}

impl TransducerState {
    /// Capacitance C, F.
    pub fn capacitance(&self) -> f64 {
        1.0 / self.elastance
    }
}

/// The paper's freestanding contact mode (seed eqs. 12–13): electrodes with dielectric films
/// on the two outer masses, a freestanding aluminium layer on the middle one.
///
/// `C = ε₀S / (d₀ + D₁ + D₂)`, and `V_oc = 2σD₂/ε₀` ([`VocModel::Paper`]) or
/// `V_oc = σ(D₂ − D₁)/ε₀` ([`VocModel::Exact`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Freestanding {
    /// ε₀·S, F·m.
    pub eps_area: f64,
    /// d₀ = d₁/ε_r1 + d₂/ε_r2, m.
    pub d0: f64,
    /// Surface charge density σ, C/m².
    pub charge_density: f64,
    /// Open-circuit voltage law.
    pub voc_model: VocModel,
    /// Contacts (0-based) holding D₁ and D₂.
    pub contacts: [usize; 2],
}

impl Freestanding {
    /// Capacitance C, F, at gaps D₁, D₂ (m).
    pub fn capacitance(&self, d1: f64, d2: f64) -> f64 {
        self.eps_area / (self.d0 + d1 + d2)
    }

    /// Open-circuit voltage V_oc, V, at gaps D₁, D₂ (m).
    pub fn open_circuit_voltage(&self, d1: f64, d2: f64) -> f64 {
        self.charge_density * self.voc_length(d1, d2) / EPSILON_0
    }

    /// The length L with `V_oc = σL/ε₀`, m.
    fn voc_length(&self, d1: f64, d2: f64) -> f64 {
        match self.voc_model {
            VocModel::Paper => 2.0 * d2,
            VocModel::Exact => d2 - d1,
        }
    }
}

/// Two-plate contact-separation mode on one contact: `C = ε₀S/(d₀ + D)`, `V_oc = σD/ε₀`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSeparation {
    /// ε₀·S, F·m.
    pub eps_area: f64,
    /// d₀ = d₁/ε_r1 + d₂/ε_r2, m.
    pub d0: f64,
    /// Surface charge density σ, C/m².
    pub charge_density: f64,
    /// The contact (0-based) whose gap D separates the plates.
    pub contact: usize,
}

impl ContactSeparation {
    /// Capacitance C, F, at gap D (m).
    pub fn capacitance(&self, d: f64) -> f64 {
        self.eps_area / (self.d0 + d)
    }

    /// Open-circuit voltage V_oc, V, at gap D (m).
    pub fn open_circuit_voltage(&self, d: f64) -> f64 {
        self.charge_density * d / EPSILON_0
    }
}

/// A triboelectric transducer of either mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transducer {
    /// Freestanding contact mode (the paper's).
    Freestanding(Freestanding),
    /// Two-plate contact-separation mode.
    ContactSeparation(ContactSeparation),
}

impl Transducer {
    /// Capacitance C, F, at the chain's gaps (m, indexed by contact).
    pub fn capacitance(&self, gaps: &[f64]) -> f64 {
        match self {
            Transducer::Freestanding(f) => f.capacitance(gaps[f.contacts[0]], gaps[f.contacts[1]]),
            Transducer::ContactSeparation(c) => c.capacitance(gaps[c.contact]),
        }
    }

    /// Open-circuit voltage V_oc, V, at the chain's gaps (m, indexed by contact).
    pub fn open_circuit_voltage(&self, gaps: &[f64]) -> f64 {
        match self {
            Transducer::Freestanding(f) => f.open_circuit_voltage(gaps[f.contacts[0]], gaps[f.contacts[1]]),
            Transducer::ContactSeparation(c) => c.open_circuit_voltage(gaps[c.contact]),
        }
    }

    /// Full state from the chain's gaps (m) and their rates (m/s), indexed by contact (the
    /// charge solver's own evaluation, `ChargeMap`).
    pub fn state(&self, gaps: &[f64], rates: &[f64]) -> TransducerState {
        ChargeMap::new(self).state_with_rates(gaps, rates)
    }

    /// The contacts (0-based) whose gaps this transducer reads.
    pub fn contacts(&self) -> &[usize] {
        match self {
            Transducer::Freestanding(f) => &f.contacts,
            Transducer::ContactSeparation(c) => std::slice::from_ref(&c.contact),
        }
    }

    /// Charge scale σS, C (the charge a fully separated transducer can move).
    pub fn charge_scale(&self) -> f64 {
        let (eps_area, sigma) = match self {
            Transducer::Freestanding(f) => (f.eps_area, f.charge_density),
            Transducer::ContactSeparation(c) => (c.eps_area, c.charge_density),
        };
        (eps_area * sigma / EPSILON_0).abs()
    }

    /// Voltage scale σd₀/ε₀, V (the open-circuit voltage of a gap as thick as the films).
    pub fn voltage_scale(&self) -> f64 {
        let (d0, sigma) = match self {
            Transducer::Freestanding(f) => (f.d0, f.charge_density),
            Transducer::ContactSeparation(c) => (c.d0, c.charge_density),
        };
        (sigma * d0 / EPSILON_0).abs()
    }
}

/// Both transducers in the form the solver evaluates at every stage point: with
/// `s = d₀ + Σ σₖ Dₖ` and `L = Σ λₖ Dₖ` over (at most) two contacts, the elastance is `s/(ε₀S)`,
/// `V_oc = σL/ε₀` and `Q_eq = σS·L/s` (one division).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ChargeMap {
    contacts: [usize; 2],
    /// Weights of the gaps in `s` and in `L`.
    s_weights: [f64; 2],
    l_weights: [f64; 2],
    d0: f64,
    inv_eps_area: f64,
    /// σ/ε₀, V/m.
    sigma_over_eps: f64,
    /// σS, C.
    sigma_area: f64,
}

impl ChargeMap {
    pub(crate) fn new(t: &Transducer) -> Self {
        match t {
            Transducer::Freestanding(f) => {
                let l_weights = match f.voc_model {
                    VocModel::Paper => [0.0, 2.0],
                    VocModel::Exact => [-1.0, 1.0],
                };
                ChargeMap {
                    contacts: f.contacts,
                    s_weights: [1.0, 1.0],
                    l_weights,
                    d0: f.d0,
                    inv_eps_area: 1.0 / f.eps_area,
                    sigma_over_eps: f.charge_density / EPSILON_0,
                    sigma_area: f.eps_area * f.charge_density / EPSILON_0,
                }
            }
            Transducer::ContactSeparation(c) => ChargeMap {
                contacts: [c.contact, c.contact],
                s_weights: [1.0, 0.0],
                l_weights: [1.0, 0.0],
                d0: c.d0,
                inv_eps_area: 1.0 / c.eps_area,
                sigma_over_eps: c.charge_density / EPSILON_0,
                sigma_area: c.eps_area * c.charge_density / EPSILON_0,
            },
        }
    }

    /// Elastance, open-circuit voltage and equilibrium charge at the chain's gaps (m); the
    /// equilibrium current is not computed (left 0).
    #[inline]
    pub(crate) fn state(&self, gaps: &[f64]) -> TransducerState {
        let [a, b] = self.contacts;
        let (da, db) = (gaps[a], gaps[b]);
        let s = self.d0 + (self.s_weights[0] * da + self.s_weights[1] * db);
        let l = self.l_weights[0] * da + self.l_weights[1] * db;
        TransducerState {
            elastance: s * self.inv_eps_area,
            voc: self.sigma_over_eps * l,
            equilibrium_charge: self.sigma_area * l / s,
            equilibrium_current: 0.0,
        }
    }

    /// The full state at the chain's gaps (m) and their rates (m/s), with the same rounding as
    /// [`state`](Self::state).
    #[inline]
    pub(crate) fn state_with_rates(&self, gaps: &[f64], rates: &[f64]) -> TransducerState {
        let [a, b] = self.contacts;
        let s = self.d0 + (self.s_weights[0] * gaps[a] + self.s_weights[1] * gaps[b]);
        let l = self.l_weights[0] * gaps[a] + self.l_weights[1] * gaps[b];
        let ds = self.s_weights[0] * rates[a] + self.s_weights[1] * rates[b];
        let dl = self.l_weights[0] * rates[a] + self.l_weights[1] * rates[b];
        TransducerState {
            equilibrium_current: self.sigma_area * (dl * s - l * ds) / (s * s),
            ..self.state(gaps)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::electrical::{HarvesterParams, TransducerMode};

    /// The solver's evaluation against the textbook formulas: C and V_oc directly, and the
    /// short-circuit current as the derivative of C·V_oc along a gap path (central difference).
    #[test]
    fn state_matches_the_closed_forms() {
        for (mode, voc_model) in [
            (TransducerMode::Freestanding, VocModel::Paper),
            (TransducerMode::Freestanding, VocModel::Exact),
            (TransducerMode::ContactSeparation, VocModel::Paper),
        ] {
            let t = HarvesterParams {
                mode,
                voc_model,
                ..HarvesterParams::default()
            }
            .transducer();
            let path = |tau: f64| [0.012 + 0.004 * tau, 0.007 - 0.003 * tau];
            let rates = [0.004, -0.003];
            let gaps = path(0.0);
            let s = t.state(&gaps, &rates);
            let qeq = |tau: f64| t.capacitance(&path(tau)) * t.open_circuit_voltage(&path(tau));
            let h = 1e-4;
            let dq = (qeq(h) - qeq(-h)) / (2.0 * h);
            let what = format!("{mode:?}, {voc_model:?}");
            assert!(
                (s.capacitance() / t.capacitance(&gaps) - 1.0).abs() < 1e-14,
                "{what}"
            );
            assert!(
                (s.voc / t.open_circuit_voltage(&gaps) - 1.0).abs() < 1e-14,
                "{what}"
            );
            assert!((s.equilibrium_charge / qeq(0.0) - 1.0).abs() < 1e-14, "{what}");
            assert!(
                (s.equilibrium_current / dq - 1.0).abs() < 1e-7,
                "{what}: {} vs {dq}",
                s.equilibrium_current
            );
        }
    }
}
