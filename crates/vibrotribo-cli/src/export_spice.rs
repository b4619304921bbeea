//! `vibrotribo export-spice RUN_DIR`: an ngspice netlist of a run's harvester, driven by the
//! run's gap waveforms, for use in one's own circuit designs (and an optional check against
//! ngspice).

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use vibrotribo::config::Config;
use vibrotribo::coupling::Coupling;
use vibrotribo::electrical::spice::{self, SpiceOptions};
use vibrotribo::electrical::{ChargeSolver, PwlGaps};
use vibrotribo::study::{RunSpec, record_trajectory};

use crate::limits;
use crate::output::si;

/// Options of `vibrotribo export-spice`.
#[derive(Debug, clap::Args)]
pub struct ExportSpiceArgs {
    /// A directory written by `vibrotribo simulate --out`.
    pub run_dir: PathBuf,
    /// First excitation period exported (default: the first after the transient, or the
    /// last --periods of a run too short for that). The periods exported must lie within
    /// the run.
    #[arg(long)]
    pub from_period: Option<u64>,
    /// Periods exported (default: 2).
    #[arg(long, default_value_t = 2)]
    pub periods: u64,
    /// PWL sampling interval as a fraction of the excitation period (every impact is also a
    /// breakpoint).
    #[arg(long, default_value_t = 1.0 / 2000.0)]
    pub dt_fraction: f64,
    /// Netlist file name, written in RUN_DIR (a plain file name: no directory part).
    #[arg(long, default_value = "harvester.cir")]
    pub name: String,
    /// Also run ngspice on the netlist and compare its delivered energy with vibrotribo's.
    #[arg(long)]
    pub check: bool,
    /// Allow a netlist above the size limits (see the guide's "Limits and safety").
    #[arg(long)]
    pub allow_large: bool,
}

/// Refuses a netlist name that is not a plain file name (a directory part, `..`), so that
/// the netlist stays inside the run's directory.
fn check_name(name: &str) -> Result<()> {
    let plain = !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\'])
        && std::path::Path::new(name).file_name() == Some(std::ffi::OsStr::new(name));
    if !plain {
        bail!(
            "--name must be a plain file name, written inside RUN_DIR (no `/`, `\\` or `..`); got {name:?}"
        );
    }
    Ok(())
}

/// Runs `vibrotribo export-spice`.
pub fn run(args: &ExportSpiceArgs) -> Result<()> {
    let summary_path = args.run_dir.join("summary.json");
    let text = std::fs::read_to_string(&summary_path).with_context(|| {
        format!(
            "cannot read {} (export-spice needs a directory written by `vibrotribo simulate --out`)",
            summary_path.display()
        )
    })?;
    let summary: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not valid JSON", summary_path.display()))?;
    let settings = summary
        .get("settings")
        .cloned()
        .with_context(|| format!("{} has no `settings`", summary_path.display()))?;
    let table: toml::Table =
        serde_json::from_value(settings).context("the recorded settings are not a table")?;
    check_name(&args.name)?;
    let config = Config::from_table(table)?;
    let chain = config.chain();
    let harvester = config.harvester();
    if chain.len() < 2 {
        bail!(
            "{} is a run of one mass, which has no harvester (the harvester sits between two masses): \
             there is nothing to export",
            args.run_dir.display()
        );
    }
    if harvester.coupling == Coupling::TwoWay {
        bail!(
            "{} is a two-way run (harvester.coupling = \"two_way\"): its gaps depend on the charges, \
             and export-spice drives the netlist with the mechanics alone; export a one-way run",
            args.run_dir.display()
        );
    }
    if !(args.dt_fraction > 0.0 && args.dt_fraction < 1.0) {
        bail!("--dt-fraction must lie in (0, 1), got {}", args.dt_fraction);
    }
    if args.periods == 0 {
        bail!("--periods must be at least 1");
    }
    let run_periods = config.run().periods;
    let from = args.from_period.unwrap_or_else(|| {
        config
            .run()
            .transient()
            .min(run_periods.saturating_sub(args.periods))
    });
    if from.checked_add(args.periods).is_none_or(|end| end > run_periods) {
        bail!(
            "--from-period {from} with --periods {} ends past the run, which has {run_periods} periods",
            args.periods
        );
    }
    let points = PwlGaps::estimated_points(args.periods as f64, args.dt_fraction);
    limits::check_memory(
        "the netlist's PWL waveforms (--periods / --dt-fraction)",
        PwlGaps::estimated_bytes(points, chain.len() - 1),
        args.allow_large,
    )?;
    let period = chain.period();
    let (t0, t1) = (from as f64 * period, (from + args.periods) as f64 * period);

    // Re-create the run's exact trajectory (the simulation is deterministic).
    let spec = RunSpec {
        periods: from + args.periods,
        ..config.run_spec(true)
    };
    let (trajectory, _) = record_trajectory(&spec, from, &mut ())?;
    let pwl = PwlGaps::from_trajectory(&trajectory, args.dt_fraction * period, t1)?;
    let options = SpiceOptions::default();
    let data_file = "vibrotribo-out.txt";
    let deck = spice::netlist(harvester, &pwl, t1, &options, data_file)?;
    let path = args.run_dir.join(&args.name);
    std::fs::write(&path, &deck).with_context(|| format!("cannot write {}", path.display()))?;
    println!(
        "wrote {} ({} PWL points, periods {from}..{} of the run, t = {t0:.6}…{t1:.6} s shifted to start at 0)",
        path.display(),
        pwl.times().len(),
        from + args.periods
    );
    println!(
        "  run it with `ngspice -b {}` in {}; it writes {data_file} (time, charge in nC, energy in nJ, voltage)",
        args.name,
        args.run_dir.display()
    );
    if args.check {
        let ours = {
            let mut s = ChargeSolver::for_chain(harvester, chain, config.charge_options().clone())?;
            s.run_pwl(&pwl)?;
            s.total_energy()
        };
        let run = spice::run_ngspice(harvester, &pwl, t1, &options)?;
        let theirs = run.energy_j.last().copied().unwrap_or(f64::NAN);
        println!(
            "  delivered energy: vibrotribo {}, ngspice {} (relative difference {:.2e}; ngspice took {:.2} s)",
            si(ours, "J"),
            si(theirs, "J"),
            (ours - theirs) / theirs,
            run.elapsed.as_secs_f64()
        );
    }
    Ok(())
}
