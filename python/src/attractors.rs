//! `vibrotribo.basins` and `vibrotribo.attractors`: basins of attraction over two initial
//! conditions, and the attractors of random starts across a parameter
//! ([`vibrotribo::attractors`]), in the columns of the command line's files.

use std::ops::ControlFlow;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use vibrotribo::attractors::{
    AcrossDelivery, AttractorOptions, BASIN_COLUMNS, DEFAULT_START_PERIODS, EXPECTED_POWER_COLUMNS,
    Fingerprint, RandomStarts, START_COLUMNS, SectionScale, StartBox, StartRunner, ValueAttractors,
    attractors_across, basin_attractor_columns, basin_attractor_rows, basin_points, basin_rows,
    census_attractor_columns, census_attractor_rows, classify, columns, expected_power_row,
    initial_condition_index, start_rows, table_of,
};
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP};
use vibrotribo::sweep::grid;

use crate::config::{config_error, config_of};
use crate::convert::table_to_py;
use crate::interrupt::Signals;
use crate::limits::check_grid;
use crate::manifest::{json_error, manifest_dict};
use crate::sweep::{PointSettings, check_points};
use vibrotribo::config::Config;
use vibrotribo::report::manifest::{AttractorsManifest, Axis, BasinsManifest};

/// The attractor options of the command line's `--cell`, `--section-tolerance`,
/// `--match-tolerance` (and `--continuation-distance`).
fn attractor_options(
    cell: f64,
    section_tolerance: f64,
    match_tolerance: f64,
    distance: Option<f64>,
) -> AttractorOptions {
    let d = AttractorOptions::default();
    AttractorOptions {
        period_tolerance: section_tolerance,
        match_tolerance,
        cell,
        continuation_distance: distance.unwrap_or(d.continuation_distance),
    }
}

/// The start runner of `base` under `settings` (a start's default periods
/// [`DEFAULT_START_PERIODS`]), its starts told apart by `options`.
fn starts_of(base: Config, settings: &PointSettings, options: AttractorOptions) -> PyResult<StartRunner> {
    StartRunner::new(settings.runner_or(base, DEFAULT_START_PERIODS)?, options)
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Basins of attraction over two initial conditions (see the Python `vibrotribo.basins`).
#[pyfunction]
#[pyo3(signature = (config, x, x_from, x_to, y, y_from, y_to, grid_size, *, cell = 0.05, section_tolerance = 1e-3, match_tolerance = 3e-3, transient = None, recorded = None, mechanics_only = false, period_tolerance = DEFAULT_PERIOD_TOLERANCE, floquet = false, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, threads = None, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn basins<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    x: String,
    x_from: f64,
    x_to: f64,
    y: String,
    y_from: f64,
    y_to: f64,
    grid_size: (usize, usize),
    cell: f64,
    section_tolerance: f64,
    match_tolerance: f64,
    transient: Option<u64>,
    recorded: Option<u64>,
    mechanics_only: bool,
    period_tolerance: f64,
    floquet: bool,
    settle: String,
    settle_cap: u64,
    threads: Option<usize>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    for (name, a, b) in [("x", x_from, x_to), ("y", y_from, y_to)] {
        if !a.is_finite() || !b.is_finite() {
            return Err(PyValueError::new_err(format!(
                "{name}_from and {name}_to must be finite numbers"
            )));
        }
    }
    let (nx, ny) = grid_size;
    if nx == 0 || ny == 0 {
        return Err(PyValueError::new_err(format!(
            "grid: ({nx}, {ny}) needs at least one node along each axis"
        )));
    }
    check_grid("grid", nx as f64 * ny as f64)?;
    let base = config_of(config)?;
    base.check_uncoupled("basins").map_err(config_error)?;
    base.check_periodic("basins of attraction (`basins`)")
        .map_err(config_error)?;
    let masses = base.chain().len();
    for (name, key) in [("x", &x), ("y", &y)] {
        initial_condition_index(key, masses).map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    }
    if x == y {
        return Err(PyValueError::new_err("x and y are the same key"));
    }
    let settings_of = PointSettings {
        transient,
        recorded,
        mechanics_only,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet,
        lyapunov: false,
        allow_large,
    };
    let options = attractor_options(cell, section_tolerance, match_tolerance, None);
    let starts = starts_of(base, &settings_of, options.clone())?;
    let (xs, ys) = (grid(x_from, x_to, nx), grid(y_from, y_to, ny));
    let points = basin_points(&xs, &ys);
    let pool = settings_of.pool()?;
    let results = run_starts(py, &pool, &starts, &points, &x, &y)?;
    let out = basin_tables(
        py,
        starts.point_runner().base().chain(),
        &points,
        &results,
        &options,
    )?;
    let manifest = BasinsManifest::new(
        &starts,
        Axis::new(&x, (x_from, x_to), xs.clone()),
        Axis::new(&y, (y_from, y_to), ys.clone()),
    )
    .map_err(json_error)?;
    let s = manifest_dict(py, &manifest)?;
    // The keys by name, their values as lists (basins.json's x and y are the axes).
    s.set_item("x", x)?;
    s.set_item("x_values", xs)?;
    s.set_item("y", y)?;
    s.set_item("y_values", ys)?;
    out.set_item("settings", s)?;
    Ok(out)
}

/// The tables of a basin grid from its starts' fingerprints (grid order), classified in
/// that order: `starts`, `basins` and `attractors`.
fn basin_tables<'py>(
    py: Python<'py>,
    chain: &vibrotribo::ChainParams,
    points: &[(f64, f64)],
    results: &[Result<Fingerprint, String>],
    options: &AttractorOptions,
) -> PyResult<Bound<'py, PyDict>> {
    let masses = chain.len();
    let fingerprints: Vec<Option<Fingerprint>> = results.iter().map(|r| r.as_ref().ok().cloned()).collect();
    let c = classify(&fingerprints, &SectionScale::of(chain), options);
    let starts_table = table_of(columns(&START_COLUMNS, &[], 0), start_rows(points, results));
    let basin_table = table_of(
        columns(&BASIN_COLUMNS, &[], 0),
        basin_rows(points, &fingerprints, &c),
    );
    let attractor_table = table_of(basin_attractor_columns(masses), basin_attractor_rows(&c, masses));
    let out = PyDict::new(py);
    out.set_item("starts", table_to_py(py, &starts_table)?)?;
    out.set_item("basins", table_to_py(py, &basin_table)?)?;
    out.set_item("attractors", table_to_py(py, &attractor_table)?)?;
    Ok(out)
}

/// A start's fingerprint as a tuple `(period, impacts_per_period, power_w, points, cells,
/// error)` (`error` None for a start that ran).
type StartTuple = (usize, f64, Option<f64>, Vec<f64>, Vec<i32>, Option<String>);

fn fingerprint_to_py(r: &Result<Fingerprint, String>) -> StartTuple {
    match r {
        Ok(f) => (
            f.period,
            f.impacts_per_period,
            f.power_w,
            f.points.clone(),
            f.cells.clone(),
            None,
        ),
        Err(e) => (0, f64::NAN, None, Vec::new(), Vec::new(), Some(e.clone())),
    }
}

fn fingerprint_of(t: StartTuple) -> Result<Fingerprint, String> {
    match t {
        (_, _, _, _, _, Some(e)) => Err(e),
        (period, impacts_per_period, power_w, points, cells, None) => Ok(Fingerprint {
            period,
            points,
            cells,
            impacts_per_period,
            power_w,
        }),
    }
}

/// The fingerprints of the starts of a basin grid (grid order), without classifying them:
/// what `vibrotribo.dask.basins` runs on a worker for some rows.
#[pyfunction]
#[pyo3(signature = (config, x, x_values, y, y_values, *, cell = 0.05, section_tolerance = 1e-3, match_tolerance = 3e-3, transient = None, recorded = None, mechanics_only = false, period_tolerance = DEFAULT_PERIOD_TOLERANCE, floquet = false, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, threads = None))]
#[allow(clippy::too_many_arguments)]
pub fn basin_starts(
    py: Python<'_>,
    config: &Bound<'_, PyAny>,
    x: String,
    x_values: Vec<f64>,
    y: String,
    y_values: Vec<f64>,
    cell: f64,
    section_tolerance: f64,
    match_tolerance: f64,
    transient: Option<u64>,
    recorded: Option<u64>,
    mechanics_only: bool,
    period_tolerance: f64,
    floquet: bool,
    settle: String,
    settle_cap: u64,
    threads: Option<usize>,
) -> PyResult<Vec<StartTuple>> {
    let base = config_of(config)?;
    let settings_of = PointSettings {
        transient,
        recorded,
        mechanics_only,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet,
        lyapunov: false,
        allow_large: true,
    };
    let options = attractor_options(cell, section_tolerance, match_tolerance, None);
    let starts = starts_of(base, &settings_of, options)?;
    let points = basin_points(&x_values, &y_values);
    let pool = settings_of.pool()?;
    let results = run_starts(py, &pool, &starts, &points, &x, &y)?;
    Ok(results.iter().map(fingerprint_to_py).collect())
}

/// The tables of a basin grid from fingerprints computed elsewhere (see [`basin_starts`]).
#[pyfunction]
#[pyo3(signature = (config, x_values, y_values, fingerprints, *, cell = 0.05, section_tolerance = 1e-3, match_tolerance = 3e-3))]
#[allow(clippy::too_many_arguments)]
pub fn classify_basins<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    x_values: Vec<f64>,
    y_values: Vec<f64>,
    fingerprints: Vec<StartTuple>,
    cell: f64,
    section_tolerance: f64,
    match_tolerance: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let base = config_of(config)?;
    let points = basin_points(&x_values, &y_values);
    if fingerprints.len() != points.len() {
        return Err(PyValueError::new_err(format!(
            "fingerprints: {} for a grid of {} starts",
            fingerprints.len(),
            points.len()
        )));
    }
    let options = attractor_options(cell, section_tolerance, match_tolerance, None);
    options
        .validate()
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    let results: Vec<Result<Fingerprint, String>> = fingerprints.into_iter().map(fingerprint_of).collect();
    basin_tables(py, base.chain(), &points, &results, &options)
}

/// Runs the starts at `points` on the pool in grid order, chunk by chunk, stopping at a
/// chunk's end if a signal handler raised.
fn run_starts(
    py: Python<'_>,
    pool: &rayon::ThreadPool,
    starts: &StartRunner,
    points: &[(f64, f64)],
    xk: &str,
    yk: &str,
) -> PyResult<Vec<Result<Fingerprint, String>>> {
    py.detach(|| {
        let mut signals = Signals::new();
        let mut out = Vec::with_capacity(points.len());
        for chunk in points.chunks(pool.current_num_threads() * 4) {
            let part: Vec<Result<Fingerprint, String>> = pool.install(|| {
                chunk
                    .par_iter()
                    .map(|&(xv, yv)| {
                        starts
                            .run(&[(xk, xv), (yk, yv)], None)
                            .map_err(|e| format!("{e:#}"))
                    })
                    .collect()
            });
            out.extend(part);
            if signals.check() {
                break;
            }
        }
        signals.result().map(|()| out)
    })
}

/// The attractors of random starts across a parameter (see the Python
/// `vibrotribo.attractors`).
#[pyfunction]
#[pyo3(signature = (config, param, values, *, samples = 100, seed = 1, position_range = None, velocity_range = None, cell = 0.05, section_tolerance = 1e-3, match_tolerance = 3e-3, continuation_distance = 0.25, transient = None, recorded = None, mechanics_only = false, period_tolerance = DEFAULT_PERIOD_TOLERANCE, floquet = false, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, threads = None, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn attractors<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    param: String,
    values: Vec<f64>,
    samples: usize,
    seed: u64,
    position_range: Option<f64>,
    velocity_range: Option<f64>,
    cell: f64,
    section_tolerance: f64,
    match_tolerance: f64,
    continuation_distance: f64,
    transient: Option<u64>,
    recorded: Option<u64>,
    mechanics_only: bool,
    period_tolerance: f64,
    floquet: bool,
    settle: String,
    settle_cap: u64,
    threads: Option<usize>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    if values.is_empty() || samples == 0 {
        return Err(PyValueError::new_err("values and samples: at least 1 each"));
    }
    check_grid("values × samples", values.len() as f64 * samples as f64)?;
    let base = config_of(config)?;
    base.check_uncoupled("attractors").map_err(config_error)?;
    base.check_periodic("attractor census (`attractors`)")
        .map_err(config_error)?;
    let settings_of = PointSettings {
        transient,
        recorded,
        mechanics_only,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet,
        lyapunov: false,
        allow_large,
    };
    let options = attractor_options(
        cell,
        section_tolerance,
        match_tolerance,
        Some(continuation_distance),
    );
    let starts = starts_of(base, &settings_of, options)?;
    let points: Vec<Vec<(&str, f64)>> = values.iter().map(|&v| vec![(param.as_str(), v)]).collect();
    check_points(starts.point_runner(), &points)?;
    let chain = starts.point_runner().base().chain();
    let masses = chain.len();
    let default_box = StartBox::of(chain);
    let bounds = match (position_range, velocity_range) {
        (None, None) => None,
        (p, v) => Some(StartBox {
            positions: p.unwrap_or(default_box.positions),
            velocities: v.unwrap_or(default_box.velocities),
        }),
    };
    if let Some(b) = &bounds {
        b.validate()
            .map_err(|e| PyValueError::new_err(format!("position_range/velocity_range: {e}")))?;
    }
    let sampling = RandomStarts {
        samples,
        seed,
        bounds,
    };
    let pool = settings_of.pool()?;
    let results: Vec<ValueAttractors> = py.detach(|| {
        let mut signals = Signals::new();
        let chunk = pool.current_num_threads() * 4;
        let r = pool.install(|| {
            attractors_across(&starts, &param, &values, &sampling, chunk, |d| match d {
                AcrossDelivery::Chunk if signals.check() => ControlFlow::Break(()),
                _ => ControlFlow::Continue(()),
            })
        });
        signals.result()?;
        r.map_err(|e| PyValueError::new_err(e.to_string()))
    })?;
    let at_table = table_of(
        census_attractor_columns(masses),
        results.iter().flat_map(|v| census_attractor_rows(v, masses)),
    );
    let expected = table_of(
        columns(&EXPECTED_POWER_COLUMNS, &[], 0),
        results.iter().map(expected_power_row),
    );
    let out = PyDict::new(py);
    out.set_item("attractors", table_to_py(py, &at_table)?)?;
    out.set_item("expected_power", table_to_py(py, &expected)?)?;
    let manifest =
        AttractorsManifest::new(&starts, Axis::of_values(&param, &values), &sampling).map_err(json_error)?;
    let s = manifest_dict(py, &manifest)?;
    out.set_item("settings", s)?;
    Ok(out)
}
