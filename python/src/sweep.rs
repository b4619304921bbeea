//! `vibrotribo.sweep` and `vibrotribo.map`: points of a configuration with keys set, run by
//! the library's sweep runners ([`vibrotribo::sweep`]) and collected in the columns of the
//! command line's files ([`SweepColumns`]).

use std::ops::ControlFlow;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::config::Config;
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP, PointResult, SettleMode};
use vibrotribo::sweep::{
    Continuation, Delivery, PointColumns, PointRequest, PointRequestError, PointRunner, SweepColumns,
    SweepError, run_continued, run_grid_on,
};

use vibrotribo::attractors::initial_condition_index;
use vibrotribo::lyapunov::LyapunovOptions;
use vibrotribo::report::manifest::{Axis, MapManifest, RunnerRecord, SweepManifest};
use vibrotribo::study::limits;

use crate::config::{config_error, config_of};
use crate::convert::table_to_py;
use crate::interrupt::Signals;
use crate::limits::{check_grid, check_memory};
use crate::manifest::{add_missing, json_error, manifest_dict};

/// Settings shared by sweeps and maps.
pub struct PointSettings {
    pub transient: Option<u64>,
    pub recorded: Option<u64>,
    pub mechanics_only: bool,
    pub threads: Option<usize>,
    pub period_tolerance: f64,
    /// `"auto"` or `"fixed"` (the command line's `--settle`).
    pub settle: String,
    /// Most periods `"auto"` settles (`--settle-cap`).
    pub settle_cap: u64,
    /// Whether each point's orbit is shot for its largest Floquet multiplier (`--floquet`).
    pub floquet: bool,
    /// Whether each point's largest Lyapunov exponent is estimated (`sweep --lyapunov`).
    pub lyapunov: bool,
    /// Whether sizes above the limits are allowed (`--allow-large`).
    pub allow_large: bool,
}

impl PointSettings {
    /// The point runner on `base`, the options checked by the library ([`PointRequest`]),
    /// with `(transient, recorded)` periods by default from its `[run]` table.
    pub fn runner(&self, base: Config) -> PyResult<PointRunner> {
        let run = base.run();
        let defaults = (run.transient(), run.periods - run.transient());
        self.runner_or(base, defaults)
    }

    /// The point runner on `base` with `(transient, recorded)` periods where the settings do
    /// not give them.
    pub fn runner_or(&self, base: Config, defaults: (u64, u64)) -> PyResult<PointRunner> {
        let settle: SettleMode = self
            .settle
            .parse()
            .map_err(|e: vibrotribo::study::UnknownSettleMode| PyValueError::new_err(e.to_string()))?;
        let request = PointRequest {
            transient: self.transient,
            recorded: self.recorded,
            period_tolerance: self.period_tolerance,
            floquet: self.floquet,
            settle: settle.with_cap(self.settle_cap),
        };
        let mut options = request.options(&base, defaults).map_err(|e| match e {
            PointRequestError::Config(e) => config_error(e),
            e => PyValueError::new_err(e.to_string()),
        })?;
        if self.lyapunov {
            base.check_periodic("lyapunov (Lyapunov exponents)")
                .map_err(config_error)?;
            options.lyapunov = Some(LyapunovOptions::default());
        }
        check_memory(
            "one point (transient + recorded periods) on each thread",
            limits::point_memory_bytes(&options, base.chain().len()) * 4.0 * self.threads_f64(),
            self.allow_large,
        )?;
        Ok(PointRunner::new(base, options, self.mechanics_only))
    }

    fn threads_f64(&self) -> f64 {
        self.threads
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from)) as f64
    }

    /// The columns of a point's row under these settings.
    pub fn columns(&self, runner: &PointRunner) -> PointColumns {
        PointColumns {
            contacts: runner.contacts(),
            floquet: self.floquet,
            lyapunov: self.lyapunov,
        }
    }

    /// A thread pool of `threads` threads (all cores by default).
    pub fn pool(&self) -> PyResult<rayon::ThreadPool> {
        if self.threads == Some(0) {
            return Err(PyValueError::new_err("threads must be at least 1"));
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads.unwrap_or(0))
            .build()
            .map_err(|e| PyValueError::new_err(format!("cannot start the threads: {e}")))
    }
}

/// Checks that every point's configuration is valid, naming the first bad one.
pub fn check_points(runner: &PointRunner, points: &[Vec<(&str, f64)>]) -> PyResult<()> {
    for keys in points {
        runner.configure(keys).map_err(config_error)?;
    }
    Ok(())
}

/// Runs `points` on the pool, handing each point's keys and result to `each` in grid order;
/// stops at a chunk's end if a signal handler raised.
pub fn run_grid(
    pool: &rayon::ThreadPool,
    runner: &PointRunner,
    points: &[Vec<(&str, f64)>],
    mut each: impl FnMut(&[(&str, f64)], &Result<PointResult, SweepError>),
) -> PyResult<()> {
    let mut signals = Signals::new();
    let chunk = pool.current_num_threads() * 4;
    run_grid_on(
        pool,
        runner,
        points,
        |keys| keys.clone(),
        chunk,
        |d| match d {
            Delivery::Point(keys, r) => {
                each(keys, &r);
                ControlFlow::Continue(())
            }
            Delivery::Chunk(_) => {
                if signals.check() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            }
        },
    );
    signals.result()
}

/// Runs `points` on the pool, collecting them into `table` in grid order.
fn run_points(
    pool: &rayon::ThreadPool,
    runner: &PointRunner,
    points: &[Vec<(&str, f64)>],
    table: &mut SweepColumns,
) -> PyResult<()> {
    run_grid(pool, runner, points, |keys, r| {
        let values: Vec<f64> = keys.iter().map(|&(_, v)| v).collect();
        table.push(&values, r);
    })
}

/// Runs a one-parameter sweep (see the Python `vibrotribo.sweep`).
#[pyfunction]
#[pyo3(signature = (config, param, values, *, continuation = String::from("none"), transient = None, recorded = None, mechanics_only = false, threads = None, period_tolerance = DEFAULT_PERIOD_TOLERANCE, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, floquet = false, lyapunov = false, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    param: String,
    values: Vec<f64>,
    continuation: String,
    transient: Option<u64>,
    recorded: Option<u64>,
    mechanics_only: bool,
    threads: Option<usize>,
    period_tolerance: f64,
    settle: String,
    settle_cap: u64,
    floquet: bool,
    lyapunov: bool,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let continuation: Continuation = continuation.parse().map_err(PyValueError::new_err)?;
    check_grid("values", values.len() as f64)?;
    let settings_of = PointSettings {
        transient,
        recorded,
        mechanics_only,
        threads,
        period_tolerance,
        settle,
        settle_cap,
        floquet,
        lyapunov,
        allow_large,
    };
    let base = config_of(config)?;
    if continuation != Continuation::None {
        // Each value starts at t = 0 from the previous one's final state: the same phase of
        // the base motion only if it is periodic.
        base.check_periodic("sweep continuation").map_err(config_error)?;
    }
    let runner = settings_of.runner(base)?;
    let points: Vec<Vec<(&str, f64)>> = values.iter().map(|&v| vec![(param.as_str(), v)]).collect();
    check_points(&runner, &points)?;
    let columns = settings_of.columns(&runner);
    let mut table = SweepColumns::new(&["param"], runner.masses(), columns, true);
    match continuation {
        Continuation::None => {
            let pool = settings_of.pool()?;
            py.detach(|| run_points(&pool, &runner, &points, &mut table))?;
        }
        Continuation::Up | Continuation::Down => {
            let mut order: Vec<usize> = (0..values.len()).collect();
            if continuation == Continuation::Down {
                order.reverse();
            }
            py.detach(|| {
                let mut signals = Signals::new();
                run_continued(&runner, &param, &values, &order, None, |j, r, _| {
                    table.push(&[values[j]], &r);
                    Ok(if signals.check() {
                        ControlFlow::Break(())
                    } else {
                        ControlFlow::Continue(())
                    })
                })
                .map_err(|e| PyValueError::new_err(e.to_string()))?;
                signals.result()
            })?;
        }
    }
    let out = PyDict::new(py);
    out.set_item("summary", table_to_py(py, &table.summary())?)?;
    out.set_item("orbit", table_to_py(py, &table.orbit())?)?;
    out.set_item("impacts", table_to_py(py, &table.impacts())?)?;
    let manifest = SweepManifest::new(Axis::of_values(&param, &values), continuation, &runner, lyapunov)
        .map_err(json_error)?;
    let s = manifest_dict(py, &manifest)?;
    // Present whether or not they are set (sweep.json has them only when they are).
    s.set_item("floquet", floquet)?;
    s.set_item("lyapunov", lyapunov)?;
    out.set_item("settings", s)?;
    Ok(out)
}

/// Runs a two-parameter map (see the Python `vibrotribo.map`).
#[pyfunction]
#[pyo3(signature = (config, x, x_values, y, y_values, *, transient = None, recorded = None, mechanics_only = false, threads = None, period_tolerance = DEFAULT_PERIOD_TOLERANCE, settle = String::from("auto"), settle_cap = DEFAULT_SETTLE_CAP, floquet = false, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn map<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    x: String,
    x_values: Vec<f64>,
    y: String,
    y_values: Vec<f64>,
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
    check_grid(
        "x_values × y_values",
        x_values.len() as f64 * y_values.len() as f64,
    )?;
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
    let runner = settings_of.runner(config_of(config)?)?;
    // Grid order as map.csv: y outer, x inner.
    let (xk, yk) = (x.as_str(), y.as_str());
    let points: Vec<Vec<(&str, f64)>> = y_values
        .iter()
        .flat_map(|&yv| x_values.iter().map(move |&xv| vec![(xk, xv), (yk, yv)]))
        .collect();
    // An initial-condition axis is checked for its index only: a start whose masses
    // interpenetrate is a row with its error (as `basins` skips it), not a failed map.
    let initial = |k: &str| k.starts_with("run.initial_");
    for k in [xk, yk].into_iter().filter(|k| initial(k)) {
        initial_condition_index(k, runner.masses()).map_err(|e| PyValueError::new_err(e.to_string()))?;
    }
    let others: Vec<Vec<(&str, f64)>> = points
        .iter()
        .map(|p| p.iter().copied().filter(|(k, _)| !initial(k)).collect())
        .collect();
    check_points(&runner, &others)?;
    let columns = settings_of.columns(&runner);
    let mut table = SweepColumns::new(&["x", "y"], runner.masses(), columns, false);
    let pool = settings_of.pool()?;
    py.detach(|| run_points(&pool, &runner, &points, &mut table))?;
    let out = PyDict::new(py);
    out.set_item("summary", table_to_py(py, &table.summary())?)?;
    let manifest = MapManifest::new(
        Axis::of_values(&x, &x_values),
        Axis::of_values(&y, &y_values),
        &runner,
    )
    .map_err(json_error)?;
    let s = manifest_dict(py, &manifest)?;
    add_missing(&s, &RunnerRecord::of(&runner))?;
    // The keys by name, their values as lists (map.json's x and y are the axes).
    s.set_item("x", x)?;
    s.set_item("x_values", x_values)?;
    s.set_item("y", y)?;
    s.set_item("y_values", y_values)?;
    s.set_item("floquet", floquet)?;
    out.set_item("settings", s)?;
    Ok(out)
}
