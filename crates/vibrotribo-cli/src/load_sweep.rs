//! `vibrotribo load-sweep`: average power against load resistance (on one mechanical run, or a
//! coupled run per load under two-way coupling), the optimal load, and the V–Q cycle.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use vibrotribo::electrical::{HarvesterParams, Load, log_spaced};
use vibrotribo::study::{LoadStudyOptions, load_study};

use crate::config::ConfigArgs;
use crate::limits;
use crate::manifest::{Kind, LoadSweepManifest, MarginRecord, read, to_value};
use crate::output::{CsvFile, column, create_dir, read_csv, si, write_json};
use crate::plot::{self, both};
use crate::progress::{Interrupted, Progress, Watch};

/// Options of `vibrotribo load-sweep`.
#[derive(Debug, clap::Args)]
pub struct LoadSweepArgs {
    #[command(flatten)]
    pub input: ConfigArgs,
    /// Smallest load resistance, Ω.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1e3)]
    pub from: f64,
    /// Largest load resistance, Ω.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1e13)]
    pub to: f64,
    /// Log-spaced resistances between --from and --to.
    #[arg(long, default_value_t = 41)]
    pub steps: usize,
    /// Points of the V–Q cycle (one excitation period, the last one simulated).
    #[arg(long, default_value_t = 400)]
    pub vq_points: usize,
    /// Write load_sweep.csv, vq_cycle.csv and load_sweep.json to this directory.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Also draw load_sweep.png/.svg and vq_cycle.png/.svg (without --out: into vibrotribo-out/load-sweep).
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Allow a job above the size limits (see the guide's "Limits and safety").
    #[arg(long)]
    pub allow_large: bool,
}

/// Runs `vibrotribo load-sweep`.
pub fn run(args: &LoadSweepArgs) -> Result<()> {
    if !(args.from.is_finite() && args.from > 0.0 && args.to.is_finite() && args.to >= args.from) {
        bail!(
            "--from and --to must be positive resistances with --from ≤ --to (got {} and {})",
            args.from,
            args.to
        );
    }
    if args.steps == 0 {
        bail!("--steps must be at least 1");
    }
    limits::check_grid("--steps", args.steps as f64)?;
    let config = args.input.load_within(args.allow_large)?;
    let spec = config.run_spec(false);

    // One-way coupling: the mechanics is simulated once and replayed for every load; two-way:
    // every load is a whole coupled run (the progress bar then counts each run's periods).
    let mut watch = Watch {
        progress: Progress::new(spec.periods, "mechanics", args.quiet),
    };
    let options = LoadStudyOptions {
        resistances: log_spaced(args.from, args.to, args.steps),
        vq_points: args.out.is_some().then_some(args.vq_points),
    };
    limits::check_memory(
        "the V–Q cycles (--vq-points)",
        options.estimated_bytes(),
        args.allow_large,
    )?;
    let study = load_study(&spec, &options, &mut watch)?;
    watch.progress.finish();
    let Some(study) = study else {
        return Err(Interrupted {
            what: "during the mechanical run; nothing was written".into(),
        }
        .into());
    };
    let sweep = &study.sweep;
    let configured = study.configured_load_ohm;
    let p_configured = study.configured_average_power_w;
    let harvester = HarvesterParams {
        load: Load::Resistor {
            resistance: configured,
        },
        ..config.harvester().clone()
    };
    let best = sweep.optimum;
    println!(
        "load sweep over {} loads from {} to {} ({} periods, {} transient)",
        args.steps,
        si(args.from, "Ω"),
        si(args.to, "Ω"),
        spec.periods,
        spec.transient_periods
    );
    println!(
        "  optimal load {} → average power {}{}",
        si(best.resistance_ohm, "Ω"),
        si(best.average_power_w, "W"),
        if sweep.optimum_at_edge {
            " (at the edge of the range: widen it)"
        } else {
            ""
        }
    );
    println!(
        "  configured load {} → {} ({:.3e} of the optimum; the optimum is {:.3e}× the configured load)",
        si(configured, "Ω"),
        si(p_configured, "W"),
        p_configured / best.average_power_w,
        best.resistance_ohm / configured
    );

    if let Some(dir) = &args.out {
        create_dir(dir)?;
        let mut csv = CsvFile::create(
            &dir.join("load_sweep.csv"),
            &["load_resistance_ohm", "average_power_w", "energy_per_period_j"],
        )?;
        for p in &sweep.points {
            csv.row([p.resistance_ohm, p.average_power_w, p.energy_per_period_j])?;
        }
        csv.flush()?;
        // V–Q cycles over the last simulated period, at the configured and the optimal load.
        let mut vq = CsvFile::create(
            &dir.join("vq_cycle.csv"),
            &["load_resistance_ohm", "time_s", "q_c", "v_v", "i_a"],
        )?;
        let mut margins = Vec::new();
        for cycle in &study.vq_cycles {
            let (r, c, margin) = (cycle.load_resistance_ohm, &cycle.samples, cycle.breakdown);
            for j in 0..c.times.len() {
                vq.row([r, c.times[j], c.charge_c[j], c.voltage_v[j], c.current_a[j]])?;
            }
            println!(
                "  at {}: largest |V_gap|/V_breakdown over the last period {:.3}{}",
                si(r, "Ω"),
                margin.worst_ratio,
                if margin.worst_ratio >= 1.0 {
                    format!(
                        " ({} across {}): the air would break down",
                        si(margin.gap_voltage_v, "V"),
                        si(margin.gap_m, "m")
                    )
                } else {
                    String::new()
                }
            );
            margins.push(MarginRecord {
                load_resistance_ohm: r,
                air_breakdown: margin,
            });
        }
        vq.flush()?;
        let manifest = LoadSweepManifest {
            command: Kind::LoadSweep,
            optimum: best,
            optimum_at_edge: sweep.optimum_at_edge,
            configured_load_ohm: configured,
            configured_average_power_w: p_configured,
            power_ratio_configured_to_optimum: p_configured / best.average_power_w,
            air_breakdown_last_period: margins,
            points: sweep.points.clone(),
            periods: spec.periods,
            transient_periods: spec.transient_periods,
            harvester,
            settings: crate::manifest::settings_of(&config)?,
            base_motion: vibrotribo::report::BaseMotionSummary::of(&spec),
        };
        write_json(&dir.join("load_sweep.json"), &to_value(&manifest)?)?;
        if args.plot {
            plot_load_sweep(dir)?;
        }
        println!(
            "  wrote {0}/load_sweep.csv, {0}/vq_cycle.csv, {0}/load_sweep.json",
            dir.display()
        );
    }
    Ok(())
}

/// Draws the power against the load and the V–Q cycles of a `load-sweep` directory
/// (`load_sweep.png`, `vq_cycle.png` and their `.svg`).
pub fn plot_load_sweep(dir: &Path) -> Result<()> {
    let m: LoadSweepManifest = read(&dir.join("load_sweep.json"))?;
    let xs: Vec<f64> = m.points.iter().map(|p| p.resistance_ohm.log10()).collect();
    let ys: Vec<f64> = m.points.iter().map(|p| p.average_power_w).collect();
    let mut fig = plot::Figure::new(
        "Average power against load resistance",
        "log10(R / Ω)",
        "average power P_a [W]",
    );
    fig.y_scale = plot::Scale::Log;
    both(dir, "load_sweep", |path| {
        plot::line_plot(path, &fig, &[plot::Series::new("P_a(R)", &xs, &ys)])
    })?;
    // The cycles of vq_cycle.csv, one per load in the order written.
    let (h, rows) = read_csv(&dir.join("vq_cycle.csv"))?;
    let (cr, ct, cq, cv) = (
        column(&h, "load_resistance_ohm")?,
        column(&h, "time_s")?,
        column(&h, "q_c")?,
        column(&h, "v_v")?,
    );
    // A cycle starts where the load changes or the time goes back.
    let mut cycles: Vec<(f64, Vec<f64>, Vec<f64>)> = Vec::new();
    let mut last_time = f64::INFINITY;
    for r in &rows {
        let number = |c: usize| -> Result<f64> {
            r[c].parse()
                .with_context(|| format!("vq_cycle.csv: {} is not a number", r[c]))
        };
        let (load, time) = (number(cr)?, number(ct)?);
        if cycles.last().is_none_or(|c| c.0 != load) || time < last_time {
            cycles.push((load, Vec::new(), Vec::new()));
        }
        if let Some(c) = cycles.last_mut() {
            c.1.push(number(cq)?);
            c.2.push(number(cv)?);
        }
        last_time = time;
    }
    let labels: Vec<String> = cycles
        .iter()
        .map(|(r, _, _)| format!("R = {}", si(*r, "Ω")))
        .collect();
    let series: Vec<plot::Series> = cycles
        .iter()
        .zip(&labels)
        .map(|((_, q, v), l)| plot::Series::new(l, q, v))
        .collect();
    let fig = plot::Figure::new("V–Q cycle (last period)", "charge Q [C]", "voltage V [V]");
    both(dir, "vq_cycle", |path| plot::line_plot(path, &fig, &series))
}
