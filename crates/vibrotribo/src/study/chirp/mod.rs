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

use std::sync::Arc;

use thiserror::Error;

use super::observer::RunObserver;
use super::point::PointError;
use super::settings::{RunSpec, Sampling};
use super::simulate::{RunOutcome, StudyError, simulate};
use crate::config::{Config, ConfigError, DEFAULT_SPLINE_TOLERANCE};
use crate::excitation::{
    BaseMotion, BaseMotionError, Chirp, ExcitationKind, ExcitationSpec, Harmonic, Sweep, WorkBudget,
};
use crate::model::{ChainParams, Frequency, StopFrame};
use crate::orbits::Cancel;

mod condense;

use condense::Condenser;
pub use condense::largest_jump;

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
    /// Bound on the chirp spline's displacement error relative to the amplitude
    /// (dimensionless; a configuration's `excitation.spline_tolerance`, see
    /// [`chirp_inputs`]).
    pub spline_tolerance: f64,
    /// The budget the chirp's spline is built within: its stop flag stops the build
    /// (a configuration's budget, see [`chirp_inputs`]). Default: unbounded, never stopped.
    pub budget: WorkBudget,
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
            spline_tolerance: DEFAULT_SPLINE_TOLERANCE,
            budget: WorkBudget::default(),
        }
    }

    /// Reference periods T of `chain` each chirp runs: the duration rounded up to a whole
    /// number of them (at least one).
    pub fn run_periods(&self, chain: &ChainParams) -> u64 {
        (self.duration_s / chain.period()).ceil().max(1.0) as u64
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
    /// The configuration is refused (naming the key), or the chirp's base motion cannot be
    /// built or run on its chain (named as the key `excitation.kind` of a chirp).
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
    /// The run that ran: the chain under the chirp (its base motion), no transient, a whole
    /// number of reference periods.
    pub spec: RunSpec,
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
fn hz_per_omega_ratio(chain: &ChainParams) -> f64 {
    chain.omega() / chain.omega_ratio() / TAU
}

/// An error naming `excitation.kind`: the chirp's base motion cannot be built or run.
fn kind_error(message: String) -> ChirpError {
    ChirpError::Config(ConfigError::Param(crate::error::ParamError::Conflict {
        name: "excitation.kind".into(),
        message,
    }))
}

/// Checks `options` against the run `spec` a chirp replaces the base motion of (its chain
/// under its own harmonic); the error names the option.
pub fn check_options(spec: &RunSpec, options: &ChirpOptions) -> Result<(), ChirpError> {
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
    positive(options.spline_tolerance, "spline_tolerance")?;
    if options.jump_window == 0 {
        return Err(bad("jump_window", "0 must be at least 1".into()));
    }
    if options.samples_per_cycle < 4 {
        return Err(bad(
            "samples_per_cycle",
            format!("{} must be at least 4", options.samples_per_cycle),
        ));
    }
    if let Some(base) = spec.base_motion.as_deref()
        && !matches!(base, BaseMotion::Harmonics(h) if crate::dynamics::as_chain_harmonic(h, &spec.chain).is_some())
    {
        return Err(kind_error(format!(
            "a chirp replaces the base motion of a harmonic run; this one is \"{}\"",
            base.kind().as_str()
        )));
    }
    let chain = &spec.chain;
    // Stops that move with the base follow the harmonic only.
    if [chain.stops.upper, chain.stops.lower]
        .iter()
        .flatten()
        .any(|s| s.frame == StopFrame::Base)
    {
        let e = BaseMotionError::MovingStops { kind: "chirp" };
        return Err(ChirpError::Config(ConfigError::Unsupported(format!(
            "excitation kind chirp: {e}"
        ))));
    }
    let hz = hz_per_omega_ratio(chain);
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
    let amplitude = options.amplitude.unwrap_or(chain.excitation.amplitude);
    if amplitude > 0.0 {
        let chirp = Chirp {
            amplitude,
            duration: options.duration_s + chain.period(),
            ..chirp
        };
        chirp
            .intervals_needed(options.spline_tolerance * amplitude)
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

/// The run of a configuration a chirp starts from, and the chirp's options with the
/// configuration's `excitation.spline_tolerance` and work budget: `config`'s chain,
/// initial state, numerical settings and (unless `options.mechanics_only`) harvester, under
/// the chain's own harmonic. The configuration's base motion must be harmonic or a chirp
/// (which the experiment's chirps replace); an error naming `excitation.kind` otherwise.
pub fn chirp_inputs(config: &Config, options: &ChirpOptions) -> Result<(RunSpec, ChirpOptions), ChirpError> {
    match config.excitation().kind() {
        ExcitationKind::Harmonic | ExcitationKind::Chirp => {}
        other => {
            return Err(kind_error(format!(
                "a chirp replaces the base motion of a harmonic configuration; this one is \"{}\"",
                other.as_str()
            )));
        }
    }
    let spec = RunSpec {
        base_motion: None,
        ..config.run_spec(options.mechanics_only)
    };
    let options = ChirpOptions {
        spline_tolerance: config.spline_tolerance(),
        budget: config.budget().clone(),
        ..options.clone()
    };
    check_options(&spec, &options)?;
    Ok((spec, options))
}

/// One chirp of the experiment, ready to run ([`plan_chirp`]).
#[derive(Debug, Clone)]
pub struct ChirpPlan {
    /// Up or down.
    pub direction: Direction,
    /// The chirp (over a whole number of reference periods, see [`ChirpRun::chirp`]).
    pub chirp: Chirp,
    /// The run under it: the chain with the chirp as its base motion, from the initial state
    /// given, `periods` reference periods, no transient.
    pub spec: RunSpec,
}

/// The chirp of `options` in `direction` as a run of `spec`'s chain (the run a chirp
/// replaces the base motion of): the frequencies from Ω, `duration_s` extended to a whole
/// number of reference periods with the same sweep law, the amplitude, the spline built
/// within `options.budget` (stopped by its stop flag). The harvester is `spec`'s, dropped
/// with `options.mechanics_only`.
pub fn plan_chirp(
    spec: &RunSpec,
    options: &ChirpOptions,
    direction: Direction,
) -> Result<ChirpPlan, ChirpError> {
    check_options(spec, options)?;
    let hz = hz_per_omega_ratio(&spec.chain);
    let (f0, f1) = match direction {
        Direction::Up => (options.from * hz, options.to * hz),
        Direction::Down => (options.to * hz, options.from * hz),
    };
    let period = spec.chain.period();
    let periods = options.run_periods(&spec.chain);
    let duration = periods as f64 * period;
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
        amplitude: options.amplitude.unwrap_or(spec.chain.excitation.amplitude),
        f_start_hz: f0,
        f_end_hz: f_end,
        duration,
        sweep: options.sweep,
    };
    let tolerance = options.spline_tolerance * chirp.amplitude;
    let excitation = ExcitationSpec::Chirp {
        chirp,
        tolerance: if tolerance > 0.0 {
            tolerance
        } else {
            f64::MIN_POSITIVE
        },
    };
    let mut chain = spec.chain.clone();
    chain.excitation.amplitude = chirp.amplitude;
    let harmonic = Harmonic {
        amplitude: chirp.amplitude,
        omega: chain.omega(),
        phase: 0.0,
    };
    let base = excitation
        .build_within(harmonic, &options.budget)
        .map_err(|e| kind_error(format!("kind = \"chirp\": {e}")))?;
    crate::dynamics::check_base_motion(&chain, &base)
        .map_err(|e| ChirpError::Config(ConfigError::Unsupported(format!("excitation kind chirp: {e}"))))?;
    let harvester = spec.harvester.clone().filter(|_| !options.mechanics_only);
    Ok(ChirpPlan {
        direction,
        chirp,
        spec: RunSpec {
            chain,
            harvester,
            periods,
            transient_periods: 0,
            sampling: None,
            breakdown_check: false,
            base_motion: Some(Arc::new(base)),
            ..spec.clone()
        },
    })
}

/// The steady state of `spec`'s harmonic motion at Ω = `omega_ratio`, at a period's end
/// (mechanics only; [`settle`](super::settle) with the defaults of a sweep point), stopped
/// by `cancel`.
fn settled_state(
    spec: &RunSpec,
    omega_ratio: f64,
    cancel: &Cancel,
) -> Result<crate::model::ChainState, ChirpError> {
    let mut chain = spec.chain.clone();
    chain.excitation.frequency = Frequency::OmegaRatio(omega_ratio);
    let s = super::settle::settle(
        &chain,
        &spec.initial,
        &spec.options,
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

/// Runs `plan` through [`simulate`], `observer` shown the run (a progress bar, a checkpoint
/// that may stop it at a period's end), and condenses it into cycles; with
/// `options.settled_start` it starts from the steady harmonic motion of `spec` (the run the
/// plan was made from) at the chirp's start Ω. A run that stops or fails early keeps the
/// cycles it completed ([`RunOutcome::ending`] says why).
pub fn run_plan<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    plan: ChirpPlan,
    options: &ChirpOptions,
    observer: &mut O,
) -> Result<ChirpRun, ChirpError> {
    let ChirpPlan {
        direction,
        chirp,
        spec: mut run,
    } = plan;
    if options.settled_start {
        let start = match direction {
            Direction::Up => options.from,
            Direction::Down => options.to,
        };
        run.initial = settled_state(spec, start, &options.cancel)?;
    }
    let f_max = chirp.f_start_hz.max(chirp.f_end_hz);
    run.sampling = Some(Sampling::Uniform {
        start: 0.0,
        step: 1.0 / (f_max * options.samples_per_cycle as f64),
    });
    let load = run.harvester.as_ref().map(|h| h.params.load);
    let mut condenser = Condenser::new(chirp, options.duration_s, run.chain.len(), load);
    let outcome = simulate(&run, &mut (&mut condenser, observer))?;
    let hz = hz_per_omega_ratio(&spec.chain);
    let (cycles, bounds) = condenser.finish(outcome.final_time, hz);
    let jump = largest_jump(&cycles, options.jump_window, |j| {
        chirp.frequency_hz(bounds[j + 1]) / hz
    });
    Ok(ChirpRun {
        direction,
        chirp,
        duration_s: options.duration_s,
        spec: run,
        cycles,
        jump,
        outcome,
    })
}

/// One chirp of the experiment on `spec`'s chain: [`plan_chirp`], then [`run_plan`].
pub fn run_chirp<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    options: &ChirpOptions,
    direction: Direction,
    observer: &mut O,
) -> Result<ChirpRun, ChirpError> {
    let plan = plan_chirp(spec, options, direction)?;
    run_plan(spec, plan, options, observer)
}

/// The up chirp, then the down chirp (see [`run_chirp`]).
pub fn chirp_study<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    options: &ChirpOptions,
    observer: &mut O,
) -> Result<ChirpStudy, ChirpError> {
    let up = run_chirp(spec, options, Direction::Up, observer)?;
    let down = run_chirp(spec, options, Direction::Down, observer)?;
    Ok(ChirpStudy { up, down })
}
