//! The field energy of a transducer, the voltage it implies and the electrostatic forces on
//! its plates (two-way coupling; docs/MODEL.md §2).
//!
//! ## Derivation (parallel plates, Gauss's law)
//!
//! **Freestanding mode.** From the top electrode down: electrode (charge q₁), dielectric film 1
//! (thickness d₁, ε_r1) whose gap-facing surface carries the tribo-charge −σS, air gap D₁,
//! the freestanding metal layer (+2σS), air gap D₂, film 2 (−σS on its gap-facing surface,
//! thickness d₂, ε_r2), bottom electrode (q₂). The stack is neutral (q₁ + q₂ = 0), so the field
//! outside it vanishes and Gauss's law gives the field in each layer from the charge above it:
//!
//! ```text
//! film 1: q₁/(ε₀ε_r1 S)   gap 1: (q₁ − σS)/(ε₀S)   gap 2: (q₁ + σS)/(ε₀S)   film 2: q₁/(ε₀ε_r2 S)
//! ```
//!
//! With the transferred charge Q = −q₁ the field energy `½∫ε E² dV` is
//!
//! ```text
//! U(Q, D₁, D₂) = [Q² d₀ + (Q + σS)² D₁ + (σS − Q)² D₂] / (2ε₀S),    d₀ = d₁/ε_r1 + d₂/ε_r2.
//! ```
//!
//! Its charge derivative is the terminal voltage with the opposite sign,
//!
//! ```text
//! ∂U/∂Q = Q(d₀ + D₁ + D₂)/(ε₀S) − σ(D₂ − D₁)/ε₀ = Q/C − V_oc = −V,
//! ```
//!
//! which is the exact law `V = −Q/C + σ(D₂ − D₁)/ε₀` ([`VocModel::Exact`]): the circuit takes
//! power `V·dQ/dt = −∂U/∂Q · dQ/dt` out of the field. The generalised force conjugate to a
//! gap at constant charge is
//!
//! ```text
//! G₁ = −∂U/∂D₁ = −(Q + σS)²/(2ε₀S),    G₂ = −∂U/∂D₂ = −(σS − Q)²/(2ε₀S),
//! ```
//!
//! the attraction `E²ε₀S/2` of the field in that gap: negative (it closes the gap) and
//! independent of the gaps. So `dU/dt = −V·I − Σ G_k dD_k/dt` along any motion: what the
//! forces take from the masses and what the load takes from the field add up to −dU/dt.
//!
//! **Contact-separation mode.** Electrode with film (−σS on its surface) — gap D — the second
//! electrode, whose own tribo-charge +σS sits on its face. The same steps give
//! `U = [Q² d₀ + (σS − Q)² D]/(2ε₀S)`, `−∂U/∂Q = −Q/C + σD/ε₀ = V` and `G = −(σS − Q)²/(2ε₀S)`.
//!
//! **The paper's law** `V_oc = 2σD₂/ε₀` ([`VocModel::Paper`]) is not the voltage of this charge
//! arrangement: it fixes ∂U/∂Q but no charge distribution gives it, so the gap dependence of
//! U, and with it the force on the plates, is undefined. [`Electrostatics::new`] refuses it.
//!
//! ## Forces on the masses
//!
//! The gap between mass k and k + 1 is `D_k = δ_k − (x_{k+1} − x_k)`, so a generalised force
//! G_k on gap k is the force `+G_k` on mass k and `−G_k` on mass k + 1
//! ([`Electrostatics::mass_forces`]).

use thiserror::Error;

use super::params::{EPSILON_0, VocModel};
use super::transducer::Transducer;

/// Why a transducer has no field energy (and so no electrostatic force).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum NoFieldEnergy {
    /// The paper's open-circuit voltage law.
    #[error(
        "two-way coupling needs voc_model = \"exact\": the paper's V_oc = 2σD₂/ε₀ is not the \
         voltage of any charge arrangement of the parallel-plate model, so it defines no field \
         energy and no force on the plates (docs/MODEL.md §2)"
    )]
    PaperVoc,
}

/// One air gap's share of the field energy: `(a·Q + b)² D / (2ε₀S)`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct GapCharge {
    /// The contact (0-based) whose gap this is.
    contact: usize,
    /// Sign of Q in the charge facing the gap (±1).
    a: f64,
    /// The fixed tribo-charge facing the gap, C.
    b: f64,
}

/// The field energy of a transducer as a function of the transferred charge and the gaps,
/// with the voltage and the forces it implies (see the module docs for the derivation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Electrostatics {
    /// 1/(ε₀S), 1/(F·m).
    inv_eps_area: f64,
    /// d₀, m.
    d0: f64,
    gaps: [GapCharge; 2],
    ngaps: usize,
}

impl Electrostatics {
    /// The field energy of `transducer`; an error for the paper's open-circuit voltage law.
    pub fn new(transducer: &Transducer) -> Result<Self, NoFieldEnergy> {
        match transducer {
            Transducer::Freestanding(f) => {
                if f.voc_model == VocModel::Paper {
                    return Err(NoFieldEnergy::PaperVoc);
                }
                let sigma_area = f.eps_area * f.charge_density / EPSILON_0;
                Ok(Electrostatics {
                    inv_eps_area: 1.0 / f.eps_area,
                    d0: f.d0,
                    gaps: [
                        GapCharge {
                            contact: f.contacts[0],
                            a: 1.0,
                            b: sigma_area,
                        },
                        GapCharge {
                            contact: f.contacts[1],
                            a: -1.0,
                            b: sigma_area,
                        },
                    ],
                    ngaps: 2,
                })
            }
            Transducer::ContactSeparation(c) => {
                let sigma_area = c.eps_area * c.charge_density / EPSILON_0;
                let gap = GapCharge {
                    contact: c.contact,
                    a: -1.0,
                    b: sigma_area,
                };
                Ok(Electrostatics {
                    inv_eps_area: 1.0 / c.eps_area,
                    d0: c.d0,
                    gaps: [gap, gap],
                    ngaps: 1,
                })
            }
        }
    }

    fn gap_charges(&self) -> &[GapCharge] {
        &self.gaps[..self.ngaps]
    }

    /// Field energy U, J, at transferred charge `q` (C) and the chain's gaps (m, indexed by
    /// contact).
    pub fn energy(&self, q: f64, gaps: &[f64]) -> f64 {
        let films = q * q * self.d0;
        let air: f64 = self
            .gap_charges()
            .iter()
            .map(|g| (g.a * q + g.b).powi(2) * gaps[g.contact])
            .sum();
        0.5 * (films + air) * self.inv_eps_area
    }

    /// Terminal voltage `V = −∂U/∂Q`, V, at charge `q` (C) and gaps (m).
    pub fn voltage(&self, q: f64, gaps: &[f64]) -> f64 {
        let films = q * self.d0;
        let air: f64 = self
            .gap_charges()
            .iter()
            .map(|g| g.a * (g.a * q + g.b) * gaps[g.contact])
            .sum();
        -(films + air) * self.inv_eps_area
    }

    /// The generalised forces `G_k = −∂U/∂D_k`, N, at charge `q` (C), as (contact, force)
    /// pairs; negative values close the gap. They do not depend on the gaps.
    pub fn gap_forces(&self, q: f64) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.gap_charges()
            .iter()
            .map(move |g| (g.contact, -0.5 * (g.a * q + g.b).powi(2) * self.inv_eps_area))
    }

    /// Adds the electrostatic force on every mass, N, at charge `q` (C) to `forces` (length N,
    /// the chain's masses; a force is positive along the positions x).
    pub fn mass_forces(&self, q: f64, forces: &mut [f64]) {
        for (k, g) in self.gap_forces(q) {
            forces[k] += g;
            forces[k + 1] -= g;
        }
    }

    /// The coefficients `(c₀, c₁, c₂)` of each gap force as a polynomial in the charge,
    /// `G_k(Q) = c₀ + c₁Q + c₂Q²` (N, N/C, N/C²), as (contact, coefficients) pairs.
    pub fn gap_force_polynomials(&self) -> impl Iterator<Item = (usize, [f64; 3])> + '_ {
        self.gap_charges().iter().map(|g| {
            let s = -0.5 * self.inv_eps_area;
            (g.contact, [s * g.b * g.b, s * 2.0 * g.a * g.b, s * g.a * g.a])
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::electrical::{HarvesterParams, TransducerMode};

    fn transducer(mode: TransducerMode, voc_model: VocModel) -> Transducer {
        HarvesterParams {
            mode,
            voc_model,
            ..HarvesterParams::default()
        }
        .transducer()
    }

    /// The energy's charge derivative (central difference) is minus the transducer's own
    /// voltage law `−Q/C + V_oc`; its gap derivatives are minus the gap forces.
    #[test]
    fn derivatives_of_the_energy_are_the_voltage_and_the_forces() {
        for mode in [TransducerMode::Freestanding, TransducerMode::ContactSeparation] {
            let t = transducer(mode, VocModel::Exact);
            let e = Electrostatics::new(&t).unwrap();
            let gaps = [0.0123, 0.0071];
            let scale = t.charge_scale();
            for q in [-0.7 * scale, -0.1 * scale, 0.0, 0.3 * scale, 1.2 * scale] {
                let law = -q / t.capacitance(&gaps) + t.open_circuit_voltage(&gaps);
                let v = e.voltage(q, &gaps);
                assert!(
                    (v - law).abs() <= 1e-12 * law.abs().max(1.0),
                    "{mode:?}: {v} vs {law}"
                );
                let h = 1e-4 * scale;
                let du_dq = (e.energy(q + h, &gaps) - e.energy(q - h, &gaps)) / (2.0 * h);
                assert!(
                    (-du_dq - law).abs() <= 1e-6 * law.abs(),
                    "{mode:?}: {du_dq} vs {law}"
                );
                for (k, g) in e.gap_forces(q) {
                    let dg = 1e-6;
                    let mut up = gaps;
                    up[k] += dg;
                    let mut down = gaps;
                    down[k] -= dg;
                    let du = (e.energy(q, &up) - e.energy(q, &down)) / (2.0 * dg);
                    assert!(g < 0.0, "{mode:?}: an attraction");
                    assert!((-du - g).abs() <= 1e-7 * g.abs(), "{mode:?} gap {k}: {du} vs {g}");
                }
                let mut poly = e.gap_force_polynomials();
                for (k, g) in e.gap_forces(q) {
                    let (kp, c) = poly.next().unwrap();
                    assert_eq!(k, kp);
                    let p = c[0] + c[1] * q + c[2] * q * q;
                    assert!((p - g).abs() <= 1e-12 * g.abs());
                }
            }
        }
    }

    /// The issue's estimate: σ²S/(2ε₀) across one gap at Q = 0 (0.127 N for the paper's
    /// σ = 15 µC/m², S = 0.01 m²), equal and opposite on the two masses of the gap.
    #[test]
    fn the_force_at_zero_charge_is_the_textbook_attraction() {
        let p = HarvesterParams {
            voc_model: VocModel::Exact,
            ..HarvesterParams::default()
        };
        let e = Electrostatics::new(&p.transducer()).unwrap();
        let expected = p.charge_density.powi(2) * p.area / (2.0 * EPSILON_0);
        let mut forces = [0.0; 3];
        e.mass_forces(0.0, &mut forces);
        assert!((forces[0] + expected).abs() < 1e-12 * expected, "{forces:?}");
        assert!(forces[1].abs() < 1e-12 * expected, "{forces:?}");
        assert!((forces[2] - expected).abs() < 1e-12 * expected, "{forces:?}");
    }

    #[test]
    fn the_paper_law_has_no_energy() {
        let t = transducer(TransducerMode::Freestanding, VocModel::Paper);
        let err = Electrostatics::new(&t).unwrap_err();
        assert!(err.to_string().contains("voc_model = \"exact\""));
    }
}
