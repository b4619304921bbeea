//! Impacts between clusters (Newton's law, simultaneous impacts resolved pairwise) and the
//! replacement of a chatter tail by its accumulation point.

use super::super::observer::EventKind;
use super::super::simulator::Simulator;
use super::closure::{Closure, TOL};
use crate::error::SimError;

impl Simulator {
    /// Applies pairwise cluster impacts until no closed contact approaches, logs one impact
    /// per contact struck (and a grazing touch of speed 0 at `trigger` if it was reached with
    /// no closing speed), then replaces each geometric chatter tail by its accumulation point
    /// where it is safe to. Returns whether any impulse was applied. Resting contacts take
    /// part as the open touching contacts they are (Newton's cradle); they stay resting if
    /// nothing is struck, and are decided again by [`settle`](Self::settle) otherwise.
    pub(in crate::dynamics) fn resolve_impacts(&mut self, trigger: usize) -> Result<bool, SimError> {
        let ncont = self.closure.len();
        for (closure, resting) in self.closure.iter_mut().zip(self.scratch_resting.iter_mut()) {
            *resting = *closure == Closure::Resting;
            if *resting {
                *closure = Closure::Open;
            }
        }
        let mut iterations = 0;
        loop {
            let mut best: Option<(usize, f64)> = None;
            for k in 0..ncont {
                if self.closure[k].is_closed() {
                    continue;
                }
                let gap = self.gap(k);
                // The trigger is at zero gap by the search's verdict.
                if gap > self.pos_tol && k != trigger {
                    continue;
                }
                let vc = self.closing_speed(k);
                if vc > self.vel_tol {
                    if self.scratch_first_speed[k].is_nan() {
                        self.scratch_first_speed[k] = vc;
                    }
                    if best.is_none_or(|(_, b)| vc > b) {
                        best = Some((k, vc));
                    }
                }
            }
            let Some((k, vc)) = best else { break };
            iterations += 1;
            if iterations > self.options.max_impact_iterations {
                return Err(SimError::ImpactIteration {
                    t: self.t,
                    iterations,
                });
            }
            let mu = self.params.contact_restitution(k);
            if self.stop_impulse(k, vc, mu) {
                continue;
            }
            let up = self.cluster_range(k);
            let low = self.cluster_range(k + 1);
            let mu_mass = self.range_mass(up);
            let ml_mass = self.range_mass(low);
            let impulse = (1.0 + mu) * vc * mu_mass * ml_mass / (mu_mass + ml_mass);
            for i in up.0..=up.1 {
                self.v[i] += impulse / mu_mass;
            }
            for i in low.0..=low.1 {
                self.v[i] -= impulse / ml_mass;
            }
        }
        let struck = iterations > 0;
        if !struck {
            for (closure, &resting) in self.closure.iter_mut().zip(&self.scratch_resting) {
                if resting {
                    *closure = Closure::Resting;
                }
            }
        }
        if self.scratch_first_speed[trigger].is_nan() {
            // Reached with no closing speed: a grazing touch, logged as an impact of speed 0.
            self.scratch_first_speed[trigger] = 0.0;
        }
        for k in 0..ncont {
            let before = self.scratch_first_speed[k];
            if before.is_nan() {
                continue;
            }
            let after = -self.closing_speed(k);
            if before > 0.0 {
                if before < self.last_speed[k] {
                    self.sequence[k] += 1;
                } else {
                    self.sequence[k] = 1;
                }
                self.last_speed[k] = before;
            }
            self.push_event(EventKind::Impact, k, before, after, 0);
        }
        for k in 0..ncont {
            if self.params.contact_restitution(k) < 1.0 {
                let before = self.scratch_first_speed[k];
                if before > 0.0 && !self.closure[k].is_closed() {
                    self.try_chatter_jump(k);
                }
            }
        }
        Ok(struck)
    }

    /// Free acceleration, m/s², and its rate, m/s³, of the cluster occupying `range` (its
    /// members share velocity; x of its top mass is the cluster coordinate).
    fn cluster_accel(&self, (first, last): (usize, usize)) -> (f64, f64) {
        let ph = self.phase_now;
        let (y, yd) = self.forcing.base(ph);
        let ydd = -self.forcing.omega * self.forcing.omega * y;
        let base = self.offsets[first];
        let (mut m, mut c, mut k, mut f) = (0.0, 0.0, 0.0, 0.0);
        for i in first..=last {
            m += self.params.masses[i];
            c += self.params.damping[i];
            k += self.params.stiffness[i];
            f -= self.params.stiffness[i] * (self.offsets[i] - base);
        }
        let s = self.x[first];
        let v = self.v[first];
        if self.forces.is_empty() {
            let a = (-c * (v - yd) - k * (s - y) + f) / m;
            let j = (-c * (a - ydd) - k * (v - yd)) / m;
            return (a, j);
        }
        // With the external forces on the range and their rate.
        let (fe, fe_rate) = self.forces.range_at(first, last, self.t);
        let a = (-c * (v - yd) - k * (s - y) + f + fe) / m;
        let j = (-c * (a - ydd) - k * (v - yd) + fe_rate) / m;
        (a, j)
    }

    /// After an impact at open contact k: if the rebound is the start of a chatter tail whose
    /// constant-acceleration limit is accurate to the tolerance, merge the two sides and
    /// schedule the accumulation point.
    fn try_chatter_jump(&mut self, k: usize) {
        let mu = self.params.contact_restitution(k);
        let u = -self.closing_speed(k);
        if u <= self.vel_tol {
            return; // zero rebound: settle() decides.
        }
        let (up, low) = self.side_ranges(k);
        let (au, ju) = self
            .prescribed_side_accel(k, true)
            .unwrap_or_else(|| self.cluster_accel(up.expect("a free cluster above")));
        let (al, jl) = self
            .prescribed_side_accel(k, false)
            .unwrap_or_else(|| self.cluster_accel(low.expect("a free cluster below")));
        // d'' = a_U − a_L; closing acceleration a = −d''.
        let a = al - au;
        let jerk = (ju - jl).abs();
        if a <= self.acc_tol {
            return;
        }
        let flight = 2.0 * u / a;
        let remaining = flight / (1.0 - mu);
        // First-order effect of the changing acceleration on the remaining flights
        // Σ τ_n² j/a, with a safety factor of 4 (checked against an independent bounce-by-bounce
        // integration in tests/suite/special_cases.rs).
        let error = 4.0 * jerk / a * flight * flight / (1.0 - mu * mu);
        // Resolving the next bounce individually cannot time it better than the gap's
        // rounding (about two ulps of the positions) over the rebound speed; below that, the
        // jump is the more accurate choice.
        let rounding = 2.0 * f64::EPSILON * (self.pos_tol / TOL) / u;
        let tolerance = (self.options.chatter_tolerance * self.forcing.period).max(rounding);
        if error <= tolerance && jerk * remaining <= 0.1 * a {
            self.closure[k] = Closure::Chatter {
                t_acc: self.t + remaining,
                impacts: self.sequence[k],
            };
            // Merge now (momentum-conserving; into a stop: at its velocity) so that later
            // checks see the new cluster.
            if self.stop_at(k).is_some() || self.range_anchor(self.cluster_range(k)).is_some() {
                self.merge_into_stop(k);
            } else {
                self.merge_range(self.cluster_range(k));
            }
        }
    }
}
