//! `vibrotribo sweep` and `vibrotribo merge`: one-parameter sweeps (orbit diagrams,
//! impact-velocity diagrams, power curves), parallel, continued, or sharded across machines.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use serde_json::json;
use vibrotribo::ChainState;
use vibrotribo::config::Config;
use vibrotribo::lyapunov::LyapunovOptions;
use vibrotribo::study::{AutoSettle, PointOptions, PointResult, SettleMode};
use vibrotribo::sweep::{Continuation, Delivery, PointRunner, error_text, grid, run_chunks, run_continued};

use crate::config::ConfigArgs;
use crate::job::{CsvSpec, GridOutput, Layout};
use crate::limits;
use crate::output::{PointColumns, numbered};
use crate::progress::{Interrupted, Progress, interrupted};

/// `I/N`: the I-th (0-based) of N interleaved slices of the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This slice, 0 ≤ index < count.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("--shard takes I/N (e.g. 3/16), got {s:?}"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| format!("--shard: bad index {i:?}"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("--shard: bad count {n:?}"))?;
        if count == 0 || index >= count {
            return Err(format!(
                "--shard {s}: need 0 ≤ I < N (Slurm: --array=0-{})",
                count.max(1) - 1
            ));
        }
        Ok(Shard { index, count })
    }
}

/// `--settle`: how long each point runs before its recorded window.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Settle {
    /// Until the motion repeats, finishing a geometric approach by Newton shooting, at most
    /// `--settle-cap` periods ([`SettleMode::Auto`]).
    #[default]
    Auto,
    /// The fixed `--transient` ([`SettleMode::Fixed`]).
    Fixed,
}

impl std::str::FromStr for Settle {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "auto" => Ok(Settle::Auto),
            "fixed" => Ok(Settle::Fixed),
            other => Err(format!("unknown --settle {other:?}: expected auto or fixed")),
        }
    }
}

impl Settle {
    /// `auto` or `fixed`.
    pub fn as_str(self) -> &'static str {
        match self {
            Settle::Auto => "auto",
            Settle::Fixed => "fixed",
        }
    }

    /// The library's settle mode, with at most `cap` periods for `auto`.
    pub fn mode(self, cap: u64) -> SettleMode {
        match self {
            Settle::Auto => SettleMode::Auto(AutoSettle {
                cap_periods: cap,
                ..AutoSettle::default()
            }),
            Settle::Fixed => SettleMode::Fixed,
        }
    }
}

/// The default of `--settle-cap`, periods.
pub const SETTLE_CAP: u64 = 2000;

/// Settings shared by sweeps and maps.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Transient periods per value (default: the configuration's run.transient_periods).
    #[arg(long)]
    pub transient: Option<u64>,
    /// Recorded periods per value (default: run.periods − run.transient_periods).
    #[arg(long)]
    pub recorded: Option<u64>,
    /// Mechanics only: no harvester, average_power_w left empty (faster).
    #[arg(long)]
    pub mechanics_only: bool,
    /// Relative tolerance of the period detection.
    #[arg(long, default_value_t = 1e-4)]
    pub period_tolerance: f64,
    /// Also find the periodic orbit of each point's detected period by shooting and write
    /// its largest Floquet multiplier modulus (column `max_abs_multiplier`; < 1: stable).
    #[arg(long)]
    pub floquet: bool,
    /// How long each point runs before its recorded window: `auto` until the motion repeats
    /// within the period tolerance (checked every 50 periods; a geometric approach to a
    /// periodic orbit is finished by Newton shooting; a motion whose returns do not shrink
    /// stops after --transient periods), at most --settle-cap periods; `fixed` exactly
    /// --transient periods.
    #[arg(long, default_value = "auto", value_name = "auto|fixed", value_parser = clap::value_parser!(Settle))]
    pub settle: Settle,
    /// Most periods `--settle auto` runs before the recorded window.
    #[arg(long, default_value_t = SETTLE_CAP, value_name = "PERIODS")]
    pub settle_cap: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run even if the estimated output exceeds 20 GiB or the memory 4 GiB.
    #[arg(long)]
    pub allow_large: bool,
}

/// Options of `vibrotribo sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The swept parameter: a configuration key (`excitation.omega_ratio`,
    /// `oscillator.gaps[1]`, `harvester.load_resistance`, …) or a derived one (`mass_ratio`,
    /// `gap_ratio`, `gap`, `omega_ratio`, `restitution`, …).
    #[arg(long)]
    pub param: String,
    /// First value.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Last value.
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Number of values, equally spaced from --from to --to.
    #[arg(long)]
    pub steps: usize,
    /// Carry the final state to the next value (`up`, `down`), or start every value afresh
    /// (`none`, parallel).
    #[arg(long, default_value = "none", value_parser = clap::value_parser!(Continuation), value_name = "none|up|down")]
    pub continuation: Continuation,
    /// Compute only the I-th of N interleaved slices of the grid (0 ≤ I < N), e.g.
    /// `--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`; combine with `vibrotribo merge`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Write orbit.csv, impacts.csv, summary.csv and sweep.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Continue the interrupted sweep (or shard) in --out DIR from its finished values; the
    /// result is what one uninterrupted run writes.
    #[arg(long)]
    pub resume: bool,
    /// Also draw the diagrams (PNG and SVG) into the output directory (without --out:
    /// vibrotribo-out/sweep).
    #[arg(long)]
    pub plot: bool,
    /// Also compute the largest Lyapunov exponent over the recorded periods of every value
    /// (columns `lyapunov_max_1_s` and its batch-means standard error `lyapunov_spread_1_s`
    /// at the end of summary.csv).
    #[arg(long)]
    pub lyapunov: bool,
    #[command(flatten)]
    pub run: RunArgs,
}

impl RunArgs {
    /// The point runner of these settings on `base` (transient and recorded periods by
    /// default from its `[run]` table).
    pub fn runner(&self, base: Config) -> Result<PointRunner> {
        let settings = base.run();
        let defaults = (settings.transient(), settings.periods - settings.transient());
        self.runner_or(base, defaults)
    }

    /// The point runner of these settings on `base`, with `(transient, recorded)` periods
    /// where the options do not give them.
    pub fn runner_or(&self, base: Config, (transient, recorded): (u64, u64)) -> Result<PointRunner> {
        let transient = self.transient.unwrap_or(transient);
        let recorded = self.recorded.unwrap_or(recorded);
        if recorded == 0 {
            bail!("--recorded must be at least 1");
        }
        if !(self.period_tolerance > 0.0 && self.period_tolerance < 1.0) {
            bail!(
                "--period-tolerance must lie in (0, 1), got {}",
                self.period_tolerance
            );
        }
        if self.settle_cap == 0 {
            bail!("--settle-cap must be at least 1");
        }
        if self.floquet {
            base.check_periodic("--floquet (Floquet multipliers)")?;
        }
        // Under a base motion that is not periodic there is no periodic motion to settle to
        // or classify: each point runs exactly `transient + recorded` periods.
        let periodic = base.is_periodic();
        let options = PointOptions {
            transient_periods: transient,
            recorded_periods: recorded,
            period_tolerance: self.period_tolerance,
            floquet: self.floquet,
            settle: if periodic {
                self.settle.mode(self.settle_cap)
            } else {
                vibrotribo::study::SettleMode::Fixed
            },
            classify: periodic,
            ..PointOptions::default()
        };
        Ok(PointRunner::new(base, options, self.mechanics_only))
    }
}

/// Checks every point of a grid (`keys` gives each point's settings); the error names the
/// first bad point.
pub fn check_all<'k, P>(
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)>,
) -> Result<()> {
    for p in points {
        let k = keys(p);
        runner.configure(&k).with_context(|| {
            k.iter()
                .map(|(key, v)| format!("{key} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        })?;
    }
    Ok(())
}

/// Runs `points` in parallel chunks (see [`vibrotribo::sweep::run_grid`]), calling `write`
/// with each point's result in grid order and with `None` after each chunk, ticking a
/// progress bar (label, points done before, points in all) and stopping after the current
/// chunk on SIGINT/SIGTERM, keeping what was written. Returns how many were written.
pub fn run_points<'k, P, W>(
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)> + Sync,
    progress: (&str, u64, u64),
    quiet: bool,
    mut write: W,
) -> Result<usize>
where
    P: Sync,
    W: FnMut(Option<(&P, &Result<PointResult, String>)>) -> Result<()>,
{
    run_chunked(
        points,
        |p| runner.run(&keys(p), None).map_err(|e| error_text(&e)),
        progress,
        quiet,
        |d| match d {
            Some((p, r)) => write(Some((p, &r))),
            None => write(None),
        },
    )
}

/// Runs `work` on `points` in parallel chunks ([`vibrotribo::sweep::run_chunks`]), calling
/// `write` with each result in order and with `None` after each chunk, with a progress bar
/// (label, points done before, points in all) and a stop after the current chunk on
/// SIGINT/SIGTERM. Returns how many were written.
pub fn run_chunked<P, R, W, F>(
    points: &[P],
    work: W,
    (what, before, total): (&str, u64, u64),
    quiet: bool,
    mut write: F,
) -> Result<usize>
where
    P: Sync,
    R: Send,
    W: Fn(&P) -> R + Sync,
    F: FnMut(Option<(&P, R)>) -> Result<()>,
{
    let progress = Progress::new(total, what, quiet).starting_at(before);
    let mut failure = None;
    let done = run_chunks(points, rayon::current_num_threads() * 4, work, |d| {
        let (written, checkpoint) = match d {
            Delivery::Point(p, r) => {
                progress.inc(1);
                (write(Some((p, r))), false)
            }
            Delivery::Chunk(_) => (write(None), true),
        };
        if let Err(e) = written {
            failure = Some(e);
            return ControlFlow::Break(());
        }
        if checkpoint && interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    progress.finish();
    match failure {
        Some(e) => Err(e),
        None => Ok(done),
    }
}

/// Installs the worker-thread count (once per process).
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    if let Some(n) = threads {
        if n == 0 {
            bail!("--threads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| anyhow!("cannot set up {n} threads: {e}"))?;
    }
    Ok(())
}

/// Files of a sweep directory: `orbit.csv`, `impacts.csv`, `summary.csv` (the index file,
/// one row per value; its columns are [`PointColumns`]) and the manifest `sweep.json`.
fn sweep_layout(masses: usize, columns: PointColumns) -> Layout {
    let mut orbit_cols = vec!["param".to_string(), "period".to_string()];
    orbit_cols.extend(numbered("x", masses, "_m"));
    let mut summary_cols = vec!["param".to_string()];
    summary_cols.extend(columns.names());
    Layout {
        manifest: "sweep.json",
        files: vec![
            CsvSpec {
                name: "orbit.csv",
                columns: orbit_cols,
            },
            CsvSpec {
                name: "impacts.csv",
                columns: ["param", "time_s", "contact", "rel_velocity_m_s"]
                    .map(String::from)
                    .to_vec(),
            },
            CsvSpec {
                name: "summary.csv",
                columns: summary_cols,
            },
        ],
        index_file: 2,
        key_fields: 1,
    }
}

/// Writes one value's rows: orbit, impacts, then its summary row (last, see [`crate::job`]).
fn write_value(
    out: &mut GridOutput,
    value: f64,
    result: &Result<PointResult, String>,
    columns: PointColumns,
) -> Result<()> {
    let p = value.to_string();
    if let Ok(r) = result {
        // Masses per stroboscopic sample.
        let n = r.strobe.len() / r.strobe_periods.len().max(1);
        for (j, &period) in r.strobe_periods.iter().enumerate() {
            let mut row = vec![p.clone(), period.to_string()];
            row.extend(r.strobe[j * n..(j + 1) * n].iter().map(f64::to_string));
            out.row(0, row)?;
        }
        for i in &r.impacts {
            out.row(
                1,
                vec![
                    p.clone(),
                    i.time.to_string(),
                    (i.contact + 1).to_string(),
                    i.closing_speed.to_string(),
                ],
            )?;
        }
    }
    let mut row = vec![p];
    row.extend(columns.cells(result));
    out.row(2, row)
}

/// The point columns of a chain with `contacts` contacts
/// ([`ChainParams::contact_count`](vibrotribo::ChainParams::contact_count)).
pub fn point_columns(contacts: usize, floquet: bool, lyapunov: bool) -> PointColumns {
    PointColumns {
        contacts,
        floquet,
        lyapunov,
    }
}

/// The settings a sweep records in `sweep.json` (everything that determines its output).
fn settings_json(
    args: &SweepArgs,
    runner: &PointRunner,
    values: &[f64],
    shard: Option<Shard>,
) -> serde_json::Value {
    let o = runner.options();
    let mut settings = json!({
        "command": "sweep",
        "param": args.param,
        "from": args.from,
        "to": args.to,
        "steps": args.steps,
        "values": values,
        "continuation": args.continuation,
        "transient_periods": o.transient_periods,
        "recorded_periods": o.recorded_periods,
        "period_tolerance": o.period_tolerance,
        "max_period_detected": o.period_options().max_period,
        "grazing_ratio": o.grazing_ratio,
        "electrical_warmup_periods": o.electrical_warmup_periods,
        "mechanics_only": args.run.mechanics_only,
        "shard": shard.map(|s| json!({"index": s.index, "count": s.count})),
        "settings": runner.base().table(),
        "vibrotribo_version": env!("CARGO_PKG_VERSION"),
    });
    if o.floquet {
        settings["floquet"] = json!(true);
    }
    add_settle_settings(&mut settings, o);
    add_base_motion(&mut settings, runner.base());
    if args.lyapunov {
        // Only with the option, so that other sweeps' manifests stay as they were.
        settings["lyapunov"] = json!(true);
    }
    settings
}

/// Records the base motion of `config` in a manifest (`base_motion`, when it is not the
/// chain's own harmonic: kind, how it was run, spline accuracy, record scaling).
pub fn add_base_motion(settings: &mut serde_json::Value, config: &vibrotribo::config::Config) {
    if let Some(b) = vibrotribo::report::base_motion_json(config, &config.run_spec(true)) {
        settings["base_motion"] = b;
    }
}

/// Records the settling of `options` in a manifest (`sweep.json`, `map.json`): `settle`
/// (`auto` or `fixed`), and for `auto` `settle_cap_periods` and `settle_block_periods`.
pub fn add_settle_settings(settings: &mut serde_json::Value, options: &PointOptions) {
    settings["settle"] = json!(options.settle.as_str());
    if let SettleMode::Auto(a) = &options.settle {
        settings["settle_cap_periods"] = json!(a.cap_periods);
        settings["settle_block_periods"] = json!(a.block);
        settings["settle_newton"] = json!(a.shoot);
    }
}

/// Checks that a grid's values are distinct: rows are keyed by their value.
pub fn check_distinct(what: &str, values: &[f64]) -> Result<()> {
    let mut seen = std::collections::HashSet::new();
    for v in values {
        if !seen.insert(v.to_bits()) {
            bail!("{what}: the grid repeats the value {v} (use --steps 1 for a single value)");
        }
    }
    Ok(())
}

/// Estimated bytes written per point of a sweep or map (the orbit rows dominate).
pub fn estimate_point_output(runner: &PointRunner, orbit: bool) -> f64 {
    let o = runner.options();
    let n = runner.masses() as f64;
    let orbit_bytes = if orbit {
        o.recorded_periods as f64 * (n + 2.0) * limits::CSV_NUMBER_BYTES
    } else {
        0.0
    };
    orbit_bytes + (n + 8.0) * limits::CSV_NUMBER_BYTES
}

/// Estimated memory of one point's run (stroboscopic samples and per-period counts).
pub fn estimate_point_memory(runner: &PointRunner) -> f64 {
    let o = runner.options();
    let n = runner.masses() as f64;
    let before = match &o.settle {
        SettleMode::Auto(a) => a.cap_periods.max(o.transient_periods),
        SettleMode::Fixed => o.transient_periods,
    };
    (before + o.recorded_periods) as f64 * (8.0 * n + 96.0)
}

/// Runs `vibrotribo sweep`.
pub fn run(args: &SweepArgs) -> Result<()> {
    if args.steps == 0 {
        bail!("--steps must be at least 1");
    }
    limits::check_grid("--steps", args.steps as f64)?;
    if !args.from.is_finite() || !args.to.is_finite() {
        bail!("--from and --to must be finite numbers");
    }
    if args.resume && args.out.is_none() {
        bail!("--resume needs --out DIR (the directory of the job to continue)");
    }
    if args.shard.is_some() && args.continuation != Continuation::None {
        bail!(
            "--shard needs --continuation none: a continuation is one sequential chain (run `up` and `down` as separate jobs instead)"
        );
    }
    set_threads(args.run.threads)?;
    let base = args.input.load()?;
    if args.lyapunov {
        base.check_periodic("--lyapunov (Lyapunov exponents)")?;
    }
    if args.continuation != Continuation::None {
        // Each value starts at t = 0 from the previous one's final state: that is the same
        // phase of the base motion only if the motion is periodic.
        base.check_periodic("sweep --continuation")?;
    }
    let mut runner = args.run.runner(base)?;
    if args.lyapunov {
        let options = PointOptions {
            lyapunov: Some(LyapunovOptions::default()),
            ..runner.options().clone()
        };
        runner = PointRunner::new(runner.base().clone(), options, runner.mechanics_only());
    }
    let masses = runner.masses();
    let columns = point_columns(runner.contacts(), runner.options().floquet, args.lyapunov);
    let values = grid(args.from, args.to, args.steps);
    check_distinct("--from/--to/--steps", &values)?;
    // Fail early on a bad key or on any value of the grid that makes a bad configuration.
    check_all(&runner, &values, |&v| vec![(args.param.as_str(), v)])?;
    let mut order: Vec<usize> = (0..values.len()).collect();
    if args.continuation == Continuation::Down {
        order.reverse();
    }
    if let Some(s) = args.shard {
        order.retain(|j| j % s.count == s.index);
    }
    let threads = rayon::current_num_threads() as f64;
    limits::check_memory(
        "one value of the sweep (--transient + --recorded periods)",
        estimate_point_memory(&runner) * threads * 4.0,
        args.run.allow_large,
    )?;
    if args.out.is_some() {
        limits::check_output(
            "the sweep's files",
            estimate_point_output(&runner, true) * order.len() as f64,
            args.run.allow_large,
        )?;
    }
    let keys: Vec<String> = order.iter().map(|&j| values[j].to_string()).collect();
    let settings = settings_json(args, &runner, &values, args.shard);
    let continued = args.continuation != Continuation::None;
    let mut state: Option<ChainState> = None;
    let (mut out, skip) = match &args.out {
        None => (None, 0),
        Some(dir) if args.resume => {
            let checkpoint = if continued {
                crate::job::read_checkpoint(dir)?
            } else {
                None
            };
            let keep = if continued {
                checkpoint.as_ref().map_or(0, |c| c.0)
            } else {
                order.len()
            };
            let (o, done) = GridOutput::resume(dir, sweep_layout(masses, columns), settings, &keys, keep)?;
            if let Some((n, s)) = checkpoint.filter(|c| c.0 == done && done > 0) {
                state = Some(serde_json::from_value(s).map_err(|e| {
                    anyhow!(
                        "--resume: {}/{} is damaged: {e}",
                        dir.display(),
                        crate::job::CHECKPOINT
                    )
                })?);
                debug_assert_eq!(n, done);
            }
            (Some(o), done)
        }
        Some(dir) => (
            Some(GridOutput::create(dir, sweep_layout(masses, columns), settings)?),
            0,
        ),
    };
    let started = Instant::now();
    let mut failed = 0usize;
    let key = args.param.as_str();
    let todo = &order[skip..];
    let computed = match args.continuation {
        Continuation::None => run_points(
            &runner,
            todo,
            |&j| vec![(key, values[j])],
            ("values", skip as u64, order.len() as u64),
            args.run.quiet,
            |point| match (point, out.as_mut()) {
                (Some((&j, r)), o) => {
                    failed += usize::from(r.is_err());
                    o.map_or(Ok(()), |o| write_value(o, values[j], r, columns))
                }
                (None, Some(o)) => o.commit(),
                (None, None) => Ok(()),
            },
        )?,
        Continuation::Up | Continuation::Down => {
            let progress =
                Progress::new(order.len() as u64, "values", args.run.quiet).starting_at(skip as u64);
            let mut written = 0usize;
            let mut failure = None;
            let (done, _) = run_continued(&runner, key, &values, todo, state, |j, r, state| {
                let r = r.map_err(|e| error_text(&e));
                failed += usize::from(r.is_err());
                written += 1;
                if let Some(o) = out.as_mut() {
                    let w = write_value(o, values[j], &r, columns)
                        .and_then(|()| o.checkpoint(skip + written, json!(state)));
                    if let Err(e) = w {
                        failure = Some(e);
                        return Ok(ControlFlow::Break(()));
                    }
                }
                progress.inc(1);
                Ok(if interrupted() {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                })
            })?;
            progress.finish();
            if let Some(e) = failure {
                return Err(e);
            }
            done
        }
    };
    let done = skip + computed;
    let complete = done == order.len();
    if let (Some(o), Some(dir)) = (out, &args.out) {
        o.finish(complete, done)?;
        if complete && args.plot {
            crate::plots::plot_sweep(dir)?;
        }
    }
    println!(
        "sweep of {} over {} values from {} to {}{}: {computed} computed{} ({failed} failed) in {:.2} s on {} threads",
        args.param,
        values.len(),
        args.from,
        args.to,
        args.shard
            .map_or(String::new(), |s| format!(" (shard {}/{})", s.index, s.count)),
        if skip > 0 {
            format!(", {skip} kept from before")
        } else {
            String::new()
        },
        started.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    if let Some(dir) = &args.out {
        println!(
            "  wrote {0}/orbit.csv, {0}/impacts.csv, {0}/summary.csv, {0}/sweep.json",
            dir.display()
        );
    }
    if !complete {
        return Err(Interrupted {
            what: format!(
                "the files hold the {done} of {} values finished, marked incomplete in sweep.json; \
                 the same command with --resume continues",
                order.len()
            ),
        }
        .into());
    }
    Ok(())
}

/// Options of `vibrotribo merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Output directories of the shards of one sweep or map (`--shard I/N`).
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Where to write the merged files (a new or empty directory).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// The keys (`param` values as written) of a sweep's grid from its `sweep.json`.
fn sweep_keys(settings: &serde_json::Value) -> Result<Vec<String>> {
    settings["values"]
        .as_array()
        .ok_or_else(|| anyhow!("sweep.json lacks the values"))?
        .iter()
        .map(|v| {
            v.as_f64()
                .map(|x| x.to_string())
                .ok_or_else(|| anyhow!("sweep.json: a value is not a number"))
        })
        .collect()
}

/// Runs `vibrotribo merge`.
pub fn merge(args: &MergeArgs) -> Result<()> {
    let first = &args.shards[0];
    if first.join("map.json").exists() {
        crate::map::merge(args)?;
    } else if first.join("basins.json").exists() {
        crate::basins::merge(args)?;
    } else {
        // orbit.csv: param, period, x1_m, …, xN_m.
        let masses = header_len(&first.join("orbit.csv"))?.saturating_sub(2);
        let floquet = floquet_of(first, "sweep.json")?;
        let lyapunov = crate::output::read_json(&first.join("sweep.json"))?["lyapunov"] == json!(true);
        // summary.csv: param, then the point columns.
        let columns = PointColumns::from_width(
            header_len(&first.join("summary.csv"))?.saturating_sub(1),
            floquet,
            lyapunov,
        );
        crate::job::merge(
            &args.shards,
            &args.out,
            &sweep_layout(masses, columns),
            sweep_keys,
        )?;
    }
    println!("merged {} shards into {}", args.shards.len(), args.out.display());
    Ok(())
}

/// Whether the job in `dir` (manifest `manifest`) has the Floquet column.
pub fn floquet_of(dir: &Path, manifest: &str) -> Result<bool> {
    Ok(crate::output::read_json(&dir.join(manifest))?["floquet"].as_bool() == Some(true))
}

/// The number of columns of the CSV file `path` (from its header).
pub fn header_len(path: &Path) -> Result<usize> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(text.lines().next().unwrap_or("").split(',').count())
}
