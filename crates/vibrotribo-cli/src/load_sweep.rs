//! `vibrotribo load-sweep`: average power against load resistance on one mechanical run, the
//! optimal load, and the V–Q cycle.

use std::path::PathBuf;

use anyhow::{Result, bail};
use serde_json::json;
use vibrotribo::electrical::breakdown::BreakdownMargin;
use vibrotribo::electrical::{ElectricalSamples, HarvesterParams, Load, load_sweep, log_spaced};
use vibrotribo::study::{Ending, Harvester, ReplayOptions, record_trajectory, replay};
use vibrotribo::{ChainParams, Trajectory};

use crate::config::ConfigArgs;
use crate::output::{CsvFile, create_dir, si, write_json};
use crate::plot;
use crate::plots::both;
use crate::progress::{Interrupted, Progress, Watch};

/// The V–Q cycle of period `index` at `points + 1` times of `harvester` along `trajectory`
/// (of `chain`), and the air-breakdown check from that period on.
pub fn vq_cycle(
    trajectory: &Trajectory,
    chain: &ChainParams,
    harvester: &Harvester,
    index: u64,
    points: usize,
) -> Result<(ElectricalSamples, BreakdownMargin)> {
    let r = replay(
        trajectory,
        chain,
        harvester,
        &ReplayOptions {
            breakdown_from_period: Some(index),
            vq_cycle: Some((index, points)),
            ..ReplayOptions::default()
        },
    )?;
    Ok((
        r.vq_cycle.unwrap_or_default(),
        r.electrical.breakdown.unwrap_or_default(),
    ))
}

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
    /// Also draw load_sweep.png/.svg and vq_cycle.png/.svg (needs --out).
    #[arg(long)]
    pub plot: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
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
    if args.plot && args.out.is_none() {
        bail!("--plot needs --out DIR");
    }
    let config = args.input.load()?;
    let spec = config.run_spec(false);
    let chain = &spec.chain;
    let configured = config
        .harvester()
        .load
        .resistance()
        .unwrap_or(Load::default().resistance().unwrap_or(1e5));
    let resistor = |r: f64| Harvester {
        params: HarvesterParams {
            load: Load::Resistor { resistance: r },
            ..config.harvester().clone()
        },
        ..Harvester::new(config.harvester().clone(), config.charge_options().clone())
    };
    let harvester = resistor(configured).params;
    let options = config.charge_options().clone();
    let period = chain.period();

    // The coupling is one-way: simulate the mechanics once and replay it for every load.
    let mut watch = Watch {
        progress: Progress::new(spec.periods, "mechanics", args.quiet),
    };
    let (trajectory, ending) = record_trajectory(&spec, 0, &mut watch)?;
    watch.progress.finish();
    if ending != Ending::Completed {
        return Err(Interrupted {
            what: "during the mechanical run; nothing was written".into(),
        }
        .into());
    }

    let resistances = log_spaced(args.from, args.to, args.steps);
    let sweep = load_sweep(
        &trajectory,
        &harvester,
        period,
        &resistances,
        spec.transient_periods as usize,
        &options,
    )?;
    let at = |r: f64| -> Result<f64> {
        let replayed = replay(
            &trajectory,
            chain,
            &resistor(r),
            &ReplayOptions {
                transient_periods: spec.transient_periods,
                ..ReplayOptions::default()
            },
        )?;
        Ok(replayed.electrical.power.map_or(f64::NAN, |s| s.average_power_w))
    };
    let p_configured = at(configured)?;
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
        let last = spec.periods - 1;
        let mut vq = CsvFile::create(
            &dir.join("vq_cycle.csv"),
            &["load_resistance_ohm", "time_s", "q_c", "v_v", "i_a"],
        )?;
        let mut cycles = Vec::new();
        let mut margins = Vec::new();
        for r in [configured, best.resistance_ohm] {
            let (c, margin) = vq_cycle(&trajectory, chain, &resistor(r), last, args.vq_points)?;
            {
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
                margins.push(json!({"load_resistance_ohm": r, "air_breakdown": margin}));
                cycles.push((r, c.charge_c.clone(), c.voltage_v.clone()));
            }
        }
        vq.flush()?;
        write_json(
            &dir.join("load_sweep.json"),
            &json!({
                "optimum": best,
                "optimum_at_edge": sweep.optimum_at_edge,
                "configured_load_ohm": configured,
                "configured_average_power_w": p_configured,
                "power_ratio_configured_to_optimum": p_configured / best.average_power_w,
                "air_breakdown_last_period": margins,
                "points": sweep.points,
                "periods": spec.periods,
                "transient_periods": spec.transient_periods,
                "harvester": harvester,
                "settings": config.table(),
            }),
        )?;
        if args.plot {
            let xs: Vec<f64> = sweep.points.iter().map(|p| p.resistance_ohm.log10()).collect();
            let ys: Vec<f64> = sweep.points.iter().map(|p| p.average_power_w).collect();
            let mut fig = plot::Figure::new(
                "Average power against load resistance",
                "log10(R / Ω)",
                "average power P_a [W]",
            );
            fig.y_scale = plot::Scale::Log;
            both(dir, "load_sweep", |path| {
                plot::line_plot(path, &fig, &[plot::Series::new("P_a(R)", &xs, &ys)])
            })?;
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
            both(dir, "vq_cycle", |path| plot::line_plot(path, &fig, &series))?;
        }
        println!(
            "  wrote {0}/load_sweep.csv, {0}/vq_cycle.csv, {0}/load_sweep.json",
            dir.display()
        );
    }
    Ok(())
}
