//! `vibrotribo simulate`: one run of the chain and its harvester, with a human summary and
//! optional files.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use vibrotribo::analysis::RunStats;
use vibrotribo::electrical::{
    ChargeSolver, ElectricalSamples, HarvesterParams, LoadKind, PowerSummary, TransducerMode,
};
use vibrotribo::{ChainParams, Event, Flow, Observer, Simulator, StateView};

use crate::config::{ConfigArgs, Loaded, RunSpec};
use crate::limits;
use crate::output::{CsvFile, create_dir, numbered, si, write_json};
use crate::progress::{Interrupted, Progress, interrupted};

/// Options of `vibrotribo simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Write events.csv, trajectory.csv and summary.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Mechanics only: skip the triboelectric harvester.
    #[arg(long)]
    pub mechanics_only: bool,
    /// Also write the per-run analyses (Poincaré sections, PSDs) and draw the pictures
    /// (needs --out).
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run even if the estimated output exceeds 20 GiB or the memory 4 GiB.
    #[arg(long)]
    pub allow_large: bool,
}

/// Streams `events.csv` and `trajectory.csv` as the simulation goes.
struct Files {
    events: CsvFile,
    trajectory: CsvFile,
    period: f64,
    per_period: u64,
    next_sample: u64,
    last_sample: u64,
    gaps: Vec<f64>,
    x: Vec<f64>,
    v: Vec<f64>,
    /// The gaps d_k at the current sample, m.
    d: Vec<f64>,
    row: Vec<f64>,
    rectifier: bool,
    /// Whether there are electrical columns.
    electrical: bool,
    error: Option<anyhow::Error>,
}

impl Files {
    fn create(
        dir: &Path,
        params: &ChainParams,
        spec: &RunSpec,
        harvester: Option<&HarvesterParams>,
    ) -> Result<Self> {
        create_dir(dir)?;
        let n = params.len();
        let mut ev_cols: Vec<String> = [
            "time_s",
            "kind",
            "contact",
            "rel_velocity_m_s",
            "rel_velocity_after_m_s",
            "sequence_impacts",
        ]
        .map(String::from)
        .to_vec();
        ev_cols.extend(numbered("x", n, "_m"));
        ev_cols.extend(numbered("v", n, "_m_s"));
        let mut tr_cols = vec!["time_s".to_string()];
        tr_cols.extend(numbered("x", n, "_m"));
        tr_cols.extend(numbered("v", n, "_m_s"));
        let rectifier = harvester.is_some_and(|h| h.load == LoadKind::Rectifier);
        if harvester.is_some() {
            tr_cols.extend(["q_c", "i_a", "v_v", "c_f", "voc_v"].map(String::from));
            if rectifier {
                tr_cols.push("vs_v".into());
            }
        }
        tr_cols.push("y_m".into());
        tr_cols.extend(numbered("d", n - 1, "_m"));
        Ok(Files {
            events: CsvFile::create(&dir.join("events.csv"), &ev_cols)?,
            trajectory: CsvFile::create(&dir.join("trajectory.csv"), &tr_cols)?,
            period: params.period(),
            per_period: spec.samples_per_period,
            next_sample: 0,
            last_sample: spec.periods * spec.samples_per_period,
            gaps: params.gaps.clone(),
            x: vec![0.0; n],
            v: vec![0.0; n],
            d: vec![0.0; n - 1],
            row: Vec::with_capacity(tr_cols.len()),
            rectifier,
            electrical: harvester.is_some(),
            error: None,
        })
    }

    fn keep(&mut self, r: Result<()>) {
        if let (Err(e), None) = (r, &self.error) {
            self.error = Some(e);
        }
    }

    fn flush(&mut self) -> Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.events.flush()?;
        self.trajectory.flush()
    }

    /// Writes the grid rows inside `flow`; electrical columns come from `samples`, which the
    /// charge solver has just recorded for this flow (same grid, t_j = T·(j/per_period)).
    fn rows(&mut self, flow: &Flow<'_>, samples: Option<&ElectricalSamples>) {
        let mut cursor = 0;
        while self.next_sample <= self.last_sample {
            let j = self.next_sample;
            let t = self.period * (j as f64 / self.per_period as f64);
            if t > flow.t_end {
                break;
            }
            flow.state_at(t, &mut self.x, &mut self.v);
            let (y, _) = flow.base_at(t);
            for (k, d) in self.d.iter_mut().enumerate() {
                *d = self.gaps[k] - (self.x[k + 1] - self.x[k]);
            }
            self.row.clear();
            self.row.push(t);
            self.row.extend_from_slice(&self.x);
            self.row.extend_from_slice(&self.v);
            if self.electrical {
                let idx = cursor;
                let at = |v: &[f64]| v.get(idx).copied().unwrap_or(f64::NAN);
                let e = samples.filter(|s| s.times.get(idx).is_some_and(|&ts| ts == t));
                if e.is_some() {
                    cursor += 1;
                }
                let get = |f: fn(&ElectricalSamples) -> &Vec<f64>| e.map_or(f64::NAN, |s| at(f(s)));
                self.row.push(get(|s| &s.charge_c));
                self.row.push(get(|s| &s.current_a));
                self.row.push(get(|s| &s.voltage_v));
                self.row.push(get(|s| &s.capacitance_f));
                self.row.push(get(|s| &s.voc_v));
                if self.rectifier {
                    self.row.push(get(|s| &s.storage_voltage_v));
                }
            }
            self.row.push(y);
            self.row.extend_from_slice(&self.d);
            let r = self.trajectory.row(self.row.iter());
            self.keep(r);
            self.next_sample += 1;
        }
    }

    fn event(&mut self, e: &Event, state: &StateView<'_>) {
        let fields: Vec<String> = [
            e.time.to_string(),
            e.kind.as_str().to_string(),
            (e.contact + 1).to_string(),
            e.velocity_before.to_string(),
            e.velocity_after.to_string(),
            e.sequence_impacts.to_string(),
        ]
        .into_iter()
        .chain(state.positions.iter().map(f64::to_string))
        .chain(state.velocities.iter().map(f64::to_string))
        .collect();
        let r = self.events.row(fields);
        self.keep(r);
    }
}

/// Everything that watches a `simulate` run.
struct Recorder {
    stats: RunStats,
    solver: Option<ChargeSolver>,
    files: Option<Files>,
}

impl Observer for Recorder {
    fn flow(&mut self, flow: &Flow<'_>) {
        if let Some(s) = &mut self.solver {
            s.flow(flow);
        }
        if let Some(f) = &mut self.files {
            let fresh = self.solver.as_mut().map(ChargeSolver::take_samples);
            f.rows(flow, fresh.as_ref());
        }
    }

    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.stats.event(event, state);
        if let Some(f) = &mut self.files {
            f.event(event, state);
        }
    }
}

/// Runs `vibrotribo simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    if args.plot && args.out.is_none() {
        anyhow::bail!("--plot needs --out DIR");
    }
    let loaded = args.input.load()?;
    let params = loaded.config.chain_params()?;
    let spec = loaded.config.run_spec(&params)?;
    let options = loaded.config.sim_options()?;
    let harvester = if args.mechanics_only {
        None
    } else {
        Some(loaded.harvester(&params)?)
    };
    let period = params.period();
    check_size(&params, &spec, harvester.as_ref(), args)?;
    let mut sim = Simulator::new(&params, &spec.initial, options)?;
    let solver = match &harvester {
        Some(h) => {
            let mut s = ChargeSolver::for_chain(h, &params, loaded.charge_options()?)?
                .with_breakdown_check(spec.transient_periods as f64 * period);
            if args.out.is_some() {
                s = s.with_periodic_sampling(spec.samples_per_period)?;
            }
            Some(s)
        }
        None => None,
    };
    let files = match &args.out {
        Some(dir) => Some(Files::create(dir, &params, &spec, harvester.as_ref())?),
        None => None,
    };
    let mut rec = Recorder {
        stats: RunStats::new(params.len() - 1, period, spec.transient_periods),
        solver,
        files,
    };
    let progress = Progress::new(spec.periods, "periods", args.quiet);
    let started = Instant::now();
    let mut done = 0;
    let mut failure: Option<anyhow::Error> = None;
    for p in 1..=spec.periods {
        if let Err(e) = sim.run_until(p as f64 * period, &mut rec) {
            failure = Some(e.into());
            break;
        }
        if let Some(Err(e)) = rec.solver.as_ref().map(ChargeSolver::status) {
            failure = Some(anyhow::Error::from(e).context("charge solver"));
            break;
        }
        done = p;
        progress.inc(1);
        if interrupted() {
            break;
        }
    }
    progress.finish();
    let outcome = Outcome {
        done,
        elapsed: started.elapsed().as_secs_f64(),
        impacts_per_period: rec.stats.impacts_per_period(done),
        power: rec
            .solver
            .as_ref()
            .and_then(|s| s.summary(spec.transient_periods as usize)),
        failure,
    };
    if let (Some(files), Some(dir)) = (rec.files.as_mut(), &args.out) {
        files.flush()?;
        let summary = summary_json(&loaded, &params, &spec, &rec, harvester.as_ref(), &outcome);
        write_json(&dir.join("summary.json"), &summary)?;
        if args.plot {
            crate::plots::analyze_run(dir, None)?;
        }
    }
    print_summary(
        &params,
        &spec,
        &rec,
        harvester.as_ref(),
        &outcome,
        args.out.as_deref(),
    );
    if let Some(e) = outcome.failure {
        return Err(e).context(format!("simulation stopped after {done} complete periods"));
    }
    if done < spec.periods {
        return Err(Interrupted {
            what: format!(
                "after {done} of {} periods{}",
                spec.periods,
                if args.out.is_some() {
                    "; the files hold what was computed, summary.json says \"interrupted\": true"
                } else {
                    ""
                }
            ),
        }
        .into());
    }
    Ok(())
}

/// Refuses a run whose per-period statistics or files would be unreasonably large (see
/// [`limits`]).
fn check_size(
    params: &ChainParams,
    spec: &RunSpec,
    harvester: Option<&HarvesterParams>,
    args: &SimulateArgs,
) -> Result<()> {
    let periods = spec.periods as f64;
    let n = params.len() as f64;
    // Per period: impact counts per contact, the solver's period record, and the per-period
    // arrays of summary.json.
    let per_period = 48.0
        + 4.0 * n
        + if harvester.is_some() {
            80.0 + 2.0 * limits::CSV_NUMBER_BYTES
        } else {
            0.0
        };
    limits::check_memory(
        &format!("{} periods of per-period statistics", spec.periods),
        periods * per_period,
        args.allow_large,
    )?;
    if args.out.is_some() {
        let columns = 1.0 + 2.0 * n + 1.0 + (n - 1.0) + if harvester.is_some() { 6.0 } else { 0.0 };
        let rows = periods * spec.samples_per_period as f64 + 1.0;
        limits::check_output(
            "trajectory.csv",
            rows * columns * limits::CSV_NUMBER_BYTES,
            args.allow_large,
        )?;
    }
    Ok(())
}

/// How a run ended and what it found, for the printed summary and `summary.json`.
struct Outcome {
    /// Complete periods simulated.
    done: u64,
    /// Wall time, s.
    elapsed: f64,
    /// Impacts per period after the transient, per contact.
    impacts_per_period: Vec<f64>,
    /// The harvester's power after the transient (`None` without a harvester, or without a
    /// complete period after the transient).
    power: Option<PowerSummary>,
    /// Why the run stopped early, if it failed.
    failure: Option<anyhow::Error>,
}

fn summary_json(
    loaded: &Loaded,
    params: &ChainParams,
    spec: &RunSpec,
    rec: &Recorder,
    harvester: Option<&HarvesterParams>,
    outcome: &Outcome,
) -> serde_json::Value {
    let stats = &rec.stats;
    let done = outcome.done;
    let per_contact = &outcome.impacts_per_period;
    let after = stats.impacts_after_transient();
    let mut out = json!({
        "periods": done,
        "periods_requested": spec.periods,
        "transient_periods": spec.transient_periods,
        "impacts": after.iter().sum::<u64>(),
        "impacts_per_period": per_contact.iter().sum::<f64>(),
        "impacts_per_period_by_contact": per_contact,
        "impacts_by_contact": after,
        "impacts_in_each_period": stats.impacts_by_period(done),
        "sticks": stats.sticks,
        "releases": stats.releases,
        "chatter_sequences": stats.chatter_sequences,
        "max_closing_speed_m_s": stats.max_closing_speed,
        "events_total": stats.events,
        "excitation_period_s": params.period(),
        "omega_rad_s": params.omega(),
        "omega_ratio": params.omega_ratio(),
    });
    let obj = out.as_object_mut().expect("object");
    if let (Some(solver), Some(h)) = (&rec.solver, harvester) {
        let s = &outcome.power;
        obj.insert(
            "average_power_w".into(),
            json!(s.as_ref().map(|s| s.average_power_w)),
        );
        obj.insert(
            "energy_per_period_j".into(),
            json!(s.as_ref().map(|s| s.energy_per_period_j)),
        );
        obj.insert(
            "peak_current_a".into(),
            json!(s.as_ref().map(|s| s.peak_current_a)),
        );
        obj.insert(
            "peak_voltage_v".into(),
            json!(s.as_ref().map(|s| s.peak_voltage_v)),
        );
        obj.insert("power_curve".into(), json!(solver.power_curve()));
        obj.insert(
            "energy_in_each_period_j".into(),
            json!(solver.periods().iter().map(|p| p.energy_j).collect::<Vec<_>>()),
        );
        if h.load == LoadKind::Rectifier {
            obj.insert(
                "storage_voltage_at_period_end_v".into(),
                json!(
                    solver
                        .periods()
                        .iter()
                        .map(|p| p.storage_voltage_v)
                        .collect::<Vec<_>>()
                ),
            );
            obj.insert("time_to_target_s".into(), json!(solver.time_to_target()));
        }
        if let Some(margin) = solver.breakdown_margin() {
            obj.insert("air_breakdown".into(), json!(margin));
        }
        obj.insert("harvester".into(), json!(h));
        obj.insert("electrical_solver".into(), json!(format!("{:?}", solver.stats())));
    }
    obj.insert("nondimensional".into(), json!(params.nondimensional()));
    obj.insert("parameters".into(), json!(params));
    obj.insert("settings".into(), json!(loaded.table));
    obj.insert("wall_time_s".into(), json!(outcome.elapsed));
    obj.insert(
        "interrupted".into(),
        json!(done < spec.periods && outcome.failure.is_none()),
    );
    obj.insert(
        "error".into(),
        json!(outcome.failure.as_ref().map(|e| format!("{e:#}"))),
    );
    out
}

fn print_summary(
    params: &ChainParams,
    spec: &RunSpec,
    rec: &Recorder,
    harvester: Option<&HarvesterParams>,
    outcome: &Outcome,
    out: Option<&Path>,
) {
    let stats = &rec.stats;
    let n = params.len();
    let per_contact = &outcome.impacts_per_period;
    println!(
        "vibrotribo simulate: {n} masses {:?} kg, Ω = {:.4} (ω = {:.3} rad/s, f = {:.4} Hz, T = {:.6} s)",
        params.masses,
        params.omega_ratio(),
        params.omega(),
        params.omega() / (2.0 * std::f64::consts::PI),
        params.period()
    );
    println!(
        "  simulated {} periods ({} transient) in {:.3} s: {} events",
        outcome.done, spec.transient_periods, outcome.elapsed, stats.events
    );
    let contacts: Vec<String> = per_contact
        .iter()
        .enumerate()
        .map(|(k, c)| format!("m{}–m{}: {c:.2}", k + 1, k + 2))
        .collect();
    println!(
        "  after the transient: {:.2} impacts/period ({}), {} sticks, {} chatter sequences",
        per_contact.iter().sum::<f64>(),
        contacts.join(", "),
        stats.sticks,
        stats.chatter_sequences
    );
    let speeds: Vec<String> = stats
        .max_closing_speed
        .iter()
        .enumerate()
        .map(|(k, v)| format!("m{}–m{}: {v:.3} m/s", k + 1, k + 2))
        .collect();
    println!("  largest closing speed: {}", speeds.join(", "));
    if let (Some(solver), Some(h)) = (&rec.solver, harvester) {
        let load = match h.load {
            LoadKind::Resistor => format!("resistor {}", si(h.load_resistance, "Ω")),
            LoadKind::Rectifier => format!("rectifier into {}", si(h.storage_capacitance, "F")),
            other => other.as_str().to_string(),
        };
        match &outcome.power {
            Some(s) => println!(
                "  harvester ({}, V_oc {}, {load}): average power {} after the transient, {} per period, peak current {}, peak voltage {}",
                h.mode.as_str(),
                match h.mode {
                    TransducerMode::Freestanding => h.voc_model.as_str(),
                    TransducerMode::ContactSeparation => "σD/ε0",
                },
                si(s.average_power_w, "W"),
                si(s.energy_per_period_j, "J"),
                si(s.peak_current_a, "A"),
                si(s.peak_voltage_v, "V"),
            ),
            None => println!("  harvester: no complete period after the transient"),
        }
        if let Some(m) = solver.breakdown_margin().filter(|m| m.worst_ratio > 0.0) {
            println!(
                "  air gaps: largest |V_gap|/V_breakdown = {:.3} (gap {}, {} across {}; Paschen's law, air at 1 atm){}",
                m.worst_ratio,
                m.gap,
                si(m.gap_voltage_v, "V"),
                si(m.gap_m, "m"),
                if m.worst_ratio >= 1.0 {
                    ": the air would break down"
                } else {
                    ""
                }
            );
        }
        if h.load == LoadKind::Rectifier {
            if let Some(v) = solver.storage_voltage() {
                println!("  storage capacitor at {}", si(v, "V"));
            }
            if let Some(t) = solver.time_to_target() {
                println!("  target voltage reached at t = {t:.6} s");
            }
        }
    }
    if let Some(dir) = out {
        println!(
            "  wrote {0}/events.csv, {0}/trajectory.csv, {0}/summary.json",
            dir.display()
        );
    }
}
