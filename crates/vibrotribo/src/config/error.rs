//! Errors of reading a configuration.

use thiserror::Error;

use crate::error::ParamError;

/// A configuration could not be read, or holds a bad value. Every variant names the key or
/// the file at fault.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The file could not be read.
    #[error("cannot read configuration {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// What the operating system said.
        message: String,
    },
    /// The text is not valid TOML.
    #[error("{origin} is not valid TOML: {message}")]
    Syntax {
        /// The file (or "the configuration").
        origin: String,
        /// The parser's message, with the line.
        message: String,
    },
    /// A key is not part of the configuration.
    #[error("unknown parameter `{key}`{}; known keys: {known}", super::keys::did_you_mean(.key))]
    UnknownKey {
        /// The key as given.
        key: String,
        /// The keys that exist.
        known: String,
    },
    /// A key has a value of the wrong type (or a table has an unknown field, with the
    /// deserializer's message).
    #[error("{origin}: {message}")]
    Type {
        /// The file, or the key that was set.
        origin: String,
        /// What is wrong.
        message: String,
    },
    /// A value is out of range, named by its key (`oscillator.masses[1]`).
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A `key=value` override or a key is malformed.
    #[error("{0}")]
    Malformed(String),
    /// A valid configuration the engine or a tool cannot run, the reason named (rigid stops
    /// moving with the base under a non-harmonic base motion, a signal shorter than the run,
    /// a stroboscopic tool under a base motion that is not periodic).
    #[error("{0}")]
    Unsupported(String),
    /// Setting a key made another key bad (a derived key such as `mass_ratio` sets
    /// `oscillator.masses`; new masses may not fit the given gaps).
    #[error("{key}: {error}")]
    Setting {
        /// The key that was set, with its value.
        key: String,
        /// The error, in terms of the key at fault.
        error: Box<ConfigError>,
    },
}
