//! The extension module `vibrotribo._vibrotribo`: Python bindings of vibrotribo's run layer
//! (configurations, runs, sweeps, maps, load sweeps, periodic orbits and their continuation, Lyapunov spectra). The Python
//! package `vibrotribo` (python/vibrotribo/) wraps what this returns into result objects;
//! nothing here computes: it converts arguments, releases the GIL while the library runs,
//! watches for Ctrl-C at the library's checkpoints, and converts results to numpy arrays.

use pyo3::prelude::*;

mod config;
mod convert;
mod interrupt;
mod loads;
mod lyapunov;
mod optimize;
mod orbits;
mod simulate;
mod sweep;

/// `steps` values equally spaced from `start` to `stop`, both included (`stop` exactly): the
/// grid of the command line's `--from/--to/--steps`.
#[pyfunction]
fn grid(start: f64, stop: f64, steps: usize) -> Vec<f64> {
    vibrotribo::sweep::grid(start, stop, steps)
}

/// `steps` values spaced evenly in the logarithm from `start` to `stop` (the load sweep's
/// resistances, Ω).
#[pyfunction]
fn log_spaced(start: f64, stop: f64, steps: usize) -> Vec<f64> {
    vibrotribo::electrical::log_spaced(start, stop, steps)
}

#[pymodule]
fn _vibrotribo(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "DEFAULT_PERIOD_TOLERANCE",
        vibrotribo::study::DEFAULT_PERIOD_TOLERANCE,
    )?;
    m.add("DEFAULT_SETTLE_CAP", vibrotribo::study::DEFAULT_SETTLE_CAP)?;
    m.add_class::<config::PyConfig>()?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::map, m)?)?;
    m.add_function(wrap_pyfunction!(loads::load_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(orbits::periodic, m)?)?;
    m.add_function(wrap_pyfunction!(orbits::continue_, m)?)?;
    m.add_function(wrap_pyfunction!(lyapunov::lyapunov, m)?)?;
    m.add_function(wrap_pyfunction!(optimize::optimize, m)?)?;
    m.add_function(wrap_pyfunction!(grid, m)?)?;
    m.add_function(wrap_pyfunction!(log_spaced, m)?)?;
    m.add("OrbitNotFound", m.py().get_type::<orbits::OrbitNotFound>())?;
    Ok(())
}
