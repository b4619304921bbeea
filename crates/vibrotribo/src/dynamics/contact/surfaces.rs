//! The event functions of the contacts: the gap of an open contact and the force of a
//! closed one, as explicit [`Signal`]s of time.

use super::super::signal::Signal;
use super::super::simulator::Simulator;

/// The force band of a resting contact, in multiples of the force that corresponds to the
/// acceleration tolerance: a contact rests while `|w| ≤ acc_tol`, and its force must leave
/// `±REST_BAND` times that before it sticks or parts, so that the next contact decision sees
/// it clearly pressing or clearly separating.
const REST_BAND: f64 = 4.0;

impl Simulator {
    /// Gap of open contact k as a [`Signal`]: d_k = δ_k + o_k^U + s_U − s_L.
    pub(in crate::dynamics) fn gap_signal(&self, k: usize) -> Signal {
        if self.stop_at(k).is_some() {
            return self.stop_gap_signal(k);
        }
        let u = self.cluster_of(k);
        let l = u + 1;
        debug_assert_eq!(self.clusters[l].first, k + 1);
        let w = self.forcing.omega;
        let mut sig = Signal::default();
        sig.add_constant(self.params.gaps[k]);
        sig.add_constant(self.offsets[k] - self.offsets[self.clusters[u].first]);
        sig.add_oscillator(u, &self.clusters[u].oscillator, 1.0, 0.0, w);
        sig.add_oscillator(l, &self.clusters[l].oscillator, -1.0, 0.0, w);
        sig
    }

    /// Contact force of closed contact j (N, compressive positive) as a [`Signal`]:
    /// `N_j = Σ_{i∈G, i≤j} m_i (a_G − a_i)`, written as
    /// `e₀ + e₁ (s − y) + e₂ (s' − y')` for the cluster coordinate s.
    pub(in crate::dynamics) fn force_signal(&self, j: usize) -> Signal {
        if let Some(sig) = self.anchored_force_signal(j) {
            return sig;
        }
        let g = self.cluster_of(j);
        let c = &self.clusters[g];
        let kc = &self.consts[g];
        let base = self.offsets[c.first];
        let (mut mj, mut cj, mut kj, mut fj) = (0.0, 0.0, 0.0, 0.0);
        for i in c.first..=j {
            mj += self.params.masses[i];
            cj += self.params.damping[i];
            kj += self.params.stiffness[i];
            fj += self.params.stiffness[i] * (self.offsets[i] - base);
        }
        let r = mj / kc.mass;
        let e1 = kj - r * kc.stiffness;
        let e2 = cj - r * kc.damping;
        // Σ_G k_i o_i = −F₀.
        let e0 = fj + r * kc.force;
        let w = self.forcing.omega;
        let a = self.forcing.amplitude;
        let mut sig = Signal::default();
        sig.add_constant(fj);
        sig.add_constant(r * kc.force);
        debug_assert!((sig.constant - e0).abs() <= 1e-12 * sig.constant_mag.max(1e-300));
        sig.add_oscillator(g, &c.oscillator, e1, e2, w);
        // − e₁ y − e₂ y' with y = A sin ωt, y' = Aω cos ωt.
        sig.add_harmonic(-e2 * a * w, -e1 * a);
        if !self.forces.is_empty() {
            // The external forces: r Σ_G f_i − Σ_{i≤j} f_i (the cluster's share is in F₀ and
            // in the oscillator's particular polynomial).
            sig.add_constant(-self.forces.range_constant(c.first, j));
            sig.add_polynomial(&self.forces.range_poly(c.first, c.last), r);
            sig.add_polynomial(&self.forces.range_poly(c.first, j), -1.0);
        }
        sig
    }

    /// The force band of resting contact k, N: [`REST_BAND`] times the acceleration tolerance
    /// times the reduced mass of the two parts of its cluster (the force that makes their
    /// relative acceleration equal to the tolerance).
    pub(in crate::dynamics) fn rest_band(&self, k: usize) -> f64 {
        let c = &self.clusters[self.cluster_of(k)];
        let upper: f64 = self.params.masses[c.first..=k].iter().sum();
        let lower: f64 = self.params.masses[k + 1..=c.last].iter().sum();
        REST_BAND * self.acc_tol * upper * lower / (upper + lower)
    }
}
