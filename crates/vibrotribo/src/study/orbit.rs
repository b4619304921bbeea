//! What a harvester delivers on a periodic orbit: the charge solved along the orbit repeated
//! exactly (one period of it recorded once and replayed), so that the result is the orbit's
//! own, stable or unstable, not that of a simulation that drifts off an unstable orbit.

use super::settings::Harvester;
use super::simulate::{ElectricalOutcome, StudyError};
use crate::dynamics::{Flow, Simulator, Trajectory};
use crate::electrical::{ChargeSolver, GapWaveform};
use crate::model::{ChainParams, ChainState, SimOptions};
use crate::orbits::PeriodicOrbit;

/// A piece of the orbit's flow shifted by `shift` seconds (a whole number of orbit periods).
struct Shifted<'a> {
    flow: Flow<'a>,
    shift: f64,
}

impl GapWaveform for Shifted<'_> {
    fn gaps(&self, t: f64, gaps: &mut [f64], rates: &mut [f64]) {
        self.flow.gaps_at(t - self.shift, gaps, rates);
    }
}

/// The charge of `harvester` on `orbit`, solved over `warmup + periods` repetitions of the
/// orbit (each `orbit.period` excitation periods long) from the electrostatic equilibrium
/// (or the harvester's initial charge); the power summary covers the last `periods`
/// repetitions. The circuit forgets its start within a few R·C, so one repetition of warm-up
/// suffices for all but the largest loads.
pub fn power_on_orbit(
    orbit: &PeriodicOrbit,
    harvester: &Harvester,
    sim: &SimOptions,
    warmup: u32,
    periods: u32,
) -> Result<ElectricalOutcome, StudyError> {
    power_on_periodic_state(
        &orbit.params,
        &orbit.state,
        orbit.period,
        harvester,
        sim,
        warmup,
        periods,
    )
}

/// [`power_on_orbit`] for the orbit of period `period` (excitation periods) of `chain`
/// through `state` at t = 0 (a point of a continued branch, say).
pub fn power_on_periodic_state(
    chain: &ChainParams,
    state: &ChainState,
    period: u32,
    harvester: &Harvester,
    sim: &SimOptions,
    warmup: u32,
    periods: u32,
) -> Result<ElectricalOutcome, StudyError> {
    let mut trajectory = Trajectory::for_chain(chain);
    let duration = f64::from(period) * chain.period();
    Simulator::new(chain, state, sim.clone())?.run_until(duration, &mut trajectory)?;
    let mut solver = ChargeSolver::for_chain(&harvester.params, chain, harvester.options.clone())?;
    for k in 0..warmup + periods {
        let shift = f64::from(k) * duration;
        for seg in trajectory.segments() {
            let flow = trajectory.flow_at(seg.t_start).ok_or(StudyError::Electrical(
                crate::electrical::ElectricalError::EmptyTrajectory,
            ))?;
            solver.advance(seg.t_start + shift, seg.t_end + shift, &Shifted { flow, shift })?;
        }
    }
    Ok(ElectricalOutcome {
        periods: solver.periods().to_vec(),
        power: solver.summary((warmup * period) as usize),
        breakdown: None,
        storage_voltage: solver.storage_voltage(),
        terminal_energy_j: solver.terminal_energy(),
        time_to_target: solver.time_to_target(),
        solver: solver.stats(),
        coupling: None,
        solver_error: None,
        period: chain.period(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::electrical::{ChargeOptions, HarvesterParams};
    use crate::orbits::{ShootingOptions, periodic_orbit_from_transient};
    use crate::study::{RunSpec, simulate};

    /// On the default case's stable period-1 orbit, the power of the replayed orbit is the
    /// power of a long simulation that has settled onto it.
    #[test]
    fn orbit_power_is_the_settled_power() {
        let chain = ChainParams::default();
        let orbit = periodic_orbit_from_transient(
            &chain,
            &ChainState::at_rest(3),
            100,
            Some(1),
            &ShootingOptions::default(),
        )
        .unwrap();
        let harvester = Harvester::new(HarvesterParams::default(), ChargeOptions::default());
        let on = power_on_orbit(&orbit, &harvester, &SimOptions::default(), 2, 4).unwrap();
        let p_orbit = on.power.unwrap().average_power_w;
        let spec = RunSpec {
            harvester: Some(harvester),
            transient_periods: 300,
            ..RunSpec::new(chain, 310)
        };
        let settled = simulate(&spec, &mut ()).unwrap();
        let p_run = settled.electrical.unwrap().power.unwrap().average_power_w;
        assert!(
            (p_orbit - p_run).abs() < 1e-6 * p_run,
            "orbit {p_orbit} W, settled run {p_run} W"
        );
    }
}
