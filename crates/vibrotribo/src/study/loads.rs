//! [`load_study`]: average power against the load resistance on one mechanical run (the
//! coupling is one-way, so the mechanics is simulated once and replayed for every load), the
//! optimal load, the power at the configured load, and V–Q cycles over the last period.

use super::observer::RunObserver;
use super::replay::{ReplayOptions, record_trajectory, replay};
use super::settings::{Harvester, RunSpec};
use super::simulate::{Ending, StudyError};
use crate::electrical::breakdown::BreakdownMargin;
use crate::electrical::{ElectricalSamples, HarvesterParams, Load, LoadSweep, load_sweep};
use crate::error::ParamError;
use crate::{ChainParams, Trajectory};

/// Settings of [`load_study`].
#[derive(Debug, Clone, PartialEq)]
pub struct LoadStudyOptions {
    /// The resistances, Ω (e.g. [`log_spaced`](crate::electrical::log_spaced)).
    pub resistances: Vec<f64>,
    /// Points of the V–Q cycles over the last period at the configured and the optimal load
    /// (`None`: no cycles).
    pub vq_points: Option<usize>,
}

/// The V–Q cycle of one load over the last simulated period.
#[derive(Debug, Clone, PartialEq)]
pub struct VqCycle {
    /// Load resistance, Ω.
    pub load_resistance_ohm: f64,
    /// Times, charge, voltage and current over the period.
    pub samples: ElectricalSamples,
    /// The worst air-breakdown ratio over the period.
    pub breakdown: BreakdownMargin,
}

/// What [`load_study`] found.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadStudy {
    /// Power at every resistance and the refined optimum.
    pub sweep: LoadSweep,
    /// The configured load resistance, Ω (the paper's 100 kΩ if the load is not a resistor).
    pub configured_load_ohm: f64,
    /// Average power at the configured load after the transient, W (NaN if no complete
    /// period after it).
    pub configured_average_power_w: f64,
    /// V–Q cycles at the configured and the optimal load, in that order (if asked).
    pub vq_cycles: Vec<VqCycle>,
}

/// Runs the mechanics of `spec` once (shown to `observer`, which may stop it: then `None`),
/// then solves the charge of `spec`'s harvester with a resistor of each of
/// `options.resistances` along it (the power averaged after `spec.transient_periods`), finds
/// the optimal load, the power at the configured load and, if asked, the V–Q cycles of the
/// last period. `spec` must have a harvester.
pub fn load_study<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    options: &LoadStudyOptions,
    observer: &mut O,
) -> Result<Option<LoadStudy>, StudyError> {
    let configured = spec.harvester.as_ref().ok_or_else(|| ParamError::Conflict {
        name: "harvester".into(),
        message: "a load study needs a harvester".into(),
    })?;
    let configured_load_ohm = configured
        .params
        .load
        .resistance()
        .unwrap_or(Load::default().resistance().unwrap_or(1e5));
    let resistor = |r: f64| Harvester {
        params: HarvesterParams {
            load: Load::Resistor { resistance: r },
            ..configured.params.clone()
        },
        ..Harvester::new(configured.params.clone(), configured.options.clone())
    };
    let (trajectory, ending) = record_trajectory(spec, 0, observer)?;
    if ending != Ending::Completed {
        return Ok(None);
    }
    let chain = &spec.chain;
    let sweep = load_sweep(
        &trajectory,
        &resistor(configured_load_ohm).params,
        chain.period(),
        &options.resistances,
        spec.transient_periods as usize,
        &configured.options,
    )?;
    let replayed = replay(
        &trajectory,
        chain,
        &resistor(configured_load_ohm),
        &ReplayOptions {
            transient_periods: spec.transient_periods,
            ..ReplayOptions::default()
        },
    )?;
    let configured_average_power_w = replayed.electrical.power.map_or(f64::NAN, |s| s.average_power_w);
    let mut vq_cycles = Vec::new();
    if let Some(points) = options.vq_points {
        for r in [configured_load_ohm, sweep.optimum.resistance_ohm] {
            vq_cycles.push(vq_cycle(
                &trajectory,
                chain,
                &resistor(r),
                spec.periods - 1,
                points,
            )?);
        }
    }
    Ok(Some(LoadStudy {
        sweep,
        configured_load_ohm,
        configured_average_power_w,
        vq_cycles,
    }))
}

/// The V–Q cycle of period `index` at `points + 1` times of `harvester` along `trajectory`
/// (of `chain`), and the air-breakdown check from that period on.
pub fn vq_cycle(
    trajectory: &Trajectory,
    chain: &ChainParams,
    harvester: &Harvester,
    index: u64,
    points: usize,
) -> Result<VqCycle, StudyError> {
    let r = replay(
        trajectory,
        chain,
        harvester,
        &ReplayOptions {
            breakdown_from_period: Some(index),
            vq_cycle: Some((index, points)),
            ..ReplayOptions::default()
        },
    )?;
    Ok(VqCycle {
        load_resistance_ohm: harvester.params.load.resistance().unwrap_or(f64::NAN),
        samples: r.vq_cycle.unwrap_or_default(),
        breakdown: r.electrical.breakdown.unwrap_or_default(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::electrical::{ChargeOptions, log_spaced};

    /// The power at each load is that of a full simulation with that load (the charge solved
    /// alongside the mechanics, not replayed), and the optimum beats every grid point.
    #[test]
    fn replayed_loads_equal_direct_runs() {
        let spec = RunSpec {
            transient_periods: 4,
            harvester: Some(Harvester::new(
                HarvesterParams::default(),
                ChargeOptions::default(),
            )),
            ..RunSpec::new(ChainParams::default(), 10)
        };
        let options = LoadStudyOptions {
            resistances: log_spaced(1e5, 1e11, 4),
            vq_points: Some(50),
        };
        let study = load_study(&spec, &options, &mut ()).unwrap().unwrap();
        for p in &study.sweep.points {
            let mut direct = spec.clone();
            if let Some(h) = direct.harvester.as_mut() {
                h.params.load = Load::Resistor {
                    resistance: p.resistance_ohm,
                };
            }
            let run = crate::study::simulate(&direct, &mut ()).unwrap();
            let want = run.electrical.unwrap().power.unwrap().average_power_w;
            assert!(
                (p.average_power_w - want).abs() <= 1e-6 * want,
                "R = {}: replayed {} vs direct {want}",
                p.resistance_ohm,
                p.average_power_w
            );
            assert!(study.sweep.optimum.average_power_w >= p.average_power_w);
        }
        assert_eq!(study.configured_load_ohm, 1e5);
        assert_eq!(study.vq_cycles.len(), 2);
        assert_eq!(study.vq_cycles[0].samples.times.len(), 51);
    }
}
