//! `response.json` and `band_response.json`, the manifests of `vibrotribo response` and
//! `vibrotribo band-response`: the settings and the library's summary of the response
//! ([`ResponseSummary`], [`BandSummary`]: the peak and half-power band overall, of each
//! sweep and of each branch, and what the branches are), flattened into it. Frequencies are
//! in the unit of the swept key (`param`), Hz for a band response.

use serde::{Deserialize, Serialize};
use serde_json::Value;
use vibrotribo::response::{BandSummary, ResponseSummary};

use super::{Kind, SettleRecord};

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
    /// The bandwidths, the sweeps, the branches and whether the response is complete.
    #[serde(flatten)]
    pub summary: ResponseSummary,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<vibrotribo::report::BaseMotionSummary>,
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
    /// Transient periods per run.
    pub transient_periods: u64,
    /// Recorded periods per run.
    pub recorded_periods: u64,
    /// The centres, the band, the seeds, the bandwidth and whether every run ran.
    #[serde(flatten)]
    pub summary: BandSummary,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion (the configuration's band; each run moves it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<vibrotribo::report::BaseMotionSummary>,
    /// The program's version.
    pub vibrotribo_version: String,
}
