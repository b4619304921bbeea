//! The groups of keys that several manifests share, each built from the library's runner or
//! options so that the command line's manifests and Python's `settings` dicts hold the same
//! values: a point's periods ([`PeriodsRecord`]), with the period detection's tolerance
//! ([`PointRecord`]), what a sweep point detects ([`DetectionRecord`]), all of the point
//! runner's keys ([`RunnerRecord`]) and the configuration table ([`settings_of`]).

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::config::Config;
use crate::report::BaseMotionSummary;
use crate::study::PointOptions;
use crate::sweep::PointRunner;

/// The periods each point of a study runs.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PeriodsRecord {
    /// Transient periods per point, in excitation periods.
    #[serde(default)]
    pub transient_periods: u64,
    /// Recorded periods per point, in excitation periods.
    #[serde(default)]
    pub recorded_periods: u64,
}

impl PeriodsRecord {
    /// The periods of `options`.
    pub fn of(options: &PointOptions) -> Self {
        PeriodsRecord {
            transient_periods: options.transient_periods,
            recorded_periods: options.recorded_periods,
        }
    }
}

/// The periods of each point and the tolerance its period is detected with.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PointRecord {
    /// Transient and recorded periods.
    #[serde(flatten)]
    pub periods: PeriodsRecord,
    /// Relative tolerance of the period detection (dimensionless).
    #[serde(default)]
    pub period_tolerance: f64,
}

impl PointRecord {
    /// The periods and tolerance of `options`.
    pub fn of(options: &PointOptions) -> Self {
        PointRecord {
            periods: PeriodsRecord::of(options),
            period_tolerance: options.period_tolerance,
        }
    }
}

/// What a point's motion is classified by beyond its periods: the longest period looked
/// for, the grazing threshold and the charge solver's warm-up.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct DetectionRecord {
    /// Longest period detected, in excitation periods.
    #[serde(default)]
    pub max_period_detected: usize,
    /// Grazing threshold of the closing speed, relative to the largest one (dimensionless).
    #[serde(default)]
    pub grazing_ratio: f64,
    /// Periods the charge solver warms up over before its recorded window, in excitation
    /// periods.
    #[serde(default)]
    pub electrical_warmup_periods: u64,
}

impl DetectionRecord {
    /// The detection settings of `options`.
    pub fn of(options: &PointOptions) -> Self {
        DetectionRecord {
            max_period_detected: options.period_options().max_period,
            grazing_ratio: options.grazing_ratio,
            electrical_warmup_periods: options.electrical_warmup_periods,
        }
    }
}

/// The point runner's keys: its periods, tolerances and whether it leaves the harvester out.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RunnerRecord {
    /// Periods and the period detection's tolerance.
    #[serde(flatten)]
    pub point: PointRecord,
    /// Longest period, grazing threshold, charge solver warm-up.
    #[serde(flatten)]
    pub detection: DetectionRecord,
    /// Mechanics only (no harvester).
    #[serde(default)]
    pub mechanics_only: bool,
}

impl RunnerRecord {
    /// The keys of `runner`.
    pub fn of(runner: &PointRunner) -> Self {
        let o = runner.options();
        RunnerRecord {
            point: PointRecord::of(o),
            detection: DetectionRecord::of(o),
            mechanics_only: runner.mechanics_only(),
        }
    }
}

/// A manifest's `settings`: the configuration `config` as its table (the library's
/// document), in JSON.
pub fn settings_of(config: &Config) -> Result<Value, serde_json::Error> {
    serde_json::to_value(config.table())
}

/// The program's version, as the manifests record it (`vibrotribo_version`).
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// The base motion of `config` when it is not the chain's own harmonic (kind, how it was run,
/// spline accuracy, record scaling), as the manifests record it (`base_motion`).
pub fn base_motion_of(config: &Config) -> Option<BaseMotionSummary> {
    BaseMotionSummary::of(&config.run_spec(true))
}
