//! The observer that gathers a run's transducer states for the figures of merit, counts the
//! run's cycles and keeps the breakdown boundary at the states it visits for the V–Q plot.

use crate::dynamics::{Event, StateView};
use crate::electrical::{HarvesterParams, TransducerMode};
use crate::study::{RunObserver, Sample};

use super::cycle::{CycleState, MeritReport, StateSet, figures_of_merit};

/// The breakdown boundary at one state of the run, in the V–Q plane: the smallest and the
/// largest charge no air gap breaks down at, C, and the terminal voltage there, V (NaN where
/// no gap limits the charge on that side).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct BoundaryPoint {
    /// Smallest allowed charge, C.
    pub q_low_c: f64,
    /// Terminal voltage at it, V.
    pub v_low_v: f64,
    /// Largest allowed charge, C.
    pub q_high_c: f64,
    /// Terminal voltage at it, V.
    pub v_high_v: f64,
}

/// Most boundary points kept (every other one is dropped when twice as many are held).
const BOUNDARY_POINTS: usize = 2000;

/// Most samples of the stroke coordinate kept for counting cycles (4 bytes each).
const COUNTED_SAMPLES: usize = 1 << 23;

/// Gathers the transducer states of a run's samples and events from time `from` on (the end
/// of the transient; the events add the states at contact, which a sample grid misses): the
/// figures of merit come from [`finish`](Self::finish).
#[derive(Debug, Clone)]
pub struct MeritWatch {
    params: HarvesterParams,
    /// The chain's gaps at rest δₖ, m.
    rest_gaps: Vec<f64>,
    /// Scratch: the gaps at an event, m.
    gaps: Vec<f64>,
    from: f64,
    period: f64,
    set: StateSet,
    /// Range of the stroke coordinate (the gap, or `(D₂ − D₁)/2`), m.
    stroke: (f64, f64),
    /// The stroke coordinate at each sample, m, for counting cycles.
    strokes: Vec<f32>,
    /// Times of the first and last kept samples, s.
    span: (f64, f64),
    counted: bool,
    boundary: Vec<BoundaryPoint>,
    stride: u64,
    seen: u64,
}

impl MeritWatch {
    /// A watch of the transducer `params` on a chain with the gaps at rest `rest_gaps`, m,
    /// from time `from`, s, on, counting cycles per excitation period `period`, s.
    pub fn new(params: &HarvesterParams, rest_gaps: &[f64], from: f64, period: f64) -> Self {
        MeritWatch {
            params: params.clone(),
            rest_gaps: rest_gaps.to_vec(),
            gaps: vec![0.0; rest_gaps.len()],
            from,
            period,
            set: StateSet::new(params),
            stroke: (f64::INFINITY, f64::NEG_INFINITY),
            strokes: Vec::new(),
            span: (f64::NAN, f64::NAN),
            counted: true,
            boundary: Vec::new(),
            stride: 1,
            seen: 0,
        }
    }

    /// Adds one state of the sample grid: time `t`, s, the chain's gaps `gaps`, m.
    pub fn add(&mut self, t: f64, gaps: &[f64]) {
        if t < self.from {
            return;
        }
        let Some(s) = self.add_state(gaps) else {
            return;
        };
        if self.strokes.len() < COUNTED_SAMPLES {
            self.strokes.push(self.stroke_of(gaps).unwrap_or(f64::NAN) as f32);
        } else {
            self.counted = false;
        }
        if self.span.0.is_nan() {
            self.span.0 = t;
        }
        self.span.1 = t;
        if self.seen.is_multiple_of(self.stride) {
            let (lo, hi) = s.allowed;
            let edge = |q: f64| {
                if q.is_finite() {
                    (q, s.voltage(q))
                } else {
                    (f64::NAN, f64::NAN)
                }
            };
            let (l, h) = (edge(lo), edge(hi));
            self.boundary.push(BoundaryPoint {
                q_low_c: l.0,
                v_low_v: l.1,
                q_high_c: h.0,
                v_high_v: h.1,
            });
            if self.boundary.len() >= 2 * BOUNDARY_POINTS {
                let kept: Vec<BoundaryPoint> = self.boundary.iter().step_by(2).copied().collect();
                self.boundary = kept;
                self.stride *= 2;
            }
        }
        self.seen += 1;
    }

    /// The stroke coordinate at the chain's gaps `gaps`, m: the gap in contact-separation
    /// mode, `(D₂ − D₁)/2` in the freestanding mode.
    fn stroke_of(&self, gaps: &[f64]) -> Option<f64> {
        let k = self.params.contact;
        let x = match self.params.mode {
            TransducerMode::ContactSeparation => gaps.get(k).copied(),
            TransducerMode::Freestanding => gaps.get(k + 1).zip(gaps.get(k)).map(|(d2, d1)| 0.5 * (d2 - d1)),
        };
        x.filter(|x| x.is_finite())
    }

    /// Adds the state at the gaps `gaps`, m, to the set and the stroke's range.
    fn add_state(&mut self, gaps: &[f64]) -> Option<CycleState> {
        let s = CycleState::new(&self.params, gaps)?;
        self.set.add(s);
        if let Some(x) = self.stroke_of(gaps) {
            self.stroke = (self.stroke.0.min(x), self.stroke.1.max(x));
        }
        Some(s)
    }

    /// The breakdown boundary at the states seen (at most a few thousand, evenly thinned).
    pub fn boundary(&self) -> &[BoundaryPoint] {
        &self.boundary
    }

    /// The run's cycles per excitation period: rises of the stroke coordinate through ¾ of
    /// its range after a fall below ¼ (a Schmitt trigger), counted between the first and the
    /// last rise on the sample grid; `None` with fewer than two rises.
    fn cycles_per_period(&self) -> Option<f64> {
        if !self.counted || self.period.is_nan() || self.period <= 0.0 {
            return None;
        }
        let (lo, hi) = self
            .strokes
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &q| {
                (a.min(q), b.max(q))
            });
        if hi.is_nan() || lo.is_nan() || hi <= lo {
            return None;
        }
        let (low, high) = (lo + 0.25 * (hi - lo), hi - 0.25 * (hi - lo));
        let dt = (self.span.1 - self.span.0) / (self.strokes.len().max(2) - 1) as f64;
        let (mut armed, mut rises, mut first, mut last) = (false, 0u64, 0usize, 0usize);
        for (j, &q) in self.strokes.iter().enumerate() {
            if q <= low {
                armed = true;
            } else if q >= high && armed {
                armed = false;
                if rises == 0 {
                    first = j;
                }
                last = j;
                rises += 1;
            }
        }
        (rises >= 2 && last > first).then(|| (rises - 1) as f64 * self.period / ((last - first) as f64 * dt))
    }

    /// The figures of merit of the states seen, with the run's energy per period
    /// `energy_per_period`, J, compared per cycle; `None` with fewer than two states.
    pub fn finish(&self, energy_per_period: Option<f64>) -> Option<MeritReport> {
        let stroke = match self.params.mode {
            // Zi et al.'s x_max: the largest separation.
            TransducerMode::ContactSeparation => self.stroke.1,
            TransducerMode::Freestanding => self.stroke.1 - self.stroke.0,
        };
        let mut report = figures_of_merit(&self.params, &self.set, stroke)?;
        report.cycles_per_period = self.cycles_per_period();
        report.energy_per_cycle_j = energy_per_period
            .zip(report.cycles_per_period)
            .map(|(e, n)| e / n);
        report.energy_fraction_of_cmeo = report
            .energy_per_cycle_j
            .filter(|_| report.cmeo_energy_per_cycle_j > 0.0)
            .map(|e| e / report.cmeo_energy_per_cycle_j);
        Some(report)
    }
}

impl RunObserver for MeritWatch {
    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, s: &Sample<'_>) {
        if s.electrical.is_some() {
            self.add(s.time, s.gaps);
        }
    }

    fn event(&mut self, e: &Event, state: &StateView<'_>) {
        if e.time < self.from || state.positions.len() != self.rest_gaps.len() + 1 {
            return;
        }
        let mut gaps = std::mem::take(&mut self.gaps);
        for (k, g) in gaps.iter_mut().enumerate() {
            *g = (self.rest_gaps[k] - (state.positions[k + 1] - state.positions[k])).max(0.0);
        }
        self.add_state(&gaps);
        self.gaps = gaps;
    }
}

/// A watch that may be absent (a run without a harvester): observes nothing then.
impl RunObserver for Option<MeritWatch> {
    fn wants_samples(&self) -> bool {
        self.is_some()
    }

    fn sample(&mut self, s: &Sample<'_>) {
        if let Some(w) = self {
            w.sample(s);
        }
    }

    fn event(&mut self, e: &Event, state: &StateView<'_>) {
        if let Some(w) = self {
            w.event(e, state);
        }
    }
}
