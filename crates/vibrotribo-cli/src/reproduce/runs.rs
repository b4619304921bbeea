//! Running the paper's cases: configurations, parallel sweeps, and runs that keep time
//! histories; small numerical helpers.

use anyhow::{Context, Result};
use rayon::prelude::*;
use toml::Value;
use vibrotribo::config::Config;
use vibrotribo::electrical::ElectricalSamples;
use vibrotribo::study::{ElectricalOutcome, PointResult, RunObserver, RunSpec, Sample, Sampling, simulate};
use vibrotribo::{ChainParams, Event, EventKind, StateView};

use super::context::Ctx;
use crate::progress::check_interrupt;

/// A configuration built from `sets` on top of the paper's defaults.
pub(super) fn config(sets: &[(&str, Value)]) -> Result<Config> {
    let mut c = Config::default();
    for (k, v) in sets {
        c.set(k, v.clone()).with_context(|| format!("setting {k}"))?;
    }
    Ok(c)
}

/// `config` with the numeric `key` set to `value`.
/// The paper's chatter case (Sect. 4.4, Figs. 20–25): m1 = m3 = 50 g, R_m = 3, δ1 = δ2 = 5 mm.
pub(super) fn chatter_case() -> Result<Config> {
    config(&[
        ("oscillator.masses", arr(&[0.05, 0.15, 0.05])),
        ("oscillator.gaps", arr(&[0.005, 0.005])),
    ])
}

pub(super) fn with(config: &Config, key: &str, value: f64) -> Result<Config> {
    crate::config::with(config, key, value)
}

pub(super) fn arr(v: &[f64]) -> Value {
    Value::Array(v.iter().map(|x| Value::Float(*x)).collect())
}

pub(super) fn f(x: f64) -> Value {
    Value::Float(x)
}

/// Runs `values` of `key` in parallel, each from rest; the results in grid order. Points whose
/// charge solver failed are noted in `ctx.failures`.
pub(super) fn sweep(
    ctx: &Ctx,
    base: &Config,
    key: &str,
    values: &[f64],
    mechanics_only: bool,
) -> Result<Vec<PointResult>> {
    let runner = ctx.run_args(mechanics_only).runner(base.clone())?;
    let results: Vec<Result<PointResult>> = values
        .par_iter()
        .map(|&v| runner.run(&[(key, v)], None).map_err(anyhow::Error::from))
        .collect();
    check_interrupt(|| format!("during a sweep of {key}; REPORT.md is written only by a complete run"))?;
    let results: Vec<PointResult> = results
        .into_iter()
        .zip(values)
        .map(|(r, v)| r.with_context(|| format!("{key} = {v}")))
        .collect::<Result<_>>()?;
    let mut failures = ctx.failures.lock().expect("not poisoned");
    for (r, v) in results.iter().zip(values) {
        if let Some(e) = &r.electrical_error {
            failures.push(format!("{key} = {v}: {e}"));
        }
    }
    Ok(results)
}

/// Samples and impacts of one run, for time histories.
#[derive(Default)]
pub(super) struct Series1 {
    pub(super) t: Vec<f64>,
    pub(super) x: Vec<Vec<f64>>,
    pub(super) v: Vec<Vec<f64>>,
    /// The gaps d_k, m.
    pub(super) d: Vec<Vec<f64>>,
    /// Their rates d_k', m/s.
    pub(super) rate: Vec<Vec<f64>>,
    /// Each impact's contact (0-based) and the positions of the masses then.
    pub(super) impacts: Vec<(usize, Vec<f64>)>,
}

/// Collects the samples of the last periods of a run and its impacts there.
pub(super) struct SeriesCollector {
    pub(super) keep_from: f64,
    pub(super) data: Series1,
    pub(super) electrical: ElectricalSamples,
}

impl RunObserver for SeriesCollector {
    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, s: &Sample<'_>) {
        if s.time < self.keep_from {
            return;
        }
        self.data.t.push(s.time);
        push_each(&mut self.data.x, s.positions);
        push_each(&mut self.data.v, s.velocities);
        push_each(&mut self.data.d, s.gaps);
        let v = s.velocities;
        for (k, r) in self.data.rate.iter_mut().enumerate() {
            r.push(-(v[k + 1] - v[k]));
        }
        if let Some(e) = &s.electrical {
            let out = &mut self.electrical;
            out.times.push(s.time);
            out.charge_c.push(e.charge_c);
            out.current_a.push(e.current_a);
            out.voltage_v.push(e.voltage_v);
            out.capacitance_f.push(e.capacitance_f);
            out.voc_v.push(e.voc_v);
            if let Some(vs) = e.storage_voltage_v {
                out.storage_voltage_v.push(vs);
            }
        }
    }

    fn event(&mut self, e: &Event, state: &StateView<'_>) {
        if e.kind == EventKind::Impact && e.time >= self.keep_from {
            self.data.impacts.push((e.contact, state.positions.to_vec()));
        }
    }
}

/// Appends `values[i]` to `series[i]`.
pub(super) fn push_each(series: &mut [Vec<f64>], values: &[f64]) {
    for (s, &v) in series.iter_mut().zip(values) {
        s.push(v);
    }
}

/// One run of `periods` periods keeping samples (and the harvester's electrical samples) of
/// the last `keep` periods at `spp` samples per period.
pub(super) struct Run {
    pub(super) params: ChainParams,
    pub(super) series: Series1,
    /// The harvester's electrical samples of the kept periods (empty without one).
    pub(super) samples: ElectricalSamples,
    /// What the harvester delivered over the whole run.
    pub(super) electrical: Option<ElectricalOutcome>,
}

pub(super) fn run_series(
    config: &Config,
    periods: u64,
    keep: u64,
    spp: u64,
    electrical: bool,
) -> Result<Run> {
    let params = config.chain().clone();
    let n = params.len();
    let period = params.period();
    let keep_from = (periods - keep.min(periods)) as f64 * period;
    let spec = RunSpec {
        periods,
        sampling: Some(Sampling::Uniform {
            start: 0.0,
            step: period / spp as f64,
        }),
        ..config.run_spec(!electrical)
    };
    let mut obs = SeriesCollector {
        keep_from,
        data: Series1 {
            x: vec![Vec::new(); n],
            v: vec![Vec::new(); n],
            d: vec![Vec::new(); n - 1],
            rate: vec![Vec::new(); n - 1],
            ..Series1::default()
        },
        electrical: ElectricalSamples::default(),
    };
    let outcome = simulate(&spec, &mut obs)?;
    if let Some(e) = outcome.failure() {
        return Err(e.clone().into());
    }
    Ok(Run {
        params,
        series: obs.data,
        samples: obs.electrical,
        electrical: outcome.electrical,
    })
}

pub(super) fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The motion of a point that is not periodic after settling: `chaotic`, `quasiperiodic`
/// or `settling` (`non-periodic` if it was not classified).
pub(super) fn motion_of(r: &PointResult) -> &'static str {
    r.motion.as_ref().map_or("non-periodic", |m| m.motion.as_str())
}

/// The values of `values` whose point is not periodic, by motion (`chaotic: 1.2–1.4;
/// quasiperiodic: …`), or `none`.
pub(super) fn describe_motions(values: &[f64], results: &[PointResult], step: f64) -> String {
    let mut parts = Vec::new();
    for kind in ["chaotic", "quasiperiodic", "settling", "non-periodic"] {
        let at: Vec<f64> = values
            .iter()
            .zip(results)
            .filter(|(_, r)| r.period() == 0 && motion_of(r) == kind)
            .map(|(v, _)| *v)
            .collect();
        if !at.is_empty() {
            parts.push(format!("{kind} at {}", describe_ranges(&at, step)));
        }
    }
    if parts.is_empty() {
        "none".into()
    } else {
        parts.join("; ")
    }
}

pub(super) fn describe_ranges(values: &[f64], step: f64) -> String {
    if values.is_empty() {
        return "none".into();
    }
    let mut out = Vec::new();
    let mut start = values[0];
    let mut last = values[0];
    for &v in &values[1..] {
        if v - last > 1.5 * step {
            out.push((start, last));
            start = v;
        }
        last = v;
    }
    out.push((start, last));
    out.iter()
        .map(|(a, b)| {
            if (b - a).abs() < 1e-12 {
                format!("{a:.2}")
            } else {
                format!("{a:.2}–{b:.2}")
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}
