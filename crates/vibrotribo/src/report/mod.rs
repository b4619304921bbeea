//! What a run reports: the summary of one [`simulate`](crate::study::simulate) run
//! ([`RunSummary`]) as the command line writes it to `summary.json` and reads it back, and as
//! Python returns it as a dict, one type for both so that they hold the same keys and the same
//! numbers; with its parts that other results share: the motion of a run or a sweep point
//! ([`MotionRecord`]) and the base motion as the engine ran it ([`BaseMotionSummary`]); and the
//! manifests of the command line's output directories ([`manifest`]), from which Python's
//! results state their settings.

mod base_motion;
pub mod manifest;
mod motion;
mod settle;
mod summary;

pub use base_motion::{BaseMotionSummary, base_motion_lines};
pub use motion::{CoexistingRecord, MotionRecord, NewtonRecord};
pub use settle::SettleRecord;
pub use summary::{
    ElectricalSummary, MeritSummary, RectifierSummary, RunSummary, StoppedPhase, SummaryCommand, failure_text,
};
