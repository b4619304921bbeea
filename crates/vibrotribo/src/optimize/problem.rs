//! What is optimised: the varied keys and their ranges, the objective, the constraints and
//! the search's settings, each read from its command-line text with an error naming it.

use std::fmt;
use std::str::FromStr;

use crate::config::{Config, Param};

use super::error::OptimizeError;

/// How a variable maps to the unit interval the search runs in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Scale {
    /// `value = LO + u (HI − LO)`.
    #[default]
    Linear,
    /// `value = LO (HI/LO)^u`: chosen where `HI/LO ≥ 100` with both bounds positive.
    Log,
}

/// One varied configuration key with its range.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    /// The key, as in `--set`.
    pub key: String,
    /// The key resolved against the configuration.
    pub param: Param,
    /// Lower bound, in the key's unit.
    pub lo: f64,
    /// Upper bound, in the key's unit.
    pub hi: f64,
    /// Linear or logarithmic.
    pub scale: Scale,
}

impl Variable {
    /// Reads `KEY=LO..HI` against `config`: the key must be a numeric key of it, the range
    /// finite with `LO < HI`; logarithmic where `HI/LO ≥ 100` and `LO > 0`.
    pub fn parse(config: &Config, text: &str) -> Result<Self, OptimizeError> {
        let syntax = || OptimizeError::VarySyntax { text: text.into() };
        let (key, range) = text.split_once('=').ok_or_else(syntax)?;
        let (lo, hi) = range.split_once("..").ok_or_else(syntax)?;
        let key = key.trim().to_string();
        let (lo, hi): (f64, f64) = (
            lo.trim().parse().map_err(|_| syntax())?,
            hi.trim().parse().map_err(|_| syntax())?,
        );
        if key.is_empty() {
            return Err(syntax());
        }
        if !(lo.is_finite() && hi.is_finite() && lo < hi) {
            return Err(OptimizeError::BadRange { key, lo, hi });
        }
        let param = Param::new(config, &key).map_err(|source| OptimizeError::UnknownKey {
            key: key.clone(),
            source,
        })?;
        // Both ends must make a valid configuration (a mass of zero, a negative resistance…).
        for v in [lo, hi] {
            config
                .with_values(&[(&param, v)])
                .map_err(|source| OptimizeError::UnknownKey {
                    key: key.clone(),
                    source,
                })?;
        }
        let scale = if lo > 0.0 && hi / lo >= 100.0 {
            Scale::Log
        } else {
            Scale::Linear
        };
        Ok(Variable {
            key,
            param,
            lo,
            hi,
            scale,
        })
    }

    /// The value at `u` ∈ [0, 1] of the unit interval (clamped into it).
    pub fn value(&self, u: f64) -> f64 {
        let u = u.clamp(0.0, 1.0);
        match self.scale {
            Scale::Linear => self.lo + u * (self.hi - self.lo),
            Scale::Log => self.lo * (self.hi / self.lo).powf(u),
        }
    }

    /// The position in the unit interval of `value` (the inverse of [`value`](Self::value)).
    pub fn unit(&self, value: f64) -> f64 {
        match self.scale {
            Scale::Linear => (value - self.lo) / (self.hi - self.lo),
            Scale::Log => (value / self.lo).ln() / (self.hi / self.lo).ln(),
        }
    }
}

/// What the search maximises.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Objective {
    /// The run's average power after the transient, W.
    #[default]
    AveragePower,
    /// The mean of the average power over K seeded random starts, W (with its standard
    /// error): the power an unknown start should expect on a multistable device.
    ExpectedPower,
    /// Average power per kilogram of the chain's total mass, W/kg.
    PowerPerMass,
}

impl Objective {
    /// The name on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Objective::AveragePower => "average_power",
            Objective::ExpectedPower => "expected_power",
            Objective::PowerPerMass => "power_per_mass",
        }
    }
}

impl FromStr for Objective {
    type Err = OptimizeError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "average_power" => Ok(Objective::AveragePower),
            "expected_power" => Ok(Objective::ExpectedPower),
            "power_per_mass" => Ok(Objective::PowerPerMass),
            _ => Err(OptimizeError::UnknownObjective { name: s.into() }),
        }
    }
}

impl fmt::Display for Objective {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A constrained quantity of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Quantity {
    /// The largest |V_gap|/V_breakdown of the air gaps after the transient (Paschen's law),
    /// dimensionless.
    BreakdownRatio,
    /// The largest |x_i| of any mass after the transient, on the sample grid, m.
    MaxDisplacement,
}

impl Quantity {
    /// The name on the command line.
    pub fn as_str(self) -> &'static str {
        match self {
            Quantity::BreakdownRatio => "breakdown_ratio",
            Quantity::MaxDisplacement => "max_displacement",
        }
    }
}

/// An upper bound on a quantity: `QUANTITY<=BOUND`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Constraint {
    /// The quantity.
    pub quantity: Quantity,
    /// Its upper bound, in its unit.
    pub bound: f64,
}

impl Constraint {
    /// Reads `breakdown_ratio<=X` or `max_displacement<=X`; an error for a bound below 0 (the
    /// quantities are never negative).
    pub fn parse(text: &str) -> Result<Self, OptimizeError> {
        let syntax = || OptimizeError::ConstraintSyntax { text: text.into() };
        let (name, bound) = text.split_once("<=").ok_or_else(syntax)?;
        let quantity = match name.trim() {
            "breakdown_ratio" => Quantity::BreakdownRatio,
            "max_displacement" => Quantity::MaxDisplacement,
            _ => return Err(syntax()),
        };
        let bound: f64 = bound.trim().parse().map_err(|_| syntax())?;
        if bound.is_nan() {
            return Err(syntax());
        }
        if bound < 0.0 {
            return Err(OptimizeError::ImpossibleConstraint {
                text: text.into(),
                quantity: quantity.as_str(),
            });
        }
        Ok(Constraint { quantity, bound })
    }
}

impl fmt::Display for Constraint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}<={}", self.quantity.as_str(), self.bound)
    }
}

/// Settings of the search.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct OptimizeOptions {
    /// Random starts per design for `expected_power` (K ≥ 2). Default 4.
    pub starts: u64,
    /// Seed of the swarm and of the random starts. Default 0.
    pub seed: u64,
    /// Particles of the swarm. Default 8.
    pub particles: usize,
    /// Generations of the swarm after the first. Default 6.
    pub swarm_iterations: u64,
    /// Iterations of Nelder–Mead. Default 30.
    pub local_iterations: u64,
}

impl Default for OptimizeOptions {
    fn default() -> Self {
        OptimizeOptions {
            starts: 4,
            seed: 0,
            particles: 8,
            swarm_iterations: 6,
            local_iterations: 30,
        }
    }
}

impl OptimizeOptions {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), OptimizeError> {
        if self.starts < 2 {
            return Err(OptimizeError::BadOption {
                name: "starts",
                value: self.starts as f64,
                reason: "at least 2 (a standard error needs two starts)",
            });
        }
        if self.particles < 2 {
            return Err(OptimizeError::BadOption {
                name: "particles",
                value: self.particles as f64,
                reason: "at least 2",
            });
        }
        Ok(())
    }
}

/// A design problem: the base configuration, the varied keys, the objective, the
/// constraints and the search's settings.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The configuration every design starts from.
    pub base: Config,
    /// The varied keys (at least one, each once).
    pub variables: Vec<Variable>,
    /// What is maximised.
    pub objective: Objective,
    /// Upper bounds on the run's quantities.
    pub constraints: Vec<Constraint>,
    /// Settings of the search.
    pub options: OptimizeOptions,
}

impl Problem {
    /// Checks the problem: at least one variable, none twice, a harvester on the chain, valid
    /// options.
    pub fn validate(&self) -> Result<(), OptimizeError> {
        if self.variables.is_empty() {
            return Err(OptimizeError::NothingVaried);
        }
        for (i, v) in self.variables.iter().enumerate() {
            if self.variables[..i].iter().any(|w| w.key == v.key) {
                return Err(OptimizeError::DuplicateKey { key: v.key.clone() });
            }
        }
        if self.base.chain().len() < 2 {
            return Err(OptimizeError::Unsupported {
                objective: self.objective.as_str(),
                reason: "the chain has no harvester (one mass): there is no power to optimise",
            });
        }
        self.options.validate()
    }

    /// The configuration of the design at `unit` (one coordinate per variable in [0, 1]).
    pub fn design(&self, unit: &[f64]) -> Result<Config, crate::config::ConfigError> {
        let values: Vec<(&Param, f64)> = self
            .variables
            .iter()
            .zip(unit)
            .map(|(v, &u)| (&v.param, v.value(u)))
            .collect();
        self.base.with_values(&values)
    }
}
