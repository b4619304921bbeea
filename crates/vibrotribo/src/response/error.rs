//! Why a frequency response could not be set up.

use thiserror::Error;

use crate::config::ConfigError;

/// A frequency response (or a random-band response) that is not well posed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum ResponseError {
    /// No value to run.
    #[error("the response needs at least one value of the parameter (--steps, values=)")]
    NoValues,
    /// A value that is not finite, or values out of increasing order.
    #[error(
        "the values must be finite and strictly increasing (value {index} is {value}); the up sweep runs them in their order, the down sweep in reverse"
    )]
    BadValues {
        /// Index of the first value at fault.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A value of the parameter makes a bad configuration, or the configuration refuses the
    /// study (a base motion that is not periodic for the sweeps, two-way coupling for the
    /// branches): the error names the key.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// An option out of range (`name` is its field: `width_hz`, `seeds`, `max_seeds`,
    /// `match_tolerance`).
    #[error("{name} = {value}: {reason}")]
    Option {
        /// The option.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// The random-band response needs a configuration whose base motion is band-limited
    /// noise with a flat spectrum.
    #[error(
        "the random-band response moves the band of a flat-spectrum random base motion: give a configuration with excitation.kind = \"random\" and excitation.rms_acceleration, f_low_hz, f_high_hz (this one has {found})"
    )]
    NotFlatNoise {
        /// What the configuration has instead.
        found: String,
    },
    /// A band centre too low for the band's width: its lower edge would not be positive.
    #[error(
        "the band centred on {centre_hz} Hz, {width_hz} Hz wide, starts at {} Hz: every centre must exceed half the width",
        centre_hz - 0.5 * width_hz
    )]
    BandBelowZero {
        /// The centre, Hz.
        centre_hz: f64,
        /// The band's width, Hz.
        width_hz: f64,
    },
}
