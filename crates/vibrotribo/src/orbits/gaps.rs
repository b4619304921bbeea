//! The smallest gap an orbit leaves open: the lowest smooth local minimum of the gaps
//! `d_k(t)` between events. It tends to zero at a grazing approached from the side without
//! the new impact (on the other side the closing speed of that impact tends to zero). The
//! gaps of rigid stops count too (contacts N − 1 and N), except while a cluster is stuck
//! to the stop.

use nalgebra::{DMatrix, DVector};

use crate::dynamics::{Flow, Simulator, Trajectory};
use crate::model::{ChainParams, SimOptions, StopFrame, StopSide};
use crate::sensitivity::{Sensitivity, SensitivityError, SensitivityOptions, state_from_vector};

/// Samples per excitation period at which the gap rates are checked for a sign change.
const SAMPLES: f64 = 1024.0;

/// Bisection steps on the gap rate.
const BISECTIONS: usize = 60;

/// The lowest smooth local minimum of a gap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct GapMinimum {
    /// Contact, 0-based.
    pub contact: usize,
    /// The gap there, m.
    pub gap: f64,
    /// When, s.
    pub time: f64,
}

/// The lowest smooth local minimum of the gaps over `periods` excitation periods from `z` at
/// t = `phase`, or `None` if no gap has one.
pub(crate) fn smallest_gap_minimum(
    params: &ChainParams,
    z: &DVector<f64>,
    periods: u32,
    phase: f64,
    sim: &SimOptions,
) -> Option<GapMinimum> {
    gap_minima(params, z, periods, phase, sim)
        .into_iter()
        .min_by(|a, b| a.gap.total_cmp(&b.gap))
}

/// Every smooth local minimum of the gaps over `periods` excitation periods from `z` at
/// t = `phase`, in time order.
pub(crate) fn gap_minima(
    params: &ChainParams,
    z: &DVector<f64>,
    periods: u32,
    phase: f64,
    sim: &SimOptions,
) -> Vec<GapMinimum> {
    let mut out = Vec::new();
    let _ = collect_minima(params, z, periods, phase, sim, &mut out);
    out
}

fn collect_minima(
    params: &ChainParams,
    z: &DVector<f64>,
    periods: u32,
    phase: f64,
    sim: &SimOptions,
    out: &mut Vec<GapMinimum>,
) -> Option<()> {
    let mut simulator =
        Simulator::new_at(params, phase, &state_from_vector(z.as_slice()), sim.clone()).ok()?;
    let mut trajectory = Trajectory::new(&simulator);
    simulator
        .run_until(phase + f64::from(periods) * params.period(), &mut trajectory)
        .ok()?;
    let contacts = params.contact_count().max(trajectory.gap_count());
    let (mut gaps, mut rates) = (vec![0.0; contacts], vec![0.0; contacts]);
    let mut state = (vec![0.0; params.len()], vec![0.0; params.len()]);
    let dt = params.period() / SAMPLES;
    for segment in trajectory.segments() {
        let flow = trajectory.flow_at(0.5 * (segment.t_start + segment.t_end))?;
        let steps = ((segment.t_end - segment.t_start) / dt).ceil().max(1.0) as usize;
        let h = (segment.t_end - segment.t_start) / steps as f64;
        let mut before = vec![0.0; contacts];
        for j in 0..=steps {
            let t = segment.t_start + j as f64 * h;
            all_gaps(params, &flow, t, &mut gaps, &mut rates, &mut state);
            if j > 0 {
                for k in 0..contacts {
                    if before[k] < 0.0 && rates[k] > 0.0 {
                        // A smooth minimum of gap k in (t − h, t): bisect on its rate.
                        let (mut lo, mut hi) = (t - h, t);
                        for _ in 0..BISECTIONS {
                            let mid = 0.5 * (lo + hi);
                            all_gaps(params, &flow, mid, &mut gaps, &mut rates, &mut state);
                            if rates[k] < 0.0 { lo = mid } else { hi = mid }
                        }
                        let time = 0.5 * (lo + hi);
                        all_gaps(params, &flow, time, &mut gaps, &mut rates, &mut state);
                        out.push(GapMinimum {
                            contact: k,
                            gap: gaps[k],
                            time,
                        });
                        all_gaps(params, &flow, t, &mut gaps, &mut rates, &mut state);
                    }
                }
            }
            before.copy_from_slice(&rates);
        }
    }
    Some(())
}

/// The gradient `∂d_k(t)/∂z` of the gap of `contact` at time `t` (on the flow from `z` at
/// t = `phase`, before any event at `t` itself) with respect to the section state `z`: the
/// gap's gradient in the state at `t` (a difference of positions, or one position against a
/// stop) times the state-transition matrix Φ(t, phase). `None` where the flow is not
/// differentiable on the way.
pub(crate) fn gap_gradient(
    params: &ChainParams,
    z: &DVector<f64>,
    phase: f64,
    contact: usize,
    t: f64,
    sim: &SimOptions,
    sensitivity: &SensitivityOptions,
) -> Option<DVector<f64>> {
    let n = params.len();
    let dim = 2 * n;
    let mut simulator =
        Simulator::new_at(params, phase, &state_from_vector(z.as_slice()), sim.clone()).ok()?;
    let mut stm = Sensitivity::new(params, sensitivity.clone());
    simulator.run_until(t, &mut stm).ok()?;
    let phi = match stm.stm() {
        Ok(phi) => phi.clone(),
        Err(SensitivityError::Empty) => DMatrix::identity(dim, dim),
        Err(_) => return None,
    };
    // d_k = δ_k − (x_{k+1} − x_k) between masses; the lower stop's gap grows with x_N, the
    // upper stop's falls with x_1.
    let mut grad = DVector::zeros(dim);
    match contact {
        k if k + 1 < n => {
            grad[k] = 1.0;
            grad[k + 1] = -1.0;
        }
        k if k + 1 == n => grad[n - 1] = 1.0,
        _ => grad[0] = -1.0,
    }
    Some(phi.transpose() * grad)
}

/// Gaps and their rates at time `t` of every contact: between masses from the flow, and of
/// each stop from the state (`state`: scratch positions and velocities). A stop the chain
/// lacks, or one a cluster is stuck to, gets gap ∞ and rate 0 (never a minimum).
fn all_gaps(
    params: &ChainParams,
    flow: &Flow<'_>,
    t: f64,
    gaps: &mut [f64],
    rates: &mut [f64],
    state: &mut (Vec<f64>, Vec<f64>),
) {
    let n = params.len();
    let between = n - 1;
    flow.gaps_at(t, &mut gaps[..between], &mut rates[..between]);
    if gaps.len() == between {
        return;
    }
    let (x, v) = (&mut state.0, &mut state.1);
    flow.state_at(t, x, v);
    let (sin, cos) = (params.omega() * t.rem_euclid(params.period())).sin_cos();
    let a = params.excitation.amplitude;
    for k in between..gaps.len() {
        let side = if k == between {
            StopSide::Lower
        } else {
            StopSide::Upper
        };
        let stuck = flow.clusters().iter().any(|c| c.stop == Some(side));
        let Some(stop) = params.stops.get(side).filter(|_| !stuck) else {
            gaps[k] = f64::INFINITY;
            rates[k] = 0.0;
            continue;
        };
        let (y, yd) = match stop.frame {
            StopFrame::Fixed => (0.0, 0.0),
            StopFrame::Base => (a * sin, a * params.omega() * cos),
        };
        (gaps[k], rates[k]) = match side {
            StopSide::Upper => (stop.gap - (x[0] - y), yd - v[0]),
            StopSide::Lower => (stop.gap - (y - x[n - 1]), v[n - 1] - yd),
        };
    }
}
