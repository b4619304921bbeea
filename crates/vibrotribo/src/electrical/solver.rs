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
//! Radau IIA collocation (L-stable, stiffly accurate) on these equations, with the stage
//! values of `Q` written as `u = Q − Q_eq = −C·V` and the exact increments `Q_eq(tᵢ) − Q_eq(t₀)`
//! of the waveform: the unknowns then hold the load voltage without cancellation when it is a
//! millionth of V_oc (small R), and `Q` stays exactly constant when nothing flows (R → ∞).
//! The delivered energy is a quadrature component of the same collocation,
//! `ΔE = h Σ bⱼ p(tⱼ, Yⱼ)` over the stage values, not a sampled sum.
//!
//! - **Resistor**: 7 stages (order 13, stage order 7). The stage system is linear,
//!   `(I + hA·diag(k)) Z = −ΔQ_eq − hA k u₀` with `k = 1/(RC)`, solved exactly by elimination
//!   without pivoting (safe for these matrices, see [`radau`](super::radau)). The high order
//!   lets a step span a good part of a flow piece: about 60 steps per period on the paper's
//!   default case, for loads from 1 kΩ to 10 GΩ.
//! - **Rectifier**: 3 stages (order 5). Its steps are short around every switching of the
//!   bridge, where a low order is cheaper; the 6 × 6 stage system is solved by Newton's
//!   method with the exact Jacobian at every iteration, started from the previous step's
//!   collocation polynomial, and given up early (RADAU5's test on the contraction rate θ)
//!   when the remaining iterations cannot converge. The diode law's constants are computed
//!   once.
//!
//! The gaps come in as a [`GapWaveform`]; the simulator's flow is first expanded into
//! piecewise Taylor polynomials accurate to the rounding of its closed form (see
//! `dynamics::taylor`), so the stage points of a step cost one Horner sweep each instead of
//! an exponential and a sine–cosine pair per cluster.
//!
//! Error control uses Hairer's embedded estimate (RADAU5's first estimate, of order S,
//! without its second, "stiffly filtered" one, which in the quasi-static regime of a small
//! load accepts steps 10⁴ times too long) on two things:
//!
//! - the load voltage `−u/C` (and the storage voltage), per step, `rtol·|V| + atol`; by
//!   default `atol = rtol × (largest |V| seen)` for the resistor, `rtol × (largest V_s seen,
//!   at least nV_T)` for the rectifier;
//! - the energy, per unit step, against `rtol × (average power)`: summed over a period the
//!   allowed error is `rtol ×` the period's energy. Without this the voltage test alone lets
//!   a stiff load take steps of a tenth of a period, far too long for the quadrature of V².
//!   Steps shorter than `T/1000` (boundary layers) are allowed `rtol × E/1000` each rather
//!   than an error proportional to their length.
//!
//! A noise allowance keeps the tests above the precision of the input (gaps are differences
//! of positions), so tight tolerances cannot drive the step to zero. The step size follows
//! RADAU5's controller with Gustafsson's predictive variant (`h ∝ err^(−1/(S+1))`). Where the
//! estimate cannot see the solution's structure, the step is shaped directly:
//!
//! - after a kink the resistor's charge crosses a boundary layer of width `RC`; its amplitude
//!   is estimated from the quasi-static charge `u ≈ −I_sc/k`, the layer is entered at
//!   `h·k = 2`, and once it has decayed below the tolerance the step returns to the size it
//!   had before the kink;
//! - a failed stiff rectifier step (the bridge switching) jumps to `h·k ≈ 2`, and a rectifier
//!   step in which a conducting junction's voltage moves by more than 4 n·V_T is retried
//!   shorter: the current changes by orders of magnitude there, which neither the collocation
//!   polynomial nor its error estimate follows;
//! - after a kink the rectifier's first step covers a sweep of 10 n·V_T of the voltage.
//!
//! Every call of [`ChargeSolver::advance`] restarts the integration (mechanical kinks such as
//! impacts fall on flow boundaries), and excitation period boundaries are step boundaries, so
//! energy is booked per period exactly. Sampled outputs come from the collocation
//! polynomial with the transducer evaluated exactly at the sample time.

use super::ElectricalError;
use super::breakdown::{BreakdownMargin, BreakdownWatch};
use super::diode::DiodeLaw;
use super::params::{HarvesterParams, LoadKind};
use super::radau::{Tableau, solve_fixed, solve_unpivoted};
use super::transducer::{ChargeMap, Transducer, TransducerState};
use super::waveform::{GapWaveform, PwlGaps};
use crate::dynamics::{Flow, GapPolynomial, Observer, Trajectory};
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
    /// solution on the paper's default and chatter cases for loads from 1 kΩ to 10 GΩ and for
    /// the rectifier.
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
        self.capacitance_f.push(row.ts.capacitance());
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
    /// Rejected steps (error test, Newton failure, or a rectifier step over a switching).
    pub rejected: u64,
    /// Newton iterations (rectifier).
    pub newton_iterations: u64,
    /// Evaluations of the gap waveform (for the simulator's flow: of its Taylor expansion,
    /// see [`GapWaveform`]).
    pub waveform_evaluations: u64,
    /// Smooth pieces integrated (flows, split at period boundaries).
    pub pieces: u64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum LoadModel {
    Resistor { conductance: f64 },
    Rectifier(RectifierLoad),
    Open,
    Short,
}

/// A uniform grid `t0 + span·(j/per)`, j = 0, 1, …, up to `last` if given (`per` = 1: a
/// step of `span`; `per` samples per `span`: the grid hits `t0 + k·span` exactly).
#[derive(Debug, Clone)]
struct Grid {
    t0: f64,
    span: f64,
    per: u64,
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
            let t = self.t0 + self.span * (self.next as f64 / self.per as f64);
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
    /// Stages of the method (the arrays hold that many entries).
    stages: usize,
    t0: f64,
    h: f64,
    y0: [f64; 2],
    /// Stage increments `z[c][i]` of `u` (C, c = 0) and of the storage voltage (V, c = 1).
    z: [[f64; MAX_STAGES]; 2],
    e0: f64,
    /// Stage values of the delivered power, W.
    power: [f64; MAX_STAGES],
    /// `Q_eq` at t0 and its increments at the stages, C.
    qeq0: f64,
    dq: [f64; MAX_STAGES],
    stiff: bool,
}

/// Result of solving the stages of one trial step (one buffer reused for every trial).
#[derive(Debug, Clone, Copy)]
struct Trial<const S: usize> {
    /// Stage increments `z[c][i]` of `u` (C, c = 0) and of the storage voltage (V, c = 1).
    z: [[f64; S]; 2],
    /// Stage values of the delivered power, W.
    power: [f64; S],
    /// Energy delivered over the step, J: `h Σ bⱼ pⱼ`.
    energy: f64,
    /// Largest |terminal voltage|, V, and |current|, A, at the stages.
    peak_voltage: f64,
    peak_current: f64,
    /// Largest stage value of the voltage that scales the default absolute tolerance, V (the
    /// load voltage for a resistor, the storage voltage for the rectifier).
    scale_voltage: f64,
    /// Scaled error estimate (≤ 1 accepts).
    err: f64,
    /// Whether the step is stiff (h·|∂Q'/∂Q| ≥ 1): then `u` is interpolated directly in dense
    /// output, otherwise `Q` (and `u = Q − Q_eq` with the exact `Q_eq`).
    stiff: bool,
    /// h·|∂Q'/∂Q| at t0.
    hk: f64,
    /// Factor for the next step after a failed Newton iteration.
    retry: f64,
    /// `Q_eq` at t0 and its increments at the stages, C.
    qeq0: f64,
    dq: [f64; S],
}

impl<const S: usize> Trial<S> {
    fn new() -> Self {
        Trial {
            z: [[0.0; S]; 2],
            power: [0.0; S],
            energy: 0.0,
            peak_voltage: 0.0,
            peak_current: 0.0,
            scale_voltage: 0.0,
            err: 0.0,
            stiff: false,
            hk: 0.0,
            retry: 0.25,
            qeq0: 0.0,
            dq: [0.0; S],
        }
    }
}

/// The rectifier's constants, as the stage solver takes them.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RectifierLoad {
    diode: DiodeLaw,
    /// 1/C_s, 1/F.
    inv_cs: f64,
    /// 1/R_L, S (0 without a load resistor).
    load_conductance: f64,
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
    /// The transducer in the form evaluated at stage points.
    charge_map: ChargeMap,
    /// `NOISE_CHARGE / NOISE` times the charge scale σS, C (see `qeq_noise_scale`).
    charge_noise: f64,
    load: LoadModel,
    options: ChargeOptions,
    tab_resistor: Tableau<RESISTOR_STAGES>,
    tab_rectifier: Tableau<RECTIFIER_STAGES>,
    period: f64,
    gaps: Vec<f64>,
    rates: Vec<f64>,
    /// Gaps at the stage points of a step, `node_gaps[i·n + k]`, m.
    node_gaps: Vec<f64>,
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
    /// Average power over the last complete period, W (0 before there is one).
    last_period_power: f64,
    h: f64,
    h_acc: f64,
    /// `err^(1/(S+1))` of the last accepted step (at least that of 1e-2).
    err_acc_root: f64,
    have_acc: bool,
    /// Voltage scale of the default absolute tolerance, V.
    v_scale: f64,
    /// Time the solver started, s.
    t_start: f64,
    last_step: Option<Step>,
    /// Whether the waveform is smooth from `last_step` to now (no piece boundary since).
    smooth_since_last_step: bool,
    periods: Vec<PeriodStats>,
    steps_in_period: u64,
    sampler: Option<Grid>,
    vq: Option<Grid>,
    target_time: Option<f64>,
    stats: SolverStats,
    error: Option<ElectricalError>,
    /// The current piece of flow, expanded (buffers reused).
    poly: GapPolynomial,
    /// The harvester solved (for checks that need its geometry).
    harvester: HarvesterParams,
    /// The air-breakdown check, if requested.
    breakdown: Option<BreakdownWatch>,
}

/// Points per piece at which an open or short circuit (no steps) is checked for air
/// breakdown before the refinement.
const BREAKDOWN_POINTS: usize = 32;

/// Stages of the Radau IIA method for the resistor: order 13, stage order 7.
const RESISTOR_STAGES: usize = 7;

/// Stages for the rectifier: its steps are short around every switching of the bridge, where
/// a low order is cheaper (smaller Newton systems).
const RECTIFIER_STAGES: usize = 3;

/// Room for the stages of either method in a stored step.
const MAX_STAGES: usize = 7;

/// Steps per period below which the energy test stops shrinking with the step (see
/// `ChargeSolver::energy_error`).
const ENERGY_FLOOR_STEPS: f64 = 1000.0;

/// A boundary layer being crossed (see `ChargeSolver::kink_start`).
#[derive(Debug, Clone, Copy)]
struct Layer {
    conductance: f64,
    /// ∫k dt since the kink.
    decayed: f64,
    /// ∫k dt after which the layer is below the tolerance.
    needed: f64,
    /// The step before the kink, s.
    h_smooth: f64,
}

/// Sweep of the rectifier's voltage, in units of n·V_T, that the first step after a kink may
/// cover.
const KINK_SWING: f64 = 10.0;

/// Largest change, in units of n·V_T, of a bridge junction's voltage over one rectifier step
/// while that junction conducts.
const SWITCH_SWEEP: f64 = 4.0;

/// Reverse bias, in units of n·V_T, beyond which a junction counts as off (its current is
/// then −I_s to within e⁻⁶).
const SWITCH_FLOOR: f64 = -6.0;

/// Growth per accepted step of the step size after a failure of Newton's method.
const SOLVE_REGROWTH: f64 = 2.0;

/// Decay (e-folds) beyond the tolerance before a layer counts as gone.
const LAYER_MARGIN: f64 = 3.0;

/// `x^(1/(S+1))`: the error estimate is O(h^(S+1)).
#[inline]
fn err_root<const S: usize>(x: f64) -> f64 {
    // Only S = 3 and S = 7 are tabulated (`Tableau::new`).
    if S == 7 {
        x.sqrt().sqrt().sqrt()
    } else {
        x.sqrt().sqrt()
    }
}

/// Most Newton iterations per stage solve before the step is retried smaller.
const MAX_NEWTON: usize = 12;

/// Newton's iterations stop when the estimated remaining error of the stages is below this
/// fraction of the error tolerance.
const NEWTON_TOL: f64 = 1e-3;

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
        let charge_map = ChargeMap::new(&transducer);
        let load = match params.load {
            LoadKind::Resistor => LoadModel::Resistor {
                conductance: 1.0 / params.load_resistance,
            },
            LoadKind::Rectifier => LoadModel::Rectifier(RectifierLoad {
                diode: DiodeLaw::new(&params.diode()),
                inv_cs: 1.0 / params.storage_capacitance,
                load_conductance: params.storage_load_resistance.map_or(0.0, |r| 1.0 / r),
            }),
            LoadKind::Open => LoadModel::Open,
            LoadKind::Short => LoadModel::Short,
        };
        let v_floor = match load {
            LoadModel::Rectifier(RectifierLoad { diode, .. }) => diode.thermal_scale(),
            _ => (1e-12 * transducer.voltage_scale()).max(f64::MIN_POSITIVE),
        };
        Ok(ChargeSolver {
            transducer,
            charge_map,
            charge_noise: NOISE_CHARGE / NOISE * transducer.charge_scale(),
            node_gaps: vec![0.0; MAX_STAGES * gaps],
            load,
            options,
            tab_resistor: Tableau::new(),
            tab_rectifier: Tableau::new(),
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
            last_period_power: 0.0,
            h: 1e-6 * period,
            h_acc: 0.0,
            err_acc_root: 0.0,
            have_acc: false,
            v_scale: 0.0,
            t_start: 0.0,
            last_step: None,
            smooth_since_last_step: false,
            periods: Vec::new(),
            steps_in_period: 0,
            sampler: None,
            vq: None,
            target_time: None,
            stats: SolverStats::default(),
            error: None,
            poly: GapPolynomial::default(),
            harvester: params.clone(),
            breakdown: None,
        })
    }

    /// Also checks the air gaps for breakdown (Paschen's law, air at 1 atm; see
    /// [`breakdown`](super::breakdown)) from time `from`, s, on: the worst ratio over the whole
    /// solution, located by maximising it between the solver's stage points, so that it
    /// does not depend on any sampling. See [`breakdown_margin`](Self::breakdown_margin).
    pub fn with_breakdown_check(mut self, from: f64) -> Self {
        self.breakdown = Some(BreakdownWatch::new(&self.harvester, from));
        self
    }

    /// The worst air-breakdown ratio so far, if [`with_breakdown_check`](Self::with_breakdown_check)
    /// was requested (all zero before the checked window).
    pub fn breakdown_margin(&self) -> Option<&BreakdownMargin> {
        self.breakdown.as_ref().map(|w| &w.margin)
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
            span: dt,
            per: 1,
            next: 0,
            last: None,
            data: ElectricalSamples::default(),
        });
        Ok(self)
    }

    /// Also records [`samples`](Self::samples) at `t_j = T·(j/per_period)`, j = 0, 1, …
    /// (T the excitation period): `per_period` samples per period, landing exactly on the
    /// period boundaries `kT` where a run split into periods stops.
    pub fn with_periodic_sampling(mut self, per_period: u64) -> Result<Self, ParamError> {
        if per_period == 0 {
            return Err(ParamError::Invalid {
                name: "run.samples_per_period".into(),
                value: 0.0,
                reason: "must be positive",
            });
        }
        self.sampler = Some(Grid {
            t0: 0.0,
            span: self.period,
            per: per_period,
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
            span: self.period / points as f64,
            per: 1,
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
        if trajectory.gap_count() != self.gaps.len() {
            return Err(ParamError::Length {
                name: "trajectory.gaps".into(),
                expected: self.gaps.len(),
                got: trajectory.gap_count(),
            }
            .into());
        }
        for seg in trajectory.segments() {
            let flow = trajectory
                .flow_at(seg.t_start)
                .ok_or(ElectricalError::EmptyTrajectory)?;
            self.advance_flow(&flow)?;
        }
        Ok(())
    }

    /// Advances over a piece of the simulator's flow, through its Taylor expansion.
    fn advance_flow(&mut self, flow: &Flow<'_>) -> Result<(), ElectricalError> {
        let mut poly = std::mem::take(&mut self.poly);
        poly.build(flow);
        let result = self.advance(flow.t_start, flow.t_end, &poly);
        self.poly = poly;
        result
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
        matches!(self.load, LoadModel::Rectifier(_)).then_some(self.y[1])
    }

    /// Energy delivered to the load since the start, J.
    pub fn total_energy(&self) -> f64 {
        self.energy
    }

    /// Per-period records, in time order (the last may be incomplete).
    pub fn periods(&self) -> &[PeriodStats] {
        &self.periods
    }

    /// Samples on the grid of [`with_sampling`](Self::with_sampling) or
    /// [`with_periodic_sampling`](Self::with_periodic_sampling), if requested (those not yet
    /// taken by [`take_samples`](Self::take_samples)).
    pub fn samples(&self) -> Option<&ElectricalSamples> {
        self.sampler.as_ref().map(|g| &g.data)
    }

    /// Takes the samples recorded so far (empty if sampling was not requested), so that a
    /// long run that streams them out holds only the newest in memory.
    pub fn take_samples(&mut self) -> ElectricalSamples {
        self.sampler
            .as_mut()
            .map(|g| std::mem::take(&mut g.data))
            .unwrap_or_default()
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
        let ts = self.charge_map.state_with_rates(&self.gaps, &self.rates);
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

    /// The transducer at the stage points `times` of a step: like [`eval`](Self::eval)
    /// without the rates (the equilibrium current is left 0).
    #[inline]
    fn eval_nodes<W: GapWaveform + ?Sized, const S: usize>(
        &mut self,
        times: &[f64; S],
        wave: &W,
    ) -> Result<[TransducerState; S], ElectricalError> {
        let n = self.gaps.len();
        wave.gap_values_at(times, &mut self.node_gaps[..S * n]);
        self.stats.waveform_evaluations += S as u64;
        let mut nodes = [TransducerState::default(); S];
        for (i, node) in nodes.iter_mut().enumerate() {
            *node = self.charge_map.state(&self.node_gaps[i * n..(i + 1) * n]);
            if !(node.elastance > 0.0 && node.elastance.is_finite() && node.equilibrium_charge.is_finite()) {
                return Err(ElectricalError::InvalidGaps { t: times[i] });
            }
        }
        Ok(nodes)
    }

    fn start<W: GapWaveform + ?Sized>(&mut self, t0: f64, wave: &W) -> Result<(), ElectricalError> {
        let ts = self.eval(t0, wave)?;
        let q0 = self.initial_charge.unwrap_or(ts.equilibrium_charge);
        self.t = t0;
        self.t_start = t0;
        // Open and short circuits are closed forms (`row`) that never read `y`.
        self.y = [q0 - ts.equilibrium_charge, self.storage_initial_voltage];
        self.open_charge = q0;
        self.ts_now = ts;
        self.started = true;
        self.v_scale = match self.load {
            LoadModel::Rectifier(_) => self.storage_initial_voltage.abs(),
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
            LoadModel::Rectifier(RectifierLoad { diode, .. }) => (
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
            if let [.., done, _] = self.periods.as_slice()
                && done.is_complete(self.period)
            {
                self.last_period_power = done.energy_j / self.period;
            }
        }
        let n0 = self.eval(ta, wave)?;
        let r0 = self.row(n0, self.y, self.energy);
        self.note_peaks(r0.current, r0.voltage);
        if self.stats.pieces == 1 {
            // The very first instant of the run.
            self.sample_between(ta, ta, wave, None)?;
        }
        match self.load {
            LoadModel::Resistor { conductance } => {
                let tab = self.tab_resistor;
                self.integrate(&tab, ta, tb, n0, wave, |s, h, n0, nodes, trial| {
                    s.trial_resistor(&tab, conductance, h, n0, nodes, trial);
                    true
                })?;
            }
            LoadModel::Rectifier(load) => {
                let tab = self.tab_rectifier;
                self.integrate(&tab, ta, tb, n0, wave, |s, h, n0, nodes, trial| {
                    s.trial_rectifier(&tab, &load, h, n0, nodes, trial)
                })?;
            }
            LoadModel::Open | LoadModel::Short => {
                let n1 = self.eval(tb, wave)?;
                self.t = tb;
                self.ts_now = n1;
                let r1 = self.row(n1, self.y, self.energy);
                self.note_peaks(r1.current, r1.voltage);
                self.sample_between(ta, tb, wave, None)?;
                self.watch_piece(ta, tb, wave)?;
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

    /// Integrates `[ta, tb]` (smooth) with Radau IIA of `S` stages; `solve` solves the stage
    /// system of one trial step (false if it failed, with `trial.retry` set).
    fn integrate<W, const S: usize, F>(
        &mut self,
        tab: &Tableau<S>,
        ta: f64,
        tb: f64,
        mut n0: TransducerState,
        wave: &W,
        mut solve: F,
    ) -> Result<(), ElectricalError>
    where
        W: GapWaveform + ?Sized,
        F: FnMut(&mut Self, f64, &TransducerState, &[TransducerState; S], &mut Trial<S>) -> bool,
    {
        let mut t = ta;
        let c = tab.c;
        // A kink starts a new error history.
        self.have_acc = false;
        let mut layer = self.kink_start(&n0);
        let mut trial = Trial::<S>::new();
        // Step size at which the stage solver last failed.
        let mut solve_cap = f64::INFINITY;
        // The last step's polynomial does not extrapolate across a kink.
        self.smooth_since_last_step = false;
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
            let times: [f64; S] = std::array::from_fn(|i| if i + 1 == S { t1 } else { t + c[i] * h });
            let nodes = self.eval_nodes(&times, wave)?;
            let solved = solve(self, h, &n0, &nodes, &mut trial);
            let err = if solved && !trial.err.is_nan() {
                trial.err
            } else {
                f64::INFINITY
            };
            if err <= 1.0 {
                self.accept(t, t1, &trial, nodes[S - 1]);
                self.smooth_since_last_step = true;
                self.record(wave)?;
                let hnew = self.controller::<S>(h, err, true);
                self.h = if clipped {
                    // A step shortened to meet the interval end says little about the next.
                    (h * 0.9 / err_root::<S>(err.max(1e-10))).min(h_prop).max(hnew)
                } else {
                    hnew
                };
                if self.h > solve_cap {
                    self.h = self.h.min(solve_cap.max(SOLVE_REGROWTH * h));
                    solve_cap *= SOLVE_REGROWTH;
                }
                n0 = nodes[S - 1];
                t = t1;
                if let Some(l) = layer.as_mut() {
                    let mean_el: f64 = (0..S).map(|j| tab.a[S - 1][j] * nodes[j].elastance).sum();
                    l.decayed += mean_el * h * l.conductance;
                    if l.decayed >= l.needed {
                        // The layer is gone: resume the step of the smooth solution before the
                        // kink.
                        self.h = self.h.max(l.h_smooth);
                        layer = None;
                    }
                }
            } else {
                self.stats.rejected += 1;
                self.h = if err.is_finite() {
                    self.controller::<S>(h, err, false)
                } else if solved {
                    0.25 * h
                } else {
                    // The stage solver failed at h: grow back towards it only slowly.
                    solve_cap = solve_cap.min(h);
                    trial.retry * h
                };
                // A stiff step that fails has usually met a boundary layer, where the estimate
                // does not fall with h until h·k ~ 1: go there at once. For the resistor only
                // the first step of a piece meets one (after the kink); the rectifier meets
                // one at every switching of the bridge.
                let layer_possible = t == ta || matches!(self.load, LoadModel::Rectifier(_));
                if solved && layer_possible && trial.hk > 2.0 {
                    self.h = self.h.min(2.0 * h / trial.hk);
                }
                // The predictive controller compares consecutive accepted steps.
                self.have_acc = false;
            }
        }
        Ok(())
    }

    /// Sets the first step of a piece (after a possible kink) and returns the boundary layer
    /// to follow, if any.
    ///
    /// Resistor: the charge must cross a boundary layer of width RC if the kink moved the
    /// quasi-static charge `u ≈ −I_sc/k` (k = 1/(RC), I_sc = dQ_eq/dt, valid when the step is
    /// long against 1/k) by more than the tolerance; the step is set to `h·k = 2` and the
    /// layer is followed until it has decayed below the tolerance. Rectifier: the first step
    /// covers a sweep of `KINK_SWING` n·V_T of the voltage, over which the bridge switches.
    fn kink_start(&mut self, n0: &TransducerState) -> Option<Layer> {
        let conductance = match self.load {
            LoadModel::Resistor { conductance } => conductance,
            LoadModel::Rectifier(RectifierLoad { diode, .. }) => {
                // The bridge switches as the voltage sweeps a few n·V_T: start there.
                let v0 = -self.y[0] * n0.elastance;
                let b = diode.bridge(v0, self.y[1]);
                let sweep = (n0.elastance * (n0.equilibrium_current - b.current)).abs();
                let h_switch = KINK_SWING * diode.thermal_scale() / sweep;
                if h_switch > 0.0 {
                    self.h = self.h.min(h_switch);
                }
                return None;
            }
            _ => return None,
        };
        let k0 = conductance * n0.elastance;
        if self.h * k0 <= 2.0 {
            return None;
        }
        let jump = ((self.y[0] + n0.equilibrium_current / k0) * n0.elastance).abs();
        let tol = self.options.rtol * (self.y[0] * n0.elastance).abs() + self.atol();
        if jump.is_nan() || jump <= tol {
            return None;
        }
        let h_smooth = self.h;
        self.h = 2.0 / k0;
        Some(Layer {
            conductance,
            decayed: 0.0,
            needed: (jump / tol).ln() + LAYER_MARGIN,
            h_smooth,
        })
    }

    /// Step-size controller of RADAU5 (with Gustafsson's predictive variant): the next step
    /// after a step of `h` with scaled error `err`.
    fn controller<const S: usize>(&mut self, h: f64, err: f64, accepted: bool) -> f64 {
        const SAFE: f64 = 0.9;
        let err = err.max(1e-10);
        // A rejected step may shrink by up to 1000× at once: the estimate of a linear stage
        // system is reliable, and kinks leave boundary layers orders of magnitude thinner
        // than the step that met them.
        let max_shrink = if accepted { 5.0 } else { 1000.0 };
        let root = err_root::<S>(err);
        let mut quot = (root / SAFE).clamp(0.125, max_shrink);
        if accepted {
            if self.have_acc {
                // (err²/err_acc)^(1/(S+1)), from the roots already taken.
                let gus = ((self.h_acc / h) * root * root / self.err_acc_root / SAFE).clamp(0.125, 5.0);
                quot = quot.max(gus);
            }
            self.h_acc = h;
            self.err_acc_root = root.max(err_root::<S>(1e-2));
            self.have_acc = true;
        }
        h / quot
    }

    /// Resistor: Radau IIA on `Q' = −k (Q − Q_eq)`, `k = 1/(RC)`, solved for the stage
    /// increments `Zᵢ` of `u = Q − Q_eq` with the exact increments `ΔQ_eq,ᵢ` of the
    /// equilibrium charge: `(I + hA·diag(k)) Z = −ΔQ_eq − hA k u₀` (linear, solved exactly).
    fn trial_resistor<const S: usize>(
        &self,
        tab: &Tableau<S>,
        conductance: f64,
        h: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; S],
        trial: &mut Trial<S>,
    ) {
        let u0 = self.y[0];
        let mut hk = [0.0; S];
        let mut dq = [0.0; S];
        for j in 0..S {
            hk[j] = h * conductance * nodes[j].elastance;
            dq[j] = nodes[j].equilibrium_charge - n0.equilibrium_charge;
        }
        let mut m = [[0.0; S]; S];
        let mut z = [0.0; S];
        for i in 0..S {
            let mut row_sum = 0.0;
            for j in 0..S {
                let v = tab.a[i][j] * hk[j];
                m[i][j] = v;
                row_sum += v;
            }
            m[i][i] += 1.0;
            z[i] = -dq[i] - row_sum * u0;
        }
        trial.qeq0 = n0.equilibrium_charge;
        trial.dq = dq;
        if !solve_unpivoted(&mut m, &mut z) {
            trial.err = f64::INFINITY;
            return;
        }
        let v0 = -u0 * n0.elastance;
        let mut v_max = v0.abs();
        for j in 0..S {
            let v = -(u0 + z[j]) * nodes[j].elastance;
            trial.power[j] = v * v * conductance;
            v_max = v_max.max(v.abs());
        }
        let v1 = -(u0 + z[S - 1]) * nodes[S - 1].elastance;
        trial.z[0] = z;
        trial.peak_voltage = v_max;
        trial.peak_current = v_max * conductance;
        trial.scale_voltage = v_max;
        trial.stiff = hk[S - 1] >= 1.0;
        let k0 = conductance * n0.elastance;
        trial.hk = h * k0;
        // Error estimate for Q: (1 + γ₀hk₀) e = γ₀ (h Q'₀ + Σ dᵢ ΔQᵢ), ΔQᵢ = Zᵢ + ΔQ_eq,ᵢ.
        let f0 = -k0 * u0;
        let g = tab.gamma0;
        let den = 1.0 + g * h * k0;
        let mut dz = 0.0;
        let mut terms = (h * f0).abs();
        // (ΔQ_eq carries the noise of Q_eq itself, not of its small increment.)
        let qeq_mag = self.qeq_noise_scale(n0, &dq);
        for i in 0..S {
            dz += tab.dd[i] * (z[i] + dq[i]);
            terms += tab.dd[i].abs() * (z[i].abs() + qeq_mag);
        }
        let g_den = g / den;
        let e = g_den * (h * f0 + dz);
        // Noise level of the estimate, in volts.
        let el1 = nodes[S - 1].elastance;
        let noise = NOISE * g_den * terms * el1;
        let scale = self.options.rtol * v0.abs().max(v1.abs()) + self.atol() + noise;
        let err_v = (e * el1).abs() / scale;
        // Energy: p = G V²; a voltage noise δV makes a power noise 2G|V|δV.
        let p0 = conductance * v0 * v0;
        let p_noise = conductance * noise * (2.0 * v_max + noise);
        // ∂p/∂u = 2 G u / C², and the noise of e (in charge) through it.
        let dp_du = -2.0 * conductance * v0 * n0.elastance;
        let coupling = (dp_du * e, (dp_du * noise / el1).abs());
        let err_e = self.energy_error(tab, h, p0, trial, p_noise, coupling);
        trial.err = err_v.max(err_e);
    }

    /// Rectifier: Radau IIA on `Q' = I(V, V_s)`, `C_s V_s' = I_out − V_s/R_L`, with the stages
    /// of Q written as `u = Q − Q_eq` (exact `ΔQ_eq` as for the resistor); Newton's method on
    /// the 2S × 2S stage system with the exact Jacobian at every stage. False if Newton fails.
    fn trial_rectifier(
        &mut self,
        tab: &Tableau<RECTIFIER_STAGES>,
        load: &RectifierLoad,
        h: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; RECTIFIER_STAGES],
        trial: &mut Trial<RECTIFIER_STAGES>,
    ) -> bool {
        const S: usize = RECTIFIER_STAGES;
        let RectifierLoad {
            diode,
            inv_cs,
            load_conductance: gl,
        } = *load;
        let y0 = self.y;
        let atol = self.atol();
        let rtol = self.options.rtol;
        // Predictor: extrapolate the previous collocation polynomial.
        let mut z = [[0.0; S]; 2];
        if let Some(last) = self
            .last_step
            .as_ref()
            .filter(|l| self.smooth_since_last_step && l.stages == S)
        {
            let ratio = h / last.h;
            if ratio <= 8.0 && (last.t0 + last.h - self.t).abs() <= 1e-12 * self.period {
                for i in 0..S {
                    let w = tab.dense_weights(1.0 + tab.c[i] * ratio);
                    for (zc, lc) in z.iter_mut().zip(&last.z) {
                        zc[i] = (0..S).map(|m| w[m] * lc[m]).sum::<f64>() - lc[S - 1];
                    }
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
            let mut fs = [[0.0; 2]; S];
            let mut js = [[[0.0; 2]; 2]; S];
            for j in 0..S {
                let yj = [y0[0] + z[0][j], y0[1] + z[1][j]];
                let (r, jac, _, _) = f(yj, &nodes[j]);
                fs[j] = r;
                js[j] = jac;
            }
            let mut m = [[0.0; 2 * RECTIFIER_STAGES]; 2 * RECTIFIER_STAGES];
            let mut rhs = [0.0; 2 * RECTIFIER_STAGES];
            for i in 0..S {
                for c in 0..2 {
                    let mut acc = z[c][i] + if c == 0 { dq[i] } else { 0.0 };
                    for j in 0..S {
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
            if !solve_fixed(&mut m, &mut rhs) {
                trial.retry = 0.25;
                return false;
            }
            let mut norm: f64 = 0.0;
            for i in 0..S {
                z[0][i] += rhs[2 * i];
                z[1][i] += rhs[2 * i + 1];
                norm = norm
                    .max((rhs[2 * i] * nodes[i].elastance).abs() / sc_v)
                    .max(rhs[2 * i + 1].abs() / sc_s);
            }
            if !norm.is_finite() {
                trial.retry = 0.25;
                return false;
            }
            // Convergence rate θ (RADAU5): stop when the remaining error θ/(1−θ)·‖ΔZ‖ is small,
            // give up early when the iterations left cannot get there.
            if norm <= NEWTON_TOL {
                converged = true;
                break;
            }
            if iter > 0 {
                let theta = norm / prev_norm;
                if iter >= 2 && theta >= 0.99 {
                    trial.retry = 0.5;
                    return false;
                }
                if theta < 0.99 {
                    let left = (MAX_NEWTON - 1 - iter) as i32;
                    let predicted = norm * theta.powi(left) / (1.0 - theta) / NEWTON_TOL;
                    if iter >= 2 && predicted >= 1.0 {
                        let q = predicted.clamp(1e-4, 20.0);
                        trial.retry = 0.8 * q.powf(-1.0 / (4.0 + left as f64));
                        return false;
                    }
                }
            }
            prev_norm = norm;
        }
        if !converged {
            trial.retry = 0.5;
            return false;
        }
        // A bridge that switches within the step: its current changes by orders of magnitude
        // between the stage points, which the collocation polynomial and the error estimate
        // cannot follow. Retry so that each junction's voltage moves by at most SWITCH_SWEEP
        // n·V_T (its current by e⁴) above SWITCH_FLOOR.
        let sweep = {
            let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for j in 0..=S {
                let (u, vs, el) = if j == 0 {
                    (y0[0], y0[1], n0.elastance)
                } else {
                    (y0[0] + z[0][j - 1], y0[1] + z[1][j - 1], nodes[j - 1].elastance)
                };
                let v = -u * el;
                for (k, x) in diode.junction_exponents(v, vs).into_iter().enumerate() {
                    lo[k] = lo[k].min(x);
                    hi[k] = hi[k].max(x);
                }
            }
            (0..2)
                .filter(|&k| hi[k] > SWITCH_FLOOR)
                .map(|k| hi[k] - lo[k].max(SWITCH_FLOOR))
                .fold(0.0, f64::max)
        };
        if sweep > SWITCH_SWEEP {
            trial.retry = (0.9 * SWITCH_SWEEP / sweep).clamp(0.1, 0.9);
            return false;
        }
        trial.z = z;
        trial.qeq0 = n0.equilibrium_charge;
        trial.dq = dq;
        let (mut peak_v, mut peak_i, mut scale_v) = (0.0f64, 0.0f64, y0[1].abs());
        let mut v1 = 0.0;
        for j in 0..S {
            let yj = [y0[0] + z[0][j], y0[1] + z[1][j]];
            let (_, _, v, b) = f(yj, &nodes[j]);
            peak_v = peak_v.max(v.abs());
            peak_i = peak_i.max(b.current.abs());
            scale_v = scale_v.max(yj[1].abs());
            trial.power[j] = yj[1] * b.output;
            v1 = v;
        }
        trial.peak_voltage = peak_v;
        trial.peak_current = peak_i;
        trial.scale_voltage = scale_v;
        // Error estimate: (I − γ₀hJ₀) e = γ₀ (h f₀ + Σ dᵢ ΔYᵢ), ΔYᵢ = (Zᵢ + ΔQ_eq,ᵢ, Z_s,ᵢ).
        let (f0, j0, _, b0) = f(y0, n0);
        trial.hk = h * j0[0][0].abs();
        trial.stiff = trial.hk >= 1.0;
        let g = tab.gamma0;
        let dy = |i: usize, c: usize| z[c][i] + if c == 0 { dq[i] } else { 0.0 };
        let dz = [0, 1].map(|c| (0..S).map(|i| tab.dd[i] * dy(i, c)).sum::<f64>());
        let qeq_mag = self.qeq_noise_scale(n0, &dq);
        let noise = [0, 1].map(|c| {
            let q = if c == 0 { qeq_mag } else { 0.0 };
            NOISE
                * g
                * ((h * f0[c]).abs() + (0..S).map(|i| tab.dd[i].abs() * (z[c][i].abs() + q)).sum::<f64>())
        });
        let lhs = [
            [1.0 - g * h * j0[0][0], -g * h * j0[0][1]],
            [-g * h * j0[1][0], 1.0 - g * h * j0[1][1]],
        ];
        let mut e = [g * (h * f0[0] + dz[0]), g * (h * f0[1] + dz[1])];
        if !solve_fixed(&mut { lhs }, &mut e) {
            return false;
        }
        let y1 = [y0[0] + z[0][S - 1], y0[1] + z[1][S - 1]];
        let el1 = nodes[S - 1].elastance;
        let sc_v = rtol * v0.abs().max(v1.abs()) + atol + noise[0] * el1;
        let sc_s = rtol * y0[1].abs().max(y1[1].abs()) + atol + noise[1];
        let err_y = ((e[0] * el1).abs() / sc_v).max(e[1].abs() / sc_s);
        // Energy: p = V_s I_out; noise from the voltage and storage-voltage noise.
        let p0 = y0[1] * b0.output;
        let p_noise = (y0[1] * b0.output_dv).abs() * noise[0] * el1
            + (b0.output.abs() + (y0[1] * b0.output_dvs).abs()) * noise[1];
        let dp_du = -y0[1] * b0.output_dv * n0.elastance;
        let dp_dvs = b0.output + y0[1] * b0.output_dvs;
        let coupling = (
            dp_du * e[0] + dp_dvs * e[1],
            (dp_du * noise[0]).abs() + (dp_dvs * noise[1]).abs(),
        );
        let err_e = self.energy_error(tab, h, p0, trial, p_noise, coupling);
        trial.err = err_y.max(err_e);
        true
    }

    /// The magnitude whose `NOISE` fraction bounds the noise of `Q_eq` over a step, C.
    fn qeq_noise_scale<const S: usize>(&self, n0: &TransducerState, dq: &[f64; S]) -> f64 {
        n0.equilibrium_charge.abs() + dq[S - 1].abs() + self.charge_noise
    }

    /// Sets the energy of a trial step from its stage powers (W) and returns the scaled error
    /// estimate of that energy.
    ///
    /// The estimate is Hairer's for the quadrature component of the augmented system,
    /// `γ₀(h p₀ + Σ dᵢ ZEᵢ) + γ₀h (∂p/∂y)·e_y` with `ZE = hA·p` and
    /// `coupling = ((∂p/∂y)·e_y, its noise)`. The coupling term matters: after a step whose
    /// accepted error left the state slightly off the slow manifold of a stiff load, the
    /// quadrature part alone reads the decayed layer as an O(h) error, and the coupling term
    /// cancels it. The estimate is tested against `rtol·max(h, T/ENERGY_FLOOR_STEPS)·P_ref`,
    /// P_ref the larger of the average power since the start and over the last complete
    /// period, plus the estimate's noise from a stage-power noise `p_noise`, W: an error per
    /// unit step, so that the allowed error summed over a period is `rtol × its energy`, except
    /// that steps shorter than `T/ENERGY_FLOOR_STEPS` (boundary layers) may each use
    /// `rtol × E/ENERGY_FLOOR_STEPS`. Inactive during the first 1e-3 of a period after the
    /// start, where no power scale exists yet.
    fn energy_error<const S: usize>(
        &self,
        tab: &Tableau<S>,
        h: f64,
        p0: f64,
        trial: &mut Trial<S>,
        p_noise: f64,
        coupling: (f64, f64),
    ) -> f64 {
        let power = &trial.power;
        trial.energy = h * (0..S).map(|j| tab.a[S - 1][j] * power[j]).sum::<f64>();
        let Some(p_ref) = self.power_ref() else {
            return 0.0;
        };
        let dz: f64 = h * (0..S).map(|j| tab.dd_a[j] * power[j]).sum::<f64>();
        let g = tab.gamma0;
        let e = g * (h * p0 + dz) + g * h * coupling.0;
        let terms = (h * p0).abs() + h * (0..S).map(|j| tab.dd_a_abs[j] * power[j].abs()).sum::<f64>();
        let noise = g * (NOISE * terms + (1.0 + tab.dd_abs_sum) * h * p_noise + h * coupling.1);
        let floor = self.period / ENERGY_FLOOR_STEPS;
        e.abs() / (self.options.rtol * h.max(floor) * p_ref + noise)
    }

    /// The power scale of the energy test, W: the larger of the average power since the start
    /// and over the last complete period; `None` during the first 1e-3 of a period, before
    /// there is one.
    fn power_ref(&self) -> Option<f64> {
        let elapsed = self.t - self.t_start;
        if elapsed < 1e-3 * self.period {
            return None;
        }
        let p_ref = (self.energy / elapsed).max(self.last_period_power);
        (p_ref > 0.0).then_some(p_ref)
    }

    /// Commits an accepted step (its polynomial becomes `last_step`).
    fn accept<const S: usize>(&mut self, t0: f64, t1: f64, trial: &Trial<S>, n1: TransducerState) {
        let pad =
            |a: &[f64; S]| -> [f64; MAX_STAGES] { std::array::from_fn(|i| if i < S { a[i] } else { 0.0 }) };
        self.last_step = Some(Step {
            stages: S,
            t0,
            h: t1 - t0,
            y0: self.y,
            z: [pad(&trial.z[0]), pad(&trial.z[1])],
            e0: self.energy,
            power: pad(&trial.power),
            qeq0: trial.qeq0,
            dq: pad(&trial.dq),
            stiff: trial.stiff,
        });
        self.stats.steps += 1;
        self.t = t1;
        self.ts_now = n1;
        self.y = [self.y[0] + trial.z[0][S - 1], self.y[1] + trial.z[1][S - 1]];
        self.energy += trial.energy;
        if let Some(p) = self.periods.last_mut() {
            p.energy_j += trial.energy;
        }
        self.note_peaks(trial.peak_current, trial.peak_voltage);
        self.v_scale = self.v_scale.max(trial.scale_voltage);
    }

    /// State and energy at `t` inside an accepted step, from its collocation polynomial.
    ///
    /// `qeq` is `Q_eq(t)`, C. A stiff step interpolates `u` through its stage values (the
    /// quasi-static `u` is smooth where `Q` nearly equals `Q_eq`); a non-stiff one evaluates the
    /// collocation polynomial of `Q` and subtracts the exact `Q_eq(t)`.
    fn dense(&self, step: &Step, t: f64, qeq: f64) -> ([f64; 2], f64) {
        if step.stages == RESISTOR_STAGES {
            dense_with(&self.tab_resistor, step, t, qeq)
        } else {
            dense_with(&self.tab_rectifier, step, t, qeq)
        }
    }

    /// Outputs of the last accepted step: samples, V–Q points, target crossing, breakdown.
    fn record<W: GapWaveform + ?Sized>(&mut self, wave: &W) -> Result<(), ElectricalError> {
        if self.sampler.is_none()
            && self.vq.is_none()
            && self.target_voltage.is_none()
            && self.breakdown.is_none()
        {
            return Ok(());
        }
        let Some(step) = self.last_step else {
            return Ok(());
        };
        if self.breakdown.is_some() {
            self.watch_step(&step, wave)?;
        }
        let t1 = step.t0 + step.h;
        self.sample_between(step.t0, t1, wave, Some(&step))?;
        if let (Some(target), None, LoadModel::Rectifier(_)) =
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

    /// The air-breakdown check over an accepted step: its stage points (whose gaps are still
    /// in `node_gaps`), refined between the neighbours of one that beats the worst so far.
    fn watch_step<W: GapWaveform + ?Sized>(&mut self, step: &Step, wave: &W) -> Result<(), ElectricalError> {
        let Some(mut watch) = self.breakdown.take() else {
            return Ok(());
        };
        let n = self.gaps.len();
        let c: &[f64] = if step.stages == RESISTOR_STAGES {
            &self.tab_resistor.c
        } else {
            &self.tab_rectifier.c
        };
        let node = |i: usize| step.t0 + c[i] * step.h;
        let mut best = None;
        if node(step.stages - 1) >= watch.from() {
            for i in 0..step.stages {
                let q = step.y0[0] + step.z[0][i] + step.qeq0 + step.dq[i];
                if watch.observe(node(i), q, &self.node_gaps[i * n..(i + 1) * n]) {
                    best = Some(i);
                }
            }
        }
        let mut result = Ok(());
        if let Some(i) = best {
            let a = if i == 0 { step.t0 } else { node(i - 1) };
            let b = if i + 1 < step.stages { node(i + 1) } else { node(i) };
            watch.refine(a, b, |t, gaps| match self.eval(t, wave) {
                Ok(ts) => {
                    gaps.copy_from_slice(&self.gaps[..gaps.len()]);
                    let (y, _) = self.dense(step, t, ts.equilibrium_charge);
                    Some(y[0] + ts.equilibrium_charge)
                }
                Err(e) => {
                    result = Err(e);
                    None
                }
            });
        }
        self.breakdown = Some(watch);
        result
    }

    /// The air-breakdown check over a piece `[ta, tb]` of an open or short circuit, whose
    /// charge is known in closed form: equally spaced points, refined around the worst.
    fn watch_piece<W: GapWaveform + ?Sized>(
        &mut self,
        ta: f64,
        tb: f64,
        wave: &W,
    ) -> Result<(), ElectricalError> {
        let Some(mut watch) = self.breakdown.take() else {
            return Ok(());
        };
        let mut result = Ok(());
        if tb >= watch.from() {
            let at = |j: usize| ta + (tb - ta) * (j as f64 / BREAKDOWN_POINTS as f64);
            let mut best = None;
            for j in 0..=BREAKDOWN_POINTS {
                let ts = match self.eval(at(j), wave) {
                    Ok(ts) => ts,
                    Err(e) => {
                        self.breakdown = Some(watch);
                        return Err(e);
                    }
                };
                let q = self.row(ts, self.y, self.energy).charge;
                if watch.observe(at(j), q, &self.gaps) {
                    best = Some(j);
                }
            }
            if let Some(j) = best {
                let (a, b) = (at(j.saturating_sub(1)), at((j + 1).min(BREAKDOWN_POINTS)));
                watch.refine(a, b, |t, gaps| match self.eval(t, wave) {
                    Ok(ts) => {
                        gaps.copy_from_slice(&self.gaps[..gaps.len()]);
                        Some(self.row(ts, self.y, self.energy).charge)
                    }
                    Err(e) => {
                        result = Err(e);
                        None
                    }
                });
            }
        }
        self.breakdown = Some(watch);
        result
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
        if self.sampler.is_none() && self.vq.is_none() {
            return Ok(());
        }
        let rectifier = matches!(self.load, LoadModel::Rectifier(_));
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
                    let (y, e) = match step {
                        Some(s) => self.dense(s, t, ts.equilibrium_charge),
                        None => (self.y, self.energy),
                    };
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

/// [`ChargeSolver::dense`] with the tableau of the step's method.
fn dense_with<const S: usize>(tab: &Tableau<S>, step: &Step, t: f64, qeq: f64) -> ([f64; 2], f64) {
    debug_assert_eq!(step.stages, S);
    let w = tab.dense_weights((t - step.t0) / step.h);
    let mut y = step.y0;
    let mut e = step.e0;
    for (i, wi) in w.iter().enumerate() {
        y[0] += wi * step.z[0][i];
        y[1] += wi * step.z[1][i];
        // The energy's stage increment ZEᵢ = h Σⱼ aᵢⱼ pⱼ.
        e += wi * step.h * (0..S).map(|j| tab.a[i][j] * step.power[j]).sum::<f64>();
    }
    if !step.stiff {
        let interp: f64 = w.iter().zip(&step.dq).map(|(wi, dqi)| wi * dqi).sum();
        y[0] += interp - (qeq - step.qeq0);
    }
    (y, e)
}

impl Observer for ChargeSolver {
    fn flow(&mut self, flow: &Flow<'_>) {
        if self.error.is_none()
            && flow.t_end > flow.t_start
            && let Err(e) = self.advance_flow(flow)
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
