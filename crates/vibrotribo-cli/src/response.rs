//! `vibrotribo response`: the frequency response of a configuration
//! ([`vibrotribo::response::frequency_response`]): power against a parameter from an up and
//! a down sweep and, with `--branches`, on the branches of periodic orbits through the
//! motions they found; the peak and half-power band of each; `response.csv`,
//! `branches.csv`, `response.json` and the picture.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::time::Instant;

use anyhow::{Result, bail};
use vibrotribo::orbits::ShootingOptions;
use vibrotribo::response::{
    BandwidthRecord, BranchSeeding, DEFAULT_MAX_SEEDS, FrequencyResponse, ResponseOptions, ResponseStep,
    Rows, branch_table, frequency_response, response_table,
};
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP, Direction, SettleMode};
use vibrotribo::sweep::{PointRunner, grid};

use crate::config::ConfigArgs;
use crate::continuation::end_text;
use crate::job::{RunArgs, estimate_point_memory};
use crate::limits;
use crate::manifest::{Axis, ResponseManifest, to_value};
use crate::output::{CsvFile, check_out_dir, create_dir, write_json};
use crate::progress::{Interrupted, Progress, interrupted, orbit_cancel};
use crate::response_picture::band_text;

/// The run settings of each value (or run) of `response` and `band-response`.
#[derive(Debug, clap::Args)]
pub struct PointArgs {
    /// Transient periods per value (default: the configuration's run.transient_periods).
    #[arg(long)]
    pub transient: Option<u64>,
    /// Recorded periods per value (default: run.periods − run.transient_periods).
    #[arg(long)]
    pub recorded: Option<u64>,
    /// Relative tolerance of the period detection.
    #[arg(long, default_value_t = DEFAULT_PERIOD_TOLERANCE)]
    pub period_tolerance: f64,
    /// How long each value runs before its recorded window: `auto` until the motion repeats,
    /// at most --settle-cap periods; `fixed` exactly --transient periods (a base motion that
    /// is not periodic always runs fixed).
    #[arg(long, default_value = "auto", value_name = "auto|fixed")]
    pub settle: SettleMode,
    /// Most periods `--settle auto` runs before the recorded window.
    #[arg(long, default_value_t = DEFAULT_SETTLE_CAP, value_name = "PERIODS")]
    pub settle_cap: u64,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run even if the estimated memory exceeds 4 GiB, or a random base motion's build
    /// exceeds 10⁹ harmonic evaluations.
    #[arg(long)]
    pub allow_large: bool,
    /// Write into an --out directory that holds another command's results.
    #[arg(long)]
    pub force: bool,
}

impl PointArgs {
    /// The point runner on `config` (refused for a chain without a harvester: a response is
    /// power).
    pub fn runner(&self, config: vibrotribo::config::Config) -> Result<PointRunner> {
        let runner = RunArgs {
            transient: self.transient,
            recorded: self.recorded,
            mechanics_only: false,
            period_tolerance: self.period_tolerance,
            floquet: false,
            settle: self.settle,
            settle_cap: self.settle_cap,
            threads: None,
            quiet: self.quiet,
            allow_large: self.allow_large,
            force: self.force,
        }
        .runner(config)?;
        if runner.mechanics_only() {
            bail!("a single mass has no harvester: there is no power to take a response of");
        }
        Ok(runner)
    }

    /// Refuses a job of `points` runs, `parallel` at a time, beyond the limits.
    pub fn check_size(&self, what: &str, runner: &PointRunner, points: f64, parallel: f64) -> Result<()> {
        limits::check_grid(what, points)?;
        limits::check_memory(
            "the runs in progress (--transient + --recorded periods each)",
            estimate_point_memory(runner) * parallel * 4.0,
            self.allow_large,
        )
    }
}

/// Options of `vibrotribo response`.
#[derive(Debug, clap::Args)]
pub struct ResponseArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The swept parameter: any key `sweep --param` accepts (`excitation.omega_ratio`,
    /// `excitation.frequency_hz`, …); the band is in its unit.
    #[arg(long, default_value = "excitation.omega_ratio")]
    pub param: String,
    /// First value.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Last value (above --from).
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Number of values, equally spaced from --from to --to.
    #[arg(long)]
    pub steps: usize,
    /// Also follow the branches of periodic orbits through the periodic motions the sweeps
    /// found (continuation across the range, through folds; power on every point).
    #[arg(long)]
    pub branches: bool,
    /// With --branches: most sweep values continued (each towards both ends of the range).
    #[arg(long, default_value_t = DEFAULT_MAX_SEEDS, value_name = "N")]
    pub branch_seeds: usize,
    #[command(flatten)]
    pub run: PointArgs,
    /// Write response.csv, branches.csv (with --branches) and response.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the response (without --out: into vibrotribo-out/response).
    #[arg(long)]
    pub plot: bool,
}

/// Refuses `--from`, `--to`, `--steps` that make no increasing grid.
pub fn check_range(from: f64, to: f64, steps: usize) -> Result<()> {
    if steps == 0 {
        bail!("--steps must be at least 1");
    }
    if !(from.is_finite() && to.is_finite()) || (steps > 1 && from >= to) {
        bail!("--from and --to must be finite, --from below --to (the values run from --from to --to)");
    }
    Ok(())
}

/// Writes `rows` to `path`, each cell as its CSV field.
pub fn write_rows(path: &Path, rows: &Rows) -> Result<()> {
    let mut f = CsvFile::create(path, &rows.names)?;
    for row in &rows.rows {
        f.row(row)?;
    }
    f.flush()
}

/// Runs `vibrotribo response`.
pub fn run(args: &ResponseArgs) -> Result<()> {
    check_range(args.from, args.to, args.steps)?;
    if args.branch_seeds == 0 {
        bail!("--branch-seeds must be at least 1");
    }
    let runner = args.run.runner(args.input.load_within(args.run.allow_large)?)?;
    args.run
        .check_size("--steps", &runner, 2.0 * args.steps as f64, 2.0)?;
    if let Some(dir) = &args.out {
        check_out_dir(dir, "response.json", args.run.force, |_| true)?;
    }
    let values = grid(args.from, args.to, args.steps);
    let options = ResponseOptions {
        branches: args.branches.then(|| {
            let d = BranchSeeding::default();
            BranchSeeding {
                max_seeds: args.branch_seeds,
                continuation: vibrotribo::orbits::ContinuationOptions {
                    shooting: ShootingOptions {
                        cancel: orbit_cancel(),
                        ..d.continuation.shooting
                    },
                    ..d.continuation
                },
                ..d
            }
        }),
    };
    let started = Instant::now();
    let bar = Progress::new(2 * values.len() as u64, "values", args.run.quiet);
    let spinner: OnceLock<Progress> = OnceLock::new();
    let hook = |step: ResponseStep| {
        match step {
            ResponseStep::Value(_) => bar.inc(1),
            _ => {
                spinner.get_or_init(|| Progress::spinner("branches", args.run.quiet));
            }
        }
        if interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    };
    let r = frequency_response(&runner, &args.param, &values, &options, &hook)?;
    bar.finish();
    if let Some(s) = spinner.get() {
        s.finish();
    }
    let elapsed = started.elapsed().as_secs_f64();
    print_response(&r, elapsed);
    if let Some(dir) = &args.out {
        create_dir(dir)?;
        write_rows(&dir.join("response.csv"), &response_table(&r))?;
        if args.branches {
            write_rows(&dir.join("branches.csv"), &branch_table(&r))?;
        }
        let m = manifest(args, &runner, &r, options.branches.as_ref(), elapsed)?;
        write_json(&dir.join("response.json"), &to_value(&m)?)?;
        println!(
            "  wrote {0}/response.csv{1}, {0}/response.json",
            dir.display(),
            if args.branches {
                format!(", {}/branches.csv", dir.display())
            } else {
                String::new()
            }
        );
        if args.plot {
            crate::response_picture::plot_response(dir)?;
        }
    }
    if !r.complete {
        return Err(Interrupted {
            what: match &args.out {
                Some(dir) => format!(
                    "the files in {} hold the values and branches finished (\"complete\": false in response.json)",
                    dir.display()
                ),
                None => "the response above is of the values finished".into(),
            },
        }
        .into());
    }
    Ok(())
}

fn print_response(r: &FrequencyResponse, elapsed: f64) {
    println!(
        "vibrotribo response: {} over {} values from {} to {}, up and down sweeps{} in {elapsed:.2} s",
        r.key,
        r.values.len(),
        r.values.first().copied().unwrap_or(f64::NAN),
        r.values.last().copied().unwrap_or(f64::NAN),
        if r.branches.is_empty() {
            String::new()
        } else {
            format!(", {} branches", r.branches.len())
        }
    );
    for d in [Direction::Up, Direction::Down] {
        let s = r.sweep(d);
        println!(
            "  {:>6}: {}{}",
            d.as_str(),
            band_text(BandwidthRecord::of(r.sweep_bandwidth(d)).as_ref(), ""),
            if s.failed() > 0 {
                format!(" ({} values failed)", s.failed())
            } else {
                String::new()
            }
        );
    }
    for (i, b) in r.branches.iter().enumerate() {
        let folds: Vec<String> = b
            .bifurcations
            .iter()
            .map(|f| format!("{} at {:.6}", f.kind.name(), f.parameter))
            .collect();
        println!(
            "  branch {i} (period {}, from the {} sweep at {} towards {}): {} points ({} stable), {}; {}{}",
            b.period,
            b.seed.direction.as_str(),
            b.seed.value,
            b.towards,
            b.points.len(),
            b.points.iter().filter(|p| p.stable).count(),
            end_text(&b.end),
            band_text(BandwidthRecord::of(b.bandwidth()).as_ref(), ""),
            if folds.is_empty() {
                String::new()
            } else {
                format!("; {}", folds.join(", "))
            }
        );
    }
    for f in &r.branch_failures {
        println!(
            "  no branch from the {} sweep at {} towards {}: {}",
            f.seed.direction.as_str(),
            f.seed.value,
            f.towards,
            f.error
        );
    }
    println!(
        "  all: {}",
        band_text(BandwidthRecord::of(r.bandwidth()).as_ref(), "")
    );
}

/// `response.json`.
fn manifest(
    args: &ResponseArgs,
    runner: &PointRunner,
    r: &FrequencyResponse,
    seeding: Option<&BranchSeeding>,
    elapsed: f64,
) -> Result<ResponseManifest> {
    let axis = Axis {
        param: args.param.clone(),
        from: args.from,
        to: args.to,
        steps: args.steps,
        values: r.values.clone(),
    };
    Ok(ResponseManifest::new(runner, axis, r.summary(seeding), elapsed)?)
}
