//! Applying what the event search found: the contact laws at an event (impacts, chatter
//! jumps, sticking, release) and the clusters rebuilt from the closed contacts.

use super::*;

impl Simulator {
    /// Rebuilds clusters and their oscillators at the current time from the mass states and
    /// the contact closures. Merged masses take the momentum-weighted (centre-of-mass)
    /// velocity and position, so internal impulses conserve momentum exactly.
    pub(super) fn rebuild(&mut self) -> Result<(), SimError> {
        let n = self.x.len();
        for (k, from) in self.search_from.iter_mut().enumerate() {
            // A nudge lasts until something happens at the contact or beyond it in time.
            if *from <= self.t || self.closure[k].is_closed() {
                *from = f64::NEG_INFINITY;
            }
        }
        self.clusters.clear();
        self.consts.clear();
        self.term_scale = 0.0;
        let mut first = 0;
        for i in 0..n {
            let ends = i == n - 1 || !self.closure[i].is_closed();
            if !ends {
                continue;
            }
            let last = i;
            let base = self.offsets[first];
            let mut k = ClusterConsts::default();
            let mut momentum = 0.0;
            let mut moment = 0.0;
            for j in first..=last {
                let m = self.params.masses[j];
                let o = self.offsets[j] - base;
                k.mass += m;
                k.damping += self.params.damping[j];
                k.stiffness += self.params.stiffness[j];
                k.force -= self.params.stiffness[j] * o;
                momentum += m * self.v[j];
                moment += m * (self.x[j] - o);
            }
            if !self.forces.is_empty() {
                k.force += self.forces.range_constant(first, last);
            }
            if let Some((osc, stop)) = self.anchored_flow(first, last) {
                self.term_scale = self.term_scale.max(osc.magnitude());
                self.clusters.push(ClusterFlow {
                    first,
                    last,
                    oscillator: osc,
                    stop: Some(stop),
                });
                self.consts.push(k);
                first = i + 1;
                continue;
            }
            let s = moment / k.mass;
            let vs = momentum / k.mass;
            for j in first..=last {
                self.x[j] = s + (self.offsets[j] - base);
                self.v[j] = vs;
            }
            let osc = Oscillator::new_at_phase(
                OscConstants {
                    mass: k.mass,
                    damping: k.damping,
                    stiffness: k.stiffness,
                    force: k.force,
                    poly: self.forces.range_poly(first, last),
                },
                &self.forcing,
                self.t,
                self.phase_now,
                s,
                vs,
            )
            .map_err(|e| match e {
                SimError::OutOfRange { .. } => SimError::OutOfRange {
                    first: first + 1,
                    last: last + 1,
                },
                _ => SimError::UndampedResonance {
                    first: first + 1,
                    last: last + 1,
                },
            })?;
            self.term_scale = self.term_scale.max(osc.magnitude());
            self.clusters.push(ClusterFlow {
                first,
                last,
                oscillator: osc,
                stop: None,
            });
            self.consts.push(k);
            first = i + 1;
        }
        self.refresh_tolerances();
        Ok(())
    }

    pub(super) fn handle(&mut self, what: Pending) -> Result<(), SimError> {
        if self.forces.has_polynomials() {
            // The polynomial parts of the flows grew along the piece: the scale of the terms
            // the state is summed from is theirs at the event.
            let t = self.t;
            self.term_scale = self
                .clusters
                .iter()
                .map(|c| c.oscillator.magnitude_at(t))
                .fold(self.term_scale, f64::max);
        }
        self.refresh_tolerances();
        // Contacts struck at this event (none unless it is an impact).
        self.scratch_first_speed.fill(f64::NAN);
        match what {
            Pending::Impact { contact, at_start } => {
                let struck = self.resolve_impacts(contact)?;
                // A touch at the search start with no closing speed is the rounding of the
                // event function (as for the gap of a just-released contact), not a new
                // contact state: only a contact that presses beyond rounding closes there.
                let quiet = at_start && !struck;
                let stuck = self.settle(None, quiet);
                if quiet && stuck.is_empty() {
                    // A rounding-level touch at the search start that changes nothing: not an
                    // event. Search this contact again from a hair later.
                    self.scratch_events.clear();
                    let nudge = (NUDGE * self.forcing.period).max(8.0 * f64::EPSILON * self.t.abs());
                    self.search_from[contact] = self.t + nudge;
                }
            }
            Pending::Release(j) => {
                self.closure[j] = Closure::Open;
                self.sequence[j] = 0;
                self.last_speed[j] = f64::INFINITY;
                self.push_event(EventKind::Release, j, 0.0, 0.0, 0);
                self.settle(Some(j), false);
            }
            Pending::Press(j) => {
                self.closure[j] = Closure::Stuck;
                self.sequence[j] = 0;
                self.last_speed[j] = f64::INFINITY;
                self.push_event(EventKind::Stick, j, 0.0, 0.0, 0);
            }
            Pending::Part(j) => {
                self.closure[j] = Closure::Open;
                self.settle(Some(j), false);
            }
            Pending::ChatterEnd(j) => {
                let impacts = match self.closure[j] {
                    Closure::Chatter { impacts, .. } => impacts,
                    _ => 0,
                };
                self.push_event(EventKind::Chatter, j, 0.0, 0.0, impacts);
                // The accumulation point: stick if the contact presses, else release.
                self.closure[j] = Closure::Stuck;
                let was_open_before = self.settle(None, false);
                if !was_open_before.contains(&j) {
                    // settle() logged nothing for j: it stays closed, now as a stuck contact.
                    self.push_event(EventKind::Stick, j, 0.0, 0.0, 0);
                }
                self.sequence[j] = 0;
                self.last_speed[j] = f64::INFINITY;
            }
        }
        self.project_contacts();
        self.rebuild()
    }
}
