//! `vibrotribo.response` and `vibrotribo.band_response`: the frequency response
//! ([`vibrotribo::response`]) as `vibrotribo response` and `vibrotribo band-response` run it:
//! the tables of their CSV files and the summary of their manifests.

use std::ops::ControlFlow;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::orbits::ShootingOptions;
use vibrotribo::response::{
    BandOptions, BandPlan, BranchSeeding, DEFAULT_BAND_SEEDS, DEFAULT_MAX_SEEDS, ResponseError,
    ResponseOptions, ResponseStep, band_response as run_band, band_seed_table, band_table, branch_table,
    frequency_response, response_table,
};
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP};

use crate::config::{config_error, config_of};
use crate::convert::{json_to_py, table_to_py};
use crate::interrupt::{Signals, cancel_hook, cancel_result};
use crate::limits::check_grid;
use crate::manifest::RunnerSettings;
use crate::sweep::PointSettings;
use vibrotribo::report::manifest::{Axis, Kind};

/// A library error as a Python exception (a bad key or value: the configuration's error).
fn response_error(e: ResponseError) -> PyErr {
    match e {
        ResponseError::Config(c) => config_error(c),
        other => PyValueError::new_err(other.to_string()),
    }
}

fn summary_to_py<'py, T: serde::Serialize>(py: Python<'py>, s: &T) -> PyResult<Bound<'py, PyAny>> {
    let v = serde_json::to_value(s).map_err(|e| PyValueError::new_err(e.to_string()))?;
    json_to_py(py, &v)
}

/// The point settings of a response (no threads of its own: the sweeps run a thread each).
fn point_settings(
    transient: Option<u64>,
    recorded: Option<u64>,
    period_tolerance: f64,
    (settle, settle_cap): (String, u64),
    threads: Option<usize>,
    allow_large: bool,
) -> PointSettings {
    PointSettings {
        transient,
        recorded,
        mechanics_only: false,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet: false,
        lyapunov: false,
        allow_large,
    }
}

/// Runs the frequency response (see the Python `vibrotribo.response`).
#[pyfunction]
#[pyo3(signature = (config, values, *, param = String::from("excitation.omega_ratio"), branches = false, branch_seeds = DEFAULT_MAX_SEEDS, transient = None, recorded = None, period_tolerance = DEFAULT_PERIOD_TOLERANCE, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn response<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    values: Vec<f64>,
    param: String,
    branches: bool,
    branch_seeds: usize,
    transient: Option<u64>,
    recorded: Option<u64>,
    period_tolerance: f64,
    settle: String,
    settle_cap: u64,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_grid("values (two sweeps)", 2.0 * values.len() as f64)?;
    let s = point_settings(
        transient,
        recorded,
        period_tolerance,
        (settle, settle_cap),
        Some(2),
        allow_large,
    );
    let runner = s.runner(config_of(config)?)?;
    if runner.mechanics_only() {
        return Err(PyValueError::new_err(
            "a single mass has no harvester: there is no power to take a response of",
        ));
    }
    let (cancel, signals) = cancel_hook();
    let options = ResponseOptions {
        branches: branches.then(|| {
            let d = BranchSeeding::default();
            BranchSeeding {
                max_seeds: branch_seeds,
                continuation: vibrotribo::orbits::ContinuationOptions {
                    shooting: ShootingOptions {
                        cancel,
                        ..d.continuation.shooting
                    },
                    ..d.continuation
                },
                ..d
            }
        }),
    };
    let hook = |_: ResponseStep| {
        // A poisoned lock (a panic while checking) stops the computation.
        if signals.lock().map_or(true, |mut s| s.check_now_and_then()) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let r = py.detach(|| frequency_response(&runner, &param, &values, &options, &hook));
    cancel_result(&signals)?;
    let r = r.map_err(response_error)?;
    let out = PyDict::new(py);
    out.set_item("response", table_to_py(py, &response_table(&r).table())?)?;
    out.set_item("branches", table_to_py(py, &branch_table(&r).table())?)?;
    out.set_item(
        "summary",
        summary_to_py(py, &r.summary(options.branches.as_ref()))?,
    )?;
    let st = RunnerSettings::dict(
        py,
        Kind::Response,
        Some(Axis::of_values(&param, &values)),
        &runner,
    )?;
    out.set_item("settings", st)?;
    Ok(out)
}

/// Runs the random-band response (see the Python `vibrotribo.band_response`).
#[pyfunction]
#[pyo3(signature = (config, centres_hz, *, width = None, seeds = DEFAULT_BAND_SEEDS, transient = None, recorded = None, period_tolerance = DEFAULT_PERIOD_TOLERANCE, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, threads = None, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn band_response<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    centres_hz: Vec<f64>,
    width: Option<f64>,
    seeds: u64,
    transient: Option<u64>,
    recorded: Option<u64>,
    period_tolerance: f64,
    settle: String,
    settle_cap: u64,
    threads: Option<usize>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_grid("centres_hz × seeds", centres_hz.len() as f64 * seeds as f64)?;
    let s = point_settings(
        transient,
        recorded,
        period_tolerance,
        (settle, settle_cap),
        threads,
        allow_large,
    );
    let runner = s.runner(config_of(config)?)?;
    if runner.mechanics_only() {
        return Err(PyValueError::new_err(
            "a single mass has no harvester: there is no power to take a response of",
        ));
    }
    let plan = BandPlan::new(
        runner.base(),
        &BandOptions {
            centres_hz,
            width_hz: width,
            seeds,
        },
    )
    .map_err(|e| match e {
        ResponseError::Option { name, value, reason } => {
            let name = if name == "width_hz" { "width" } else { name };
            PyValueError::new_err(format!("{name} = {value}: {reason}"))
        }
        other => response_error(other),
    })?;
    let pool = s.pool()?;
    let r = py.detach(|| {
        let mut signals = Signals::new();
        let r = run_band(&runner, &plan, Some(&pool), || {
            if signals.check_now_and_then() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        });
        (r, signals)
    });
    r.1.result()?;
    let r = r.0.map_err(response_error)?;
    let out = PyDict::new(py);
    out.set_item("response", table_to_py(py, &band_table(&r).table())?)?;
    out.set_item("seeds", table_to_py(py, &band_seed_table(&r).table())?)?;
    out.set_item("summary", summary_to_py(py, &r.summary())?)?;
    let st = RunnerSettings::dict(py, Kind::BandResponse, None, &runner)?;
    out.set_item("settings", st)?;
    Ok(out)
}
