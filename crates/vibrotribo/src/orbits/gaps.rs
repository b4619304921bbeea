//! The smallest gap an orbit leaves open: the lowest smooth local minimum of the gaps
//! `d_k(t)` between events. It tends to zero at a grazing approached from the side without
//! the new impact (on the other side the closing speed of that impact tends to zero).

use nalgebra::DVector;

use crate::dynamics::{Simulator, Trajectory};
use crate::model::{ChainParams, SimOptions};
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
    let contacts = trajectory.gap_count();
    let (mut gaps, mut rates) = (vec![0.0; contacts], vec![0.0; contacts]);
    let dt = params.period() / SAMPLES;
    let mut best: Option<(usize, f64)> = None;
    for segment in trajectory.segments() {
        let flow = trajectory.flow_at(0.5 * (segment.t_start + segment.t_end))?;
        let steps = ((segment.t_end - segment.t_start) / dt).ceil().max(1.0) as usize;
        let h = (segment.t_end - segment.t_start) / steps as f64;
        let mut before = vec![0.0; contacts];
        for j in 0..=steps {
            let t = segment.t_start + j as f64 * h;
            flow.gaps_at(t, &mut gaps, &mut rates);
            if j > 0 {
                for k in 0..contacts {
                    if before[k] < 0.0 && rates[k] > 0.0 {
                        // A smooth minimum of gap k in (t − h, t): bisect on its rate.
                        let (mut lo, mut hi) = (t - h, t);
                        for _ in 0..BISECTIONS {
                            let mid = 0.5 * (lo + hi);
                            flow.gaps_at(mid, &mut gaps, &mut rates);
                            if rates[k] < 0.0 { lo = mid } else { hi = mid }
                        }
                        flow.gaps_at(0.5 * (lo + hi), &mut gaps, &mut rates);
                        if best.is_none_or(|b| gaps[k] < b.1) {
                            best = Some((k, gaps[k]));
                        }
                        flow.gaps_at(t, &mut gaps, &mut rates);
                    }
                }
            }
            before.copy_from_slice(&rates);
        }
    }
    best
}
