//! `vibrotribo.basins` and `vibrotribo.attractors`: basins of attraction over two initial
//! conditions, and the attractors of random starts across a parameter
//! ([`vibrotribo::attractors`]), in the columns of the command line's files.

use std::ops::ControlFlow;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use vibrotribo::attractors::{
    AcrossDelivery, Attractor, AttractorOptions, Classification, DEFAULT_START_PERIODS, Fingerprint,
    RandomStarts, SectionScale, StartBox, StartRunner, ValueAttractors, attractors_across, basin_points,
    classify, initial_condition_index,
};
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP};
use vibrotribo::sweep::{Cell, Kind, Table, grid};

use crate::config::{config_error, config_of, table_to_dict};
use crate::convert::table_to_py;
use crate::interrupt::Signals;
use crate::limits::check_grid;
use crate::sweep::{PointSettings, check_points};

/// `x1_m … xN_m, v1_m_s … vN_m_s`.
fn state_names(masses: usize) -> Vec<String> {
    let mut names: Vec<String> = (1..=masses).map(|i| format!("x{i}_m")).collect();
    names.extend((1..=masses).map(|i| format!("v{i}_m_s")));
    names
}

/// A table with the given (name, kind) columns.
fn table(columns: &[(&str, Kind)], extra: Vec<String>) -> Table {
    let mut names: Vec<String> = columns.iter().map(|(n, _)| n.to_string()).collect();
    let mut kinds: Vec<Kind> = columns.iter().map(|(_, k)| *k).collect();
    kinds.extend(extra.iter().map(|_| Kind::Float));
    names.extend(extra);
    Table::new(names, kinds)
}

fn opt(v: Option<f64>) -> Cell {
    v.map_or(Cell::Missing, Cell::Float)
}

/// One attractor's row of `attractors.csv` after its leading columns.
fn attractor_cells(c: &Classification, a: usize, at: &Attractor, masses: usize) -> Vec<Cell> {
    let (f, se) = c.fraction(a);
    let mut row = vec![
        Cell::Int(at.period as i64),
        Cell::Int(at.starts as i64),
        Cell::Float(f),
        Cell::Float(se),
        Cell::Float(at.impacts_per_period),
        opt(at.power_w),
        opt(at.power_se),
    ];
    row.extend(at.points[..2 * masses].iter().map(|&x| Cell::Float(x)));
    row
}

const ATTRACTOR_TAIL: [(&str, Kind); 7] = [
    ("period", Kind::Int),
    ("starts", Kind::Int),
    ("fraction", Kind::Float),
    ("fraction_se", Kind::Float),
    ("impacts_per_period", Kind::Float),
    ("average_power_w", Kind::Float),
    ("power_se_w", Kind::Float),
];

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
    let starts = StartRunner::new(
        settings_of.runner_or(base, DEFAULT_START_PERIODS)?,
        options.clone(),
    )
    .map_err(|e| PyValueError::new_err(e.to_string()))?;
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
    let o = starts.point_runner().options();
    let s = PyDict::new(py);
    s.set_item("command", "basins")?;
    s.set_item("x", x)?;
    s.set_item("x_values", xs)?;
    s.set_item("y", y)?;
    s.set_item("y_values", ys)?;
    s.set_item("transient_periods", o.transient_periods)?;
    s.set_item("recorded_periods", o.recorded_periods)?;
    s.set_item("mechanics_only", mechanics_only)?;
    s.set_item(
        "settings",
        table_to_dict(py, starts.point_runner().base().table())?,
    )?;
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
    let scale = SectionScale::of(chain);
    let c = classify(&fingerprints, &scale, options);
    let mut starts_table = table(
        &[
            ("x", Kind::Float),
            ("y", Kind::Float),
            ("period", Kind::Int),
            ("impacts_per_period", Kind::Float),
            ("average_power_w", Kind::Float),
            ("error", Kind::Text),
        ],
        Vec::new(),
    );
    let mut basin_table = table(
        &[
            ("x", Kind::Float),
            ("y", Kind::Float),
            ("attractor", Kind::Int),
            ("period", Kind::Int),
            ("impacts_per_period", Kind::Float),
            ("average_power_w", Kind::Float),
        ],
        Vec::new(),
    );
    for ((&(xv, yv), r), label) in points.iter().zip(results).zip(&c.labels) {
        let (period, impacts, power, error) = match r {
            Ok(f) => (
                Cell::Int(f.period as i64),
                Cell::Float(f.impacts_per_period),
                opt(f.power_w),
                String::new(),
            ),
            Err(e) => (Cell::Missing, Cell::Missing, Cell::Missing, e.clone()),
        };
        starts_table.push_row(vec![
            Cell::Float(xv),
            Cell::Float(yv),
            period.clone(),
            impacts.clone(),
            power.clone(),
            Cell::Text(error),
        ]);
        basin_table.push_row(vec![
            Cell::Float(xv),
            Cell::Float(yv),
            label.map_or(Cell::Missing, |a| Cell::Int(a as i64 + 1)),
            period,
            impacts,
            power,
        ]);
    }
    let mut attractor_table = table(
        &[&[("attractor", Kind::Int)][..], &ATTRACTOR_TAIL[..]].concat(),
        state_names(masses),
    );
    for (a, at) in c.attractors.iter().enumerate() {
        let mut row = vec![Cell::Int(a as i64 + 1)];
        row.extend(attractor_cells(&c, a, at, masses));
        attractor_table.push_row(row);
    }
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
    let starts = StartRunner::new(settings_of.runner_or(base, DEFAULT_START_PERIODS)?, options)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
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
    let starts = StartRunner::new(settings_of.runner_or(base, DEFAULT_START_PERIODS)?, options)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
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
    let mut at_table = table(
        &[
            &[("param", Kind::Float), ("attractor", Kind::Int)][..],
            &ATTRACTOR_TAIL[..],
        ]
        .concat(),
        state_names(masses),
    );
    let mut expected = table(
        &[
            ("param", Kind::Float),
            ("expected_power_w", Kind::Float),
            ("expected_power_se_w", Kind::Float),
            ("attractors", Kind::Int),
            ("starts", Kind::Int),
            ("failed", Kind::Int),
            ("error", Kind::Text),
        ],
        Vec::new(),
    );
    for v in &results {
        let c = &v.classification;
        let mut order: Vec<usize> = (0..c.attractors.len()).collect();
        order.sort_by_key(|&k| v.ids[k]);
        for k in order {
            let mut row = vec![Cell::Float(v.value), Cell::Int(v.ids[k] as i64 + 1)];
            row.extend(attractor_cells(c, k, &c.attractors[k], masses));
            at_table.push_row(row);
        }
        expected.push_row(vec![
            Cell::Float(v.value),
            opt(v.expected_power.map(|p| p.0)),
            opt(v.expected_power.map(|p| p.1)),
            Cell::Int(c.attractors.iter().filter(|a| a.starts > 0).count() as i64),
            Cell::Int(c.classified() as i64),
            Cell::Int(v.failed as i64),
            Cell::Text(v.first_error.clone().unwrap_or_default()),
        ]);
    }
    let out = PyDict::new(py);
    out.set_item("attractors", table_to_py(py, &at_table)?)?;
    out.set_item("expected_power", table_to_py(py, &expected)?)?;
    let o = starts.point_runner().options();
    let s = PyDict::new(py);
    s.set_item("command", "attractors")?;
    s.set_item("param", param)?;
    s.set_item("values", values)?;
    s.set_item("samples", samples)?;
    s.set_item("seed", seed)?;
    s.set_item("transient_periods", o.transient_periods)?;
    s.set_item("recorded_periods", o.recorded_periods)?;
    s.set_item("mechanics_only", mechanics_only)?;
    s.set_item(
        "settings",
        table_to_dict(py, starts.point_runner().base().table())?,
    )?;
    out.set_item("settings", s)?;
    Ok(out)
}
