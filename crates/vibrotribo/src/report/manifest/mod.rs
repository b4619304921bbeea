//! The manifests of the command line's output directories (`sweep.json`, `map.json`,
//! `basins.json`, …), each a serde type whose fields are in the order of the file's keys, and
//! the groups of keys they share ([`PeriodsRecord`], [`PointRecord`], [`RunnerRecord`],
//! [`SettleRecord`], [`settings_of`]). The command line writes and reads them; Python builds
//! the `settings` of its results from the same types, so that both state the same keys with
//! the same values.
//!
//! A command's manifest type lives in its own file here (grid jobs in `grid.rs`, the attractor
//! studies in `attractors.rs`, `chirp` in `chirp.rs`, `curve` in `curve.rs`, `bifmap` in `bifmap.rs`, `response` and
//! `band-response` in `response.rs`, the others in `commands.rs`); its kind is a [`Kind`] and
//! a line of the table in `kind.rs`.

mod attractors;
mod bifmap;
mod chirp;
mod commands;
mod curve;
mod grid;
mod kind;
mod records;
mod response;

pub use attractors::*;
pub use bifmap::*;
pub use chirp::*;
pub use commands::*;
pub use curve::{Codim2Record, CurveManifest};
pub use grid::{Axis, MapManifest, ShardRecord, SweepManifest};
pub use kind::Kind;
pub use records::{
    DetectionRecord, PeriodsRecord, PointRecord, RunnerRecord, base_motion_of, settings_of, version,
};
pub use response::*;

pub use super::SettleRecord;

/// `text` (a command's manifest as the program wrote it, with its `settings` emptied and its
/// long lists cut) read as `T` and written back gives the same text.
#[cfg(test)]
fn round_trips<T: serde::de::DeserializeOwned + serde::Serialize>(text: &str) -> T {
    let m: T = serde_json::from_str(text).unwrap_or_else(|e| panic!("{e}: {text}"));
    assert_eq!(serde_json::to_string(&m).expect("serialises"), text);
    m
}
