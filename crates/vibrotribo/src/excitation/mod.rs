//! Base motion beyond one sine: the signal side. The engine runs these motions exactly
//! ([`Simulator::driven`](crate::Simulator::driven)).
//!
//! The chain's base moves as y(t) (m); mass i feels it through its spring and damper, the
//! force k_i y + c_i y'. Today's engine drives it with `y = A sin ωt`
//! ([`Excitation`](crate::Excitation)). This module describes and builds the other kinds of
//! base motion, each as something the exact engine can integrate in closed form:
//!
//! - a sum of [`Harmonic`]s (`multisine`): a particular solution per harmonic;
//! - a [`PiecewiseCubic`] displacement, C² (displacement, velocity and acceleration
//!   continuous): on each interval the forcing is a cubic polynomial in time (`chirp`,
//!   `random`, `record`).
//!
//! Files: `spline.rs` (the piecewise cubic, interpolating splines, the Hall–Meyer error
//! bounds), `harmonics.rs` (harmonics, multisines, sampling a smooth signal into a spline),
//! `pieces.rs` (sums of harmonics as degree-7 Chebyshev interpolants, far fewer intervals
//! than a spline: what the engine runs multisines and random signals on),
//! `budget.rs` (the cost of a build, its limit and its stop flag), `chirp.rs`, `random.rs` (random-phase multisine from a PSD), `record.rs` (CSV records,
//! exact integration with baseline correction), `error.rs`.
//!
//! [`ExcitationSpec`] is what the `[excitation]` table of a configuration says (see
//! [`Config::excitation`](crate::config::Config::excitation)); [`ExcitationSpec::build`]
//! makes it a [`BaseMotion`]. Times are those of the run: t = 0 is its start (for a record,
//! its first sample).

mod budget;
mod chirp;
mod error;
mod harmonics;
mod pieces;
mod random;
mod record;
mod spline;

use std::sync::Arc;

pub use budget::{MAX_PIECE_EVALUATIONS, WorkBudget, build_cost};
pub use chirp::{Chirp, Sweep};
pub use error::{BaseMotionError, SignalError};
pub use harmonics::{
    Harmonic, MAX_KNOTS, SplineAccuracy, evaluate_sum, fourth_derivative_bound, harmonics_to_spline,
};
pub use pieces::{HarmonicPieces, PIECE_DEGREE, PieceAccuracy, PieceCoefficients, piece_accuracy};
pub use random::{MAX_COMPONENTS, Psd, RandomSpec};
pub use record::{
    BaselineCorrection, MIN_SAMPLES, Quantity, RecordReport, RecordSamples, RecordScaling, parse_record,
    read_record, record_displacement, record_reads,
};
pub use spline::{EndCondition, PiecewiseCubic, knot_spacing, spline_error_bounds};

/// The kind of base motion (`excitation.kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ExcitationKind {
    /// `y = A sin ωt` (the default; the engine's own).
    #[default]
    Harmonic,
    /// A sum of harmonics.
    Multisine,
    /// A frequency sweep.
    Chirp,
    /// Band-limited random acceleration from a PSD.
    Random,
    /// A recorded displacement or acceleration.
    Record,
}

impl ExcitationKind {
    /// The name used in configurations (`"harmonic"`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            ExcitationKind::Harmonic => "harmonic",
            ExcitationKind::Multisine => "multisine",
            ExcitationKind::Chirp => "chirp",
            ExcitationKind::Random => "random",
            ExcitationKind::Record => "record",
        }
    }
}

/// A record to drive the base with: its samples (shared: configurations are cloned often),
/// what they are and how they are scaled.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordSpec {
    /// The samples as read.
    pub samples: Arc<RecordSamples>,
    /// Displacement or acceleration.
    pub quantity: Quantity,
    /// The scaling applied to the values.
    pub scaling: RecordScaling,
}

/// The base motion a configuration describes, in SI units (frequencies already resolved
/// against the reference frequency).
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ExcitationSpec {
    /// The chain's own [`Excitation`](crate::Excitation), `y = A sin ωt`.
    #[default]
    Harmonic,
    /// `y = Σ A_j sin(ω_j t + φ_j)`.
    Multisine(Vec<Harmonic>),
    /// A chirp, sampled into a spline.
    Chirp {
        /// The sweep.
        chirp: Chirp,
        /// Bound on the spline's displacement error, m.
        tolerance: f64,
    },
    /// Random acceleration, sampled into a spline.
    Random {
        /// The density, seed and duration.
        spec: RandomSpec,
        /// Bound on the spline's displacement error relative to the RMS displacement.
        relative_tolerance: f64,
    },
    /// A record.
    Record(RecordSpec),
}

impl ExcitationSpec {
    /// Its kind.
    pub fn kind(&self) -> ExcitationKind {
        match self {
            ExcitationSpec::Harmonic => ExcitationKind::Harmonic,
            ExcitationSpec::Multisine(_) => ExcitationKind::Multisine,
            ExcitationSpec::Chirp { .. } => ExcitationKind::Chirp,
            ExcitationSpec::Random { .. } => ExcitationKind::Random,
            ExcitationSpec::Record(_) => ExcitationKind::Record,
        }
    }

    /// How long the motion is defined, s (`None`: for all time).
    pub fn duration(&self) -> Option<f64> {
        match self {
            ExcitationSpec::Harmonic | ExcitationSpec::Multisine(_) => None,
            ExcitationSpec::Chirp { chirp, .. } => Some(chirp.duration),
            ExcitationSpec::Random { spec, .. } => Some(spec.duration),
            ExcitationSpec::Record(r) => Some(r.samples.duration()),
        }
    }

    /// The base motion. `harmonic` is the chain's excitation (amplitude m, ω rad/s), used by
    /// the harmonic kind only. Chirps, random signals and records can be expensive (up to
    /// [`MAX_KNOTS`] knots): build once per run. A random signal's build is refused above
    /// [`MAX_PIECE_EVALUATIONS`] (see [`build_within`](Self::build_within)).
    pub fn build(&self, harmonic: Harmonic) -> Result<BaseMotion, SignalError> {
        self.build_within(harmonic, &WorkBudget::default())
    }

    /// [`build`](Self::build) within `budget`: a random signal costlier than
    /// [`MAX_PIECE_EVALUATIONS`] is refused unless it allows large builds, and its build (and
    /// a chirp's spline) stops when its stop flag is set ([`SignalError::Stopped`]).
    pub fn build_within(&self, harmonic: Harmonic, budget: &WorkBudget) -> Result<BaseMotion, SignalError> {
        Ok(match self {
            ExcitationSpec::Harmonic => BaseMotion::Harmonics(vec![harmonic]),
            ExcitationSpec::Multisine(h) => BaseMotion::Harmonics(h.clone()),
            ExcitationSpec::Chirp { chirp, tolerance } => {
                let (displacement, accuracy) = chirp.to_spline_within(*tolerance, budget)?;
                BaseMotion::Spline(SplineMotion {
                    displacement,
                    accuracy: Some(accuracy),
                    record: None,
                })
            }
            ExcitationSpec::Random {
                spec,
                relative_tolerance,
            } => {
                let (pieces, harmonics) = spec.to_pieces(*relative_tolerance, budget)?;
                BaseMotion::Pieces(PiecesMotion {
                    pieces: Arc::new(pieces),
                    harmonics,
                })
            }
            ExcitationSpec::Record(r) => {
                let (displacement, report) = record_displacement(&r.samples, r.quantity, r.scaling)?;
                BaseMotion::Spline(SplineMotion {
                    displacement,
                    accuracy: None,
                    record: Some(report),
                })
            }
        })
    }
}

/// A base displacement given as a C² piecewise cubic, with what is known of its accuracy.
#[derive(Debug, Clone, PartialEq)]
pub struct SplineMotion {
    /// The displacement, m (defined on `[0, displacement.end()]`).
    pub displacement: PiecewiseCubic,
    /// For a signal sampled from a formula (a chirp): the spline's error bounds against it.
    pub accuracy: Option<SplineAccuracy>,
    /// For a record: its scaling and baseline correction.
    pub record: Option<RecordReport>,
}

/// A sum of harmonics over a finite duration (a random signal) as the piecewise polynomials
/// the engine is driven by.
#[derive(Debug, Clone, PartialEq)]
pub struct PiecesMotion {
    /// The displacement and velocity pieces, on `[0, pieces.end()]` (shared: runs and
    /// configurations are cloned often).
    pub pieces: Arc<HarmonicPieces>,
    /// The exact displacement they interpolate, as harmonics.
    pub harmonics: Vec<Harmonic>,
}

/// The lines stating what piecewise polynomials achieve: `piece_degree`, `piece_intervals`,
/// `piece_displacement_error_bound_m`, `piece_velocity_error_bound_m_s`.
pub fn pieces_summary(a: &PieceAccuracy) -> Vec<(String, String)> {
    vec![
        ("piece_degree".into(), PIECE_DEGREE.to_string()),
        ("piece_intervals".into(), a.intervals.to_string()),
        (
            "piece_displacement_error_bound_m".into(),
            format!("{:e}", a.displacement_bound),
        ),
        (
            "piece_velocity_error_bound_m_s".into(),
            format!("{:e}", a.velocity_bound),
        ),
    ]
}

/// A base motion the exact engine can integrate in closed form.
#[derive(Debug, Clone, PartialEq)]
pub enum BaseMotion {
    /// A sum of harmonics, for all t.
    Harmonics(Vec<Harmonic>),
    /// A C² piecewise cubic displacement, on `[0, end]` (chirps, records).
    Spline(SplineMotion),
    /// A sum of harmonics on `[0, end]` as piecewise polynomials (random signals).
    Pieces(PiecesMotion),
}

impl BaseMotion {
    /// The kind of motion as a configuration names it: `multisine` for a sum of harmonics
    /// (the harmonic kind when it is the chain's own sine), `chirp` or `record` for a spline
    /// (a record carries its report), `random` for pieces.
    pub fn kind(&self) -> ExcitationKind {
        match self {
            BaseMotion::Harmonics(_) => ExcitationKind::Multisine,
            BaseMotion::Spline(s) if s.record.is_some() => ExcitationKind::Record,
            BaseMotion::Spline(_) => ExcitationKind::Chirp,
            BaseMotion::Pieces(_) => ExcitationKind::Random,
        }
    }

    /// Displacement (m), velocity (m/s) and acceleration (m/s²) of the base at `t` (s).
    pub fn evaluate(&self, t: f64) -> [f64; 3] {
        match self {
            BaseMotion::Harmonics(h) => evaluate_sum(h, t),
            BaseMotion::Spline(s) => s.displacement.evaluate(t),
            // The exact sum; the pieces are within their stated bounds of it.
            BaseMotion::Pieces(p) => evaluate_sum(&p.harmonics, t),
        }
    }

    /// Where the motion ends, s (`None`: never).
    pub fn end(&self) -> Option<f64> {
        match self {
            BaseMotion::Harmonics(_) => None,
            BaseMotion::Spline(s) => Some(s.displacement.end()),
            BaseMotion::Pieces(p) => Some(p.pieces.end()),
        }
    }

    /// What a run's output should state about the base motion, as (name, value) lines:
    /// knots and error bounds of a sampled signal, scaling and baseline correction of a
    /// record.
    pub fn summary(&self) -> Vec<(String, String)> {
        let mut out = Vec::new();
        match self {
            BaseMotion::Harmonics(h) => out.push(("harmonics".into(), h.len().to_string())),
            BaseMotion::Pieces(p) => {
                out.push(("harmonics".into(), p.harmonics.len().to_string()));
                out.push(("duration_s".into(), format!("{:e}", p.pieces.end())));
                out.extend(pieces_summary(&p.pieces.accuracy()));
            }
            BaseMotion::Spline(s) => {
                out.push(("spline_intervals".into(), s.displacement.intervals().to_string()));
                out.push(("duration_s".into(), format!("{:e}", s.displacement.end())));
                if let Some(a) = &s.accuracy {
                    out.push(("knot_spacing_s".into(), format!("{:e}", a.knot_spacing)));
                    out.push(("spline_error_bound_m".into(), format!("{:e}", a.error_bounds[0])));
                    out.push((
                        "spline_velocity_error_bound_m_s".into(),
                        format!("{:e}", a.error_bounds[1]),
                    ));
                }
                if let Some(r) = &s.record {
                    out.push(("record_scale_factor".into(), format!("{:e}", r.scale_factor)));
                    out.push((
                        "record_peak_acceleration_m_s2".into(),
                        format!("{:e}", r.peak_acceleration),
                    ));
                    if let Some(b) = &r.baseline {
                        out.push((
                            "baseline_acceleration_offset_m_s2".into(),
                            format!("{:e}", b.acceleration_offset),
                        ));
                        out.push((
                            "baseline_acceleration_slope_m_s3".into(),
                            format!("{:e}", b.acceleration_slope),
                        ));
                        out.push(("baseline_relative_size".into(), format!("{:e}", b.relative_size)));
                        out.push((
                            "baseline_removed_displacement_m".into(),
                            format!("{:e}", b.removed_displacement),
                        ));
                    }
                }
            }
        }
        out
    }
}
