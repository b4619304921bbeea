//! The run layer: one entry point, [`simulate`], that takes a chain, an optional harvester,
//! numerical options and observers and returns typed results; and the studies built on it
//! (a sweep point, [`run_point`]; the power on a periodic orbit, [`power_on_orbit`]).
//!
//! Every front end (the command line, Python) runs through here: none wires the simulator,
//! the charge solver and the statistics together itself.

mod chirp;
mod floquet;
pub mod limits;
mod loads;
mod lyapunov;
mod mass_ratio;
mod motion;
mod observer;
mod orbit;
mod point;
mod record;
mod replay;
mod run_motion;
mod settings;
mod settle;
mod simulate;
#[cfg(feature = "spice")]
mod spice_export;

pub use chirp::{
    ChirpError, ChirpOptions, ChirpPlan, ChirpRun, ChirpStudy, Cycle, DEFAULT_JUMP_WINDOW,
    DEFAULT_SAMPLES_PER_CYCLE, Direction, Jump, MIN_CYCLES, check_options, chirp_inputs, chirp_study,
    largest_jump, plan_chirp, run_chirp, run_plan,
};
pub use floquet::FloquetError;
pub use loads::{LoadStudy, LoadStudyOptions, VqCycle, load_study, vq_cycle};
pub use lyapunov::{LyapunovRun, lyapunov_spectrum};
pub use mass_ratio::{
    MassRatioOptimum, PAPER_MASS_RATIO_FIT, mass_ratio_optima, paper_mass_ratio_fit, refine_maximum,
};
pub use motion::{
    LabelSource, LyapunovSkipped, MAX_CLASSIFY_WORK, Motion, MotionReport, Window, classify, classify_cost,
    exponent_sign,
};
pub use observer::{Checkpoint, ElectricalSample, Mechanics, RunObserver, Sample};
pub use orbit::{power_on_orbit, power_on_periodic_state};
pub use point::{
    DEFAULT_PERIOD_TOLERANCE, ImpactRecord, PointError, PointOptions, PointResult, run_point,
    run_point_driven,
};
pub use record::{EventColumns, Recording, SampleColumns};
pub use replay::{ReplayOptions, Replayed, record_trajectory, replay};
pub use run_motion::RunMotion;
pub use settings::{ElectricalFailure, Harvester, RunSettings, RunSpec, Sampling};
pub use settle::{
    AutoSettle, DEFAULT_SETTLE_CAP, SettleEnding, SettleMode, Settled, ShotOrbit, UnknownSettleMode, settle,
};
pub use simulate::{ElectricalOutcome, Ending, RunOutcome, StudyError, simulate};
#[cfg(feature = "spice")]
pub use spice_export::{
    DEFAULT_SPICE_DT_FRACTION, DEFAULT_SPICE_PERIODS, SPICE_DATA_FILE, SpiceExport, SpiceExportError,
    spice_check, spice_export, spice_export_bytes,
};
