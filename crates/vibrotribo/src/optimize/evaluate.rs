//! One design evaluated: its run (or K runs from random starts), the objective with its
//! standard error, the score that ranks it, and the constrained quantities.

use crate::attractors::{StartBox, random_start};
use crate::config::Config;
use crate::study::{RunObserver, Sample, simulate};

use super::problem::{Constraint, Objective, Problem, Quantity};

/// Student's z for a two-sided 95 % interval.
const Z_95: f64 = 1.959_963_984_540_054;

/// The numbers of one design.
#[derive(Debug, Clone, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Evaluation {
    /// The varied keys' values, in the order of the problem's variables.
    pub values: Vec<f64>,
    /// The objective (W, or W/kg for `power_per_mass`); `None` if the run failed.
    pub objective: Option<f64>,
    /// Its standard error, same unit (over the starts for `expected_power`, from batch means
    /// of the periods otherwise; `None` where it cannot be estimated).
    pub standard_error: Option<f64>,
    /// What ranks designs: the objective, or under a base motion that is not periodic the
    /// lower end of its 95 % confidence interval.
    pub score: Option<f64>,
    /// Largest |V_gap|/V_breakdown after the transient, dimensionless.
    pub breakdown_ratio: f64,
    /// Largest |x_i| of any mass after the transient, m.
    pub max_displacement_m: f64,
    /// Sum of the constraints' relative excesses, `(q − bound)/bound` (0: feasible).
    pub violation: f64,
    /// Why the design could not be evaluated (the error's text), if it could not.
    pub failure: Option<String>,
}

impl Evaluation {
    /// Whether the design ran and met every constraint.
    pub fn feasible(&self) -> bool {
        self.score.is_some() && self.violation == 0.0
    }
}

/// The largest |x_i| over the samples from `from` on.
struct Displacement {
    from: f64,
    max: f64,
}

impl RunObserver for Displacement {
    fn wants_samples(&self) -> bool {
        true
    }
    fn sample(&mut self, s: &Sample<'_>) {
        if s.time >= self.from {
            self.max = s.positions.iter().fold(self.max, |m, x| m.max(x.abs()));
        }
    }
}

/// Power, W, its standard error, the breakdown ratio and the largest displacement, m, of one
/// run of `config` (from `start`, or the configured initial state).
fn run_once(
    config: &Config,
    start: Option<crate::ChainState>,
) -> Result<(f64, Option<f64>, f64, f64), String> {
    let mut spec = config.sampled_run_spec(false);
    spec.breakdown_check = true;
    if let Some(s) = start {
        spec.initial = s;
    }
    let mut watch = Displacement {
        from: spec.transient_periods as f64 * spec.chain.period(),
        max: 0.0,
    };
    let outcome = simulate(&spec, &mut watch).map_err(|e| e.to_string())?;
    if let Some(e) = outcome.failure() {
        return Err(e.to_string());
    }
    let e = outcome.electrical.as_ref().ok_or("the chain has no harvester")?;
    let power = e.power.as_ref().ok_or("no complete period after the transient")?;
    let se = e.average_power_se(spec.transient_periods);
    let ratio = e.breakdown.map_or(0.0, |m| m.worst_ratio);
    Ok((power.average_power_w, se, ratio, watch.max))
}

/// Evaluates the design at `unit` (one coordinate per variable in [0, 1]) of `problem`.
pub fn evaluate(problem: &Problem, unit: &[f64]) -> Evaluation {
    let values: Vec<f64> = problem
        .variables
        .iter()
        .zip(unit)
        .map(|(v, &u)| v.value(u))
        .collect();
    let failed = |why: String| Evaluation {
        values: values.clone(),
        failure: Some(why),
        ..Evaluation::default()
    };
    let config = match problem.design(unit) {
        Ok(c) => c,
        Err(e) => return failed(e.to_string()),
    };
    let runs: Result<Vec<_>, String> = match problem.objective {
        Objective::ExpectedPower => {
            let chain = config.chain();
            let bounds = StartBox::of(chain);
            (0..problem.options.starts)
                .map(|k| {
                    let s =
                        random_start(chain, &bounds, problem.options.seed, k).map_err(|e| e.to_string())?;
                    run_once(&config, Some(s))
                })
                .collect()
        }
        _ => run_once(&config, None).map(|r| vec![r]),
    };
    let runs = match runs {
        Ok(r) => r,
        Err(why) => return failed(why),
    };
    let n = runs.len() as f64;
    let mean = runs.iter().map(|r| r.0).sum::<f64>() / n;
    let (mut objective, mut se) = match problem.objective {
        Objective::ExpectedPower => {
            let var = runs.iter().map(|r| (r.0 - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, Some((var / n).sqrt()))
        }
        _ => (mean, runs[0].1),
    };
    if problem.objective == Objective::PowerPerMass {
        let mass: f64 = config.chain().masses.iter().sum();
        objective /= mass;
        se = se.map(|s| s / mass);
    }
    let score = match (config.is_periodic(), se) {
        (false, Some(s)) => objective - Z_95 * s,
        _ => objective,
    };
    let breakdown_ratio = runs.iter().map(|r| r.2).fold(0.0, f64::max);
    let max_displacement_m = runs.iter().map(|r| r.3).fold(0.0, f64::max);
    let violation = violation(&problem.constraints, breakdown_ratio, max_displacement_m);
    Evaluation {
        values,
        objective: Some(objective),
        standard_error: se,
        score: Some(score),
        breakdown_ratio,
        max_displacement_m,
        violation,
        failure: None,
    }
}

/// Sum of the relative excesses of the constrained quantities over their bounds.
fn violation(constraints: &[Constraint], breakdown_ratio: f64, displacement: f64) -> f64 {
    constraints
        .iter()
        .map(|c| {
            let q = match c.quantity {
                Quantity::BreakdownRatio => breakdown_ratio,
                Quantity::MaxDisplacement => displacement,
            };
            if q <= c.bound {
                0.0
            } else {
                (q - c.bound) / c.bound.max(f64::MIN_POSITIVE)
            }
        })
        .sum()
}
