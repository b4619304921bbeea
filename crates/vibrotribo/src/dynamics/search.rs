//! Which event comes next: the certified searches of every contact's event function, raced
//! by time.
//!
//! Each open contact's gap and each closed contact's force is searched for its first zero
//! ([`super::roots`]). The searches advance one iteration at a time, always the one furthest
//! behind, against a horizon that shrinks to the earliest zero found so far: no search
//! certifies time past a zero that already ends the flow (before, a search run on its own went
//! on to its own zero or the end of the period, though an earlier contact's zero would come
//! first). The result is the one of running the searches one after the other in contact order:
//! the earliest zero wins, and at equal times the lower contact (and, within a contact, a chatter
//! end or a resting contact's change before its force's zero).

use super::contact::Closure;
use super::roots::{Found, Racer, Search, Stall, first_root};
use super::simulator::{Pending, Simulator};
use crate::error::SimError;

/// The best candidate so far: its time, s, its contact and its rank within the contact (0 for
/// a chatter end or a resting contact's event, 1 for a search's zero).
#[derive(Debug, Clone, Copy)]
struct Candidate {
    t: f64,
    contact: usize,
    rank: u8,
    what: Pending,
}

impl Candidate {
    /// Whether this candidate comes before `other` (earlier, or at the same time of a lower
    /// contact or rank).
    fn precedes(&self, other: &Candidate) -> bool {
        self.t < other.t || (self.t == other.t && (self.contact, self.rank) < (other.contact, other.rank))
    }
}

/// The horizon of a search of `contact` (rank 1) given the best candidate so far: a zero must
/// come before it, or at its time when the search's contact precedes it.
fn horizon_for(contact: usize, best: Option<&Candidate>, stop: f64) -> f64 {
    match best {
        None => stop,
        Some(b) if (b.contact, b.rank) < (contact, 1) => b.t,
        Some(b) => b.t.next_up(),
    }
}

impl Simulator {
    /// The earliest event in `(t, stop]`, if any.
    pub(super) fn next_event(&mut self, stop: f64) -> Result<Option<(f64, Pending)>, SimError> {
        let mut racers = std::mem::take(&mut self.scratch_racers);
        racers.clear();
        let found = self.race(stop, &mut racers);
        self.scratch_racers = racers;
        found
    }

    fn race(&self, stop: f64, racers: &mut Vec<Racer>) -> Result<Option<(f64, Pending)>, SimError> {
        let mut best: Option<Candidate> = None;
        let offer = |best: &mut Option<Candidate>, c: Candidate| {
            if best.is_none_or(|b| c.precedes(&b)) {
                *best = Some(c);
            }
        };
        // Chatter ends and resting contacts first (rare; each searched on its own), and the
        // searches to race.
        for k in 0..self.closure.len() {
            if self.absent(k) {
                continue;
            }
            // A jump whose accumulation point lies beyond the stop goes on after it.
            if let Closure::Chatter { t_acc, .. } = self.closure[k]
                && t_acc < stop
            {
                let c = Candidate {
                    t: t_acc.max(self.t),
                    contact: k,
                    rank: 0,
                    what: Pending::ChatterEnd(k),
                };
                offer(&mut best, c);
            }
            let (signal, start, gap) = match self.closure[k] {
                Closure::Open => (self.gap_signal(k), self.t.max(self.search_from[k]), true),
                Closure::Resting => {
                    let horizon = horizon_for(k, best.as_ref(), stop);
                    if let Some((t, what)) = self.resting_event(k, horizon)? {
                        offer(
                            &mut best,
                            Candidate {
                                t,
                                contact: k,
                                rank: 0,
                                what,
                            },
                        );
                    }
                    continue;
                }
                _ => (self.force_signal(k), self.t, false),
            };
            racers.push(Racer {
                contact: k,
                amp: signal.harmonic_amplitude(),
                signal,
                start,
                search: Search::new(start),
                gap,
            });
        }
        let w = self.forcing.omega;
        // The race: advance the search furthest behind (the lower contact at equal times)
        // until every search has ended.
        while let Some(i) = racers
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.search.time().total_cmp(&b.1.search.time()))
            .map(|(i, _)| i)
        {
            let r = &mut racers[i];
            let horizon = horizon_for(r.contact, best.as_ref(), stop);
            let (signal, amp) = (&r.signal, r.amp);
            let mut eval = |t: f64| signal.jet(t, self.phase_at(t), &self.clusters, w, horizon, amp);
            let outcome = r.search.advance(&mut eval, horizon);
            match outcome {
                Ok(None) => continue,
                Ok(Some(Found::Root(te))) if te < horizon => {
                    let what = if r.gap {
                        Pending::Impact {
                            contact: r.contact,
                            at_start: te <= r.start,
                        }
                    } else {
                        Pending::Release(r.contact)
                    };
                    let c = Candidate {
                        t: te.max(self.t),
                        contact: r.contact,
                        rank: 1,
                        what,
                    };
                    offer(&mut best, c);
                }
                Ok(Some(_)) => {}
                Err(stall) => return Err(self.stalled(r.contact, stall)),
            }
            racers.swap_remove(i);
        }
        Ok(best.map(|b| (b.t, b.what)))
    }

    /// The earliest event of resting contact k before `horizon`, if any: its force falls to
    /// minus its band (it parts) or rises to plus its band (it sticks).
    #[cold]
    fn resting_event(&self, k: usize, horizon: f64) -> Result<Option<(f64, Pending)>, SimError> {
        let band = self.rest_band(k);
        let mut part = self.force_signal(k);
        part.add_constant(band);
        let mut press = part.negated();
        press.add_constant(2.0 * band);
        let w = self.forcing.omega;
        let mut best = None;
        let mut horizon = horizon;
        for (sig, what) in [(part, Pending::Part(k)), (press, Pending::Press(k))] {
            let amp = sig.harmonic_amplitude();
            let eval = |t: f64| sig.jet(t, self.phase_at(t), &self.clusters, w, horizon, amp);
            match first_root(eval, self.t, horizon) {
                Ok(Found::Root(te)) if te < horizon => {
                    horizon = te.max(self.t);
                    best = Some((horizon, what));
                }
                Ok(_) => {}
                Err(stall) => return Err(self.stalled(k, stall)),
            }
        }
        Ok(best)
    }

    /// The error for a search of contact k that could not separate a zero from its start.
    #[cold]
    fn stalled(&self, k: usize, stall: Stall) -> SimError {
        SimError::Stalled {
            t: stall.t,
            what: match self.closure[k] {
                Closure::Open => format!("the gap of {}", self.contact_name(k)),
                _ => format!("the contact force of {}", self.contact_name(k)),
            },
        }
    }
}
