//! Finite differences of the exact flow map against its state-transition matrix (shared by
//! the sensitivity tests with and without rigid stops).

use nalgebra::{DMatrix, DVector};
use vibrotribo::sensitivity::{Horizon, length_scale, speed_scale, state_from_vector, state_vector};
use vibrotribo::{ChainParams, ChainState, Event, EventKind, EventLog, SimOptions, Simulator};

/// End state and events of a plain run (no sensitivities): the map differentiated.
pub fn run(params: &ChainParams, z: &DVector<f64>, horizon: Horizon) -> Option<(DVector<f64>, Vec<Event>)> {
    run_with(params, z, horizon, &SimOptions::default())
}

pub fn run_with(
    params: &ChainParams,
    z: &DVector<f64>,
    horizon: Horizon,
    options: &SimOptions,
) -> Option<(DVector<f64>, Vec<Event>)> {
    run_prepared(params, z, horizon, options, &|_| Some(()))
}

/// [`run_with`] with `prepare` applied to the simulator before it runs (e.g. to set external
/// forces).
pub fn run_prepared(
    params: &ChainParams,
    z: &DVector<f64>,
    horizon: Horizon,
    options: &SimOptions,
    prepare: &dyn Fn(&mut Simulator) -> Option<()>,
) -> Option<(DVector<f64>, Vec<Event>)> {
    let mut sim = Simulator::new(params, &state_from_vector(z.as_slice()), options.clone()).ok()?;
    prepare(&mut sim)?;
    let mut log = EventLog::default();
    sim.run_until(horizon.end_time(params), &mut log).ok()?;
    Some((
        state_vector(&sim.state()),
        log.events.iter().map(|e| e.event).collect(),
    ))
}

pub fn signature(events: &[Event]) -> Vec<(EventKind, usize)> {
    events.iter().map(|e| (e.kind, e.contact)).collect()
}

/// Φ against Richardson-extrapolated central differences with step `h_rel` of the state
/// scales (positions: L, velocities: L·ω). Compared in scaled units: `D⁻¹ΦD`.
pub struct FdComparison {
    /// max |Φ̂ − D̂| / max(1, max|Φ̂|).
    pub error: f64,
    /// max |D̂(h) − D̂(2h)| / max(1, max|Φ̂|): how far the differences can be trusted.
    pub fd_uncertainty: f64,
}

pub fn compare_with_fd(
    params: &ChainParams,
    state: &ChainState,
    horizon: Horizon,
    phi: &DMatrix<f64>,
    events: &[Event],
    h_rel: f64,
) -> Option<FdComparison> {
    compare_with_fd_prepared(params, state, horizon, phi, events, h_rel, &|_| Some(()))
}

/// [`compare_with_fd`] for runs whose simulator is prepared by `prepare` before it runs.
pub fn compare_with_fd_prepared(
    params: &ChainParams,
    state: &ChainState,
    horizon: Horizon,
    phi: &DMatrix<f64>,
    events: &[Event],
    h_rel: f64,
    prepare: &dyn Fn(&mut Simulator) -> Option<()>,
) -> Option<FdComparison> {
    let n = params.len();
    let (l, v) = (length_scale(params), speed_scale(params));
    let scale = |i: usize| if i < n { l } else { v };
    let z0 = state_vector(state);
    let reference = signature(events);
    let (mut error, mut fd_uncertainty, mut phi_max) = (0.0f64, 0.0f64, 0.0f64);
    for j in 0..2 * n {
        let h = h_rel * scale(j);
        let mut ends = Vec::with_capacity(4);
        for step in [h, -h, 2.0 * h, -2.0 * h] {
            let mut z = z0.clone();
            z[j] += step;
            let (end, ev) = run_prepared(params, &z, horizon, &SimOptions::default(), prepare)?;
            if signature(&ev) != reference {
                return None;
            }
            ends.push(end);
        }
        for i in 0..2 * n {
            let d1 = (ends[0][i] - ends[1][i]) / (2.0 * h);
            let d2 = (ends[2][i] - ends[3][i]) / (4.0 * h);
            let fd = (d1 + (d1 - d2) / 3.0) * scale(j) / scale(i);
            let exact = phi[(i, j)] * scale(j) / scale(i);
            phi_max = phi_max.max(exact.abs());
            error = error.max((fd - exact).abs());
            fd_uncertainty = fd_uncertainty.max(((d1 - d2) * scale(j) / scale(i)).abs());
        }
    }
    let norm = phi_max.max(1.0);
    Some(FdComparison {
        error: error / norm,
        fd_uncertainty: fd_uncertainty / norm,
    })
}
