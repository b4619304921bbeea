//! [`RunSummary`]: the summary of one run, `summary.json`, written and read through this one
//! type (the command line writes and reads the file, Python hands the same object out as a
//! dict).

use std::error::Error;
use std::fmt::Write as _;

use serde::{Deserialize, Deserializer, Serialize};

use super::base_motion::BaseMotionSummary;
use super::motion::MotionRecord;
use crate::analysis::RunStats;
use crate::config::Config;
use crate::coupling::CouplingStats;
use crate::electrical::breakdown::BreakdownMargin;
use crate::electrical::{HarvesterParams, LoadKind};
use crate::merit::MeritReport;
use crate::model::{ChainParams, NondimGroups};
use crate::study::{Ending, MotionReport, RunOutcome, RunSpec, Sampling, SettleMode};

/// Why a run failed, as one line: `simulation stopped after N complete periods: <error>:
/// <its source>: …` (the error and the chain of its sources, each after `: `).
pub fn failure_text(outcome: &RunOutcome) -> Option<String> {
    let e = outcome.failure()?;
    let mut text = format!("simulation stopped after {} complete periods", outcome.periods);
    let mut cause: Option<&dyn Error> = Some(e);
    while let Some(c) = cause {
        let _ = write!(text, ": {c}");
        cause = c.source();
    }
    Some(text)
}

/// The command that writes a run summary: the `command` of `summary.json`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SummaryCommand {
    /// `vibrotribo simulate` (`vibrotribo.simulate` in Python).
    #[default]
    Simulate,
}

/// The phase before the configured run in which a signal stopped it
/// ([`RunSummary::stopped_while_settling`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StoppedPhase {
    /// Settling to a periodic motion (`--settle auto`).
    Settling,
}

/// Student's t quantile t(0.975) with 9 degrees of freedom: the 95 % interval of a mean of
/// 10 batch means is ± this × their standard error.
const T_975_9: f64 = 2.262_157_162_8;

/// The summary of one run: periods, impacts (after the transient, in all, per period and per
/// contact), sticks, releases, chatter sequences, the largest closing speeds, the excitation;
/// with a harvester its electrical figures ([`ElectricalSummary`]); the base motion, the
/// nondimensional groups, the chain's parameters, the configuration's settings, the wall
/// time, whether the run was interrupted and why it failed ([`failure_text`]); how it
/// settled, its motion after the transient and, with a harvester, its figures of merit.
/// Units are in the key names (`_w`, `_j`, `_a`, `_v`, `_s`, `_m_s`, `_rad_s`); the fields
/// are in the order of the file's keys.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// Always [`SummaryCommand::Simulate`] (files without the key read as such).
    #[serde(default)]
    pub command: SummaryCommand,
    /// Complete periods run.
    pub periods: u64,
    /// Periods asked for.
    pub periods_requested: u64,
    /// Of which transient.
    pub transient_periods: u64,
    /// Impacts after the transient, all contacts.
    pub impacts: u64,
    /// Impacts per excitation period after the transient, all contacts.
    pub impacts_per_period: f64,
    /// The same per contact (masses' contacts, then the lower and the upper stop).
    pub impacts_per_period_by_contact: Vec<f64>,
    /// Impacts per second after the transient, 1/s.
    pub impacts_per_second: f64,
    /// Impacts after the transient per contact.
    pub impacts_by_contact: Vec<u64>,
    /// Impacts in each period (all contacts), transient included.
    pub impacts_in_each_period: Vec<u32>,
    /// Sticks after the transient.
    pub sticks: u64,
    /// Releases after the transient.
    pub releases: u64,
    /// Chatter sequences ended by an accumulation-point jump, after the transient.
    pub chatter_sequences: u64,
    /// Largest closing speed per contact after the transient, m/s.
    pub max_closing_speed_m_s: Vec<f64>,
    /// All events, transient included.
    pub events_total: u64,
    /// Samples per excitation period of the run's time history (`trajectory.csv`; absent for
    /// a run that took no periodic samples).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples_per_period: Option<u64>,
    /// Excitation period T, s.
    pub excitation_period_s: f64,
    /// Excitation angular frequency ω, rad/s.
    pub omega_rad_s: f64,
    /// Ω = ω/Ω₁, dimensionless.
    pub omega_ratio: f64,
    /// The harvester's figures (absent without a harvester).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub electrical: Option<ElectricalSummary>,
    /// The base motion, when it is not the chain's own harmonic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub base_motion: Option<BaseMotionSummary>,
    /// The paper's nondimensional groups.
    pub nondimensional: NondimGroups,
    /// The chain's parameters.
    pub parameters: ChainParams,
    /// The configuration's settings (the library's document).
    pub settings: serde_json::Value,
    /// Wall-clock time of the run, s.
    pub wall_time_s: f64,
    /// Whether the run (or its classification) was stopped by a signal.
    pub interrupted: bool,
    /// Why the run failed ([`failure_text`]).
    pub error: Option<String>,
    /// How the run settled before its first period: `fixed` or `auto`.
    pub settle: String,
    /// `auto`: most periods run before the configured run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_cap_periods: Option<u64>,
    /// A run stopped by a signal before its first period: the settling periods run by then
    /// (absent otherwise; a classified motion says how long it settled in `motion`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_periods: Option<u64>,
    /// A run stopped by a signal before its first period: the phase it was stopped in
    /// (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interrupted_while: Option<StoppedPhase>,
    /// The motion after the transient (`None`: not classified, a run that did not complete
    /// or a base motion that is not periodic).
    pub motion: Option<MotionRecord>,
    /// The figures of merit (absent where they were not computed).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub merit: Option<MeritSummary>,
}

/// The electrical part of a [`RunSummary`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElectricalSummary {
    /// Average power after the transient, W (`None`: no complete period after it).
    pub average_power_w: Option<f64>,
    /// Energy per period after the transient, J.
    pub energy_per_period_j: Option<f64>,
    /// Peak current after the transient, A.
    pub peak_current_a: Option<f64>,
    /// Peak load voltage after the transient, V.
    pub peak_voltage_v: Option<f64>,
    /// Batch-means standard error of the average power, W.
    pub average_power_se_w: Option<f64>,
    /// 95 % confidence interval of the average power from 10 batch means, W (10 periods or
    /// more).
    pub average_power_ci95_w: Option<[f64; 2]>,
    /// The running average power P_a(N) after each period N, W (seed eq. 14).
    pub power_curve: Vec<f64>,
    /// Energy delivered in each period, J.
    pub energy_in_each_period_j: Vec<f64>,
    /// The storage capacitor (rectifier loads only).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub rectifier: Option<RectifierSummary>,
    /// The worst air-breakdown ratio after the transient (if checked).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub air_breakdown: Option<BreakdownMargin>,
    /// The harvester's parameters.
    pub harvester: HarvesterParams,
    /// The charge solver's work counters, in words.
    pub electrical_solver: String,
    /// The coupled run's work counters (two-way coupling only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coupling_stats: Option<CouplingStats>,
}

/// The storage capacitor of a rectifier load in a [`RunSummary`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RectifierSummary {
    /// Storage voltage at the end of each period, V (`None` where it was not solved).
    pub storage_voltage_at_period_end_v: Vec<Option<f64>>,
    /// First time the storage voltage reached the target, s.
    pub time_to_target_s: Option<f64>,
}

/// The figures of merit of a [`RunSummary`] ([`crate::merit`]); every figure `None` with
/// fewer than two states after the transient.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeritSummary {
    /// Energy per cycle of the cycle for maximised energy output, J.
    pub cmeo_energy_per_cycle_j: Option<f64>,
    /// Zi et al.'s structural figure of merit, dimensionless.
    pub fom_s: Option<f64>,
    /// The largest ideal-switch cycle inside the breakdown boundary, J.
    pub breakdown_limited_energy_per_cycle_j: Option<f64>,
    /// The run's energy per cycle, J.
    pub energy_per_cycle_j: Option<f64>,
    /// The run's energy per cycle as a fraction of the CMEO, dimensionless.
    pub energy_fraction_of_cmeo: Option<f64>,
    /// The whole report: the stroke, the cycles per period, the CMEO cycle's corners.
    #[serde(deserialize_with = "present")]
    pub merit: Option<MeritReport>,
}

/// A key that must be present, `null` or not: it tells whether the flattened group it belongs
/// to is there.
fn present<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Option<T>, D::Error> {
    Option::deserialize(d)
}

impl MeritSummary {
    /// The figures of `merit`.
    pub fn of(merit: Option<&MeritReport>) -> Self {
        MeritSummary {
            cmeo_energy_per_cycle_j: merit.map(|m| m.cmeo_energy_per_cycle_j),
            fom_s: merit.and_then(|m| m.fom_s),
            breakdown_limited_energy_per_cycle_j: merit.and_then(|m| m.breakdown_limited_energy_per_cycle_j),
            energy_per_cycle_j: merit.and_then(|m| m.energy_per_cycle_j),
            energy_fraction_of_cmeo: merit.and_then(|m| m.energy_fraction_of_cmeo),
            merit: merit.copied(),
        }
    }
}

impl RunSummary {
    /// The summary of a run of `spec` (read from `config`) that ended in `outcome` after
    /// `wall_time_s` seconds, settled with a fixed transient, with no motion and no figures of
    /// merit (set them with [`RunSummary::set_settle`], [`RunSummary::set_motion`] and the
    /// `merit` field).
    pub fn new(config: &Config, spec: &RunSpec, outcome: &RunOutcome, wall_time_s: f64) -> Self {
        let params = &spec.chain;
        let stats = &outcome.stats;
        let done = outcome.periods;
        let per_contact = stats.impacts_per_period(done);
        let after = stats.impacts_after_transient();
        let electrical = match (&outcome.electrical, &spec.harvester) {
            (Some(e), Some(h)) => Some(ElectricalSummary::new(e, &h.params, spec.transient_periods)),
            _ => None,
        };
        RunSummary {
            command: SummaryCommand::Simulate,
            periods: done,
            periods_requested: spec.periods,
            transient_periods: spec.transient_periods,
            impacts: after.iter().sum(),
            impacts_per_period: per_contact.iter().sum(),
            impacts_per_second: per_contact.iter().sum::<f64>() / params.period(),
            impacts_per_period_by_contact: per_contact,
            impacts_by_contact: after,
            impacts_in_each_period: stats.impacts_by_period(done),
            sticks: stats.sticks,
            releases: stats.releases,
            chatter_sequences: stats.chatter_sequences,
            max_closing_speed_m_s: stats.max_closing_speed.clone(),
            events_total: stats.events,
            samples_per_period: match spec.sampling {
                Some(Sampling::PerPeriod(n)) => Some(n),
                _ => None,
            },
            excitation_period_s: params.period(),
            omega_rad_s: params.omega(),
            omega_ratio: params.omega_ratio(),
            electrical,
            base_motion: BaseMotionSummary::of(spec),
            nondimensional: params.nondimensional(),
            parameters: params.clone(),
            settings: serde_json::to_value(config.table()).unwrap_or_default(),
            wall_time_s,
            interrupted: outcome.ending == Ending::Stopped,
            error: failure_text(outcome),
            settle: SettleMode::Fixed.as_str().to_string(),
            settle_cap_periods: None,
            settle_periods: None,
            interrupted_while: None,
            motion: None,
            merit: None,
        }
    }

    /// The summary of a run of `spec` (read from `config`) stopped by a signal while it settled
    /// by `mode`, after `settle_periods` settling periods and `wall_time_s` seconds: no period
    /// of the configured run computed (`periods` 0, every count zero, no electrical figures,
    /// no motion), `interrupted` true and `interrupted_while` settling.
    pub fn stopped_while_settling(
        config: &Config,
        spec: &RunSpec,
        mode: &SettleMode,
        settle_periods: u64,
        wall_time_s: f64,
    ) -> Self {
        let chain = &spec.chain;
        let nothing = RunOutcome {
            periods: 0,
            ending: Ending::Stopped,
            stats: RunStats::new(chain.contact_count(), chain.period(), spec.transient_periods),
            electrical: None,
            final_state: spec.initial.clone(),
            final_time: 0.0,
        };
        let mut summary = RunSummary::new(config, spec, &nothing, wall_time_s);
        summary.set_settle(mode);
        summary.settle_periods = Some(settle_periods);
        summary.interrupted_while = Some(StoppedPhase::Settling);
        summary
    }

    /// Records that the run settled by `mode` (its cap with [`SettleMode::Auto`]).
    pub fn set_settle(&mut self, mode: &SettleMode) {
        self.settle = mode.as_str().to_string();
        self.settle_cap_periods = match mode {
            SettleMode::Auto(a) => Some(a.cap_periods),
            SettleMode::Fixed => None,
        };
    }

    /// Records the motion after the transient (`None`: not classified).
    pub fn set_motion(&mut self, motion: Option<&MotionReport>) {
        self.motion = motion.map(MotionRecord::of);
    }
}

impl ElectricalSummary {
    /// The figures of the harvester `params` in the run's electrical outcome `e`, the power
    /// averaged after `transient` periods.
    fn new(e: &crate::study::ElectricalOutcome, params: &HarvesterParams, transient: u64) -> Self {
        let s = e.power.as_ref();
        let se = e.average_power_se(transient);
        ElectricalSummary {
            average_power_w: s.map(|s| s.average_power_w),
            energy_per_period_j: s.map(|s| s.energy_per_period_j),
            peak_current_a: s.map(|s| s.peak_current_a),
            peak_voltage_v: s.map(|s| s.peak_voltage_v),
            average_power_se_w: se,
            // Student's t with 9 degrees of freedom over the 10 batch means.
            average_power_ci95_w: s
                .filter(|s| s.periods >= 10)
                .zip(se)
                .map(|(s, se)| [s.average_power_w - T_975_9 * se, s.average_power_w + T_975_9 * se]),
            power_curve: e.power_curve(),
            energy_in_each_period_j: e.periods.iter().map(|p| p.energy_j).collect(),
            rectifier: (params.load.kind() == LoadKind::Rectifier).then(|| RectifierSummary {
                storage_voltage_at_period_end_v: e.periods.iter().map(|p| p.storage_voltage_v).collect(),
                time_to_target_s: e.time_to_target,
            }),
            air_breakdown: e.breakdown,
            harvester: params.clone(),
            electrical_solver: format!("{:?}", e.solver),
            coupling_stats: e.coupling,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::study::simulate;

    /// The summary's counts are those of the run's statistics, and a failed run says after
    /// how many periods and why.
    #[test]
    fn summary_counts_and_failure() {
        let config = Config::default()
            .with("run.periods", 12.into())
            .and_then(|c| c.with("run.transient_periods", 4.into()))
            .unwrap();
        let spec = config.run_spec(false);
        let outcome = simulate(&spec, &mut ()).unwrap();
        let s = RunSummary::new(&config, &spec, &outcome, 0.5);
        assert_eq!(s.periods, 12);
        assert_eq!(
            s.impacts,
            outcome.stats.impacts_after_transient().iter().sum::<u64>()
        );
        assert_eq!(s.error, None);
        assert!(!s.interrupted);
        let power = s.electrical.as_ref().and_then(|e| e.average_power_w);
        assert!(power.is_some_and(|p| p > 0.0), "{power:?}");

        // Two events per period at most: the default case cannot run.
        let tight = config.with("options.max_events_per_period", 2.into()).unwrap();
        let spec = tight.run_spec(true);
        let outcome = simulate(&spec, &mut ()).unwrap();
        let text = failure_text(&outcome).expect("the run fails");
        assert!(
            text.starts_with(&format!(
                "simulation stopped after {} complete periods: ",
                outcome.periods
            )),
            "{text}"
        );
        assert!(text.contains(&outcome.failure().unwrap().to_string()), "{text}");
        assert_eq!(
            RunSummary::new(&tight, &spec, &outcome, 0.0).error.as_deref(),
            Some(text.as_str())
        );
    }

    /// A summary written and read back is the same summary, and its text the same text: with
    /// a harvester and figures of merit, and without (the optional groups absent, not null).
    #[test]
    fn a_summary_round_trips_through_its_text() {
        let config = Config::default()
            .with("run.periods", 6.into())
            .and_then(|c| c.with("run.transient_periods", 2.into()))
            .unwrap();
        for mechanics_only in [false, true] {
            let spec = config.run_spec(mechanics_only);
            let outcome = simulate(&spec, &mut ()).unwrap();
            let mut s = RunSummary::new(&config, &spec, &outcome, 0.25);
            if !mechanics_only {
                s.merit = Some(MeritSummary::of(None));
            }
            let text = serde_json::to_string_pretty(&s).unwrap();
            let back: RunSummary = serde_json::from_str(&text).unwrap();
            assert_eq!(back, s);
            assert_eq!(serde_json::to_string_pretty(&back).unwrap(), text);
            assert_eq!(text.contains("\"merit\""), !mechanics_only, "{text}");
            assert_eq!(text.contains("\"harvester\""), !mechanics_only, "{text}");
        }
    }
}
