//! What a two-parameter continuation returns, and its settings.

use nalgebra::Complex;
use thiserror::Error;

use super::super::continuation::check_path;
use super::super::error::NewtonFailure;
use super::super::shooting::ShootingOptions;
use crate::error::{ParamError, check, check_positive};
use crate::model::ChainState;

/// The bifurcation condition a curve follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CurveKind {
    /// A real multiplier at +1 (saddle-node): `λ − 1 = 0`.
    Fold,
    /// A real multiplier at −1 (flip): `λ + 1 = 0`.
    PeriodDoubling,
    /// A complex pair on the unit circle: `|λ| − 1 = 0`.
    NeimarkSacker,
    /// The smallest smooth local minimum of the gap at one contact is zero: the orbit touches
    /// the contact with zero closing speed.
    Grazing,
}

impl CurveKind {
    /// Its name in files and on the command line: `fold`, `period_doubling`,
    /// `neimark_sacker` or `grazing`.
    pub fn name(&self) -> &'static str {
        match self {
            CurveKind::Fold => "fold",
            CurveKind::PeriodDoubling => "period_doubling",
            CurveKind::NeimarkSacker => "neimark_sacker",
            CurveKind::Grazing => "grazing",
        }
    }

    /// Every kind, in the order of the names above.
    pub const ALL: [CurveKind; 4] = [
        CurveKind::Fold,
        CurveKind::PeriodDoubling,
        CurveKind::NeimarkSacker,
        CurveKind::Grazing,
    ];
}

impl std::str::FromStr for CurveKind {
    type Err = CurveError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        CurveKind::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| CurveError::UnknownKind(s.to_string()))
    }
}

/// Settings of [`continue_curve`](super::continue_curve).
#[derive(Debug, Clone, PartialEq)]
pub struct CurveOptions {
    /// First arclength step, in scaled units (state in L and L·ω, each parameter in its unit:
    /// the second in |to − from|, the first in a tenth of its start value). Default 0.02.
    pub initial_step: f64,
    /// Smallest step: a curve that cannot be continued with it ends with
    /// [`CurveEnd::StepFloor`]. Default 1e-6.
    pub min_step: f64,
    /// Largest step. Default 0.05.
    pub max_step: f64,
    /// Most points on the curve ([`CurveEnd::MaxPoints`] beyond). Default 200.
    pub max_points: usize,
    /// Converged when the scaled orbit residual and the condition (a multiplier's distance
    /// from ±1 or the unit circle, or the gap minimum in L) are at most this. Default 1e-10.
    pub tolerance: f64,
    /// Newton iterations per corrector step. Default 10.
    pub corrector_iterations: usize,
    /// Step of the forward differences of the condition and of the map in the parameters,
    /// in scaled units. Default 1e-7.
    pub difference_step: f64,
    /// Codimension-two points and the curve's end are located to this accuracy in the
    /// scaled parameters. Default 1e-8.
    pub location_tolerance: f64,
    /// Settings of the simulations and sensitivities (and of the first orbit's shooting).
    pub shooting: ShootingOptions,
}

impl Default for CurveOptions {
    fn default() -> Self {
        CurveOptions {
            initial_step: 0.02,
            min_step: 1e-6,
            max_step: 0.05,
            max_points: 200,
            tolerance: 1e-10,
            corrector_iterations: 10,
            difference_step: 1e-7,
            location_tolerance: 1e-8,
            shooting: ShootingOptions::default(),
        }
    }
}

impl CurveOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_path(self.initial_step, self.min_step, self.max_step, self.max_points)?;
        check_positive("tolerance", self.tolerance)?;
        check(
            "corrector_iterations",
            self.corrector_iterations as f64,
            self.corrector_iterations > 0,
            "must be positive",
        )?;
        check_positive("difference_step", self.difference_step)?;
        check_positive("location_tolerance", self.location_tolerance)?;
        self.shooting.validate()
    }
}

/// One orbit on a bifurcation curve.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint {
    /// The first parameter.
    pub parameter: f64,
    /// The second parameter.
    pub parameter2: f64,
    /// Section state at t ≡ 0 (mod T): positions, m, and velocities, m/s.
    pub state: ChainState,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// The condition's value at the point (zero to the tolerance).
    pub condition: f64,
    /// Grazing curves: the smallest gap minimum at the grazing contact, m (zero to the
    /// tolerance times L).
    pub gap_minimum: Option<f64>,
    /// Impacts per excitation period at each contact.
    pub impacts_per_period: Vec<f64>,
    /// Arclength from the curve's start, scaled units.
    pub arclength: f64,
}

/// What happens at a codimension-two point of a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Codim2Kind {
    /// The orbit on the curve grazes a contact (an impact appears or disappears there): its
    /// event sequence changes, the curve of a smooth bifurcation meets a grazing curve and
    /// ends.
    Grazing {
        /// Contact, 0-based.
        contact: usize,
    },
    /// The event sequence changes otherwise (sticking, chatter, the order of impacts): the
    /// curve ends.
    SequenceChange,
    /// A second bifurcation condition holds on the curve: it meets the curve of that kind
    /// (a fold meeting a period doubling, a grazing orbit with a multiplier at −1, …).
    Meets {
        /// The other condition.
        kind: CurveKind,
    },
}

impl Codim2Kind {
    /// Its name in files: `grazing`, `sequence_change`, or `meets_KIND`.
    pub fn name(&self) -> String {
        match self {
            Codim2Kind::Grazing { .. } => "grazing".into(),
            Codim2Kind::SequenceChange => "sequence_change".into(),
            Codim2Kind::Meets { kind } => format!("meets_{}", kind.name()),
        }
    }
}

/// A codimension-two point located on a curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Codim2Point {
    /// What happens.
    pub kind: Codim2Kind,
    /// The orbit at the point (for a sequence change: the last one with the curve's
    /// sequence).
    pub point: CurvePoint,
    /// Width of the final bracket in the scaled parameters.
    pub precision: f64,
}

/// Why a curve ended.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum CurveEnd {
    /// The second parameter reached the end of its range (the last point sits on it).
    RangeEnd {
        /// The range end.
        parameter2: f64,
    },
    /// [`CurveOptions::max_points`] points were computed.
    MaxPoints,
    /// The corrector failed down to the smallest step.
    StepFloor {
        /// The first parameter at the last point.
        parameter: f64,
        /// The second parameter at the last point.
        parameter2: f64,
        /// Why the last attempt failed.
        reason: NewtonFailure,
    },
    /// The orbit's event sequence changes: the codimension-two point listed last.
    SequenceChange,
    /// The condition no longer applies: no real multiplier left near ±1, the complex pair
    /// of a Neimark–Sacker curve turned real (a strong resonance), or the gap lost its
    /// minimum.
    Degenerate {
        /// The first parameter at the last point.
        parameter: f64,
        /// The second parameter at the last point.
        parameter2: f64,
    },
}

/// A bifurcation curve in two parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    /// The condition followed.
    pub kind: CurveKind,
    /// Grazing curves: the contact, 0-based.
    pub contact: Option<usize>,
    /// Period of the orbits, in excitation periods.
    pub period: u32,
    /// The points in order along the curve.
    pub points: Vec<CurvePoint>,
    /// Codimension-two points in order along the curve.
    pub codim2: Vec<Codim2Point>,
    /// Why it ended.
    pub end: CurveEnd,
}

/// Why a curve could not be started.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CurveError {
    /// A kind name that is not one of the four.
    #[error("unknown bifurcation kind {0:?}: expected fold, period_doubling, neimark_sacker or grazing")]
    UnknownKind(String),
    /// An option is invalid.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// The start of the range is not where the start point is.
    #[error("the start point's second parameter {start} is not a finite number")]
    Start {
        /// The value.
        start: f64,
    },
    /// The defining system has no solution near the start point at the start of the range.
    #[error("no {} orbit of period {period} near the start point: {reason} (residuals [{}])", kind.name(), list(residuals))]
    NoStart {
        /// The condition.
        kind: CurveKind,
        /// Period of the orbit.
        period: u32,
        /// Why Newton's method stopped.
        reason: NewtonFailure,
        /// Residual history (the larger of the orbit's and the condition's).
        residuals: Vec<f64>,
    },
}

fn list(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| format!("{v:.2e}"))
        .collect::<Vec<_>>()
        .join(", ")
}
