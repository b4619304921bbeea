//! The energy balance of a coupled run, observed from outside the coupling code (used by
//! tests/suite/coupling_checks.rs under the sine and tests/suite/coupling_base_motion.rs under random and
//! recorded base motion): the base's work W and the damping D by Gauss–Legendre quadrature of
//! the closed-form flow against the base displacement on its own pieces, the energy lost at
//! events L, the chain's energy E, and the charge and gaps of every sample.

use vibrotribo::study::{RunObserver, RunSpec, Sample};
use vibrotribo::{Event, Flow, StateView};

use super::base_motion::Base;
use super::quadrature::{Sum, gauss_legendre};

/// The terms of the balance over a run.
pub struct Balance<'a> {
    /// The base motion y(t).
    pub base: Base<'a>,
    /// Masses, kg.
    pub m: Vec<f64>,
    /// Spring stiffnesses to the base, N/m.
    pub k: Vec<f64>,
    /// Damping coefficients to the base, N·s/m.
    pub c: Vec<f64>,
    /// Gaps at rest, m.
    pub deltas: Vec<f64>,
    /// Longest quadrature interval, s.
    pub h_max: f64,
    nodes: (Vec<f64>, Vec<f64>),
    /// W_base, J.
    pub work: Sum,
    /// D_damping, J.
    pub damping: Sum,
    /// L_events: the energy lost at events, J.
    pub lost: Sum,
    /// Energy changes between pieces of flow that no event reports, J.
    pub unreported: Sum,
    /// Events seen.
    pub events: usize,
    /// Quadrature intervals summed over.
    pub quadrature_intervals: usize,
    /// Time, positions, velocities after the last flow or event.
    pub last: (f64, Vec<f64>, Vec<f64>),
    /// (time, charge, gaps) of every sample (one per period boundary).
    pub samples: Vec<(f64, f64, Vec<f64>)>,
}

impl<'a> Balance<'a> {
    /// Observes `spec`'s run under `base`; `omega_max` (rad/s) bounds the frequencies of
    /// the integrands, which sets the quadrature intervals.
    pub fn new(spec: &RunSpec, base: Base<'a>, omega_max: f64) -> Self {
        let chain = &spec.chain;
        assert!(chain.forces.is_empty() && chain.stops.upper.is_none() && chain.stops.lower.is_none());
        Balance {
            base,
            m: chain.masses.clone(),
            k: chain.stiffness.clone(),
            c: chain.damping.clone(),
            deltas: chain.gaps.clone(),
            // Products of terms up to ω_max: 12 nodes over 0.5/ω_max are exact far below
            // rounding.
            h_max: 0.5 / omega_max,
            nodes: gauss_legendre(12),
            work: Sum::default(),
            damping: Sum::default(),
            lost: Sum::default(),
            unreported: Sum::default(),
            events: 0,
            quadrature_intervals: 0,
            last: (
                0.0,
                spec.initial.positions.clone(),
                spec.initial.velocities.clone(),
            ),
            samples: Vec::new(),
        }
    }

    /// E = Σ ½ m v² + ½ k (x − y)², J.
    pub fn energy(&self, t: f64, x: &[f64], v: &[f64]) -> f64 {
        let (y, _) = self.base.value(t);
        (0..self.m.len())
            .map(|i| 0.5 * self.m[i] * v[i] * v[i] + 0.5 * self.k[i] * (x[i] - y).powi(2))
            .sum()
    }

    pub fn gaps(&self, x: &[f64]) -> Vec<f64> {
        (0..self.deltas.len())
            .map(|k| self.deltas[k] - (x[k + 1] - x[k]))
            .collect()
    }
}

impl RunObserver for Balance<'_> {
    fn flow(&mut self, flow: &Flow<'_>) {
        let n = self.m.len();
        let (a, b) = (flow.t_start, flow.t_end);
        let (mut x, mut v) = (vec![0.0; n], vec![0.0; n]);
        flow.state_at(a, &mut x, &mut v);
        assert!(
            (a - self.last.0).abs() <= 1e-12 * a.max(1.0),
            "flow at {a}, last {}",
            self.last.0
        );
        let gain = self.energy(a, &x, &v) - self.energy(a, &self.last.1, &self.last.2);
        self.unreported.add(gain);
        let (xs, ws) = std::mem::take(&mut self.nodes);
        for (p0, p1, piece) in self.base.parts(a, b) {
            let len = p1 - p0;
            if len <= 0.0 {
                continue;
            }
            let parts = (len / self.h_max).ceil().max(1.0) as usize;
            let h = len / parts as f64;
            for j in 0..parts {
                let lo = p0 + j as f64 * h;
                let hi = if j + 1 == parts { p1 } else { lo + h };
                let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                let (mut p, mut d) = (0.0, 0.0);
                for (z, w) in xs.iter().zip(&ws) {
                    let t = mid + half * z;
                    flow.state_at(t, &mut x, &mut v);
                    let (y, yd) = self.base.at(t, piece);
                    for i in 0..n {
                        let f = -self.k[i] * (x[i] - y) - self.c[i] * (v[i] - yd);
                        p += w * f * yd;
                        d += w * self.c[i] * (v[i] - yd).powi(2);
                    }
                }
                self.work.add(half * p);
                self.damping.add(half * d);
                self.quadrature_intervals += 1;
            }
        }
        self.nodes = (xs, ws);
        flow.state_at(b, &mut x, &mut v);
        self.last = (b, x, v);
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        let t = event.time;
        let before = self.energy(t, &self.last.1, &self.last.2);
        let after = self.energy(t, state.positions, state.velocities);
        self.lost.add(before - after);
        self.events += 1;
        self.last = (t, state.positions.to_vec(), state.velocities.to_vec());
    }

    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, sample: &Sample<'_>) {
        let e = sample
            .electrical
            .expect("an electrical sample at every period boundary");
        self.samples.push((sample.time, e.charge_c, sample.gaps.to_vec()));
    }
}
