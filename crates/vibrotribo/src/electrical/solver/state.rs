//! The charge solver's state, and the internal pieces of a step (load model, trial step,
//! accepted step, output grids) and its numerical constants.

use super::results::{ChargeOptions, ElectricalSamples, PeriodStats, SolverStats};
use crate::dynamics::GapPolynomial;
use crate::electrical::ElectricalError;
use crate::electrical::breakdown::BreakdownWatch;
use crate::electrical::diode::DiodeLaw;
use crate::electrical::params::HarvesterParams;
use crate::electrical::radau::Tableau;
use crate::electrical::transducer::{ChargeMap, Transducer, TransducerState};

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum LoadModel {
    Resistor { conductance: f64 },
    Rectifier(RectifierLoad),
    Open,
    Short,
}

/// A uniform grid `t0 + span·(j/per)`, j = 0, 1, …, up to `last` if given (`per` = 1: a
/// step of `span`; `per` samples per `span`: the grid hits `t0 + k·span` exactly).
#[derive(Debug, Clone)]
pub(super) struct Grid {
    pub(super) t0: f64,
    pub(super) span: f64,
    pub(super) per: u64,
    pub(super) next: u64,
    pub(super) last: Option<u64>,
    pub(super) data: ElectricalSamples,
}

impl Grid {
    /// Whether [`next_in`](Self::next_in) has a time for `[ta, tb]` or earlier ones to skip:
    /// false exactly where it would return `None` at once, changing nothing.
    #[inline]
    pub(super) fn due(&self, tb: f64) -> bool {
        self.last.is_none_or(|l| self.next <= l)
            && self.t0 + self.span * (self.next as f64 / self.per as f64) <= tb
    }

    /// The next grid time inside `[ta, tb]`, advancing past earlier ones.
    pub(super) fn next_in(&mut self, ta: f64, tb: f64) -> Option<f64> {
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
pub(super) struct Row {
    pub(super) ts: TransducerState,
    pub(super) charge: f64,
    pub(super) current: f64,
    pub(super) voltage: f64,
    pub(super) storage: f64,
    pub(super) energy: f64,
}

/// One accepted Radau step: enough to evaluate its collocation polynomial.
#[derive(Debug, Clone, Copy)]
pub(super) struct Step {
    /// Stages of the method (the arrays hold that many entries).
    pub(super) stages: usize,
    pub(super) t0: f64,
    pub(super) h: f64,
    pub(super) y0: [f64; 2],
    /// Stage increments `z[c][i]` of `u` (C, c = 0) and of the storage voltage (V, c = 1).
    pub(super) z: [[f64; MAX_STAGES]; 2],
    pub(super) e0: f64,
    /// Stage values of the delivered power, W.
    pub(super) power: [f64; MAX_STAGES],
    /// `Q_eq` at t0 and its increments at the stages, C.
    pub(super) qeq0: f64,
    pub(super) dq: [f64; MAX_STAGES],
    pub(super) stiff: bool,
    /// The boundary layer carried in closed form by this step, if any (`layer.rs`).
    pub(super) layer: Option<super::layer_term::LayerTerm>,
}

/// Result of solving the stages of one trial step (one buffer reused for every trial).
#[derive(Debug, Clone, Copy)]
pub(super) struct Trial<const S: usize> {
    /// Stage increments `z[c][i]` of `u` (C, c = 0) and of the storage voltage (V, c = 1).
    pub(super) z: [[f64; S]; 2],
    /// Stage values of the delivered power, W.
    pub(super) power: [f64; S],
    /// Energy delivered over the step, J: `h Σ bⱼ pⱼ`.
    pub(super) energy: f64,
    /// Energy that left the transducer through its terminals over the step, J: `h Σ bⱼ Vⱼ Iⱼ`
    /// (V the terminal voltage, I = dQ/dt at the stages).
    pub(super) terminal_energy: f64,
    /// Largest |terminal voltage|, V, and |current|, A, at the stages.
    pub(super) peak_voltage: f64,
    pub(super) peak_current: f64,
    /// Largest stage value of the voltage that scales the default absolute tolerance, V (the
    /// load voltage for a resistor, the storage voltage for the rectifier).
    pub(super) scale_voltage: f64,
    /// Scaled error estimate (≤ 1 accepts).
    pub(super) err: f64,
    /// Whether the step is stiff (h·|∂Q'/∂Q| ≥ 1): then `u` is interpolated directly in dense
    /// output, otherwise `Q` (and `u = Q − Q_eq` with the exact `Q_eq`).
    pub(super) stiff: bool,
    /// h·|∂Q'/∂Q| at t0.
    pub(super) hk: f64,
    /// Factor for the next step after a failed Newton iteration.
    pub(super) retry: f64,
    /// `Q_eq` at t0 and its increments at the stages, C.
    pub(super) qeq0: f64,
    pub(super) dq: [f64; S],
}

impl<const S: usize> Trial<S> {
    pub(super) fn new() -> Self {
        Trial {
            z: [[0.0; S]; 2],
            power: [0.0; S],
            energy: 0.0,
            terminal_energy: 0.0,
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
pub(super) struct RectifierLoad {
    pub(super) diode: DiodeLaw,
    /// 1/C_s, 1/F.
    pub(super) inv_cs: f64,
    /// 1/R_L, S (0 without a load resistor).
    pub(super) load_conductance: f64,
}

/// Integrates the transducer's charge and the load driven by gap waveforms (see the module
/// docs). As an [`Observer`](crate::Observer) it consumes the simulator's flows directly; any other waveform
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
    pub(super) transducer: Transducer,
    /// The transducer in the form evaluated at stage points.
    pub(super) charge_map: ChargeMap,
    /// `NOISE_CHARGE / NOISE` times the charge scale σS, C (see `qeq_noise_scale`).
    pub(super) charge_noise: f64,
    pub(super) load: LoadModel,
    pub(super) options: ChargeOptions,
    pub(super) tab_resistor: Tableau<RESISTOR_STAGES>,
    pub(super) tab_rectifier: Tableau<RECTIFIER_STAGES>,
    pub(super) period: f64,
    pub(super) gaps: Vec<f64>,
    pub(super) rates: Vec<f64>,
    /// Gaps at the stage points of a step, `node_gaps[i·n + k]`, m.
    pub(super) node_gaps: Vec<f64>,
    pub(super) initial_charge: Option<f64>,
    pub(super) storage_initial_voltage: f64,
    pub(super) target_voltage: Option<f64>,
    pub(super) v_floor: f64,
    pub(super) started: bool,
    pub(super) t: f64,
    /// State: u = Q − C·V_oc, C; storage voltage, V.
    pub(super) y: [f64; 2],
    /// The transducer at `t`.
    pub(super) ts_now: TransducerState,
    /// The charge held by an open circuit, C.
    pub(super) open_charge: f64,
    /// Energy delivered since the start, J.
    pub(super) energy: f64,
    /// Energy that left the transducer through its terminals since the start, J (∫V·I dt;
    /// see [`ChargeSolver::terminal_energy`]).
    pub(super) terminal_energy: f64,
    /// Average power over the last complete period, W (0 before there is one).
    pub(super) last_period_power: f64,
    pub(super) h: f64,
    pub(super) h_acc: f64,
    /// `err^(1/(S+1))` of the last accepted step (at least that of 1e-2).
    pub(super) err_acc_root: f64,
    pub(super) have_acc: bool,
    /// Voltage scale of the default absolute tolerance, V.
    pub(super) v_scale: f64,
    /// Time the solver started, s.
    pub(super) t_start: f64,
    pub(super) last_step: Option<Step>,
    /// Whether the waveform is smooth from `last_step` to now (no piece boundary since).
    pub(super) smooth_since_last_step: bool,
    pub(super) periods: Vec<PeriodStats>,
    pub(super) steps_in_period: u64,
    pub(super) sampler: Option<Grid>,
    pub(super) vq: Option<Grid>,
    pub(super) target_time: Option<f64>,
    pub(super) stats: SolverStats,
    pub(super) error: Option<ElectricalError>,
    /// The current piece of flow, expanded (buffers reused).
    pub(super) poly: GapPolynomial,
    /// The harvester solved (for checks that need its geometry).
    pub(super) harvester: HarvesterParams,
    /// The air-breakdown check, if requested.
    pub(super) breakdown: Option<BreakdownWatch>,
    /// Charge moments accumulated over the accepted steps, if requested (two-way coupling).
    pub(super) moments: Option<ChargeMoments>,
    /// Times at which the charge is wanted from the accepted steps (two-way coupling).
    pub(super) probes: Probes,
}

/// Most probe times at once ([`ChargeSolver::set_probes`]).
pub(crate) const MAX_PROBES: usize = 16;

/// Times at which the charge is read from the accepted steps' collocation polynomials as the
/// solver passes them, and the charges found, C (NaN until passed).
#[derive(Debug, Clone, Copy)]
pub(super) struct Probes {
    pub times: [f64; MAX_PROBES],
    pub values: [f64; MAX_PROBES],
    pub len: usize,
    /// The first probe not yet passed.
    pub next: usize,
}

impl Default for Probes {
    fn default() -> Self {
        Probes {
            times: [0.0; MAX_PROBES],
            values: [f64::NAN; MAX_PROBES],
            len: 0,
            next: 0,
        }
    }
}

/// Time integrals of the charge over the steps accepted since
/// [`ChargeSolver::start_moments`], by the collocation quadrature of each step (the same
/// quadrature that books the energy): with `d = Q − q_ref` and `τ = t − t_ref`,
/// `[∫d, ∫d², ∫τ d, ∫τ d²]` (C·s, C²·s, C·s², C²·s²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChargeMoments {
    /// Reference time, s.
    pub t_ref: f64,
    /// Reference charge, C.
    pub q_ref: f64,
    /// The integrals.
    pub sums: [f64; 4],
}

/// Points per piece at which an open or short circuit (no steps) is checked for air
/// breakdown before the refinement.
pub(super) const BREAKDOWN_POINTS: usize = 32;

/// Stages of the Radau IIA method for the resistor: order 13, stage order 7.
pub(super) const RESISTOR_STAGES: usize = 7;

/// Stages for the rectifier: its steps are short around every switching of the bridge, where
/// a low order is cheaper (smaller Newton systems).
pub(super) const RECTIFIER_STAGES: usize = 3;

/// Room for the stages of either method in a stored step.
pub(super) const MAX_STAGES: usize = 7;

/// Steps per period below which the energy test stops shrinking with the step (see
/// `ChargeSolver::energy_error`).
pub(super) const ENERGY_FLOOR_STEPS: f64 = 1000.0;

/// A boundary layer being crossed (see `ChargeSolver::kink_start`).
#[derive(Debug, Clone, Copy)]
pub(super) struct Layer {
    pub(super) conductance: f64,
    /// ∫k dt since the kink.
    pub(super) decayed: f64,
    /// ∫k dt after which the layer is below the tolerance.
    pub(super) needed: f64,
    /// The step before the kink, s.
    pub(super) h_smooth: f64,
}

/// Sweep of the rectifier's voltage, in units of n·V_T, that the first step after a kink may
/// cover.
pub(super) const KINK_SWING: f64 = 10.0;

/// Largest change, in units of n·V_T, of a bridge junction's voltage over one rectifier step
/// while that junction conducts.
pub(super) const SWITCH_SWEEP: f64 = 4.0;

/// Reverse bias, in units of n·V_T, beyond which a junction counts as off (its current is
/// then −I_s to within e⁻⁶).
pub(super) const SWITCH_FLOOR: f64 = -6.0;

/// Growth per accepted step of the step size after a failure of Newton's method.
pub(super) const SOLVE_REGROWTH: f64 = 2.0;

/// Decay (e-folds) beyond the tolerance before a layer counts as gone.
pub(super) const LAYER_MARGIN: f64 = 3.0;

/// `x^(1/(S+1))`: the error estimate is O(h^(S+1)).
#[inline]
pub(super) fn err_root<const S: usize>(x: f64) -> f64 {
    // Only S = 3 and S = 7 are tabulated (`Tableau::new`).
    if S == 7 {
        x.sqrt().sqrt().sqrt()
    } else {
        x.sqrt().sqrt()
    }
}

/// Most Newton iterations per stage solve before the step is retried smaller.
pub(super) const MAX_NEWTON: usize = 12;

/// Newton's iterations stop when the estimated remaining error of the stages is below this
/// fraction of the error tolerance.
pub(super) const NEWTON_TOL: f64 = 1e-3;

/// Relative noise allowance of the error estimates: an estimate below this fraction of the
/// terms it is computed from is noise and never rejects a step. The floor is the precision of
/// the input, not of the arithmetic: gaps are differences of positions (~0.1 m) carried to
/// ~1e-17 m, which near contact is ~1e-13 of d₀ + D (d₀ ~ 0.1 mm).
pub(super) const NOISE: f64 = 1e-12;

/// Absolute noise allowance of the equilibrium charge, as a fraction of the charge scale σS:
/// the gap rounding above moves `Q_eq` by `(∂Q_eq/∂D)·δD ~ 1e-21 C` on the paper's device even
/// where `Q_eq` itself is near zero.
pub(super) const NOISE_CHARGE: f64 = 1e-13;
