//! Frequency response with bandwidth: the average power a harvester delivers against the
//! frequency of its base motion, with the peak and the half-power band.
//!
//! ## Under a sine
//!
//! [`frequency_response`] sweeps a key (usually `excitation.omega_ratio`) over increasing
//! values twice: up, the values in order, and down, in reverse, each value started from the
//! final state of the one before (a sweep point, [`run_point`](crate::study::run_point),
//! settled and recorded as `sweep --continuation up|down` runs it). A nonlinear harvester
//! has coexisting motions over a range of frequency; the up sweep stays on a branch until it
//! ends and jumps, the down sweep likewise from the other side, so the two powers differ
//! over the hysteresis loop. With [`ResponseOptions::branches`] the periodic motions the
//! sweeps found are followed by continuation across the range ([`BranchSeeding`]), through
//! folds and onto the unstable parts, so that every branch the sweeps touched is traced
//! whole, with the power on each point.
//!
//! ## Under random input
//!
//! [`band_response`] moves the band of a band-limited random base motion across
//! frequencies at a fixed width and RMS acceleration and averages the power over several
//! seeds, with its standard error ([`BandPlan`]).
//!
//! ## Bandwidth
//!
//! The peak and the half-power band come from
//! [`half_power_bandwidth`](crate::analysis::half_power_bandwidth): the envelope of the
//! samples (at each value the largest power of any sweep or stable branch point there), its
//! largest sample, and the interval around it where the envelope stays at or above half of
//! it, the edges interpolated linearly between samples. Each sweep and each branch also has
//! its own. The band is in the unit of the swept key (Ω for `excitation.omega_ratio`), Hz
//! for a random-band response.

mod band;
mod branches;
mod error;
mod summary;
mod sweeps;
mod table;

pub use band::{
    BandOptions, BandPlan, BandPoint, BandResponse, DEFAULT_BAND_SEEDS, F_HIGH_KEY, F_LOW_KEY, SEED_KEY,
    band_response,
};
pub use branches::{
    BranchFailure, BranchSeed, BranchSeeding, DEFAULT_BRANCH_POINTS, DEFAULT_MATCH_TOLERANCE,
    DEFAULT_MAX_SEEDS, ResponseBranch, ResponseBranchPoint,
};
pub use error::ResponseError;
pub use summary::{
    BandSummary, BandwidthRecord, BifurcationRecord, BranchFailureRecord, BranchRecord, ResponseSummary,
    SeedingRecord, SweepRecord,
};
pub use sweeps::{
    FrequencyResponse, ResponseHook, ResponseOptions, ResponseStep, ResponseSweep, frequency_response,
};
pub use table::{Rows, band_seed_table, band_table, branch_table, response_table};
