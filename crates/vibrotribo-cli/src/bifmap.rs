//! `vibrotribo bifmap`: a device's bifurcation map in two parameters — its fold,
//! period-doubling, Neimark–Sacker and grazing curves ([`vibrotribo::bifmap`]) — over its
//! power map (the points of `vibrotribo map`), with the codimension-two points.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use vibrotribo::bifmap::{
    BifmapOptions, BifurcationMap, HalfEnd, MapRequest, Rows, SeedOutcome, Stage, bifurcation_map,
    codim2_rows, curve_rows, located_rows, memory_bytes, validate,
};
use vibrotribo::config::Config;
use vibrotribo::orbits::curve::CurveKind;
use vibrotribo::sweep::{Cell, PointColumns, PointRunner, grid};

use crate::config::ConfigArgs;
use crate::continuation::end_text as branch_end_text;
use crate::curve::end_text as curve_end_text;
use crate::job::{
    RunArgs, check_all, check_distinct, estimate_point_memory, estimate_point_output, point_columns,
    run_points, set_threads,
};
use crate::limits;
use crate::manifest::{
    Axis, BifmapCurveRecord, BifmapManifest, Kind, PointRecord, PowerMapRecord, SeedRecord, SettleRecord,
    base_motion_of, to_value,
};
use crate::output::{CsvFile, check_out_dir, create_dir, write_json};
use crate::progress::{Interrupted, Progress, interrupted, orbit_cancel};

/// Options of `vibrotribo bifmap`.
#[derive(Debug, clap::Args)]
pub struct BifmapArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// The first parameter, along x: any key `continue --param` accepts (`omega_ratio`,
    /// `mass_ratio`, `gap_ratio`, …). The seed branches are continued in it.
    #[arg(long)]
    pub x: String,
    /// First x value (the curves are followed over --x-from … --x-to).
    #[arg(long, allow_negative_numbers = true)]
    pub x_from: f64,
    /// Last x value.
    #[arg(long, allow_negative_numbers = true)]
    pub x_to: f64,
    /// Values of x in the power map.
    #[arg(long, default_value_t = 21)]
    pub x_steps: usize,
    /// The second parameter, along y: the curves are followed in it.
    #[arg(long)]
    pub y: String,
    /// First y value.
    #[arg(long, allow_negative_numbers = true)]
    pub y_from: f64,
    /// Last y value.
    #[arg(long, allow_negative_numbers = true)]
    pub y_to: f64,
    /// Values of y in the power map.
    #[arg(long, default_value_t = 11)]
    pub y_steps: usize,
    /// Values of y (equally spaced, both ends) at which branches are continued in x from
    /// both ends of its range to locate the bifurcations the curves start from.
    #[arg(long, default_value_t = MapRequest::new("", (0.0, 1.0), "", (0.0, 1.0)).seeds)]
    pub seeds: usize,
    /// Values of x (equally spaced, both ends) at which each seed value's orbits are sought
    /// after --orbit-transient periods from the configured initial state, then continued.
    #[arg(long, default_value_t = MapRequest::new("", (0.0, 1.0), "", (0.0, 1.0)).x_starts)]
    pub x_starts: usize,
    /// The curves drawn, comma-separated (default all).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "fold,period_doubling,neimark_sacker,grazing"
    )]
    pub kinds: Vec<String>,
    /// Period of the seed branches' first orbits, in excitation periods (default: detected
    /// after --orbit-transient).
    #[arg(long)]
    pub period: Option<u32>,
    /// Period doublings followed along the seed branches (curves of period P, 2P, …).
    #[arg(long, default_value_t = BifmapOptions::default().doublings)]
    pub doublings: u32,
    /// Periods simulated from the configured initial state before shooting for each seed
    /// branch's first orbit.
    #[arg(long, default_value_t = BifmapOptions::default().transient)]
    pub orbit_transient: u32,
    /// Most points per seed branch.
    #[arg(long, default_value_t = BifmapOptions::default().branch_points)]
    pub branch_points: usize,
    /// Most points per half of a curve (from its seed towards either end of y).
    #[arg(long, default_value_t = BifmapOptions::default().curve_points)]
    pub curve_points: usize,
    /// Most curves traced (located bifurcations beyond are counted, not followed).
    #[arg(long, default_value_t = BifmapOptions::default().max_curves)]
    pub max_curves: usize,
    /// Write curves.csv, codim2.csv, located.csv, map.csv and bifmap.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw the curves over the power map (bifmap.png and .svg).
    #[arg(long)]
    pub plot: bool,
    #[command(flatten)]
    pub run: RunArgs,
}

/// The request and options of the map of `args`.
fn request_of(args: &BifmapArgs) -> Result<(MapRequest, BifmapOptions)> {
    let kinds = args
        .kinds
        .iter()
        .map(|k| k.trim().parse::<CurveKind>().context("--kinds"))
        .collect::<Result<Vec<_>>>()?;
    if args.period == Some(0) {
        bail!("--period must be at least 1");
    }
    let request = MapRequest {
        x: args.x.clone(),
        x_range: (args.x_from, args.x_to),
        y: args.y.clone(),
        y_range: (args.y_from, args.y_to),
        seeds: args.seeds,
        x_starts: args.x_starts,
        kinds,
    };
    let options = BifmapOptions {
        transient: args.orbit_transient,
        period: args.period,
        doublings: args.doublings,
        branch_points: args.branch_points,
        curve_points: args.curve_points,
        max_curves: args.max_curves,
        cancel: orbit_cancel(),
    };
    Ok((request, options))
}

/// Refuses a map whose branches, curves or files would be unreasonably large.
fn check_sizes(
    args: &BifmapArgs,
    (request, options): (&MapRequest, &BifmapOptions),
    runner: &PointRunner,
    points: usize,
) -> Result<()> {
    let (n, contacts) = (runner.masses(), runner.contacts());
    limits::check_memory(
        "the seed branches and curves (--seeds, --branch-points, --max-curves, --curve-points)",
        memory_bytes(request, options, n, contacts),
        args.run.allow_large,
    )?;
    let threads = rayon::current_num_threads() as f64;
    limits::check_memory(
        "one point of the power map (--transient + --recorded periods)",
        estimate_point_memory(runner) * threads * 4.0,
        args.run.allow_large,
    )?;
    if args.out.is_some() {
        let row = (10 + 6 * n + contacts) as f64 * limits::CSV_NUMBER_BYTES;
        limits::check_output(
            "curves.csv and map.csv",
            2.0 * args.max_curves as f64 * args.curve_points as f64 * row
                + estimate_point_output(runner, false) * points as f64,
            args.run.allow_large,
        )?;
    }
    Ok(())
}

/// Runs `vibrotribo bifmap`.
pub fn run(args: &BifmapArgs) -> Result<()> {
    if !make(args, true)? {
        return Err(Interrupted {
            what: match &args.out {
                Some(dir) => format!(
                    "the files in {} hold the curves and map points computed so far (\"complete\": false in bifmap.json)",
                    dir.display()
                ),
                None => "the curves above are as far as they were followed".into(),
            },
        }
        .into());
    }
    Ok(())
}

/// Computes the map of `args` and writes its files (with `--out`) and picture (with
/// `--plot`, when complete); `say`: print what it found. Returns whether the curves and the
/// power map are complete (`false` after SIGINT/SIGTERM).
pub fn make(args: &BifmapArgs, say: bool) -> Result<bool> {
    crate::map::check_axis("x", args.x_from, args.x_to, args.x_steps)?;
    crate::map::check_axis("y", args.y_from, args.y_to, args.y_steps)?;
    if args.x_from == args.x_to || args.y_from == args.y_to {
        bail!(
            "--x-from/--x-to and --y-from/--y-to must each span a range (the curves are followed over them)"
        );
    }
    limits::check_grid("--x-steps × --y-steps", args.x_steps as f64 * args.y_steps as f64)?;
    let (request, options) = request_of(args)?;
    set_threads(args.run.threads)?;
    let base = args.input.load_within(args.run.allow_large)?;
    validate(&base, &request, &options)?;
    let runner = args.run.runner(base.clone())?;
    let (xs, ys) = (
        grid(args.x_from, args.x_to, args.x_steps),
        grid(args.y_from, args.y_to, args.y_steps),
    );
    check_distinct("--x-from/--x-to/--x-steps", &xs)?;
    check_distinct("--y-from/--y-to/--y-steps", &ys)?;
    let points: Vec<(f64, f64)> = ys.iter().flat_map(|&y| xs.iter().map(move |&x| (x, y))).collect();
    check_all(&runner, &points, |&(x, y)| {
        vec![(args.x.as_str(), x), (args.y.as_str(), y)]
    })?;
    check_sizes(args, (&request, &options), &runner, points.len())?;
    if let Some(dir) = &args.out {
        check_out_dir(dir, "bifmap.json", args.run.force, |_| true)?;
        create_dir(dir)?;
    }
    let started = Instant::now();
    let map = curves(&base, &request, &options, args.run.quiet)?;
    if say {
        print_map(&map, args.seeds, started.elapsed().as_secs_f64());
    }
    if let Some(dir) = &args.out {
        write_tables(dir, &base, &map)?;
    }
    // The power map: the points of `vibrotribo map`, as it computes and writes them.
    let columns = point_columns(runner.contacts(), runner.options().floquet, false);
    let mut csv = match &args.out {
        Some(dir) => {
            let mut names = vec!["x".to_string(), "y".to_string()];
            names.extend(columns.names());
            Some(CsvFile::create(&dir.join("map.csv"), &names)?)
        }
        None => None,
    };
    let done = if interrupted() {
        0
    } else {
        power_map(args, &runner, &points, columns, csv.as_mut())?
    };
    if let Some(csv) = csv.as_mut() {
        csv.flush()?;
    }
    let complete = map.complete && done == points.len();
    if say {
        println!(
            "  power map of {} × {} points: {done} computed; {:.1} s in all on {} threads",
            xs.len(),
            ys.len(),
            started.elapsed().as_secs_f64(),
            rayon::current_num_threads()
        );
    }
    if let Some(dir) = &args.out {
        let manifest = manifest_of(args, &base, &runner, &map, (&xs, &ys), done, complete)?;
        write_json(&dir.join("bifmap.json"), &to_value(&manifest)?)?;
        if complete && args.plot {
            crate::bifmap_picture::plot_dir(dir)?;
        }
        if say {
            println!(
                "  wrote {0}/curves.csv, {0}/codim2.csv, {0}/located.csv, {0}/map.csv, {0}/bifmap.json",
                dir.display()
            );
        }
    }
    Ok(complete)
}

/// The curves of the map, with a progress bar over the seed branches, then the curves.
fn curves(
    base: &Config,
    request: &MapRequest,
    options: &BifmapOptions,
    quiet: bool,
) -> Result<BifurcationMap> {
    let bar = Progress::new(2 * request.seeds as u64, "seeds", quiet);
    let mut curves_bar: Option<Progress> = None;
    let map = bifurcation_map(base, request, options, |stage| match stage {
        Stage::Seeds { .. } => bar.inc(1),
        Stage::Curves { done, total } => {
            bar.finish();
            let b = curves_bar.get_or_insert_with(|| Progress::new(total as u64, "curves", quiet));
            b.set_len(total as u64);
            b.set_position(done as u64);
        }
        _ => {}
    });
    bar.finish();
    if let Some(b) = &curves_bar {
        b.finish();
    }
    Ok(map?)
}

/// The power map's points, each written to `csv` as `vibrotribo map` writes it; returns how
/// many were computed (fewer after SIGINT/SIGTERM).
fn power_map(
    args: &BifmapArgs,
    runner: &PointRunner,
    points: &[(f64, f64)],
    columns: PointColumns,
    mut csv: Option<&mut CsvFile>,
) -> Result<usize> {
    let (xk, yk) = (args.x.as_str(), args.y.as_str());
    run_points(
        runner,
        points,
        |&(x, y)| vec![(xk, x), (yk, y)],
        ("points", 0, points.len() as u64),
        args.run.quiet,
        |point| {
            let (Some(csv), Some((&(x, y), r))) = (csv.as_deref_mut(), point) else {
                return Ok(());
            };
            let mut row = vec![Cell::Float(x), Cell::Float(y)];
            row.extend(columns.cells(r));
            csv.row(row.iter().map(ToString::to_string))
        },
    )
}

fn write_rows(path: &Path, rows: &Rows) -> Result<()> {
    let mut csv = CsvFile::create(path, &rows.names)?;
    for r in &rows.rows {
        csv.row(r.iter().map(ToString::to_string))?;
    }
    csv.flush()
}

/// `curves.csv`, `codim2.csv` and `located.csv`.
fn write_tables(dir: &Path, base: &Config, map: &BifurcationMap) -> Result<()> {
    let chain = base.chain();
    write_rows(
        &dir.join("curves.csv"),
        &curve_rows(map, chain.len(), chain.contact_count()),
    )?;
    write_rows(&dir.join("codim2.csv"), &codim2_rows(map))?;
    write_rows(&dir.join("located.csv"), &located_rows(map))
}

/// Why a half of a curve ended, in words.
pub fn half_end_text(end: &HalfEnd) -> String {
    match end {
        HalfEnd::Curve(e) => curve_end_text(e),
        HalfEnd::LeftMap { x, y } => format!("leaves the map after ({x}, {y})"),
        HalfEnd::Stopped => "stopped by a signal".into(),
        HalfEnd::NoStart(e) => format!("could not be started: {e}"),
        other => format!("{other:?}"),
    }
}

fn print_map(map: &BifurcationMap, seeds: usize, seconds: f64) {
    let found: usize = map.seeds.iter().filter(|s| s.branches().is_some()).count();
    println!(
        "vibrotribo bifmap: {} curves in ({}, {}) from {} bifurcations located on the branches of {seeds} seed values ({found} branches followed), in {seconds:.1} s{}",
        map.curves.len(),
        map.x,
        map.y,
        map.located.len(),
        if map.untraced > 0 {
            format!("; {} not followed (--max-curves)", map.untraced)
        } else {
            String::new()
        }
    );
    for (i, c) in map.curves.iter().enumerate() {
        let ends: Vec<String> = c.ends.iter().flatten().map(half_end_text).collect();
        println!(
            "  curve {i}: {} of period {}{}, located at {} = {:.8}, {} = {}; {} points; {}",
            c.kind.name(),
            c.period,
            c.contact
                .map_or(String::new(), |k| format!(" at contact {}", k + 1)),
            map.x,
            c.located.parameter,
            map.y,
            map.seeds.get(c.seed).map_or(f64::NAN, |s| s.y),
            c.points.len(),
            ends.join("; ")
        );
        for q in &c.codim2 {
            println!(
                "    {} at {} = {:.8}, {} = {:.8}",
                q.kind.name(),
                map.x,
                q.point.parameter,
                map.y,
                q.point.parameter2
            );
        }
    }
}

fn manifest_of(
    args: &BifmapArgs,
    base: &Config,
    runner: &PointRunner,
    map: &BifurcationMap,
    (xs, ys): (&[f64], &[f64]),
    done: usize,
    complete: bool,
) -> Result<BifmapManifest> {
    let seeds = map
        .seeds
        .iter()
        .map(|s| {
            let c = s.branches();
            SeedRecord {
                y: s.y,
                x_start: s.x_start,
                x_end: s.x_end,
                branches: c.map_or(0, |c| c.branches.len()),
                points: c.map_or(0, |c| c.branches.iter().map(|b| b.points.len()).sum()),
                ends: c.map_or(Vec::new(), |c| {
                    c.branches.iter().map(|b| branch_end_text(&b.end)).collect()
                }),
                on_branch_of: match s.outcome {
                    SeedOutcome::OnBranch(i) => Some(i),
                    _ => None,
                },
                error: s.error_text(),
            }
        })
        .collect();
    let curves = map
        .curves
        .iter()
        .enumerate()
        .map(|(i, c)| BifmapCurveRecord {
            curve: i,
            kind: c.kind.name().into(),
            period: c.period,
            contact: c.contact.map(|k| k + 1),
            seed_y: map.seeds.get(c.seed).map_or(f64::NAN, |s| s.y),
            located_x: c.located.parameter,
            points: c.points.len(),
            end_towards_from: c.ends[0].as_ref().map(half_end_text),
            end_towards_to: c.ends[1].as_ref().map(half_end_text),
            found_again: c.found_again,
        })
        .collect();
    let o = runner.options();
    Ok(BifmapManifest {
        command: Kind::Bifmap,
        complete,
        x: Axis::new(&map.x, (args.x_from, args.x_to), xs.to_vec()),
        y: Axis::new(&map.y, (args.y_from, args.y_to), ys.to_vec()),
        seed_values: grid(args.y_from, args.y_to, args.seeds),
        x_starts: grid(args.x_from, args.x_to, args.x_starts),
        kinds: args.kinds.iter().map(|k| k.trim().to_string()).collect(),
        period: args.period,
        doublings: args.doublings,
        orbit_transient_periods: args.orbit_transient,
        branch_points: args.branch_points,
        curve_points: args.curve_points,
        max_curves: args.max_curves,
        mechanics_only: runner.mechanics_only(),
        seeds,
        curves,
        untraced: map.untraced,
        codim2_points: map.curves.iter().map(|c| c.codim2.len()).sum(),
        power_map: PowerMapRecord {
            point: PointRecord::of(o),
            floquet: o.floquet,
            settle: SettleRecord::of(o),
            done,
            points: xs.len() * ys.len(),
        },
        settings: crate::manifest::settings_of(base).context("the configuration as JSON")?,
        base_motion: base_motion_of(base),
        vibrotribo_version: crate::manifest::version(),
    })
}
