//! Why an optimisation could not be set up or finished.

use thiserror::Error;

use crate::config::ConfigError;

/// An optimisation problem that is not well posed, or a search that failed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum OptimizeError {
    /// A `--vary` argument is not `KEY=LO..HI`.
    #[error("--vary {text:?}: expected KEY=LO..HI (e.g. harvester.load_resistance=1e9..1e12)")]
    VarySyntax {
        /// The argument.
        text: String,
    },
    /// A varied key is not a numeric key of the configuration.
    #[error("--vary {key}: {source}")]
    UnknownKey {
        /// The key.
        key: String,
        /// Why the configuration refused it.
        source: ConfigError,
    },
    /// A range that is empty, reversed or not finite.
    #[error("--vary {key}: the range {lo}..{hi} is empty or not finite (LO < HI, both finite)")]
    BadRange {
        /// The key.
        key: String,
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
    },
    /// The same key varied twice.
    #[error("--vary {key}: the key is varied twice")]
    DuplicateKey {
        /// The key.
        key: String,
    },
    /// No key is varied.
    #[error("nothing to optimise: give at least one --vary KEY=LO..HI")]
    NothingVaried,
    /// An unknown objective.
    #[error("--objective {name:?}: expected average_power, expected_power or power_per_mass")]
    UnknownObjective {
        /// The name given.
        name: String,
    },
    /// A `--constraint` argument that cannot be read.
    #[error(
        "--constraint {text:?}: expected breakdown_ratio<=X or max_displacement<=X (X in its unit: 1, m)"
    )]
    ConstraintSyntax {
        /// The argument.
        text: String,
    },
    /// A constraint no design can meet (a non-negative quantity bounded below zero).
    #[error("--constraint {text}: impossible ({quantity} is never below 0)")]
    ImpossibleConstraint {
        /// The constraint as given.
        text: String,
        /// The constrained quantity.
        quantity: &'static str,
    },
    /// An option out of its range.
    #[error("{name} = {value}: {reason}")]
    BadOption {
        /// The option.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        reason: &'static str,
    },
    /// The objective needs something the configuration does not have.
    #[error("--objective {objective}: {reason}")]
    Unsupported {
        /// The objective.
        objective: &'static str,
        /// Why.
        reason: &'static str,
    },
    /// No design of those evaluated met the constraints.
    #[error(
        "no design met the constraints ({constraints}) among {evaluations} evaluated; the least violated: {least}"
    )]
    Infeasible {
        /// The constraints, as given.
        constraints: String,
        /// Evaluations made.
        evaluations: u64,
        /// The least violating design's constraint values.
        least: String,
    },
    /// The search stopped: interrupted, or the optimiser failed.
    #[error("the search stopped: {reason}")]
    Stopped {
        /// Why (the optimiser's message, or the interruption).
        reason: String,
    },
}
