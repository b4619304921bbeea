//! The charge solver's public face: construction, what it records, advancing it over gap
//! waveforms and the simulator's flow, what it reports; the circuit at one instant.

use super::results::{
    ChargeOptions, ElectricalSamples, PeriodStats, PowerSummary, SolverStats, power_curve, summarize,
};
use super::state::{
    ChargeMoments, ChargeSolver, Grid, LoadModel, MAX_STAGES, NOISE, NOISE_CHARGE, RectifierLoad, Row,
};
use crate::dynamics::{Flow, GapPolynomial, Observer, Trajectory, Verdict};
use crate::electrical::ElectricalError;
use crate::electrical::breakdown::{BreakdownMargin, BreakdownWatch};
use crate::electrical::diode::DiodeLaw;
use crate::electrical::params::{HarvesterParams, Load};
use crate::electrical::radau::Tableau;
use crate::electrical::transducer::{ChargeMap, Transducer, TransducerState};
use crate::electrical::waveform::{GapWaveform, PwlGaps};
use crate::error::ParamError;
use crate::model::ChainParams;

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
        let load = match &params.load {
            Load::Resistor { resistance } => LoadModel::Resistor {
                conductance: 1.0 / resistance,
            },
            Load::Rectifier(r) => LoadModel::Rectifier(RectifierLoad {
                diode: DiodeLaw::new(&r.diode),
                inv_cs: 1.0 / r.storage_capacitance,
                load_conductance: r.storage_load_resistance.map_or(0.0, |r| 1.0 / r),
            }),
            Load::Open => LoadModel::Open,
            Load::Short => LoadModel::Short,
        };
        let rectifier = params.load.rectifier();
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
            storage_initial_voltage: rectifier.map_or(0.0, |r| r.storage_initial_voltage),
            target_voltage: rectifier.and_then(|r| r.target_voltage),
            v_floor,
            started: false,
            t: 0.0,
            y: [0.0; 2],
            ts_now: TransducerState::default(),
            open_charge: 0.0,
            energy: 0.0,
            terminal_energy: 0.0,
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
            moments: None,
            probes: Default::default(),
        })
    }

    /// Also checks the air gaps for breakdown (Paschen's law, air at 1 atm; see
    /// [`breakdown`](crate::electrical::breakdown)) from time `from`, s, on: the worst ratio over the whole
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
    pub(super) fn advance_flow(&mut self, flow: &Flow<'_>) -> Result<(), ElectricalError> {
        let mut poly = std::mem::take(&mut self.poly);
        let result = match poly.build(flow) {
            Ok(()) => self.advance(flow.t_start, flow.t_end, &poly),
            Err(e) => Err(ElectricalError::TooFine {
                t_start: e.t_start,
                t_end: e.t_end,
                rate: e.rate,
                sub_pieces: e.sub_pieces,
                limit: crate::dynamics::MAX_COEFFICIENTS,
            }),
        };
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

    /// Starts accumulating the charge's time integrals ([`ChargeMoments`]) from now, with
    /// reference time `t_ref` (s) and charge `q_ref` (C); restarts them if already running.
    /// False (and nothing accumulated) for an open or short circuit, whose charge is not
    /// integrated by steps. A [`checkpoint`](Self::checkpoint) saves them, a rewind restores
    /// them.
    pub fn start_moments(&mut self, t_ref: f64, q_ref: f64) -> bool {
        if matches!(self.load, LoadModel::Open | LoadModel::Short) {
            self.moments = None;
            return false;
        }
        self.moments = Some(ChargeMoments {
            t_ref,
            q_ref,
            sums: [0.0; 4],
        });
        true
    }

    /// The charge's time integrals since [`start_moments`](Self::start_moments), if running.
    pub fn moments(&self) -> Option<ChargeMoments> {
        self.moments
    }

    /// Stops accumulating the charge's time integrals.
    pub fn stop_moments(&mut self) {
        self.moments = None;
    }

    /// Asks for the charge at `times` (s, ascending, after the current time; at most
    /// [`MAX_PROBES`](super::state::MAX_PROBES)), read from the accepted steps' collocation
    /// polynomials as the solver passes them ([`probe`](Self::probe)); replaces earlier
    /// probes. Used by two-way coupling to sample a window's charge in one run.
    pub(crate) fn set_probes(&mut self, times: &[f64]) {
        let n = times.len().min(super::state::MAX_PROBES);
        self.probes = Default::default();
        self.probes.times[..n].copy_from_slice(&times[..n]);
        self.probes.len = n;
    }

    /// The charge at probe `i` of [`set_probes`](Self::set_probes), C, once the solver has
    /// passed its time.
    pub(crate) fn probe(&self, i: usize) -> Option<f64> {
        (i < self.probes.next).then(|| self.probes.values[i])
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

    /// Energy that left the transducer through its terminals since the start, J: ∫V·I dt,
    /// V the terminal voltage (V) and I = dQ/dt (A), by each step's collocation quadrature
    /// (the one that books [`total_energy`](Self::total_energy)). For a resistor it is the
    /// load's energy; for the rectifier, the energy into the storage side
    /// ([`total_energy`](Self::total_energy), `∫V_s I_out dt`) plus what the bridge
    /// dissipates (diodes, their series resistances and leakage); 0 in open circuit (I = 0)
    /// and short circuit (V = 0). With two-way coupling it is the electrical term of the
    /// energy balance: the work of the electrostatic forces on the masses is
    /// −ΔU − ∫V·I dt (docs/MODEL.md §2).
    pub fn terminal_energy(&self) -> f64 {
        self.terminal_energy
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

    pub(super) fn eval<W: GapWaveform + ?Sized>(
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

    /// The transducer at `t` from the gaps alone: like [`eval`](Self::eval) without the rates
    /// (the equilibrium current is left 0).
    pub(super) fn eval_value<W: GapWaveform + ?Sized>(
        &mut self,
        t: f64,
        wave: &W,
    ) -> Result<TransducerState, ElectricalError> {
        wave.gap_values(t, &mut self.gaps);
        self.stats.waveform_evaluations += 1;
        self.state_at_gaps(&self.gaps, t)
    }

    /// The transducer at `gaps` (m, at time `t`, s), checked: an error unless its elastance is
    /// positive and finite and its equilibrium charge finite.
    #[inline]
    fn state_at_gaps(&self, gaps: &[f64], t: f64) -> Result<TransducerState, ElectricalError> {
        let ts = self.charge_map.state(gaps);
        if ts.elastance > 0.0 && ts.elastance.is_finite() && ts.equilibrium_charge.is_finite() {
            Ok(ts)
        } else {
            Err(ElectricalError::InvalidGaps { t })
        }
    }

    /// The transducer at the stage points `times` of a step: like [`eval`](Self::eval)
    /// without the rates (the equilibrium current is left 0).
    #[inline]
    pub(super) fn eval_nodes<W: GapWaveform + ?Sized, const S: usize>(
        &mut self,
        times: &[f64; S],
        wave: &W,
    ) -> Result<[TransducerState; S], ElectricalError> {
        let n = self.gaps.len();
        let gaps = &mut self.node_gaps[..S * n];
        wave.gap_values_at(times, gaps);
        self.stats.waveform_evaluations += S as u64;
        let mut nodes = [TransducerState::default(); S];
        // Every node first, then one test (the error names the first invalid one).
        let mut valid = true;
        // (Rows by multiplication: `chunks_exact` would divide by the row length.)
        for (i, node) in nodes.iter_mut().enumerate() {
            *node = self.charge_map.state(&gaps[i * n..(i + 1) * n]);
            valid &=
                node.elastance > 0.0 && node.elastance.is_finite() && node.equilibrium_charge.is_finite();
        }
        if !valid {
            for (i, &t) in times.iter().enumerate() {
                self.state_at_gaps(&self.node_gaps[i * n..(i + 1) * n], t)?;
            }
        }
        Ok(nodes)
    }

    pub(super) fn start<W: GapWaveform + ?Sized>(
        &mut self,
        t0: f64,
        wave: &W,
    ) -> Result<(), ElectricalError> {
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
    pub(super) fn row(&self, ts: TransducerState, y: [f64; 2], e: f64) -> Row {
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
    pub(super) fn piece<W: GapWaveform + ?Sized>(
        &mut self,
        ta: f64,
        tb: f64,
        wave: &W,
    ) -> Result<(), ElectricalError> {
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
                // The boundary layer after the kink in closed form where it fits in one step.
                let (start, n_start, kink) = match self.layer_step(&tab, conductance, ta, tb, n0, wave)? {
                    Some((t1, n1)) => (t1, n1, false),
                    None => (ta, n0, true),
                };
                if start < tb {
                    self.integrate(&tab, start, tb, n_start, wave, kink, |s, h, n0, nodes, trial| {
                        s.trial_resistor(&tab, conductance, h, n0, nodes, trial);
                        true
                    })?;
                }
            }
            LoadModel::Rectifier(load) => {
                let tab = self.tab_rectifier;
                self.integrate(&tab, ta, tb, n0, wave, true, |s, h, n0, nodes, trial| {
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
                self.fill_probes(tb, wave, None)?;
                self.watch_piece(ta, tb, wave)?;
            }
        }
        let vs = self.storage_voltage();
        let p = self.periods.last_mut().expect("pushed above");
        p.t_end = tb;
        p.storage_voltage_v = vs;
        Ok(())
    }

    pub(super) fn note_peaks(&mut self, current: f64, voltage: f64) {
        if let Some(p) = self.periods.last_mut() {
            p.peak_current_a = p.peak_current_a.max(current.abs());
            p.peak_voltage_v = p.peak_voltage_v.max(voltage.abs());
        }
    }

    /// The scaled absolute voltage tolerance, V.
    pub(super) fn atol(&self) -> f64 {
        self.options
            .atol_voltage
            .unwrap_or(self.options.rtol * self.v_scale.max(self.v_floor))
    }
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

    /// A failed charge solve fails the run at once.
    fn proceed(&mut self) -> Verdict {
        match &self.error {
            Some(e) => Err(Box::new(e.clone())),
            None => Ok(std::ops::ControlFlow::Continue(())),
        }
    }
}
