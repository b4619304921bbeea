//! The options every grid job shares: shards, settling, the per-point run settings and the
//! shards `merge` combines.

use std::path::PathBuf;

use anyhow::Result;
use vibrotribo::config::Config;
use vibrotribo::study::{DEFAULT_PERIOD_TOLERANCE, DEFAULT_SETTLE_CAP, SettleMode};
use vibrotribo::sweep::{PointRequest, PointRunner};

/// `I/N`: the I-th (0-based) of N interleaved slices of the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This slice, 0 ≤ index < count.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("--shard takes I/N (e.g. 3/16), got {s:?}"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| format!("--shard: bad index {i:?}"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("--shard: bad count {n:?}"))?;
        if count == 0 || index >= count {
            return Err(format!(
                "--shard {s}: need 0 ≤ I < N (Slurm: --array=0-{})",
                count.max(1) - 1
            ));
        }
        Ok(Shard { index, count })
    }
}

/// Settings shared by sweeps and maps.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Transient periods per value (sweep, map: default the configuration's
    /// run.transient_periods; basins, attractors: default 500 per start).
    #[arg(long)]
    pub transient: Option<u64>,
    /// Recorded periods per value (sweep, map: default run.periods − run.transient_periods;
    /// basins, attractors: default 100 per start).
    #[arg(long)]
    pub recorded: Option<u64>,
    /// Mechanics only: no harvester, average_power_w left empty (faster).
    #[arg(long)]
    pub mechanics_only: bool,
    /// Relative tolerance of the period detection.
    #[arg(long, default_value_t = DEFAULT_PERIOD_TOLERANCE)]
    pub period_tolerance: f64,
    /// Also find the periodic orbit of each point's detected period by shooting and write
    /// its largest Floquet multiplier modulus (column `max_abs_multiplier`; < 1: stable).
    #[arg(long)]
    pub floquet: bool,
    /// How long each point runs before its recorded window: `auto` until the motion repeats
    /// within the period tolerance (checked every 50 periods; a geometric approach to a
    /// periodic orbit is finished by Newton shooting; a motion whose returns do not shrink
    /// stops after --transient periods), at most --settle-cap periods; `fixed` exactly
    /// --transient periods (the results of earlier versions).
    #[arg(long, default_value = "auto", value_name = "auto|fixed")]
    pub settle: SettleMode,
    /// Most periods `--settle auto` runs before the recorded window.
    #[arg(long, default_value_t = DEFAULT_SETTLE_CAP, value_name = "PERIODS")]
    pub settle_cap: u64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
    /// Run even if the estimated output exceeds 20 GiB or the memory 4 GiB, or if a random
    /// base motion's build exceeds 10⁹ harmonic evaluations.
    #[arg(long)]
    pub allow_large: bool,
    /// Write into an --out directory that holds another job's results (files of the same
    /// name are replaced).
    #[arg(long)]
    pub force: bool,
}

impl RunArgs {
    /// The point runner of these settings on `base` (transient and recorded periods by
    /// default from its `[run]` table).
    pub fn runner(&self, base: Config) -> Result<PointRunner> {
        let settings = base.run();
        let defaults = (settings.transient(), settings.periods - settings.transient());
        self.runner_or(base, defaults)
    }

    /// The point runner of these settings on `base`, with `(transient, recorded)` periods
    /// where the options do not give them (checked by the library's [`PointRequest`]).
    pub fn runner_or(&self, base: Config, defaults: (u64, u64)) -> Result<PointRunner> {
        let request = PointRequest {
            transient: self.transient,
            recorded: self.recorded,
            period_tolerance: self.period_tolerance,
            floquet: self.floquet,
            settle: self.settle.with_cap(self.settle_cap),
        };
        let options = request.options(&base, defaults)?;
        // A single mass (against a stop) has no gap between masses to harvest from: its
        // points are mechanics only, as `simulate` runs it.
        let mechanics_only = self.mechanics_only || base.chain().len() < 2;
        Ok(PointRunner::new(base, options, mechanics_only))
    }
}

/// Options of `vibrotribo merge`.
#[derive(Debug, clap::Args)]
pub struct MergeArgs {
    /// Output directories of the shards of one sweep or map (`--shard I/N`).
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// Where to write the merged files (a new or empty directory).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
}

/// Refuses a start's recorded window too short for its period test (`--recorded` below
/// (repeats + 1) × the largest period tested): every start would fail, none be classified.
pub fn check_recorded(options: &vibrotribo::study::PointOptions) -> anyhow::Result<()> {
    let popts = options.period_options();
    let needed = popts.samples_needed() as u64;
    if options.recorded_periods < needed {
        anyhow::bail!(
            "--recorded {}: a start's period test reads {needed} recorded periods ({} + 1 times \
             the largest period tested, {}); with fewer no start can be classified: give \
             --recorded {needed} or more",
            options.recorded_periods,
            popts.repeats,
            popts.max_period
        );
    }
    Ok(())
}
