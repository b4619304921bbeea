//! `bifmap.json`: the manifest of a bifurcation map (`vibrotribo bifmap`), which `plot DIR`
//! reads to draw it.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use crate::report::BaseMotionSummary;

use super::{Axis, Kind, PointRecord, SettleRecord};

/// One start of a seed value, continued towards one end of the first key's range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedRecord {
    /// The second key's value.
    pub y: f64,
    /// The first key's value the orbit was sought at.
    pub x_start: f64,
    /// The end of the first key's range it was continued towards.
    pub x_end: f64,
    /// Branches followed (the first and the period-doubled ones).
    pub branches: usize,
    /// Points on them.
    pub points: usize,
    /// Why each branch ended, in words.
    pub ends: Vec<String>,
    /// The start's orbit lies on the branches of this earlier start (its index in `seeds`),
    /// which were not followed again.
    pub on_branch_of: Option<usize>,
    /// Why there is no branch (no periodic orbit found at the start), if so.
    pub error: Option<String>,
}

/// One curve of the map (its points are the rows of `curves.csv` with its id).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BifmapCurveRecord {
    /// Its id in `curves.csv` and `codim2.csv`.
    pub curve: usize,
    /// `fold`, `period_doubling`, `neimark_sacker` or `grazing`.
    pub kind: String,
    /// Period of its orbits, in excitation periods.
    pub period: u32,
    /// Grazing: the contact, 1-based.
    pub contact: Option<usize>,
    /// The seed value of the second key it was located at.
    pub seed_y: f64,
    /// The first key's value it was located at there.
    pub located_x: f64,
    /// Points on it.
    pub points: usize,
    /// Why its half towards `y.from` ended, in words (`null`: the seed is that end).
    pub end_towards_from: Option<String>,
    /// Why its half towards `y.to` ended, in words (`null`: the seed is that end).
    pub end_towards_to: Option<String>,
    /// Other located bifurcations that lie on it.
    pub found_again: usize,
}

/// The power map's settings and progress (its rows are `map.csv`, as `vibrotribo map` writes
/// it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PowerMapRecord {
    /// Transient and recorded periods per point and the period detection's tolerance.
    #[serde(flatten)]
    pub point: PointRecord,
    /// Whether `map.csv` has the Floquet column.
    pub floquet: bool,
    /// How each point settled.
    #[serde(flatten)]
    pub settle: SettleRecord,
    /// Points computed (all of them unless the map was stopped).
    pub done: usize,
    /// Points of the grid.
    pub points: usize,
}

/// `bifmap.json`: the settings of a bifurcation map and what it found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BifmapManifest {
    /// Always [`Kind::Bifmap`].
    pub command: Kind,
    /// Whether everything was computed (`false`: stopped by a signal; what was computed is
    /// written).
    pub complete: bool,
    /// The first key (canonical) and the power map's grid along it.
    pub x: Axis,
    /// The second key (canonical) and the power map's grid along it.
    pub y: Axis,
    /// The seed values of the second key.
    pub seed_values: Vec<f64>,
    /// The first key's values where each seed value's orbits were sought.
    pub x_starts: Vec<f64>,
    /// The curve kinds asked for.
    pub kinds: Vec<String>,
    /// Period of the seed branches' first orbits (`null`: detected).
    pub period: Option<u32>,
    /// Period doublings followed along the seed branches.
    pub doublings: u32,
    /// Transient periods before each seed branch's first orbit.
    pub orbit_transient_periods: u32,
    /// Most points per seed branch.
    pub branch_points: usize,
    /// Most points per half of a curve.
    pub curve_points: usize,
    /// Most curves traced.
    pub max_curves: usize,
    /// Mechanics only (no power in `map.csv`).
    pub mechanics_only: bool,
    /// The starts of the seed values and their branches.
    pub seeds: Vec<SeedRecord>,
    /// The curves.
    pub curves: Vec<BifmapCurveRecord>,
    /// Located bifurcations not followed (beyond `max_curves`).
    pub untraced: usize,
    /// Codimension-two points in all (rows of `codim2.csv`).
    pub codim2_points: usize,
    /// The power map.
    pub power_map: PowerMapRecord,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
    /// The program's version.
    pub vibrotribo_version: String,
}
