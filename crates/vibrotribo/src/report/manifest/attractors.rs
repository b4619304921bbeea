//! The manifests of the attractor studies: `basins.json` (`vibrotribo basins`, a grid of
//! starts) and `attractors.json` (`vibrotribo attractors`, random starts across a key), with
//! their constructors from the library's start runner.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{Axis, Kind, PeriodsRecord, ShardRecord, settings_of, version};
use crate::attractors::{RandomStarts, SectionScale, StartRunner};

/// The classification tolerances of `basins.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BasinTolerances {
    /// Relative tolerance of the period detection.
    pub period_tolerance: f64,
    /// Relative distance under which two attractors are one.
    pub match_tolerance: f64,
    /// Side of a fingerprint's cell, relative.
    pub cell: f64,
}

/// The scales that make a section point dimensionless.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SectionScaleRecord {
    /// Number of masses.
    pub masses: usize,
    /// Length scale, m.
    pub length_m: f64,
    /// Speed scale, m/s.
    pub speed_m_s: f64,
}

/// `basins.json`: everything that determines a basins job's output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BasinsManifest {
    /// Always [`Kind::Basins`].
    pub command: Kind,
    /// The x axis.
    pub x: Axis,
    /// The y axis.
    pub y: Axis,
    /// Transient and recorded periods per start.
    #[serde(flatten)]
    pub periods: PeriodsRecord,
    /// Longest period detected, in excitation periods.
    pub max_period_detected: usize,
    /// How attractors are told apart.
    pub attractor_options: BasinTolerances,
    /// The scales of the section.
    pub section_scale: SectionScaleRecord,
    /// Mechanics only (no harvester).
    pub mechanics_only: bool,
    /// The shard, if the job is one.
    pub shard: Option<ShardRecord>,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The program's version.
    pub vibrotribo_version: String,
    /// Whether the job finished (written by the job machinery; read only).
    #[serde(default, skip_serializing)]
    pub complete: bool,
}

/// The box random starts are drawn from, around the configured state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartBoxRecord {
    /// Half-width of the positions, m.
    pub positions_m: f64,
    /// Half-width of the velocities, m/s.
    pub velocities_m_s: f64,
}

/// The classification settings of `attractors.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AttractorTolerances {
    /// Relative tolerance of the period detection.
    pub period_tolerance: f64,
    /// Relative distance under which two attractors are one.
    pub match_tolerance: f64,
    /// Side of a fingerprint's cell, relative.
    pub cell: f64,
    /// Relative distance under which an attractor continues one of the previous value.
    pub continuation_distance: f64,
}

/// `attractors.json`: the settings of an attractors study and how far it got.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AttractorsManifest {
    /// Always [`Kind::Attractors`].
    pub command: Kind,
    /// The varied key and its values (`param`, `from`, `to`, `steps`, `values`).
    #[serde(flatten)]
    pub axis: Axis,
    /// Random starts per value.
    pub samples: usize,
    /// Seed of the starts.
    pub seed: u64,
    /// The box of the starts (`None`: the library's default).
    pub start_box: Option<StartBoxRecord>,
    /// Transient and recorded periods per start.
    #[serde(flatten)]
    pub periods: PeriodsRecord,
    /// How attractors are told apart and followed.
    pub attractor_options: AttractorTolerances,
    /// Mechanics only (no harvester).
    pub mechanics_only: bool,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The program's version.
    pub vibrotribo_version: String,
    /// Whether every value was run.
    pub complete: bool,
    /// Values run.
    pub done: usize,
}

impl BasinsManifest {
    /// The manifest of a grid of `starts` over the initial conditions `x` and `y`; not a
    /// shard, nothing done.
    pub fn new(starts: &StartRunner, x: Axis, y: Axis) -> Result<Self, serde_json::Error> {
        let runner = starts.point_runner();
        let o = runner.options();
        let options = starts.options();
        let scale = SectionScale::of(runner.base().chain());
        Ok(BasinsManifest {
            command: Kind::Basins,
            x,
            y,
            periods: PeriodsRecord::of(o),
            max_period_detected: o.period_options().max_period,
            attractor_options: BasinTolerances {
                period_tolerance: options.period_tolerance,
                match_tolerance: options.match_tolerance,
                cell: options.cell,
            },
            section_scale: SectionScaleRecord {
                masses: scale.masses,
                length_m: scale.length,
                speed_m_s: scale.speed,
            },
            mechanics_only: runner.mechanics_only(),
            shard: None,
            settings: settings_of(runner.base())?,
            vibrotribo_version: version(),
            complete: false,
        })
    }
}

impl AttractorsManifest {
    /// The manifest of a census of `starts` across `axis`, its starts drawn by `sampling`;
    /// nothing done.
    pub fn new(starts: &StartRunner, axis: Axis, sampling: &RandomStarts) -> Result<Self, serde_json::Error> {
        let runner = starts.point_runner();
        let options = starts.options();
        Ok(AttractorsManifest {
            command: Kind::Attractors,
            axis,
            samples: sampling.samples,
            seed: sampling.seed,
            start_box: sampling.bounds.map(|b| StartBoxRecord {
                positions_m: b.positions,
                velocities_m_s: b.velocities,
            }),
            periods: PeriodsRecord::of(runner.options()),
            attractor_options: AttractorTolerances {
                period_tolerance: options.period_tolerance,
                match_tolerance: options.match_tolerance,
                cell: options.cell,
                continuation_distance: options.continuation_distance,
            },
            mechanics_only: runner.mechanics_only(),
            settings: settings_of(runner.base())?,
            vibrotribo_version: version(),
            complete: false,
            done: 0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::round_trips;
    use super::*;

    #[test]
    fn basins_manifest_round_trips_byte_for_byte() {
        round_trips::<BasinsManifest>(
            r#"{"command":"basins","x":{"param":"run.initial_positions[0]","from":-0.01,"to":0.01,"steps":3,"values":[-0.01,0.0,0.01]},"y":{"param":"run.initial_velocities[0]","from":-0.1,"to":0.1,"steps":3,"values":[-0.1,0.0,0.1]},"transient_periods":20,"recorded_periods":10,"max_period_detected":5,"attractor_options":{"period_tolerance":0.001,"match_tolerance":0.003,"cell":0.05},"section_scale":{"masses":3,"length_m":0.12,"speed_m_s":4.2},"mechanics_only":false,"shard":null,"settings":{},"vibrotribo_version":"0.1.0"}"#,
        );
    }

    /// The job machinery's progress keys are read (`complete`) or ignored (`rows`).
    #[test]
    fn a_finished_basins_manifest_reads_as_complete() {
        let text = r#"{"command":"basins","x":{"param":"a","from":0.0,"to":1.0,"steps":2,"values":[0.0,1.0]},"y":{"param":"b","from":0.0,"to":1.0,"steps":2,"values":[0.0,1.0]},"transient_periods":20,"recorded_periods":10,"max_period_detected":5,"attractor_options":{"period_tolerance":0.001,"match_tolerance":0.003,"cell":0.05},"section_scale":{"masses":3,"length_m":0.12,"speed_m_s":4.2},"mechanics_only":false,"shard":null,"settings":{},"vibrotribo_version":"0.1.0","complete":true,"done":4,"rows":{"starts.csv":4}}"#;
        let m: BasinsManifest = serde_json::from_str(text).expect("a basins manifest");
        assert!(m.complete);
        let fresh = serde_json::to_string(&m).expect("serialises");
        assert!(fresh.ends_with(r#""vibrotribo_version":"0.1.0"}"#), "{fresh}");
    }

    #[test]
    fn attractors_manifest_round_trips_byte_for_byte() {
        round_trips::<AttractorsManifest>(
            r#"{"command":"attractors","param":"omega_ratio","from":0.7,"to":0.8,"steps":2,"values":[0.7],"samples":3,"seed":1,"start_box":null,"transient_periods":20,"recorded_periods":10,"attractor_options":{"period_tolerance":0.001,"match_tolerance":0.003,"cell":0.05,"continuation_distance":0.25},"mechanics_only":false,"settings":{},"vibrotribo_version":"0.1.0","complete":true,"done":2}"#,
        );
    }
}
