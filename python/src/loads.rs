//! `vibrotribo.load_sweep`: power against the load resistance (on one mechanical run, or a
//! coupled run per load under two-way coupling: [`vibrotribo::study::load_study`]), as
//! `vibrotribo load-sweep` writes it.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibrotribo::electrical::log_spaced;
use vibrotribo::study::{LoadStudyOptions, load_study};

use crate::config::config_of;
use crate::convert::{array1, json_to_py};
use crate::interrupt::Signals;

fn json<T: serde::Serialize>(py: Python<'_>, v: &T) -> PyResult<Py<PyAny>> {
    let value = serde_json::to_value(v).map_err(|e| PyValueError::new_err(e.to_string()))?;
    Ok(json_to_py(py, &value)?.unbind())
}

/// Runs a load sweep (see the Python `vibrotribo.load_sweep`).
#[pyfunction]
#[pyo3(signature = (config, *, resistances = None, low = 1e3, high = 1e13, steps = 41, vq_points = Some(400), allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn load_sweep<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    resistances: Option<Vec<f64>>,
    low: f64,
    high: f64,
    steps: usize,
    vq_points: Option<usize>,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(config)?;
    let resistances = match resistances {
        Some(r) => r,
        None => {
            if !(low.is_finite() && low > 0.0 && high.is_finite() && high >= low) {
                return Err(PyValueError::new_err(format!(
                    "low and high must be positive resistances with low ≤ high (got {low} and {high})"
                )));
            }
            if steps == 0 {
                return Err(PyValueError::new_err("steps must be at least 1"));
            }
            log_spaced(low, high, steps)
        }
    };
    if let Some(r) = resistances.iter().find(|r| !(r.is_finite() && **r > 0.0)) {
        return Err(PyValueError::new_err(format!(
            "resistances must be positive, got {r}"
        )));
    }
    crate::limits::check_grid("resistances", resistances.len() as f64)?;
    let spec = config.run_spec(false);
    let options = LoadStudyOptions {
        resistances,
        vq_points,
    };
    crate::limits::check_memory(
        "the V–Q curve (vq_points)",
        options.estimated_bytes(),
        allow_large,
    )?;
    let (study, signals) = py.detach(|| {
        let mut signals = Signals::new();
        (load_study(&spec, &options, &mut signals), signals)
    });
    signals.result()?;
    let study = study
        .map_err(|e| PyValueError::new_err(e.to_string()))?
        .ok_or_else(|| PyValueError::new_err("the mechanical run stopped"))?;
    let out = PyDict::new(py);
    let points = PyDict::new(py);
    let p = &study.sweep.points;
    points.set_item(
        "load_resistance_ohm",
        array1(py, p.iter().map(|x| x.resistance_ohm).collect()),
    )?;
    points.set_item(
        "average_power_w",
        array1(py, p.iter().map(|x| x.average_power_w).collect()),
    )?;
    points.set_item(
        "energy_per_period_j",
        array1(py, p.iter().map(|x| x.energy_per_period_j).collect()),
    )?;
    out.set_item("points", points)?;
    out.set_item("optimum", json(py, &study.sweep.optimum)?)?;
    out.set_item("optimum_at_edge", study.sweep.optimum_at_edge)?;
    out.set_item("configured_load_ohm", study.configured_load_ohm)?;
    out.set_item("configured_average_power_w", study.configured_average_power_w)?;
    let vq = PyDict::new(py);
    let cycles = &study.vq_cycles;
    let col = |f: &dyn Fn(&vibrotribo::study::VqCycle, usize) -> f64| -> Vec<f64> {
        cycles
            .iter()
            .flat_map(|c| (0..c.samples.times.len()).map(move |j| f(c, j)))
            .collect()
    };
    vq.set_item(
        "load_resistance_ohm",
        array1(py, col(&|c, _| c.load_resistance_ohm)),
    )?;
    vq.set_item("time_s", array1(py, col(&|c, j| c.samples.times[j])))?;
    vq.set_item("q_c", array1(py, col(&|c, j| c.samples.charge_c[j])))?;
    vq.set_item("v_v", array1(py, col(&|c, j| c.samples.voltage_v[j])))?;
    vq.set_item("i_a", array1(py, col(&|c, j| c.samples.current_a[j])))?;
    out.set_item("vq_cycle", vq)?;
    let margins = PyList::empty(py);
    for c in cycles {
        let d = PyDict::new(py);
        d.set_item("load_resistance_ohm", c.load_resistance_ohm)?;
        d.set_item("air_breakdown", json(py, &c.breakdown)?)?;
        margins.append(d)?;
    }
    out.set_item("air_breakdown_last_period", margins)?;
    out.set_item("periods", spec.periods)?;
    out.set_item("transient_periods", spec.transient_periods)?;
    Ok(out)
}
