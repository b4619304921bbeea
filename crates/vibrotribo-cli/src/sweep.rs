//! `vibrotribo sweep` and `vibrotribo merge`: one-parameter sweeps (orbit diagrams,
//! impact-velocity diagrams, power curves), parallel, continued, or sharded across machines.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use rayon::prelude::*;
use serde_json::json;
use vibrotribo::analysis::{PointOptions, PointResult, run_point};
use vibrotribo::{ChainParams, ChainState};

use crate::config::{ConfigArgs, Loaded, RunSpec};
use crate::output::{CsvFile, create_dir, numbered, point_cells, point_columns, read_json, write_json};
use crate::progress::{Progress, interrupted};

/// Direction of parameter continuation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Continuation {
    /// Every value starts from the configured initial state; values run in parallel.
    None,
    /// Values in increasing order, each starting from the previous one's final state.
    Up,
    /// Values in decreasing order, each starting from the previous one's final state.
    Down,
}

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
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
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
    #[arg(long)]
    pub from: f64,
    /// Last value.
    #[arg(long)]
    pub to: f64,
    /// Number of values, equally spaced from --from to --to.
    #[arg(long)]
    pub steps: usize,
    /// Carry the final state to the next value (`up`, `down`), or start every value afresh
    /// (`none`, parallel).
    #[arg(long, value_enum, default_value_t = Continuation::None)]
    pub continuation: Continuation,
    /// Compute only the I-th of N interleaved slices of the grid (0 ≤ I < N), e.g.
    /// `--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`; combine with `vibrotribo merge`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Write orbit.csv, impacts.csv, summary.csv and sweep.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the diagrams (PNG and SVG) into the output directory.
    #[arg(long)]
    pub plot: bool,
    #[command(flatten)]
    pub run: RunArgs,
}

/// The grid of a sweep: `steps` values from `from` to `to`.
pub fn grid(from: f64, to: f64, steps: usize) -> Vec<f64> {
    match steps {
        0 => Vec::new(),
        1 => vec![from],
        _ => (0..steps)
            .map(|j| {
                if j == steps - 1 {
                    to
                } else {
                    from + (to - from) * j as f64 / (steps - 1) as f64
                }
            })
            .collect(),
    }
}

/// Everything needed to run one value of a sweep or a map.
pub struct PointRunner {
    base: Loaded,
    masses: usize,
    options: PointOptions,
    mechanics_only: bool,
}

impl PointRunner {
    /// A runner for the configuration `base`.
    pub fn new(base: Loaded, run: &RunArgs) -> Result<Self> {
        let params = base.config.chain_params()?;
        let spec = base.config.run_spec(&params)?;
        let transient = run.transient.unwrap_or(spec.transient_periods);
        let recorded = run.recorded.unwrap_or(spec.periods - spec.transient_periods);
        if recorded == 0 {
            bail!("--recorded must be at least 1");
        }
        if !(run.period_tolerance > 0.0 && run.period_tolerance < 1.0) {
            bail!(
                "--period-tolerance must lie in (0, 1), got {}",
                run.period_tolerance
            );
        }
        Ok(PointRunner {
            base,
            masses: params.len(),
            options: PointOptions {
                transient_periods: transient,
                recorded_periods: recorded,
                period_tolerance: run.period_tolerance,
                ..PointOptions::default()
            },
            mechanics_only: run.mechanics_only,
        })
    }

    /// The point options in use.
    pub fn options(&self) -> &PointOptions {
        &self.options
    }

    /// The base configuration.
    pub fn base(&self) -> &Loaded {
        &self.base
    }

    /// Number of masses of the chain (the same at every point: keys set numbers, not arrays).
    pub fn masses(&self) -> usize {
        self.masses
    }

    /// The base configuration with `keys` set to `values`: its chain and run settings.
    fn configure(&self, keys: &[(&str, f64)]) -> Result<(Loaded, ChainParams, RunSpec)> {
        let mut loaded = self.base.clone();
        for (k, v) in keys {
            loaded = loaded.with(k, *v)?;
        }
        let params = loaded.config.chain_params()?;
        let spec = loaded.config.run_spec(&params)?;
        Ok((loaded, params, spec))
    }

    /// Checks that the configuration with `keys` set to `values` is valid, without running it.
    pub fn check(&self, keys: &[(&str, f64)]) -> Result<()> {
        let (loaded, params, _) = self.configure(keys)?;
        if !self.mechanics_only {
            loaded.harvester(&params)?;
        }
        Ok(())
    }

    /// Checks every point of a grid (`keys` gives each point's settings); the error names
    /// the first bad point.
    pub fn check_all<'k, P>(&self, points: &[P], keys: impl Fn(&P) -> Vec<(&'k str, f64)>) -> Result<()> {
        for p in points {
            let k = keys(p);
            self.check(&k).with_context(|| {
                k.iter()
                    .map(|(key, v)| format!("{key} = {v}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            })?;
        }
        Ok(())
    }

    /// Runs the configuration with `keys` set to `values`, from `initial` (or the configured
    /// initial state).
    pub fn run(&self, keys: &[(&str, f64)], initial: Option<&ChainState>) -> Result<PointResult> {
        let (loaded, params, spec) = self.configure(keys)?;
        let sim_options = loaded.config.sim_options()?;
        let harvester = if self.mechanics_only {
            None
        } else {
            Some((loaded.harvester(&params)?, loaded.charge_options()?))
        };
        let initial = match initial {
            Some(s) if s.positions.len() == params.len() && params.validate_state(s).is_ok() => s.clone(),
            _ => spec.initial,
        };
        Ok(run_point(
            &params,
            &initial,
            &sim_options,
            harvester.as_ref().map(|(h, o)| (h, o)),
            &self.options,
        )?)
    }
}

/// Runs `points` in parallel chunks, calling `write` in grid order (so the output does not
/// depend on the thread count) and ticking a progress bar labelled `what`; stops after the
/// current chunk on Ctrl-C, keeping what was written. Returns how many were written.
pub fn run_grid<'k, P, W>(
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)> + Sync,
    what: &str,
    quiet: bool,
    mut write: W,
) -> Result<usize>
where
    P: Sync,
    W: FnMut(&P, &Result<PointResult, String>) -> Result<()>,
{
    let progress = Progress::new(points.len() as u64, what, quiet);
    let chunk = rayon::current_num_threads() * 4;
    let mut done = 0;
    for block in points.chunks(chunk) {
        let results: Vec<Result<PointResult, String>> = block
            .par_iter()
            .map(|p| runner.run(&keys(p), None).map_err(|e| format!("{e:#}")))
            .collect();
        for (p, r) in block.iter().zip(&results) {
            write(p, r)?;
            done += 1;
            progress.inc(1);
        }
        if interrupted() {
            break;
        }
    }
    progress.finish();
    Ok(done)
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

/// The output files of a sweep, written value by value in order.
struct SweepFiles {
    orbit: CsvFile,
    impacts: CsvFile,
    summary: CsvFile,
    contacts: usize,
}

impl SweepFiles {
    fn create(dir: &Path, masses: usize) -> Result<Self> {
        create_dir(dir)?;
        let mut orbit_cols = vec!["param".to_string(), "period".to_string()];
        orbit_cols.extend(numbered("x", masses, "_m"));
        let mut summary_cols = vec!["param".to_string()];
        summary_cols.extend(point_columns(masses - 1));
        Ok(SweepFiles {
            orbit: CsvFile::create(&dir.join("orbit.csv"), &orbit_cols)?,
            impacts: CsvFile::create(
                &dir.join("impacts.csv"),
                &["param", "time_s", "contact", "rel_velocity_m_s"],
            )?,
            summary: CsvFile::create(&dir.join("summary.csv"), &summary_cols)?,
            contacts: masses - 1,
        })
    }

    fn write(&mut self, value: f64, result: &Result<PointResult, String>) -> Result<()> {
        let p = value.to_string();
        if let Ok(r) = result {
            let n = self.contacts + 1;
            for (j, &period) in r.strobe_periods.iter().enumerate() {
                let mut row = vec![p.clone(), period.to_string()];
                row.extend(r.strobe[j * n..(j + 1) * n].iter().map(f64::to_string));
                self.orbit.row(row)?;
            }
            for i in &r.impacts {
                self.impacts.row([
                    p.clone(),
                    i.time.to_string(),
                    (i.contact + 1).to_string(),
                    i.closing_speed.to_string(),
                ])?;
            }
        }
        let mut row = vec![p];
        row.extend(point_cells(result, self.contacts));
        self.summary.row(row)
    }

    fn flush(&mut self) -> Result<()> {
        self.orbit.flush()?;
        self.impacts.flush()?;
        self.summary.flush()
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
    json!({
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
        "settings": runner.base().table,
        "vibrotribo_version": env!("CARGO_PKG_VERSION"),
    })
}

/// Runs `vibrotribo sweep`.
pub fn run(args: &SweepArgs) -> Result<()> {
    if args.steps == 0 {
        bail!("--steps must be at least 1");
    }
    if !args.from.is_finite() || !args.to.is_finite() {
        bail!("--from and --to must be finite numbers");
    }
    if args.plot && args.out.is_none() {
        bail!("--plot needs --out DIR");
    }
    if args.shard.is_some() && args.continuation != Continuation::None {
        bail!(
            "--shard needs --continuation none: a continuation is one sequential chain (run `up` and `down` as separate jobs instead)"
        );
    }
    set_threads(args.run.threads)?;
    let base = args.input.load()?;
    let runner = PointRunner::new(base, &args.run)?;
    let masses = runner.masses();
    let values = grid(args.from, args.to, args.steps);
    // Fail early on a bad key or on any value of the grid that makes a bad configuration.
    runner.check_all(&values, |&v| vec![(args.param.as_str(), v)])?;
    let mut order: Vec<usize> = (0..values.len()).collect();
    if args.continuation == Continuation::Down {
        order.reverse();
    }
    if let Some(s) = args.shard {
        order.retain(|j| j % s.count == s.index);
    }
    let mut files = match &args.out {
        Some(dir) => Some(SweepFiles::create(dir, masses)?),
        None => None,
    };
    let started = Instant::now();
    let mut failed = 0usize;
    let mut record = |value: f64, result: &Result<PointResult, String>| -> Result<()> {
        if result.is_err() {
            failed += 1;
        }
        match files.as_mut() {
            Some(f) => f.write(value, result),
            None => Ok(()),
        }
    };
    let key = args.param.as_str();
    let done = match args.continuation {
        Continuation::None => run_grid(
            &runner,
            &order,
            |&j| vec![(key, values[j])],
            "values",
            args.run.quiet,
            |&j, r| record(values[j], r),
        )?,
        Continuation::Up | Continuation::Down => {
            let progress = Progress::new(order.len() as u64, "values", args.run.quiet);
            let mut done = 0usize;
            let mut state: Option<ChainState> = None;
            for &j in &order {
                let r = runner
                    .run(&[(key, values[j])], state.as_ref())
                    .map_err(|e| format!("{e:#}"));
                if let Ok(p) = &r {
                    state = Some(p.final_state.clone());
                }
                record(values[j], &r)?;
                done += 1;
                progress.inc(1);
                if interrupted() {
                    break;
                }
            }
            progress.finish();
            done
        }
    };
    let complete = done == order.len();
    if let (Some(f), Some(dir)) = (files.as_mut(), &args.out) {
        f.flush()?;
        let mut settings = settings_json(args, &runner, &values, args.shard);
        settings["complete"] = json!(complete);
        write_json(&dir.join("sweep.json"), &settings)?;
        if args.plot {
            crate::plots::plot_sweep(dir)?;
        }
    }
    println!(
        "sweep of {} over {} values from {} to {}{}: {done} computed ({failed} failed) in {:.2} s on {} threads",
        args.param,
        values.len(),
        args.from,
        args.to,
        args.shard
            .map_or(String::new(), |s| format!(" (shard {}/{})", s.index, s.count)),
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
        eprintln!("interrupted: the files hold the {done} values finished; rerun to complete");
    }
    Ok(())
}

/// Options of `vibrotribo merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Output directories of the shards of one sweep (`--shard I/N`).
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Where to write the merged files.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Rows of a CSV file grouped by their first field (the parameter value), keeping order.
fn rows_by_param(path: &Path) -> Result<(String, BTreeMap<u64, Vec<String>>)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut lines = text.lines();
    let header = lines
        .next()
        .ok_or_else(|| anyhow!("{} is empty", path.display()))?
        .to_string();
    let mut groups: BTreeMap<u64, Vec<String>> = BTreeMap::new();
    for line in lines {
        let p = line.split(',').next().unwrap_or("");
        let v: f64 = p
            .parse()
            .with_context(|| format!("{}: bad parameter value {p:?}", path.display()))?;
        groups.entry(v.to_bits()).or_default().push(line.to_string());
    }
    Ok((header, groups))
}

/// Runs `vibrotribo merge`.
pub fn merge(args: &MergeArgs) -> Result<()> {
    let mut settings: Option<serde_json::Value> = None;
    let mut seen = vec![];
    let mut complete = true;
    for dir in &args.shards {
        let mut s = read_json(&dir.join("sweep.json"))?;
        let shard = s["shard"].clone();
        if shard.is_null() {
            bail!("{} is not a shard (it was run without --shard)", dir.display());
        }
        complete &= s["complete"].as_bool().unwrap_or(false);
        seen.push((
            shard["index"].as_u64().unwrap_or(0),
            shard["count"].as_u64().unwrap_or(0),
        ));
        s["shard"] = serde_json::Value::Null;
        s["complete"] = serde_json::Value::Null;
        match &settings {
            None => settings = Some(s),
            Some(first) if *first != s => bail!("{} is a shard of a different sweep", dir.display()),
            Some(_) => {}
        }
    }
    let mut settings = settings.expect("at least one shard");
    let count = seen[0].1;
    let mut indices: Vec<u64> = seen.iter().map(|s| s.0).collect();
    indices.sort_unstable();
    indices.dedup();
    if seen.iter().any(|s| s.1 != count) || indices.len() != seen.len() || indices.len() as u64 != count {
        bail!("need each of the {count} shards exactly once, got indices {indices:?}");
    }
    if !complete {
        bail!("some shards are incomplete (interrupted): rerun them before merging");
    }
    settings["complete"] = json!(true);
    // Grid order is the order of the values.
    let values: Vec<f64> = settings["values"]
        .as_array()
        .ok_or_else(|| anyhow!("sweep.json lacks the values"))?
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::NAN))
        .collect();
    create_dir(&args.out)?;
    for name in ["orbit.csv", "impacts.csv", "summary.csv"] {
        let mut header = None;
        let mut all: BTreeMap<u64, Vec<String>> = BTreeMap::new();
        for dir in &args.shards {
            let (h, groups) = rows_by_param(&dir.join(name))?;
            if header.as_ref().is_some_and(|x| *x != h) {
                bail!("{}: header differs between shards", name);
            }
            header = Some(h);
            for (k, rows) in groups {
                if all.insert(k, rows).is_some() {
                    bail!("{name}: a value appears in two shards");
                }
            }
        }
        let mut text = header.unwrap_or_default();
        text.push('\n');
        for v in &values {
            if let Some(rows) = all.remove(&v.to_bits()) {
                for r in rows {
                    text.push_str(&r);
                    text.push('\n');
                }
            }
        }
        if !all.is_empty() {
            bail!("{name}: rows for values outside the sweep's grid");
        }
        let path = args.out.join(name);
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    write_json(&args.out.join("sweep.json"), &settings)?;
    println!("merged {} shards into {}", args.shards.len(), args.out.display());
    Ok(())
}
