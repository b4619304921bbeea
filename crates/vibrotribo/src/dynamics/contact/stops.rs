//! Rigid stops as contacts (see [`crate::model::Stops`] for the geometry and numbering).
//!
//! A stop is a body of infinite mass with the prescribed motion `Y(t)` (0, or the base motion
//! `A sin ωt`): the contact laws treat it as a neighbour of the chain that no impulse or
//! force moves.
//!
//! - **Gap** of the upper stop `d = gap − x₁ + Y`, of the lower one `d = gap + x_N − Y`; the
//!   closing speed is `x₁' − Y'` and `Y' − x_N'`.
//! - **Impact**: the cluster that meets the stop rebounds with `V⁺ = Y' − r (V − Y')` (the
//!   limit of Newton's law with momentum conservation as the other mass goes to infinity); an
//!   impact between two clusters one of which is stuck to a stop moves only the other one
//!   (the stuck one is part of the stop's infinite mass).
//! - **Sticking** (and the chatter accumulation point): a cluster stuck to a stop follows the
//!   stop, `s(t) = const + Y(t)` ([`Oscillator::prescribed`](super::super::oscillator::Oscillator::prescribed)).
//!   The stop's force is what makes the cluster follow it, `λ = ±(Σ_G F_i − M Ÿ)`, positive
//!   while it presses; the cluster releases when it falls to zero. In the contact LCP the
//!   stop is a neighbour of infinite mass (its term `1/m` is zero).
//! - **Chatter** against a stop (Budd & Dux): the closing acceleration is `Ÿ − a` (upper) or
//!   `a − Ÿ` (lower) with `a` the cluster's free acceleration.

use super::super::oscillator::Oscillator;
use super::super::signal::Signal;
use super::super::simulator::Simulator;
use crate::model::{ChainParams, StopFrame, StopSide};

/// A range of masses `(first, last)`, 0-based, inclusive.
type Range = (usize, usize);

impl Simulator {
    /// The stop at contact k, if k is a stop's contact (`k ≥ N − 1`).
    #[inline]
    pub(in crate::dynamics) fn stop_at(&self, k: usize) -> Option<StopSide> {
        let n = self.x.len();
        if k + 1 < n {
            None
        } else if k + 1 == n {
            Some(StopSide::Lower)
        } else {
            Some(StopSide::Upper)
        }
    }

    /// Whether contact k is the contact of a stop the chain does not have (never searched).
    #[inline]
    pub(in crate::dynamics) fn absent(&self, k: usize) -> bool {
        self.stop_at(k)
            .is_some_and(|side| self.params.stops.get(side).is_none())
    }

    /// Whether the stop on `side` moves with the base (1) or is fixed in space (0).
    fn moves(&self, side: StopSide) -> f64 {
        match self.params.stops.get(side).map(|s| s.frame) {
            Some(StopFrame::Base) => 1.0,
            _ => 0.0,
        }
    }

    /// `Y, Y', Y'', Y'''` of the stop on `side` at the current time.
    pub(in crate::dynamics) fn wall(&self, side: StopSide) -> [f64; 4] {
        let frame = self.params.stops.get(side).map_or(StopFrame::Fixed, |s| s.frame);
        let (y, yd) = self.forcing.base(self.phase_now);
        ChainParams::frame_motion(frame, y, yd, self.forcing.omega)
    }

    fn stop_gap_width(&self, side: StopSide) -> f64 {
        self.params.stops.get(side).map_or(f64::INFINITY, |s| s.gap)
    }

    /// Current gap at stop contact k, m (an absent stop is infinitely far).
    pub(in crate::dynamics) fn stop_gap(&self, k: usize) -> f64 {
        let n = self.x.len();
        let side = self.stop_at(k).expect("a stop's contact");
        let y = self.wall(side)[0];
        match side {
            StopSide::Upper => self.stop_gap_width(side) - (self.x[0] - y),
            StopSide::Lower => self.stop_gap_width(side) - (y - self.x[n - 1]),
        }
    }

    /// Closing speed `−d'` of contact k, m/s.
    #[inline]
    pub(in crate::dynamics) fn closing_speed(&self, k: usize) -> f64 {
        let n = self.x.len();
        if k + 1 < n {
            self.v[k + 1] - self.v[k]
        } else if k + 1 == n {
            self.wall(StopSide::Lower)[1] - self.v[n - 1]
        } else {
            self.v[0] - self.wall(StopSide::Upper)[1]
        }
    }

    /// The mass ranges on the two sides of contact k (`None`: the stop itself).
    pub(in crate::dynamics) fn side_ranges(&self, k: usize) -> (Option<Range>, Option<Range>) {
        let n = self.x.len();
        match self.stop_at(k) {
            None => (Some(self.cluster_range(k)), Some(self.cluster_range(k + 1))),
            Some(StopSide::Lower) => (Some(self.cluster_range(n - 1)), None),
            Some(StopSide::Upper) => (None, Some(self.cluster_range(0))),
        }
    }

    /// The stop a mass range is stuck to (through a closed stop contact), if any.
    pub(in crate::dynamics) fn range_anchor(&self, (first, last): (usize, usize)) -> Option<StopSide> {
        if self.params.stops.is_empty() {
            return None;
        }
        let n = self.x.len();
        if first == 0 && self.closure[n].is_closed() {
            Some(StopSide::Upper)
        } else if last == n - 1 && self.closure[n - 1].is_closed() {
            Some(StopSide::Lower)
        } else {
            None
        }
    }

    /// Mass of one side of a contact, kg: infinite for a stop or a range stuck to one.
    fn side_mass(&self, side: Option<(usize, usize)>) -> f64 {
        match side {
            Some(r) if self.range_anchor(r).is_none() => self.range_mass(r),
            _ => f64::INFINITY,
        }
    }

    /// Adds `dv` to the velocities of `range` unless it is stuck to a stop.
    fn kick(&mut self, range: Option<(usize, usize)>, dv: f64) {
        if let Some(r) = range
            && self.range_anchor(r).is_none()
        {
            for v in &mut self.v[r.0..=r.1] {
                *v += dv;
            }
        }
    }

    /// Applies the Newton impact at contact k with closing speed `vc` and restitution `mu`
    /// if one side has infinite mass (a stop, or a cluster stuck to one); returns false
    /// (doing nothing) for an impact between two free clusters.
    pub(in crate::dynamics) fn stop_impulse(&mut self, k: usize, vc: f64, mu: f64) -> bool {
        let (up, low) = self.side_ranges(k);
        let (m_up, m_low) = (self.side_mass(up), self.side_mass(low));
        if m_up.is_finite() && m_low.is_finite() {
            return false;
        }
        if m_up.is_finite() {
            self.kick(up, (1.0 + mu) * vc);
        } else if m_low.is_finite() {
            self.kick(low, -(1.0 + mu) * vc);
        }
        true
    }

    /// Removes the overlap at open contact k (gap `gap` < 0) if one side has infinite mass,
    /// by moving the other; returns false (doing nothing) between two free clusters.
    pub(in crate::dynamics) fn project_stop(&mut self, k: usize, gap: f64) -> bool {
        let (up, low) = self.side_ranges(k);
        let (m_up, m_low) = (self.side_mass(up), self.side_mass(low));
        if m_up.is_finite() && m_low.is_finite() {
            return false;
        }
        let (range, sign) = if m_up.is_finite() { (up, 1.0) } else { (low, -1.0) };
        if let Some(r) = range
            && self.range_anchor(r).is_none()
        {
            for x in &mut self.x[r.0..=r.1] {
                *x += sign * (-gap);
            }
            let residual = self.gap(k);
            if residual < 0.0 {
                for x in &mut self.x[r.0..=r.1] {
                    *x += sign * (-residual);
                }
            }
        }
        true
    }

    /// Acceleration, m/s², and its rate, m/s³, of the side of contact k above (`upper`) or
    /// below it, for the chatter test: the stop's `Ÿ, Y'''` for a stop or a range stuck to
    /// one, `None` for a free cluster (its free acceleration applies).
    pub(in crate::dynamics) fn prescribed_side_accel(&self, k: usize, upper: bool) -> Option<(f64, f64)> {
        let (up, low) = self.side_ranges(k);
        let range = if upper { up } else { low };
        let side = match range {
            None => self.stop_at(k)?,
            Some(r) => self.range_anchor(r)?,
        };
        let w = self.wall(side);
        Some((w[2], w[3]))
    }

    /// At the start of a chatter jump at contact k whose cluster now meets a stop (k is a
    /// stop's contact, or one side is stuck to a stop): the cluster's velocity becomes the
    /// stop's.
    pub(in crate::dynamics) fn merge_into_stop(&mut self, k: usize) {
        let (range, side) = match self.stop_at(k) {
            Some(side) => {
                let (up, low) = self.side_ranges(k);
                (up.or(low), Some(side))
            }
            None => {
                let r = self.cluster_range(k);
                (Some(r), self.range_anchor(r))
            }
        };
        if let (Some(r), Some(side)) = (range, side) {
            let v = self.wall(side)[1];
            self.v[r.0..=r.1].fill(v);
        }
    }

    /// Gap acceleration of stop contact k with no contact forces, m/s² (`q` of the LCP):
    /// `Ÿ − a₁` above, `a_N − Ÿ` below, with `free(i)` the free acceleration of mass i.
    pub(in crate::dynamics) fn stop_free_gap_accel(&self, k: usize, free: impl Fn(usize) -> f64) -> f64 {
        let n = self.x.len();
        match self.stop_at(k) {
            Some(StopSide::Upper) => self.wall(StopSide::Upper)[2] - free(0),
            Some(StopSide::Lower) => free(n - 1) - self.wall(StopSide::Lower)[2],
            None => unreachable!("contact {k} is not a stop"),
        }
    }

    /// `(1/m above, 1/m below)` of contact k in the LCP (zero on a stop's side).
    #[inline]
    pub(in crate::dynamics) fn inverse_masses(&self, k: usize) -> (f64, f64) {
        let m = &self.params.masses;
        let n = m.len();
        match self.stop_at(k) {
            None => (1.0 / m[k], 1.0 / m[k + 1]),
            Some(StopSide::Lower) => (1.0 / m[n - 1], 0.0),
            Some(StopSide::Upper) => (0.0, 1.0 / m[0]),
        }
    }

    /// The contact above contact k in the chain's spatial order (upper stop, 0 … N − 2,
    /// lower stop), if any. Only for a chain with stops.
    fn contact_above(&self, k: usize) -> Option<usize> {
        let n = self.x.len();
        if k == n {
            None
        } else if k == 0 {
            Some(n)
        } else {
            Some(k - 1)
        }
    }

    /// The contact below contact k in the spatial order, if any. Only for a chain with stops.
    fn contact_below(&self, k: usize) -> Option<usize> {
        let n = self.x.len();
        if k + 1 == n {
            None
        } else if k == n {
            Some(0)
        } else {
            Some(k + 1)
        }
    }

    /// `w_k = q_k + (Wλ)_k` of the contact LCP for a chain with stops: the tridiagonal
    /// Delassus matrix in spatial order, with zero `1/m` on a stop's side.
    pub(in crate::dynamics) fn gap_accel_with_stops(&self, k: usize) -> f64 {
        let lam = &self.scratch_lambda;
        let (ia, ib) = self.inverse_masses(k);
        let mut w = self.scratch_q[k] + lam[k] * (ia + ib);
        if let Some(p) = self.contact_above(k) {
            w -= lam[p] * ia;
        }
        if let Some(q) = self.contact_below(k) {
            w -= lam[q] * ib;
        }
        w
    }

    /// Solves `W_AA λ_A = −q_A` on each run of consecutive active contacts in spatial order
    /// (Thomas algorithm) for a chain with stops; inactive contacts get λ = 0.
    pub(in crate::dynamics) fn solve_active_forces_with_stops(&mut self) {
        let n = self.x.len();
        let ncont = self.scratch_q.len();
        // Spatial order: upper stop (n), 0 … n − 2, lower stop (n − 1).
        let at = |p: usize| if p == 0 { n } else { p - 1 };
        let mut p = 0;
        while p < ncont {
            if !self.scratch_active[at(p)] {
                self.scratch_lambda[at(p)] = 0.0;
                p += 1;
                continue;
            }
            let start = p;
            while p < ncont && self.scratch_active[at(p)] {
                p += 1;
            }
            // Forward sweep into a stack buffer (the heap only for runs beyond 64 contacts).
            let len = p - start;
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
            for idx in 0..len {
                let j = at(start + idx);
                let (ia, ib) = self.inverse_masses(j);
                let (b, a, c) = (ia + ib, -ia, -ib);
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
                    dp[idx] - cp[idx] * self.scratch_lambda[at(start + idx + 1)]
                } else {
                    dp[idx]
                };
                self.scratch_lambda[at(start + idx)] = val.max(0.0);
            }
        }
    }

    /// Velocities of touching groups next to a stop that they touch with a rounding-level
    /// relative velocity: the stop's (see `equalize_touching`).
    pub(in crate::dynamics) fn equalize_stops(&mut self) {
        let n = self.x.len();
        for side in [StopSide::Upper, StopSide::Lower] {
            if self.params.stops.get(side).is_none() {
                continue;
            }
            let k = self.params.stop_contact(side);
            if !self.scratch_candidate[k] {
                continue;
            }
            // The group joined to the stop by closed or touching contacts.
            let (mut first, mut last) = match side {
                StopSide::Upper => (0, 0),
                StopSide::Lower => (n - 1, n - 1),
            };
            let mut open = !self.closure[k].is_closed();
            match side {
                StopSide::Upper => {
                    while last + 1 < n && (self.closure[last].is_closed() || self.scratch_candidate[last]) {
                        open |= !self.closure[last].is_closed();
                        last += 1;
                    }
                }
                StopSide::Lower => {
                    while first > 0
                        && (self.closure[first - 1].is_closed() || self.scratch_candidate[first - 1])
                    {
                        open |= !self.closure[first - 1].is_closed();
                        first -= 1;
                    }
                }
            }
            if open {
                let v = self.wall(side)[1];
                self.v[first..=last].fill(v);
            }
        }
    }

    /// The prescribed flow of cluster `first..=last` if it is stuck to a stop (its members
    /// put exactly on the stop's motion), else `None`.
    pub(in crate::dynamics) fn anchored_flow(
        &mut self,
        first: usize,
        last: usize,
    ) -> Option<(Oscillator, StopSide)> {
        let side = self.range_anchor((first, last))?;
        let n = self.x.len();
        let gap = self.stop_gap_width(side);
        let moves = self.moves(side);
        let w = self.wall(side);
        let base = self.offsets[first];
        // Position of the cluster's top mass with the stop's gap closed, less Y(t).
        let mean = match side {
            StopSide::Upper => gap,
            StopSide::Lower => -gap - (self.offsets[n - 1] - base),
        };
        for i in first..=last {
            self.x[i] = mean + w[0] + (self.offsets[i] - base);
            self.v[i] = w[1];
        }
        Some((Oscillator::prescribed(&self.forcing, self.t, mean, moves), side))
    }

    /// Gap of open stop contact k as a [`Signal`].
    pub(in crate::dynamics) fn stop_gap_signal(&self, k: usize) -> Signal {
        let n = self.x.len();
        let side = self.stop_at(k).expect("a stop's contact");
        let a = self.forcing.amplitude * self.moves(side);
        let w = self.forcing.omega;
        let mut sig = Signal::default();
        sig.add_constant(self.stop_gap_width(side));
        match side {
            StopSide::Upper => {
                let c = self.cluster_of(0);
                sig.add_oscillator(c, &self.clusters[c].oscillator, -1.0, 0.0, w);
                sig.add_harmonic(0.0, a);
            }
            StopSide::Lower => {
                let c = self.cluster_of(n - 1);
                let first = self.clusters[c].first;
                sig.add_constant(self.offsets[n - 1] - self.offsets[first]);
                sig.add_oscillator(c, &self.clusters[c].oscillator, 1.0, 0.0, w);
                sig.add_harmonic(0.0, -a);
            }
        }
        sig
    }

    /// Contact force (compressive positive), N, of closed contact j in a cluster stuck to a
    /// stop, as a [`Signal`], or `None` if j's cluster is free. For the stop's own contact it
    /// is the stop's force on the cluster, `λ = Σ_G F_i − M Ÿ` above and `M Ÿ − Σ_G F_i`
    /// below; inside the cluster it is computed from the part away from the stop, on which
    /// only the springs, dashpots, external forces and that contact act:
    /// `N_j = Σ_{i>j} F_i − M_{>j} Ÿ` (stuck above) or `M_{≤j} Ÿ − Σ_{i≤j} F_i` (stuck below).
    /// `F_i = −c_i(s' − y') − k_i(s + o_i − y) + f_i(t)` with o_i the member's offset and f_i
    /// its external force.
    pub(in crate::dynamics) fn anchored_force_signal(&self, j: usize) -> Option<Signal> {
        let n = self.x.len();
        let g = match self.stop_at(j) {
            Some(StopSide::Upper) => self.cluster_of(0),
            Some(StopSide::Lower) => self.cluster_of(n - 1),
            None => self.cluster_of(j),
        };
        let c = &self.clusters[g];
        let side = c.stop?;
        let (range, sign) = match (self.stop_at(j), side) {
            (Some(_), StopSide::Upper) => ((c.first, c.last), 1.0),
            (Some(_), StopSide::Lower) => ((c.first, c.last), -1.0),
            (None, StopSide::Upper) => ((j + 1, c.last), 1.0),
            (None, StopSide::Lower) => ((c.first, j), -1.0),
        };
        let base = self.offsets[c.first];
        let (mut m, mut cc, mut kk, mut ko) = (0.0, 0.0, 0.0, 0.0);
        for i in range.0..=range.1 {
            m += self.params.masses[i];
            cc += self.params.damping[i];
            kk += self.params.stiffness[i];
            ko += self.params.stiffness[i] * (self.offsets[i] - base);
        }
        let w = self.forcing.omega;
        let a = self.forcing.amplitude;
        let wall = a * self.moves(side);
        // sign · (−ko − kk (s − y) − cc (s' − y') + m ω² Y), Y = wall · sin ωt.
        let mut sig = Signal::default();
        sig.add_constant(-sign * ko);
        sig.add_oscillator(g, &c.oscillator, -sign * kk, -sign * cc, w);
        sig.add_harmonic(sign * cc * a * w, sign * kk * a);
        sig.add_harmonic(0.0, sign * m * w * w * wall);
        if !self.forces.is_empty() {
            // The external forces on the part, Σ f_i(t), are among its F_i.
            sig.add_constant(sign * self.forces.range_constant(range.0, range.1));
            sig.add_polynomial(&self.forces.range_poly(range.0, range.1), sign);
        }
        Some(sig)
    }

    /// Whether contact k may rest (touch with no force): not at a stop, whose touching
    /// contacts are open or stuck.
    #[inline]
    pub(in crate::dynamics) fn may_rest(&self, k: usize) -> bool {
        self.stop_at(k).is_none()
    }

    /// The label of contact k in messages (1-based).
    pub(in crate::dynamics) fn contact_name(&self, k: usize) -> String {
        match self.stop_at(k) {
            None => format!("contact {}", k + 1),
            Some(side) => format!("contact {} (the {} stop)", k + 1, side.as_str()),
        }
    }
}
