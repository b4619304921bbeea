//! The resistor's boundary layer after a kink, carried in closed form.
//!
//! ## What it replaces
//!
//! After a kink (an impact changes the gaps' velocities, so the short-circuit current jumps)
//! the resistor's charge `u = Q − Q_eq` leaves its slow solution and relaxes back to it as
//! `exp(−∫k dt)`, `k = 1/(RC)`, a layer of width R·C (~0.2–90 µs at 100 kΩ). Resolving it
//! with collocation steps took about 40 % of all accepted Radau steps on the paper's cases
//! (`bench/README.md`, "The boundary layer in closed form").
//!
//! ## Method
//!
//! `u' = −k(t)·u − I_sc(t)` is linear, so `u = w + δ·φ(t)` with `φ = exp(−∫_{t₀}^t k)` and `w`
//! any solution of the same equation. The first step after the kink integrates `w`, started
//! on the slow solution, and carries `δ·φ` exactly:
//!
//! 1. **The slow start `w₀`.** The collocation polynomial of a step (degree S through t₀ and the
//!    S Radau nodes) is asked to satisfy the equation at t₀ as well as at the nodes: S + 1
//!    conditions for the S stage values and `w₀`. For the exact slow solution these hold to
//!    the collocation error; a start off the slow solution by `ε` violates the condition at t₀
//!    by `k₀ε`. This is the same quantity Hairer's embedded estimate measures (`γ₀(h f₀ +
//!    Σ ddᵢ Zᵢ)`, `f₀` the derivative at t₀), so the step is the Radau step from the `w₀`
//!    whose estimate vanishes. So that this estimate is not missed, the step is short: as
//!    long as the layer needs (~30–40 R·C), and resolved far better than the tolerance where
//!    it is at most a third of the step the controller had before the kink (error ∝ h⁸).
//!    Longer layer steps are checked by step doubling instead: `w₀`, the end, and the full
//!    step's polynomial at the stage points of two half steps (its interior has only the
//!    stage order 7, the end order 13) must agree within the voltage tolerance. After the
//!    layer step the next step resumes the step size from before the kink.
//! 2. **The layer `δ·φ`,** `δ = u(t₀) − w₀`, with `∫k` from the interpolant of the stage
//!    elastances (the quadrature of the method's own A matrix at the stages). The step must
//!    be long enough for the layer to decay below the tolerance within it (and to hold the
//!    quadrature nodes below).
//! 3. **The energy** `∫ G e² u² dt` (G = 1/R, e the elastance) splits into the slow part
//!    `∫ G e² w²`, the method's quadrature of the stage powers of `w` as for any step, and the
//!    layer's part `∫ G e² (2wδφ + δ²φ²)`, by Gauss–Laguerre quadrature (10 nodes) in the
//!    scaled time `s = k·(t − t₀)` with `e`, `w` and `∫k` from the step's interpolants. The
//!    two terms have their own scales (φ and φ²), so each integrand is smooth against
//!    Laguerre's weight.
//!
//! Outputs at the stages (the air-breakdown check, peaks) and dense output (samples, the V–Q
//! cycle) add `δ·φ` and the layer's partial energy. Not used for the rectifier (nonlinear),
//! with charge moments (two-way coupling, whose windows are short), or where the piece is too
//! short for the layer (or the step doubling fails): then the layer is crossed with short
//! steps (`ChargeSolver::kink_start`).

use super::layer_term::{LayerTerm, MONO_TERMS, Mono};
use super::state::{ChargeSolver, NOISE, RESISTOR_STAGES, Step, Trial};
use crate::electrical::ElectricalError;
use crate::electrical::radau::{Tableau, solve_unpivoted, solve_unpivoted_many};
use crate::electrical::transducer::TransducerState;
use crate::electrical::waveform::GapWaveform;

/// Smallest `h·k` of a step that carries a layer: the Laguerre nodes of its energy (up to
/// s = 29.9, `layer_term`) then lie inside it.
const MIN_HK: f64 = 32.0;

/// `∫k dt` beyond the layer's own need by which it must have decayed at the step's end
/// (`e^(−2)` of the tolerance, on top of the margin in `layer_decay_needed`).
const DECAY_MARGIN: f64 = 2.0;

/// A layer step at most this fraction of the step the controller had before the kink is not
/// checked by step doubling: its slow part's collocation error is then below
/// `(1/3)^(S+1) = 1.5e-4` of that of a step the estimate accepted.
const UNCHECKED_FRACTION: f64 = 1.0 / 3.0;

// The collocation polynomial (degree S) and its integral fit in a `Mono`.
const _: () = assert!(MONO_TERMS == RESISTOR_STAGES + 2);

/// The monomial coefficients (in θ) of the collocation polynomial through `(0, y0)` and
/// `(cᵢ, y[i])`: `y0 + Σᵢ ℓᵢ(θ)(y[i] − y0)` with the tableau's basis.
fn interpolant(tab: &Tableau<RESISTOR_STAGES>, y0: f64, y: &[f64; RESISTOR_STAGES]) -> Mono {
    let mut m = [0.0; MONO_TERMS];
    m[0] = y0;
    for (basis, yi) in tab.increment_basis.iter().zip(y) {
        for (mj, bj) in m[1..].iter_mut().zip(basis) {
            *mj += bj * (yi - y0);
        }
    }
    m
}

/// The slow start of one step: `w₀` and the stage increments `zᵢ = wᵢ − w₀`.
struct SlowStart {
    w0: f64,
    z: [f64; RESISTOR_STAGES],
}

impl ChargeSolver {
    /// The stage increments of the resistor's Radau step of length `h` from `u0`:
    /// `(I + hA·diag(k)) z = −ΔQ_eq − (hA k) u₀` (as `trial_resistor`), or `None`.
    fn stage_solve(
        tab: &Tableau<RESISTOR_STAGES>,
        conductance: f64,
        h: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; RESISTOR_STAGES],
        u0: f64,
    ) -> Option<[f64; RESISTOR_STAGES]> {
        let hk = std::array::from_fn(|j| h * conductance * nodes[j].elastance);
        let (mut m, mut z) = tab.stage_system(&hk, |i, row_sum| {
            -(nodes[i].equilibrium_charge - n0.equilibrium_charge) - row_sum * u0
        });
        solve_unpivoted(&mut m, &mut z).then_some(z)
    }

    /// The Radau step from the `w₀` whose embedded estimate vanishes (module docs, 1.), or
    /// `None` if its stage system cannot be solved.
    fn slow_start(
        tab: &Tableau<RESISTOR_STAGES>,
        conductance: f64,
        h: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; RESISTOR_STAGES],
    ) -> Option<SlowStart> {
        const S: usize = RESISTOR_STAGES;
        let hk: [f64; S] = std::array::from_fn(|j| h * conductance * nodes[j].elastance);
        let dq: [f64; S] = std::array::from_fn(|j| nodes[j].equilibrium_charge - n0.equilibrium_charge);
        // (I + hA·diag(k)) z = −ΔQ_eq − (hA k) w₀: z = z_a + w₀ z_b.
        let (mut m, zb) = tab.stage_system(&hk, |_, row_sum| -row_sum);
        let mut z = [std::array::from_fn(|i| -dq[i]), zb];
        if !solve_unpivoted_many(&mut m, &mut z) {
            return None;
        }
        let [za, zb] = z;
        // The estimate's condition h f₀ + Σ ddᵢ (zᵢ + ΔQ_eq,ᵢ) = 0 with f₀ = −k₀ w₀.
        let k0h = h * conductance * n0.elastance;
        let mut num = 0.0;
        let mut den = -k0h;
        for i in 0..S {
            num += tab.dd[i] * (za[i] + dq[i]);
            den += tab.dd[i] * zb[i];
        }
        let w0 = -num / den;
        if !w0.is_finite() {
            return None;
        }
        Some(SlowStart {
            w0,
            z: std::array::from_fn(|i| za[i] + w0 * zb[i]),
        })
    }

    /// Crosses the boundary layer at the start of a resistor piece `[ta, tb]` in one step
    /// (module docs) if there is one and the piece can hold it. Returns the time and
    /// transducer state the piece continues from, or `None` (nothing done: the piece starts as
    /// before, crossing the layer with short steps).
    ///
    /// The step is as short as the layer allows (`h·k₀ ≥ 32` and the layer decayed below the
    /// tolerance at its end), so that the slow part is smooth over it; the next step resumes
    /// the step the controller had before the kink, as after a layer crossed with short steps.
    /// Where the layer step is not at least 3× shorter than that step (so that its slow part is
    /// not resolved far better than the tolerance already), it is checked by step doubling.
    pub(super) fn layer_step<W: GapWaveform + ?Sized>(
        &mut self,
        tab: &Tableau<RESISTOR_STAGES>,
        conductance: f64,
        ta: f64,
        tb: f64,
        n0: TransducerState,
        wave: &W,
    ) -> Result<Option<(f64, TransducerState)>, ElectricalError> {
        const S: usize = RESISTOR_STAGES;
        if !self.options.analytic_layers || self.moments.is_some() {
            return Ok(None);
        }
        let Some(layer_need) = self.layer_decay_needed(conductance, &n0) else {
            return Ok(None);
        };
        let needed = layer_need + DECAY_MARGIN;
        let u0 = self.y[0];
        let e0 = n0.elastance;
        let k0 = conductance * e0;
        let h_smooth = self.h;
        let mut h_len: f64 = MIN_HK.max(1.1 * needed) / k0;
        let c = tab.c;
        for _ in 0..4 {
            if h_len >= tb - ta {
                h_len = tb - ta;
            }
            if h_len * k0 < MIN_HK {
                return Ok(None);
            }
            let t1 = if h_len == tb - ta { tb } else { ta + h_len };
            let h = t1 - ta;
            let doubling = h > UNCHECKED_FRACTION * h_smooth;
            // With doubling, the half steps first: the full step's node gaps must be the last
            // evaluated (the breakdown check reads them).
            let halves = if doubling {
                let half = 0.5 * h;
                let times_half: [f64; S] = std::array::from_fn(|i| ta + c[i] * half);
                let nodes_half = self.eval_nodes(&times_half, wave)?;
                let Some(first) = Self::slow_start(tab, conductance, half, &n0, &nodes_half) else {
                    return Ok(None);
                };
                let w_half = first.w0 + first.z[S - 1];
                let mid = times_half[S - 1];
                let times_second: [f64; S] =
                    std::array::from_fn(|i| if i + 1 == S { t1 } else { mid + c[i] * half });
                let nodes_second = self.eval_nodes(&times_second, wave)?;
                let Some(second) = Self::stage_solve(
                    tab,
                    conductance,
                    t1 - mid,
                    &nodes_half[S - 1],
                    &nodes_second,
                    w_half,
                ) else {
                    return Ok(None);
                };
                Some((first, nodes_half, w_half, second, nodes_second))
            } else {
                None
            };
            let times: [f64; S] = std::array::from_fn(|i| if i + 1 == S { t1 } else { ta + c[i] * h });
            let nodes = self.eval_nodes(&times, wave)?;
            let Some(slow) = Self::slow_start(tab, conductance, h, &n0, &nodes) else {
                return Ok(None);
            };
            // The layer must have decayed within the step (k may fall along it).
            let decay_end =
                h * conductance * (0..S).map(|j| tab.a[S - 1][j] * nodes[j].elastance).sum::<f64>();
            if decay_end < needed {
                if t1 == tb {
                    return Ok(None);
                }
                h_len *= 2.0 * needed / decay_end.max(f64::MIN_POSITIVE);
                continue;
            }
            let w0 = slow.w0;
            let dq: [f64; S] = std::array::from_fn(|j| nodes[j].equilibrium_charge - n0.equilibrium_charge);
            let noise = NOISE * (self.qeq_noise_scale(&n0, &dq) + w0.abs()) * e0;
            let scale_at = |w: f64, e: f64| self.options.rtol * (w * e).abs() + self.atol() + noise * e / e0;
            let mut err_w: f64 = 0.0;
            if let Some((first, nodes_half, w_half, second, nodes_second)) = &halves {
                // Step doubling: the slow start, the end, and the full step's polynomial at the
                // half steps' stage points (its interior has only the stage order S).
                let e1 = nodes[S - 1].elastance;
                let w1 = w0 + slow.z[S - 1];
                err_w = err_w
                    .max(((w0 - first.w0) * e0).abs() / scale_at(w0, e0))
                    .max(((w1 - w_half - second[S - 1]) * e1).abs() / scale_at(w1, e1));
                for (theta0, start, z, at) in [
                    (0.0, first.w0, &first.z, nodes_half),
                    (0.5, *w_half, second, nodes_second),
                ] {
                    for i in 0..S {
                        let dense = tab.dense_weights(theta0 + 0.5 * c[i]);
                        let full_at = w0 + dense.iter().zip(&slow.z).map(|(l, z)| l * z).sum::<f64>();
                        let half_at = start + z[i];
                        let e = at[i].elastance;
                        err_w = err_w.max(((full_at - half_at) * e).abs() / scale_at(half_at, e));
                    }
                }
            }
            let mut trial = Trial::<S>::new();
            let layer = self.fill_layer_trial(tab, conductance, h, u0, &n0, &nodes, &slow, &mut trial);
            let p0_w = conductance * (w0 * e0).powi(2);
            let p_noise = conductance * noise * (2.0 * trial.peak_voltage + noise);
            let err_e = self.energy_error(tab, h, p0_w, &mut trial, p_noise, (0.0, 0.0));
            trial.energy += layer.energy;
            trial.terminal_energy = trial.energy;
            self.steps_in_period += 1;
            if !(err_w <= 1.0 && err_e <= 1.0 && layer.energy.is_finite()) {
                // Shorter would not hold the layer: cross it with short steps.
                self.stats.rejected += 1;
                return Ok(None);
            }
            self.have_acc = false;
            self.accept(ta, t1, &trial, nodes[S - 1]);
            if let Some(step) = self.last_step.as_mut() {
                step.layer = Some(layer);
            }
            self.smooth_since_last_step = true;
            self.record(wave)?;
            self.h = h_smooth.max(h);
            return Ok(Some((t1, nodes[S - 1])));
        }
        Ok(None)
    }

    /// The trial of a layer step: true stage increments (slow part plus layer), the slow
    /// part's stage powers (its energy by the method's quadrature), peaks; returns the layer.
    #[allow(clippy::too_many_arguments)]
    fn fill_layer_trial(
        &self,
        tab: &Tableau<RESISTOR_STAGES>,
        conductance: f64,
        h: f64,
        u0: f64,
        n0: &TransducerState,
        nodes: &[TransducerState; RESISTOR_STAGES],
        slow: &SlowStart,
        trial: &mut Trial<RESISTOR_STAGES>,
    ) -> LayerTerm {
        const S: usize = RESISTOR_STAGES;
        let delta = u0 - slow.w0;
        let e: [f64; S] = std::array::from_fn(|j| nodes[j].elastance);
        let w: [f64; S] = std::array::from_fn(|j| slow.w0 + slow.z[j]);
        let layer = LayerTerm::new(
            delta,
            conductance,
            h,
            interpolant(tab, n0.elastance, &e),
            interpolant(tab, slow.w0, &w),
        );
        let v0 = -u0 * n0.elastance;
        let mut v_max = v0.abs();
        for (j, node) in nodes.iter().enumerate() {
            let phi = layer.phi(tab.c[j]);
            let u = slow.w0 + slow.z[j] + delta * phi;
            trial.z[0][j] = u - u0;
            let vw = -(slow.w0 + slow.z[j]) * node.elastance;
            trial.power[j] = vw * vw * conductance;
            v_max = v_max.max((u * node.elastance).abs());
            trial.dq[j] = node.equilibrium_charge - n0.equilibrium_charge;
        }
        trial.qeq0 = n0.equilibrium_charge;
        trial.peak_voltage = v_max;
        trial.peak_current = v_max * conductance;
        trial.scale_voltage = v_max;
        trial.stiff = true;
        trial.hk = h * conductance * n0.elastance;
        trial.err = 0.0;
        layer
    }
}

/// Dense output of a layer step at `t` (module docs): the slow part from its collocation
/// polynomial (`step.z` holds the true stage increments, slow part plus layer) plus `δ·φ`; the
/// energy from the slow part's stage powers plus the layer's energy so far.
/// (The energy only if `ENERGY`, else `step.e0`.)
pub(super) fn dense_layer<const ENERGY: bool>(
    tab: &Tableau<RESISTOR_STAGES>,
    step: &Step,
    layer: &LayerTerm,
    t: f64,
) -> ([f64; 2], f64) {
    const S: usize = RESISTOR_STAGES;
    let theta = (t - step.t0) / step.h;
    let wts = tab.dense_weights(theta);
    let w0 = step.y0[0] - layer.delta;
    let mut u = w0;
    let mut e = step.e0;
    for (i, wi) in wts.iter().enumerate() {
        // Slow increment = true increment − δ(φᵢ − 1). (Not the monomial interpolant `slow`:
        // the product form of the weights is exact to rounding, the monomial one to ~1e-11.)
        let zi = step.z[0][i] - layer.delta * (layer.phi(tab.c[i]) - 1.0);
        u += wi * zi;
        if ENERGY {
            e += wi * step.h * (0..S).map(|j| tab.a[i][j] * step.power[j]).sum::<f64>();
        }
    }
    u += layer.delta * layer.phi(theta);
    if ENERGY {
        e += layer.energy_until(theta);
    }
    ([u, step.y0[1]], e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolant_reproduces_a_polynomial_of_degree_seven() {
        let tab = Tableau::<RESISTOR_STAGES>::new();
        let p = [0.3, -1.2, 2.5, 0.7, -3.1, 1.9, 0.4, -0.8];
        let eval = |t: f64| p.iter().rev().fold(0.0, |acc, c| acc * t + c);
        let y: [f64; RESISTOR_STAGES] = std::array::from_fn(|i| eval(tab.c[i]));
        let m = interpolant(&tab, eval(0.0), &y);
        for (j, (a, b)) in m.iter().zip(&p).enumerate() {
            assert!((a - b).abs() < 1e-9, "coefficient {j}: {a} against {b}");
        }
        assert_eq!(m[RESISTOR_STAGES + 1], 0.0);
    }
}
