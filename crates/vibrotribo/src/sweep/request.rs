//! [`PointRequest`]: what a front end (a command's options, a Python call's arguments) asks
//! of the points of a sweep or a map, checked and turned into [`PointOptions`] in one place.

use crate::config::{Config, ConfigError};
use crate::study::{AutoSettle, DEFAULT_PERIOD_TOLERANCE, PointOptions, SettleMode};

/// What is asked of the points of a sweep or a map.
#[derive(Debug, Clone, PartialEq)]
pub struct PointRequest {
    /// Periods before the recorded window (`None`: the front end's default, usually
    /// `run.transient_periods`).
    pub transient: Option<u64>,
    /// Periods recorded (`None`: the front end's default, usually the rest of `run.periods`).
    pub recorded: Option<u64>,
    /// Relative tolerance of the period detection, in (0, 1). Default
    /// [`DEFAULT_PERIOD_TOLERANCE`].
    pub period_tolerance: f64,
    /// Whether each point's periodic orbit is found by shooting and its largest Floquet
    /// multiplier reported. Default false.
    pub floquet: bool,
    /// How long a point runs before its recorded window. Default [`SettleMode::Auto`] with
    /// the default [`AutoSettle`] (at most
    /// [`DEFAULT_SETTLE_CAP`](crate::study::DEFAULT_SETTLE_CAP) periods).
    pub settle: SettleMode,
}

impl Default for PointRequest {
    fn default() -> Self {
        PointRequest {
            transient: None,
            recorded: None,
            period_tolerance: DEFAULT_PERIOD_TOLERANCE,
            floquet: false,
            settle: SettleMode::Auto(AutoSettle::default()),
        }
    }
}

/// A [`PointRequest`] that cannot be met.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PointRequestError {
    /// No period would be recorded.
    #[error("the recorded periods (--recorded, recorded=) must be at least 1")]
    NoRecordedPeriods,
    /// The period tolerance is not in (0, 1).
    #[error("the period tolerance (--period-tolerance, period_tolerance=) must lie in (0, 1), got {0}")]
    PeriodTolerance(f64),
    /// Automatic settling may run no period.
    #[error("the settle cap (--settle-cap, settle_cap=) must be at least 1 period")]
    SettleCap,
    /// The configuration does not allow what is asked (Floquet multipliers under a base
    /// motion that is not periodic).
    #[error(transparent)]
    Config(#[from] ConfigError),
}

impl PointRequest {
    /// The point options for sweeps and maps of `base`, with `(transient, recorded)` periods
    /// where the request does not give them. Under a base motion that is not periodic there
    /// is no periodic motion to settle to or classify: each point then runs exactly
    /// `transient + recorded` periods ([`SettleMode::Fixed`]) and is not classified.
    pub fn options(
        &self,
        base: &Config,
        (transient, recorded): (u64, u64),
    ) -> Result<PointOptions, PointRequestError> {
        let recorded = self.recorded.unwrap_or(recorded);
        if recorded == 0 {
            return Err(PointRequestError::NoRecordedPeriods);
        }
        if !(self.period_tolerance > 0.0 && self.period_tolerance < 1.0) {
            return Err(PointRequestError::PeriodTolerance(self.period_tolerance));
        }
        if matches!(self.settle, SettleMode::Auto(a) if a.cap_periods == 0) {
            return Err(PointRequestError::SettleCap);
        }
        if self.floquet {
            base.check_periodic("--floquet (Floquet multipliers)")?;
        }
        let periodic = base.is_periodic();
        Ok(PointOptions {
            transient_periods: self.transient.unwrap_or(transient),
            recorded_periods: recorded,
            period_tolerance: self.period_tolerance,
            floquet: self.floquet,
            settle: if periodic { self.settle } else { SettleMode::Fixed },
            classify: periodic,
            ..PointOptions::default()
        })
    }

    /// [`options`](Self::options) with the defaults of `base`'s `[run]` table:
    /// `run.transient_periods` before the window and the rest of `run.periods` recorded.
    pub fn options_of_run(&self, base: &Config) -> Result<PointOptions, PointRequestError> {
        let run = base.run();
        self.options(base, (run.transient(), run.periods - run.transient()))
    }
}
