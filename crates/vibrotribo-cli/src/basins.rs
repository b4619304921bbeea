//! `vibrotribo basins`: basins of attraction over two initial-condition keys
//! ([`vibrotribo::attractors`]): every start of a grid run in parallel and fingerprinted
//! (`starts.csv`, a grid job that shards, merges and resumes like a map), then, once the
//! grid is complete, classified in grid order into `basins.csv` and `attractors.csv`, so
//! the result does not depend on threads or shards.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, anyhow, bail};
use serde::Deserialize;
use serde_json::Value;
use vibrotribo::attractors::{
    AttractorOptions, BASIN_COLUMNS, Classification, Fingerprint, SectionScale, StartRunner,
    basin_attractor_columns, basin_attractor_rows, basin_rows, classify, columns,
};
use vibrotribo::sweep::grid;

use crate::config::ConfigArgs;
use crate::job::{CsvSpec, GridOutput, Layout};
use crate::job::{MergeArgs, RunArgs, Shard, check_distinct, run_chunked, set_threads};
use crate::limits;
use crate::manifest::{Axis, BasinsManifest, ShardRecord, read};
use crate::output::{csv_text, read_csv, si, write_rows};
use crate::plot::{self, CategoryMap, Figure};
use crate::progress::Interrupted;

/// `NXxNY`: the nodes of a basin grid along x and y.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GridSize {
    /// Nodes along x.
    pub nx: usize,
    /// Nodes along y.
    pub ny: usize,
}

impl std::str::FromStr for GridSize {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (a, b) = s
            .split_once(['x', 'X', '×'])
            .ok_or_else(|| format!("--grid takes NXxNY (e.g. 200x200), got {s:?}"))?;
        let parse = |t: &str| {
            t.trim()
                .parse::<usize>()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| format!("--grid {s}: {t:?} is not a positive whole number"))
        };
        Ok(GridSize {
            nx: parse(a)?,
            ny: parse(b)?,
        })
    }
}

/// Options of `vibrotribo basins`.
#[derive(Debug, clap::Args)]
pub struct BasinsArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Initial condition along x: `run.initial_positions[i]` (m) or
    /// `run.initial_velocities[i]` (m/s), i 0-based.
    #[arg(long)]
    pub x: String,
    /// First x value.
    #[arg(long, allow_negative_numbers = true)]
    pub x_from: f64,
    /// Last x value.
    #[arg(long, allow_negative_numbers = true)]
    pub x_to: f64,
    /// Initial condition along y.
    #[arg(long)]
    pub y: String,
    /// First y value.
    #[arg(long, allow_negative_numbers = true)]
    pub y_from: f64,
    /// Last y value.
    #[arg(long, allow_negative_numbers = true)]
    pub y_to: f64,
    /// Nodes of the grid, NXxNY (e.g. 200x200).
    #[arg(long, value_name = "NXxNY")]
    pub grid: GridSize,
    /// Write starts.csv, basins.csv, attractors.csv and basins.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Compute only the I-th of N interleaved slices of the grid; combine with `merge`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Continue the interrupted job (or shard) in --out DIR from its finished starts.
    #[arg(long)]
    pub resume: bool,
    /// Also draw the basin picture (PNG and SVG).
    #[arg(long)]
    pub plot: bool,
    /// Cell edge of the recurrence grid that matches non-periodic section clouds (scaled
    /// units: positions over L = Σδ + A, velocities over L·ω).
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
    #[command(flatten)]
    pub run: RunArgs,
}

/// Transient and recorded periods of a start unless `--transient`/`--recorded` say.
pub const DEFAULT_PERIODS: (u64, u64) = vibrotribo::attractors::DEFAULT_START_PERIODS;

/// Checks that `key` is an initial condition of a chain of `masses` masses.
fn check_key(option: &str, key: &str, masses: usize) -> Result<()> {
    vibrotribo::attractors::initial_condition_index(key, masses)
        .map(|_| ())
        .map_err(|e| anyhow!("{option} {e}"))
}

/// `starts.csv`: one row per start, the fingerprint of where it ended.
pub fn layout() -> Layout {
    Layout {
        manifest: "basins.json",
        files: vec![CsvSpec {
            name: "starts.csv",
            columns: [
                "x",
                "y",
                "period",
                "impacts_per_period",
                "average_power_w",
                "points",
                "cells",
                "error",
            ]
            .map(String::from)
            .to_vec(),
        }],
        index_file: 0,
        key_fields: 2,
    }
}

fn points_of(xs: &[f64], ys: &[f64]) -> Vec<(f64, f64)> {
    vibrotribo::attractors::basin_points(xs, ys)
}

fn key_of(&(x, y): &(f64, f64)) -> String {
    format!("{x},{y}")
}

fn joined<T: ToString>(v: &[T]) -> String {
    v.iter().map(ToString::to_string).collect::<Vec<_>>().join(" ")
}

/// A start's row after its key: the fingerprint (numbers written exactly), or the error.
fn cells_of(r: &Result<Fingerprint, String>) -> Vec<String> {
    match r {
        Ok(f) => vec![
            f.period.to_string(),
            f.impacts_per_period.to_string(),
            f.power_w.map_or(String::new(), |p| p.to_string()),
            joined(&f.points),
            joined(&f.cells),
            String::new(),
        ],
        Err(e) => {
            let mut row = vec![String::new(); 5];
            row.push(csv_text(e));
            row
        }
    }
}

/// The fingerprint of a row of `starts.csv` (`None` for a failed start).
fn parse_row(row: &[String]) -> Result<Option<Fingerprint>> {
    if row.len() < 8 {
        bail!("a row of starts.csv has {} fields, expected 8", row.len());
    }
    if !row[7].is_empty() || row[2].is_empty() {
        return Ok(None);
    }
    let numbers = |t: &str| -> Result<Vec<f64>> {
        t.split_whitespace()
            .map(|x| x.parse().map_err(|_| anyhow!("starts.csv: bad number {x:?}")))
            .collect()
    };
    Ok(Some(Fingerprint {
        period: row[2].parse().context("starts.csv: period")?,
        impacts_per_period: row[3].parse().context("starts.csv: impacts_per_period")?,
        power_w: if row[4].is_empty() {
            None
        } else {
            Some(row[4].parse().context("starts.csv: average_power_w")?)
        },
        points: numbers(&row[5])?,
        cells: row[6]
            .split_whitespace()
            .map(|c| c.parse().map_err(|_| anyhow!("starts.csv: bad cell {c:?}")))
            .collect::<Result<_>>()?,
    }))
}

/// Runs `vibrotribo basins`.
pub fn run(args: &BasinsArgs) -> Result<()> {
    for (name, a, b) in [("x", args.x_from, args.x_to), ("y", args.y_from, args.y_to)] {
        if !a.is_finite() || !b.is_finite() {
            bail!("--{name}-from and --{name}-to must be finite numbers");
        }
    }
    let (nx, ny) = (args.grid.nx, args.grid.ny);
    limits::check_grid("--grid", nx as f64 * ny as f64)?;
    if args.resume && args.out.is_none() {
        bail!("--resume needs --out DIR (the directory of the job to continue)");
    }
    set_threads(args.run.threads)?;
    let base = args.input.load_within(args.run.allow_large)?;
    base.check_uncoupled("basins")?;
    base.check_periodic("basins of attraction (`basins`)")?;
    let masses = base.chain().len();
    check_key("--x", &args.x, masses)?;
    check_key("--y", &args.y, masses)?;
    if args.x == args.y {
        bail!("--x and --y are the same key");
    }
    let options = AttractorOptions {
        period_tolerance: args.section_tolerance,
        match_tolerance: args.match_tolerance,
        cell: args.cell,
        ..AttractorOptions::default()
    };
    let starts = StartRunner::new(args.run.runner_or(base, DEFAULT_PERIODS)?, options.clone())
        .map_err(|e| anyhow!("{e}"))?;
    let (xs, ys) = (grid(args.x_from, args.x_to, nx), grid(args.y_from, args.y_to, ny));
    check_distinct("--x-from/--x-to/--grid", &xs)?;
    check_distinct("--y-from/--y-to/--grid", &ys)?;
    let mut points = points_of(&xs, &ys);
    if let Some(s) = args.shard {
        points = points
            .into_iter()
            .enumerate()
            .filter(|(j, _)| j % s.count == s.index)
            .map(|(_, p)| p)
            .collect();
    }
    let o = starts.point_runner().options();
    crate::job::check_recorded(o)?;
    let grid = BasinGrid {
        starts,
        x: Axis::new(&args.x, (args.x_from, args.x_to), xs),
        y: Axis::new(&args.y, (args.y_from, args.y_to), ys),
    };
    let settings = crate::manifest::to_value(&grid.manifest(args.shard)?)?;
    let keys: Vec<String> = points.iter().map(key_of).collect();
    let (mut out, skip) = match &args.out {
        None => (None, 0),
        Some(dir) if args.resume => {
            let (o, done) = GridOutput::resume(dir, layout(), settings, &keys, keys.len())?;
            (Some(o), done)
        }
        Some(dir) => (
            Some(GridOutput::create(dir, layout(), settings, args.run.force)?),
            0,
        ),
    };
    let started = Instant::now();
    let (computed, fingerprints) = grid.run(&points[skip..], skip, args.run.quiet, out.as_mut())?;
    let done = skip + computed;
    let complete = done == points.len();
    println!(
        "basins over {} × {} ({nx} × {ny} starts{}): {computed} computed{} in {:.2} s on {} threads",
        args.x,
        args.y,
        args.shard
            .map_or(String::new(), |s| format!(", shard {}/{}", s.index, s.count)),
        if skip > 0 {
            format!(", {skip} kept from before")
        } else {
            String::new()
        },
        started.elapsed().as_secs_f64(),
        rayon::current_num_threads()
    );
    match (out, &args.out) {
        (Some(out), Some(dir)) => {
            out.finish(complete, done)?;
            if complete && args.shard.is_none() {
                let classes = finish(dir)?;
                print_attractors(&classes);
                if args.plot {
                    plot_basins(dir)?;
                }
                println!(
                    "  wrote {0}/basins.csv, {0}/attractors.csv, {0}/starts.csv",
                    dir.display()
                );
            }
        }
        _ if complete && args.shard.is_none() => {
            print_attractors(&grid.classify(&fingerprints));
        }
        _ => {}
    }
    if !complete {
        return Err(Interrupted {
            what: format!(
                "starts.csv holds the {done} of {} starts finished, marked incomplete in basins.json; \
                 the same command with --resume continues",
                points.len()
            ),
        }
        .into());
    }
    Ok(())
}

/// A grid of starts: the runner of one start and the two initial-condition axes it spans.
pub struct BasinGrid {
    /// The runner of one start and the options that tell its attractors apart.
    pub starts: StartRunner,
    /// The initial condition along x and its values.
    pub x: Axis,
    /// The initial condition along y and its values.
    pub y: Axis,
}

impl BasinGrid {
    /// Every start of the grid, in grid order (x fastest).
    pub fn points(&self) -> Vec<(f64, f64)> {
        points_of(&self.x.values, &self.y.values)
    }

    /// The grid's manifest (`basins.json`; the shard `shard` of it, if any), nothing done.
    pub fn manifest(&self, shard: Option<Shard>) -> Result<BasinsManifest> {
        let mut m = BasinsManifest::new(&self.starts, self.x.clone(), self.y.clone())?;
        m.shard = shard.map(|s| ShardRecord {
            index: s.index,
            count: s.count,
        });
        Ok(m)
    }

    /// Runs the starts `points` (the two keys set to each point's values) in parallel chunks,
    /// in grid order, with a progress bar counting from `skip` and a stop on SIGINT/SIGTERM
    /// after a chunk; each start's row goes to `out` (`starts.csv` of a grid job) as it
    /// comes. Returns how many ran and their fingerprints (`None`: the start failed).
    pub fn run(
        &self,
        points: &[(f64, f64)],
        skip: usize,
        quiet: bool,
        mut out: Option<&mut GridOutput>,
    ) -> Result<(usize, Vec<Option<Fingerprint>>)> {
        let (xk, yk) = (self.x.param.as_str(), self.y.param.as_str());
        let mut fingerprints = Vec::new();
        let total = (skip + points.len()) as u64;
        let computed = run_chunked(
            points,
            |&(x, y)| {
                self.starts
                    .run(&[(xk, x), (yk, y)], None)
                    .map_err(|e| format!("{e:#}"))
            },
            |_| false,
            ("starts", skip as u64, total),
            quiet,
            |d| {
                let Some((&(x, y), r)) = d else {
                    return out.as_deref_mut().map_or(Ok(()), GridOutput::commit);
                };
                if let Some(out) = out.as_deref_mut() {
                    let mut row = vec![x.to_string(), y.to_string()];
                    row.extend(cells_of(&r));
                    out.row(0, row)?;
                }
                fingerprints.push(r.ok());
                Ok(())
            },
        )?;
        Ok((computed, fingerprints))
    }

    /// The attractors of the starts' `fingerprints` (grid order), classified in that order.
    pub fn classify(&self, fingerprints: &[Option<Fingerprint>]) -> Classification {
        let chain = self.starts.point_runner().base().chain();
        classify(fingerprints, &SectionScale::of(chain), self.starts.options())
    }
}

/// Runs every start of `grid` into the directory `dir` as `basins --out DIR` writes it
/// (`basins.json`, `starts.csv` start by start; an older job there is replaced) and, once
/// every start has run, classifies them in grid order into `basins.csv` and
/// `attractors.csv`. Returns how many starts ran and the classification, `None` when a
/// signal stopped the run (the directory then holds the starts that finished, marked
/// incomplete).
pub fn write_grid(grid: &BasinGrid, dir: &Path, quiet: bool) -> Result<(usize, Option<Classification>)> {
    let points = grid.points();
    let settings = crate::manifest::to_value(&grid.manifest(None)?)?;
    let mut out = GridOutput::create(dir, layout(), settings, true)?;
    let (done, fingerprints) = grid.run(&points, 0, quiet, Some(&mut out))?;
    let complete = done == points.len();
    out.finish(complete, done)?;
    if !complete {
        return Ok((done, None));
    }
    let c = grid.classify(&fingerprints);
    let masses = grid.starts.point_runner().base().chain().len();
    write_tables(dir, &points, &fingerprints, &c, masses)?;
    Ok((done, Some(c)))
}

fn print_attractors(c: &Classification) {
    println!(
        "  {} attractors among {} starts that ran:",
        c.attractors.len(),
        c.classified()
    );
    for (a, name) in names(c).iter().enumerate() {
        let (f, se) = c.fraction(a);
        println!("    {name} (basin {:.1} ± {:.1} %)", 100.0 * f, 100.0 * se);
    }
}

/// A legend name per attractor: `A1: period 1, 4.00 impacts/T, 12.92 µW`.
fn names(c: &Classification) -> Vec<String> {
    c.attractors
        .iter()
        .enumerate()
        .map(|(a, at)| {
            let kind = if at.is_periodic() {
                format!("period {}", at.period)
            } else {
                "non-periodic".to_string()
            };
            let power = at.power_w.map_or(String::new(), |p| format!(", {}", si(p, "W")));
            format!(
                "A{}: {kind}, {:.2} impacts/T{power}",
                a + 1,
                at.impacts_per_period
            )
        })
        .collect()
}

/// Reads the fingerprints of a complete basins directory and the settings that classify
/// them.
fn read_job(
    dir: &Path,
) -> Result<(
    BasinsManifest,
    Vec<Option<Fingerprint>>,
    SectionScale,
    AttractorOptions,
)> {
    let m: BasinsManifest = read(&dir.join("basins.json"))?;
    if !m.complete {
        bail!(
            "{} is incomplete: finish it with --resume (or merge its shards) first",
            dir.display()
        );
    }
    let (_, rows) = read_csv(&dir.join("starts.csv"))?;
    let fingerprints = rows.iter().map(|r| parse_row(r)).collect::<Result<Vec<_>>>()?;
    let s = &m.section_scale;
    let scale = SectionScale {
        masses: s.masses,
        length: s.length_m,
        speed: s.speed_m_s,
    };
    let a = &m.attractor_options;
    let options = AttractorOptions {
        period_tolerance: a.period_tolerance,
        match_tolerance: a.match_tolerance,
        cell: a.cell,
        ..AttractorOptions::default()
    };
    Ok((m, fingerprints, scale, options))
}

/// Classifies a complete directory's starts (grid order) and writes `basins.csv` and
/// `attractors.csv`.
pub fn finish(dir: &Path) -> Result<Classification> {
    let (m, fingerprints, scale, options) = read_job(dir)?;
    let c = classify(&fingerprints, &scale, &options);
    write_tables(
        dir,
        &points_of(&m.x.values, &m.y.values),
        &fingerprints,
        &c,
        scale.masses,
    )?;
    Ok(c)
}

/// Writes `basins.csv` (each start at `points`, in grid order, with its fingerprint and
/// attractor) and `attractors.csv` (the attractors of `c`) to `dir`.
pub fn write_tables(
    dir: &Path,
    points: &[(f64, f64)],
    fingerprints: &[Option<Fingerprint>],
    c: &Classification,
    masses: usize,
) -> Result<()> {
    if points.len() != fingerprints.len() {
        bail!(
            "{}: starts.csv holds {} starts for a grid of {}",
            dir.display(),
            fingerprints.len(),
            points.len()
        );
    }
    write_rows(
        &dir.join("basins.csv"),
        &columns(&BASIN_COLUMNS, &[], 0).0,
        basin_rows(points, fingerprints, c),
    )?;
    write_rows(
        &dir.join("attractors.csv"),
        &basin_attractor_columns(masses).0,
        basin_attractor_rows(c, masses),
    )
}

/// Draws the basin picture of a complete directory (`basins.png`/`.svg`).
pub fn plot_basins(dir: &Path) -> Result<()> {
    let (m, fingerprints, scale, options) = read_job(dir)?;
    let c = classify(&fingerprints, &scale, &options);
    let (xs, ys) = (&m.x.values, &m.y.values);
    if xs.is_empty() || ys.is_empty() {
        bail!("{}: basins.json has an empty axis", dir.display());
    }
    let mut names = names(&c);
    for (a, name) in names.iter_mut().enumerate() {
        let (f, _) = c.fraction(a);
        name.push_str(&format!(" ({:.1} %)", 100.0 * f));
    }
    let map = CategoryMap {
        x_nodes: (xs[0], xs[xs.len() - 1]),
        y_nodes: (ys[0], ys[ys.len() - 1]),
        nx: xs.len(),
        ny: ys.len(),
        cells: &c.labels,
        names: &names,
        missing: "no run (e.g. overlapping masses)",
    };
    let fig = Figure::new(
        format!(
            "Basins of attraction ({} transient periods)",
            m.periods.transient_periods
        ),
        m.x.param.clone(),
        m.y.param.clone(),
    );
    crate::plot::both(dir, "basins", |path| plot::category_map(path, &fig, &map))
}

/// Merges the shards of a basins job (`vibrotribo merge`) and classifies the result.
pub fn merge(args: &MergeArgs) -> Result<()> {
    let keys = |m: &Value| -> Result<Vec<String>> {
        let m = BasinsManifest::deserialize(m).context("basins.json")?;
        Ok(points_of(&m.x.values, &m.y.values).iter().map(key_of).collect())
    };
    crate::job::merge(&args.shards, &args.out, &layout(), keys)?;
    let classes = finish(&args.out)?;
    print_attractors(&classes);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_exactly() {
        let f = Fingerprint {
            period: 2,
            points: vec![0.1, -1.0 / 3.0, 2.5e-17, 4.0],
            cells: vec![],
            impacts_per_period: 2.5,
            power_w: Some(1.292e-5),
        };
        let mut row = vec!["0.1".to_string(), "-0.2".to_string()];
        row.extend(cells_of(&Ok(f.clone())));
        assert_eq!(parse_row(&row).unwrap(), Some(f));
        let g = Fingerprint {
            period: 0,
            points: vec![1.0; 4],
            cells: vec![-3, 0, 7, 1, 2, 2, 2, 2],
            impacts_per_period: 7.0,
            power_w: None,
        };
        let mut row = vec!["0".to_string(), "0".to_string()];
        row.extend(cells_of(&Ok(g.clone())));
        assert_eq!(parse_row(&row).unwrap(), Some(g));
        let mut row = vec!["0".to_string(), "0".to_string()];
        row.extend(cells_of(&Err("overlap, at contact 1".into())));
        assert_eq!(parse_row(&row).unwrap(), None);
        assert_eq!("20x30".parse::<GridSize>().unwrap(), GridSize { nx: 20, ny: 30 });
        assert!("20x0".parse::<GridSize>().is_err());
    }
}
