//! Analyses of simulated motion: Poincaré sections, periodicity, spectra, fits
//! (seed Sect. 4; MODEL-NOTES §3).

mod stats;

pub use stats::RunStats;
