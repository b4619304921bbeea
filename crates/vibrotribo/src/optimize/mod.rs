//! Multi-parameter design optimisation: the configuration keys to vary within bounds, an
//! objective (average power, expected power over random starts, power per mass), constraints
//! (air breakdown, displacement), and a derivative-free global + local search.
//!
//! ## Method
//!
//! The varied keys are mapped to the unit cube, each linearly or, where its range spans
//! decades (`HI/LO ≥ 100` with both positive), logarithmically ([`Variable`]). A particle
//! swarm explores the cube (global), then Nelder–Mead refines from the swarm's best (local);
//! both from [argmin](https://argmin-rs.org), a maintained optimisation framework whose
//! solvers are derivative-free and take their random numbers from a seeded generator, so a
//! run is reproducible, and whose swarm evaluates a generation in parallel (rayon). The
//! objective of a simulated harvester is not differentiable in its parameters where the
//! motion changes (impacts appear, orbits fold, chaos sets in), which rules out gradient
//! methods; the swarm guards against the many local optima of a multistable device, the
//! simplex converges on a smooth one.
//!
//! Constraints ([`Constraint`]) are kept by ranking: any feasible design beats every
//! infeasible one, and infeasible ones are ranked by how far they violate.
//!
//! Robustness ([`Objective`]): `expected_power` averages the power over K seeded random
//! starts (the attractor an unknown start ends on), with its standard error; under a random
//! or recorded base motion, whose power is a noisy estimate, designs are ranked by the lower
//! end of the 95 % confidence interval of their power, so that a design wins only by a
//! margin its own noise cannot explain.
//!
//! Every evaluation goes through a callback and can be served from a cache
//! ([`Cache`]): the search is deterministic for a seed, so a run resumed with the evaluations
//! of an interrupted one retraces it and ends where the uninterrupted run ends.

mod error;
mod evaluate;
mod problem;
mod runner;

pub use error::OptimizeError;
pub use evaluate::{Evaluation, evaluate};
pub use problem::{Constraint, Objective, OptimizeOptions, Problem, Quantity, Scale, Variable};
pub use runner::{Cache, HistoryPoint, OptimizeResult, optimize, optimize_with};
