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
}
