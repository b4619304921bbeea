//! The run layer: one entry point, [`simulate`], that takes a chain, an optional harvester,
//! numerical options and observers and returns typed results; and the studies built on it
//! (a sweep point, [`run_point`]).
//!
//! Every front end (the command line, Python) runs through here: none wires the simulator,
//! the charge solver and the statistics together itself.

mod loads;
mod observer;
mod point;
mod record;
mod replay;
mod settings;
mod simulate;

pub use loads::{LoadStudy, LoadStudyOptions, VqCycle, load_study, vq_cycle};
pub use observer::{Checkpoint, ElectricalSample, Mechanics, RunObserver, Sample};
pub use point::{ImpactRecord, PointError, PointOptions, PointResult, run_point};
pub use record::{EventColumns, Recording, SampleColumns};
pub use replay::{ReplayOptions, Replayed, record_trajectory, replay};
pub use settings::{ElectricalFailure, Harvester, RunSettings, RunSpec, Sampling};
pub use simulate::{ElectricalOutcome, Ending, RunOutcome, StudyError, simulate};
