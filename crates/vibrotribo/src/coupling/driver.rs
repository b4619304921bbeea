//! The coupled run: windows of exact mechanics under a polynomial electrostatic force,
//! relaxed against the charge solver (see the module docs of [`crate::coupling`]).

use std::ops::ControlFlow;

use thiserror::Error;

use super::CouplingOptions;
use super::host::{ChargeHost, Trial};
use super::window::{
    ChargePolynomial, DEGREE, NODES, amplified_rounding, force_polynomial, length_ratio, nodes,
    polynomial_moments, significant_degree,
};
use crate::dynamics::response::SERIES_REACH;
use crate::dynamics::{ContactStatus, Event, EventKind, RunEnd, Segment, Simulator, StateView};
use crate::electrical::{ChargeMoments, ElectricalError, Electrostatics, NoFieldEnergy};
use crate::error::SimError;
use crate::model::{ChainState, ForcePolynomial};

/// A coupled run could not go on.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CouplingError {
    /// The mechanics stopped.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The charge solver stopped.
    #[error("charge solver: {0}")]
    Electrical(ElectricalError),
    /// The transducer has no field energy.
    #[error(transparent)]
    NoFieldEnergy(#[from] NoFieldEnergy),
    /// The windows had to shrink below rounding without meeting the tolerance.
    #[error(
        "two-way coupling: the window at t = {t} s shrank to {h:e} s without the charge meeting its \
         tolerance (harvester.coupling_tolerance may be too tight)"
    )]
    WindowCollapsed {
        /// Time, s.
        t: f64,
        /// Window length reached, s.
        h: f64,
    },
}

/// Work counters of a coupled run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CouplingStats {
    /// Windows accepted.
    pub windows: u64,
    /// Relaxation sweeps (mechanics + charge over a window), accepted or not.
    pub sweeps: u64,
    /// Windows redone shorter because the charge polynomial's error estimate was too large.
    pub shortened: u64,
    /// Windows cut short by an event.
    pub cut_by_event: u64,
}

/// Windows shorter than this many periods carry a constant charge (its variation there is far
/// below any tolerance, and a polynomial in so short a time would only amplify rounding).
const CONSTANT_BELOW: f64 = 1e-9;

/// A window shortened for accuracy below this many periods fails the run.
const MIN_WINDOW: f64 = 1e-12;

/// Redos of one window cut by an event before its end is accepted where the event fell.
const MAX_CUTS: u32 = 8;

/// The last accepted window's charge, for predicting the next.
#[derive(Debug, Clone, Copy)]
struct Previous {
    t0: f64,
    charge: ChargePolynomial,
    /// Whether an event ended it (then the charge's derivatives jump: no extrapolation).
    cut: bool,
}

/// The chain and its harvester with the electrostatic force acting on the masses.
///
/// ```
/// use vibrotribo::coupling::{CoupledChain, CouplingOptions, SolverOnly};
/// use vibrotribo::electrical::{ChargeOptions, ChargeSolver, HarvesterParams, VocModel};
/// use vibrotribo::{ChainParams, ChainState, SimOptions, Simulator};
///
/// let chain = ChainParams::default();
/// let harvester = HarvesterParams { voc_model: VocModel::Exact, ..HarvesterParams::default() };
/// let sim = Simulator::new(&chain, &ChainState::at_rest(3), SimOptions::default())?;
/// let mut host = SolverOnly(ChargeSolver::for_chain(&harvester, &chain, ChargeOptions::default())?);
/// let mut coupled = CoupledChain::new(sim, &harvester, CouplingOptions::default())?;
/// coupled.run_until(2.0 * chain.period(), &mut host)?;
/// assert!(host.0.total_energy() > 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Debug, Clone)]
pub struct CoupledChain {
    sim: Simulator,
    statics: Electrostatics,
    options: CouplingOptions,
    /// Preferred length of the next window, s.
    h: f64,
    previous: Option<Previous>,
    /// A simulator whose buffers the next trial reuses (see [`Simulator::assign_from`]).
    spare: Option<Simulator>,
    /// Smallest mass, kg.
    min_mass: f64,
    /// Largest natural frequency of a single mass, rad/s.
    omega_n: f64,
    /// The least `ω_n τ` at which the engine sums a force's response from its particular
    /// polynomial (below it, as a power series that does not amplify rounding): the
    /// response's [`SERIES_REACH`] in `(2α + ω_n)τ` over `1 + 2ζ` of the most damped mass (a
    /// cluster's damping ratio is at most its members' largest).
    series_x: f64,
    /// Smallest stiffness, N/m.
    min_stiffness: f64,
    stats: CouplingStats,
    /// Length of the last accepted first window after an event, s (NaN before one).
    after_event: f64,
    started: bool,
    /// The time of the last window of length zero (an event at its start), s, and how many
    /// such windows in a row were accepted there.
    instant: (f64, u32),
    /// Per mass: the force polynomial of the current trial (N/sʲ in t − t₀).
    forces: Vec<ForcePolynomial>,
    /// Per mass: the impulse and first moment (`∫F dτ`, `∫τ F dτ` over the window, N·s,
    /// N·s²) of the force of the solver's charge in the last sweep, if measured.
    target: Vec<[f64; 2]>,
    segments: Vec<Segment>,
    events: Vec<(Event, Vec<f64>, Vec<f64>)>,
}

impl CoupledChain {
    /// Couples `sim` to the harvester `params` (whose solver the host of
    /// [`run_until`](Self::run_until) owns). Refuses a transducer without field energy (the
    /// paper's open-circuit voltage law).
    pub fn new(
        mut sim: Simulator,
        params: &crate::electrical::HarvesterParams,
        options: CouplingOptions,
    ) -> Result<Self, CouplingError> {
        let statics = Electrostatics::new(&params.transducer())?;
        // Every trial installs its forces (a rebuild) before it runs: re-anchoring the flows
        // where the last one stopped would be redone at once.
        sim.set_rebuild_at_stops(false);
        let n = sim.params().len();
        let min_mass = sim.params().masses.iter().copied().fold(f64::INFINITY, f64::min);
        let h = options.max_window_periods * sim.period();
        let p = sim.params();
        let omega_n = p
            .masses
            .iter()
            .zip(&p.stiffness)
            .map(|(m, k)| (k / m).sqrt())
            .fold(0.0, f64::max);
        let zeta_max = p
            .masses
            .iter()
            .zip(&p.stiffness)
            .zip(&p.damping)
            .map(|((m, k), c)| c / (2.0 * (k * m).sqrt()))
            .fold(0.0, f64::max);
        let series_x = SERIES_REACH / (1.0 + 2.0 * zeta_max);
        let min_stiffness = p.stiffness.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(CoupledChain {
            sim,
            statics,
            options,
            h,
            previous: None,
            spare: None,
            min_mass,
            omega_n,
            series_x,
            min_stiffness,
            stats: CouplingStats::default(),
            after_event: f64::NAN,
            started: false,
            instant: (f64::NAN, 0),
            forces: vec![ForcePolynomial::zero(); n],
            target: vec![[0.0; 2]; n],
            segments: Vec::new(),
            events: Vec::new(),
        })
    }

    /// Current time, s.
    pub fn time(&self) -> f64 {
        self.sim.time()
    }

    /// The state of the chain now.
    pub fn state(&self) -> ChainState {
        self.sim.state()
    }

    /// The mechanics (with the force of the last window installed).
    pub fn simulator(&self) -> &Simulator {
        &self.sim
    }

    /// Work counters so far.
    pub fn stats(&self) -> CouplingStats {
        self.stats
    }

    /// Runs to `t_end`, s, reporting the accepted motion to `host` and advancing its charge
    /// solver. Stops early (at a window's end) when `host` asks to.
    pub fn run_until<H: ChargeHost + ?Sized>(
        &mut self,
        t_end: f64,
        host: &mut H,
    ) -> Result<RunEnd, CouplingError> {
        if t_end.is_nan() || t_end < self.sim.time() {
            return Err(SimError::Backwards {
                requested: t_end,
                current: self.sim.time(),
            }
            .into());
        }
        if !self.started {
            self.start(host)?;
        }
        let period = self.sim.period();
        while self.sim.time() < t_end {
            let t0 = self.sim.time();
            let mut boundary = ((t0 / period).floor() + 1.0) * period;
            if boundary <= t0 * (1.0 + 4.0 * f64::EPSILON) {
                boundary += period;
            }
            let limit = t_end.min(boundary);
            self.window(t0, limit, host)?;
            self.replay(host);
            match host.proceed() {
                Ok(ControlFlow::Continue(())) => {}
                Ok(ControlFlow::Break(())) => return Ok(RunEnd::Stopped { t: self.sim.time() }),
                Err(e) => return Err(SimError::Observer(e.to_string()).into()),
            }
        }
        Ok(RunEnd::Reached)
    }

    /// Starts the solver at the current time (its initial charge) if it has not started.
    fn start<H: ChargeHost + ?Sized>(&mut self, host: &mut H) -> Result<(), CouplingError> {
        let t0 = self.sim.time();
        let state = self.sim.state();
        let deltas = self.sim.params().gaps.clone();
        let wave = |_: f64, gaps: &mut [f64], rates: &mut [f64]| {
            for k in 0..gaps.len() {
                gaps[k] = deltas[k] - (state.positions[k + 1] - state.positions[k]);
                rates[k] = -(state.velocities[k + 1] - state.velocities[k]);
            }
        };
        host.charge_solver().advance(t0, t0, &wave)?;
        self.started = true;
        Ok(())
    }

    /// The charge tolerance of a window of length `h`, C, around charge `q0`.
    fn charge_tolerance(&self, h: f64, q0: f64, scale: f64) -> f64 {
        let slope = self.force_slope(q0.abs() + scale);
        let tol_x = self.options.position_tolerance;
        let omega = 2.0 * std::f64::consts::PI / self.sim.period();
        // The force error δF = slope·δQ moves a mass by ∫(h − τ)δF/m ≤ h²·mean|δF|/m and
        // changes its velocity by ≤ h·mean|δF|/m; the window's estimate bounds mean|δQ|.
        let by_position = tol_x * self.min_mass / (slope * h * h);
        let by_velocity = tol_x * omega * self.min_mass / (slope * h);
        by_position.min(by_velocity).max(1e-15 * scale)
    }

    /// The largest `|∂G_k/∂Q|` of a gap force for charges up to `q` in magnitude, N/C.
    fn force_slope(&self, q: f64) -> f64 {
        self.statics
            .gap_force_polynomials()
            .map(|(_, c)| c[1].abs() + 2.0 * c[2].abs() * q)
            .fold(0.0, f64::max)
    }

    /// The force error, N, allowed on a mass where the engine decides a contact (a stick or a
    /// release at a window's end): the force of the weakest spring stretched by the position
    /// tolerance. A release then comes within this force over the contact force's rate of
    /// the zero of the force of the solver's charge.
    fn force_tolerance(&self) -> f64 {
        self.min_stiffness * self.options.position_tolerance
    }

    /// The electrostatic force on each mass of the transferred charge `q` (C), N: each gap's
    /// force `G_k` acts on mass k and, with the opposite sign, on mass k + 1.
    fn mass_forces(&self, q: f64) -> Vec<f64> {
        let mut forces = vec![0.0; self.forces.len()];
        for (k, c) in self.statics.gap_force_polynomials() {
            let g = c[0] + c[1] * q + c[2] * q * q;
            forces[k] += g;
            forces[k + 1] -= g;
        }
        forces
    }

    /// How far the installed force at `span` after the window's start misses the force of the
    /// charge `q` on the masses, N: the largest and the summed `|installed − exact|` (the
    /// largest against [`force_tolerance`](Self::force_tolerance) is the window's end test).
    fn end_force_errors(&self, span: f64, q: f64) -> (f64, f64) {
        let mut worst: f64 = 0.0;
        let mut sum = 0.0;
        for (f, e) in self.forces.iter().zip(&self.mass_forces(q)) {
            let installed = f.coefficients.iter().rev().fold(0.0, |acc, &c| acc * span + c);
            worst = worst.max((installed - e).abs());
            sum += (installed - e).abs();
        }
        (worst, sum)
    }

    /// Installs on `sim` the force polynomials of the charge `q` on a window from `t0`.
    ///
    /// Every trial of every window starting at `t0` has the same force at `t0`: that of the
    /// solver's charge there, `q0` (the polynomial's constant term is set to it, and the
    /// moment-matching correction vanishes at τ = 0). The engine decides the contacts at a
    /// window's start (stick, release, a touch) with the force there; if it differed from
    /// trial to trial, an event at the start decided under one trial's force was undone at
    /// the same instant by the next window's first trial (notes/coupled-stick-loop.md).
    fn install(
        &mut self,
        sim: &mut Simulator,
        t0: f64,
        q: &ChargePolynomial,
        q0: f64,
        negligible: f64,
        matched: bool,
    ) -> Result<(), SimError> {
        for f in &mut self.forces {
            f.t_ref = t0;
            f.coefficients.clear();
            f.coefficients.resize(super::window::FORCE_DEGREE + 1, 0.0);
        }
        for (k, c) in self.statics.gap_force_polynomials() {
            let g = force_polynomial(q, c);
            for (j, gj) in g.iter().enumerate() {
                self.forces[k].coefficients[j] += gj;
                self.forces[k + 1].coefficients[j] -= gj;
            }
        }
        let at_start = self.mass_forces(q0);
        for (f, &f0) in self.forces.iter_mut().zip(&at_start) {
            // The force at the start is the solver's charge's (the polynomial's value there
            // differs from it by the fit's truncation and rounding only).
            f.coefficients[0] = f0;
            let keep = significant_degree(&f.coefficients, q.h, negligible);
            f.coefficients.truncate(keep + 1);
        }
        if matched {
            // Add to each mass the force βτ + γτ² that gives its polynomial the impulse and
            // first moment of the force of the solver's charge (measured in the last sweep):
            // a transient the polynomial cannot follow (the charge's boundary layer of width
            // R·C after an impact) then reaches the masses with its integral and its first
            // moment, which is all a window short against the mechanics' time scales passes
            // on to the positions and velocities at its end. It vanishes at τ = 0, so that
            // the force at the window's start stays the solver's charge's (see above).
            let h = q.h;
            let budget = self.rounding_budget();
            let (omega_n, series_x) = (self.omega_n, self.series_x);
            for (f, target) in self.forces.iter_mut().zip(&self.target) {
                let [i0, i1] = polynomial_moments(&f.coefficients, h);
                let (d0, d1) = (target[0] - i0, target[1] - i1);
                // ∫βτ + γτ² = βh²/2 + γh³/3 = d0, ∫τ(βτ + γτ²) = βh³/3 + γh⁴/4 = d1.
                let mut beta = 18.0 * d0 / (h * h) - 24.0 * d1 / (h * h * h);
                let mut gamma = 36.0 * d1 / (h * h * h * h) - 24.0 * d0 / (h * h * h);
                // The terms' rounding, amplified as in `fit`: beyond the budget only the
                // impulse is matched.
                if amplified_rounding(&[0.0, beta, gamma], h, omega_n, series_x) > budget {
                    beta = 2.0 * d0 / (h * h);
                    gamma = 0.0;
                }
                if f.coefficients.len() < 3 {
                    f.coefficients.resize(3, 0.0);
                }
                f.coefficients[1] += beta;
                f.coefficients[2] += gamma;
            }
        }
        sim.set_external_forces(&self.forces)
    }

    /// The most a force polynomial's terms may amplify rounding on a window
    /// ([`amplified_rounding`]), N: the force of the weakest spring stretched by a hundredth of
    /// the position tolerance, over the unit roundoff.
    fn rounding_budget(&self) -> f64 {
        0.01 * self.options.position_tolerance * self.min_stiffness / f64::EPSILON
    }

    /// Per mass, the impulse and first moment of the force of the solver's charge over
    /// `[t_ref, t_ref + span]`, from its charge moments (into `target`).
    fn measure(&mut self, m: &ChargeMoments, span: f64) {
        for t in &mut self.target {
            *t = [0.0; 2];
        }
        let [s0, s1, s2, s3] = m.sums;
        for (k, c) in self.statics.gap_force_polynomials() {
            // G(q_ref + d) = g0 + g1 d + c₂ d².
            let q = m.q_ref;
            let g0 = c[0] + c[1] * q + c[2] * q * q;
            let g1 = c[1] + 2.0 * c[2] * q;
            let impulse = g0 * span + g1 * s0 + c[2] * s1;
            let moment = 0.5 * g0 * span * span + g1 * s2 + c[2] * s3;
            self.target[k][0] += impulse;
            self.target[k][1] += moment;
            self.target[k + 1][0] -= impulse;
            self.target[k + 1][1] -= moment;
        }
    }

    /// How far the installed forces' impulse and first moment over `[0, span]` miss the
    /// measured ones (`target`), against the tolerances: the displacement error at the end,
    /// `|∫(span − τ)δF|/m`, against the position tolerance, and the velocity error `|∫δF|/m`
    /// against the position tolerance times the excitation frequency (as in
    /// [`charge_tolerance`](Self::charge_tolerance)). ≤ 1 passes.
    fn moment_error(&self, span: f64) -> f64 {
        let tol_x = self.options.position_tolerance;
        let omega = 2.0 * std::f64::consts::PI / self.sim.period();
        let masses = &self.sim.params().masses;
        let mut worst: f64 = 0.0;
        for ((f, target), m) in self.forces.iter().zip(&self.target).zip(masses) {
            let [i0, i1] = polynomial_moments(&f.coefficients, span);
            let (d0, d1) = (target[0] - i0, target[1] - i1);
            let by_position = (span * d0 - d1).abs() / (m * tol_x);
            let by_velocity = d0.abs() / (m * tol_x * omega);
            worst = worst.max(by_position).max(by_velocity);
        }
        worst
    }

    /// The charge polynomial through `values` at the nodes of a window of length `h`, s, cut
    /// to the highest degree whose force polynomials the engine can integrate without
    /// amplifying rounding beyond a hundredth of the position tolerance: where the engine
    /// sums a force term f_j τʲ's response from its particular polynomial, that polynomial
    /// carries terms up to j!/(ω_n τ)ʲ times the static effect f_j τʲ/K, which the
    /// homogeneous part then cancels. It does so only from `ω_n τ ≥` `series_x` on (a power
    /// series before), so the amplification is at most j!/max(ω_n h, series_x)ʲ: about one for
    /// a lightly damped chain, whatever the window's length. Constant on windows shorter than
    /// [`CONSTANT_BELOW`] periods.
    ///
    /// On a window that decides a contact (`precise`, see [`window`](Self::window)) the
    /// budget alone decides at every length: there the force at the window's end must meet the
    /// force tolerance, which a constant does not where the force changes.
    fn fit(&self, values: &[f64; NODES], h: f64, precise: bool) -> ChargePolynomial {
        let period = self.sim.period();
        if !precise && h < CONSTANT_BELOW * period {
            return ChargePolynomial::constant(values[0], h);
        }
        let full = ChargePolynomial::new(values, h);
        let budget = self.rounding_budget();
        for degree in (1..=DEGREE).rev() {
            let q = full.truncated(degree);
            let safe = self.statics.gap_force_polynomials().all(|(_, c)| {
                amplified_rounding(&force_polynomial(&q, c), h, self.omega_n, self.series_x) <= budget
            });
            if safe {
                return q;
            }
        }
        full.truncated(0)
    }

    /// Finds and carries out the next window from `t0` (ending by `limit`, s): on return the
    /// mechanics and the solver stand at its end and `segments`/`events` hold its motion.
    fn window<H: ChargeHost + ?Sized>(
        &mut self,
        t0: f64,
        limit: f64,
        host: &mut H,
    ) -> Result<(), CouplingError> {
        let period = self.sim.period();
        let mut h = self.h.min(limit - t0);
        // The first window after an event starts in the charge's R·C layer (after an impact),
        // where the preferred length of the smooth stretch before it is far too long: it starts
        // from at most 1.5× the length the last such window was accepted at (consecutive
        // impacts of a chatter sequence are alike).
        let after_cut = matches!(self.previous, Some(p) if p.cut);
        if after_cut && self.after_event > 0.0 {
            h = h.min(1.5 * self.after_event);
        }
        let q0 = host.charge_solver().charge();
        let scale = host.charge_solver().transducer().charge_scale();
        // Whether the window decides a contact: a contact is stuck (or in a chatter sequence)
        // at its start, or a trial of it ended at a stick, release or chatter point. Its force
        // must then also meet the force tolerance at its end, where the engine decides.
        //
        // Not after two windows of length zero at this instant: the events at a window's start
        // are decided with the first trial that sees one, and the trials' force polynomials
        // agree at the start but not in their derivatives, which decide a pair whose contact
        // force is zero there (a stick at a chatter point). Trials that keep those derivatives
        // could then undo each other's events at one instant (stick, release, stick, ...);
        // such a window keeps the forces of a window that decides nothing.
        let settled = !(self.instant.0 == t0 && self.instant.1 >= 2);
        let mut precise = settled
            && self
                .sim
                .contact_status()
                .iter()
                .any(|s| *s != ContactStatus::Open);
        let mut guess = match self.previous {
            Some(p) if !p.cut => self.fit(&p.charge.values_at_nodes(t0 - p.t0, h), h, precise),
            _ => ChargePolynomial::constant(q0, h),
        };
        let mut sweeps = 0;
        // Every trial below that is not accepted rewinds the solver to this state before the
        // next one.
        let cp = host.charge_solver().checkpoint();
        // The time of the event a window was cut at and is now redone up to, s: the run goes an
        // ulp past it, so that the search (whose horizon excludes its end) still reports an
        // event that falls at the window's end to the ulp (a graze that it would otherwise take
        // for the next window's start and pass over).
        let mut event_at_end: Option<f64> = None;
        // The last window length, s, redone shorter for its error estimate, and that estimate, C.
        let mut too_long: Option<(f64, f64)> = None;
        let mut cuts = 0;
        // Whether `target` holds the force moments measured by the last sweep of this window
        // (same length): the next trial then matches them.
        let mut matched = false;
        let mut trial = self.spare.take().unwrap_or_else(|| self.sim.clone());
        loop {
            sweeps += 1;
            self.stats.sweeps += 1;
            let tol = self.charge_tolerance(h, q0, scale);
            let mut negligible = 0.01 * 2.0 * self.options.position_tolerance * self.min_mass / (h * h);
            if precise {
                negligible = negligible.min(0.25 * self.force_tolerance());
            }
            let tracked = host.charge_solver().start_moments(t0, q0);
            trial.assign_from(&self.sim);
            self.install(&mut trial, t0, &guess, q0, negligible, matched)?;
            self.segments.clear();
            self.events.clear();
            let times = nodes(t0, h);
            let mut values = [q0; NODES];
            let mut cut = None;
            {
                let mut watcher = Trial {
                    host: &mut *host,
                    segments: &mut self.segments,
                    events: &mut self.events,
                };
                // One run over the window; the solver reads the charge at the inner nodes from
                // its steps as it passes them.
                watcher.host.charge_solver().set_probes(&times[1..NODES - 1]);
                let stop = match event_at_end {
                    Some(te) => times[NODES - 1].max(te).next_up(),
                    _ => times[NODES - 1],
                };
                let end = trial.run_until(stop, &mut watcher);
                let solver = watcher.host.charge_solver();
                let probed: [Option<f64>; NODES - 2] = std::array::from_fn(|i| solver.probe(i));
                solver.set_probes(&[]);
                let reached = match end {
                    Ok(RunEnd::Reached) => NODES,
                    Ok(RunEnd::Stopped { t }) => {
                        let j = (1..NODES).find(|&j| times[j] >= t).unwrap_or(NODES - 1);
                        cut = Some((j, t));
                        j
                    }
                    Err(SimError::Observer(_)) => {
                        return Err(match solver.status().err() {
                            Some(e) => e.into(),
                            None => SimError::Observer("coupled run".into()).into(),
                        });
                    }
                    Err(e) => return Err(e.into()),
                };
                for (j, v) in values.iter_mut().enumerate().take(reached.min(NODES - 1)).skip(1) {
                    *v = probed[j - 1].unwrap_or_else(|| solver.charge());
                }
                if reached == NODES {
                    values[NODES - 1] = solver.charge();
                }
            }
            if let Some((j, te)) = cut {
                // An event inside the window: at its last node (the window ends there, with the
                // event applied) or before it (redo the window up to the event).
                let at_end = j == NODES - 1 && (times[j] - te).abs() <= 1e-9 * h;
                let shorter = te - t0;
                if at_end || cuts >= MAX_CUTS {
                    values[j] = host.charge_solver().charge();
                } else if shorter > 0.0 && shorter < CONSTANT_BELOW * period {
                    // The event follows the window's start within CONSTANT_BELOW periods (as
                    // when two contacts close at one instant to rounding): over so short a time
                    // the trial's force, which starts at the force of the solver's charge, is
                    // that force, and the trial up to the event is the window, with a constant
                    // charge (redoing it would repeat the same motion).
                    self.stats.cut_by_event += 1;
                    let q = host.charge_solver().charge();
                    host.charge_solver().stop_moments();
                    self.accept(trial, t0, ChargePolynomial::constant(q, shorter), true, None);
                    return Ok(());
                } else {
                    host.charge_solver().rewind(&cp);
                    self.stats.cut_by_event += 1;
                    cuts += 1;
                    if shorter <= 0.0 {
                        // The event is at the window's start: accept it with no flow.
                        host.charge_solver().stop_moments();
                        self.instant = if self.instant.0 == t0 {
                            (t0, self.instant.1 + 1)
                        } else {
                            (t0, 1)
                        };
                        self.accept(trial, t0, ChargePolynomial::constant(q0, 0.0), true, None);
                        return Ok(());
                    }
                    guess = self.fit(&guess.values_at_nodes(0.0, shorter), shorter, precise);
                    h = shorter;
                    event_at_end = Some(te);
                    matched = false;
                    continue;
                }
            }
            let decided = settled
                && self.events.iter().any(|(e, _, _)| {
                    matches!(e.kind, EventKind::Stick | EventKind::Release | EventKind::Chatter)
                });
            precise = precise || decided;
            let sampled = self.fit(&values, h, precise);
            let misfit = guess
                .values_at_nodes(0.0, h)
                .iter()
                .zip(&values)
                .map(|(g, v)| (g - v).abs())
                .fold(0.0, f64::max);
            let estimate = sampled.error_estimate();
            let span = host.charge_solver().time() - t0;
            let moment_error = match host.charge_solver().moments() {
                Some(m) if tracked && span > 0.0 => {
                    self.measure(&m, span);
                    self.moment_error(span)
                }
                _ => 0.0,
            };
            // Below CONSTANT_BELOW periods the window itself bounds how far a decision at its
            // end can be from the zero of the force (every window starts at the force of the
            // solver's charge), and the force test is not made.
            //
            // A window that only has a contact stuck (none decided in it) is held to the test
            // only where a release may hide at its end: where the engine's contact force there
            // is within the force error of zero. A contact force is r·ΣF_G − Σ_{i≤j}F_i with
            // 0 ≤ r ≤ 1, so its error is at most the summed error on the masses; beyond that its
            // sign is the true force's and the window decides nothing. (Testing every window of
            // a long sticking phase cost up to 61× in the chatter case at low Ω.)
            let force_error = if precise && span > 0.0 && h > CONSTANT_BELOW * period {
                let q = host.charge_solver().charge();
                let (worst, summed) = self.end_force_errors(span, q);
                let near = decided
                    || trial
                        .contact_forces()
                        .iter()
                        .flatten()
                        .any(|n| n.abs() <= summed + self.force_tolerance());
                if near { worst / self.force_tolerance() } else { 0.0 }
            } else {
                0.0
            };
            if estimate > tol {
                host.charge_solver().rewind(&cp);
                self.stats.shortened += 1;
                // The estimate falls as h^(DEGREE+1) where the charge is smooth, but only about
                // as h where the window holds the start of a boundary layer (the charge's R·C
                // relaxation after an impact): after a first cut, the order the estimate showed
                // between the last two lengths decides the next cut.
                let order = match too_long {
                    Some((h_prev, e_prev)) if h_prev > h && e_prev > estimate => {
                        ((e_prev / estimate).ln() / (h_prev / h).ln()).clamp(1.0, (DEGREE + 1) as f64)
                    }
                    Some(_) => 1.0,
                    None => (DEGREE + 1) as f64,
                };
                too_long = Some((h, estimate));
                let factor = (0.8 * length_ratio(tol, estimate, order)).clamp(0.02, 0.8);
                let shorter = h * factor;
                if shorter <= MIN_WINDOW * period {
                    return Err(CouplingError::WindowCollapsed { t: t0, h: shorter });
                }
                guess = self.fit(&sampled.values_at_nodes(0.0, shorter), shorter, precise);
                h = shorter;
                event_at_end = None;
                self.h = self.h.min(h);
                sweeps = 0;
                matched = false;
                continue;
            }
            if misfit > tol || moment_error > 1.0 || force_error > 1.0 {
                host.charge_solver().rewind(&cp);
                // The end force still off after a few sweeps: the window is too long for the
                // polynomial (a transient it does not resolve), not the guess too far.
                let stalled = force_error > 1.0 && sweeps >= 3;
                if sweeps >= self.options.max_iterations || stalled {
                    h *= 0.5;
                    event_at_end = None;
                    if h <= MIN_WINDOW * period {
                        return Err(CouplingError::WindowCollapsed { t: t0, h });
                    }
                    self.h = self.h.min(h);
                    sweeps = 0;
                    guess = self.fit(&sampled.values_at_nodes(0.0, h), h, precise);
                    matched = false;
                } else {
                    guess = sampled;
                    matched = tracked;
                }
                continue;
            }
            // The length at which the estimate would meet the tolerance, over this one.
            let ratio = length_ratio(tol, estimate, (DEGREE + 1) as f64);
            let next = if cut.is_some() {
                // A window that ends at an event is as long as the event allows, not as its
                // accuracy needs: it only lowers the preferred length, to the length its
                // estimate predicts (without the growth limit), never to a multiple of its own
                // length (which after an event just past a window's start would start the next
                // windows from a few picoseconds).
                h * 0.8 * ratio
            } else {
                (h * (0.8 * ratio).clamp(0.2, 4.0)).min(self.options.max_window_periods * period)
            };
            if after_cut && cut.is_none() {
                self.after_event = h;
            }
            host.charge_solver().stop_moments();
            self.accept(trial, t0, sampled, cut.is_some(), Some(next));
            return Ok(());
        }
    }

    fn accept(&mut self, trial: Simulator, t0: f64, charge: ChargePolynomial, cut: bool, next: Option<f64>) {
        // The window's start state becomes the next window's trial buffer.
        self.spare = Some(std::mem::replace(&mut self.sim, trial));
        self.stats.windows += 1;
        self.previous = Some(Previous { t0, charge, cut });
        if let Some(next) = next
            && (!cut || next < self.h)
        {
            self.h = next;
        }
    }

    /// Reports the accepted window's motion to `host`.
    fn replay<H: ChargeHost + ?Sized>(&mut self, host: &mut H) {
        for seg in &self.segments {
            host.flow(&self.sim.flow_of(seg));
        }
        for (e, x, v) in &self.events {
            host.event(
                e,
                &StateView {
                    time: e.time,
                    positions: x,
                    velocities: v,
                },
            );
        }
    }
}

// Not `#[from]`: that would also make the inner error the `source()`, which the message
// already shows (a failure's chain printed it twice).
impl From<ElectricalError> for CouplingError {
    fn from(e: ElectricalError) -> Self {
        CouplingError::Electrical(e)
    }
}
