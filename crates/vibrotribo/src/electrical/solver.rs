//! The charge solver: integrates the circuit equations driven by a gap waveform.
//!
//! ## Equations
//!
//! With `Q` the charge moved between the electrodes, the transducer's terminal voltage is
//! `V = V_oc − Q/C` (seed eq. 11); `Q_eq = C·V_oc` is the equilibrium (short-circuit) charge.
//!
//! ```text
//! resistor R:    Q' = V/R = −(Q − Q_eq)/(R C)                power V²/R
//! rectifier:     Q' = I(V, V_s),  C_s V_s' = I_out(V, V_s) − V_s/R_L     power V_s·I_out
//! ```
//!
//! (bridge currents from [`Diode::bridge`](super::Diode::bridge)). The resistor equation is
//! linear and stiff: R·C runs from ~0.2 µs to ~90 µs against a ~0.1 s period at the paper's
//! 100 kΩ.
//!
//! ## Method
//!
//! 3-stage Radau IIA (order 5, L-stable) on these equations, with the stage values of `Q`
//! written as `u = Q − Q_eq = −C·V` and the exact increments `Q_eq(tᵢ) − Q_eq(t₀)` of the
//! waveform: the unknowns then hold the load voltage without cancellation when it is a
//! millionth of V_oc (small R), and `Q` stays exactly constant when nothing flows (R → ∞).
//! For the resistor the stage system is a 3×3 linear solve (exact); for the rectifier it is
//! solved by Newton's method with the exact Jacobian at every stage. The delivered energy is
//! a quadrature component of the same collocation, `ΔE = h Σ bⱼ p(tⱼ, Yⱼ)` over the stage
//! values, not a sampled sum.
//!
//! Error control uses Hairer's embedded estimate (RADAU5's first estimate, without its
//! second, "stiffly filtered" one, which in the quasi-static regime of a small load accepts
//! steps 10⁴ times too long) on two things:
//!
//! - the load voltage `−u/C` (and the storage voltage), per step, `rtol·|V| + atol`; by
//!   default `atol = rtol × (largest |V| seen)` for the resistor, `rtol × (largest V_s seen,
//!   at least nV_T)` for the rectifier;
//! - the energy, per unit step, against `rtol × (average power)`: summed over a period the
//!   allowed error is `rtol ×` the period's energy. Without this the voltage test alone lets
//!   a stiff load take steps of a tenth of a period, far too long for the quadrature of V².
//!
//! A noise allowance keeps the tests above the precision of the input (gaps are differences
//! of positions), so tight tolerances cannot drive the step to zero. The step size follows
//! RADAU5's controller with Gustafsson's predictive variant; a failed stiff step jumps to
//! `h·k ≈ 2` (a boundary layer after a kink).
//!
//! Every call of [`ChargeSolver::advance`] restarts the integration (mechanical kinks such as
//! impacts fall on flow boundaries), and excitation period boundaries are step boundaries, so
//! energy is booked per period exactly. Sampled outputs come from the collocation
//! polynomial with the transducer evaluated exactly at the sample time.

use super::ElectricalError;
use super::diode::Diode;
use super::params::{HarvesterParams, LoadKind};
use super::radau::{Tableau, solve_dense};
use super::transducer::{Transducer, TransducerState};
use super::waveform::{GapWaveform, PwlGaps};
use crate::dynamics::{Flow, Observer, Trajectory};
use crate::error::ParamError;
use crate::model::ChainParams;

/// Numerical settings of the charge solver.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct ChargeOptions {
    /// Relative tolerance of the local error on the load voltage (and storage voltage) per
    /// step and of the delivered energy per period (`electrical.rtol`), dimensionless.
    /// Default 1e-5, which keeps the energy per period within 1e-7 relative of a converged
    /// solution on the paper's default and chatter cases for loads from 1 kΩ to 10 GΩ.
    pub rtol: f64,
    /// Absolute voltage tolerance, V (`electrical.atol_voltage`). Absent (default): `rtol`
    /// times the largest load voltage seen so far (resistor) or the largest storage voltage,
    /// at least nV_T (rectifier).
    pub atol_voltage: Option<f64>,
    /// Guard against runaway step counts (`electrical.max_steps_per_period`): at most this
    /// many steps, accepted or rejected, within one excitation period. Default 10 000 000.
    pub max_steps_per_period: u64,
}

impl Default for ChargeOptions {
    fn default() -> Self {
        ChargeOptions {
            rtol: 1e-5,
            atol_voltage: None,
            max_steps_per_period: 10_000_000,
        }
    }
}

impl ChargeOptions {
    /// Checks the options, naming the offending key.
    pub fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &str, value: f64, reason| ParamError::Invalid {
            name: name.into(),
            value,
            reason,
        };
        if !(self.rtol.is_finite() && self.rtol >= 1e-12 && self.rtol <= 1e-2) {
            return Err(bad("electrical.rtol", self.rtol, "must lie in [1e-12, 1e-2]"));
        }
        if let Some(a) = self.atol_voltage
            && !(a.is_finite() && a > 0.0)
        {
            return Err(bad("electrical.atol_voltage", a, "must be positive"));
        }
        if self.max_steps_per_period == 0 {
            return Err(bad("electrical.max_steps_per_period", 0.0, "must be positive"));
        }
        Ok(())
    }
}

/// What one excitation period `[kT, (k+1)T)` delivered.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PeriodStats {
    /// Period index k (time `kT` to `(k+1)T`).
    pub index: i64,
    /// Start of the part of the period covered, s.
    pub t_start: f64,
    /// End of the part of the period covered, s.
    pub t_end: f64,
    /// Energy delivered to the load in the period, J: `∫ V²/R dt` for the resistor (seed
    /// eq. 14's numerator), `∫ V_s I_out dt` (into storage capacitor and its resistor) for the
    /// rectifier, 0 for open and short circuit.
    pub energy_j: f64,
    /// Largest |current| seen in the period (at solver nodes and sample times), A.
    pub peak_current_a: f64,
    /// Largest |terminal voltage| seen in the period (at solver nodes and sample times), V.
    pub peak_voltage_v: f64,
    /// Storage capacitor voltage at the end of the covered part, V (rectifier only).
    pub storage_voltage_v: Option<f64>,
}

impl PeriodStats {
    /// Whether the whole period `period`, s, was covered.
    pub fn is_complete(&self, period: f64) -> bool {
        self.t_end - self.t_start >= period * (1.0 - 1e-9)
    }
}

/// Electrical quantities sampled at given times.
#[derive(Debug, Clone, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ElectricalSamples {
    /// Sample times, s.
    pub times: Vec<f64>,
    /// Charge moved between the electrodes Q, C.
    pub charge_c: Vec<f64>,
    /// Current out of the transducer I = dQ/dt, A.
    pub current_a: Vec<f64>,
    /// Terminal (load) voltage V = V_oc − Q/C, V.
    pub voltage_v: Vec<f64>,
    /// Transducer capacitance C, F.
    pub capacitance_f: Vec<f64>,
    /// Open-circuit voltage V_oc, V.
    pub voc_v: Vec<f64>,
    /// Storage capacitor voltage, V (rectifier only; empty otherwise).
    pub storage_voltage_v: Vec<f64>,
    /// Energy delivered to the load since the solver started, J.
    pub energy_j: Vec<f64>,
}

impl ElectricalSamples {
    fn push(&mut self, t: f64, row: &Row, rectifier: bool) {
        self.times.push(t);
        self.charge_c.push(row.charge);
        self.current_a.push(row.current);
        self.voltage_v.push(row.voltage);
        self.capacitance_f.push(1.0 / row.ts.elastance);
        self.voc_v.push(row.ts.voc);
        if rectifier {
            self.storage_voltage_v.push(row.storage);
        }
        self.energy_j.push(row.energy);
    }
}

/// Work counters of a solver.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolverStats {
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps (error test or Newton failure).
    pub rejected: u64,
    /// Newton iterations (rectifier).
    pub newton_iterations: u64,
    /// Evaluations of the gap waveform.
    pub waveform_evaluations: u64,
    /// Smooth pieces integrated (flows, split at period boundaries).
    pub pieces: u64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum LoadModel {
    Resistor {
        conductance: f64,
    },
    Rectifier {
        diode: Diode,
        inv_cs: f64,
        load_conductance: f64,
    },
    Open,
    Short,
}

/// A uniform grid `t0 + j·dt`, j = 0, 1, …, up to `last` if given.
#[derive(Debug, Clone)]
struct Grid {
    t0: f64,
    dt: f64,
    next: u64,
    last: Option<u64>,
    data: ElectricalSamples,
}

impl Grid {
    /// The next grid time inside `[ta, tb]`, advancing past earlier ones.
    fn next_in(&mut self, ta: f64, tb: f64) -> Option<f64> {
        loop {
            if self.last.is_some_and(|l| self.next > l) {
                return None;
            }
            let t = self.t0 + self.next as f64 * self.dt;
            if t > tb {
                return None;
            }
            self.next += 1;
            if t >= ta {
                return Some(t);
            }
        }
    }
}

/// Electrical quantities at one instant.
#[derive(Debug, Clone, Copy)]
struct Row {
    ts: TransducerState,
    charge: f64,
    current: f64,
    voltage: f64,
    storage: f64,
    energy: f64,
}

/// One accepted Radau step: enough to evaluate its collocation polynomial.
#[derive(Debug, Clone, Copy)]
struct Step {
    t0: f64,
    h: f64,
    y0: [f64; 2],
    z: [[f64; 2]; 3],
    e0: f64,
    ze: [f64; 3],
    /// `Q_eq` at t0 and its increments at the stages, C.
    qeq0: f64,
    dq: [f64; 3],
    stiff: bool,
}

/// Result of solving the stages of one trial step.
#[derive(Debug, Clone, Copy, Default)]
struct Trial {
    z: [[f64; 2]; 3],
    /// Stage increments of the delivered energy, J.
    ze: [f64; 3],
    /// Stage values of the terminal voltage, V, and current, A.
    voltage: [f64; 3],
    current: [f64; 3],
    /// Scaled error estimate (≤ 1 accepts).
    err: f64,
    /// Whether the step is stiff (h·|∂Q'/∂Q| ≥ 1): then `u` is interpolated directly in dense
    /// output, otherwise `Q` (and `u = Q − Q_eq` with the exact `Q_eq`).
    stiff: bool,
    /// h·|∂Q'/∂Q| at t0.
    hk: f64,
    /// `Q_eq` at t0 and its increments at the stages, C.
    qeq0: f64,
    dq: [f64; 3],
}

/// Integrates the transducer's charge and the load driven by gap waveforms (see the module
/// docs). As an [`Observer`] it consumes the simulator's flows directly; any other waveform
/// goes through [`advance`](Self::advance).
///
/// ```
/// use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
/// use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams};
///
/// let chain = ChainParams::default();
/// let mut sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default())?;
/// let mut solver = ChargeSolver::for_chain(&HarvesterParams::default(), &chain, ChargeOptions::default())?;
/// sim.run_until(6.0 * chain.period(), &mut solver)?;
/// solver.status()?;
/// let summary = solver.summary(2).expect("four periods after the transient");
/// assert!(summary.average_power_w > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct ChargeSolver {
    transducer: Transducer,
    load: LoadModel,
    options: ChargeOptions,
    tab: Tableau,
    period: f64,
    gaps: Vec<f64>,
    rates: Vec<f64>,
    initial_charge: Option<f64>,
    storage_initial_voltage: f64,
    target_voltage: Option<f64>,
    v_floor: f64,
    started: bool,
    t: f64,
    /// State: u = Q − C·V_oc, C; storage voltage, V.
    y: [f64; 2],
    /// The transducer at `t`.
    ts_now: TransducerState,
    /// The charge held by an open circuit, C.
    open_charge: f64,
    /// Energy delivered since the start, J.
    energy: f64,
    h: f64,
    h_acc: f64,
    err_acc: f64,
    have_acc: bool,
    /// Voltage scale of the default absolute tolerance, V.
    v_scale: f64,
    /// Time the solver started, s.
    t_start: f64,
    last_step: Option<Step>,
    periods: Vec<PeriodStats>,
    steps_in_period: u64,
    sampler: Option<Grid>,
    vq: Option<Grid>,
    target_time: Option<f64>,
    stats: SolverStats,
    error: Option<ElectricalError>,
}

/// Most Newton iterations per stage solve before the step is retried smaller.
const MAX_NEWTON: usize = 12;

/// Relative noise allowance of the error estimates: an estimate below this fraction of the
/// terms it is computed from is noise and never rejects a step. The floor is the precision of
/// the input, not of the arithmetic: gaps are differences of positions (~0.1 m) carried to
/// ~1e-17 m, which near contact is ~1e-13 of d₀ + D (d₀ ~ 0.1 mm).
const NOISE: f64 = 1e-12;

/// Absolute noise allowance of the equilibrium charge, as a fraction of the charge scale σS:
/// the gap rounding above moves `Q_eq` by `(∂Q_eq/∂D)·δD ~ 1e-21 C` on the paper's device even
/// where `Q_eq` itself is near zero.
const NOISE_CHARGE: f64 = 1e-13;

impl ChargeSolver {
    /// A solver for the harvester `params` on a chain with `gaps` gaps (N − 1), booking energy
    /// per excitation period `period`, s.
    pub fn new(
        params: &HarvesterParams,
        period: f64,
        gaps: usize,
        options: ChargeOptions,
    ) -> Result<Self, ParamError> {
        params.validate_for_gaps(gaps)?;
        options.validate()?;
        if !(period.is_finite() && period > 0.0) {
            return Err(ParamError::Invalid {
                name: "excitation.period".into(),
                value: period,
                reason: "must be positive",
            });
        }
        let transducer = params.transducer();
        let load = match params.load {
            LoadKind::Resistor => LoadModel::Resistor {
                conductance: 1.0 / params.load_resistance,
            },
            LoadKind::Rectifier => LoadModel::Rectifier {
                diode: params.diode(),
                inv_cs: 1.0 / params.storage_capacitance,
                load_conductance: params.storage_load_resistance.map_or(0.0, |r| 1.0 / r),
            },
            LoadKind::Open => LoadModel::Open,
            LoadKind::Short => LoadModel::Short,
        };
        let v_floor = match load {
            LoadModel::Rectifier { diode, .. } => diode.ideality * diode.thermal_voltage,
            _ => (1e-12 * transducer.voltage_scale()).max(f64::MIN_POSITIVE),
        };
        Ok(ChargeSolver {
            transducer,
            load,
            options,
            tab: Tableau::new(),
            period,
            gaps: vec![0.0; gaps],
            rates: vec![0.0; gaps],
            initial_charge: params.initial_charge,
            storage_initial_voltage: params.storage_initial_voltage,
            target_voltage: params.target_voltage,
            v_floor,
            started: false,
            t: 0.0,
            y: [0.0; 2],
            ts_now: TransducerState::default(),
            open_charge: 0.0,
            energy: 0.0,
            h: 1e-6 * period,
            h_acc: 0.0,
            err_acc: 0.0,
            have_acc: false,
            v_scale: 0.0,
            t_start: 0.0,
            last_step: None,
            periods: Vec::new(),
            steps_in_period: 0,
            sampler: None,
            vq: None,
            target_time: None,
            stats: SolverStats::default(),
            error: None,
        })
    }

    /// A solver for the harvester `params` mounted on `chain` (its period and gap count).
    pub fn for_chain(
        params: &HarvesterParams,
        chain: &ChainParams,
        options: ChargeOptions,
    ) -> Result<Self, ParamError> {
        chain.validate()?;
        ChargeSolver::new(params, chain.period(), chain.len() - 1, options)
    }

    /// Also records [`samples`](Self::samples) at `t0 + j·dt` (s), j = 0, 1, ….
    pub fn with_sampling(mut self, t0: f64, dt: f64) -> Result<Self, ParamError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(ParamError::Invalid {
                name: "output.sample_interval".into(),
                value: dt,
                reason: "must be positive",
            });
        }
        if !t0.is_finite() {
            return Err(ParamError::Invalid {
                name: "output.sample_start".into(),
                value: t0,
                reason: "must be a finite number",
            });
        }
        self.sampler = Some(Grid {
            t0,
            dt,
            next: 0,
            last: None,
            data: ElectricalSamples::default(),
        });
        Ok(self)
    }

    /// Also records the V–Q cycle of period `index` (time `index·T` to `(index+1)·T`) at
    /// `points + 1` equally spaced times, ends included; see [`vq_cycle`](Self::vq_cycle).
    pub fn with_vq_cycle(mut self, index: u64, points: usize) -> Result<Self, ParamError> {
        if points == 0 {
            return Err(ParamError::Invalid {
                name: "output.vq_points".into(),
                value: 0.0,
                reason: "must be positive",
            });
        }
        self.vq = Some(Grid {
            t0: index as f64 * self.period,
            dt: self.period / points as f64,
            next: 0,
            last: Some(points as u64),
            data: ElectricalSamples::default(),
        });
        Ok(self)
    }

    /// Advances the solution over `[t0, t1]`, s, on which `wave` is smooth (see
    /// [`GapWaveform`]). The first call starts the solver at `t0` (with the initial charge);
    /// every later call must start where the previous one ended.
    pub fn advance<W: GapWaveform + ?Sized>(
        &mut self,
        t0: f64,
        t1: f64,
        wave: &W,
    ) -> Result<(), ElectricalError> {
        if !t0.is_finite() || !t1.is_finite() || t1 < t0 {
            return Err(ElectricalError::Backwards {
                requested: t1,
                current: t0,
            });
        }
        if !self.started {
            self.start(t0, wave)?;
        } else if (t0 - self.t).abs() > 1e-9 * self.period.max(self.t.abs()) {
            return Err(ElectricalError::Discontiguous {
                expected: self.t,
                got: t0,
            });
        }
        let eps = 1e-12 * self.period;
        while self.t < t1 {
            let k = (self.t / self.period).floor();
            let mut boundary = (k + 1.0) * self.period;
            if boundary <= self.t + eps {
                boundary += self.period;
            }
            let end = if boundary < t1 - eps { boundary } else { t1 };
            self.piece(self.t, end, wave)?;
        }
        Ok(())
    }

    /// Runs over every piece of a piecewise-linear waveform.
    pub fn run_pwl(&mut self, pwl: &PwlGaps) -> Result<(), ElectricalError> {
        if pwl.gap_count() != self.gaps.len() {
            return Err(ParamError::Length {
                name: "pwl.gaps".into(),
                expected: self.gaps.len(),
                got: pwl.gap_count(),
            }
            .into());
        }
        for j in 0..pwl.pieces() {
            let p = pwl.piece(j);
            let (a, b) = p.span();
            self.advance(a, b, &p)?;
        }
        Ok(())
    }

    /// Replays a recorded trajectory (every segment of flow, in order).
    pub fn run_trajectory(&mut self, trajectory: &Trajectory) -> Result<(), ElectricalError> {
        if trajectory.segments().is_empty() {
            return Err(ElectricalError::EmptyTrajectory);
        }
        for seg in trajectory.segments() {
            let flow = trajectory
                .flow_at(seg.t_start)
                .ok_or(ElectricalError::EmptyTrajectory)?;
            if flow.len() - 1 != self.gaps.len() {
                return Err(ParamError::Length {
                    name: "trajectory.gaps".into(),
                    expected: self.gaps.len(),
                    got: flow.len() - 1,
                }
                .into());
            }
            self.advance(seg.t_start, seg.t_end, &flow)?;
        }
        Ok(())
    }

    /// The first error met while observing a simulation (an [`Observer`] cannot return one),
    /// or `Ok`.
    pub fn status(&self) -> Result<(), ElectricalError> {
        match &self.error {
            Some(e) => Err(e.clone()),
            None => Ok(()),
        }
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Excitation period used to book energy, s.
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The transducer.
    pub fn transducer(&self) -> &Transducer {
        &self.transducer
    }

    /// Charge Q moved between the electrodes at the current time, C.
    pub fn charge(&self) -> f64 {
        self.row(self.ts_now, self.y, self.energy).charge
    }

    /// Terminal (load) voltage V at the current time, V.
    pub fn voltage(&self) -> f64 {
        self.row(self.ts_now, self.y, self.energy).voltage
    }

    /// Storage capacitor voltage at the current time, V (rectifier only).
    pub fn storage_voltage(&self) -> Option<f64> {
        matches!(self.load, LoadModel::Rectifier { .. }).then_some(self.y[1])
    }

    /// Energy delivered to the load since the start, J.
    pub fn total_energy(&self) -> f64 {
        self.energy
    }

    /// Per-period records, in time order (the last may be incomplete).
    pub fn periods(&self) -> &[PeriodStats] {
        &self.periods
    }

    /// Samples on the grid of [`with_sampling`](Self::with_sampling), if requested.
    pub fn samples(&self) -> Option<&ElectricalSamples> {
        self.sampler.as_ref().map(|g| &g.data)
    }

    /// The V–Q cycle of [`with_vq_cycle`](Self::with_vq_cycle), if requested (plot
    /// `voltage_v` against `charge_c`).
    pub fn vq_cycle(&self) -> Option<&ElectricalSamples> {
        self.vq.as_ref().map(|g| &g.data)
    }

    /// First time the storage voltage reached `target_voltage`, s (rectifier only).
    pub fn time_to_target(&self) -> Option<f64> {
        self.target_time
    }

    /// Work counters.
    pub fn stats(&self) -> SolverStats {
        self.stats
    }

    /// Average power and related figures over the complete periods after the first
    /// `transient` ones (see [`summarize`]).
    pub fn summary(&self, transient: usize) -> Option<PowerSummary> {
        summarize(&self.periods, self.period, transient)
    }

    /// The running average power `P_a(N)` from the first recorded period (see
    /// [`power_curve`]).
    pub fn power_curve(&self) -> Vec<f64> {
        power_curve(&self.periods, self.period)
    }

    fn eval<W: GapWaveform + ?Sized>(
        &mut self,
        t: f64,
        wave: &W,
    ) -> Result<TransducerState, ElectricalError> {
        wave.gaps(t, &mut self.gaps, &mut self.rates);
        self.stats.waveform_evaluations += 1;
        let ts = self.transducer.state(&self.gaps, &self.rates);
        if ts.elastance > 0.0
            && ts.elastance.is_finite()
            && ts.equilibrium_current.is_finite()
            && ts.voc.is_finite()
        {
            Ok(ts)
        } else {
            Err(ElectricalError::InvalidGaps { t })
        }
    }

    fn start<W: GapWaveform + ?Sized>(&mut self, t0: f64, wave: &W) -> Result<(), ElectricalError> {
        let ts = self.eval(t0, wave)?;
        let q0 = self.initial_charge.unwrap_or(ts.equilibrium_charge);
        self.t = t0;
        self.t_start = t0;
        self.y = [q0 - ts.equilibrium_charge, self.storage_initial_voltage];
        if matches!(self.load, LoadModel::Short) {
            self.y[0] = 0.0;
        }
        self.open_charge = q0;
        self.ts_now = ts;
        self.started = true;
        self.v_scale = match self.load {
            LoadModel::Rectifier { .. } => self.storage_initial_voltage.abs(),
            _ => (self.y[0] * ts.elastance).abs(),
        };
        Ok(())
    }

    /// The electrical quantities at `t` given the state `y` and energy `e` there.
    fn row(&self, ts: TransducerState, y: [f64; 2], e: f64) -> Row {
        let (u, vs) = (y[0], y[1]);
        let voltage = -u * ts.elastance;
        let (charge, current, voltage) = match self.load {
            LoadModel::Resistor { conductance } => {
                (u + ts.equilibrium_charge, voltage * conductance, voltage)
            }
            LoadModel::Rectifier { diode, .. } => (
                u + ts.equilibrium_charge,
                diode.bridge(voltage, vs).current,
                voltage,
            ),
            LoadModel::Open => (self.open_charge, 0.0, ts.voc - self.open_charge * ts.elastance),
            LoadModel::Short => (ts.equilibrium_charge, ts.equilibrium_current, 0.0),
        };
        Row {
            ts,
            charge,
            current,
            voltage,
            storage: vs,
            energy: e,
        }
    }

    /// Books a piece `[ta, tb]` (inside one period) and integrates it.
    fn piece<W: GapWaveform + ?Sized>(&mut self, ta: f64, tb: f64, wave: &W) -> Result<(), ElectricalError> {
        self.stats.pieces += 1;
        let index = (0.5 * (ta + tb) / self.period).floor() as i64;
        if self.periods.last().is_none_or(|p| p.index != index) {
            self.periods.push(PeriodStats {
                index,
                t_start: ta,
                t_end: ta,
                energy_j: 0.0,
                peak_current_a: 0.0,
                peak_voltage_v: 0.0,
                storage_voltage_v: None,
            });
            self.steps_in_period = 0;
        }
        let n0 = self.eval(ta, wave)?;
        let r0 = self.row(n0, self.y, self.energy);
        self.note_peaks(r0.current, r0.voltage);
        if self.stats.pieces == 1 {
            // The very first instant of the run.
            self.sample_between(ta, ta, wave, None)?;
        }
        match self.load {
            LoadModel::Resistor { .. } | LoadModel::Rectifier { .. } => self.integrate(ta, tb, n0, wave)?,
            LoadModel::Open | LoadModel::Short => {
                let n1 = self.eval(tb, wave)?;
                self.t = tb;
                self.ts_now = n1;
                self.y[0] = match self.load {
                    LoadModel::Open => self.open_charge - n1.equilibrium_charge,
                    _ => 0.0,
                };
                let r1 = self.row(n1, self.y, self.energy);
                self.note_peaks(r1.current, r1.voltage);
                self.sample_between(ta, tb, wave, None)?;
            }
        }
        let vs = self.storage_voltage();
        let p = self.periods.last_mut().expect("pushed above");
        p.t_end = tb;
        p.storage_voltage_v = vs;
        Ok(())
    }

    fn note_peaks(&mut self, current: f64, voltage: f64) {
        if let Some(p) = self.periods.last_mut() {
            p.peak_current_a = p.peak_current_a.max(current.abs());
            p.peak_voltage_v = p.peak_voltage_v.max(voltage.abs());
        }
    }

    /// The scaled absolute voltage tolerance, V.
    fn atol(&self) -> f64 {
        self.options
            .atol_voltage
            .unwrap_or(self.options.rtol * self.v_scale.max(self.v_floor))
    }

    fn integrate<W: GapWaveform + ?Sized>(
        &mut self,
        ta: f64,
        tb: f64,
        mut n0: TransducerState,
        wave: &W,
    ) -> Result<(), ElectricalError> {
        if matches!(self.load, LoadModel::Open | LoadModel::Short) {
            return Ok(());
        }
        let mut t = ta;
        let c = self.tab.c;
        while t < tb {
            self.steps_in_period += 1;
            if self.steps_in_period > self.options.max_steps_per_period {
                return Err(ElectricalError::StepLimit {
                    t,
                    limit: self.options.max_steps_per_period,
                });
            }
            let remaining = tb - t;
            let h_prop = self.h;
            let mut h = h_prop;
            let mut clipped = false;
            if h >= remaining {
                h = remaining;
                clipped = true;
            } else if h > 0.5 * remaining {
                h = 0.5 * remaining;
                clipped = true;
            }
            let t1 = if h == remaining { tb } else { t + h };
            let h = t1 - t;
            if h <= 4.0 * f64::EPSILON * t.abs().max(self.period) && h < remaining {
                return Err(ElectricalError::StepSizeUnderflow { t, h });
            }
            let nodes = [
                self.eval(t + c[0] * h, wave)?,
                self.eval(t + c[1] * h, wave)?,
                self.eval(t1, wave)?,
            ];
            let trial = match self.load {
                LoadModel::Resistor { conductance } => Some(self.trial_resistor(conductance, h, &n0, &nodes)),
                LoadModel::Rectifier {
                    diode,
                    inv_cs,
                    load_conductance,
                } => self.trial_rectifier(diode, inv_cs, load_conductance, h, &n0, &nodes),
                LoadModel::Open | LoadModel::Short => None,
            };
            let err = trial.map_or(f64::INFINITY, |tr| {
                if tr.err.is_nan() { f64::INFINITY } else { tr.err }
            });
            if let Some(trial) = trial.filter(|_| err <= 1.0) {
                let step = self.accept(t, t1, &trial, nodes[2]);
                self.record(step, wave)?;
                let hnew = self.controller(h, err, true);
                self.h = if clipped {
                    // A step shortened to meet the interval end says little about the next.
                    (h * 0.9 * err.max(1e-10).powf(-0.25)).min(h_prop).max(hnew)
                } else {
                    hnew
                };
                n0 = nodes[2];
                t = t1;
            } else {
                self.stats.rejected += 1;
                self.h = if err.is_finite() {
                    self.controller(h, err, false)
                } else {
                    0.25 * h
                };
                // A stiff step that fails has usually met a boundary layer (after a kink),
                // where the estimate does not fall with h until h·k ~ 1: go there at once.
                if let Some(tr) = trial
                    && tr.hk > 2.0
                {
                    self.h = self.h.min(2.0 * h / tr.hk);
                }
            }
        }
        Ok(())
    }

    /// Step-size controller of RADAU5 (with Gustafsson's predictive variant): the next step
    /// after a step of `h` with scaled error `err`.
    fn controller(&mut self, h: f64, err: f64, accepted: bool) -> f64 {
        const SAFE: f64 = 0.9;
        let err = err.max(1e-10);
        // A rejected step may shrink by up to 1000× at once: the estimate of a linear stage
        // system is reliable, and kinks leave boundary layers orders of magnitude thinner
        // than the step that met them.
        let max_shrink = if accepted { 5.0 } else { 1000.0 };
        let mut quot = (err.powf(0.25) / SAFE).clamp(0.125, max_shrink);
        if accepted {
            if self.have_acc {
                let gus = ((self.h_acc / h) * (err * err / self.err_acc).powf(0.25) / SAFE).clamp(0.125, 5.0);
                quot = quot.max(gus);
            }
            self.h_acc = h;
            self.err_acc = err.max(1e-2);
            self.have_acc = true;
        }
        h / quot
    }

    /// Resistor: Radau IIA on `Q' = −k (Q − Q_eq)`, `k = 1/(RC)`, solved for the stage
    /// increments `Zᵢ` of `u = Q − Q_eq` with the exact increments `ΔQ_eq,ᵢ` of the
    /// equilibrium charge: `(I + hA·diag(k)) Z = −ΔQ_eq − hA k u₀` (linear, solved exactly).
    fn trial_resistor(
        &self,
        conductance: f64,
        h: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; 3],
    ) -> Trial {
        let tab = &self.tab;
        let u0 = self.y[0];
        let k = nodes.map(|n| conductance * n.elastance);
        let dq = nodes.map(|n| n.equilibrium_charge - n0.equilibrium_charge);
        let mut m = [[0.0; 3]; 3];
        let mut rhs = [0.0; 3];
        for i in 0..3 {
            rhs[i] = -dq[i];
            for j in 0..3 {
                let ha = h * tab.a[i][j];
                m[i][j] = ha * k[j] + if i == j { 1.0 } else { 0.0 };
                rhs[i] -= ha * k[j] * u0;
            }
        }
        let mut trial = Trial {
            qeq0: n0.equilibrium_charge,
            dq,
            ..Trial::default()
        };
        if !solve_dense(&mut m, &mut rhs, 3) {
            trial.err = f64::INFINITY;
            return trial;
        }
        let mut power = [0.0; 3];
        for j in 0..3 {
            trial.z[j][0] = rhs[j];
            let v = -(u0 + rhs[j]) * nodes[j].elastance;
            trial.voltage[j] = v;
            trial.current[j] = v * conductance;
            power[j] = v * v * conductance;
        }
        trial.stiff = h * k[2] >= 1.0;
        trial.hk = h * conductance * n0.elastance;
        // Error estimate for Q: (1 + γ₀hk₀) e = γ₀ (h Q'₀ + Σ dᵢ ΔQᵢ), ΔQᵢ = Zᵢ + ΔQ_eq,ᵢ.
        let k0 = conductance * n0.elastance;
        let f0 = -k0 * u0;
        let dz: f64 = (0..3).map(|i| tab.dd[i] * (rhs[i] + dq[i])).sum();
        let g = tab.gamma0;
        let den = 1.0 + g * h * k0;
        let e = g * (h * f0 + dz) / den;
        // Noise level of the estimate, in volts.
        // (ΔQ_eq carries the noise of Q_eq itself, not of its small increment.)
        let qeq_mag = self.qeq_noise_scale(n0, &dq);
        let terms = (h * f0).abs()
            + (0..3)
                .map(|i| tab.dd[i].abs() * (rhs[i].abs() + qeq_mag))
                .sum::<f64>();
        let noise = NOISE * g * terms / den * nodes[2].elastance;
        let v0 = -u0 * n0.elastance;
        let scale = self.options.rtol * v0.abs().max(trial.voltage[2].abs()) + self.atol() + noise;
        let err_v = (e * nodes[2].elastance).abs() / scale;
        // Energy: p = G V²; a voltage noise δV makes a power noise 2G|V|δV.
        let p0 = conductance * v0 * v0;
        let v_max = trial.voltage.iter().fold(v0.abs(), |m, v| m.max(v.abs()));
        let p_noise = conductance * noise * (2.0 * v_max + noise);
        // ∂p/∂u = 2 G u / C², and the noise of e (in charge) through it.
        let dp_du = -2.0 * conductance * v0 * n0.elastance;
        let coupling = (dp_du * e, (dp_du * noise / nodes[2].elastance).abs());
        trial.err = err_v.max(self.energy_error(h, p0, &power, &mut trial.ze, p_noise, coupling));
        trial
    }

    /// Rectifier: Radau IIA on `Q' = I(V, V_s)`, `C_s V_s' = I_out − V_s/R_L`, with the stages
    /// of Q written as `u = Q − Q_eq` (exact `ΔQ_eq` as for the resistor); Newton's method on
    /// the 6 × 6 stage system with the exact Jacobian at every stage. `None` if Newton fails.
    #[allow(clippy::too_many_arguments)]
    fn trial_rectifier(
        &mut self,
        diode: Diode,
        inv_cs: f64,
        gl: f64,
        h: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; 3],
    ) -> Option<Trial> {
        let tab = self.tab;
        let y0 = self.y;
        let atol = self.atol();
        let rtol = self.options.rtol;
        // Predictor: extrapolate the previous collocation polynomial.
        let mut z = [[0.0; 2]; 3];
        if let Some(last) = &self.last_step {
            let ratio = h / last.h;
            if ratio <= 2.0 && (last.t0 + last.h - self.t).abs() <= 1e-12 * self.period {
                for (i, zi) in z.iter_mut().enumerate() {
                    let w = tab.dense_weights(1.0 + tab.c[i] * ratio);
                    *zi = std::array::from_fn(|comp| {
                        w[0] * last.z[0][comp] + w[1] * last.z[1][comp] + (w[2] - 1.0) * last.z[2][comp]
                    });
                }
            }
        }
        let f = |y: [f64; 2], n: &TransducerState| {
            let v = -y[0] * n.elastance;
            let b = diode.bridge(v, y[1]);
            let rhs = [b.current, (b.output - gl * y[1]) * inv_cs];
            let jac = [
                [-n.elastance * b.current_dv, b.current_dvs],
                [-n.elastance * b.output_dv * inv_cs, (b.output_dvs - gl) * inv_cs],
            ];
            (rhs, jac, v, b)
        };
        let dq = nodes.map(|n| n.equilibrium_charge - n0.equilibrium_charge);
        let v0 = -y0[0] * n0.elastance;
        let sc_v = rtol * v0.abs() + atol;
        let sc_s = rtol * y0[1].abs() + atol;
        let mut converged = false;
        let mut prev_norm = f64::INFINITY;
        for iter in 0..MAX_NEWTON {
            self.stats.newton_iterations += 1;
            let mut fs = [[0.0; 2]; 3];
            let mut js = [[[0.0; 2]; 2]; 3];
            for j in 0..3 {
                let yj = [y0[0] + z[j][0], y0[1] + z[j][1]];
                let (r, jac, _, _) = f(yj, &nodes[j]);
                fs[j] = r;
                js[j] = jac;
            }
            let mut m = [[0.0; 6]; 6];
            let mut rhs = [0.0; 6];
            for i in 0..3 {
                for c in 0..2 {
                    let mut acc = z[i][c] + if c == 0 { dq[i] } else { 0.0 };
                    for j in 0..3 {
                        let ha = h * tab.a[i][j];
                        acc -= ha * fs[j][c];
                        for d in 0..2 {
                            m[2 * i + c][2 * j + d] = -ha * js[j][c][d];
                        }
                    }
                    m[2 * i + c][2 * i + c] += 1.0;
                    rhs[2 * i + c] = -acc;
                }
            }
            if !solve_dense(&mut m, &mut rhs, 6) {
                return None;
            }
            let mut norm: f64 = 0.0;
            for i in 0..3 {
                z[i][0] += rhs[2 * i];
                z[i][1] += rhs[2 * i + 1];
                norm = norm
                    .max((rhs[2 * i] * nodes[i].elastance).abs() / sc_v)
                    .max(rhs[2 * i + 1].abs() / sc_s);
            }
            if !norm.is_finite() || (iter >= 2 && norm > prev_norm) {
                return None;
            }
            prev_norm = norm;
            if norm <= 1e-3 {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        let mut trial = Trial {
            z,
            qeq0: n0.equilibrium_charge,
            dq,
            ..Trial::default()
        };
        let mut power = [0.0; 3];
        for j in 0..3 {
            let yj = [y0[0] + z[j][0], y0[1] + z[j][1]];
            let (_, _, v, b) = f(yj, &nodes[j]);
            trial.voltage[j] = v;
            trial.current[j] = b.current;
            power[j] = yj[1] * b.output;
        }
        // Error estimate: (I − γ₀hJ₀) e = γ₀ (h f₀ + Σ dᵢ ΔYᵢ), ΔYᵢ = (Zᵢ + ΔQ_eq,ᵢ, Z_s,ᵢ).
        let (f0, j0, _, _) = f(y0, n0);
        trial.stiff = h * j0[0][0].abs() >= 1.0;
        trial.hk = h * j0[0][0].abs();
        let g = tab.gamma0;
        let dy = |i: usize, c: usize| z[i][c] + if c == 0 { dq[i] } else { 0.0 };
        let dz = [0, 1].map(|c| (0..3).map(|i| tab.dd[i] * dy(i, c)).sum::<f64>());
        let qeq_mag = self.qeq_noise_scale(n0, &dq);
        let noise = [0, 1].map(|c| {
            let q = if c == 0 { qeq_mag } else { 0.0 };
            NOISE
                * g
                * ((h * f0[c]).abs() + (0..3).map(|i| tab.dd[i].abs() * (z[i][c].abs() + q)).sum::<f64>())
        });
        let lhs = [
            [1.0 - g * h * j0[0][0], -g * h * j0[0][1]],
            [-g * h * j0[1][0], 1.0 - g * h * j0[1][1]],
        ];
        let solve2 = |b: [f64; 2]| {
            let mut m = lhs;
            let mut b = b;
            solve_dense(&mut m, &mut b, 2).then_some(b)
        };
        let y1 = [y0[0] + z[2][0], y0[1] + z[2][1]];
        let el1 = nodes[2].elastance;
        let sc_v = rtol * v0.abs().max(trial.voltage[2].abs()) + atol + noise[0] * el1;
        let sc_s = rtol * y0[1].abs().max(y1[1].abs()) + atol + noise[1];
        let norm = |e: [f64; 2]| ((e[0] * el1).abs() / sc_v).max(e[1].abs() / sc_s);
        let e = solve2([g * (h * f0[0] + dz[0]), g * (h * f0[1] + dz[1])])?;
        // Energy: p = V_s I_out; noise from the voltage and storage-voltage noise.
        let b0 = diode.bridge(v0, y0[1]);
        let p0 = y0[1] * b0.output;
        let p_noise = (y0[1] * b0.output_dv).abs() * noise[0] * el1
            + (b0.output.abs() + (y0[1] * b0.output_dvs).abs()) * noise[1];
        let dp_du = -y0[1] * b0.output_dv * n0.elastance;
        let dp_dvs = b0.output + y0[1] * b0.output_dvs;
        let coupling = (
            dp_du * e[0] + dp_dvs * e[1],
            (dp_du * noise[0]).abs() + (dp_dvs * noise[1]).abs(),
        );
        trial.err = norm(e).max(self.energy_error(h, p0, &power, &mut trial.ze, p_noise, coupling));
        Some(trial)
    }

    /// The magnitude whose `NOISE` fraction bounds the noise of `Q_eq` over a step, C.
    fn qeq_noise_scale(&self, n0: &TransducerState, dq: &[f64; 3]) -> f64 {
        n0.equilibrium_charge.abs() + dq[2].abs() + NOISE_CHARGE / NOISE * self.transducer.charge_scale()
    }

    /// Fills the energy stage increments `ze` from the stage powers (W) and returns the scaled
    /// error estimate of the energy increment.
    ///
    /// The estimate is Hairer's for the quadrature component of the augmented system,
    /// `γ₀(h p₀ + Σ dᵢ ZEᵢ) + γ₀h (∂p/∂y)·e_y` with `coupling = ((∂p/∂y)·e_y, its noise)`. The
    /// coupling term matters: after a step whose accepted error left the state slightly off
    /// the slow manifold of a stiff load, the quadrature part alone reads the decayed layer as
    /// an O(h) error, and the coupling term cancels it. The estimate is tested against an
    /// error per unit step `rtol·h·P_ref`, P_ref the larger of the average power since the
    /// start and over the last complete period (so the allowed error summed over a period is
    /// `rtol × its energy`), plus the estimate's noise from a stage-power noise `p_noise`, W.
    /// Inactive during the first 1e-3 of a period after the start, where no power scale
    /// exists yet.
    fn energy_error(
        &self,
        h: f64,
        p0: f64,
        power: &[f64; 3],
        ze: &mut [f64; 3],
        p_noise: f64,
        coupling: (f64, f64),
    ) -> f64 {
        let tab = &self.tab;
        for (i, zi) in ze.iter_mut().enumerate() {
            *zi = h * (0..3).map(|j| tab.a[i][j] * power[j]).sum::<f64>();
        }
        let elapsed = self.t - self.t_start;
        if elapsed < 1e-3 * self.period {
            return 0.0;
        }
        let mut p_ref = self.energy / elapsed;
        if let Some(last) = self.periods.iter().rev().find(|p| p.is_complete(self.period)) {
            p_ref = p_ref.max(last.energy_j / self.period);
        }
        if p_ref.is_nan() || p_ref <= 0.0 {
            return 0.0;
        }
        let dz: f64 = (0..3).map(|i| tab.dd[i] * ze[i]).sum();
        let g = tab.gamma0;
        let e = g * (h * p0 + dz) + g * h * coupling.0;
        let dd_sum: f64 = tab.dd.iter().map(|d| d.abs()).sum();
        let terms = (h * p0).abs() + (0..3).map(|i| (tab.dd[i] * ze[i]).abs()).sum::<f64>();
        let noise = g * (NOISE * terms + (1.0 + dd_sum) * h * p_noise + h * coupling.1);
        e.abs() / (self.options.rtol * h * p_ref + noise)
    }

    /// Commits an accepted step and returns its polynomial.
    fn accept(&mut self, t0: f64, t1: f64, trial: &Trial, n1: TransducerState) -> Step {
        let h = t1 - t0;
        let ze = trial.ze;
        let step = Step {
            t0,
            h,
            y0: self.y,
            z: trial.z,
            e0: self.energy,
            ze,
            qeq0: trial.qeq0,
            dq: trial.dq,
            stiff: trial.stiff,
        };
        self.stats.steps += 1;
        self.t = t1;
        self.ts_now = n1;
        self.y = [self.y[0] + trial.z[2][0], self.y[1] + trial.z[2][1]];
        self.energy += ze[2];
        if let Some(p) = self.periods.last_mut() {
            p.energy_j += ze[2];
        }
        for j in 0..3 {
            self.note_peaks(trial.current[j], trial.voltage[j]);
        }
        match self.load {
            LoadModel::Rectifier { .. } => {
                for zj in &trial.z {
                    self.v_scale = self.v_scale.max((step.y0[1] + zj[1]).abs());
                }
            }
            _ => {
                for v in &trial.voltage {
                    self.v_scale = self.v_scale.max(v.abs());
                }
            }
        }
        self.last_step = Some(step);
        step
    }

    /// State and energy at `t` inside an accepted step, from its collocation polynomial.
    ///
    /// `qeq` is `Q_eq(t)`, C. A stiff step interpolates `u` through its stage values (the
    /// quasi-static `u` is smooth where `Q` nearly equals `Q_eq`); a non-stiff one evaluates the
    /// collocation polynomial of `Q` and subtracts the exact `Q_eq(t)`.
    fn dense(&self, step: &Step, t: f64, qeq: f64) -> ([f64; 2], f64) {
        let w = self.tab.dense_weights((t - step.t0) / step.h);
        let mut y = step.y0;
        let mut e = step.e0;
        for ((wi, zi), zei) in w.iter().zip(&step.z).zip(&step.ze) {
            y[0] += wi * zi[0];
            y[1] += wi * zi[1];
            e += wi * zei;
        }
        if !step.stiff {
            let interp: f64 = w.iter().zip(&step.dq).map(|(wi, dqi)| wi * dqi).sum();
            y[0] += interp - (qeq - step.qeq0);
        }
        (y, e)
    }

    /// Outputs of an accepted step: samples, V–Q points, target crossing.
    fn record<W: GapWaveform + ?Sized>(&mut self, step: Step, wave: &W) -> Result<(), ElectricalError> {
        let t1 = step.t0 + step.h;
        self.sample_between(step.t0, t1, wave, Some(&step))?;
        if let (Some(target), None, LoadModel::Rectifier { .. }) =
            (self.target_voltage, self.target_time, self.load)
        {
            let before = step.y0[1] - target;
            let after = self.y[1] - target;
            if before < 0.0 && after >= 0.0 {
                let (mut lo, mut hi) = (step.t0, t1);
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if mid <= lo || mid >= hi {
                        break;
                    }
                    if self.dense(&step, mid, 0.0).0[1] >= target {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                self.target_time = Some(hi);
            }
        }
        Ok(())
    }

    /// Samples grid times inside `[ta, tb]`: from a step's polynomial, or (open, short, or
    /// the first instant) from the current state.
    fn sample_between<W: GapWaveform + ?Sized>(
        &mut self,
        ta: f64,
        tb: f64,
        wave: &W,
        step: Option<&Step>,
    ) -> Result<(), ElectricalError> {
        let rectifier = matches!(self.load, LoadModel::Rectifier { .. });
        for which in 0..2 {
            let mut grid = match which {
                0 => self.sampler.take(),
                _ => self.vq.take(),
            };
            let mut result = Ok(());
            if let Some(g) = grid.as_mut() {
                while let Some(t) = g.next_in(ta, tb) {
                    let ts = match self.eval(t, wave) {
                        Ok(ts) => ts,
                        Err(e) => {
                            result = Err(e);
                            break;
                        }
                    };
                    let (mut y, e) = match step {
                        Some(s) => self.dense(s, t, ts.equilibrium_charge),
                        None => (self.y, self.energy),
                    };
                    if step.is_none() && matches!(self.load, LoadModel::Open) {
                        y[0] = self.open_charge - ts.equilibrium_charge;
                    }
                    let row = self.row(ts, y, e);
                    self.note_peaks(row.current, row.voltage);
                    g.data.push(t, &row, rectifier);
                }
            }
            match which {
                0 => self.sampler = grid,
                _ => self.vq = grid,
            }
            result?;
        }
        Ok(())
    }
}

impl Observer for ChargeSolver {
    fn flow(&mut self, flow: &Flow<'_>) {
        if self.error.is_none()
            && flow.t_end > flow.t_start
            && let Err(e) = self.advance(flow.t_start, flow.t_end, flow)
        {
            self.error = Some(e);
        }
    }
}

/// Average power and related figures over a run (seed eq. 14).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PowerSummary {
    /// Complete periods averaged over (after the transient).
    pub periods: usize,
    /// `P_a = Σ E_k / (N T)` over those periods, W (seed eq. 14).
    pub average_power_w: f64,
    /// Mean energy per period over those periods, J.
    pub energy_per_period_j: f64,
    /// Largest |current| over those periods, A.
    pub peak_current_a: f64,
    /// Largest |terminal voltage| over those periods, V.
    pub peak_voltage_v: f64,
}

/// Averages the complete periods of `periods` after the first `transient` complete ones;
/// `None` if none remain. `period` is the excitation period T, s.
pub fn summarize(periods: &[PeriodStats], period: f64, transient: usize) -> Option<PowerSummary> {
    let used: Vec<&PeriodStats> = periods
        .iter()
        .filter(|p| p.is_complete(period))
        .skip(transient)
        .collect();
    if used.is_empty() {
        return None;
    }
    let n = used.len();
    let energy: f64 = used.iter().map(|p| p.energy_j).sum();
    Some(PowerSummary {
        periods: n,
        average_power_w: energy / (n as f64 * period),
        energy_per_period_j: energy / n as f64,
        peak_current_a: used.iter().map(|p| p.peak_current_a).fold(0.0, f64::max),
        peak_voltage_v: used.iter().map(|p| p.peak_voltage_v).fold(0.0, f64::max),
    })
}

/// The paper's running average power `P_a(N) = Σ_{k<N} E_k / (N T)`, W, for N = 1, 2, … over
/// the complete periods of `periods` (from the first one recorded, transient included).
pub fn power_curve(periods: &[PeriodStats], period: f64) -> Vec<f64> {
    let mut sum = 0.0;
    periods
        .iter()
        .filter(|p| p.is_complete(period))
        .enumerate()
        .map(|(k, p)| {
            sum += p.energy_j;
            sum / ((k + 1) as f64 * period)
        })
        .collect()
}
