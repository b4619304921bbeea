//! `vibrotribo sweep`: one-parameter sweeps (orbit diagrams, impact-velocity diagrams, power
//! curves), parallel, continued, or sharded across machines (and the merge of a sweep's
//! shards).

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use serde::Deserialize;
use serde_json::json;
use vibrotribo::ChainState;
use vibrotribo::lyapunov::LyapunovOptions;
use vibrotribo::study::{PointOptions, PointResult};
use vibrotribo::sweep::{
    Cell, Continuation, IMPACT_COLUMNS, PointColumns, PointRunner, SweepError, grid, impact_rows, is_stopped,
    orbit_columns, orbit_rows, run_continued,
};

use crate::config::ConfigArgs;
use crate::job::{
    CsvSpec, GridOutput, Layout, MergeArgs, RunArgs, Shard, check_all, check_distinct, estimate_point_memory,
    estimate_point_output, header_len, point_columns, run_points, set_threads,
};
use crate::limits;
use crate::manifest::{Axis, ShardRecord, SweepManifest, to_value};
use crate::progress::{Interrupted, Progress, interrupted, orbit_cancel};

/// Options of `vibrotribo sweep`.
#[derive(Debug, clap::Args)]
pub struct SweepArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The swept parameter: a configuration key (`excitation.omega_ratio`,
    /// `oscillator.gaps[1]`, `harvester.load_resistance`, …) or a derived one (`mass_ratio`,
    /// `gap_ratio`, `gap`, `omega_ratio`, `restitution`, …); an integer key
    /// (`excitation.seed`) takes whole values.
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

/// Files of a sweep directory: `orbit.csv`, `impacts.csv`, `summary.csv` (the index file,
/// one row per value; its columns are [`PointColumns`]) and the manifest `sweep.json`.
fn sweep_layout(masses: usize, columns: PointColumns) -> Layout {
    let keyed = |rest: Vec<String>| {
        let mut cols = vec!["param".to_string()];
        cols.extend(rest);
        cols
    };
    Layout {
        manifest: "sweep.json",
        files: vec![
            CsvSpec {
                name: "orbit.csv",
                columns: keyed(orbit_columns(masses)),
            },
            CsvSpec {
                name: "impacts.csv",
                columns: keyed(IMPACT_COLUMNS.map(String::from).to_vec()),
            },
            CsvSpec {
                name: "summary.csv",
                columns: keyed(columns.names()),
            },
        ],
        index_file: 2,
        key_fields: 1,
    }
}

/// Writes one value's rows (the library's [`orbit_rows`], [`impact_rows`] and
/// [`PointColumns::cells`]): orbit, impacts, then its summary row (last, see [`crate::job`]).
fn write_value(
    out: &mut GridOutput,
    (value, masses): (f64, usize),
    result: &Result<PointResult, SweepError>,
    columns: PointColumns,
) -> Result<()> {
    let text = |row: Vec<Cell>| row.iter().map(ToString::to_string).collect::<Vec<_>>();
    if let Ok(r) = result {
        for row in orbit_rows(&[value], masses, r) {
            out.row(0, text(row))?;
        }
        for row in impact_rows(&[value], r) {
            out.row(1, text(row))?;
        }
    }
    let mut row = vec![Cell::Float(value)];
    row.extend(columns.cells(result));
    out.row(2, text(row))
}

/// The manifest `sweep.json` of a sweep (everything that determines its output).
fn manifest(
    args: &SweepArgs,
    runner: &PointRunner,
    values: &[f64],
    shard: Option<Shard>,
) -> Result<SweepManifest> {
    let axis = Axis {
        param: args.param.clone(),
        from: args.from,
        to: args.to,
        steps: args.steps,
        values: values.to_vec(),
    };
    let mut m = SweepManifest::new(axis, args.continuation, runner, args.lyapunov)
        .context("the configuration as JSON")?;
    m.shard = shard.map(|s| ShardRecord {
        index: s.index,
        count: s.count,
    });
    Ok(m)
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
    let base = args.input.load_within(args.run.allow_large)?;
    if args.lyapunov {
        base.check_periodic("--lyapunov (Lyapunov exponents)")?;
    }
    if args.continuation != Continuation::None {
        // Each value starts at t = 0 from the previous one's final state: that is the same
        // phase of the base motion only if the motion is periodic.
        base.check_periodic("sweep --continuation")?;
    }
    // A point stops part-way on SIGINT/SIGTERM (and is not written).
    let mut runner = args.run.runner(base)?.with_cancel(orbit_cancel());
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
    let settings = to_value(&manifest(args, &runner, &values, args.shard)?)?;
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
            Some(GridOutput::create(
                dir,
                sweep_layout(masses, columns),
                settings,
                args.run.force,
            )?),
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
                    o.map_or(Ok(()), |o| write_value(o, (values[j], masses), r, columns))
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
            run_continued(&runner, key, &values, todo, state, |j, r, state| {
                if is_stopped(&r) {
                    return Ok(ControlFlow::Break(()));
                }
                failed += usize::from(r.is_err());
                written += 1;
                if let Some(o) = out.as_mut() {
                    let w = write_value(o, (values[j], masses), &r, columns)
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
            written
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

/// The keys (`param` values as written) of a sweep's grid from its `sweep.json`.
fn sweep_keys(settings: &serde_json::Value) -> Result<Vec<String>> {
    let m = SweepManifest::deserialize(settings).context("sweep.json")?;
    Ok(m.axis.values.iter().map(f64::to_string).collect())
}

/// Combines the shards of one sweep (`vibrotribo merge` of `sweep.json` directories).
pub fn merge(args: &MergeArgs) -> Result<()> {
    let first = &args.shards[0];
    // orbit.csv: param, period, x1_m, …, xN_m.
    let masses = header_len(&first.join("orbit.csv"))?.saturating_sub(2);
    let m: SweepManifest = crate::manifest::read(&first.join("sweep.json"))?;
    // summary.csv: param, then the point columns.
    let columns = PointColumns::from_width(
        header_len(&first.join("summary.csv"))?.saturating_sub(1),
        m.floquet,
        m.lyapunov,
    );
    crate::job::merge(
        &args.shards,
        &args.out,
        &sweep_layout(masses, columns),
        sweep_keys,
    )
}
