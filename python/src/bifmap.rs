//! `vibrotribo.bifmap`: a device's bifurcation map in two keys ([`vibrotribo::bifmap`]) over
//! its power map (the points of `vibrotribo.map`), as `vibrotribo bifmap` computes them.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibrotribo::bifmap::{
    BifmapError, BifmapOptions, BifurcationMap, HalfEnd, MapRequest, SeedOutcome, bifurcation_map,
    codim2_rows, curve_rows, located_rows, memory_bytes, validate,
};
use vibrotribo::orbits::curve::{CurveError, CurveKind};
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP};
use vibrotribo::sweep::SweepColumns;

use crate::config::{config_error, config_of};
use crate::convert::table_to_py;
use crate::interrupt::{cancel_hook, cancel_result};
use crate::limits::{check_grid, check_memory};
use crate::manifest::RunnerSettings;
use crate::sweep::{PointSettings, check_points, run_grid};
use vibrotribo::report::manifest::Kind;

fn error(e: BifmapError) -> PyErr {
    match e {
        BifmapError::Value { source, .. } | BifmapError::Key(source) => config_error(source),
        other => PyValueError::new_err(other.to_string()),
    }
}

/// Why a half of a curve ended, as a dict (`reason` and its details).
fn half_end<'py>(py: Python<'py>, end: &HalfEnd) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    match end {
        HalfEnd::Curve(e) => {
            d.set_item("reason", "curve")?;
            d.set_item("detail", format!("{e:?}"))?;
        }
        HalfEnd::LeftMap { x, y } => {
            d.set_item("reason", "left_map")?;
            d.set_item("x", x)?;
            d.set_item("y", y)?;
        }
        HalfEnd::Stopped => d.set_item("reason", "stopped")?,
        HalfEnd::NoStart(e) => {
            d.set_item("reason", "no_start")?;
            d.set_item("detail", e.to_string())?;
        }
        other => d.set_item("reason", format!("{other:?}"))?,
    }
    Ok(d)
}

/// The curves (their settings and ends) and seeds of `map` as lists of dicts.
fn records<'py>(py: Python<'py>, map: &BifurcationMap) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyList>)> {
    let curves = PyList::empty(py);
    for (i, c) in map.curves.iter().enumerate() {
        let d = PyDict::new(py);
        d.set_item("curve", i)?;
        d.set_item("kind", c.kind.name())?;
        d.set_item("period", c.period)?;
        d.set_item("contact", c.contact.map(|k| k + 1))?;
        d.set_item("seed_y", map.seeds.get(c.seed).map_or(f64::NAN, |s| s.y))?;
        d.set_item("located_x", c.located.parameter)?;
        d.set_item("points", c.points.len())?;
        let ends = PyList::empty(py);
        for e in &c.ends {
            match e {
                Some(e) => ends.append(half_end(py, e)?)?,
                None => ends.append(py.None())?,
            }
        }
        d.set_item("ends", ends)?;
        d.set_item("found_again", c.found_again)?;
        curves.append(d)?;
    }
    let seeds = PyList::empty(py);
    for s in &map.seeds {
        let d = PyDict::new(py);
        d.set_item("y", s.y)?;
        d.set_item("x_start", s.x_start)?;
        d.set_item("x_end", s.x_end)?;
        let c = s.branches();
        d.set_item("branches", c.map_or(0, |c| c.branches.len()))?;
        d.set_item(
            "points",
            c.map_or(0, |c| c.branches.iter().map(|b| b.points.len()).sum::<usize>()),
        )?;
        d.set_item(
            "on_branch_of",
            match s.outcome {
                SeedOutcome::OnBranch(i) => Some(i),
                _ => None,
            },
        )?;
        d.set_item("error", s.error_text())?;
        seeds.append(d)?;
    }
    Ok((curves, seeds))
}

/// A bifurcation map in two keys over the power map (see the Python `vibrotribo.bifmap`).
#[pyfunction]
#[pyo3(signature = (config, x, x_values, y, y_values, *, seeds = 5, x_starts = 5, kinds = None, period = None, doublings = 1, orbit_transient = 200, branch_points = 1000, curve_points = 200, max_curves = 64, transient = None, recorded = None, mechanics_only = false, threads = None, period_tolerance = DEFAULT_PERIOD_TOLERANCE, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, floquet = false, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn bifmap<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    x: String,
    x_values: Vec<f64>,
    y: String,
    y_values: Vec<f64>,
    seeds: usize,
    x_starts: usize,
    kinds: Option<Vec<String>>,
    period: Option<u32>,
    doublings: u32,
    orbit_transient: u32,
    branch_points: usize,
    curve_points: usize,
    max_curves: usize,
    transient: Option<u64>,
    recorded: Option<u64>,
    mechanics_only: bool,
    threads: Option<usize>,
    period_tolerance: f64,
    settle: String,
    settle_cap: u64,
    floquet: bool,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let ends = |v: &[f64], name: &str| match (v.first(), v.last()) {
        (Some(&a), Some(&b)) if a != b => Ok((a, b)),
        _ => Err(PyValueError::new_err(format!(
            "{name} must span a range (the curves are followed from its first to its last value)"
        ))),
    };
    let (x_range, y_range) = (ends(&x_values, "x_values")?, ends(&y_values, "y_values")?);
    if period == Some(0) {
        return Err(PyValueError::new_err("period: must be at least 1"));
    }
    check_grid(
        "x_values × y_values",
        x_values.len() as f64 * y_values.len() as f64,
    )?;
    let kinds = match kinds {
        None => CurveKind::ALL.to_vec(),
        Some(k) => k
            .iter()
            .map(|k| k.parse::<CurveKind>())
            .collect::<Result<Vec<_>, CurveError>>()
            .map_err(|e| PyValueError::new_err(e.to_string()))?,
    };
    let base = config_of(config)?;
    // As the command line: a single mass has no gap between masses to harvest from.
    let settings_of = PointSettings {
        transient,
        recorded,
        mechanics_only: mechanics_only || base.chain().len() < 2,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet,
        lyapunov: false,
        allow_large,
    };
    let runner = settings_of.runner(base.clone())?;
    let (xk, yk) = (x.as_str(), y.as_str());
    let points: Vec<Vec<(&str, f64)>> = y_values
        .iter()
        .flat_map(|&yv| x_values.iter().map(move |&xv| vec![(xk, xv), (yk, yv)]))
        .collect();
    check_points(&runner, &points)?;
    let (cancel, signals) = cancel_hook();
    let request = MapRequest {
        x: x.clone(),
        x_range,
        y: y.clone(),
        y_range,
        seeds,
        x_starts,
        kinds,
    };
    let options = BifmapOptions {
        transient: orbit_transient,
        period,
        doublings,
        branch_points,
        curve_points,
        max_curves,
        cancel,
    };
    validate(&base, &request, &options).map_err(error)?;
    check_memory(
        "the seed branches and curves (seeds, branch_points, max_curves, curve_points)",
        memory_bytes(&request, &options, runner.masses(), runner.contacts()),
        allow_large,
    )?;
    let pool = settings_of.pool()?;
    let map = py.detach(|| pool.install(|| bifurcation_map(&base, &request, &options, |_| {})));
    // A Ctrl-C during the map (polled at every step) stops it and raises here.
    cancel_result(&signals)?;
    py.check_signals()?;
    let map = map.map_err(error)?;
    let columns = settings_of.columns(&runner);
    let mut table = SweepColumns::new(&["x", "y"], runner.masses(), columns, false);
    py.detach(|| {
        run_grid(&pool, &runner, &points, |keys, r| {
            let values: Vec<f64> = keys.iter().map(|&(_, v)| v).collect();
            table.push(&values, r);
        })
    })?;
    let chain = base.chain();
    let out = PyDict::new(py);
    out.set_item("x", map.x.as_str())?;
    out.set_item("y", map.y.as_str())?;
    out.set_item(
        "curve_points",
        table_to_py(py, &curve_rows(&map, chain.len(), chain.contact_count()).table())?,
    )?;
    out.set_item("codim2", table_to_py(py, &codim2_rows(&map).table())?)?;
    out.set_item("located", table_to_py(py, &located_rows(&map).table())?)?;
    let (curves, seeds) = records(py, &map)?;
    out.set_item("curves", curves)?;
    out.set_item("seeds", seeds)?;
    out.set_item("untraced", map.untraced)?;
    out.set_item("map", table_to_py(py, &table.summary())?)?;
    let s = RunnerSettings::dict(py, Kind::Bifmap, None, &runner)?;
    s.set_item("x_values", x_values)?;
    s.set_item("y_values", y_values)?;
    s.set_item(
        "seed_values",
        vibrotribo::sweep::grid(y_range.0, y_range.1, request.seeds),
    )?;
    s.set_item(
        "x_starts",
        vibrotribo::sweep::grid(x_range.0, x_range.1, request.x_starts),
    )?;
    s.set_item("floquet", floquet)?;
    out.set_item("settings", s)?;
    Ok(out)
}
