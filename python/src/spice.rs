//! `vibrotribo.export_spice`: a run's harvester as an ngspice netlist driven by its gap
//! waveforms ([`vibrotribo::study::spice_export`]), the text the command line's
//! `export-spice` writes, and optionally the check against ngspice.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::study::{
    DEFAULT_SPICE_DT_FRACTION, DEFAULT_SPICE_PERIODS, SPICE_DATA_FILE, SpiceExportError, spice_check,
    spice_export, spice_export_bytes,
};

use crate::config::config_of;
use crate::convert::{array1, array2};

fn export_error(e: SpiceExportError) -> PyErr {
    match e {
        SpiceExportError::Option { .. }
        | SpiceExportError::Param(_)
        | SpiceExportError::OneMass
        | SpiceExportError::TwoWay => PyValueError::new_err(e.to_string()),
        other => PyRuntimeError::new_err(other.to_string()),
    }
}

/// The netlist of a configuration's run (see the Python `vibrotribo.export_spice`).
#[pyfunction]
#[pyo3(signature = (config, *, from_period = None, periods = DEFAULT_SPICE_PERIODS, dt_fraction = DEFAULT_SPICE_DT_FRACTION, check = false, allow_large = false))]
#[allow(clippy::too_many_arguments)]
pub fn export_spice<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    from_period: Option<u64>,
    periods: u64,
    dt_fraction: f64,
    check: bool,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(config)?;
    // The PWL waveforms' size, checked before they are built (as `export-spice` does).
    if let Some(bytes) = spice_export_bytes(&config, periods, dt_fraction) {
        crate::limits::check_memory(
            "the netlist's PWL waveforms (periods / dt_fraction)",
            bytes,
            allow_large,
        )?;
    }
    let export = py
        .detach(|| spice_export(&config, from_period, periods, dt_fraction))
        .map_err(export_error)?;
    let out = PyDict::new(py);
    out.set_item("netlist", &export.netlist)?;
    out.set_item("data_file", SPICE_DATA_FILE)?;
    out.set_item("from_period", export.from_period)?;
    out.set_item("periods", export.periods)?;
    out.set_item("window_s", export.window_s)?;
    out.set_item("pwl_times_s", array1(py, export.pwl.times().to_vec()))?;
    let pwl = &export.pwl;
    let contacts = pwl.gap_count();
    let flat: Vec<f64> = (0..pwl.times().len())
        .flat_map(|j| (0..contacts).map(move |k| pwl.value(j, k)))
        .collect();
    out.set_item("pwl_gaps_m", array2(py, flat, contacts)?)?;
    if check {
        let (ours, theirs, elapsed) = py
            .detach(|| spice_check(&config, &export))
            .map_err(export_error)?;
        out.set_item("energy_j", ours)?;
        out.set_item("ngspice_energy_j", theirs)?;
        out.set_item("ngspice_s", elapsed)?;
    }
    Ok(out)
}
