//! Average power against load resistance on one recorded mechanical trajectory (the coupling
//! is one-way, so the mechanics is simulated once and replayed for every load).

use super::ElectricalError;
use super::params::{HarvesterParams, Load};
use super::solver::{ChargeOptions, ChargeSolver};
use crate::dynamics::Trajectory;
use crate::error::ParamError;

/// Average power at one load.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct LoadPoint {
    /// Load resistance R, Ω.
    pub resistance_ohm: f64,
    /// Average power after the transient (seed eq. 14), W.
    pub average_power_w: f64,
    /// Mean energy per period after the transient, J.
    pub energy_per_period_j: f64,
}

/// Result of [`load_sweep`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct LoadSweep {
    /// One point per requested resistance, in the order given.
    pub points: Vec<LoadPoint>,
    /// The best load: the best grid point refined by golden-section search in log R between
    /// its neighbours.
    pub optimum: LoadPoint,
    /// True if the best grid point is the first or last of the sorted grid (the optimum may lie
    /// outside the range; not refined).
    pub optimum_at_edge: bool,
}

/// `n` resistances log-spaced from `min` to `max`, Ω (both included; `[min]` if n = 1).
pub fn log_spaced(min: f64, max: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![min],
        _ => {
            let (a, b) = (min.ln(), max.ln());
            // The ends exactly (exp∘ln is not the identity in floating point).
            (0..n)
                .map(|k| match k {
                    0 => min,
                    k if k == n - 1 => max,
                    k => (a + (b - a) * k as f64 / (n - 1) as f64).exp(),
                })
                .collect()
        }
    }
}

/// Runs the charge solver with a resistor load of each of `resistances` (Ω) over the recorded
/// `trajectory` (excitation period `period`, s), averages power over the complete periods after
/// the first `transient` ones, and refines the optimum by golden-section search in log R
/// (relative precision 1e-3 in R). The other fields of `params` (transducer, initial charge)
/// apply; its `load` and `load_resistance` are replaced.
pub fn load_sweep(
    trajectory: &Trajectory,
    params: &HarvesterParams,
    period: f64,
    resistances: &[f64],
    transient: usize,
    options: &ChargeOptions,
) -> Result<LoadSweep, ElectricalError> {
    check_resistances(resistances)?;
    if trajectory.segments().is_empty() {
        return Err(ElectricalError::EmptyTrajectory);
    }
    let gaps = trajectory.gap_count();
    let evaluate = |r: f64| -> Result<LoadPoint, ElectricalError> {
        let mut p = params.clone();
        p.load = Load::Resistor { resistance: r };
        let mut solver = ChargeSolver::new(&p, period, gaps, options.clone())?;
        solver.run_trajectory(trajectory)?;
        let s = solver.summary(transient).ok_or_else(|| ParamError::Invalid {
            name: "sweep.transient_periods".into(),
            value: transient as f64,
            reason: "leaves no complete period of the trajectory to average",
        })?;
        Ok(LoadPoint {
            resistance_ohm: r,
            average_power_w: s.average_power_w,
            energy_per_period_j: s.energy_per_period_j,
        })
    };
    best_load(resistances, evaluate)
}

/// Checks the resistances of a load sweep: at least one, each finite and positive (Ω).
pub fn check_resistances(resistances: &[f64]) -> Result<(), ParamError> {
    if resistances.is_empty() {
        return Err(ParamError::Length {
            name: "sweep.resistances".into(),
            expected: 1,
            got: 0,
        });
    }
    for (i, &r) in resistances.iter().enumerate() {
        if !(r.is_finite() && r > 0.0) {
            return Err(ParamError::Invalid {
                name: format!("sweep.resistances[{i}]"),
                value: r,
                reason: "must be a positive resistance",
            });
        }
    }
    Ok(())
}

/// The power at each of `resistances` (Ω, checked by [`check_resistances`]) as `evaluate`
/// gives it, and the optimum: the best grid point refined by golden-section search in log R
/// between its neighbours (relative precision 1e-3 in R). [`load_sweep`] evaluates a load by
/// the charge along one recorded trajectory; a two-way coupled study by a whole coupled run.
pub fn best_load<E: From<ParamError>>(
    resistances: &[f64],
    mut evaluate: impl FnMut(f64) -> Result<LoadPoint, E>,
) -> Result<LoadSweep, E> {
    check_resistances(resistances)?;
    let points = resistances
        .iter()
        .map(|&r| evaluate(r))
        .collect::<Result<Vec<_>, _>>()?;
    let mut sorted = points.clone();
    sorted.sort_by(|a, b| a.resistance_ohm.total_cmp(&b.resistance_ohm));
    let Some(best) =
        (0..sorted.len()).max_by(|&a, &b| sorted[a].average_power_w.total_cmp(&sorted[b].average_power_w))
    else {
        return Err(ParamError::Length {
            name: "sweep.resistances".into(),
            expected: 1,
            got: 0,
        }
        .into());
    };
    if best == 0 || best + 1 == sorted.len() {
        return Ok(LoadSweep {
            points,
            optimum: sorted[best],
            optimum_at_edge: true,
        });
    }
    // Golden-section search for the maximum of P(ln R) on the bracket around the best point.
    let inv_phi = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (
        sorted[best - 1].resistance_ohm.ln(),
        sorted[best + 1].resistance_ohm.ln(),
    );
    let mut x1 = b - inv_phi * (b - a);
    let mut x2 = a + inv_phi * (b - a);
    let mut p1 = evaluate(x1.exp())?;
    let mut p2 = evaluate(x2.exp())?;
    let mut optimum = sorted[best];
    while b - a > 1e-3 {
        if p1.average_power_w >= p2.average_power_w {
            b = x2;
            x2 = x1;
            p2 = p1;
            x1 = b - inv_phi * (b - a);
            p1 = evaluate(x1.exp())?;
        } else {
            a = x1;
            x1 = x2;
            p1 = p2;
            x2 = a + inv_phi * (b - a);
            p2 = evaluate(x2.exp())?;
        }
        for p in [p1, p2] {
            if p.average_power_w > optimum.average_power_w {
                optimum = p;
            }
        }
    }
    Ok(LoadSweep {
        points,
        optimum,
        optimum_at_edge: false,
    })
}
