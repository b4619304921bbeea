//! Sticking, release and resting by the contact linear complementarity problem.

use super::super::observer::EventKind;
use super::super::simulator::Simulator;
use super::closure::Closure;

impl Simulator {
    /// Decides which contacts at zero gap and zero relative velocity are closed, by the
    /// contact LCP (see module docs): stuck where the force is compressive, resting where the
    /// force and the gap acceleration are both zero within rounding, open where the gap
    /// accelerates apart. Logs a `Stick` for each contact that starts pressing and a `Release`
    /// for each that stops; returns the contacts that were logged. `exclude` is a contact that
    /// has just released and must not close again at once.
    ///
    /// A touching contact left open has its rounding-level relative velocity removed, the two
    /// sides taking their common centre-of-mass velocity. A `quiet` settle (after a touch that
    /// changed nothing, see `handle`) decides sticking and release as always, but starts no
    /// resting contact and adjusts no velocity.
    pub(in crate::dynamics) fn settle(&mut self, exclude: Option<usize>, quiet: bool) -> Vec<usize> {
        let ncont = self.closure.len();
        let (y, yd) = self.forcing.base(self.phase_now);
        let mut any = false;
        for k in 0..ncont {
            let cand = if Some(k) == exclude {
                false
            } else if self.closure[k].is_closed() {
                true
            } else {
                // A contact struck at this instant touches by the impact's verdict: its gap is
                // the event time's rounding times the closing speed, which can exceed the
                // rounding of the positions.
                let touching = self.gap(k) <= self.pos_tol || !self.scratch_first_speed[k].is_nan();
                touching && self.closing_speed(k).abs() <= self.vel_tol
            };
            self.scratch_candidate[k] = cand;
            any |= cand;
        }
        if !any {
            return Vec::new();
        }
        // Free accelerations and gap accelerations q_k = a_k − a_{k+1}.
        let p = &self.params;
        let forced = !self.forces.is_empty();
        let t = self.t;
        let free = |i: usize| {
            let a = (-p.damping[i] * (self.v[i] - yd) - p.stiffness[i] * (self.x[i] - y)) / p.masses[i];
            if forced {
                a + self.forces.at(i, t).0 / p.masses[i]
            } else {
                a
            }
        };
        for k in 0..ncont {
            let q = if self.stop_at(k).is_some() {
                self.stop_free_gap_accel(k, free)
            } else {
                free(k) - free(k + 1)
            };
            self.scratch_q[k] = q;
            self.scratch_lambda[k] = 0.0;
            self.scratch_active[k] = false;
        }
        // Chandrasekaran: grow the active set by every candidate with w < 0; at most ncont rounds.
        for _ in 0..=ncont {
            let mut added = false;
            for k in 0..ncont {
                if self.scratch_candidate[k] && !self.scratch_active[k] && self.gap_accel(k) < -self.acc_tol {
                    self.scratch_active[k] = true;
                    added = true;
                }
            }
            if !added {
                break;
            }
            self.solve_active_forces();
        }
        let mut logged = Vec::new();
        for k in 0..ncont {
            let before = self.closure[k];
            let after = if self.scratch_active[k] {
                if before.presses() { before } else { Closure::Stuck }
            } else if self.scratch_candidate[k]
                && self.may_rest(k)
                && (!quiet || before == Closure::Resting)
                && self.gap_accel(k) <= self.acc_tol
            {
                Closure::Resting
            } else {
                Closure::Open
            };
            self.closure[k] = after;
            if after.presses() && !before.presses() {
                self.sequence[k] = 0;
                self.last_speed[k] = f64::INFINITY;
                self.push_event(EventKind::Stick, k, 0.0, 0.0, 0);
                logged.push(k);
            } else if before.presses() && !after.presses() {
                self.push_event(EventKind::Release, k, 0.0, 0.0, 0);
                logged.push(k);
            }
        }
        if !quiet {
            self.equalize_touching();
            if !self.params.stops.is_empty() {
                self.equalize_stops();
            }
        }
        logged
    }

    /// Gives each group of masses joined by touching contacts (closed ones, and open ones with
    /// a rounding-level relative velocity, the candidates of [`settle`](Self::settle)) that
    /// contains an open one their common centre-of-mass velocity, if they differ: a plastic
    /// impulse of rounding size (momentum kept, energy never gained). The whole group at once:
    /// equalizing one contact after another, or merging a closed cluster in it later, would
    /// leave a rounding-level relative velocity across the open contact again.
    fn equalize_touching(&mut self) {
        // The contacts between masses (the stops' are seen to by `equalize_stops`).
        let ncont = self.x.len() - 1;
        let mut first = 0;
        let mut open = false;
        for k in 0..=ncont {
            if k < ncont && (self.closure[k].is_closed() || self.scratch_candidate[k]) {
                open |= !self.closure[k].is_closed();
                continue;
            }
            let v = &mut self.v[first..=k];
            if open && v.iter().any(|&vi| vi != v[0]) {
                let m = &self.params.masses[first..=k];
                let total: f64 = m.iter().sum();
                let momentum: f64 = m.iter().zip(v.iter()).map(|(m, v)| m * v).sum();
                v.fill(momentum / total);
            }
            first = k + 1;
            open = false;
        }
    }

    /// w_k = q_k + (Wλ)_k for the chain's tridiagonal Delassus matrix W.
    fn gap_accel(&self, k: usize) -> f64 {
        if !self.params.stops.is_empty() {
            return self.gap_accel_with_stops(k);
        }
        let m = &self.params.masses;
        let lam = &self.scratch_lambda;
        let mut w = self.scratch_q[k] + lam[k] * (1.0 / m[k] + 1.0 / m[k + 1]);
        if k > 0 {
            w -= lam[k - 1] / m[k];
        }
        if k + 1 < lam.len() {
            w -= lam[k + 1] / m[k + 1];
        }
        w
    }

    /// Solves `W_AA λ_A = −q_A` on each run of consecutive active contacts (Thomas algorithm).
    fn solve_active_forces(&mut self) {
        if !self.params.stops.is_empty() {
            return self.solve_active_forces_with_stops();
        }
        let m = &self.params.masses;
        let ncont = self.scratch_q.len();
        let mut k = 0;
        while k < ncont {
            if !self.scratch_active[k] {
                self.scratch_lambda[k] = 0.0;
                k += 1;
                continue;
            }
            let start = k;
            while k < ncont && self.scratch_active[k] {
                k += 1;
            }
            // Forward sweep on [start, k): diag b_j = 1/m_j + 1/m_{j+1}, sub a_j = −1/m_j,
            // super c_j = −1/m_{j+1}. Store modified super in lambda temporarily via a
            // small local buffer.
            let len = k - start;
            let mut cprime = [0.0f64; 64];
            let mut dprime = [0.0f64; 64];
            let mut heap_c;
            let mut heap_d;
            let (cp, dp): (&mut [f64], &mut [f64]) = if len <= 64 {
                (&mut cprime[..len], &mut dprime[..len])
            } else {
                heap_c = vec![0.0; len];
                heap_d = vec![0.0; len];
                (&mut heap_c[..], &mut heap_d[..])
            };
            for (idx, j) in (start..k).enumerate() {
                let b = 1.0 / m[j] + 1.0 / m[j + 1];
                let a = -1.0 / m[j];
                let c = -1.0 / m[j + 1];
                let rhs = -self.scratch_q[j];
                if idx == 0 {
                    cp[0] = c / b;
                    dp[0] = rhs / b;
                } else {
                    let denom = b - a * cp[idx - 1];
                    cp[idx] = c / denom;
                    dp[idx] = (rhs - a * dp[idx - 1]) / denom;
                }
            }
            for idx in (0..len).rev() {
                let val = if idx + 1 < len {
                    dp[idx] - cp[idx] * self.scratch_lambda[start + idx + 1]
                } else {
                    dp[idx]
                };
                self.scratch_lambda[start + idx] = val.max(0.0);
            }
        }
    }
}
