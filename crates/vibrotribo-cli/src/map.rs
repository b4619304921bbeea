//! `vibrotribo map` (average power, period and impacts per period on a two-parameter grid)
//! and `vibrotribo optimize-mass-ratio` (the optimal mass ratio R_mo(Ω) and the paper's
//! quadratic fit of it, seed Fig. 16).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result, bail};
use serde::Deserialize;
use vibrotribo::analysis::fit_quadratic;
use vibrotribo::config::Param;

use crate::config::ConfigArgs;
use crate::job::{CsvSpec, GridOutput, Layout};
use crate::job::{
    MergeArgs, RunArgs, Shard, check_all, check_distinct, estimate_point_memory, estimate_point_output,
    header_len, point_columns, run_points, set_threads,
};
use crate::limits;
use crate::manifest::{
    Axis, FitManifest, FitRecord, Kind, MapManifest, PaperFitRecord, PeriodsRecord, ShardRecord, to_value,
};
pub use crate::mass_ratio_picture::plot_optimal_mass_ratio;
use crate::mass_ratio_picture::plot_optimize_mass_ratio;
use crate::output::{CsvFile, check_out_dir, create_dir, write_json};
use crate::progress::Interrupted;
use vibrotribo::sweep::{Cell, PointColumns, grid};

/// Options of `vibrotribo map`.
#[derive(Debug, clap::Args)]
pub struct MapArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Parameter along x (any key `sweep --param` accepts).
    #[arg(long)]
    pub x: String,
    /// First x value.
    #[arg(long, allow_negative_numbers = true)]
    pub x_from: f64,
    /// Last x value.
    #[arg(long, allow_negative_numbers = true)]
    pub x_to: f64,
    /// Number of x values.
    #[arg(long)]
    pub x_steps: usize,
    /// Parameter along y.
    #[arg(long)]
    pub y: String,
    /// First y value.
    #[arg(long, allow_negative_numbers = true)]
    pub y_from: f64,
    /// Last y value.
    #[arg(long, allow_negative_numbers = true)]
    pub y_to: f64,
    /// Number of y values.
    #[arg(long)]
    pub y_steps: usize,
    /// Write map.csv and map.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Compute only the I-th of N interleaved slices of the grid (points in map.csv order),
    /// e.g. `--shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`; combine with `merge`.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Continue the interrupted map (or shard) in --out DIR from its finished points.
    #[arg(long)]
    pub resume: bool,
    /// Also draw heat maps (PNG and SVG) into the output directory.
    #[arg(long)]
    pub plot: bool,
    #[command(flatten)]
    pub run: RunArgs,
}

/// Checks one axis of a grid: at least one value, finite ends.
pub(crate) fn check_axis(name: &str, from: f64, to: f64, steps: usize) -> Result<()> {
    if steps == 0 {
        bail!("--{name}-steps must be at least 1");
    }
    if !from.is_finite() || !to.is_finite() {
        bail!("--{name}-from and --{name}-to must be finite numbers");
    }
    Ok(())
}

/// Files of a map directory: `map.csv` (one row per point) and the manifest `map.json`.
fn map_layout(columns: PointColumns) -> Layout {
    let mut cols = vec!["x".to_string(), "y".to_string()];
    cols.extend(columns.names());
    Layout {
        manifest: "map.json",
        files: vec![CsvSpec {
            name: "map.csv",
            columns: cols,
        }],
        index_file: 0,
        key_fields: 2,
    }
}

/// The points of a map in grid order (y outer, x inner) and their keys (`x,y` as written).
fn map_points(xs: &[f64], ys: &[f64]) -> Vec<(f64, f64)> {
    ys.iter().flat_map(|&y| xs.iter().map(move |&x| (x, y))).collect()
}

fn point_key(&(x, y): &(f64, f64)) -> String {
    format!("{x},{y}")
}

/// Runs `vibrotribo map`.
pub fn run(args: &MapArgs) -> Result<()> {
    check_axis("x", args.x_from, args.x_to, args.x_steps)?;
    check_axis("y", args.y_from, args.y_to, args.y_steps)?;
    limits::check_grid("--x-steps × --y-steps", args.x_steps as f64 * args.y_steps as f64)?;
    if args.resume && args.out.is_none() {
        bail!("--resume needs --out DIR (the directory of the job to continue)");
    }
    set_threads(args.run.threads)?;
    let base = args.input.load_within(args.run.allow_large)?;
    let (px, py) = (Param::new(&base, &args.x)?, Param::new(&base, &args.y)?);
    if px.overlaps(&py) {
        bail!(
            "--x {} and --y {} set the same quantity: a map needs two different parameters \
             (for one parameter use `vibrotribo sweep`)",
            args.x,
            args.y
        );
    }
    // A point stops part-way on SIGINT/SIGTERM (and is not written).
    let runner = args
        .run
        .runner(base)?
        .with_cancel(crate::progress::orbit_cancel());
    let (xs, ys) = (
        grid(args.x_from, args.x_to, args.x_steps),
        grid(args.y_from, args.y_to, args.y_steps),
    );
    check_distinct("--x-from/--x-to/--x-steps", &xs)?;
    check_distinct("--y-from/--y-to/--y-steps", &ys)?;
    let mut points = map_points(&xs, &ys);
    if let Some(s) = args.shard {
        points = points
            .into_iter()
            .enumerate()
            .filter(|(j, _)| j % s.count == s.index)
            .map(|(_, p)| p)
            .collect();
    }
    check_all(&runner, &points, |&(x, y)| {
        vec![(args.x.as_str(), x), (args.y.as_str(), y)]
    })?;
    let threads = rayon::current_num_threads() as f64;
    limits::check_memory(
        "one point of the map (--transient + --recorded periods)",
        estimate_point_memory(&runner) * threads * 4.0,
        args.run.allow_large,
    )?;
    if args.out.is_some() {
        limits::check_output(
            "map.csv",
            estimate_point_output(&runner, false) * points.len() as f64,
            args.run.allow_large,
        )?;
    }
    let columns = point_columns(runner.contacts(), runner.options().floquet, false);
    let axis = |param: &str, from: f64, to: f64, steps: usize, values: &[f64]| Axis {
        param: param.to_string(),
        from,
        to,
        steps,
        values: values.to_vec(),
    };
    let mut manifest = MapManifest::new(
        axis(&args.x, args.x_from, args.x_to, args.x_steps, &xs),
        axis(&args.y, args.y_from, args.y_to, args.y_steps, &ys),
        &runner,
    )
    .context("the configuration as JSON")?;
    manifest.shard = args.shard.map(|s| ShardRecord {
        index: s.index,
        count: s.count,
    });
    let settings = to_value(&manifest)?;
    let keys: Vec<String> = points.iter().map(point_key).collect();
    let (mut out, skip) = match &args.out {
        None => (None, 0),
        Some(dir) if args.resume => {
            let (o, done) = GridOutput::resume(dir, map_layout(columns), settings, &keys, keys.len())?;
            (Some(o), done)
        }
        Some(dir) => (
            Some(GridOutput::create(
                dir,
                map_layout(columns),
                settings,
                args.run.force,
            )?),
            0,
        ),
    };
    let started = Instant::now();
    let (xk, yk) = (args.x.as_str(), args.y.as_str());
    let computed = run_points(
        &runner,
        &points[skip..],
        |&(x, y)| vec![(xk, x), (yk, y)],
        ("points", skip as u64, points.len() as u64),
        args.run.quiet,
        |point| {
            let Some(out) = out.as_mut() else { return Ok(()) };
            let Some((&(x, y), r)) = point else {
                return out.commit();
            };
            let mut row = vec![Cell::Float(x), Cell::Float(y)];
            row.extend(columns.cells(r));
            out.row(0, row.iter().map(ToString::to_string).collect())
        },
    )?;
    let done = skip + computed;
    let complete = done == points.len();
    if let (Some(out), Some(dir)) = (out, &args.out) {
        out.finish(complete, done)?;
        if complete && args.plot && args.shard.is_none() {
            crate::plots::plot_map(dir)?;
        }
    }
    println!(
        "map of {} × {} ({} × {} points{}): {computed} computed{} in {:.2} s on {} threads",
        args.x,
        ys.len(),
        xs.len(),
        ys.len(),
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
    if let Some(dir) = &args.out {
        println!("  wrote {0}/map.csv, {0}/map.json", dir.display());
    }
    if !complete {
        return Err(Interrupted {
            what: format!(
                "map.csv holds the {done} of {} points finished, marked incomplete in map.json; \
                 the same command with --resume continues",
                points.len()
            ),
        }
        .into());
    }
    Ok(())
}

/// Merges the shards of a map (`vibrotribo merge`).
pub fn merge(args: &MergeArgs) -> Result<()> {
    // map.csv: x, y, then the point columns.
    let first: MapManifest = crate::manifest::read(&args.shards[0].join("map.json"))?;
    let columns = PointColumns::from_width(
        header_len(&args.shards[0].join("map.csv"))?.saturating_sub(2),
        first.floquet,
        false,
    );
    let keys = |m: &serde_json::Value| -> Result<Vec<String>> {
        let m = MapManifest::deserialize(m).context("map.json")?;
        Ok(map_points(&m.x.values, &m.y.values)
            .iter()
            .map(point_key)
            .collect())
    };
    crate::job::merge(&args.shards, &args.out, &map_layout(columns), keys)
}

/// Options of `vibrotribo optimize-mass-ratio`.
#[derive(Debug, clap::Args)]
pub struct OptimizeArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// First Ω.
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.55)]
    pub omega_from: f64,
    /// Last Ω.
    #[arg(long, allow_negative_numbers = true, default_value_t = 0.95)]
    pub omega_to: f64,
    /// Number of Ω values.
    #[arg(long, default_value_t = 9)]
    pub omega_steps: usize,
    /// Smallest mass ratio R_m = m2/m1 tried (m1 and m3 fixed).
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.2)]
    pub rm_from: f64,
    /// Largest mass ratio tried.
    #[arg(long, allow_negative_numbers = true, default_value_t = 7.0)]
    pub rm_to: f64,
    /// Number of mass ratios per Ω.
    #[arg(long, default_value_t = 59)]
    pub rm_steps: usize,
    /// Write power_grid.csv, optimum.csv and fit.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw R_mo(Ω) with the fits (PNG and SVG).
    #[arg(long)]
    pub plot: bool,
    #[command(flatten)]
    pub run: RunArgs,
}

/// The paper's fit of the optimal mass ratio, R_mo = aΩ² + bΩ + c (Sect. 4.3.2).
pub const PAPER_FIT: [f64; 3] = vibrotribo::study::PAPER_MASS_RATIO_FIT;

/// The paper's fit evaluated at Ω = `w`.
pub fn paper_fit(w: f64) -> f64 {
    vibrotribo::study::paper_mass_ratio_fit(w)
}

/// The maximum of `values` on the equally spaced `grid`, refined by the parabola through the
/// best point and its neighbours (when it is interior and the parabola is concave).
pub fn refine_maximum(grid: &[f64], values: &[f64]) -> Option<(f64, f64)> {
    vibrotribo::study::refine_maximum(grid, values)
}

/// The optimal mass ratio at each Ω of `omegas`: the maximum of its row of `power` (row-major,
/// `ratios.len()` mass ratios per Ω) refined by [`refine_maximum`], as (Ω, R_mo, power there
/// in W, whether R_mo is at an end of `ratios`). An Ω without a finite power is left out.
pub(crate) fn optima(omegas: &[f64], ratios: &[f64], power: &[f64]) -> Vec<(f64, f64, f64, bool)> {
    vibrotribo::study::mass_ratio_optima(omegas, ratios, power)
        .into_iter()
        .map(|o| (o.omega_ratio, o.mass_ratio, o.average_power_w, o.at_edge))
        .collect()
}

/// Runs `vibrotribo optimize-mass-ratio`.
pub fn optimize(args: &OptimizeArgs) -> Result<()> {
    check_axis("omega", args.omega_from, args.omega_to, args.omega_steps)?;
    check_axis("rm", args.rm_from, args.rm_to, args.rm_steps)?;
    if args.rm_from <= 0.0 {
        bail!("--rm-from must be positive");
    }
    if args.run.mechanics_only {
        bail!("the optimal mass ratio maximises power: --mechanics-only does not apply");
    }
    set_threads(args.run.threads)?;
    let base = args.input.load_within(args.run.allow_large)?;
    // A point stops part-way on SIGINT/SIGTERM (and is not written).
    let runner = args
        .run
        .runner(base)?
        .with_cancel(crate::progress::orbit_cancel());
    let contacts = runner.contacts();
    let (omegas, ratios) = (
        grid(args.omega_from, args.omega_to, args.omega_steps),
        grid(args.rm_from, args.rm_to, args.rm_steps),
    );
    let points: Vec<(f64, f64)> = omegas
        .iter()
        .flat_map(|&w| ratios.iter().map(move |&r| (w, r)))
        .collect();
    check_all(&runner, &points, |&(w, r)| {
        vec![("omega_ratio", w), ("mass_ratio", r)]
    })?;
    let mut power = vec![f64::NAN; points.len()];
    let mut index = 0;
    let mut grid_csv = match &args.out {
        Some(dir) => {
            // It writes no manifest of its own: any command's manifest is another job's.
            check_out_dir(dir, "", args.run.force, |_| false)?;
            create_dir(dir)?;
            Some(CsvFile::create(
                &dir.join("power_grid.csv"),
                &[
                    "omega_ratio",
                    "mass_ratio",
                    "average_power_w",
                    "impacts_per_period",
                    "period",
                    "error",
                ],
            )?)
        }
        None => None,
    };
    let started = Instant::now();
    let done = run_points(
        &runner,
        &points,
        |&(w, r)| vec![("omega_ratio", w), ("mass_ratio", r)],
        ("points", 0, points.len() as u64),
        args.run.quiet,
        |point| {
            let Some((&(w, r), res)) = point else {
                return Ok(());
            };
            if let Ok(p) = res {
                power[index] = p.average_power_w.unwrap_or(f64::NAN);
            }
            index += 1;
            if let Some(csv) = grid_csv.as_mut() {
                // Of the point's columns: average_power_w, impacts_per_period, period, error.
                let mut cells = point_columns(contacts, false, false).cells(res);
                let error = cells.get(6 + contacts).cloned().unwrap_or(Cell::Missing);
                cells.truncate(3);
                csv.row(
                    [Cell::Float(w), Cell::Float(r)]
                        .into_iter()
                        .chain(cells)
                        .chain([error]),
                )?;
            }
            Ok(())
        },
    )?;
    if done < points.len() {
        let kept = match (grid_csv.as_mut(), &args.out) {
            (Some(csv), Some(dir)) => {
                csv.flush()?;
                format!(
                    "{} holds the {done} points finished; no optimum or fit was written",
                    dir.join("power_grid.csv").display()
                )
            }
            _ => "nothing was written".to_string(),
        };
        return Err(Interrupted {
            what: format!("after {done} of {} points; {kept}", points.len()),
        }
        .into());
    }
    let n = ratios.len();
    let optimum = optima(&omegas, &ratios, &power);
    let ws: Vec<f64> = optimum.iter().map(|o| o.0).collect();
    let rs: Vec<f64> = optimum.iter().map(|o| o.1).collect();
    let fit = fit_quadratic(&ws, &rs).ok();
    println!(
        "optimal mass ratio over Ω = {}…{} ({} values) × R_m = {}…{} ({} values), {} transient + {} recorded periods, in {:.1} s:",
        args.omega_from,
        args.omega_to,
        omegas.len(),
        args.rm_from,
        args.rm_to,
        n,
        runner.options().transient_periods,
        runner.options().recorded_periods,
        started.elapsed().as_secs_f64()
    );
    for (w, r, p, edge) in &optimum {
        let paper = paper_fit(*w);
        println!(
            "  Ω = {w:.4}: R_mo = {r:.3} (paper's fit {paper:.3}), P = {:.4e} W{}",
            p,
            if *edge {
                " (at the edge of the R_m range)"
            } else {
                ""
            }
        );
    }
    if let Some(f) = &fit {
        println!(
            "  fit R_mo = {:.2} Ω² {:+.2} Ω {:+.2} (R² = {}); the paper's: {} Ω² {:+} Ω {:+}",
            f.a,
            f.b,
            f.c,
            f.r_squared.map_or("n/a".into(), |r| format!("{r:.3}")),
            PAPER_FIT[0],
            PAPER_FIT[1],
            PAPER_FIT[2]
        );
    }
    if let (Some(csv), Some(dir)) = (grid_csv.as_mut(), &args.out) {
        csv.flush()?;
        let mut o = CsvFile::create(
            &dir.join("optimum.csv"),
            &[
                "omega_ratio",
                "optimal_mass_ratio",
                "average_power_w",
                "at_edge",
                "paper_fit",
            ],
        )?;
        for (w, r, p, edge) in &optimum {
            let paper = paper_fit(*w);
            o.row([
                w.to_string(),
                r.to_string(),
                p.to_string(),
                edge.to_string(),
                paper.to_string(),
            ])?;
        }
        o.flush()?;
        let manifest = FitManifest {
            command: Kind::OptimizeMassRatio,
            fit: fit.as_ref().map(|f| FitRecord {
                a: f.a,
                b: f.b,
                c: f.c,
                r_squared: f.r_squared,
                rms_residual: f.rms_residual,
            }),
            paper_fit: PaperFitRecord {
                a: PAPER_FIT[0],
                b: PAPER_FIT[1],
                c: PAPER_FIT[2],
            },
            omega_ratio: ws,
            optimal_mass_ratio: rs,
            periods: PeriodsRecord::of(runner.options()),
            settings: crate::manifest::settings_of(runner.base())?,
        };
        write_json(&dir.join("fit.json"), &to_value(&manifest)?)?;
        if args.plot {
            plot_optimize_mass_ratio(dir)?;
        }
        println!(
            "  wrote {0}/power_grid.csv, {0}/optimum.csv, {0}/fit.json",
            dir.display()
        );
    }
    Ok(())
}
