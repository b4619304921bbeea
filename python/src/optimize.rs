//! `vibrotribo.optimize`: design optimisation over configuration keys
//! ([`vibrotribo::optimize`]), as `vibrotribo optimize` runs it, returned as a dict.

use std::sync::Mutex;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::optimize::{
    Cache, Constraint, Objective, OptimizeError, OptimizeOptions, Problem, Variable, optimize as run_search,
};

use crate::config::config_of;
use crate::convert::json_to_py;
use crate::interrupt::Signals;

fn value_error(e: OptimizeError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// Optimises a design: `vary` as `["KEY=LO..HI", …]`, `objective` one of `average_power`,
/// `expected_power`, `power_per_mass`, `constraints` as `["breakdown_ratio<=0.9", …]`.
/// Returns a dict with `best` (key → value), `objective`, `objective_standard_error`,
/// `score`, `breakdown_ratio`, `max_displacement_m`, `evaluations`, `history` and
/// `best_config` (the best design's TOML).
#[pyfunction]
#[pyo3(signature = (config, vary, *, objective = "average_power", constraints = None, starts = 4, seed = 0, particles = 8, swarm_iterations = 6, local_iterations = 30))]
#[allow(clippy::too_many_arguments)]
pub fn optimize<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    vary: Vec<String>,
    objective: &str,
    constraints: Option<Vec<String>>,
    starts: u64,
    seed: u64,
    particles: usize,
    swarm_iterations: u64,
    local_iterations: u64,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(config)?;
    let variables = vary
        .iter()
        .map(|v| Variable::parse(&config, v))
        .collect::<Result<Vec<_>, _>>()
        .map_err(value_error)?;
    let constraints = constraints
        .unwrap_or_default()
        .iter()
        .map(|c| Constraint::parse(c))
        .collect::<Result<Vec<_>, _>>()
        .map_err(value_error)?;
    let problem = Problem {
        base: config,
        variables,
        objective: objective.parse::<Objective>().map_err(value_error)?,
        constraints,
        options: OptimizeOptions {
            starts,
            seed,
            particles,
            swarm_iterations,
            local_iterations,
        },
    };
    let signals = Mutex::new(Signals::new());
    let result = py.detach(|| {
        let stop = || {
            signals
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
                .check_now_and_then()
        };
        run_search(&problem, &mut Cache::default(), &|_, _, _| {}, &stop)
    });
    signals
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .result()?;
    let result = result.map_err(value_error)?;
    let out = PyDict::new(py);
    let best = PyDict::new(py);
    for (v, value) in problem.variables.iter().zip(&result.best.values) {
        best.set_item(&v.key, value)?;
    }
    let b = &result.best;
    out.set_item("best", best)?;
    out.set_item("objective", b.objective)?;
    out.set_item("objective_standard_error", b.standard_error)?;
    out.set_item("score", b.score)?;
    out.set_item("breakdown_ratio", b.breakdown_ratio)?;
    out.set_item("max_displacement_m", b.max_displacement_m)?;
    out.set_item("evaluations", result.evaluations)?;
    let history = serde_json::to_value(&result.history).map_err(|e| PyValueError::new_err(e.to_string()))?;
    out.set_item("history", json_to_py(py, &history)?)?;
    let design = problem
        .design(&result.best_unit)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let toml = toml::to_string(design.table()).map_err(|e| PyValueError::new_err(e.to_string()))?;
    out.set_item("best_config", toml)?;
    Ok(out)
}
