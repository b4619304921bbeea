//! `vibrotribo.chirp`: the frequency-sweep experiment ([`vibrotribo::study::run_chirp`]),
//! the chain driven by a slow chirp of the base up and then down in Ω; the per-cycle
//! response in the columns of the command line's `response.csv` and the jumps of
//! `chirp.json`.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibrotribo::excitation::Sweep;
use vibrotribo::study::{
    ChirpError, ChirpOptions, ChirpRun, DEFAULT_JUMP_WINDOW, DEFAULT_SAMPLES_PER_CYCLE, Direction, Ending,
    chirp_inputs, run_chirp,
};
use vibrotribo::sweep::{Cell, Kind, Table};

use crate::config::{config_error, config_of};
use crate::convert::table_to_py;
use crate::interrupt::{Signals, cancel_hook, cancel_result};
use crate::manifest::{ChirpSettings, json_error, manifest_dict};
use vibrotribo::report::manifest::{ChirpSettingsRecord, Kind as ManifestKind, settings_of, version};

/// A library error in the words of the Python function (`from_`, `duration`, …).
fn chirp_error(e: ChirpError) -> PyErr {
    match e {
        ChirpError::Option { option, message } => {
            let name = if option == "from" { "from_" } else { option };
            PyValueError::new_err(format!("{name}: {message}"))
        }
        ChirpError::Config(c) => config_error(c),
        other => PyValueError::new_err(other.to_string()),
    }
}

fn run_to_py<'py>(py: Python<'py>, r: &ChirpRun) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("f_start_hz", r.chirp.f_start_hz)?;
    d.set_item("f_end_hz_requested", r.chirp.frequency_hz(r.duration_s))?;
    d.set_item("run_duration_s", r.chirp.duration)?;
    d.set_item("periods", r.outcome.periods)?;
    d.set_item("cycles", r.cycles.len())?;
    d.set_item("impacts", r.cycles.iter().map(|c| c.impacts).sum::<u64>())?;
    d.set_item("complete", r.outcome.ending == Ending::Completed)?;
    d.set_item("failure", r.outcome.failure().map(|e| e.to_string()))?;
    let jump = match &r.jump {
        Some(j) => {
            let jd = PyDict::new(py);
            jd.set_item("omega_ratio", j.omega_ratio)?;
            jd.set_item("frequency_hz", r.chirp.frequency_hz(r.cycles[j.index].end_s))?;
            jd.set_item("cycle", r.cycles[j.index].cycle)?;
            jd.set_item("mass", j.mass + 1)?;
            jd.set_item("size_m", j.size_m)?;
            jd.set_item("relative", j.relative)?;
            Some(jd)
        }
        None => None,
    };
    d.set_item("jump", jump)?;
    Ok(d)
}

/// Runs the chirp experiment (see the Python `vibrotribo.chirp`).
#[pyfunction]
#[pyo3(signature = (config, from_, to, duration, *, sweep = String::from("linear"), amplitude = None, mechanics_only = false, from_rest = false, samples_per_cycle = DEFAULT_SAMPLES_PER_CYCLE, jump_window = DEFAULT_JUMP_WINDOW))]
#[allow(clippy::too_many_arguments)]
pub fn chirp<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    from_: f64,
    to: f64,
    duration: f64,
    sweep: String,
    amplitude: Option<f64>,
    mechanics_only: bool,
    from_rest: bool,
    samples_per_cycle: u64,
    jump_window: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let law = match sweep.as_str() {
        "linear" => Sweep::Linear,
        "logarithmic" => Sweep::Logarithmic,
        other => {
            return Err(PyValueError::new_err(format!(
                "sweep: unknown {other:?}, expected \"linear\" or \"logarithmic\""
            )));
        }
    };
    let config = config_of(config)?;
    // The settling at the start frequency runs Python's signal handlers too.
    let (cancel, settling) = cancel_hook();
    let options = ChirpOptions {
        from: from_,
        to,
        duration_s: duration,
        sweep: law,
        amplitude,
        mechanics_only,
        settled_start: !from_rest,
        samples_per_cycle,
        jump_window,
        cancel,
        ..ChirpOptions::new(from_, to, duration)
    };
    // Both chirps checked first: a bad option fails before anything runs.
    let (spec, options) = chirp_inputs(&config, &options).map_err(chirp_error)?;
    let (runs, signals) = py.detach(|| {
        let mut signals = Signals::new();
        let mut runs = Vec::new();
        for d in [Direction::Up, Direction::Down] {
            match run_chirp(&spec, &options, d, &mut signals) {
                Ok(r) => {
                    let stop = r.outcome.ending != Ending::Completed;
                    runs.push(r);
                    if stop {
                        break;
                    }
                }
                Err(e) => return (Err(e), signals),
            }
        }
        (Ok(runs), signals)
    });
    signals.result()?;
    cancel_result(&settling)?;
    let runs = runs.map_err(chirp_error)?;
    let n = config.chain().len();
    let power = !mechanics_only && n > 1;
    let mut names: Vec<String> = ["direction", "cycle", "time_s", "omega_ratio", "frequency_hz"]
        .map(String::from)
        .to_vec();
    let mut kinds = vec![Kind::Text, Kind::Int, Kind::Float, Kind::Float, Kind::Float];
    names.extend((1..=n).map(|i| format!("amplitude{i}_m")));
    kinds.extend((0..n).map(|_| Kind::Float));
    names.push("impacts".into());
    kinds.push(Kind::Int);
    if power {
        names.push("power_w".into());
        kinds.push(Kind::Float);
    }
    let mut response = Table::new(names, kinds);
    for r in &runs {
        for c in &r.cycles {
            let mut row = vec![
                Cell::Text(r.direction.as_str().to_string()),
                Cell::Int(c.cycle as i64),
                Cell::Float(c.time_s),
                Cell::Float(c.omega_ratio),
                Cell::Float(c.frequency_hz),
            ];
            row.extend(c.amplitudes.iter().map(|&a| Cell::Float(a)));
            row.push(Cell::Int(c.impacts as i64));
            if power {
                row.push(c.power_w().map_or(Cell::Missing, Cell::Float));
            }
            response.push_row(row);
        }
    }
    let out = PyDict::new(py);
    out.set_item("response", table_to_py(py, &response)?)?;
    let find = |d: Direction| runs.iter().find(|r| r.direction == d);
    for d in [Direction::Up, Direction::Down] {
        out.set_item(d.as_str(), find(d).map(|r| run_to_py(py, r)).transpose()?)?;
    }
    let settings = ChirpSettings {
        command: ManifestKind::Chirp,
        chirp: ChirpSettingsRecord::of(&config, &options, runs.first().map(|r| r.chirp.amplitude)),
        settings: settings_of(&config).map_err(json_error)?,
        vibrotribo_version: version(),
    };
    let s = manifest_dict(py, &settings)?;
    out.set_item("settings", s)?;
    out.set_item(
        "complete",
        runs.len() == 2 && runs.iter().all(|r| r.outcome.ending == Ending::Completed),
    )?;
    Ok(out)
}
