//! `response.json` and `band_response.json`, the manifests of `vibrotribo response` and
//! `vibrotribo band-response`: the settings and the library's summary of the response
//! ([`ResponseSummary`], [`BandSummary`]: the peak and half-power band overall, of each
//! sweep and of each branch, and what the branches are), flattened into it. Frequencies are
//! in the unit of the swept key (`param`), Hz for a band response.

use crate::report::BaseMotionSummary;
use crate::response::{BandSummary, ResponseSummary};
use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{Axis, Kind, PeriodsRecord, PointRecord, SettleRecord, base_motion_of, settings_of, version};
use crate::sweep::PointRunner;

/// `response.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResponseManifest {
    /// Always [`Kind::Response`].
    pub command: Kind,
    /// The swept key and its values, increasing (`param`, `from`, `to`, `steps`, `values`).
    #[serde(flatten)]
    pub axis: Axis,
    /// Transient and recorded periods per value and the period detection's tolerance.
    #[serde(flatten)]
    pub point: PointRecord,
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
    pub base_motion: Option<BaseMotionSummary>,
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
    /// Transient and recorded periods per run.
    #[serde(flatten)]
    pub periods: PeriodsRecord,
    /// The centres, the band, the seeds, the bandwidth and whether every run ran.
    #[serde(flatten)]
    pub summary: BandSummary,
    /// Wall time, s.
    pub wall_time_s: f64,
    /// The configuration (the library's document).
    pub settings: Value,
    /// The base motion (the configuration's band; each run moves it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
    /// The program's version.
    pub vibrotribo_version: String,
}

impl ResponseManifest {
    /// The manifest of the response `summary` over `axis` by `runner`, computed in
    /// `wall_time_s` seconds.
    pub fn new(
        runner: &PointRunner,
        axis: Axis,
        summary: ResponseSummary,
        wall_time_s: f64,
    ) -> Result<Self, serde_json::Error> {
        let o = runner.options();
        Ok(ResponseManifest {
            command: Kind::Response,
            axis,
            point: PointRecord::of(o),
            settle: SettleRecord::of(o),
            summary,
            wall_time_s,
            settings: settings_of(runner.base())?,
            base_motion: base_motion_of(runner.base()),
            vibrotribo_version: version(),
        })
    }
}

impl BandResponseManifest {
    /// The manifest of the band response `summary` over the centres from `from` to `to` Hz
    /// in `steps` by `runner`, computed in `wall_time_s` seconds.
    pub fn new(
        runner: &PointRunner,
        (from, to, steps): (f64, f64, usize),
        summary: BandSummary,
        wall_time_s: f64,
    ) -> Result<Self, serde_json::Error> {
        Ok(BandResponseManifest {
            command: Kind::BandResponse,
            from,
            to,
            steps,
            periods: PeriodsRecord::of(runner.options()),
            summary,
            wall_time_s,
            settings: settings_of(runner.base())?,
            base_motion: base_motion_of(runner.base()),
            vibrotribo_version: version(),
        })
    }
}
