//! `vibrotribo.optimize_mass_ratio`: the optimal mass ratio R_mo(Ω) on a grid of Ω × R_m
//! ([`vibrotribo::study::mass_ratio_optima`]) and its quadratic fit, in the columns of the
//! command line's `power_grid.csv`, `optimum.csv` and `fit.json`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::analysis::fit_quadratic;
use vibrotribo::study::{
    DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP, PAPER_MASS_RATIO_FIT, mass_ratio_optima,
    paper_mass_ratio_fit,
};
use vibrotribo::sweep::{Cell, Kind, PointColumns, Table, grid};

use crate::config::config_of;
use crate::convert::table_to_py;
use crate::limits::check_grid;
use crate::manifest::{MassRatioSettings, json_error, manifest_dict};
use crate::sweep::{PointSettings, check_points, run_grid};
use vibrotribo::report::manifest::{self, Kind as ManifestKind, PeriodsRecord};

/// Refuses an axis the command line refuses (`--{name}-from/-to/-steps`).
fn check_axis(name: &str, from: f64, to: f64, steps: usize) -> PyResult<()> {
    if !from.is_finite() || !to.is_finite() {
        return Err(PyValueError::new_err(format!(
            "{name}_from and {name}_to must be finite numbers"
        )));
    }
    if steps == 0 {
        return Err(PyValueError::new_err(format!("{name}_steps must be at least 1")));
    }
    Ok(())
}

/// The optimal mass ratio (see the Python `vibrotribo.optimize_mass_ratio`).
#[pyfunction]
#[pyo3(signature = (config, *, omega_from = 0.55, omega_to = 0.95, omega_steps = 9, rm_from = 1.2, rm_to = 7.0, rm_steps = 59, transient = None, recorded = None, period_tolerance = DEFAULT_PERIOD_TOLERANCE, floquet = false, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, threads = None, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn optimize_mass_ratio<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    omega_from: f64,
    omega_to: f64,
    omega_steps: usize,
    rm_from: f64,
    rm_to: f64,
    rm_steps: usize,
    transient: Option<u64>,
    recorded: Option<u64>,
    period_tolerance: f64,
    floquet: bool,
    settle: String,
    settle_cap: u64,
    threads: Option<usize>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    check_axis("omega", omega_from, omega_to, omega_steps)?;
    check_axis("rm", rm_from, rm_to, rm_steps)?;
    if rm_from <= 0.0 {
        return Err(PyValueError::new_err("rm_from must be positive"));
    }
    check_grid("omega_steps × rm_steps", omega_steps as f64 * rm_steps as f64)?;
    let settings_of = PointSettings {
        transient,
        recorded,
        mechanics_only: false,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet,
        lyapunov: false,
        allow_large,
    };
    let runner = settings_of.runner(config_of(config)?)?;
    let (omegas, ratios) = (
        grid(omega_from, omega_to, omega_steps),
        grid(rm_from, rm_to, rm_steps),
    );
    let points: Vec<Vec<(&str, f64)>> = omegas
        .iter()
        .flat_map(|&w| {
            ratios
                .iter()
                .map(move |&r| vec![("omega_ratio", w), ("mass_ratio", r)])
        })
        .collect();
    check_points(&runner, &points)?;
    let contacts = runner.contacts();
    let columns = PointColumns::of_contacts(contacts);
    let mut power_grid = Table::new(
        [
            "omega_ratio",
            "mass_ratio",
            "average_power_w",
            "impacts_per_period",
            "period",
            "error",
        ]
        .map(String::from)
        .to_vec(),
        vec![
            Kind::Float,
            Kind::Float,
            Kind::Float,
            Kind::Float,
            Kind::Int,
            Kind::Text,
        ],
    );
    let mut power = Vec::with_capacity(points.len());
    let pool = settings_of.pool()?;
    py.detach(|| {
        run_grid(&pool, &runner, &points, |keys, r| {
            power.push(
                r.as_ref()
                    .ok()
                    .and_then(|p| p.average_power_w)
                    .unwrap_or(f64::NAN),
            );
            // Of the point's columns: average_power_w, impacts_per_period, period, error.
            let mut cells = columns.cells(r);
            let error = cells.get(6 + contacts).cloned().unwrap_or(Cell::Missing);
            cells.truncate(3);
            let mut row = vec![Cell::Float(keys[0].1), Cell::Float(keys[1].1)];
            row.extend(cells);
            row.push(error);
            power_grid.push_row(row);
        })
    })?;
    let optimum = mass_ratio_optima(&omegas, &ratios, &power);
    let mut optimum_table = Table::new(
        [
            "omega_ratio",
            "optimal_mass_ratio",
            "average_power_w",
            "at_edge",
            "paper_fit",
        ]
        .map(String::from)
        .to_vec(),
        vec![Kind::Float, Kind::Float, Kind::Float, Kind::Bool, Kind::Float],
    );
    for o in &optimum {
        optimum_table.push_row(vec![
            Cell::Float(o.omega_ratio),
            Cell::Float(o.mass_ratio),
            Cell::Float(o.average_power_w),
            Cell::Bool(o.at_edge),
            Cell::Float(paper_mass_ratio_fit(o.omega_ratio)),
        ]);
    }
    let ws: Vec<f64> = optimum.iter().map(|o| o.omega_ratio).collect();
    let rs: Vec<f64> = optimum.iter().map(|o| o.mass_ratio).collect();
    let out = PyDict::new(py);
    out.set_item("power_grid", table_to_py(py, &power_grid)?)?;
    out.set_item("optimum", table_to_py(py, &optimum_table)?)?;
    let fit = match fit_quadratic(&ws, &rs) {
        Ok(f) => {
            let d = PyDict::new(py);
            d.set_item("a", f.a)?;
            d.set_item("b", f.b)?;
            d.set_item("c", f.c)?;
            d.set_item("r_squared", f.r_squared)?;
            d.set_item("rms_residual", f.rms_residual)?;
            Some(d)
        }
        Err(_) => None,
    };
    out.set_item("fit", fit)?;
    let paper = PyDict::new(py);
    let [a, b, c] = PAPER_MASS_RATIO_FIT;
    paper.set_item("a", a)?;
    paper.set_item("b", b)?;
    paper.set_item("c", c)?;
    out.set_item("paper_fit", paper)?;
    let settings = MassRatioSettings {
        command: ManifestKind::OptimizeMassRatio,
        omega_values: omegas,
        mass_ratio_values: ratios,
        periods: PeriodsRecord::of(runner.options()),
        mechanics_only: runner.mechanics_only(),
        settings: manifest::settings_of(runner.base()).map_err(json_error)?,
    };
    let s = manifest_dict(py, &settings)?;
    out.set_item("settings", s)?;
    Ok(out)
}
