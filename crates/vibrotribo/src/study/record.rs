//! [`Recording`]: a [`RunObserver`] that keeps a run's samples and events in columns (what
//! the command line streams to `trajectory.csv` and `events.csv`, kept in memory for front
//! ends that hand out arrays).

use super::observer::{RunObserver, Sample};
use crate::dynamics::{Event, EventKind, StateView};

/// The samples of a run in columns, one entry per sample (per sample and mass or gap for the
/// flattened ones, row-major).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SampleColumns {
    /// Time, s.
    pub time: Vec<f64>,
    /// Positions x_i, m: `positions[j·N + i]`.
    pub positions: Vec<f64>,
    /// Velocities, m/s: `velocities[j·N + i]`.
    pub velocities: Vec<f64>,
    /// Base displacement y, m.
    pub base: Vec<f64>,
    /// Gaps d_k, m: `gaps[j·(N−1) + k]`.
    pub gaps: Vec<f64>,
    /// Charge Q, C (NaN where the charge is not solved).
    pub charge_c: Vec<f64>,
    /// Current I, A (NaN where not solved).
    pub current_a: Vec<f64>,
    /// Load voltage V, V (NaN where not solved).
    pub voltage_v: Vec<f64>,
    /// Transducer capacitance C, F (NaN where not solved).
    pub capacitance_f: Vec<f64>,
    /// Open-circuit voltage V_oc, V (NaN where not solved).
    pub voc_v: Vec<f64>,
    /// Storage capacitor voltage, V (NaN without a rectifier or where not solved).
    pub storage_voltage_v: Vec<f64>,
}

/// The events of a run in columns, one entry per event (per event and mass for the
/// flattened ones, row-major).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct EventColumns {
    /// Time, s.
    pub time: Vec<f64>,
    /// What happened.
    pub kind: Vec<EventKind>,
    /// Contact, 0-based.
    pub contact: Vec<usize>,
    /// Closing speed just before an impact, m/s (0 otherwise).
    pub velocity_before: Vec<f64>,
    /// Opening speed just after an impact, m/s (0 otherwise).
    pub velocity_after: Vec<f64>,
    /// Impacts resolved one by one in a chatter sequence before its accumulation point.
    pub sequence_impacts: Vec<u32>,
    /// Positions just after the event, m: `positions[j·N + i]`.
    pub positions: Vec<f64>,
    /// Velocities just after the event, m/s: `velocities[j·N + i]`.
    pub velocities: Vec<f64>,
}

/// Keeps every event of a run and, if asked, every sample, in columns.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Recording {
    /// Whether samples are kept.
    pub keep_samples: bool,
    /// The samples.
    pub samples: SampleColumns,
    /// The events.
    pub events: EventColumns,
}

impl Recording {
    /// A recording of the events, and of the samples if `keep_samples`.
    pub fn new(keep_samples: bool) -> Self {
        Recording {
            keep_samples,
            ..Recording::default()
        }
    }
}

impl RunObserver for Recording {
    fn event(&mut self, e: &Event, state: &StateView<'_>) {
        let ev = &mut self.events;
        ev.time.push(e.time);
        ev.kind.push(e.kind);
        ev.contact.push(e.contact);
        ev.velocity_before.push(e.velocity_before);
        ev.velocity_after.push(e.velocity_after);
        ev.sequence_impacts.push(e.sequence_impacts);
        ev.positions.extend_from_slice(state.positions);
        ev.velocities.extend_from_slice(state.velocities);
    }

    fn wants_samples(&self) -> bool {
        self.keep_samples
    }

    fn sample(&mut self, s: &Sample<'_>) {
        let c = &mut self.samples;
        c.time.push(s.time);
        c.positions.extend_from_slice(s.positions);
        c.velocities.extend_from_slice(s.velocities);
        c.base.push(s.base);
        c.gaps.extend_from_slice(s.gaps);
        let e = s.electrical.as_ref();
        c.charge_c.push(e.map_or(f64::NAN, |e| e.charge_c));
        c.current_a.push(e.map_or(f64::NAN, |e| e.current_a));
        c.voltage_v.push(e.map_or(f64::NAN, |e| e.voltage_v));
        c.capacitance_f.push(e.map_or(f64::NAN, |e| e.capacitance_f));
        c.voc_v.push(e.map_or(f64::NAN, |e| e.voc_v));
        c.storage_voltage_v
            .push(e.and_then(|e| e.storage_voltage_v).unwrap_or(f64::NAN));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::{Mechanics, RunSpec, Sampling, simulate};
    use crate::{ChainParams, EventLog};

    /// The recorded events are the simulator's (as an [`EventLog`] sees them), the samples
    /// lie on the grid with gaps δ_k − (x_{k+1} − x_k), and nothing is sampled unless asked.
    #[test]
    fn records_events_and_samples() {
        let chain = ChainParams::default();
        let spec = RunSpec {
            sampling: Some(Sampling::PerPeriod(20)),
            ..RunSpec::new(chain.clone(), 6)
        };
        let mut pair = (Recording::new(true), Mechanics::new(EventLog::default()));
        simulate(&spec, &mut pair).unwrap();
        let (rec, log) = (pair.0, pair.1.inner);
        assert_eq!(rec.events.time.len(), log.events.len());
        for (j, e) in log.events.iter().enumerate() {
            assert_eq!(rec.events.time[j], e.event.time);
            assert_eq!(rec.events.kind[j], e.event.kind);
            assert_eq!(rec.events.positions[3 * j..3 * j + 3], e.positions[..]);
        }
        let s = &rec.samples;
        assert_eq!(s.time.len(), 6 * 20 + 1);
        for (j, &t) in s.time.iter().enumerate() {
            assert!((t - chain.period() * j as f64 / 20.0).abs() <= 1e-15 * t.max(1.0));
            for k in 0..2 {
                let x = &s.positions[3 * j..3 * j + 3];
                assert_eq!(s.gaps[2 * j + k], chain.gaps[k] - (x[k + 1] - x[k]));
            }
        }
        assert!(s.charge_c.iter().all(|q| q.is_nan()));

        let mut events_only = Recording::new(false);
        simulate(&spec, &mut events_only).unwrap();
        assert!(events_only.samples.time.is_empty());
        assert_eq!(events_only.events, rec.events);
    }
}
