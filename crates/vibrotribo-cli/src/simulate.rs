//! `vibrotribo simulate`: one run of the chain, with a human summary and optional files.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use serde_json::json;
use vibrotribo::analysis::RunStats;
use vibrotribo::{ChainParams, Event, Flow, Observer, Simulator, StateView};

use crate::config::{Loaded, RunSpec};
use crate::output::{CsvFile, create_dir, numbered, write_json};
use crate::progress::{Progress, interrupted};

/// Options of `vibrotribo simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    /// Configuration file (TOML); the paper's default case if omitted.
    pub config: Option<PathBuf>,
    /// Override a parameter, e.g. `--set excitation.omega_ratio=0.75`,
    /// `--set oscillator.masses=[0.05,0.15,0.05]`, `--set mass_ratio=3` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Write events.csv, trajectory.csv and summary.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Streams `events.csv` and `trajectory.csv` as the simulation goes.
struct Files {
    events: CsvFile,
    trajectory: CsvFile,
    dt: f64,
    next_sample: u64,
    last_sample: u64,
    gaps: Vec<f64>,
    x: Vec<f64>,
    v: Vec<f64>,
    error: Option<anyhow::Error>,
}

impl Files {
    fn create(dir: &Path, params: &ChainParams, spec: &RunSpec) -> Result<Self> {
        create_dir(dir)?;
        let n = params.len();
        let mut ev_cols: Vec<String> = [
            "time_s",
            "kind",
            "contact",
            "rel_velocity_m_s",
            "rel_velocity_after_m_s",
        ]
        .map(String::from)
        .to_vec();
        ev_cols.push("sequence_impacts".into());
        ev_cols.extend(numbered("x", n, "_m"));
        ev_cols.extend(numbered("v", n, "_m_s"));
        let mut tr_cols = vec!["time_s".to_string()];
        tr_cols.extend(numbered("x", n, "_m"));
        tr_cols.extend(numbered("v", n, "_m_s"));
        tr_cols.push("y_m".into());
        tr_cols.extend(numbered("d", n - 1, "_m"));
        Ok(Files {
            events: CsvFile::create(&dir.join("events.csv"), &ev_cols)?,
            trajectory: CsvFile::create(&dir.join("trajectory.csv"), &tr_cols)?,
            dt: params.period() / spec.samples_per_period as f64,
            next_sample: 0,
            last_sample: spec.periods * spec.samples_per_period,
            gaps: params.gaps.clone(),
            x: vec![0.0; n],
            v: vec![0.0; n],
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
}

impl Observer for Files {
    fn flow(&mut self, flow: &Flow<'_>) {
        while self.next_sample <= self.last_sample {
            let t = self.next_sample as f64 * self.dt;
            if t > flow.t_end {
                break;
            }
            flow.state_at(t, &mut self.x, &mut self.v);
            let (y, _) = flow.base_at(t);
            let n = self.x.len();
            let gaps = (0..n - 1).map(|k| self.gaps[k] - (self.x[k + 1] - self.x[k]));
            let row: Vec<f64> = std::iter::once(t)
                .chain(self.x.iter().copied())
                .chain(self.v.iter().copied())
                .chain(std::iter::once(y))
                .chain(gaps)
                .collect();
            let r = self.trajectory.row(row);
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

/// Runs `vibrotribo simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let loaded = Loaded::load(args.config.as_deref(), &args.set)?;
    let params = loaded.config.chain_params()?;
    let spec = loaded.config.run_spec(&params)?;
    let options = loaded.config.sim_options()?;
    let period = params.period();
    let mut sim = Simulator::new(&params, &spec.initial, options)?;
    let mut stats = RunStats::new(params.len() - 1, period, spec.transient_periods);
    let mut files = match &args.out {
        Some(dir) => Some(Files::create(dir, &params, &spec)?),
        None => None,
    };
    let progress = Progress::new(spec.periods, "periods", args.quiet);
    let started = Instant::now();
    let mut done = 0;
    let mut failure = None;
    for p in 1..=spec.periods {
        let result = sim.run_until(p as f64 * period, &mut (&mut stats, &mut files));
        if let Err(e) = result {
            failure = Some(e);
            break;
        }
        done = p;
        progress.inc(1);
        if interrupted() {
            break;
        }
    }
    progress.finish();
    let elapsed = started.elapsed().as_secs_f64();
    let summary = summary_json(&loaded, &params, &spec, &stats, done, elapsed, failure.as_ref());
    if let (Some(files), Some(dir)) = (files.as_mut(), &args.out) {
        files.flush()?;
        write_json(&dir.join("summary.json"), &summary)?;
    }
    print_summary(&params, &spec, &stats, done, elapsed, args.out.as_deref());
    if let Some(e) = failure {
        return Err(e).context(format!("simulation stopped after {done} complete periods"));
    }
    if done < spec.periods {
        eprintln!(
            "stopped early by Ctrl-C after {done} of {} periods; files hold what was computed",
            spec.periods
        );
    }
    Ok(())
}

fn summary_json(
    loaded: &Loaded,
    params: &ChainParams,
    spec: &RunSpec,
    stats: &RunStats,
    done: u64,
    elapsed: f64,
    failure: Option<&vibrotribo::SimError>,
) -> serde_json::Value {
    let per_contact = stats.impacts_per_period(done);
    let after = stats.impacts_after_transient();
    let nd = params.nondimensional();
    json!({
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
        "nondimensional": nd,
        "parameters": params,
        "settings": loaded.table,
        "wall_time_s": elapsed,
        "interrupted": done < spec.periods && failure.is_none(),
        "error": failure.map(|e| e.to_string()),
    })
}

fn print_summary(
    params: &ChainParams,
    spec: &RunSpec,
    stats: &RunStats,
    done: u64,
    elapsed: f64,
    out: Option<&Path>,
) {
    let n = params.len();
    let per_contact = stats.impacts_per_period(done);
    println!(
        "vibrotribo simulate: {n} masses {:?} kg, Ω = {:.4} (ω = {:.3} rad/s, f = {:.4} Hz, T = {:.6} s)",
        params.masses,
        params.omega_ratio(),
        params.omega(),
        params.omega() / (2.0 * std::f64::consts::PI),
        params.period()
    );
    println!(
        "  simulated {done} periods ({} transient) in {:.3} s: {} events",
        spec.transient_periods, elapsed, stats.events
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
    if let Some(dir) = out {
        println!(
            "  wrote {0}/events.csv, {0}/trajectory.csv, {0}/summary.json",
            dir.display()
        );
    }
}
