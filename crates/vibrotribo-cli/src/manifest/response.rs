//! `response.json` and `band_response.json`, the manifests of `vibrotribo response` and
//! `vibrotribo band-response`: the settings, the peak and half-power band of the response
//! (overall, of each sweep, of each branch) and what the branches are. Frequencies are in the
//! unit of the swept key (`param`), Hz for a band response.

use serde::{Deserialize, Serialize};
use serde_json::Value;
use vibrotribo::analysis::{AnalysisError, Bandwidth};

use super::{Kind, SettleRecord};

/// The peak and the half-power band of a response (in the unit of the swept key).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BandwidthRecord {
    /// Where the power peaks.
    pub peak_at: f64,
    /// The peak power, W.
    pub peak_power_w: f64,
    /// Lower edge of the half-power band (`null`: the power is still above half the peak at
    /// the lowest value).
    pub lower: Option<f64>,
    /// Upper edge (`null`: above half the peak at the highest value).
    pub upper: Option<f64>,
    /// `upper − lower` (`null` where an edge is).
    pub width: Option<f64>,
}

impl BandwidthRecord {
    /// The record of a bandwidth (`None` where there was no power to take one of).
    pub fn of(b: Result<Bandwidth, AnalysisError>) -> Option<Self> {
        b.ok().map(|b| BandwidthRecord {
            peak_at: b.peak_frequency,
            peak_power_w: b.peak_power,
            lower: b.lower,
            upper: b.upper,
            width: b.width(),
        })
    }
}

/// One sweep of a response.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRecord {
    /// Values computed.
    pub done: usize,
    /// Values whose run failed (their error is in response.csv).
    pub failed: usize,
    /// The sweep's own peak and band.
    pub bandwidth: Option<BandwidthRecord>,
}

/// A fold located on a branch: where a sweep riding it jumps off.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BifurcationPoint {
    /// `fold`, `period_doubling`, `neimark_sacker`, `branch_point`, …
    pub kind: String,
    /// The value of the parameter.
    pub at: f64,
}

/// One branch of a response (its points are the rows of branches.csv with its `branch`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResponseBranchRecord {
    /// Its index, the `branch` column of branches.csv.
    pub branch: usize,
    /// The sweep (`up`, `down`) whose periodic value started it.
    pub seed_sweep: String,
    /// That value.
    pub seed_at: f64,
    /// The end of the range it was continued towards.
    pub towards: f64,
    /// Period of its orbits, excitation periods.
    pub period: u32,
    /// Points.
    pub points: usize,
    /// Stable points.
    pub stable_points: usize,
    /// The bifurcations located along it.
    pub bifurcations: Vec<BifurcationPoint>,
    /// Why it ended: `range_end`, `grazing` (one it cannot cross), `step_floor`,
    /// `max_points`, `closed`, `stopped`, …
    pub end: String,
    /// Where it ended (`null` for `max_points`).
    pub end_at: Option<f64>,
    /// The peak and band of its stable points.
    pub bandwidth: Option<BandwidthRecord>,
}

/// A continuation of a response that failed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BranchFailureRecord {
    /// The sweep (`up`, `down`) of the seed.
    pub seed_sweep: String,
    /// The seed's value.
    pub seed_at: f64,
    /// The end it was continued towards.
    pub towards: f64,
    /// Why.
    pub error: String,
}

/// How the branches were seeded (present with `--branches`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedingRecord {
    /// Most seeds continued (`--branch-seeds`).
    pub max_seeds: usize,
    /// Relative power difference under which a sweep value is on a branch followed.
    pub match_tolerance: f64,
    /// Periodic sweep values on no branch that were not continued (the seed limit).
    pub seeds_skipped: usize,
    /// Continuations that failed.
    pub failures: Vec<BranchFailureRecord>,
}

/// `response.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResponseManifest {
    /// Always [`Kind::Response`].
    pub command: Kind,
    /// The swept key.
    pub param: String,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values.
    pub steps: usize,
    /// The values, increasing.
    pub values: Vec<f64>,
    /// Transient periods per value.
    pub transient_periods: u64,
    /// Recorded periods per value.
    pub recorded_periods: u64,
    /// Relative tolerance of the period detection.
    pub period_tolerance: f64,
    /// How each value settled.
    #[serde(flatten)]
    pub settle: SettleRecord,
    /// The peak and band of the envelope of both sweeps and the stable branch points.
    pub bandwidth: Option<BandwidthRecord>,
    /// The up sweep.
    pub up: SweepRecord,
    /// The down sweep.
    pub down: SweepRecord,
    /// How the branches were seeded (with `--branches`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seeding: Option<SeedingRecord>,
    /// The branches followed (with `--branches`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub branches: Vec<ResponseBranchRecord>,
    /// Whether everything asked for was computed.
    pub complete: bool,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<Value>,
    /// The program's version.
    pub vibrotribo_version: String,
}

/// `band_response.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BandResponseManifest {
    /// Always [`Kind::BandResponse`].
    pub command: Kind,
    /// First centre frequency, Hz.
    pub from: f64,
    /// Last centre frequency, Hz.
    pub to: f64,
    /// Number of centres.
    pub steps: usize,
    /// The centres, Hz, increasing.
    pub centres_hz: Vec<f64>,
    /// Width of the band, Hz.
    pub width_hz: f64,
    /// RMS base acceleration, m/s² (the configuration's).
    pub rms_acceleration: f64,
    /// The seeds run at every centre.
    pub seeds: Vec<u64>,
    /// Transient periods per run.
    pub transient_periods: u64,
    /// Recorded periods per run.
    pub recorded_periods: u64,
    /// The peak and band of the mean power against the centre frequency, Hz.
    pub bandwidth: Option<BandwidthRecord>,
    /// Runs that failed (their error is in seeds.csv).
    pub failed: usize,
    /// Whether every run ran.
    pub complete: bool,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion (the configuration's band; each run moves it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<Value>,
    /// The program's version.
    pub vibrotribo_version: String,
}
