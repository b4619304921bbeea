//! Outputs of accepted steps from their collocation polynomials: samples, the V–Q cycle, the
//! storage target crossing, the air-breakdown check.

use super::state::{BREAKDOWN_POINTS, ChargeSolver, LoadModel, MAX_STAGES, RESISTOR_STAGES, Step};
use crate::electrical::ElectricalError;
use crate::electrical::radau::Tableau;
use crate::electrical::waveform::GapWaveform;

impl ChargeSolver {
    /// State and energy at `t` inside an accepted step, from its collocation polynomial.
    ///
    /// `qeq` is `Q_eq(t)`, C. A stiff step interpolates `u` through its stage values (the
    /// quasi-static `u` is smooth where `Q` nearly equals `Q_eq`); a non-stiff one evaluates the
    /// collocation polynomial of `Q` and subtracts the exact `Q_eq(t)`.
    pub(super) fn dense(&self, step: &Step, t: f64, qeq: f64) -> ([f64; 2], f64) {
        self.dense_inner::<true>(step, t, qeq)
    }

    /// The state alone at `t` inside an accepted step (as [`dense`](Self::dense), without the
    /// energy's quadrature).
    pub(super) fn dense_state(&self, step: &Step, t: f64, qeq: f64) -> [f64; 2] {
        self.dense_inner::<false>(step, t, qeq).0
    }

    /// [`dense`](Self::dense), with the energy (else `step.e0` in its place) if `ENERGY`.
    fn dense_inner<const ENERGY: bool>(&self, step: &Step, t: f64, qeq: f64) -> ([f64; 2], f64) {
        if let Some(layer) = &step.layer {
            super::layer::dense_layer::<ENERGY>(&self.tab_resistor, step, layer, t)
        } else if step.stages == RESISTOR_STAGES {
            dense_with::<_, ENERGY>(&self.tab_resistor, step, t, qeq)
        } else {
            dense_with::<_, ENERGY>(&self.tab_rectifier, step, t, qeq)
        }
    }

    /// Outputs of the last accepted step: samples, V–Q points, target crossing, breakdown.
    pub(super) fn record<W: GapWaveform + ?Sized>(&mut self, wave: &W) -> Result<(), ElectricalError> {
        if self.probes.next < self.probes.len
            && let Some(step) = self.last_step
        {
            self.fill_probes(step.t0 + step.h, wave, Some(&step))?;
        }
        if self.breakdown.is_some() {
            self.watch_step(wave)?;
        }
        let rectifier_target = matches!(
            (self.target_voltage, self.target_time, self.load),
            (Some(_), None, LoadModel::Rectifier(_))
        );
        let Some(step) = self.last_step.as_ref() else {
            return Ok(());
        };
        let t1 = step.t0 + step.h;
        // (The step is copied out only when an output needs it: most steps hold no sample.)
        if !self.grids_due(t1) && !rectifier_target {
            return Ok(());
        }
        let step = *step;
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
                    if self.dense_state(&step, mid, 0.0)[1] >= target {
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

    /// The air-breakdown check over the last accepted step: its stage points (whose gaps are
    /// still in `node_gaps`), refined between the neighbours of one that beats the worst so
    /// far. A step none of whose stage points can beat the worst (a bound over the step,
    /// [`BreakdownWatch::may_beat`](crate::electrical::breakdown::BreakdownWatch::may_beat))
    /// is passed over: observing its points would change nothing.
    pub(super) fn watch_step<W: GapWaveform + ?Sized>(&mut self, wave: &W) -> Result<(), ElectricalError> {
        let (Some(step), Some(watch)) = (self.last_step.as_ref(), self.breakdown.as_ref()) else {
            return Ok(());
        };
        let n = self.gaps.len();
        let c: &[f64] = if step.stages == RESISTOR_STAGES {
            &self.tab_resistor.c
        } else {
            &self.tab_rectifier.c
        };
        let node = |i: usize| step.t0 + c[i] * step.h;
        if node(step.stages - 1) < watch.from() {
            return Ok(());
        }
        let mut charges = [0.0; MAX_STAGES];
        for (i, q) in charges[..step.stages].iter_mut().enumerate() {
            *q = step.y0[0] + step.z[0][i] + step.qeq0 + step.dq[i];
        }
        if !watch.may_beat(&charges[..step.stages], &self.node_gaps[..step.stages * n]) {
            return Ok(());
        }
        let step = *step;
        let Some(mut watch) = self.breakdown.take() else {
            return Ok(());
        };
        let c: &[f64] = if step.stages == RESISTOR_STAGES {
            &self.tab_resistor.c
        } else {
            &self.tab_rectifier.c
        };
        let node = |i: usize| step.t0 + c[i] * step.h;
        let mut best = None;
        for i in 0..step.stages {
            let q = step.y0[0] + step.z[0][i] + step.qeq0 + step.dq[i];
            if watch.observe(node(i), q, &self.node_gaps[i * n..(i + 1) * n]) {
                best = Some(i);
            }
        }
        let mut result = Ok(());
        if let Some(i) = best {
            let a = if i == 0 { step.t0 } else { node(i - 1) };
            let b = if i + 1 < step.stages { node(i + 1) } else { node(i) };
            watch.refine(a, b, |t, gaps| match self.eval(t, wave) {
                Ok(ts) => {
                    gaps.copy_from_slice(&self.gaps[..gaps.len()]);
                    let y = self.dense_state(&step, t, ts.equilibrium_charge);
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
    pub(super) fn watch_piece<W: GapWaveform + ?Sized>(
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

    /// Whether a grid (samples, V–Q cycle) has a time up to `tb` to take or skip.
    #[inline]
    fn grids_due(&self, tb: f64) -> bool {
        self.sampler.as_ref().is_some_and(|g| g.due(tb)) || self.vq.as_ref().is_some_and(|g| g.due(tb))
    }

    /// Samples grid times inside `[ta, tb]`: from a step's polynomial, or (open, short, or
    /// the first instant) from the current state.
    pub(super) fn sample_between<W: GapWaveform + ?Sized>(
        &mut self,
        ta: f64,
        tb: f64,
        wave: &W,
        step: Option<&Step>,
    ) -> Result<(), ElectricalError> {
        if !self.grids_due(tb) {
            return Ok(());
        }
        let rectifier = matches!(self.load, LoadModel::Rectifier(_));
        for which in 0..2 {
            let due = match which {
                0 => &self.sampler,
                _ => &self.vq,
            };
            if !due.as_ref().is_some_and(|g| g.due(tb)) {
                continue;
            }
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

impl ChargeSolver {
    /// The charges at the probe times up to `tb` (s) that are still open: from `step`'s
    /// collocation polynomial (`tb` its end), or with no step (open and short circuit, whose
    /// charge follows the gaps algebraically) from the state at each time. A probe at `tb`
    /// takes the state reached there.
    pub(super) fn fill_probes<W: GapWaveform + ?Sized>(
        &mut self,
        tb: f64,
        wave: &W,
        step: Option<&Step>,
    ) -> Result<(), ElectricalError> {
        while self.probes.next < self.probes.len && self.probes.times[self.probes.next] <= tb {
            let t = self.probes.times[self.probes.next];
            let q = if t == tb {
                self.charge()
            } else {
                let ts = self.eval_value(t, wave)?;
                let y = match step {
                    Some(s) => self.dense_state(s, t, ts.equilibrium_charge),
                    None => self.y,
                };
                self.row(ts, y, 0.0).charge
            };
            self.probes.values[self.probes.next] = q;
            self.probes.next += 1;
        }
        Ok(())
    }
}

/// [`ChargeSolver::dense`] with the tableau of the step's method (the energy only if `ENERGY`,
/// else `step.e0`).
pub(super) fn dense_with<const S: usize, const ENERGY: bool>(
    tab: &Tableau<S>,
    step: &Step,
    t: f64,
    qeq: f64,
) -> ([f64; 2], f64) {
    debug_assert_eq!(step.stages, S);
    let w = tab.dense_weights((t - step.t0) / step.h);
    let mut y = step.y0;
    let mut e = step.e0;
    for (i, wi) in w.iter().enumerate() {
        y[0] += wi * step.z[0][i];
        y[1] += wi * step.z[1][i];
        if ENERGY {
            // The energy's stage increment ZEᵢ = h Σⱼ aᵢⱼ pⱼ.
            e += wi * step.h * (0..S).map(|j| tab.a[i][j] * step.power[j]).sum::<f64>();
        }
    }
    if !step.stiff {
        let interp: f64 = w.iter().zip(&step.dq).map(|(wi, dqi)| wi * dqi).sum();
        y[0] += interp - (qeq - step.qeq0);
    }
    (y, e)
}
