//! Attractors and their basins: which motion a start ends on, how likely each motion is
//! from an unknown start, and how the coexisting motions change with a parameter.
//!
//! # Fingerprints
//!
//! A start is run like a sweep point (transient, then recorded periods;
//! [`run_point`](crate::study::run_point)) and condensed into a [`Fingerprint`] of its
//! stroboscopic set, the states `z(nT) = [x₁ … x_N, v₁ … v_N]` of the recorded periods, in
//! scaled units (positions over `L = Σδ + A`, velocities over `L·ω`; [`SectionScale`]):
//!
//! - **periodic** when positions *and* velocities repeat with some period p ≤ `max_period`
//!   within [`AttractorOptions::period_tolerance`] ([`detect_period`](crate::analysis::detect_period)
//!   on the full state); the fingerprint keeps the p section points;
//! - **non-periodic** otherwise (chaotic, quasi-periodic, a period beyond `max_period`, or
//!   still settling); the fingerprint keeps the cells of edge [`AttractorOptions::cell`] its
//!   section cloud occupies, and the cloud's mean.
//!
//! Each start also carries its impacts per period and its average power.
//!
//! # Classification
//!
//! [`classify`] groups starts in a fixed order: periodic sets of the same period match when
//! their Hausdorff distance is within [`AttractorOptions::match_tolerance`]; non-periodic
//! clouds match when they share a cell, and a cloud that links several groups merges them
//! (the recurrence grid of Attractors.jl's `AttractorsViaRecurrences`, here on the
//! stroboscopic section of the exact flow). A periodic set never matches a cloud. The
//! grouping is a function of the fingerprints and their order only: computed in parallel,
//! or in shards merged later, it is the same. Each [`Attractor`] gets its basin fraction
//! (with the binomial standard error `√(f(1 − f)/K)`), its mean impacts per period and its
//! mean power (with the standard error of that mean: a non-periodic attractor's power over a
//! finite window is a random sample), and the **expected power** of an unknown start is the
//! mean over all starts, i.e. the fraction-weighted attractor powers
//! ([`Classification::expected_power`]).
//!
//! A start that has not settled within its transient is non-periodic here: give the runs a
//! transient long against the slowest decay `2m_i/c_i` of the chain.
//!
//! # Across a parameter
//!
//! [`attractors_across`] runs K random starts ([`random_start`], from a seed, the same at
//! every value and for every thread count) at each value, classifies them, and gives the
//! attractors global identities with an [`AttractorTracker`]: an attractor continues the
//! known one whose set lies nearest within [`AttractorOptions::continuation_distance`]
//! (Attractors.jl's matching by set distance).

mod basins;
mod classify;
mod fingerprint;
#[cfg(feature = "config")]
mod runs;
mod starts;
#[cfg(feature = "config")]
mod table;
mod track;

pub use basins::{BasinKeyError, DEFAULT_START_PERIODS, basin_points, initial_condition_index};
pub use classify::{Attractor, Classification, classify};
pub use fingerprint::{AttractorOptions, Fingerprint, SectionScale};
#[cfg(feature = "config")]
pub use runs::{AcrossDelivery, RandomStarts, StartRunner, ValueAttractors, attractors_across};
pub use starts::{StartBox, random_start};
#[cfg(feature = "config")]
pub use table::{
    ATTRACTOR_COLUMNS, BASIN_COLUMNS, EXPECTED_POWER_COLUMNS, START_COLUMNS, attractor_cells,
    basin_attractor_columns, basin_attractor_rows, basin_rows, census_attractor_columns,
    census_attractor_rows, columns, expected_power_row, start_rows, state_columns, table_of,
};
pub use track::AttractorTracker;
