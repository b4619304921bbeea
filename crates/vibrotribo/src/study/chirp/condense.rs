//! A chirp run condensed into cycles as it goes ([`Condenser`]), and the largest jump of the
//! response ([`largest_jump`]).

use std::f64::consts::TAU;

use super::{Cycle, Jump};
use crate::dynamics::{Event, EventKind, StateView};
use crate::electrical::Load;
use crate::excitation::Chirp;
use crate::study::observer::{RunObserver, Sample};

/// The time (s) at which the chirp's phase reaches `phase` (rad), by bisection (the phase
/// grows strictly).
fn time_at_phase(chirp: &Chirp, phase: f64, end: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, end);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if chirp.phase(mid) < phase {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Condenses a chirp run into cycles as it goes (a [`RunObserver`]).
pub(super) struct Condenser {
    chirp: Chirp,
    /// Cycle boundaries t_0 = 0 < t_1 < … ≤ the requested duration, s.
    bounds: Vec<f64>,
    lo: Vec<Vec<f64>>,
    hi: Vec<Vec<f64>>,
    impacts: Vec<u64>,
    energy: Vec<f64>,
    load: Option<Load>,
    /// The previous sample's time, load power (resistor) or storage voltage (rectifier).
    last: Option<(f64, f64)>,
}

impl Condenser {
    pub(super) fn new(chirp: Chirp, requested: f64, masses: usize, load: Option<Load>) -> Self {
        let cycles = (chirp.phase(requested) / TAU).floor() as usize;
        let mut bounds = vec![0.0];
        bounds.extend((1..=cycles).map(|c| time_at_phase(&chirp, TAU * c as f64, chirp.duration)));
        Condenser {
            chirp,
            lo: vec![vec![f64::INFINITY; masses]; cycles],
            hi: vec![vec![f64::NEG_INFINITY; masses]; cycles],
            impacts: vec![0; cycles],
            energy: vec![0.0; cycles],
            bounds,
            load,
            last: None,
        }
    }

    /// The cycle holding `t`: [t_c, t_{c+1}), the last one closed at its end.
    fn cycle_of(&self, t: f64) -> Option<usize> {
        let cycles = self.bounds.len() - 1;
        let k = self.bounds.partition_point(|&b| b <= t);
        if k >= 1 && k <= cycles {
            Some(k - 1)
        } else if cycles > 0 && t == self.bounds[cycles] {
            Some(cycles - 1)
        } else {
            None
        }
    }

    fn extremes(&mut self, c: usize, positions: &[f64], base: f64) {
        for (i, &x) in positions.iter().enumerate() {
            let r = x - base;
            self.lo[c][i] = self.lo[c][i].min(r);
            self.hi[c][i] = self.hi[c][i].max(r);
        }
    }

    /// The cycles that end by `final_time` (s, where the run ended), and the cycle
    /// boundaries (s).
    pub(super) fn finish(self, final_time: f64, hz: f64) -> (Vec<Cycle>, Vec<f64>) {
        let mut out = Vec::new();
        for c in 0..self.impacts.len() {
            let (start, end) = (self.bounds[c], self.bounds[c + 1]);
            if end > final_time || !self.lo[c].iter().all(|x| x.is_finite()) {
                break;
            }
            let mid = time_at_phase(&self.chirp, TAU * (c as f64 + 0.5), self.chirp.duration);
            let f = self.chirp.frequency_hz(mid);
            out.push(Cycle {
                cycle: c as u64 + 1,
                start_s: start,
                end_s: end,
                time_s: mid,
                omega_ratio: f / hz,
                frequency_hz: f,
                amplitudes: self.lo[c]
                    .iter()
                    .zip(&self.hi[c])
                    .map(|(l, h)| 0.5 * (h - l))
                    .collect(),
                impacts: self.impacts[c],
                energy_j: self.load.map(|_| self.energy[c]),
            });
        }
        (out, self.bounds)
    }
}

impl RunObserver for Condenser {
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        if let Some(c) = self.cycle_of(event.time) {
            if event.kind == EventKind::Impact {
                self.impacts[c] += 1;
            }
            let base = self.chirp.displacement_velocity(event.time)[0];
            self.extremes(c, state.positions, base);
        }
    }

    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, s: &Sample<'_>) {
        if let Some(c) = self.cycle_of(s.time) {
            self.extremes(c, s.positions, s.base);
        }
        let (Some(load), Some(e)) = (self.load, s.electrical) else {
            return;
        };
        // Energy into the load between this sample and the previous one, given to the cycle
        // holding the interval's middle: ∫V²/R (trapezoid) for a resistor; for a rectifier
        // the storage energy's change ½C(V_s² − V_s,prev²) plus ∫V_s²/R_s (its resistor).
        let now = match load {
            Load::Resistor { resistance } => e.voltage_v * e.voltage_v / resistance,
            Load::Rectifier(_) => e.storage_voltage_v.unwrap_or(0.0),
            Load::Open | Load::Short => 0.0,
        };
        if let Some((t0, before)) = self.last
            && let Some(c) = self.cycle_of(0.5 * (t0 + s.time))
        {
            let dt = s.time - t0;
            self.energy[c] += match load {
                Load::Resistor { .. } => 0.5 * (before + now) * dt,
                Load::Rectifier(r) => {
                    let drain = r
                        .storage_load_resistance
                        .map_or(0.0, |rs| 0.5 * (before * before + now * now) / rs * dt);
                    // ½C(V1² − V0²) as a product: no cancellation at a large storage voltage.
                    0.5 * r.storage_capacitance * (now - before) * (now + before) + drain
                }
                Load::Open | Load::Short => 0.0,
            };
        }
        self.last = Some((s.time, now));
    }
}

/// The largest jump of the response (the jump criterion): the boundary between consecutive
/// cycles where the median amplitude of the `window` cycles after it differs most from the
/// median of the `window` cycles before it, for any mass, relative to that mass's largest
/// amplitude in the chirp. `window` = 1 is the plain cycle-to-cycle change; a few cycles keep
/// the cycle-to-cycle scatter of an irregular (chaotic, period-n) motion from passing for a
/// jump, and the median keeps a step a step. `omega_at(j)` is Ω at the end of cycle `j`.
pub fn largest_jump(cycles: &[Cycle], window: usize, omega_at: impl Fn(usize) -> f64) -> Option<Jump> {
    let n = cycles.first()?.amplitudes.len();
    let w = window.max(1);
    if cycles.len() < 2 * w {
        return None;
    }
    let median = |i: usize, range: std::ops::Range<usize>| {
        let mut v: Vec<f64> = cycles[range].iter().map(|c| c.amplitudes[i]).collect();
        v.sort_by(f64::total_cmp);
        let m = v.len() / 2;
        if v.len() % 2 == 1 {
            v[m]
        } else {
            0.5 * (v[m - 1] + v[m])
        }
    };
    let mut best: Option<Jump> = None;
    for i in 0..n {
        let top = cycles.iter().map(|c| c.amplitudes[i]).fold(0.0, f64::max);
        if top <= 0.0 {
            continue;
        }
        for j in (w - 1)..(cycles.len() - w) {
            let size = median(i, j + 1..j + 1 + w) - median(i, j + 1 - w..j + 1);
            let relative = size.abs() / top;
            if best.as_ref().is_none_or(|b| relative > b.relative) {
                best = Some(Jump {
                    index: j,
                    omega_ratio: omega_at(j),
                    mass: i,
                    size_m: size,
                    relative,
                });
            }
        }
    }
    best
}
