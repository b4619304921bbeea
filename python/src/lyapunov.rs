//! `vibrotribo.lyapunov`: the Lyapunov spectrum of a run through the library's run layer
//! ([`vibrotribo::study::lyapunov_spectrum`]). Exponents a stuck contact removes are `-inf`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::lyapunov::LyapunovOptions;
use vibrotribo::study::lyapunov_spectrum;

use crate::config::{config_error, config_of};
use crate::convert::{array1, array2};
use crate::interrupt::Signals;

/// The Lyapunov spectrum of the configuration's run (see the Python `vibrotribo.lyapunov`).
#[pyfunction]
#[pyo3(signature = (config, *, periods = 1000, transient = 300, seed = 1, batches = 10))]
pub fn lyapunov<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    periods: u64,
    transient: u64,
    seed: u64,
    batches: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if periods == 0 {
        return Err(PyValueError::new_err("periods: must be at least 1"));
    }
    let config = config_of(config)?;
    config.check_uncoupled("lyapunov").map_err(config_error)?;
    config
        .check_periodic("Lyapunov exponents")
        .map_err(crate::config::config_error)?;
    let mut spec = config.run_spec(true);
    spec.periods = transient
        .checked_add(periods)
        .ok_or_else(|| PyValueError::new_err("transient + periods: too large"))?;
    spec.transient_periods = transient;
    let options = LyapunovOptions {
        seed,
        batches,
        ..LyapunovOptions::default()
    };
    let (run, signals) = py.detach(|| {
        let mut signals = Signals::new();
        let run = lyapunov_spectrum(&spec, &options, &mut signals);
        (run, signals)
    });
    signals.result()?;
    let run = run.map_err(|e| PyValueError::new_err(e.to_string()))?;
    let s = run.spectrum.map_err(|e| PyValueError::new_err(e.to_string()))?;
    let out = PyDict::new(py);
    out.set_item("exponents", array1(py, s.exponents.clone()))?;
    out.set_item("spread", array1(py, s.spread.clone()))?;
    out.set_item("largest", s.largest())?;
    out.set_item("largest_spread", s.largest_spread())?;
    out.set_item("sum", s.sum())?;
    out.set_item("kaplan_yorke_dimension", s.kaplan_yorke_dimension())?;
    out.set_item("collapsed", s.collapsed)?;
    out.set_item("periods", s.periods)?;
    out.set_item("time_s", s.time)?;
    out.set_item("skipped_periods", s.skipped_periods)?;
    let dim = s.exponents.len();
    let running_periods: Vec<f64> = s.running.iter().map(|(p, _)| *p as f64).collect();
    let running: Vec<f64> = s.running.iter().flat_map(|(_, e)| e.iter().copied()).collect();
    out.set_item("running_periods", array1(py, running_periods))?;
    out.set_item("running", array2(py, running, dim)?)?;
    Ok(out)
}
