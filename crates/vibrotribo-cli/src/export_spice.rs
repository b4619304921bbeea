//! `vibrotribo export-spice RUN_DIR`: an ngspice netlist of a run's harvester, driven by the
//! run's gap waveforms, for use in one's own circuit designs (and an optional check against
//! ngspice).

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use vibrotribo::config::Config;
use vibrotribo::study::{SPICE_DATA_FILE, SpiceExportError, spice_check, spice_export, spice_export_bytes};

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
    #[arg(long, default_value_t = vibrotribo::study::DEFAULT_SPICE_PERIODS)]
    pub periods: u64,
    /// PWL sampling interval as a fraction of the excitation period (every impact is also a
    /// breakpoint).
    #[arg(long, default_value_t = vibrotribo::study::DEFAULT_SPICE_DT_FRACTION)]
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
    // The PWL waveforms' size, checked before they are built.
    if let Some(bytes) = spice_export_bytes(&config, args.periods, args.dt_fraction) {
        limits::check_memory(
            "the netlist's PWL waveforms (--periods / --dt-fraction)",
            bytes,
            args.allow_large,
        )?;
    }
    let export =
        spice_export(&config, args.from_period, args.periods, args.dt_fraction).map_err(|e| match e {
            SpiceExportError::Option { option, message } => {
                anyhow::anyhow!("--{}: {message}", option.replace('_', "-"))
            }
            other @ (SpiceExportError::OneMass | SpiceExportError::TwoWay) => {
                anyhow::anyhow!("{}: {other}", args.run_dir.display())
            }
            other => other.into(),
        })?;
    let path = args.run_dir.join(&args.name);
    std::fs::write(&path, &export.netlist).with_context(|| format!("cannot write {}", path.display()))?;
    let (from, (t0, t1)) = (export.from_period, export.window_s);
    println!(
        "wrote {} ({} PWL points, periods {from}..{} of the run, t = {t0:.6}…{t1:.6} s shifted to start at 0)",
        path.display(),
        export.pwl.times().len(),
        from + export.periods
    );
    println!(
        "  run it with `ngspice -b {}` in {}; it writes {SPICE_DATA_FILE} (time, charge in nC, energy in nJ, voltage)",
        args.name,
        args.run_dir.display()
    );
    if args.check {
        let (ours, theirs, elapsed) = spice_check(&config, &export)?;
        println!(
            "  delivered energy: vibrotribo {}, ngspice {} (relative difference {:.2e}; ngspice took {:.2} s)",
            si(ours, "J"),
            si(theirs, "J"),
            (ours - theirs) / theirs,
            elapsed
        );
    }
    Ok(())
}
