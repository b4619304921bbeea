//! The manifests of the grid jobs, `sweep.json` and `map.json`, and the records they share
//! with the other jobs (shards, settling).

use super::{Kind, PointRecord, RunnerRecord, base_motion_of, settings_of, version};
use crate::report::{BaseMotionSummary, SettleRecord};
use crate::sweep::{Continuation, PointRunner};
use serde::{Deserialize, Serialize};
use serde_json::Value;

fn is_false(b: &bool) -> bool {
    !*b
}

/// A shard of a grid job (`--shard I/N`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardRecord {
    /// This slice, 0 ≤ index < count.
    pub index: usize,
    /// Number of slices.
    pub count: usize,
}

/// `sweep.json`: everything that determines a sweep's output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepManifest {
    /// Always [`Kind::Sweep`].
    pub command: Kind,
    /// The swept key and its values (`param`, `from`, `to`, `steps`, `values`).
    #[serde(flatten)]
    pub axis: Axis,
    /// How the values start.
    #[serde(default)]
    pub continuation: Continuation,
    /// The point runner's periods, tolerances and `mechanics_only`.
    #[serde(flatten)]
    pub runner: RunnerRecord,
    /// The shard, if the job is one.
    #[serde(default)]
    pub shard: Option<ShardRecord>,
    /// The configuration (the library's document).
    #[serde(default)]
    pub settings: Value,
    /// The program's version.
    #[serde(default)]
    pub vibrotribo_version: String,
    /// Whether `summary.csv` has the Floquet column.
    #[serde(default, skip_serializing_if = "is_false")]
    pub floquet: bool,
    /// How each value settled.
    #[serde(flatten)]
    pub settle: SettleRecord,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
    /// Whether `summary.csv` has the Lyapunov columns.
    #[serde(default, skip_serializing_if = "is_false")]
    pub lyapunov: bool,
}

/// One axis of a map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    /// The key along this axis.
    pub param: String,
    /// First value.
    #[serde(default)]
    pub from: f64,
    /// Last value.
    #[serde(default)]
    pub to: f64,
    /// Number of values.
    #[serde(default)]
    pub steps: usize,
    /// The values, in grid order.
    pub values: Vec<f64>,
}

/// `map.json`: everything that determines a map's output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapManifest {
    /// Always [`Kind::Map`].
    pub command: Kind,
    /// The x axis.
    pub x: Axis,
    /// The y axis.
    pub y: Axis,
    /// The periods of each point and the period detection's tolerance.
    #[serde(flatten)]
    pub point: PointRecord,
    /// Mechanics only (no harvester).
    #[serde(default)]
    pub mechanics_only: bool,
    /// The shard, if the job is one.
    #[serde(default)]
    pub shard: Option<ShardRecord>,
    /// The configuration (the library's document).
    #[serde(default)]
    pub settings: Value,
    /// Whether `map.csv` has the Floquet column.
    #[serde(default, skip_serializing_if = "is_false")]
    pub floquet: bool,
    /// How each point settled.
    #[serde(flatten)]
    pub settle: SettleRecord,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
}

impl SweepManifest {
    /// The manifest of a sweep of `axis` by `runner`, its values started as `continuation`
    /// says, with Lyapunov columns if `lyapunov`; not a shard.
    pub fn new(
        axis: Axis,
        continuation: Continuation,
        runner: &PointRunner,
        lyapunov: bool,
    ) -> Result<Self, serde_json::Error> {
        let o = runner.options();
        Ok(SweepManifest {
            command: Kind::Sweep,
            axis,
            continuation,
            runner: RunnerRecord::of(runner),
            shard: None,
            settings: settings_of(runner.base())?,
            vibrotribo_version: version(),
            floquet: o.floquet,
            settle: SettleRecord::of(o),
            base_motion: base_motion_of(runner.base()),
            lyapunov,
        })
    }
}

impl MapManifest {
    /// The manifest of a map of the axes `x` and `y` by `runner`; not a shard.
    pub fn new(x: Axis, y: Axis, runner: &PointRunner) -> Result<Self, serde_json::Error> {
        let o = runner.options();
        Ok(MapManifest {
            command: Kind::Map,
            x,
            y,
            point: PointRecord::of(o),
            mechanics_only: runner.mechanics_only(),
            shard: None,
            settings: settings_of(runner.base())?,
            floquet: o.floquet,
            settle: SettleRecord::of(o),
            base_motion: base_motion_of(runner.base()),
        })
    }
}

impl Axis {
    /// The axis of `param` from `from` to `to` over `values`, its steps their number.
    pub fn new(param: impl Into<String>, (from, to): (f64, f64), values: Vec<f64>) -> Self {
        Axis {
            param: param.into(),
            from,
            to,
            steps: values.len(),
            values,
        }
    }

    /// The axis of `param` over `values`, its range their first and last (`0` when there are
    /// none) and its steps their number.
    pub fn of_values(param: &str, values: &[f64]) -> Self {
        Axis {
            param: param.to_string(),
            from: values.first().copied().unwrap_or(0.0),
            to: values.last().copied().unwrap_or(0.0),
            steps: values.len(),
            values: values.to_vec(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A manifest as `sweep` wrote it with `json!` (the keys in their order), read and
    /// written back through the type, gives the same text.
    #[test]
    fn sweep_manifest_round_trips_byte_for_byte() {
        let text = r#"{"command":"sweep","param":"omega_ratio","from":0.5,"to":1.0,"steps":2,"values":[0.5,1.0],"continuation":"none","transient_periods":200,"recorded_periods":50,"period_tolerance":0.0001,"max_period_detected":32,"grazing_ratio":0.001,"electrical_warmup_periods":20,"mechanics_only":true,"shard":null,"settings":{"oscillator":{"gaps":[0.02,0.02]}},"vibrotribo_version":"0.1.0","settle":"auto","settle_cap_periods":2000,"settle_block_periods":50,"settle_newton":true}"#;
        let m: SweepManifest = serde_json::from_str(text).expect("a sweep manifest");
        assert_eq!(serde_json::to_string(&m).expect("serialises"), text);
        let fixed = text.replace(
            r#""settle":"auto","settle_cap_periods":2000,"settle_block_periods":50,"settle_newton":true"#,
            r#""floquet":true,"settle":"fixed","base_motion":{"kind":"chirp"},"lyapunov":true"#,
        );
        let m: SweepManifest = serde_json::from_str(&fixed).expect("a sweep manifest");
        assert!(m.floquet && m.lyapunov && m.settle.settle_cap_periods.is_none());
        assert_eq!(m.runner.detection.max_period_detected, 32);
        assert_eq!(serde_json::to_string(&m).expect("serialises"), fixed);
    }

    #[test]
    fn map_manifest_round_trips_byte_for_byte() {
        let text = r#"{"command":"map","x":{"param":"omega_ratio","from":0.5,"to":1.0,"steps":2,"values":[0.5,1.0]},"y":{"param":"mass_ratio","from":1.0,"to":3.0,"steps":2,"values":[1.0,3.0]},"transient_periods":200,"recorded_periods":50,"period_tolerance":0.0001,"mechanics_only":false,"shard":{"index":1,"count":4},"settings":{},"settle":"fixed"}"#;
        let m: MapManifest = serde_json::from_str(text).expect("a map manifest");
        assert_eq!(m.shard, Some(ShardRecord { index: 1, count: 4 }));
        assert_eq!(serde_json::to_string(&m).expect("serialises"), text);
    }
}
