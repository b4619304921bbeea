//! The `settings` of the results, as the command line's manifests record them: each dict is
//! the JSON form of the library's manifest type ([`vibrotribo::report::manifest`]) or of a
//! struct built from its shared groups of keys, less the keys that only a command's output
//! directory has ([`CLI_ONLY`]).

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde::Serialize;
use serde_json::Value;
use vibrotribo::report::BaseMotionSummary;
use vibrotribo::report::manifest::{
    Axis, ChirpSettingsRecord, Kind, PeriodsRecord, RunnerRecord, SettleRecord, base_motion_of, settings_of,
    version,
};
use vibrotribo::sweep::PointRunner;

use crate::convert::json_to_py;

/// The keys of the command line's manifests that a result in Python has no use for: the shard
/// of a grid job, its progress and its wall time.
pub const CLI_ONLY: &[&str] = &["shard", "complete", "done", "wall_time_s"];

/// The error of a manifest that cannot be written as JSON.
pub fn json_error(e: serde_json::Error) -> PyErr {
    PyValueError::new_err(format!("cannot write the settings: {e}"))
}

/// `manifest` as a settings dict: the keys of its JSON form in their order, less
/// [`CLI_ONLY`].
pub fn manifest_dict<'py>(py: Python<'py>, manifest: &impl Serialize) -> PyResult<Bound<'py, PyDict>> {
    let mut v = serde_json::to_value(manifest).map_err(json_error)?;
    if let Some(o) = v.as_object_mut() {
        for k in CLI_ONLY {
            o.remove(*k);
        }
    }
    Ok(json_to_py(py, &v)?.cast_into::<PyDict>()?)
}

/// Adds to `d` the keys of `record`'s JSON form that it does not have yet.
pub fn add_missing(d: &Bound<'_, PyDict>, record: &impl Serialize) -> PyResult<()> {
    let extra = manifest_dict(d.py(), record)?;
    for (k, v) in extra.iter() {
        if !d.contains(&k)? {
            d.set_item(k, v)?;
        }
    }
    Ok(())
}

/// The settings of a study on the point runner: its command, the swept axis if any, the
/// runner's periods, tolerances and `mechanics_only`, how the points settled, the
/// configuration, its base motion and the library's version.
#[derive(Debug, Serialize)]
pub struct RunnerSettings {
    /// The command whose manifest these keys are.
    pub command: Kind,
    /// The swept key and its values (`param`, `from`, `to`, `steps`, `values`).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Axis>,
    /// The point runner's keys.
    #[serde(flatten)]
    pub runner: RunnerRecord,
    /// How each point settled.
    #[serde(flatten)]
    pub settle: SettleRecord,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
    /// The library's version.
    pub vibrotribo_version: String,
}

impl RunnerSettings {
    /// The settings of `command` run by `runner` over `axis`, as a dict.
    pub fn dict<'py>(
        py: Python<'py>,
        command: Kind,
        axis: Option<Axis>,
        runner: &PointRunner,
    ) -> PyResult<Bound<'py, PyDict>> {
        let s = RunnerSettings {
            command,
            axis,
            runner: RunnerRecord::of(runner),
            settle: SettleRecord::of(runner.options()),
            settings: settings_of(runner.base()).map_err(json_error)?,
            base_motion: base_motion_of(runner.base()),
            vibrotribo_version: version(),
        };
        manifest_dict(py, &s)
    }
}

/// The settings of `optimize_mass_ratio`: the grid of Ω and mass ratios, the periods of each
/// point, `mechanics_only` and the configuration.
#[derive(Debug, Serialize)]
pub struct MassRatioSettings {
    /// Always [`Kind::OptimizeMassRatio`].
    pub command: Kind,
    /// The values of Ω.
    pub omega_values: Vec<f64>,
    /// The mass ratios tried at each.
    pub mass_ratio_values: Vec<f64>,
    /// Transient and recorded periods per point.
    #[serde(flatten)]
    pub periods: PeriodsRecord,
    /// Mechanics only (no harvester).
    pub mechanics_only: bool,
    /// The configuration (the library's document).
    pub settings: Value,
}

/// The settings of `chirp`: the chirp's settings as `chirp.json` records them and the
/// configuration.
#[derive(Debug, Serialize)]
pub struct ChirpSettings {
    /// Always [`Kind::Chirp`].
    pub command: Kind,
    /// Range, duration, law, amplitude, start, sampling, how a jump is found.
    #[serde(flatten)]
    pub chirp: ChirpSettingsRecord,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The library's version.
    pub vibrotribo_version: String,
}
