//! Frequency-sweep experiments: the chain driven by a slow chirp of the base, up
//! (Ω from `from` to `to`) and down (back), each condensed into a per-cycle response (one
//! row per cycle of the chirp's phase: each mass's displacement amplitude relative to the
//! base, impacts, harvested energy) with its largest jump. Drawn together, the up and down
//! curves show the jumps and the hysteresis that `sweep --continuation up|down` shows.
//!
//! A finite sweep rate delays a jump in the direction of the sweep: the response lags the
//! steady state by about the decay time of the free motion, 1/(ζω) (a few cycles for a
//! lightly damped chain), so the up chirp jumps at a higher Ω and the down chirp at a lower
//! Ω than the quasi-static branches do, by about the Ω the sweep covers in that time.

use std::f64::consts::TAU;

use thiserror::Error;
use toml::Value;

use super::observer::{RunObserver, Sample};
use super::point::PointError;
use super::settings::Sampling;
use super::simulate::{RunOutcome, StudyError, simulate};
use crate::config::{Config, ConfigError};
use crate::dynamics::{Event, EventKind, StateView};
use crate::electrical::Load;
use crate::excitation::{Chirp, ExcitationKind, ExcitationSpec, Sweep};
use crate::orbits::Cancel;

/// The default [`ChirpOptions::samples_per_cycle`].
pub const DEFAULT_SAMPLES_PER_CYCLE: u64 = 200;

/// The default [`ChirpOptions::jump_window`], cycles.
pub const DEFAULT_JUMP_WINDOW: usize = 5;

/// Fewest chirp cycles a sweep may have.
pub const MIN_CYCLES: f64 = 10.0;

/// A frequency-sweep experiment.
#[derive(Debug, Clone, PartialEq)]
pub struct ChirpOptions {
    /// Lower end of the sweep, Ω = ω/√(k₁/m₁) (dimensionless).
    pub from: f64,
    /// Upper end of the sweep, Ω (dimensionless); above `from`.
    pub to: f64,
    /// Duration of each chirp (up, then down), s.
    pub duration_s: f64,
    /// Linear or logarithmic in frequency.
    pub sweep: Sweep,
    /// Base displacement amplitude, m (`None`: the configuration's `excitation.amplitude`).
    pub amplitude: Option<f64>,
    /// Skip the harvester (no energy per cycle).
    pub mechanics_only: bool,
    /// Start each chirp from the steady motion at its start frequency (the harmonic run at
    /// that Ω settled as `sweep --settle auto` settles a point, from the configuration's
    /// initial state; its state at a period's end, where the phase of the base is 0 as at
    /// the chirp's start), so that no start-up transient shows in the response; `false`:
    /// from the configuration's initial state.
    pub settled_start: bool,
    /// Samples of the motion per cycle at the highest frequency (the amplitudes are the
    /// extremes over the samples and the events; the energy a trapezoidal quadrature over
    /// the samples).
    pub samples_per_cycle: u64,
    /// Cycles on each side of a boundary whose median amplitudes are compared to find the
    /// jump ([`largest_jump`]).
    pub jump_window: usize,
    /// Polled at every period and Newton iteration of the settling at the start frequency
    /// ([`settled_start`](Self::settled_start)): when it asks, the chirp stops with
    /// [`ChirpError::Settle`] holding [`PointError::Stopped`]. (The chirp itself stops where
    /// the observer given to [`run_chirp`] says.) Default: never.
    pub cancel: Cancel,
}

impl ChirpOptions {
    /// A linear sweep of Ω from `from` to `to` in `duration_s` seconds each way, with the
    /// configuration's amplitude and harvester.
    pub fn new(from: f64, to: f64, duration_s: f64) -> Self {
        ChirpOptions {
            from,
            to,
            duration_s,
            sweep: Sweep::Linear,
            amplitude: None,
            mechanics_only: false,
            settled_start: true,
            samples_per_cycle: DEFAULT_SAMPLES_PER_CYCLE,
            jump_window: DEFAULT_JUMP_WINDOW,
            cancel: Cancel::never(),
        }
    }
}

/// A frequency-sweep experiment that cannot run.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ChirpError {
    /// An option of [`ChirpOptions`] is bad (`option` is its name: `from`, `to`,
    /// `duration`, `amplitude`, `samples_per_cycle`).
    #[error("{option}: {message}")]
    Option {
        /// The option at fault.
        option: &'static str,
        /// Why.
        message: String,
    },
    /// The chirp configuration is refused (naming the key).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The run could not start.
    #[error(transparent)]
    Study(#[from] StudyError),
    /// Settling at the start frequency failed.
    #[error("settling the harmonic motion at Ω = {omega_ratio} (the chirp's start): {source}")]
    Settle {
        /// The start Ω.
        omega_ratio: f64,
        /// Why.
        source: Box<PointError>,
    },
}

fn bad(option: &'static str, message: String) -> ChirpError {
    ChirpError::Option { option, message }
}

/// Which way a chirp sweeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// From `from` to `to`.
    Up,
    /// From `to` to `from`.
    Down,
}

impl Direction {
    /// `up` or `down`.
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }
}

/// One cycle of a chirp's phase, 2πc ≤ φ < 2π(c + 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Cycle {
    /// Cycle number c + 1 (from 1).
    pub cycle: u64,
    /// Start and end of the cycle, s.
    pub start_s: f64,
    /// End of the cycle, s.
    pub end_s: f64,
    /// Middle of the cycle, s.
    pub time_s: f64,
    /// Instantaneous Ω at the middle (dimensionless).
    pub omega_ratio: f64,
    /// Instantaneous frequency at the middle, Hz.
    pub frequency_hz: f64,
    /// Displacement amplitude of each mass relative to the base, (max − min)/2 of x_i − y
    /// over the cycle (samples and events), m.
    pub amplitudes: Vec<f64>,
    /// Impacts in the cycle (between masses and against stops).
    pub impacts: u64,
    /// Energy delivered to the load in the cycle, J (with a harvester).
    pub energy_j: Option<f64>,
}

impl Cycle {
    /// Average power delivered to the load over the cycle, W (with a harvester).
    pub fn power_w(&self) -> Option<f64> {
        self.energy_j.map(|e| e / (self.end_s - self.start_s))
    }
}

/// The largest jump of the response ([`largest_jump`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Jump {
    /// The cycle before the jump (index into [`ChirpRun::cycles`]); the jump lies between
    /// it and the next.
    pub index: usize,
    /// Ω at the boundary of the two cycles (dimensionless).
    pub omega_ratio: f64,
    /// The mass whose amplitude changes most (0-based).
    pub mass: usize,
    /// The change of its (median) amplitude, m (after − before; > 0 a jump up).
    pub size_m: f64,
    /// The change relative to that mass's largest amplitude in the chirp.
    pub relative: f64,
}

/// One chirp run and its per-cycle response.
#[derive(Debug, Clone)]
pub struct ChirpRun {
    /// Up or down.
    pub direction: Direction,
    /// The chirp of the run (its duration may exceed the requested one by less than a
    /// reference period T, with the same sweep law, so that the run ends on a period).
    pub chirp: Chirp,
    /// The requested duration, s: cycles ending after it are not reported.
    pub duration_s: f64,
    /// The configuration that ran (`excitation.kind = "chirp"`).
    pub config: Config,
    /// The complete cycles, in time order.
    pub cycles: Vec<Cycle>,
    /// The largest jump (None with fewer than 2 × `jump_window` cycles).
    pub jump: Option<Jump>,
    /// What the run layer returned.
    pub outcome: RunOutcome,
}

/// The up and down chirps of one experiment.
#[derive(Debug, Clone)]
pub struct ChirpStudy {
    /// Ω from `from` to `to`.
    pub up: ChirpRun,
    /// Ω from `to` to `from`.
    pub down: ChirpRun,
}

/// The chain's Ω-to-Hz factor √(k₁/m₁)/2π, Hz.
fn hz_per_omega_ratio(config: &Config) -> f64 {
    let chain = config.chain();
    chain.omega() / chain.omega_ratio() / TAU
}

/// Checks `options` against `config`; the error names the option.
pub fn check_options(config: &Config, options: &ChirpOptions) -> Result<(), ChirpError> {
    let positive = |x: f64, option: &'static str| {
        if x.is_finite() && x > 0.0 {
            Ok(())
        } else {
            Err(bad(option, format!("{x} must be finite and > 0")))
        }
    };
    positive(options.from, "from")?;
    positive(options.to, "to")?;
    positive(options.duration_s, "duration")?;
    if options.from >= options.to {
        return Err(bad(
            "from",
            format!(
                "{} must be below to = {} (the down chirp runs from to back to from)",
                options.from, options.to
            ),
        ));
    }
    if let Some(a) = options.amplitude {
        positive(a, "amplitude")?;
    }
    if options.jump_window == 0 {
        return Err(bad("jump_window", "0 must be at least 1".into()));
    }
    if options.samples_per_cycle < 4 {
        return Err(bad(
            "samples_per_cycle",
            format!("{} must be at least 4", options.samples_per_cycle),
        ));
    }
    match config.excitation().kind() {
        ExcitationKind::Harmonic | ExcitationKind::Chirp => {}
        other => {
            return Err(ChirpError::Config(ConfigError::Param(
                crate::error::ParamError::Conflict {
                    name: "excitation.kind".into(),
                    message: format!(
                        "a chirp replaces the base motion of a harmonic configuration; this one is \"{}\"",
                        other.as_str()
                    ),
                },
            )));
        }
    }
    let hz = hz_per_omega_ratio(config);
    let chirp = Chirp {
        amplitude: 1.0,
        f_start_hz: options.from * hz,
        f_end_hz: options.to * hz,
        duration: options.duration_s,
        sweep: options.sweep,
    };
    let cycles = chirp.phase(options.duration_s) / TAU;
    if cycles < MIN_CYCLES {
        return Err(bad(
            "duration",
            format!(
                "{} s holds {cycles:.2} cycles of the chirp from Ω = {} to {} ({:.4} to {:.4} Hz): give at least {MIN_CYCLES}",
                options.duration_s, options.from, options.to, chirp.f_start_hz, chirp.f_end_hz
            ),
        ));
    }
    let relative = config
        .table()
        .get("excitation")
        .and_then(|e| e.get("spline_tolerance"))
        .and_then(Value::as_float)
        .unwrap_or(crate::config::DEFAULT_SPLINE_TOLERANCE);
    let amplitude = options.amplitude.unwrap_or(config.chain().excitation.amplitude);
    if amplitude > 0.0 {
        let chirp = Chirp {
            amplitude,
            duration: options.duration_s + config.chain().period(),
            ..chirp
        };
        chirp
            .intervals_needed(relative * amplitude)
            .map_err(|e| bad("duration", format!("{} s: {e}", options.duration_s)))?;
    }
    let cap = (options.to * hz * options.duration_s) * options.samples_per_cycle as f64;
    if cap > 1e9 {
        return Err(bad(
            "duration",
            format!(
                "{} s at {} samples per cycle would take {cap:.3e} samples (at most 1e9)",
                options.duration_s, options.samples_per_cycle
            ),
        ));
    }
    Ok(())
}

/// The chirp configuration of `config` for one direction: `excitation.kind = "chirp"`, the
/// frequencies from Ω, `duration_s` extended to a whole number of reference periods
/// (`run.periods` of them, no transient) with the same sweep law, the amplitude, and the
/// chirp it describes.
pub fn chirp_config(
    config: &Config,
    options: &ChirpOptions,
    direction: Direction,
) -> Result<(Config, Chirp), ChirpError> {
    check_options(config, options)?;
    let hz = hz_per_omega_ratio(config);
    let (f0, f1) = match direction {
        Direction::Up => (options.from * hz, options.to * hz),
        Direction::Down => (options.to * hz, options.from * hz),
    };
    let requested = Chirp {
        amplitude: options.amplitude.unwrap_or(config.chain().excitation.amplitude),
        f_start_hz: f0,
        f_end_hz: f1,
        duration: options.duration_s,
        sweep: options.sweep,
    };
    let period = config.chain().period();
    let periods = (options.duration_s / period).ceil().max(1.0);
    let duration = periods * period;
    // The same law over the longer duration: f at the requested end is f1.
    let stretch = duration / options.duration_s;
    let f_end = match options.sweep {
        Sweep::Linear => f0 + (f1 - f0) * stretch,
        Sweep::Logarithmic => f0 * (f1 / f0).powf(stretch),
    };
    if f_end.is_nan() || f_end <= 0.0 {
        return Err(bad(
            "duration",
            format!(
                "{} s is too short against the reference period T = {period} s: the sweep cannot be \
                 extended to a whole period (give a longer duration)",
                options.duration_s
            ),
        ));
    }
    let chirp = Chirp {
        f_end_hz: f_end,
        duration,
        ..requested
    };
    let sweep = match options.sweep {
        Sweep::Linear => "linear",
        Sweep::Logarithmic => "logarithmic",
    };
    let mut c = config.clone();
    c.set_all([
        ("excitation.kind", Value::String("chirp".into())),
        ("excitation.f_start_hz", Value::Float(f0)),
        ("excitation.f_end_hz", Value::Float(f_end)),
        ("excitation.sweep", Value::String(sweep.into())),
        ("excitation.duration_s", Value::Float(duration)),
        ("excitation.amplitude", Value::Float(chirp.amplitude)),
        ("run.periods", Value::Integer(periods as i64)),
        ("run.transient_periods", Value::Integer(0)),
    ])?;
    c.check_runnable()?;
    // The chirp as the configuration reads it (bit for bit what drives the run).
    let chirp = match c.excitation() {
        ExcitationSpec::Chirp { chirp, .. } => *chirp,
        _ => chirp,
    };
    Ok((c, chirp))
}

/// The steady state of `config`'s harmonic motion at Ω = `omega_ratio`, at a period's end
/// (mechanics only; [`settle`](super::settle) with the defaults of a sweep point), stopped
/// by `cancel`.
fn settled_state(
    config: &Config,
    omega_ratio: f64,
    cancel: &Cancel,
) -> Result<crate::model::ChainState, ChirpError> {
    let harmonic = config.with("omega_ratio", Value::Float(omega_ratio))?;
    let s = super::settle::settle(
        harmonic.chain(),
        harmonic.initial_state(),
        harmonic.sim_options(),
        &super::point::PointOptions {
            cancel: cancel.clone(),
            ..super::point::PointOptions::default()
        },
        &super::settle::AutoSettle::default(),
    )
    .map_err(|e| ChirpError::Settle {
        omega_ratio,
        source: Box::new(e),
    })?;
    Ok(s.state)
}

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
struct Condenser {
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
    fn new(chirp: Chirp, requested: f64, masses: usize, load: Option<Load>) -> Self {
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

    /// The cycles that end by `final_time` (s, where the run ended).
    fn finish(self, final_time: f64, hz: f64) -> Vec<Cycle> {
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
        out
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

/// Runs one chirp of the experiment through [`simulate`], `observer` shown the run (a
/// progress bar, a checkpoint that may stop it at a period's end), and condenses it into
/// cycles. A run that stops or fails early keeps the cycles it completed
/// ([`RunOutcome::ending`] says why).
pub fn run_chirp<O: RunObserver + ?Sized>(
    config: &Config,
    options: &ChirpOptions,
    direction: Direction,
    observer: &mut O,
) -> Result<ChirpRun, ChirpError> {
    let (chirp_config, chirp) = chirp_config(config, options, direction)?;
    let mut spec = chirp_config.run_spec(options.mechanics_only);
    if options.settled_start {
        let start = match direction {
            Direction::Up => options.from,
            Direction::Down => options.to,
        };
        spec.initial = settled_state(config, start, &options.cancel)?;
    }
    let f_max = chirp.f_start_hz.max(chirp.f_end_hz);
    spec.sampling = Some(Sampling::Uniform {
        start: 0.0,
        step: 1.0 / (f_max * options.samples_per_cycle as f64),
    });
    let load = spec.harvester.as_ref().map(|h| h.params.load);
    let mut condenser = Condenser::new(chirp, options.duration_s, spec.chain.len(), load);
    let outcome = simulate(&spec, &mut (&mut condenser, observer))?;
    let hz = hz_per_omega_ratio(config);
    let bounds = condenser.bounds.clone();
    let cycles = condenser.finish(outcome.final_time, hz);
    let jump = largest_jump(&cycles, options.jump_window, |j| {
        chirp.frequency_hz(bounds[j + 1]) / hz
    });
    Ok(ChirpRun {
        direction,
        chirp,
        duration_s: options.duration_s,
        config: chirp_config,
        cycles,
        jump,
        outcome,
    })
}

/// The up chirp, then the down chirp (see [`run_chirp`]).
pub fn chirp_study<O: RunObserver + ?Sized>(
    config: &Config,
    options: &ChirpOptions,
    observer: &mut O,
) -> Result<ChirpStudy, ChirpError> {
    let up = run_chirp(config, options, Direction::Up, observer)?;
    let down = run_chirp(config, options, Direction::Down, observer)?;
    Ok(ChirpStudy { up, down })
}
