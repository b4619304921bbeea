//! `vibrotribo simulate`: one run of the chain and its harvester ([`vibrotribo::study::simulate`]),
//! with a human summary and optional files.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;
use serde_json::json;
use vibrotribo::config::Config;
use vibrotribo::electrical::{HarvesterParams, Load, LoadKind, TransducerMode};
use vibrotribo::excitation::WorkBudget;
use vibrotribo::merit::MeritWatch;
use vibrotribo::report::{MeritSummary, RunSummary};
use vibrotribo::study::{
    Ending, LyapunovSkipped, Motion, MotionReport, PointError, RunMotion, RunObserver, RunOutcome, RunSpec,
    Sample, SettleMode, settle, simulate,
};
use vibrotribo::{ChainParams, Event, StateView};

use crate::config::ConfigArgs;
use crate::limits;
use crate::output::{CsvFile, check_out_dir, create_dir, numbered, si};
use crate::progress::{Interrupted, Progress, Watch, orbit_cancel};
use crate::run_analyses::RunSections;

/// Options of `vibrotribo simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Write events.csv, trajectory.csv, the Poincaré sections (poincare_strobe.csv,
    /// poincare_impacts.csv) and summary.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Mechanics only: skip the triboelectric harvester.
    #[arg(long)]
    pub mechanics_only: bool,
    /// Also write the per-run analyses (Poincaré sections, PSDs) and draw the pictures
    /// (without --out: into vibrotribo-out/simulate).
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run even if the estimated output exceeds 20 GiB or the memory 4 GiB, build a random
    /// base motion costlier than 10⁹ harmonic evaluations, and compute the motion's Lyapunov
    /// exponent when its cost, (2N)³ × periods, exceeds 10¹¹ (without it the motion is then
    /// reported `undetermined`, with the reason).
    #[arg(long)]
    pub allow_large: bool,
    /// Write into an --out directory that holds another job's results (files of the same
    /// name are replaced).
    #[arg(long)]
    pub force: bool,
    /// `fixed`: the run as configured, from the initial state. `auto`: first settle (as
    /// `sweep --settle auto` does, mechanics only, at most --settle-cap periods), then the
    /// configured run from the settled state (the files start there; summary.json's
    /// `settle_periods` says how many periods came before). Either way the motion after the
    /// transient is classified (`motion` in summary.json).
    #[arg(long, default_value = "fixed", value_name = "auto|fixed")]
    pub settle: SettleMode,
    /// Most periods `--settle auto` runs before the configured run.
    #[arg(long, default_value_t = vibrotribo::study::DEFAULT_SETTLE_CAP, value_name = "PERIODS")]
    pub settle_cap: u64,
}

/// Streams `events.csv` and `trajectory.csv` as the run goes.
struct Files {
    events: CsvFile,
    trajectory: CsvFile,
    row: Vec<f64>,
    rectifier: bool,
    electrical: bool,
    error: Option<anyhow::Error>,
}

impl Files {
    fn create(dir: &Path, params: &ChainParams, harvester: Option<&HarvesterParams>) -> Result<Self> {
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
        let rectifier = harvester.is_some_and(|h| h.load.kind() == LoadKind::Rectifier);
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
}

impl RunObserver for Files {
    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, s: &Sample<'_>) {
        self.row.clear();
        self.row.push(s.time);
        self.row.extend_from_slice(s.positions);
        self.row.extend_from_slice(s.velocities);
        if self.electrical {
            let e = s.electrical;
            let get = |f: fn(&vibrotribo::study::ElectricalSample) -> f64| e.as_ref().map_or(f64::NAN, f);
            self.row.push(get(|e| e.charge_c));
            self.row.push(get(|e| e.current_a));
            self.row.push(get(|e| e.voltage_v));
            self.row.push(get(|e| e.capacitance_f));
            self.row.push(get(|e| e.voc_v));
            if self.rectifier {
                self.row.push(get(|e| e.storage_voltage_v.unwrap_or(f64::NAN)));
            }
        }
        self.row.push(s.base);
        self.row.extend_from_slice(s.gaps);
        let r = self.trajectory.row_with(|f| f.numbers(&self.row));
        self.keep(r);
    }

    fn event(&mut self, e: &Event, state: &StateView<'_>) {
        let r = self.events.row_with(|f| {
            f.number(e.time);
            f.text(e.kind.as_str());
            f.integer(e.contact as u64 + 1);
            f.number(e.velocity_before);
            f.number(e.velocity_after);
            f.integer(u64::from(e.sequence_impacts));
            f.numbers(state.positions);
            f.numbers(state.velocities);
        });
        self.keep(r);
    }
}

/// Runs `vibrotribo simulate`.
pub fn run(args: &SimulateArgs) -> Result<()> {
    let config = args.input.load_within(args.allow_large)?;
    let mut spec = config.sampled_run_spec(args.mechanics_only);
    spec.breakdown_check = true;
    check_size(&config, &spec, args.out.is_some(), args.allow_large)?;
    if let Some(dir) = &args.out {
        let settings = json!(config.table());
        check_out_dir(dir, "summary.json", args.force, |old| {
            old.get("settings") == Some(&settings)
        })?;
    }
    let harvester = spec.harvester.as_ref().map(|h| &h.params);
    let mut files = match &args.out {
        Some(dir) => Some(Files::create(dir, &spec.chain, harvester)?),
        None => None,
    };
    let started = Instant::now();
    let mut run_motion = RunMotion::new(&spec).map_err(|e| anyhow::anyhow!("{e}"))?;
    let mode = args.settle.with_cap(args.settle_cap);
    if matches!(mode, SettleMode::Auto(_)) {
        config.check_periodic("simulate --settle auto (settling to a periodic motion)")?;
    }
    run_motion.options_mut().settle = mode;
    run_motion.options_mut().cancel = orbit_cancel();
    let settled = match &mode {
        SettleMode::Auto(auto) => {
            if args.settle_cap == 0 {
                anyhow::bail!("--settle-cap must be at least 1");
            }
            let s = match settle(
                &spec.chain,
                &spec.initial,
                &spec.options,
                run_motion.options(),
                auto,
            ) {
                Ok(s) => s,
                Err(PointError::Stopped { periods }) => {
                    if let Some(f) = files.as_mut() {
                        f.flush()?;
                    }
                    return stopped_while_settling(&config, &spec, args, &mode, periods, started);
                }
                Err(e) => anyhow::bail!("while settling: {e}"),
            };
            spec.initial = s.state.clone();
            Some(s)
        }
        SettleMode::Fixed => None,
    };
    let mut watch = Watch {
        progress: Progress::new(spec.periods, "periods", args.quiet),
    };
    // The figures of merit, written beside the files.
    let mut merit = match (&files, &spec.harvester) {
        (Some(_), Some(h)) => Some(MeritWatch::new(
            &h.params,
            &spec.chain.gaps,
            spec.transient_periods as f64 * spec.chain.period(),
            spec.chain.period(),
        )),
        _ => None,
    };
    // The Poincaré sections, taken by the run's observers and written beside the files.
    let mut sections = match &files {
        Some(_) => Some(RunSections::new(&spec)?),
        None => None,
    };
    let outcome = match (files.as_mut(), sections.as_mut()) {
        (Some(f), Some(s)) => simulate(
            &spec,
            &mut (
                (f, &mut merit),
                (s.observer(), (&mut watch, run_motion.observer())),
            ),
        )?,
        _ => simulate(&spec, &mut (&mut watch, run_motion.observer()))?,
    };
    watch.progress.finish();
    // A motion under a base motion that is not periodic is not classified (no period).
    // Its Lyapunov run, where one is needed, within the documented cost unless
    // --allow-large, and stopped by SIGINT/SIGTERM.
    let budget = WorkBudget {
        allow_large: args.allow_large,
        stop: crate::progress::stop_flag(),
    };
    let motion = (outcome.ending == Ending::Completed && config.is_periodic())
        .then(|| run_motion.finish_within(&spec, &outcome.final_state, settled.as_ref(), &budget));
    let classification_stopped = motion
        .as_ref()
        .is_some_and(|m| m.lyapunov_skipped == Some(LyapunovSkipped::Stopped));
    let elapsed = started.elapsed().as_secs_f64();
    let failure = failure_error(&outcome);
    let energy = outcome
        .electrical
        .as_ref()
        .and_then(|e| e.power.as_ref())
        .map(|p| p.energy_per_period_j);
    let merit_report = merit.as_ref().and_then(|w| w.finish(energy));
    // The pictures' result, reported after the summary: a figure that fails loses no run.
    let mut plotted = Ok(());
    if let (Some(files), Some(dir)) = (files.as_mut(), &args.out) {
        files.flush()?;
        let mut summary = RunSummary::new(&config, &spec, &outcome, elapsed);
        summary.set_settle(&run_motion.options().settle);
        summary.set_motion(motion.as_ref());
        summary.interrupted |= classification_stopped;
        if let Some(w) = &merit {
            summary.merit = Some(MeritSummary::of(merit_report.as_ref()));
            crate::merit::write_boundary(dir, w.boundary())?;
        }
        if let Some(s) = &sections {
            s.write(dir)?;
        }
        crate::manifest::write(&dir.join("summary.json"), &summary)?;
        if args.plot {
            plotted = crate::run_analyses::analyze_run(dir, None);
        }
    }
    print_summary(&spec, &outcome, elapsed, args.out.as_deref());
    if let Some(m) = &merit_report {
        print_merit(m);
    }
    let base = vibrotribo::report::base_motion_lines(&spec);
    if !base.is_empty() {
        println!("  base motion:");
        for (k, v) in &base {
            println!("    {k}: {v}");
        }
    }
    if let Some(m) = &motion {
        print_motion(m);
    }
    plotted?;
    if let Some(e) = failure {
        return Err(e);
    }
    if classification_stopped {
        return Err(Interrupted {
            what: format!(
                "while classifying the motion, after the {} periods of the run{}",
                outcome.periods,
                if args.out.is_some() {
                    "; the files hold the whole run, summary.json says \"interrupted\": true"
                } else {
                    ""
                }
            ),
        }
        .into());
    }
    if outcome.ending == Ending::Stopped {
        return Err(Interrupted {
            what: format!(
                "after {} of {} periods{}",
                outcome.periods,
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

/// A run stopped by SIGINT/SIGTERM while settling, after `periods` settling periods: with
/// --out, `summary.json` says so (`"interrupted": true`, no period of the configured run
/// computed; events.csv and trajectory.csv hold their headers only); the error is the
/// signal's.
fn stopped_while_settling(
    config: &Config,
    spec: &RunSpec,
    args: &SimulateArgs,
    mode: &SettleMode,
    periods: u64,
    started: Instant,
) -> Result<()> {
    if let Some(dir) = &args.out {
        let summary =
            RunSummary::stopped_while_settling(config, spec, mode, periods, started.elapsed().as_secs_f64());
        crate::manifest::write(&dir.join("summary.json"), &summary)?;
    }
    Err(Interrupted {
        what: format!(
            "while settling, after {periods} of at most {} periods, before the configured run{}",
            args.settle_cap,
            if args.out.is_some() {
                "; summary.json says \"interrupted\": true, events.csv and trajectory.csv hold no rows"
            } else {
                ""
            }
        ),
    }
    .into())
}

/// One line of the figures of merit ([`vibrotribo::merit`]).
fn print_merit(m: &vibrotribo::merit::MeritReport) {
    let opt = |x: Option<f64>, f: &dyn Fn(f64) -> String| x.map_or("n/a".to_string(), f);
    println!(
        "  figures of merit: CMEO {} per cycle, FOM_S {}, breakdown-limited {}, the run's cycle {} ({} of the CMEO)",
        si(m.cmeo_energy_per_cycle_j, "J"),
        opt(m.fom_s, &|f| format!("{f:.4}")),
        opt(m.breakdown_limited_energy_per_cycle_j, &|e| si(e, "J")),
        opt(m.energy_per_cycle_j, &|e| si(e, "J")),
        opt(m.energy_fraction_of_cmeo, &|f| format!("{:.2} %", 100.0 * f)),
    );
}

fn print_motion(m: &MotionReport) {
    let detail = match m.motion {
        Motion::Periodic => format!(
            "period {}, residual {:.1e}, {}",
            m.residual_period,
            m.residual,
            m.label_source.map_or("reached", |s| s.as_str())
        ),
        Motion::Settling => format!(
            "rate {} per period, about {} more periods needed",
            m.rate.map_or("?".into(), |r| format!("{r:.5}")),
            m.periods_needed.map_or("?".into(), |p| format!("{p:.0}"))
        ),
        Motion::Quasiperiodic | Motion::Chaotic => match m.lyapunov {
            Some((l, s)) => format!("λ1 = {l:.4} ± {s:.4} 1/s"),
            None => "no Lyapunov exponent".into(),
        },
        Motion::Undetermined => match m.lyapunov_skipped {
            Some(why) => format!("not classified: {why}"),
            None => {
                "the window cannot tell: too short, or a two-way coupled run neither periodic nor converging"
                    .into()
            }
        },
    };
    let detail = match m.coexisting {
        Some((p, r)) => {
            format!("{detail}; a stable period-{p} orbit (|μ| = {r:.4}) coexists, not approached")
        }
        None => detail,
    };
    println!(
        "  motion after {} settling periods ({}): {} ({detail})",
        m.settle_periods,
        m.settle_ending.as_str(),
        m.motion
    );
}

/// The error of a failed run, with how far it got (summary.json holds the same text,
/// [`vibrotribo::report::failure_text`]).
fn failure_error(outcome: &RunOutcome) -> Option<anyhow::Error> {
    outcome.failure().map(|e| {
        anyhow::Error::from(e.clone()).context(format!(
            "simulation stopped after {} complete periods",
            outcome.periods
        ))
    })
}

/// Refuses a run whose per-period statistics or (with `files`) files would be unreasonably
/// large (see [`limits`]) unless `allow_large`.
pub fn check_size(config: &Config, spec: &RunSpec, files: bool, allow_large: bool) -> Result<()> {
    let periods = spec.periods as f64;
    let n = spec.chain.len() as f64;
    let electrical = spec.harvester.is_some();
    let per_period = vibrotribo::study::limits::per_period_bytes(spec.chain.len(), electrical);
    limits::check_memory(
        &format!("{} periods of per-period statistics", spec.periods),
        periods * per_period,
        allow_large,
    )?;
    if files {
        let columns = 1.0 + 2.0 * n + 1.0 + (n - 1.0) + if electrical { 6.0 } else { 0.0 };
        let rows = periods * config.run().samples_per_period as f64 + 1.0;
        limits::check_output(
            "trajectory.csv",
            rows * columns * limits::CSV_NUMBER_BYTES,
            allow_large,
        )?;
    }
    Ok(())
}

fn print_summary(spec: &RunSpec, outcome: &RunOutcome, elapsed: f64, out: Option<&Path>) {
    let params = &spec.chain;
    let stats = &outcome.stats;
    let n = params.len();
    let per_contact = stats.impacts_per_period(outcome.periods);
    println!(
        "vibrotribo simulate: {n} masses {:?} kg, Ω = {:.4} (ω = {:.3} rad/s, f = {:.4} Hz, T = {:.6} s)",
        params.masses,
        params.omega_ratio(),
        params.omega(),
        params.omega() / (2.0 * std::f64::consts::PI),
        params.period()
    );
    println!(
        "  simulated {} periods ({} transient) in {elapsed:.3} s: {} events",
        outcome.periods, spec.transient_periods, stats.events
    );
    let contacts: Vec<String> = per_contact
        .iter()
        .enumerate()
        .filter(|&(k, _)| k + 1 < params.len() || params.is_stop(k))
        .map(|(k, c)| format!("{}: {c:.2}", params.contact_name(k)))
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
        .filter(|&(k, _)| k + 1 < params.len() || params.is_stop(k))
        .map(|(k, v)| format!("{}: {v:.3} m/s", params.contact_name(k)))
        .collect();
    println!("  largest closing speed: {}", speeds.join(", "));
    if let (Some(e), Some(h)) = (&outcome.electrical, &spec.harvester) {
        let h = &h.params;
        let load = match &h.load {
            Load::Resistor { resistance } => format!("resistor {}", si(*resistance, "Ω")),
            Load::Rectifier(r) => format!("rectifier into {}", si(r.storage_capacitance, "F")),
            other => other.kind().as_str().to_string(),
        };
        match &e.power {
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
        if let Some(m) = e.breakdown.filter(|m| m.worst_ratio > 0.0) {
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
        if h.load.kind() == LoadKind::Rectifier {
            if let Some(v) = e.storage_voltage {
                println!("  storage capacitor at {}", si(v, "V"));
            }
            if let Some(t) = e.time_to_target {
                println!("  target voltage reached at t = {t:.6} s");
            }
        }
    }
    if let Some(dir) = out {
        println!(
            "  wrote {0}/events.csv, {0}/trajectory.csv, {0}/poincare_strobe.csv, {0}/poincare_impacts.csv, {0}/summary.json",
            dir.display()
        );
    }
}

#[cfg(test)]
mod tests {
    use vibrotribo::config::Config;
    use vibrotribo::study::simulate;

    /// summary.json's `error` reads exactly as the error the command reports.
    #[test]
    fn summary_error_is_the_reported_error() {
        let config = Config::default()
            .with("options.max_events_per_period", 2.into())
            .unwrap();
        let outcome = simulate(&config.run_spec(false), &mut ()).unwrap();
        let reported = format!("{:#}", super::failure_error(&outcome).expect("the run fails"));
        assert_eq!(Some(reported), vibrotribo::report::failure_text(&outcome));
    }
}
