//! The summary of a response, one serde type that the command line writes into its manifest
//! and Python returns as a dict: the peak and half-power band overall, of each sweep and of
//! each branch, and what the branches are.

use super::band::BandResponse;
use super::branches::BranchSeeding;
use super::sweeps::FrequencyResponse;
use crate::analysis::{AnalysisError, Bandwidth};
use crate::study::Direction;

/// The peak and the half-power band of a response, in the unit of the swept key.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BandwidthRecord {
    /// Where the power peaks.
    pub peak_at: f64,
    /// The peak power, W.
    pub peak_power_w: f64,
    /// Lower edge of the half-power band (`None`: the power is still above half the peak
    /// at the lowest value).
    pub lower: Option<f64>,
    /// Upper edge (`None`: above half the peak at the highest value).
    pub upper: Option<f64>,
    /// `upper − lower` (`None` where an edge is).
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
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SweepRecord {
    /// Values computed.
    pub done: usize,
    /// Values whose run failed (their error is in the response's table).
    pub failed: usize,
    /// The sweep's own peak and band.
    pub bandwidth: Option<BandwidthRecord>,
}

/// A bifurcation located on a branch (a fold is where a sweep riding it jumps off).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BifurcationRecord {
    /// [`BifurcationKind::name`](crate::orbits::BifurcationKind::name): `fold`,
    /// `period_doubling`, `neimark_sacker`, `grazing`, …
    pub kind: String,
    /// The value of the parameter.
    pub at: f64,
}

/// One branch of a response (its points are the rows of the branch table with its
/// `branch`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BranchRecord {
    /// Its index, the `branch` column of the branch table.
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
    /// The bifurcations located along it, in order.
    pub bifurcations: Vec<BifurcationRecord>,
    /// Why it ended ([`BranchEnd::name`](crate::orbits::BranchEnd::name): `range_end`,
    /// `grazing`, `step_floor`, `max_points`, `closed`, `stopped`, …).
    pub end: String,
    /// Where it ended (`None` for `max_points`).
    pub end_at: Option<f64>,
    /// The peak and band of its stable points.
    pub bandwidth: Option<BandwidthRecord>,
}

/// A continuation of a response that failed.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BranchFailureRecord {
    /// The sweep (`up`, `down`) of the seed.
    pub seed_sweep: String,
    /// The seed's value.
    pub seed_at: f64,
    /// The end it was continued towards.
    pub towards: f64,
    /// Why, with its causes.
    pub error: String,
}

/// How the branches were seeded.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SeedingRecord {
    /// Most seeds continued.
    pub max_seeds: usize,
    /// Relative power difference under which a sweep value is on a branch followed.
    pub match_tolerance: f64,
    /// Periodic sweep values on no branch that were not continued (the seed limit).
    pub seeds_skipped: usize,
    /// Continuations that failed.
    pub failures: Vec<BranchFailureRecord>,
}

/// The summary of a [`FrequencyResponse`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ResponseSummary {
    /// The peak and band of the envelope of both sweeps and the stable branch points.
    pub bandwidth: Option<BandwidthRecord>,
    /// The up sweep.
    pub up: SweepRecord,
    /// The down sweep.
    pub down: SweepRecord,
    /// How the branches were seeded (`None` without branches).
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Option::is_none"))]
    pub seeding: Option<SeedingRecord>,
    /// The branches followed.
    #[cfg_attr(feature = "serde", serde(default, skip_serializing_if = "Vec::is_empty"))]
    pub branches: Vec<BranchRecord>,
    /// Whether everything asked for was computed.
    pub complete: bool,
}

/// An error with its causes, `outer: inner: …`.
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut source = e.source();
    while let Some(s) = source {
        text.push_str(": ");
        text.push_str(&s.to_string());
        source = s.source();
    }
    text
}

impl FrequencyResponse {
    /// Its summary; `seeding` is how its branches were asked for (`None`: not asked).
    pub fn summary(&self, seeding: Option<&BranchSeeding>) -> ResponseSummary {
        let sweep = |d: Direction| SweepRecord {
            done: self.sweep(d).done(),
            failed: self.sweep(d).failed(),
            bandwidth: BandwidthRecord::of(self.sweep_bandwidth(d)),
        };
        let branches = self
            .branches
            .iter()
            .enumerate()
            .map(|(i, b)| BranchRecord {
                branch: i,
                seed_sweep: b.seed.direction.as_str().to_string(),
                seed_at: b.seed.value,
                towards: b.towards,
                period: b.period,
                points: b.points.len(),
                stable_points: b.points.iter().filter(|p| p.stable).count(),
                bifurcations: b
                    .bifurcations
                    .iter()
                    .map(|f| BifurcationRecord {
                        kind: f.kind.name().to_string(),
                        at: f.parameter,
                    })
                    .collect(),
                end: b.end.name().to_string(),
                end_at: b.end.parameter(),
                bandwidth: BandwidthRecord::of(b.bandwidth()),
            })
            .collect();
        ResponseSummary {
            bandwidth: BandwidthRecord::of(self.bandwidth()),
            up: sweep(Direction::Up),
            down: sweep(Direction::Down),
            seeding: seeding.map(|s| SeedingRecord {
                max_seeds: s.max_seeds,
                match_tolerance: s.match_tolerance,
                seeds_skipped: self.seeds_skipped,
                failures: self
                    .branch_failures
                    .iter()
                    .map(|f| BranchFailureRecord {
                        seed_sweep: f.seed.direction.as_str().to_string(),
                        seed_at: f.seed.value,
                        towards: f.towards,
                        error: chain(&f.error),
                    })
                    .collect(),
            }),
            branches,
            complete: self.complete,
        }
    }
}

/// The summary of a [`BandResponse`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct BandSummary {
    /// The centres, Hz, increasing.
    pub centres_hz: Vec<f64>,
    /// Width of the band, Hz.
    pub width_hz: f64,
    /// RMS base acceleration, m/s² (the configuration's).
    pub rms_acceleration: f64,
    /// The seeds run at every centre.
    pub seeds: Vec<u64>,
    /// The peak and band of the mean power against the centre frequency, Hz.
    pub bandwidth: Option<BandwidthRecord>,
    /// Runs that failed (their error is in the seed table).
    pub failed: usize,
    /// Whether every run ran.
    pub complete: bool,
}

impl BandResponse {
    /// Its summary.
    pub fn summary(&self) -> BandSummary {
        BandSummary {
            centres_hz: self.plan.centres_hz.clone(),
            width_hz: self.plan.width_hz,
            rms_acceleration: self.plan.rms_acceleration,
            seeds: self.plan.seeds.clone(),
            bandwidth: BandwidthRecord::of(self.bandwidth()),
            failed: self.results.iter().filter(|r| r.is_err()).count(),
            complete: self.complete,
        }
    }
}
