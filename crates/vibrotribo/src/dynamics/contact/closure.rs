//! The state of each contact (open, stuck, chattering, resting), the clusters it makes, the
//! rounding-level tolerances of the contact decisions, and the geometric corrections that
//! keep the gaps non-negative.

use super::super::simulator::Simulator;

/// The state of one contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(in crate::dynamics) enum Closure {
    /// Apart, or touching with a rounding-level relative velocity.
    Open,
    /// Stuck: the two sides press and move as one cluster.
    Stuck,
    /// A chatter tail being jumped over: one cluster until `t_acc`, s, after `impacts`
    /// impacts resolved one by one.
    Chatter {
        t_acc: f64,
        impacts: u32,
    },
    // Touching with zero force (see the module docs): one cluster, but no event.
    Resting,
}

impl Closure {
    /// Whether the two sides move as one cluster.
    pub(in crate::dynamics) fn is_closed(self) -> bool {
        !matches!(self, Closure::Open)
    }

    /// Whether the contact carries a compressive force (it entered by a `Stick` and leaves
    /// by a `Release`).
    pub(in crate::dynamics) fn presses(self) -> bool {
        matches!(self, Closure::Stuck | Closure::Chatter { .. })
    }
}

/// Relative rounding allowance for position and velocity tolerances.
pub(super) const TOL: f64 = 64.0 * f64::EPSILON;

/// Relative allowance for the acceleration tolerance of the sticking decision. It is kept
/// well above the rounding noise of the contact-force event function, so that a contact that
/// sticks carries a force its release search can tell from zero (no stick/release ping-pong).
const ACC_TOL: f64 = 4096.0 * f64::EPSILON;

impl Simulator {
    /// Rounding-level tolerances for positions, velocities and accelerations, from the scale
    /// of the current state, or of the terms the clusters' closed forms sum it from where
    /// those are larger (near resonance, mid-transient), since they set its rounding.
    pub(in crate::dynamics) fn refresh_tolerances(&mut self) {
        let p = &self.params;
        let wn2_max = p
            .masses
            .iter()
            .zip(&p.stiffness)
            .map(|(m, k)| k / m)
            .fold(0.0, f64::max);
        let xmax = self.x.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let vmax = self.v.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let length =
            xmax.max(self.term_scale) + self.offsets[self.offsets.len() - 1] + p.excitation.amplitude + 1e-9;
        let omega = self.forcing.omega;
        let speed = vmax + (p.excitation.amplitude * omega) + wn2_max.sqrt() * length;
        let mut accel = wn2_max * length + speed * wn2_max.sqrt() + p.excitation.amplitude * omega * omega;
        if !self.forces.is_empty() {
            // The external forces are terms of every acceleration the decisions compare.
            accel += self.forces.accel_scale(&p.masses, self.t);
        }
        self.pos_tol = TOL * length;
        self.vel_tol = TOL * speed;
        self.acc_tol = ACC_TOL * accel;
    }

    /// Current gap at contact k, m (negative: overlap).
    #[inline]
    pub(in crate::dynamics) fn gap(&self, k: usize) -> f64 {
        if k + 1 < self.x.len() {
            self.params.gaps[k] - (self.x[k + 1] - self.x[k])
        } else {
            self.stop_gap(k)
        }
    }

    /// Total mass and range of the cluster containing mass `i`, following the current
    /// closures (clusters may have been merged since the last rebuild).
    pub(in crate::dynamics) fn cluster_range(&self, i: usize) -> (usize, usize) {
        let mut first = i;
        while first > 0 && self.closure[first - 1].is_closed() {
            first -= 1;
        }
        let mut last = i;
        while last + 1 < self.x.len() && self.closure[last].is_closed() {
            last += 1;
        }
        (first, last)
    }

    pub(in crate::dynamics) fn range_mass(&self, (first, last): (usize, usize)) -> f64 {
        self.params.masses[first..=last].iter().sum()
    }

    /// Gives the masses of `range` their common centre-of-mass velocity and consistent
    /// positions.
    pub(in crate::dynamics) fn merge_range(&mut self, (first, last): (usize, usize)) {
        let base = self.offsets[first];
        let (mut m, mut p, mut q) = (0.0, 0.0, 0.0);
        for i in first..=last {
            let mi = self.params.masses[i];
            m += mi;
            p += mi * self.v[i];
            q += mi * (self.x[i] - (self.offsets[i] - base));
        }
        for i in first..=last {
            self.v[i] = p / m;
            self.x[i] = q / m + (self.offsets[i] - base);
        }
    }

    /// Removes rounding-level overlap at open contacts: at an event located to within an ulp
    /// of time, a fast closing speed still leaves the gap slightly negative (v × ulp(t)). The
    /// two clusters are pushed apart to zero gap about their common centre of mass (a shift of
    /// order 1e-15 m; momentum is untouched).
    pub(in crate::dynamics) fn project_contacts(&mut self) {
        for _sweep in 0..3 {
            let mut moved = false;
            for k in 0..self.closure.len() {
                if self.closure[k].is_closed() {
                    continue;
                }
                let gap = self.gap(k);
                if gap >= 0.0 {
                    continue;
                }
                debug_assert!(gap > -1e6 * self.pos_tol, "overlap {gap:e} at contact {k}");
                if self.project_stop(k, gap) {
                    moved = true;
                    continue;
                }
                let up = self.cluster_range(k);
                let low = self.cluster_range(k + 1);
                let (mu, ml) = (self.range_mass(up), self.range_mass(low));
                let overlap = -gap;
                for i in up.0..=up.1 {
                    self.x[i] += overlap * ml / (mu + ml);
                }
                for i in low.0..=low.1 {
                    self.x[i] -= overlap * mu / (mu + ml);
                }
                // Rounding of the shift itself: make the lower side exact.
                let residual = self.gap(k);
                if residual < 0.0 {
                    for i in low.0..=low.1 {
                        self.x[i] += residual;
                    }
                }
                moved = true;
            }
            if !moved {
                break;
            }
        }
    }
}
