//! `vibrotribo.simulate`: one run through the library's run layer
//! ([`vibrotribo::study::simulate`]), its samples and events as numpy arrays and its summary
//! as `summary.json` holds it ([`vibrotribo::report::RunSummary`]).

use std::time::Instant;

use numpy::PyArray1;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibrotribo::electrical::LoadKind;
use vibrotribo::report::{MeritSummary, RunSummary, failure_text};
use vibrotribo::study::{
    DEFAULT_SETTLE_CAP, Ending, PointError, Recording, RunMotion, SettleMode, limits, settle as settle_run,
    simulate as run,
};

use crate::config::{config_error, config_of};
use crate::convert::{array1, array2, serde_to_py};
use crate::interrupt::{Signals, cancel_hook, cancel_result};
use crate::limits::check_memory;

/// Runs the configuration (see the Python `vibrotribo.simulate`) and returns a dict of
/// arrays, the events and the summary.
#[pyfunction]
#[pyo3(signature = (config, *, mechanics_only = false, samples = true, settle = String::from("fixed"), settle_cap = DEFAULT_SETTLE_CAP, allow_large = false))]
pub fn simulate<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    mechanics_only: bool,
    samples: bool,
    settle: String,
    settle_cap: u64,
    allow_large: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let config = config_of(config)?;
    let mut spec = config.sampled_run_spec(mechanics_only);
    spec.breakdown_check = true;
    let spp = config.run().samples_per_period;
    check_memory(
        &if samples {
            format!(
                "run.periods = {} with run.samples_per_period = {spp} held in memory (samples=False keeps none)",
                spec.periods
            )
        } else {
            format!("run.periods = {} (per-period statistics)", spec.periods)
        },
        limits::run_memory_bytes(&spec, spp, samples),
        allow_large,
    )?;
    let mode: SettleMode = settle
        .parse()
        .map_err(|e: vibrotribo::study::UnknownSettleMode| PyValueError::new_err(format!("settle: {e}")))?;
    let mode = mode.with_cap(settle_cap);
    let mut motion = RunMotion::new(&spec).map_err(|e| PyValueError::new_err(e.to_string()))?;
    if let SettleMode::Auto(_) = &mode {
        config
            .check_periodic("simulate(settle=\"auto\") (settling to a periodic motion)")
            .map_err(config_error)?;
        if settle_cap == 0 {
            return Err(PyValueError::new_err("settle_cap: must be at least 1"));
        }
    }
    motion.options_mut().settle = mode;
    // The settling runs Python's signal handlers too.
    let (cancel, settling) = cancel_hook();
    motion.options_mut().cancel = cancel;
    let periodic = config.is_periodic();
    let computed = py.detach(|| {
        let mut recording = Recording::new(samples);
        let mut signals = Signals::new();
        let started = Instant::now();
        let settled = match &mode {
            SettleMode::Auto(auto) => {
                match settle_run(&spec.chain, &spec.initial, &spec.options, motion.options(), auto) {
                    Ok(s) => {
                        spec.initial = s.state.clone();
                        Some(s)
                    }
                    // A stop is the signal handler's exception, raised below.
                    Err(PointError::Stopped { .. }) => return Err(None),
                    Err(e) => return Err(Some(PyValueError::new_err(format!("while settling: {e}")))),
                }
            }
            SettleMode::Fixed => None,
        };
        // The figures of merit, as the command line's summary.json reports them.
        let mut merit = spec.harvester.as_ref().map(|h| {
            let period = spec.chain.period();
            vibrotribo::merit::MeritWatch::new(
                &h.params,
                &spec.chain.gaps,
                spec.transient_periods as f64 * period,
                period,
            )
        });
        let outcome = run(
            &spec,
            &mut ((&mut recording, &mut merit), (&mut signals, motion.observer())),
        );
        // The motion after the transient, as the command line's summary.json reports it (a
        // base motion that is not periodic has no period to classify against).
        let report = outcome.as_ref().ok().and_then(|o| {
            (o.ending == Ending::Completed && periodic)
                .then(|| motion.finish(&spec, &o.final_state, settled.as_ref()))
        });
        Ok((
            outcome,
            recording,
            started.elapsed().as_secs_f64(),
            signals,
            (report, merit),
        ))
    });
    let (outcome, recording, elapsed, signals, report) = match computed {
        Ok(c) => c,
        Err(Some(e)) => return Err(e),
        Err(None) => {
            cancel_result(&settling)?;
            return Err(PyKeyboardInterrupt::new_err("interrupted while settling"));
        }
    };
    let (report, merit) = report;
    signals.result()?;
    cancel_result(&settling)?;
    let outcome = outcome.map_err(|e| PyValueError::new_err(e.to_string()))?;
    let n = spec.chain.len();
    let out = PyDict::new(py);
    let s = recording.samples;
    out.set_item("t", array1(py, s.time))?;
    out.set_item("x", array2(py, s.positions, n)?)?;
    out.set_item("v", array2(py, s.velocities, n)?)?;
    out.set_item("y", array1(py, s.base))?;
    out.set_item("d", array2(py, s.gaps, n - 1)?)?;
    if let Some(h) = &spec.harvester {
        out.set_item("q", array1(py, s.charge_c))?;
        out.set_item("i", array1(py, s.current_a))?;
        out.set_item("v_load", array1(py, s.voltage_v))?;
        out.set_item("c", array1(py, s.capacitance_f))?;
        out.set_item("voc", array1(py, s.voc_v))?;
        if h.params.load.kind() == LoadKind::Rectifier {
            out.set_item("vs", array1(py, s.storage_voltage_v))?;
        }
    }
    let e = recording.events;
    let events = PyDict::new(py);
    events.set_item("t", array1(py, e.time))?;
    events.set_item("kind", PyList::new(py, e.kind.iter().map(|k| k.as_str()))?)?;
    let contact: Vec<i64> = e.contact.iter().map(|&k| k as i64 + 1).collect();
    events.set_item("contact", PyArray1::from_vec(py, contact))?;
    events.set_item("speed_before", array1(py, e.velocity_before))?;
    events.set_item("speed_after", array1(py, e.velocity_after))?;
    let seq: Vec<i64> = e.sequence_impacts.iter().map(|&s| i64::from(s)).collect();
    events.set_item("sequence_impacts", PyArray1::from_vec(py, seq))?;
    events.set_item("x", array2(py, e.positions, n)?)?;
    events.set_item("v", array2(py, e.velocities, n)?)?;
    out.set_item("events", events)?;
    let mut summary = RunSummary::new(&config, &spec, &outcome, elapsed);
    summary.set_settle(&motion.options().settle);
    summary.set_motion(report.as_ref());
    if let Some(w) = &merit {
        let energy = outcome
            .electrical
            .as_ref()
            .and_then(|e| e.power.as_ref())
            .map(|p| p.energy_per_period_j);
        summary.merit = Some(MeritSummary::of(w.finish(energy).as_ref()));
    }
    out.set_item("summary", serde_to_py(py, &summary)?)?;
    out.set_item("error", failure_text(&outcome))?;
    Ok(out)
}
