//! Recording a run's exact trajectory, and solving the charge of a harvester along a recorded
//! trajectory. The coupling is one-way (the charge does not act on the masses), so one
//! mechanical run serves any number of loads: a load sweep, a V–Q cycle, another V_oc law.

use super::observer::{Mechanics, RunObserver};
use super::settings::{Harvester, RunSpec};
use super::simulate::{ElectricalOutcome, Ending, StudyError, simulate};
use crate::dynamics::Trajectory;
use crate::electrical::{ChargeSolver, ElectricalSamples};
use crate::model::ChainParams;

/// Runs `spec` (its harvester ignored) and records its exact trajectory from period
/// `from_period` to the end; `observer` watches the run as in [`simulate`] (a progress bar, a
/// checkpoint). Returns the trajectory and how the run ended.
pub fn record_trajectory<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    from_period: u64,
    observer: &mut O,
) -> Result<(Trajectory, Ending), StudyError> {
    let mechanics = RunSpec {
        harvester: None,
        sampling: None,
        breakdown_check: false,
        ..spec.clone()
    };
    let from = from_period as f64 * spec.chain.period();
    let mut rec = (
        Mechanics::starting_at(
            Trajectory::for_chain(&crate::dynamics::driven_chain(
                &spec.chain,
                spec.base_motion.as_deref(),
            )),
            from,
        ),
        observer,
    );
    let outcome = simulate(&mechanics, &mut rec)?;
    Ok((rec.0.inner, outcome.ending))
}

/// What [`replay`] records besides the power.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ReplayOptions {
    /// Periods excluded from the power summary.
    pub transient_periods: u64,
    /// Check the air gaps for breakdown from this period on.
    pub breakdown_from_period: Option<u64>,
    /// Record the V–Q cycle of period `.0` at `.1 + 1` times.
    pub vq_cycle: Option<(u64, usize)>,
}

/// The charge of a harvester along a recorded trajectory ([`replay`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Replayed {
    /// Power, per-period energies, breakdown margin.
    pub electrical: ElectricalOutcome,
    /// The V–Q cycle, if asked for (plot `voltage_v` against `charge_c`).
    pub vq_cycle: Option<ElectricalSamples>,
}

/// Solves the charge of `harvester` (its start period is ignored) along `trajectory`, a
/// recorded run of `chain`.
pub fn replay(
    trajectory: &Trajectory,
    chain: &ChainParams,
    harvester: &Harvester,
    options: &ReplayOptions,
) -> Result<Replayed, StudyError> {
    let period = chain.period();
    let mut s = ChargeSolver::for_chain(&harvester.params, chain, harvester.options.clone())?;
    if let Some(p) = options.breakdown_from_period {
        s = s.with_breakdown_check(p as f64 * period);
    }
    if let Some((index, points)) = options.vq_cycle {
        s = s.with_vq_cycle(index, points)?;
    }
    s.run_trajectory(trajectory)?;
    Ok(Replayed {
        vq_cycle: s.vq_cycle().cloned(),
        electrical: ElectricalOutcome {
            periods: s.periods().to_vec(),
            power: s.summary(options.transient_periods as usize),
            breakdown: s.breakdown_margin().copied(),
            storage_voltage: s.storage_voltage(),
            terminal_energy_j: s.terminal_energy(),
            time_to_target: s.time_to_target(),
            solver: s.stats(),
            coupling: None,
            solver_error: None,
            period,
        },
    })
}
