//! What a run records: the `[run]` table, and the fully resolved description of one run.

use crate::electrical::{ChargeOptions, HarvesterParams};
use crate::error::{ParamError, check};
use crate::model::{ChainParams, ChainState, SimOptions};

/// The `[run]` table of a configuration: how long to simulate, what to exclude as transient,
/// how finely to sample, and where to start.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct RunSettings {
    /// Excitation periods simulated in all, transient included (`run.periods`). Default 100.
    pub periods: u64,
    /// Leading periods excluded from statistics and averages (`run.transient_periods`).
    /// `None` (default): 50, or `periods − 1` if that is less.
    pub transient_periods: Option<u64>,
    /// Samples per excitation period of the recorded trajectory (`run.samples_per_period`).
    /// Default 200.
    pub samples_per_period: u64,
    /// Initial positions x_i, m (`run.initial_positions`). `None` (default): all 0.
    pub initial_positions: Option<Vec<f64>>,
    /// Initial velocities, m/s (`run.initial_velocities`). `None` (default): all 0.
    pub initial_velocities: Option<Vec<f64>>,
    /// Whether `initial_positions` and `initial_velocities` are relative to the base's
    /// displacement y(0) and velocity y'(0) (`run.start_relative_to_base`; default false:
    /// absolute, the paper's start at rest while the base moves). With true and no initial
    /// state given, the chain starts at rest relative to the base, so that a record or a
    /// random signal that does not start at y = 0, y' = 0 gives the masses no kick.
    pub start_relative_to_base: bool,
}

impl Default for RunSettings {
    fn default() -> Self {
        RunSettings {
            periods: 100,
            transient_periods: None,
            samples_per_period: 200,
            initial_positions: None,
            initial_velocities: None,
            start_relative_to_base: false,
        }
    }
}

impl RunSettings {
    /// The transient: as given, or 50 (at most `periods − 1`).
    pub fn transient(&self) -> u64 {
        self.transient_periods
            .unwrap_or(50.min(self.periods.saturating_sub(1)))
    }

    /// Checks the settings, naming the field at fault (`periods`, `transient_periods`, …).
    pub fn validate(&self) -> Result<(), ParamError> {
        check(
            "periods",
            self.periods as f64,
            self.periods >= 1,
            "must be at least 1",
        )?;
        let transient = self.transient();
        if transient >= self.periods {
            return Err(ParamError::Conflict {
                name: "transient_periods".into(),
                message: format!("{transient} must be less than periods ({})", self.periods),
            });
        }
        check(
            "samples_per_period",
            self.samples_per_period as f64,
            self.samples_per_period >= 1,
            "must be at least 1",
        )
    }

    /// The initial state on `chain` (rest where not given), validated.
    pub fn initial_state(&self, chain: &ChainParams) -> Result<ChainState, ParamError> {
        crate::dynamics::initial_state(
            chain,
            self.initial_positions.as_deref(),
            self.initial_velocities.as_deref(),
        )
    }
}

/// A harvester mounted on the chain, and how its charge is solved.
#[derive(Debug, Clone, PartialEq)]
pub struct Harvester {
    /// Transducer and load.
    pub params: HarvesterParams,
    /// Charge solver settings.
    pub options: ChargeOptions,
    /// Period from which on the charge is solved (0: from the start). A sweep point starts it
    /// a few periods before its recorded window, from the electrostatic equilibrium.
    pub start_period: u64,
    /// What a failure of the charge solver does to the run.
    pub on_failure: ElectricalFailure,
}

impl Harvester {
    /// `params` solved with `options` from the start, a failure ending the run.
    pub fn new(params: HarvesterParams, options: ChargeOptions) -> Self {
        Harvester {
            params,
            options,
            start_period: 0,
            on_failure: ElectricalFailure::default(),
        }
    }
}

/// What a failure of the charge solver does to a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ElectricalFailure {
    /// The run ends there ([`Ending::Failed`](super::Ending::Failed)).
    #[default]
    StopRun,
    /// The mechanics goes on; the electrical results are missing (a sweep point reports its
    /// motion and the solver's error).
    KeepMechanics,
}

/// Where the trajectory is sampled for [`RunObserver::sample`](super::RunObserver::sample).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sampling {
    /// `t_j = T·(j/per_period)`, j = 0, 1, …: `per_period` samples per excitation period,
    /// landing exactly on the period boundaries.
    PerPeriod(u64),
    /// `t_j = start + step·j`, s.
    Uniform {
        /// First sample, s.
        start: f64,
        /// Spacing, s.
        step: f64,
    },
}

/// Everything that determines one run of [`simulate`](super::simulate).
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// The chain.
    pub chain: ChainParams,
    /// State at t = 0.
    pub initial: ChainState,
    /// Numerical settings of the mechanics.
    pub options: SimOptions,
    /// The harvester, if the charge is to be solved.
    pub harvester: Option<Harvester>,
    /// Excitation periods in all.
    pub periods: u64,
    /// Leading periods excluded from statistics and averages.
    pub transient_periods: u64,
    /// Samples for observers that ask for them (`None`: no sampling).
    pub sampling: Option<Sampling>,
    /// Check the air gaps for breakdown from the end of the transient on (needs a harvester).
    pub breakdown_check: bool,
    /// The base motion when it is not the chain's own `A sin ωt` (`None`: the chain's
    /// harmonic), run by the engine ([`Simulator::driven`](crate::Simulator::driven)).
    pub base_motion: Option<std::sync::Arc<crate::excitation::BaseMotion>>,
}

impl RunSpec {
    /// A run of `chain` from rest for `periods` periods, mechanics only, nothing sampled.
    pub fn new(chain: ChainParams, periods: u64) -> Self {
        let n = chain.len();
        RunSpec {
            chain,
            initial: ChainState::at_rest(n),
            options: SimOptions::default(),
            harvester: None,
            periods,
            transient_periods: 0,
            sampling: None,
            breakdown_check: false,
            base_motion: None,
        }
    }
}
