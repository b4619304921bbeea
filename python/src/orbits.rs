//! `vibrotribo.periodic` and `vibrotribo.continue_`: periodic orbits by shooting with their
//! Floquet multipliers, and their continuation in a configuration key
//! ([`vibrotribo::orbits`]).

use std::ops::ControlFlow;

use numpy::{Complex64, PyArray1, PyArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibrotribo::ChainState;
use vibrotribo::branch::{BranchError, BranchOptions, branch_powers, continue_config, orbit_power};
use vibrotribo::config::Config;
use vibrotribo::nalgebra::Complex;
use vibrotribo::orbits::{
    BifurcationKind, Branch, BranchEnd, BranchPoint, ContinuationOptions, OrbitError, PeriodicOrbit,
    ShootingOptions, find_periodic_orbit, periodic_orbit_from_transient,
};

use crate::config::{config_error, config_of};
use crate::convert::{array1, array2};
use crate::interrupt::{Signals, cancel_hook, cancel_result};

create_exception!(
    vibrotribo,
    OrbitNotFound,
    PyRuntimeError,
    "No periodic orbit was found (Newton's method did not converge, the motion is not periodic, or the orbit is not differentiable)."
);

/// `ValueError` for bad options or parameters, [`OrbitNotFound`] otherwise.
fn orbit_error(e: OrbitError) -> PyErr {
    match e {
        OrbitError::Param(p) => PyValueError::new_err(p.to_string()),
        OrbitError::ZeroPeriod => PyValueError::new_err(e.to_string()),
        other => OrbitNotFound::new_err(other.to_string()),
    }
}

fn complex_array<'py>(py: Python<'py>, m: &[Complex<f64>]) -> Bound<'py, PyAny> {
    let v: Vec<Complex64> = m.iter().map(|c| Complex64::new(c.re, c.im)).collect();
    PyArray1::from_vec(py, v).into_any()
}

/// The orbit as a dict of arrays.
fn orbit_to_py<'py>(py: Python<'py>, o: &PeriodicOrbit) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("period", o.period)?;
    d.set_item("x", array1(py, o.state.positions.clone()))?;
    d.set_item("v", array1(py, o.state.velocities.clone()))?;
    d.set_item("multipliers", complex_array(py, &o.multipliers))?;
    d.set_item("stable", o.stable)?;
    d.set_item("spectral_radius", o.spectral_radius())?;
    d.set_item("unstable_dimension", o.unstable_dimension())?;
    d.set_item("impacts_per_period", array1(py, o.impacts_per_period()))?;
    d.set_item("sticks", o.sticks())?;
    d.set_item("residual", o.residual)?;
    d.set_item("residuals", array1(py, o.residuals.clone()))?;
    d.set_item("duration_s", o.duration())?;
    d.set_item(
        "monodromy",
        array2(
            py,
            o.monodromy.transpose().as_slice().to_vec(),
            o.monodromy.ncols(),
        )?,
    )?;
    let events = PyDict::new(py);
    events.set_item("t", array1(py, o.events.iter().map(|e| e.time).collect()))?;
    events.set_item("kind", PyList::new(py, o.events.iter().map(|e| e.kind.as_str()))?)?;
    let contact: Vec<i64> = o.events.iter().map(|e| e.contact as i64 + 1).collect();
    events.set_item("contact", PyArray1::from_vec(py, contact))?;
    events.set_item(
        "speed_before",
        array1(py, o.events.iter().map(|e| e.velocity_before).collect()),
    )?;
    d.set_item("events", events)?;
    Ok(d)
}

/// The shooting options of a configuration (its simulator settings), with a tolerance and
/// an iteration limit if given.
fn shooting(config: &Config, tolerance: Option<f64>, max_iterations: Option<usize>) -> ShootingOptions {
    let d = ShootingOptions::default();
    ShootingOptions {
        tolerance: tolerance.unwrap_or(d.tolerance),
        max_iterations: max_iterations.unwrap_or(d.max_iterations),
        sim: config.sim_options().clone(),
        ..d
    }
}

/// A state from `(x, v)` for a chain of `n` masses.
fn state_of(guess: (Vec<f64>, Vec<f64>), n: usize) -> PyResult<ChainState> {
    let (x, v) = guess;
    if x.len() != n || v.len() != n {
        return Err(PyValueError::new_err(format!(
            "guess: needs {n} positions and {n} velocities, got {} and {}",
            x.len(),
            v.len()
        )));
    }
    Ok(ChainState {
        positions: x,
        velocities: v,
    })
}

/// Finds a periodic orbit (see the Python `vibrotribo.periodic`).
#[pyfunction]
#[pyo3(signature = (config, *, period = None, transient = 200, guess = None, tolerance = None, max_iterations = None, mechanics_only = false))]
#[allow(clippy::too_many_arguments)]
pub fn periodic<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    period: Option<u32>,
    transient: u32,
    guess: Option<(Vec<f64>, Vec<f64>)>,
    tolerance: Option<f64>,
    max_iterations: Option<usize>,
    mechanics_only: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if period == Some(0) {
        return Err(PyValueError::new_err("period: must be at least 1"));
    }
    let config = config_of(config)?;
    config.check_uncoupled("periodic").map_err(config_error)?;
    config.check_periodic("periodic orbits").map_err(config_error)?;
    let (cancel, signals) = cancel_hook();
    let options = ShootingOptions {
        cancel,
        ..shooting(&config, tolerance, max_iterations)
    };
    let chain = config.chain().clone();
    let orbit = match guess {
        Some(g) => {
            let state = state_of(g, chain.len())?;
            let period = period.ok_or_else(|| PyValueError::new_err("period: give it with a guess"))?;
            py.detach(|| find_periodic_orbit(&chain, &state, period, &options))
        }
        // As the command line: no transient shoots from the configured initial state itself.
        None if transient == 0 => {
            let initial = config.initial_state().clone();
            py.detach(|| find_periodic_orbit(&chain, &initial, period.unwrap_or(1), &options))
        }
        None => {
            let initial = config.initial_state().clone();
            py.detach(|| periodic_orbit_from_transient(&chain, &initial, transient, period, &options))
        }
    };
    // A Ctrl-C during the search (polled at every Newton iteration and through the
    // transient) raises here, before any array is made.
    cancel_result(&signals)?;
    py.check_signals()?;
    let orbit = orbit.map_err(orbit_error)?;
    let power = if mechanics_only {
        None
    } else {
        py.detach(|| orbit_power(&config, &orbit))
            .map_err(|e| PyValueError::new_err(e.to_string()))?
    };
    let d = orbit_to_py(py, &orbit)?;
    let p = power.as_ref().and_then(|p| p.power.as_ref());
    d.set_item("average_power_w", p.map(|p| p.average_power_w))?;
    d.set_item("energy_per_period_j", p.map(|p| p.energy_per_period_j))?;
    Ok(d)
}

/// The points of a branch as arrays.
fn points_to_py<'py>(
    py: Python<'py>,
    points: &[BranchPoint],
    n: usize,
    power: Option<&[f64]>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let flat = |f: &dyn Fn(&BranchPoint) -> &[f64]| -> Vec<f64> {
        points.iter().flat_map(|p| f(p).to_vec()).collect()
    };
    d.set_item(
        "parameter",
        array1(py, points.iter().map(|p| p.parameter).collect()),
    )?;
    d.set_item("x", array2(py, flat(&|p| &p.state.positions), n)?)?;
    d.set_item("v", array2(py, flat(&|p| &p.state.velocities), n)?)?;
    let m: Vec<Complex64> = points
        .iter()
        .flat_map(|p| p.multipliers.iter().map(|c| Complex64::new(c.re, c.im)))
        .collect();
    let rows = points.len();
    let multipliers = PyArray1::from_vec(py, m).reshape([rows, if rows == 0 { 0 } else { 2 * n }])?;
    d.set_item("multipliers", multipliers)?;
    d.set_item(
        "stable",
        PyArray1::from_vec(py, points.iter().map(|p| p.stable).collect()),
    )?;
    d.set_item(
        "sticks",
        PyArray1::from_vec(py, points.iter().map(|p| p.sticks).collect()),
    )?;
    d.set_item(
        "impacts_per_period",
        // One column per contact: N − 1, and one more per rigid stop.
        array2(
            py,
            flat(&|p| &p.impacts_per_period),
            points.first().map_or(n - 1, |p| p.impacts_per_period.len()),
        )?,
    )?;
    d.set_item(
        "arclength",
        array1(py, points.iter().map(|p| p.arclength).collect()),
    )?;
    d.set_item(
        "spectral_radius",
        array1(py, points.iter().map(|p| p.spectral_radius()).collect()),
    )?;
    // The smallest closing speed of an impact on the orbit (NaN without impacts), m/s, and
    // its contact (1-based, 0 without impacts): branch.csv's min_closing_speed_m_s.
    d.set_item(
        "min_closing_speed_m_s",
        array1(
            py,
            points
                .iter()
                .map(|p| p.min_closing_speed.map_or(f64::NAN, |m| m.1))
                .collect(),
        ),
    )?;
    let contacts: Vec<i64> = points
        .iter()
        .map(|p| p.min_closing_speed.map_or(0, |m| m.0 as i64 + 1))
        .collect();
    d.set_item("min_closing_contact", PyArray1::from_vec(py, contacts))?;
    let power = match power {
        Some(p) => p.to_vec(),
        None => vec![f64::NAN; points.len()],
    };
    d.set_item("average_power_w", array1(py, power))?;
    Ok(d)
}

/// What happens at a bifurcation, as a dict: `kind` and its details (contacts 1-based).
fn kind_to_py<'py>(py: Python<'py>, kind: &BifurcationKind, d: &Bound<'py, PyDict>) -> PyResult<()> {
    match kind {
        BifurcationKind::NeimarkSacker { angle } => d.set_item("angle", angle)?,
        BifurcationKind::Grazing { contact, appears } => {
            d.set_item("contact", contact + 1)?;
            d.set_item("appears", appears)?;
        }
        BifurcationKind::Sticking { contact, onset } => {
            d.set_item("contact", contact + 1)?;
            d.set_item("onset", onset)?;
        }
        _ => {}
    }
    let _ = py;
    d.set_item("kind", kind.name())
}

/// Why a branch ended, as a dict: `reason` and its details.
fn end_to_py<'py>(py: Python<'py>, end: &BranchEnd) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let reason = match end {
        BranchEnd::RangeEnd { parameter } => {
            d.set_item("parameter", parameter)?;
            "range_end"
        }
        BranchEnd::MaxPoints => "max_points",
        BranchEnd::StepFloor {
            parameter,
            reason,
            non_smooth,
            residuals,
        } => {
            d.set_item("parameter", parameter)?;
            d.set_item("why", reason.to_string())?;
            d.set_item("non_smooth", non_smooth.as_ref().map(|p| p.to_string()))?;
            d.set_item("residuals", residuals.clone())?;
            "step_floor"
        }
        BranchEnd::Grazing {
            parameter,
            contact,
            gap,
        } => {
            d.set_item("parameter", parameter)?;
            d.set_item("contact", contact + 1)?;
            d.set_item("gap_m", gap)?;
            "grazing"
        }
        BranchEnd::CascadeDepth { parameter } => {
            d.set_item("parameter", parameter)?;
            "cascade_depth"
        }
        BranchEnd::Unlocated { parameter, between } => {
            d.set_item("parameter", parameter)?;
            d.set_item("between", [between.0, between.1])?;
            "unlocated"
        }
        BranchEnd::SwitchFailed { parameter } => {
            d.set_item("parameter", parameter)?;
            "switch_failed"
        }
        BranchEnd::Collapsed { parameter } => {
            d.set_item("parameter", parameter)?;
            "collapsed"
        }
        BranchEnd::Stopped { parameter } => {
            d.set_item("parameter", parameter)?;
            "stopped"
        }
        BranchEnd::Closed { parameter } => {
            d.set_item("parameter", parameter)?;
            "closed"
        }
        BranchEnd::Retraced { parameter } => {
            d.set_item("parameter", parameter)?;
            "retraced"
        }
        BranchEnd::Rejoined { parameter, branch } => {
            d.set_item("parameter", parameter)?;
            d.set_item("branch", branch)?;
            "rejoined"
        }
        BranchEnd::RunsOnto { parameter, branch } => {
            d.set_item("parameter", parameter)?;
            d.set_item("branch", branch)?;
            "runs_onto"
        }
        _ => "other",
    };
    d.set_item("reason", reason)?;
    Ok(d)
}

fn branch_to_py<'py>(
    py: Python<'py>,
    b: &Branch,
    n: usize,
    power: Option<&[f64]>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("period", b.period)?;
    d.set_item("parent", b.parent)?;
    d.set_item("points", points_to_py(py, &b.points, n, power)?)?;
    let bifurcations = PyList::empty(py);
    for bif in &b.bifurcations {
        let e = PyDict::new(py);
        kind_to_py(py, &bif.kind, &e)?;
        e.set_item("parameter", bif.parameter)?;
        e.set_item("precision", bif.precision)?;
        e.set_item("x", array1(py, bif.point.state.positions.clone()))?;
        e.set_item("v", array1(py, bif.point.state.velocities.clone()))?;
        e.set_item("multipliers", complex_array(py, &bif.point.multipliers))?;
        e.set_item("child", bif.child)?;
        if bif.kind == BifurcationKind::BranchPoint {
            e.set_item("other_child", bif.other_child)?;
        }
        if let Some(after) = &bif.after {
            e.set_item("multipliers_after", complex_array(py, &after.multipliers))?;
        }
        if let Some(c) = &bif.crossing {
            e.set_item("crossing", c.kind.name())?;
            e.set_item("nordmark", c.nordmark.map(|n| n.name()))?;
        }
        bifurcations.append(e)?;
    }
    d.set_item("bifurcations", bifurcations)?;
    d.set_item("end", end_to_py(py, &b.end)?)?;
    Ok(d)
}

/// Continues a periodic orbit in a configuration key (see the Python `vibrotribo.continue_`).
#[pyfunction]
#[pyo3(signature = (config, param, start, stop, *, period = None, transient = None, guess = None, max_points = None, doubling_depth = None, initial_step = None, max_step = None, mechanics_only = false))]
#[allow(clippy::too_many_arguments)]
pub fn continue_<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    param: String,
    start: f64,
    stop: f64,
    period: Option<u32>,
    transient: Option<u32>,
    guess: Option<(Vec<f64>, Vec<f64>)>,
    max_points: Option<usize>,
    doubling_depth: Option<u32>,
    initial_step: Option<f64>,
    max_step: Option<f64>,
    mechanics_only: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if period == Some(0) {
        return Err(PyValueError::new_err("period: must be at least 1"));
    }
    if !(start.is_finite() && stop.is_finite()) || start == stop {
        return Err(PyValueError::new_err(format!(
            "start and stop must be finite and different (got {start} and {stop})"
        )));
    }
    let base = config_of(config)?;
    base.check_uncoupled("continue_").map_err(config_error)?;
    base.check_periodic("continuation of periodic orbits")
        .map_err(config_error)?;
    let d = BranchOptions::default();
    let (cancel, signals) = cancel_hook();
    let options = BranchOptions {
        transient: transient.unwrap_or(d.transient),
        period,
        continuation: ContinuationOptions {
            max_points: max_points.unwrap_or(d.continuation.max_points),
            doubling_depth: doubling_depth.unwrap_or(d.continuation.doubling_depth),
            initial_step: initial_step.unwrap_or(d.continuation.initial_step),
            max_step: max_step.unwrap_or(d.continuation.max_step),
            shooting: ShootingOptions {
                cancel,
                ..d.continuation.shooting
            },
            ..d.continuation
        },
    };
    let n = base.chain().len();
    let guess = match guess {
        Some(g) => Some((
            state_of(g, n)?,
            period.ok_or_else(|| PyValueError::new_err("period: give it with a guess"))?,
        )),
        None => None,
    };
    let c = py.detach(|| continue_config(&base, &param, start, stop, guess, &options));
    // A Ctrl-C during the continuation (polled at every step and Newton iteration) stops it
    // and raises here, before any array is made.
    cancel_result(&signals)?;
    py.check_signals()?;
    let c = c.map_err(|e| match e {
        BranchError::Value { source, .. } => config_error(source),
        BranchError::FirstOrbit { source, .. } | BranchError::Continuation(source) => orbit_error(source),
        other => PyRuntimeError::new_err(other.to_string()),
    })?;
    let powers = if mechanics_only {
        None
    } else {
        // The power along the branches, point by point, with a Ctrl-C checkpoint after each.
        let (powers, signals) = py.detach(|| {
            let mut signals = Signals::new();
            let p = branch_powers(&base, &param, &c, || {
                if signals.check_now_and_then() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            });
            (p, signals)
        });
        signals.result()?;
        Some(powers)
    };
    let out = PyDict::new(py);
    out.set_item("parameter", &c.parameter)?;
    let branches = PyList::empty(py);
    for (j, b) in c.branches.iter().enumerate() {
        let power = powers.as_ref().map(|p| p[j].as_slice());
        branches.append(branch_to_py(py, b, n, power)?)?;
    }
    out.set_item("branches", branches)?;
    Ok(out)
}
