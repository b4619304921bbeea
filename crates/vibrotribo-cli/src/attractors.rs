//! `vibrotribo attractors`: the attractors of K random starts at each value of a parameter
//! ([`vibrotribo::attractors::attractors_across`]), followed from value to value, with each
//! one's basin fraction and power and the expected power of an unknown start.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use vibrotribo::attractors::{
    AcrossDelivery, AttractorOptions, EXPECTED_POWER_COLUMNS, RandomStarts, StartBox, StartRunner,
    ValueAttractors, attractors_across, census_attractor_columns, census_attractor_rows, columns,
    expected_power_row,
};
use vibrotribo::sweep::grid;

use crate::basins::DEFAULT_PERIODS;
use crate::config::ConfigArgs;
use crate::job::{RunArgs, check_all, check_distinct, set_threads};
use crate::manifest::{AttractorsManifest, Axis, read, to_value};
use crate::output::{CsvFile, check_out_dir, create_dir, read_csv, si, write_json};
use crate::plot::{self, Bands, Figure, Legend, Scale, Series};
use crate::progress::{Interrupted, Progress, interrupted};

/// Options of `vibrotribo attractors`.
#[derive(Debug, clap::Args)]
pub struct AttractorsArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The parameter (any key `sweep --param` accepts).
    #[arg(long)]
    pub param: String,
    /// First value.
    #[arg(long, allow_negative_numbers = true)]
    pub from: f64,
    /// Last value.
    #[arg(long, allow_negative_numbers = true)]
    pub to: f64,
    /// Number of values.
    #[arg(long)]
    pub steps: usize,
    /// Random starts per value, K.
    #[arg(long, default_value_t = 100)]
    pub samples: usize,
    /// Seed of the random starts (the same starts at every value and for any thread count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Starts' positions uniform in ±this, m (default: the base amplitude A).
    #[arg(long)]
    pub position_range: Option<f64>,
    /// Starts' velocities uniform in ±this, m/s (default: the base's peak speed A·ω).
    #[arg(long)]
    pub velocity_range: Option<f64>,
    /// Write attractors.csv, expected_power.csv and attractors.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the basin fractions (stacked bands) and the power per attractor.
    #[arg(long)]
    pub plot: bool,
    /// Cell edge of the recurrence grid for non-periodic section clouds (scaled units).
    #[arg(long, default_value_t = 0.05)]
    pub cell: f64,
    /// A start's stroboscopic section (positions and velocities, scaled units) is periodic
    /// when it repeats within this tolerance (coarser than a sweep's --period-tolerance,
    /// which does not apply here: a start still ringing down onto an orbit is that orbit).
    #[arg(long, default_value_t = 1e-3)]
    pub section_tolerance: f64,
    /// Two periodic section sets are one attractor within this scaled distance.
    #[arg(long, default_value_t = 3e-3)]
    pub match_tolerance: f64,
    /// An attractor continues one of the previous value within this scaled set distance
    /// (when no seeded run decides).
    #[arg(long, default_value_t = 0.25)]
    pub continuation_distance: f64,
    #[command(flatten)]
    pub run: RunArgs,
}

/// Runs `vibrotribo attractors`.
pub fn run(args: &AttractorsArgs) -> Result<()> {
    if args.steps == 0 || args.samples == 0 {
        bail!("--steps and --samples must be at least 1");
    }
    if !args.from.is_finite() || !args.to.is_finite() {
        bail!("--from and --to must be finite numbers");
    }
    crate::limits::check_grid("--steps × --samples", args.steps as f64 * args.samples as f64)?;
    set_threads(args.run.threads)?;
    let base = args.input.load_within(args.run.allow_large)?;
    base.check_uncoupled("attractors")?;
    base.check_periodic("attractor census (`attractors`)")?;
    let options = AttractorOptions {
        period_tolerance: args.section_tolerance,
        match_tolerance: args.match_tolerance,
        cell: args.cell,
        continuation_distance: args.continuation_distance,
    };
    let starts = StartRunner::new(args.run.runner_or(base, DEFAULT_PERIODS)?, options.clone())
        .map_err(|e| anyhow!("{e}"))?;
    let values = grid(args.from, args.to, args.steps);
    check_distinct("--from/--to/--steps", &values)?;
    check_all(starts.point_runner(), &values, |&v| {
        vec![(args.param.as_str(), v)]
    })?;
    let chain = starts.point_runner().base().chain();
    let default_box = StartBox::of(chain);
    let bounds = match (args.position_range, args.velocity_range) {
        (None, None) => None,
        (p, v) => Some(StartBox {
            positions: p.unwrap_or(default_box.positions),
            velocities: v.unwrap_or(default_box.velocities),
        }),
    };
    if let Some(b) = &bounds {
        b.validate()
            .map_err(|e| anyhow!("--position-range/--velocity-range: {e}"))?;
    }
    let sampling = RandomStarts {
        samples: args.samples,
        seed: args.seed,
        bounds,
    };
    crate::job::check_recorded(starts.point_runner().options())?;
    let manifest = manifest_of(&starts, &args.param, (args.from, args.to), &values, &sampling)?;
    let started = Instant::now();
    let (results, finished) = write_census(
        &starts,
        manifest,
        &sampling,
        args.out.as_deref(),
        args.run.force,
        args.run.quiet,
    )?;
    let complete = finished == values.len();
    for v in &results {
        print_value(v, &args.param);
    }
    println!(
        "{} of {} values of {} with {} starts each in {:.2} s on {} threads",
        finished,
        values.len(),
        args.param,
        args.samples,
        started.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    if let Some(dir) = &args.out {
        if complete && args.plot {
            plot_attractors(dir)?;
        }
        println!(
            "  wrote {0}/attractors.csv, {0}/expected_power.csv, {0}/attractors.json",
            dir.display()
        );
    }
    if !complete {
        return Err(Interrupted {
            what: format!(
                "after {finished} of {} values; the files hold those, marked incomplete in attractors.json",
                values.len()
            ),
        }
        .into());
    }
    Ok(())
}

/// The manifest `m` as a fresh job's: incomplete, nothing done.
fn with_progress(m: &serde_json::Value, complete: bool, done: usize) -> serde_json::Value {
    let mut m = m.clone();
    m["complete"] = serde_json::Value::from(complete);
    m["done"] = serde_json::Value::from(done);
    m
}

/// The manifest (`attractors.json`) of a census of `starts` across `values` of `param`
/// (the grid from `from` to `to`), its starts drawn by `sampling`; nothing done yet.
pub fn manifest_of(
    starts: &StartRunner,
    param: &str,
    (from, to): (f64, f64),
    values: &[f64],
    sampling: &RandomStarts,
) -> Result<AttractorsManifest> {
    let axis = Axis::new(param, (from, to), values.to_vec());
    Ok(AttractorsManifest::new(starts, axis, sampling)?)
}

/// `attractors.csv` and `expected_power.csv` of a census, written value by value.
struct CensusFiles {
    attractors: CsvFile,
    expected: CsvFile,
    masses: usize,
}

impl CensusFiles {
    /// Creates the files in `dir` for a chain of `masses` masses.
    fn create(dir: &Path, masses: usize) -> Result<Self> {
        Ok(CensusFiles {
            attractors: CsvFile::create(&dir.join("attractors.csv"), &census_attractor_columns(masses).0)?,
            expected: CsvFile::create(
                &dir.join("expected_power.csv"),
                &columns(&EXPECTED_POWER_COLUMNS, &[], 0).0,
            )?,
            masses,
        })
    }

    /// Writes the rows of one value.
    fn write_value(&mut self, v: &ValueAttractors) -> Result<()> {
        for row in census_attractor_rows(v, self.masses) {
            self.attractors.row(row)?;
        }
        self.expected.row(expected_power_row(v))?;
        self.flush()
    }

    /// Flushes both files.
    fn flush(&mut self) -> Result<()> {
        self.attractors.flush()?;
        self.expected.flush()
    }
}

/// Runs the census of `starts` whose manifest is `manifest` (its parameter and values), its
/// starts drawn by `sampling`, into `dir` if given as `attractors --out DIR` writes it: the
/// manifest first (an older job there is replaced only with `force` or the same settings),
/// each value's rows of `attractors.csv` and `expected_power.csv` as it finishes, then the
/// manifest with how many values finished. Returns the values' attractors and that count.
pub fn write_census(
    starts: &StartRunner,
    manifest: AttractorsManifest,
    sampling: &RandomStarts,
    dir: Option<&Path>,
    force: bool,
    quiet: bool,
) -> Result<(Vec<ValueAttractors>, usize)> {
    let masses = starts.point_runner().base().chain().len();
    let mut files = match dir {
        Some(dir) => {
            let ours = to_value(&manifest)?;
            check_out_dir(dir, "attractors.json", force, |old| {
                with_progress(old, false, 0) == ours
            })?;
            create_dir(dir)?;
            write_json(&dir.join("attractors.json"), &ours)?;
            Some(CensusFiles::create(dir, masses)?)
        }
        None => None,
    };
    let (param, values) = (&manifest.axis.param, &manifest.axis.values);
    let (results, finished) = run_census(starts, param, values, sampling, files.as_mut(), quiet)?;
    if let (Some(mut files), Some(dir)) = (files, dir) {
        files.flush()?;
        let complete = finished == values.len();
        write_json(
            &dir.join("attractors.json"),
            &to_value(&AttractorsManifest {
                complete,
                done: finished,
                ..manifest
            })?,
        )?;
    }
    Ok((results, finished))
}

/// Runs the census of `starts` across `values` of `param` ([`attractors_across`]), with a
/// progress bar and a stop on SIGINT/SIGTERM after a chunk, each value's rows written to
/// `files` as it finishes. Returns the values' attractors and how many values finished.
fn run_census(
    starts: &StartRunner,
    param: &str,
    values: &[f64],
    sampling: &RandomStarts,
    mut files: Option<&mut CensusFiles>,
    quiet: bool,
) -> Result<(Vec<ValueAttractors>, usize)> {
    let progress = Progress::new((values.len() * sampling.samples) as u64, "starts", quiet);
    let mut failure = None;
    let mut finished = 0;
    let chunk = rayon::current_num_threads() * 4;
    let results = attractors_across(starts, param, values, sampling, chunk, |d| match d {
        AcrossDelivery::Start => {
            progress.inc(1);
            ControlFlow::Continue(())
        }
        AcrossDelivery::Value(v) => {
            finished += 1;
            if let Some(f) = files.as_deref_mut()
                && let Err(err) = f.write_value(v)
            {
                failure = Some(err);
                return ControlFlow::Break(());
            }
            ControlFlow::Continue(())
        }
        AcrossDelivery::Chunk => {
            if interrupted() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    })?;
    progress.finish();
    match failure {
        Some(e) => Err(e),
        None => Ok((results, finished)),
    }
}

fn print_value(v: &ValueAttractors, param: &str) {
    let c = &v.classification;
    let expected = v.expected_power.map_or(String::new(), |(p, se)| {
        format!(", expected power {} ± {}", si(p, "W"), si(se, "W"))
    });
    println!(
        "{param} = {}: {} attractors{expected}",
        v.value,
        c.attractors.len()
    );
    for (k, at) in c.attractors.iter().enumerate() {
        let (f, se) = c.fraction(k);
        let kind = if at.is_periodic() {
            format!("period {}", at.period)
        } else {
            "non-periodic".into()
        };
        println!(
            "  A{}: {kind}, {:.2} impacts/T, basin {:.1} ± {:.1} %{}",
            v.ids[k] + 1,
            at.impacts_per_period,
            100.0 * f,
            100.0 * se,
            at.power_w.map_or(String::new(), |p| format!(", {}", si(p, "W")))
        );
    }
}

/// Draws the fractions (stacked bands) and powers of an `attractors` directory.
pub fn plot_attractors(dir: &Path) -> Result<()> {
    let m: AttractorsManifest = read(&dir.join("attractors.json"))?;
    let param = m.axis.param.clone();
    let values = &m.axis.values[..m.done.min(m.axis.values.len())];
    let (h, rows) = read_csv(&dir.join("attractors.csv"))?;
    let col = |name: &str| crate::output::column(&h, name);
    let (cp, ca, cf, cw) = (
        col("param")?,
        col("attractor")?,
        col("fraction")?,
        col("average_power_w")?,
    );
    let ids: Vec<usize> = rows
        .iter()
        .map(|r| r[ca].parse::<usize>().context("attractors.csv: attractor"))
        .collect::<Result<_>>()?;
    let count = ids.iter().copied().max().unwrap_or(0);
    let index = |x: f64| values.iter().position(|&v| v == x);
    let mut shares = vec![vec![0.0; values.len()]; count];
    let mut powers = vec![vec![f64::NAN; values.len()]; count];
    let mut kinds = vec![String::new(); count];
    for (r, &id) in rows.iter().zip(&ids) {
        let Some(i) = r[cp].parse::<f64>().ok().and_then(index) else {
            continue;
        };
        shares[id - 1][i] = r[cf].parse().unwrap_or(0.0);
        powers[id - 1][i] = 1e6 * r[cw].parse::<f64>().unwrap_or(f64::NAN);
        if kinds[id - 1].is_empty() {
            let kind = match r[col("period")?].as_str() {
                "0" => "non-periodic".into(),
                p => format!("period {p}"),
            };
            let impacts: f64 = r[col("impacts_per_period")?].parse().unwrap_or(f64::NAN);
            kinds[id - 1] = format!("{kind}, {impacts:.2} impacts/T at {param} = {}", r[cp]);
        }
    }
    let names: Vec<String> = (0..count).map(|k| format!("A{}: {}", k + 1, kinds[k])).collect();
    let fig = Figure::new(
        format!(
            "Basin fractions of the attractors ({} random starts per value)",
            m.samples
        ),
        param.clone(),
        "basin fraction",
    );
    crate::plot::both(dir, "attractor_fractions", |path| {
        plot::stacked_bands(
            path,
            &fig,
            &Bands {
                x: values,
                shares: &shares,
                names: &names,
            },
        )
    })?;
    let (eh, erows) = read_csv(&dir.join("expected_power.csv"))?;
    let ep: Vec<f64> = crate::output::numbers(&erows, crate::output::column(&eh, "expected_power_w")?)
        .iter()
        .map(|p| 1e6 * p)
        .collect();
    if ep.iter().any(|p| p.is_finite()) {
        let expected = "expected power (fraction-weighted)".to_string();
        let mut series: Vec<Series<'_>> = names
            .iter()
            .zip(&powers)
            .map(|(n, p)| Series::new(n, values, p))
            .collect();
        series.push(Series::new(&expected, values, &ep[..values.len().min(ep.len())]));
        let mut fig = Figure::new("Average power per attractor", param, "P_a [µW]");
        fig.legend = Legend::UpperLeft;
        // A log axis only where the powers span more than a decade (it has no ticks within one).
        let finite = || powers.iter().flatten().chain(&ep).filter(|p| p.is_finite());
        let lo = finite().fold(f64::INFINITY, |a, &b| a.min(b));
        let hi = finite().fold(0.0f64, |a, &b| a.max(b));
        if lo > 0.0 && hi > 10.0 * lo {
            fig.y_scale = Scale::Log;
        }
        crate::plot::both(dir, "attractor_power", |path| {
            plot::line_plot(path, &fig, &series)
        })?;
    }
    Ok(())
}
