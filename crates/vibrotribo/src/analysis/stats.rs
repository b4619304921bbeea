//! Event statistics of a run: impacts per excitation period and contact, sticking and
//! chatter counts, closing speeds.

use crate::dynamics::{Event, EventKind, Observer, StateView};

/// Counts events per excitation period, per contact. Periods are numbered from 0 (the
/// interval [0, T)).
#[derive(Debug, Clone, PartialEq)]
pub struct RunStats {
    period: f64,
    /// Periods before this index are the transient, excluded from the `*_after_transient`
    /// summaries.
    pub transient_periods: u64,
    /// Impacts in each period, per contact: `impacts[p][k]`.
    pub impacts: Vec<Vec<u32>>,
    /// Sticks after the transient.
    pub sticks: u64,
    /// Releases after the transient.
    pub releases: u64,
    /// Chatter sequences ended by an accumulation-point jump, after the transient.
    pub chatter_sequences: u64,
    /// Largest closing speed per contact after the transient, m/s.
    pub max_closing_speed: Vec<f64>,
    /// Smallest closing speed of an impact per contact after the transient, m/s.
    pub min_closing_speed: Vec<f64>,
    /// All events, transient included.
    pub events: u64,
}

impl RunStats {
    /// Statistics for a chain with `contacts` contacts, excitation period `period` (s), and
    /// the first `transient_periods` periods treated as transient.
    pub fn new(contacts: usize, period: f64, transient_periods: u64) -> Self {
        RunStats {
            period,
            transient_periods,
            impacts: Vec::new(),
            sticks: 0,
            releases: 0,
            chatter_sequences: 0,
            max_closing_speed: vec![0.0; contacts],
            min_closing_speed: vec![f64::INFINITY; contacts],
            events: 0,
        }
    }

    fn period_of(&self, t: f64) -> u64 {
        (t / self.period).floor().max(0.0) as u64
    }

    /// Impacts after the transient, per contact, summed over `periods` in all (periods
    /// without impacts count as zero).
    pub fn impacts_after_transient(&self) -> Vec<u64> {
        let n = self.max_closing_speed.len();
        let mut sum = vec![0u64; n];
        for row in self.impacts.iter().skip(self.transient_periods as usize) {
            for (s, c) in sum.iter_mut().zip(row) {
                *s += u64::from(*c);
            }
        }
        sum
    }

    /// Mean impacts per period after the transient, per contact, over `periods` simulated.
    pub fn impacts_per_period(&self, periods: u64) -> Vec<f64> {
        let recorded = periods.saturating_sub(self.transient_periods).max(1) as f64;
        self.impacts_after_transient()
            .into_iter()
            .map(|c| c as f64 / recorded)
            .collect()
    }

    /// Total impacts in each period (all contacts), `periods` entries.
    pub fn impacts_by_period(&self, periods: u64) -> Vec<u32> {
        (0..periods as usize)
            .map(|p| self.impacts.get(p).map_or(0, |row| row.iter().sum()))
            .collect()
    }
}

impl Observer for RunStats {
    fn event(&mut self, event: &Event, _state: &StateView<'_>) {
        self.events += 1;
        let p = self.period_of(event.time);
        let after = p >= self.transient_periods;
        let k = event.contact;
        match event.kind {
            EventKind::Impact => {
                let n = self.max_closing_speed.len();
                while self.impacts.len() <= p as usize {
                    self.impacts.push(vec![0; n]);
                }
                self.impacts[p as usize][k] += 1;
                if after {
                    self.max_closing_speed[k] = self.max_closing_speed[k].max(event.velocity_before);
                    self.min_closing_speed[k] = self.min_closing_speed[k].min(event.velocity_before);
                }
            }
            EventKind::Stick if after => self.sticks += 1,
            EventKind::Release if after => self.releases += 1,
            EventKind::Chatter if after => self.chatter_sequences += 1,
            _ => {}
        }
    }
}
