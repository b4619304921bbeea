//! The parallel-plate stack's field energy, written out here from docs/MODEL.md §2 (not
//! taken from the library), and what follows from it: the forces on the masses, the
//! terminal voltage and the equilibrium charge.
//!
//! ```text
//! freestanding:        U = [Q² d₀ + (Q + σS)² D₁ + (σS − Q)² D₂] / (2ε₀S)
//! contact-separation:  U = [Q² d₀ + (σS − Q)² D] / (2ε₀S)
//! ```
//!
//! with d₀ = Σ dᵢ/ε_rᵢ. The force on gap k at constant charge is G_k = −∂U/∂D_k; it acts
//! as +G_k on mass k and −G_k on mass k + 1 (D_k = δ_k − (x_{k+1} − x_k)). The terminal
//! voltage is V = −∂U/∂Q; a resistor carries I = dQ/dt = V/R.

use vibrotribo::electrical::{HarvesterParams, TransducerMode};

/// ε₀, F/m (CODATA 2018), written here rather than taken from the library.
pub const VACUUM_PERMITTIVITY: f64 = 8.854_187_812_8e-12;

/// σS, C.
fn sigma_s(h: &HarvesterParams) -> f64 {
    h.charge_density * h.area
}

/// d₀ = Σ dᵢ/ε_rᵢ, m.
fn d0(h: &HarvesterParams) -> f64 {
    h.dielectric_thickness[0] / h.relative_permittivity[0]
        + h.dielectric_thickness[1] / h.relative_permittivity[1]
}

/// The gap forces G_k = −∂U/∂D_k, N, as (k, G_k), at charge `q`, C.
pub fn gap_forces(h: &HarvesterParams, q: f64) -> Vec<(usize, f64)> {
    let sigma_s = sigma_s(h);
    let two_eps_s = 2.0 * VACUUM_PERMITTIVITY * h.area;
    match h.mode {
        TransducerMode::Freestanding => vec![
            (h.contact, -(q + sigma_s).powi(2) / two_eps_s),
            (h.contact + 1, -(sigma_s - q).powi(2) / two_eps_s),
        ],
        TransducerMode::ContactSeparation => vec![(h.contact, -(sigma_s - q).powi(2) / two_eps_s)],
    }
}

/// The forces on the `n` masses (N, positive upward) at charge `q` (C).
pub fn electrostatic_forces(h: &HarvesterParams, n: usize, q: f64) -> Vec<f64> {
    let mut f = vec![0.0; n];
    for (k, g) in gap_forces(h, q) {
        f[k] += g;
        f[k + 1] -= g;
    }
    f
}

/// The field energy U(Q, D), J.
pub fn field_energy(h: &HarvesterParams, q: f64, gaps: &[f64]) -> f64 {
    let sigma_s = sigma_s(h);
    let air = match h.mode {
        TransducerMode::Freestanding => {
            (q + sigma_s).powi(2) * gaps[h.contact] + (sigma_s - q).powi(2) * gaps[h.contact + 1]
        }
        TransducerMode::ContactSeparation => (sigma_s - q).powi(2) * gaps[h.contact],
    };
    (q * q * d0(h) + air) / (2.0 * VACUUM_PERMITTIVITY * h.area)
}

/// The terminal voltage V = −∂U/∂Q, V.
pub fn terminal_voltage(h: &HarvesterParams, q: f64, gaps: &[f64]) -> f64 {
    let sigma_s = sigma_s(h);
    let air = match h.mode {
        TransducerMode::Freestanding => (q + sigma_s) * gaps[h.contact] - (sigma_s - q) * gaps[h.contact + 1],
        TransducerMode::ContactSeparation => -(sigma_s - q) * gaps[h.contact],
    };
    -(q * d0(h) + air) / (VACUUM_PERMITTIVITY * h.area)
}

/// The charge where V = 0, C (a short circuit's charge, a resistor's at rest).
pub fn equilibrium_charge(h: &HarvesterParams, gaps: &[f64]) -> f64 {
    let sigma_s = sigma_s(h);
    match h.mode {
        TransducerMode::Freestanding => {
            let (d1, d2) = (gaps[h.contact], gaps[h.contact + 1]);
            sigma_s * (d2 - d1) / (d0(h) + d1 + d2)
        }
        TransducerMode::ContactSeparation => {
            let d = gaps[h.contact];
            sigma_s * d / (d0(h) + d)
        }
    }
}
