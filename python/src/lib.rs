//! The extension module `vibrotribo._vibrotribo`: Python bindings of vibrotribo's run layer
//! (configurations, runs, sweeps, maps, load sweeps, periodic orbits and their continuation, bifurcation curves and maps, Lyapunov spectra, chirps, basins and attractors, the optimal mass ratio, design optimisation, frequency responses, ngspice netlists). The Python
//! package `vibrotribo` (python/vibrotribo/) wraps what this returns into result objects;
//! nothing here computes: it converts arguments, releases the GIL while the library runs,
//! watches for Ctrl-C at the library's checkpoints, and converts results to numpy arrays.

use pyo3::prelude::*;

mod attractors;
mod bifmap;
mod chirp;
mod config;
mod convert;
mod curve;
mod interrupt;
mod limits;
mod loads;
mod lyapunov;
mod manifest;
mod mass_ratio;
mod optimize;
mod orbits;
mod response;
mod simulate;
mod spice;
mod sweep;

/// `steps` values equally spaced from `start` to `stop`, both included (`stop` exactly): the
/// grid of the command line's `--from/--to/--steps`.
#[pyfunction]
fn grid(py: Python<'_>, start: f64, stop: f64, steps: usize) -> Bound<'_, numpy::PyArray1<f64>> {
    numpy::PyArray1::from_vec(py, vibrotribo::sweep::grid(start, stop, steps))
}

/// `steps` values spaced evenly in the logarithm from `start` to `stop`, both included
/// exactly (the load sweep's resistances, Ω).
#[pyfunction]
fn log_spaced(py: Python<'_>, start: f64, stop: f64, steps: usize) -> Bound<'_, numpy::PyArray1<f64>> {
    numpy::PyArray1::from_vec(py, vibrotribo::electrical::log_spaced(start, stop, steps))
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
    m.add_function(wrap_pyfunction!(curve::curve, m)?)?;
    m.add_function(wrap_pyfunction!(bifmap::bifmap, m)?)?;
    m.add_function(wrap_pyfunction!(lyapunov::lyapunov, m)?)?;
    m.add_function(wrap_pyfunction!(chirp::chirp, m)?)?;
    m.add_function(wrap_pyfunction!(attractors::basins, m)?)?;
    m.add_function(wrap_pyfunction!(attractors::attractors, m)?)?;
    m.add_function(wrap_pyfunction!(attractors::basin_starts, m)?)?;
    m.add_function(wrap_pyfunction!(attractors::classify_basins, m)?)?;
    m.add_function(wrap_pyfunction!(mass_ratio::optimize_mass_ratio, m)?)?;
    m.add_function(wrap_pyfunction!(spice::export_spice, m)?)?;
    m.add(
        "DEFAULT_START_PERIODS",
        vibrotribo::attractors::DEFAULT_START_PERIODS,
    )?;
    m.add("MAX_GRID_POINTS", vibrotribo::study::limits::MAX_GRID_POINTS)?;
    m.add("MAX_MEMORY_BYTES", vibrotribo::study::limits::MAX_MEMORY_BYTES)?;
    m.add_function(wrap_pyfunction!(optimize::optimize, m)?)?;
    m.add_function(wrap_pyfunction!(response::response, m)?)?;
    m.add_function(wrap_pyfunction!(response::band_response, m)?)?;
    m.add_function(wrap_pyfunction!(grid, m)?)?;
    m.add_function(wrap_pyfunction!(log_spaced, m)?)?;
    m.add("OrbitNotFound", m.py().get_type::<orbits::OrbitNotFound>())?;
    Ok(())
}
