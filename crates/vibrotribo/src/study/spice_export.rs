//! A run's harvester as an ngspice netlist ([`crate::electrical::spice`]), driven by the
//! run's own gap waveforms: the mechanics of the configuration re-run (the simulation is
//! deterministic) up to the exported window, its gaps sampled as piecewise-linear sources
//! (every impact a breakpoint), the window shifted to start at t = 0. What the command
//! line's `export-spice` writes and Python's `export_spice` returns.

use thiserror::Error;

use crate::config::Config;
use crate::coupling::Coupling;
use crate::electrical::spice::{self, SpiceError, SpiceOptions};
use crate::electrical::{ChargeSolver, ElectricalError, PwlGaps};
use crate::error::ParamError;
use crate::study::{RunSpec, StudyError, record_trajectory};

/// Default PWL sampling interval, as a fraction of the excitation period.
pub const DEFAULT_SPICE_DT_FRACTION: f64 = 1.0 / 2000.0;

/// Default number of excitation periods exported.
pub const DEFAULT_SPICE_PERIODS: u64 = 2;

/// The file the netlist's `wrdata` writes (time, charge in nC, energy in nJ, voltage).
pub const SPICE_DATA_FILE: &str = "vibrotribo-out.txt";

/// Why a netlist could not be exported.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SpiceExportError {
    /// An option is bad (`option`: `dt_fraction`, `periods`, `from_period`).
    #[error("{option}: {message}")]
    Option {
        /// The option at fault.
        option: &'static str,
        /// Why.
        message: String,
    },
    /// A run of one mass: the harvester sits between two masses, so there is nothing to
    /// export.
    #[error(
        "a run of one mass has no harvester (the harvester sits between two masses): there is nothing to export"
    )]
    OneMass,
    /// A two-way coupled run: its gaps depend on the charges, while the netlist is driven by
    /// the mechanics alone.
    #[error(
        "a two-way run (harvester.coupling = \"two_way\"): its gaps depend on the charges, and the netlist is driven by the mechanics alone; export a one-way run"
    )]
    TwoWay,
    /// Re-running the mechanics failed.
    #[error(transparent)]
    Study(#[from] StudyError),
    /// The waveforms or the harvester's parameters are refused.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The charge solver failed (the check).
    #[error("charge solver: {0}")]
    Electrical(#[from] ElectricalError),
    /// ngspice failed (the check).
    #[error(transparent)]
    Spice(#[from] SpiceError),
}

/// An exported netlist and the window it covers.
#[derive(Debug, Clone)]
pub struct SpiceExport {
    /// The ngspice deck.
    pub netlist: String,
    /// The gap waveforms it is driven by (times from 0).
    pub pwl: PwlGaps,
    /// First excitation period exported.
    pub from_period: u64,
    /// Periods exported.
    pub periods: u64,
    /// Start and end of the window in the run's time, s.
    pub window_s: (f64, f64),
    /// End of the netlist's transient analysis, s.
    pub t_end: f64,
}

/// The netlist of `config`'s harvester over `periods` excitation periods from `from_period`
/// (default: the first after the transient, or as late as the run allows), the gaps sampled
/// every `dt_fraction` of a period. Refused for a run of one mass and for a two-way run.
pub fn spice_export(
    config: &Config,
    from_period: Option<u64>,
    periods: u64,
    dt_fraction: f64,
) -> Result<SpiceExport, SpiceExportError> {
    let option = |option, message: String| SpiceExportError::Option { option, message };
    if !(dt_fraction > 0.0 && dt_fraction < 1.0) {
        return Err(option(
            "dt_fraction",
            format!("must lie in (0, 1), got {dt_fraction}"),
        ));
    }
    if periods == 0 {
        return Err(option("periods", "must be at least 1".into()));
    }
    if config.chain().len() < 2 {
        return Err(SpiceExportError::OneMass);
    }
    if config.harvester().coupling == Coupling::TwoWay {
        return Err(SpiceExportError::TwoWay);
    }
    // By default the first period after the transient, or as late as the run allows.
    let run_periods = config.run().periods;
    let from =
        from_period.unwrap_or_else(|| config.run().transient().min(run_periods.saturating_sub(periods)));
    let end = from
        .checked_add(periods)
        .filter(|&end| end <= run_periods)
        .ok_or_else(|| {
            option(
                "from_period",
                format!("{from} with {periods} periods ends past the run, which has {run_periods} periods"),
            )
        })?;
    let period = config.chain().period();
    let (t0, t1) = (from as f64 * period, end as f64 * period);
    let spec = RunSpec {
        periods: end,
        ..config.run_spec(true)
    };
    let (trajectory, _) = record_trajectory(&spec, from, &mut ())?;
    let pwl = PwlGaps::from_trajectory(&trajectory, dt_fraction * period, t1)?;
    let netlist = spice::netlist(
        config.harvester(),
        &pwl,
        t1,
        &SpiceOptions::default(),
        SPICE_DATA_FILE,
    )?;
    Ok(SpiceExport {
        netlist,
        pwl,
        from_period: from,
        periods,
        window_s: (t0, t1),
        t_end: t1,
    })
}

/// Bytes the gap waveforms of an export of `periods` periods sampled every `dt_fraction` of a
/// period would hold (an estimate, for the size limits), before they are built; `None` when
/// `dt_fraction` is outside (0, 1), which [`spice_export`] refuses by name.
pub fn spice_export_bytes(config: &Config, periods: u64, dt_fraction: f64) -> Option<f64> {
    (dt_fraction > 0.0 && dt_fraction < 1.0).then(|| {
        let points = PwlGaps::estimated_points(periods as f64, dt_fraction);
        PwlGaps::estimated_bytes(points, config.chain().len().saturating_sub(1).max(1))
    })
}

/// The energy delivered over an export's window by vibrotribo's charge solver and by
/// ngspice on its netlist, J (and the wall time of ngspice, s).
pub fn spice_check(config: &Config, export: &SpiceExport) -> Result<(f64, f64, f64), SpiceExportError> {
    let mut s = ChargeSolver::for_chain(
        config.harvester(),
        config.chain(),
        config.charge_options().clone(),
    )?;
    s.run_pwl(&export.pwl)?;
    let ours = s.total_energy();
    let run = spice::run_ngspice(
        config.harvester(),
        &export.pwl,
        export.t_end,
        &SpiceOptions::default(),
    )?;
    let theirs = run.energy_j.last().copied().unwrap_or(f64::NAN);
    Ok((ours, theirs, run.elapsed.as_secs_f64()))
}
