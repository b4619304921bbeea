//! The smallest gap an orbit leaves open: the lowest smooth local minimum of the gaps
//! `d_k(t)` between events. It tends to zero at a grazing approached from the side without
//! the new impact (on the other side the closing speed of that impact tends to zero). The
//! gaps of rigid stops count too (contacts N − 1 and N), except while a cluster is stuck
//! to the stop.

use nalgebra::DVector;

use crate::dynamics::{Flow, Simulator, Trajectory};
use crate::model::{ChainParams, SimOptions, StopFrame, StopSide};
use crate::sensitivity::state_from_vector;

/// Samples per excitation period at which the gap rates are checked for a sign change.
const SAMPLES: f64 = 1024.0;

/// Bisection steps on the gap rate.
const BISECTIONS: usize = 60;

/// The lowest smooth local minimum of the gaps over `periods` excitation periods from `z` at
/// t = `phase`: `(contact, gap in m)`, or `None` if no gap has one.
pub(crate) fn smallest_gap_minimum(
    params: &ChainParams,
    z: &DVector<f64>,
    periods: u32,
    phase: f64,
    sim: &SimOptions,
) -> Option<(usize, f64)> {
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
    let mut best: Option<(usize, f64)> = None;
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
                        all_gaps(params, &flow, 0.5 * (lo + hi), &mut gaps, &mut rates, &mut state);
                        if best.is_none_or(|b| gaps[k] < b.1) {
                            best = Some((k, gaps[k]));
                        }
                        all_gaps(params, &flow, t, &mut gaps, &mut rates, &mut state);
                    }
                }
            }
            before.copy_from_slice(&rates);
        }
    }
    best
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
