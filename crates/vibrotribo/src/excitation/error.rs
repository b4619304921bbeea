//! Errors of building a base motion and of reading a record.

use thiserror::Error;

/// A base motion could not be built: a bad signal, or a record file that cannot be read.
/// Record errors name the file and, where there is one, the line.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SignalError {
    /// Bad knots, samples or parameters of a signal.
    #[error("{0}")]
    Invalid(String),
    /// The record file could not be read at all.
    #[error("cannot read record {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said.
        message: String,
    },
    /// The record file is malformed at a line.
    #[error("record {path}, line {line}: {message}")]
    Record {
        /// The file.
        path: String,
        /// 1-based line number (the header is line 1).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The record as a whole is unusable (too few samples, too short).
    #[error("record {path}: {message}")]
    RecordWhole {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The signal would need more knots or components than allowed.
    #[error("{0}")]
    TooLarge(String),
    /// Building the signal's pieces would cost more than
    /// [`MAX_PIECE_EVALUATIONS`](super::MAX_PIECE_EVALUATIONS) harmonic evaluations.
    #[error(
        "the signal has {harmonics} harmonics over {intervals} intervals: about {:.1e} harmonic evaluations to build, \
         more than the limit of {:.0e} (about half a minute); narrow the band (f_low_hz, f_high_hz), \
         shorten the duration or raise spline_tolerance, or allow large jobs (--allow-large, allow_large=True)",
        super::budget::build_cost(*harmonics, *intervals),
        super::MAX_PIECE_EVALUATIONS
    )]
    Costly {
        /// Harmonics of the signal.
        harmonics: usize,
        /// Intervals of its pieces.
        intervals: usize,
    },
    /// The build was stopped by its budget's stop flag.
    #[error("stopped while building the signal, after {done} of {intervals} intervals")]
    Stopped {
        /// Intervals built.
        done: usize,
        /// Intervals asked for.
        intervals: usize,
    },
}

/// Why a base motion cannot drive a run: the combination named and the reason.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum BaseMotionError {
    /// Rigid stops with `frame = "base"` move as the chain's harmonic `A sin ωt`; they
    /// cannot follow another base motion.
    #[error(
        "rigid stops with frame = \"base\" move as the harmonic A sin ωt: they cannot \
         follow a non-harmonic base motion (use frame = \"fixed\", or kind = \"harmonic\")"
    )]
    MovingStops {
        /// The kind of base motion (`"multisine"`, `"chirp"`, `"random"`, `"record"`).
        kind: &'static str,
    },
    /// The base motion is defined on `[0, end]` and the run goes beyond it.
    #[error("the base motion ends at t = {end} s, before the run's end at {run_end} s")]
    EndsEarly {
        /// The kind of base motion.
        kind: &'static str,
        /// Where the motion ends, s.
        end: f64,
        /// Where the run ends, s.
        run_end: f64,
    },
    /// The multisine could not be turned into the piecewise polynomials the engine runs on.
    #[error("multisine: {0}")]
    Multisine(SignalError),
    /// A study that needs a periodic base motion (Floquet multipliers, periodic orbits) was
    /// asked of one that is not periodic with the reference period T.
    #[error("{what} need a base motion periodic with the reference period T; this one ({kind}) is not")]
    NotPeriodic {
        /// What was asked.
        what: &'static str,
        /// The kind of base motion.
        kind: &'static str,
    },
}
