//! The manifests of the grid jobs, `sweep.json` and `map.json`, and the records they share
//! with the other jobs (shards, settling).

use serde::{Deserialize, Serialize};
use serde_json::Value;
use vibrotribo::config::Config;
use vibrotribo::report::{BaseMotionSummary, SettleRecord};
use vibrotribo::sweep::Continuation;

use super::Kind;

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

/// The base motion of `config` when it is not the chain's own harmonic (kind, how it was run,
/// spline accuracy, record scaling).
pub fn base_motion_of(config: &Config) -> Option<BaseMotionSummary> {
    BaseMotionSummary::of(&config.run_spec(true))
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
    /// Transient periods per value.
    #[serde(default)]
    pub transient_periods: u64,
    /// Recorded periods per value.
    #[serde(default)]
    pub recorded_periods: u64,
    /// Relative tolerance of the period detection.
    #[serde(default)]
    pub period_tolerance: f64,
    /// Longest period detected, in excitation periods.
    #[serde(default)]
    pub max_period_detected: usize,
    /// Grazing threshold of the closing speed, relative.
    #[serde(default)]
    pub grazing_ratio: f64,
    /// Periods the charge solver warms up over before its recorded window.
    #[serde(default)]
    pub electrical_warmup_periods: u64,
    /// Mechanics only (no harvester).
    #[serde(default)]
    pub mechanics_only: bool,
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
    /// Transient periods per point.
    #[serde(default)]
    pub transient_periods: u64,
    /// Recorded periods per point.
    #[serde(default)]
    pub recorded_periods: u64,
    /// Relative tolerance of the period detection.
    #[serde(default)]
    pub period_tolerance: f64,
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
