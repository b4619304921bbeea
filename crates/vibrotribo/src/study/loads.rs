//! [`load_study`]: average power against the load resistance, the optimal load, the power at
//! the configured load, and V–Q cycles over the last period. Under one-way coupling the
//! mechanics is simulated once and the charge replayed along it for every load; under
//! two-way coupling (the charge acts on the masses) every load is a whole coupled run.

use super::observer::{RunObserver, Sample};
use super::replay::{ReplayOptions, record_trajectory, replay};
use super::settings::{Harvester, RunSpec, Sampling};
use super::simulate::{Ending, StudyError, simulate};
use crate::coupling::Coupling;
use crate::electrical::breakdown::BreakdownMargin;
use crate::electrical::{
    ElectricalSamples, HarvesterParams, Load, LoadPoint, LoadSweep, best_load, load_sweep,
};
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

impl LoadStudyOptions {
    /// Bytes the study's V–Q cycles hold (two cycles of `vq_points + 1` samples of eight
    /// quantities), an estimate to refuse a mistyped size before anything is allocated.
    pub fn estimated_bytes(&self) -> f64 {
        let points = self.vq_points.map_or(0.0, |p| p as f64 + 1.0);
        2.0 * points * 8.0 * std::mem::size_of::<f64>() as f64
    }
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
    if configured.params.coupling == Coupling::TwoWay {
        return coupled_load_study(spec, options, observer, (configured_load_ohm, &resistor));
    }
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

/// A coupled run of `spec` stopped by its observer (not a failure).
enum Coupled {
    Stopped,
    Failed(StudyError),
}

impl From<ParamError> for Coupled {
    fn from(e: ParamError) -> Self {
        Coupled::Failed(e.into())
    }
}

impl From<StudyError> for Coupled {
    fn from(e: StudyError) -> Self {
        Coupled::Failed(e)
    }
}

/// [`load_study`] under two-way coupling: the charge acts on the masses, so every load is a
/// whole coupled run of `spec` with that resistor (`resistor` gives the harvester), its power
/// averaged after `spec.transient_periods` exactly as [`simulate`] reports it; the V–Q
/// cycles are sampled from the coupled runs at the configured and the optimal load.
fn coupled_load_study<O: RunObserver + ?Sized>(
    spec: &RunSpec,
    options: &LoadStudyOptions,
    observer: &mut O,
    (configured_load_ohm, resistor): (f64, &dyn Fn(f64) -> Harvester),
) -> Result<Option<LoadStudy>, StudyError> {
    let mut run = |r: f64| -> Result<LoadPoint, Coupled> {
        let at = RunSpec {
            harvester: Some(resistor(r)),
            ..spec.clone()
        };
        let outcome = simulate(&at, &mut *observer)?;
        match outcome.ending {
            Ending::Completed => {}
            Ending::Stopped => return Err(Coupled::Stopped),
            Ending::Failed(e) => return Err(Coupled::Failed(e)),
        }
        let power = outcome.electrical.and_then(|e| e.power);
        Ok(LoadPoint {
            resistance_ohm: r,
            average_power_w: power.as_ref().map_or(f64::NAN, |p| p.average_power_w),
            energy_per_period_j: power.map_or(f64::NAN, |p| p.energy_per_period_j),
        })
    };
    let outcome = best_load(&options.resistances, &mut run)
        .and_then(|sweep| Ok((run(configured_load_ohm)?.average_power_w, sweep)));
    let (configured_average_power_w, sweep) = match outcome {
        Ok(found) => found,
        Err(Coupled::Stopped) => return Ok(None),
        Err(Coupled::Failed(e)) => return Err(e),
    };
    let mut vq_cycles = Vec::new();
    if let Some(points) = options.vq_points {
        for r in [configured_load_ohm, sweep.optimum.resistance_ohm] {
            vq_cycles.push(coupled_vq_cycle(spec, &resistor(r), points)?);
        }
    }
    Ok(Some(LoadStudy {
        sweep,
        configured_load_ohm,
        configured_average_power_w,
        vq_cycles,
    }))
}

/// The V–Q cycle over the last period of a coupled run of `spec` with `harvester`, at
/// `points + 1` times, and the air-breakdown check over that period.
fn coupled_vq_cycle(spec: &RunSpec, harvester: &Harvester, points: usize) -> Result<VqCycle, StudyError> {
    let period = spec.chain.period();
    let last = spec.periods - 1;
    let at = RunSpec {
        harvester: Some(harvester.clone()),
        transient_periods: last,
        breakdown_check: true,
        sampling: Some(Sampling::Uniform {
            start: last as f64 * period,
            step: period / points.max(1) as f64,
        }),
        ..spec.clone()
    };
    let mut cycle = VqSamples {
        points: points as u64,
        samples: ElectricalSamples::default(),
    };
    let outcome = simulate(&at, &mut cycle)?;
    if let Ending::Failed(e) = outcome.ending {
        return Err(e);
    }
    Ok(VqCycle {
        load_resistance_ohm: harvester.params.load.resistance().unwrap_or(f64::NAN),
        samples: cycle.samples,
        breakdown: outcome.electrical.and_then(|e| e.breakdown).unwrap_or_default(),
    })
}

/// Collects the electrical samples of the first `points + 1` grid times.
struct VqSamples {
    points: u64,
    samples: ElectricalSamples,
}

impl RunObserver for VqSamples {
    fn wants_samples(&self) -> bool {
        true
    }

    fn sample(&mut self, sample: &Sample<'_>) {
        let (Some(e), true) = (sample.electrical, sample.index <= self.points) else {
            return;
        };
        let s = &mut self.samples;
        s.times.push(sample.time);
        s.charge_c.push(e.charge_c);
        s.current_a.push(e.current_a);
        s.voltage_v.push(e.voltage_v);
        s.capacitance_f.push(e.capacitance_f);
        s.voc_v.push(e.voc_v);
        if let Some(v) = e.storage_voltage_v {
            s.storage_voltage_v.push(v);
        }
    }
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

    /// Under two-way coupling each load is a whole coupled run: the load study's power at a
    /// load is what a two-way simulation with that load reports, and not the one-way power
    /// of the same load (the charge's force changes the motion); the V–Q cycle has its
    /// points.
    #[test]
    fn two_way_loads_are_coupled_runs() {
        let load = 1e10;
        let harvester = |coupling| HarvesterParams {
            load: Load::Resistor { resistance: load },
            coupling,
            voc_model: crate::electrical::VocModel::Exact,
            ..HarvesterParams::default()
        };
        let spec = |coupling| RunSpec {
            transient_periods: 10,
            harvester: Some(Harvester::new(harvester(coupling), ChargeOptions::default())),
            ..RunSpec::new(ChainParams::default(), 20)
        };
        let options = LoadStudyOptions {
            resistances: vec![load],
            vq_points: Some(20),
        };
        let two_way = spec(Coupling::TwoWay);
        let study = load_study(&two_way, &options, &mut ()).unwrap().unwrap();
        let direct = crate::study::simulate(&two_way, &mut ()).unwrap();
        let want = direct.electrical.unwrap().power.unwrap().average_power_w;
        let got = study.sweep.points[0].average_power_w;
        assert_eq!(got, want, "load study {got} W vs two-way simulation {want} W");
        assert_eq!(study.configured_average_power_w, want);
        let one_way = load_study(&spec(Coupling::OneWay), &options, &mut ())
            .unwrap()
            .unwrap();
        let p1 = one_way.sweep.points[0].average_power_w;
        assert!(
            (p1 - want).abs() > 1e-3 * want,
            "two-way {want} W should differ from one-way {p1} W at {load} Ω"
        );
        assert_eq!(study.vq_cycles.len(), 2);
        assert_eq!(study.vq_cycles[0].samples.times.len(), 21);
    }
}
