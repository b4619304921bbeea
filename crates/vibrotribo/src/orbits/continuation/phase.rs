//! The section a branch is represented on.
//!
//! The stroboscopic map on t ≡ θ (mod T) jumps where an impact of the orbit crosses the
//! section (the orbit changes continuously, but its state at θ is taken before or after the
//! impact's velocity reset), and is strongly non-linear near it. A branch is therefore
//! followed on a section θ kept away from the orbit's events: when an event comes within
//! [`CLEARANCE`] periods of it, the section moves to the middle of the longest event-free
//! stretch of the orbit, and the point is carried there along the flow (the multipliers do
//! not depend on θ: the monodromy matrices of two sections are similar). Points are always
//! reported at t ≡ 0 (mod PT).

use nalgebra::{DMatrix, DVector};

use super::corrector::Problem;
use super::locate::StepPoint;
use crate::dynamics::{Event, Simulator};
use crate::model::ChainParams;
use crate::orbits::shooting::newton;
use crate::sensitivity::{Sensitivity, SensitivityError, state_from_vector, state_vector};

/// An event closer than this fraction of the excitation period to the section moves it.
pub(crate) const CLEARANCE: f64 = 0.02;

/// Offsets of the events after the section θ, in [0, PT), s.
fn offsets(events: &[Event], phase: f64, duration: f64) -> Vec<f64> {
    events
        .iter()
        .map(|e| (e.time - phase).rem_euclid(duration))
        .collect()
}

/// Whether an event of the orbit lies within [`CLEARANCE`] periods of its section.
pub(crate) fn too_close<F: Fn(f64) -> ChainParams>(problem: &Problem<'_, F>, point: &StepPoint) -> bool {
    let period = (problem.family)(point.described.point.parameter).period();
    let duration = f64::from(problem.period) * period;
    offsets(&point.ev.eval.events, problem.phase, duration)
        .iter()
        .any(|&o| o.min(duration - o) < CLEARANCE * period)
}

/// The point carried to the section in the middle of the orbit's longest event-free stretch:
/// the new phase, the point there (polished by Newton's method) and its tangent, oriented
/// like `tangent` carried along the flow.
pub(crate) fn move_section<F: Fn(f64) -> ChainParams>(
    problem: &Problem<'_, F>,
    point: &StepPoint,
    tangent: &DVector<f64>,
) -> Option<(f64, StepPoint, DVector<f64>)> {
    let p = point.described.point.parameter;
    let params = (problem.family)(p);
    let duration = problem.duration(&params);
    let mut o = offsets(&point.ev.eval.events, problem.phase, duration);
    o.sort_by(f64::total_cmp);
    let (first, last) = (*o.first()?, *o.last()?);
    // The longest stretch between consecutive events, cyclically.
    let (mut start, mut length) = (last, first + duration - last);
    for w in o.windows(2) {
        if w[1] - w[0] > length {
            (start, length) = (w[0], w[1] - w[0]);
        }
    }
    let shift = (start + 0.5 * length).rem_euclid(duration);
    // Carry the state and Φ over [θ, θ + shift], and the state at p ± h (below).
    let z = problem.state(&point.ev.u);
    let opts = &problem.options.shooting;
    let carry = |q: f64, stm: &mut Option<Sensitivity>| -> Option<DVector<f64>> {
        let params = (problem.family)(q);
        let start = state_from_vector(z.as_slice());
        let mut sim = Simulator::new_at(&params, problem.phase, &start, opts.sim.clone()).ok()?;
        sim.run_until(problem.phase + shift, stm).ok()?;
        Some(state_vector(&sim.state()))
    };
    let mut stm = Some(Sensitivity::new(&params, opts.sensitivity.clone()));
    let carried = carry(p, &mut stm)?;
    let phi = match stm.as_ref()?.stm() {
        Ok(phi) => phi.clone(),
        Err(SensitivityError::Empty) => DMatrix::identity(z.len(), z.len()),
        Err(_) => return None,
    };
    let phase = (problem.phase + shift).rem_euclid(duration);
    let moved = problem.with_phase(phase);
    let converged = newton(&params, carried, problem.period, phase, opts).ok()?;
    let u = moved.point(&converged.z, p);
    let ev = moved.evaluate(&u).ok()?;
    let described = moved.describe(&ev, point.described.point.arclength)?;
    // The old tangent carried along the flow: dz' = Φ dz + ∂z'/∂p dp (the last by central
    // differences), in scaled units; the parameter part is kept.
    let dim = problem.dim();
    let n = dim / 2;
    let s = |i: usize| problem.scale.of_component(i, n);
    let h = problem.options.parameter_step * p.abs().max(problem.p_scale);
    let dz_dp = (carry(p + h, &mut None)? - carry(p - h, &mut None)?) / (2.0 * h);
    let t_z = DVector::from_fn(dim, |i, _| tangent[i] * s(i));
    let carried_t = &phi * t_z + dz_dp * (tangent[dim] * problem.p_scale);
    let previous = DVector::from_fn(dim + 1, |i, _| {
        if i < dim {
            carried_t[i] / s(i)
        } else {
            tangent[dim]
        }
    });
    let t = moved.tangent(&ev, &previous)?;
    Some((
        phase,
        StepPoint {
            theta: 0.0,
            ev,
            described,
        },
        t,
    ))
}
