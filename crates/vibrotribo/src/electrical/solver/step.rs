//! One smooth piece of waveform integrated by Radau IIA: trial steps for the resistor and
//! the rectifier, error control and the step-size controller, accepting a step.

use super::state::{
    ChargeSolver, ENERGY_FLOOR_STEPS, KINK_SWING, LAYER_MARGIN, Layer, LoadModel, MAX_NEWTON, MAX_STAGES,
    NEWTON_TOL, NOISE, RECTIFIER_STAGES, RectifierLoad, SOLVE_REGROWTH, SWITCH_FLOOR, SWITCH_SWEEP, Step,
    Trial, err_root,
};
use crate::electrical::ElectricalError;
use crate::electrical::radau::{Tableau, solve_fixed, solve_unpivoted};
use crate::electrical::transducer::TransducerState;
use crate::electrical::waveform::GapWaveform;

impl ChargeSolver {
    /// Integrates `[ta, tb]` (smooth) with Radau IIA of `S` stages; `solve` solves the stage
    /// system of one trial step (false if it failed, with `trial.retry` set). `kink`: `ta` is
    /// a kink (a new error history, a boundary layer to cross); false where the piece goes on
    /// from a step that already crossed it (`layer_step`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn integrate<W, const S: usize, F>(
        &mut self,
        tab: &Tableau<S>,
        ta: f64,
        tb: f64,
        mut n0: TransducerState,
        wave: &W,
        kink: bool,
        mut solve: F,
    ) -> Result<(), ElectricalError>
    where
        W: GapWaveform + ?Sized,
        F: FnMut(&mut Self, f64, &TransducerState, &[TransducerState; S], &mut Trial<S>) -> bool,
    {
        let mut t = ta;
        let c = tab.c;
        let mut layer = None;
        if kink {
            // A kink starts a new error history.
            self.have_acc = false;
            layer = self.kink_start(&n0);
            // The last step's polynomial does not extrapolate across a kink.
            self.smooth_since_last_step = false;
        }
        let mut trial = Trial::<S>::new();
        // Step size at which the stage solver last failed.
        let mut solve_cap = f64::INFINITY;
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
                if let Some(m) = self.moments.as_mut() {
                    // The step's collocation quadrature (weights b = the last row of A) of the
                    // charge at its stages.
                    let mut sums = [0.0; 4];
                    for j in 0..S {
                        let d = self.y[0] + trial.z[0][j] + nodes[j].equilibrium_charge - m.q_ref;
                        let tau = times[j] - m.t_ref;
                        let w = tab.a[S - 1][j];
                        sums[0] += w * d;
                        sums[1] += w * d * d;
                        sums[2] += w * tau * d;
                        sums[3] += w * tau * d * d;
                    }
                    for (acc, s) in m.sums.iter_mut().zip(sums) {
                        *acc += h * s;
                    }
                }
                self.accept(t, t1, &trial, nodes[S - 1]);
                self.smooth_since_last_step = true;
                // The next step's size before the step's outputs, which do not touch the
                // controller's state (its chain of roots then overlaps their work).
                let hnew = self.controller::<S>(h, err, true);
                self.record(wave)?;
                self.h = if clipped {
                    // A step shortened to meet the interval end says little about the next:
                    // it grows back to the step proposed before at most as its error allows,
                    // and at once where its error is at the floor (no error signal at all: a
                    // piece a few ulps long, such as coupled windows ending next to an event,
                    // left the next piece to start from a step of a few ulps, which failed as
                    // an underflow).
                    let back = if err <= 1e-10 {
                        h_prop
                    } else {
                        (h * 0.9 / err_root::<S>(err)).min(h_prop)
                    };
                    back.max(hnew)
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
                    let x = mean_el * h * l.conductance;
                    l.decayed += x;
                    // Inside the layer the error follows the layer's amplitude, which the step
                    // just cut by e^(−x): grow the step so that the next error is predicted
                    // at half the tolerance (error ∝ h^(S+1), as the controller assumes).
                    let grow = (0.5 / (err.max(1e-10) * (-x).exp())).powf(1.0 / (S as f64 + 1.0));
                    if grow.is_finite() {
                        self.h = self.h.max(h * grow.min(5.0));
                    }
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
                // (Not after a layer carried in closed form: `kink` is false then.)
                let layer_possible = (kink && t == ta) || matches!(self.load, LoadModel::Rectifier(_));
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
    pub(super) fn kink_start(&mut self, n0: &TransducerState) -> Option<Layer> {
        let conductance = match self.load {
            LoadModel::Resistor { conductance } => conductance,
            LoadModel::Rectifier(RectifierLoad { diode, .. }) => {
                // The bridge switches as the voltage sweeps a few n·V_T: start there.
                let v0 = -self.y[0] * n0.elastance;
                let b = diode.bridge(v0, self.y[1]);
                let sweep = (n0.elastance * (n0.equilibrium_current - b.current)).abs();
                let h_switch = KINK_SWING * diode.thermal_scale() / sweep;
                // Far into conduction the bridge is ohmic (two series resistances): its current
                // then changes on the time scale 2R_s·C, however fast the voltage sweeps. (A
                // start away from equilibrium puts kilovolts across the bridge, where the sweep
                // rule alone asked for steps below the rounding of t and stopped the run.)
                let h_ohmic = 2.0 * diode.series_resistance() / n0.elastance;
                let h_first = h_switch.max(h_ohmic);
                if h_first > 0.0 {
                    self.h = self.h.min(h_first);
                }
                return None;
            }
            _ => return None,
        };
        let k0 = conductance * n0.elastance;
        if self.h * k0 <= 2.0 {
            return None;
        }
        let needed = self.layer_decay_needed(conductance, n0)?;
        let h_smooth = self.h;
        self.h = 2.0 / k0;
        Some(Layer {
            conductance,
            decayed: 0.0,
            needed,
            h_smooth,
        })
    }

    /// Resistor: the decay `∫k dt` after which the boundary layer at `n0` (the charge's offset
    /// from its quasi-static value `u ≈ −I_sc/k`, as a voltage) is below the voltage tolerance,
    /// with `LAYER_MARGIN`; `None` if it is below the tolerance already (no layer).
    pub(super) fn layer_decay_needed(&self, conductance: f64, n0: &TransducerState) -> Option<f64> {
        let k0 = conductance * n0.elastance;
        let jump = ((self.y[0] + n0.equilibrium_current / k0) * n0.elastance).abs();
        let tol = self.options.rtol * (self.y[0] * n0.elastance).abs() + self.atol();
        if jump.is_nan() || jump <= tol {
            return None;
        }
        Some((jump / tol).ln() + LAYER_MARGIN)
    }

    /// Step-size controller of RADAU5 (with Gustafsson's predictive variant): the next step
    /// after a step of `h` with scaled error `err`.
    pub(super) fn controller<const S: usize>(&mut self, h: f64, err: f64, accepted: bool) -> f64 {
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
    pub(super) fn trial_resistor<const S: usize>(
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
        let (mut m, mut z) = tab.stage_system(&hk, |i, row_sum| -dq[i] - row_sum * u0);
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
        // The load is the resistor: what leaves the terminals is what it dissipates.
        trial.terminal_energy = trial.energy;
        trial.err = err_v.max(err_e);
    }

    /// Rectifier: Radau IIA on `Q' = I(V, V_s)`, `C_s V_s' = I_out − V_s/R_L`, with the stages
    /// of Q written as `u = Q − Q_eq` (exact `ΔQ_eq` as for the resistor); Newton's method on
    /// the 2S × 2S stage system with the exact Jacobian at every stage. False if Newton fails.
    pub(super) fn trial_rectifier(
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
        let mut terminal = 0.0;
        for j in 0..S {
            let yj = [y0[0] + z[0][j], y0[1] + z[1][j]];
            let (_, _, v, b) = f(yj, &nodes[j]);
            peak_v = peak_v.max(v.abs());
            peak_i = peak_i.max(b.current.abs());
            scale_v = scale_v.max(yj[1].abs());
            trial.power[j] = yj[1] * b.output;
            // The power leaving the transducer's terminals: V·I, I = dQ/dt the bridge's input.
            terminal += tab.a[S - 1][j] * v * b.current;
            v1 = v;
        }
        trial.terminal_energy = h * terminal;
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
    pub(super) fn qeq_noise_scale<const S: usize>(&self, n0: &TransducerState, dq: &[f64; S]) -> f64 {
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
    pub(super) fn energy_error<const S: usize>(
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
    pub(super) fn power_ref(&self) -> Option<f64> {
        let elapsed = self.t - self.t_start;
        if elapsed < 1e-3 * self.period {
            return None;
        }
        let p_ref = (self.energy / elapsed).max(self.last_period_power);
        (p_ref > 0.0).then_some(p_ref)
    }

    /// Commits an accepted step (its polynomial becomes `last_step`).
    pub(super) fn accept<const S: usize>(&mut self, t0: f64, t1: f64, trial: &Trial<S>, n1: TransducerState) {
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
            layer: None,
        });
        self.stats.steps += 1;
        self.t = t1;
        self.ts_now = n1;
        self.y = [self.y[0] + trial.z[0][S - 1], self.y[1] + trial.z[1][S - 1]];
        self.energy += trial.energy;
        self.terminal_energy += trial.terminal_energy;
        if let Some(p) = self.periods.last_mut() {
            p.energy_j += trial.energy;
        }
        self.note_peaks(trial.peak_current, trial.peak_voltage);
        self.v_scale = self.v_scale.max(trial.scale_voltage);
    }
}
