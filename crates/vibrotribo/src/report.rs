//! What a run reports: the summary of one [`simulate`](crate::study::simulate) run as the
//! command line writes it to `summary.json` and Python returns it as a dict, built in one
//! place so that both hold the same keys and the same numbers.

use std::error::Error;
use std::fmt::Write as _;

use serde_json::json;

use crate::config::Config;
use crate::electrical::LoadKind;
use crate::study::{Ending, Motion, MotionReport, RunOutcome, RunSpec};

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

/// The summary of a run of `spec` (read from `config`) that ended in `outcome` after
/// `wall_time_s` seconds: periods, impacts (after the transient, in all, per period and per
/// contact), sticks, releases, chatter sequences, the largest closing speeds, the excitation;
/// with a harvester the average power, energy per period, peak current and voltage, the
/// running power curve, per-period energies (and storage voltages with a rectifier), the
/// air-breakdown margin and the harvester's parameters; then the nondimensional groups,
/// the chain's parameters, the configuration's settings, the wall time, whether the run was
/// interrupted and why it failed ([`failure_text`]). Units are in the key names (`_w`, `_j`,
/// `_a`, `_v`, `_s`, `_m_s`, `_rad_s`).
pub fn run_summary(
    config: &Config,
    spec: &RunSpec,
    outcome: &RunOutcome,
    wall_time_s: f64,
) -> serde_json::Value {
    let params = &spec.chain;
    let stats = &outcome.stats;
    let done = outcome.periods;
    let per_contact = stats.impacts_per_period(done);
    let after = stats.impacts_after_transient();
    let mut out = json!({
        "periods": done,
        "periods_requested": spec.periods,
        "transient_periods": spec.transient_periods,
        "impacts": after.iter().sum::<u64>(),
        "impacts_per_period": per_contact.iter().sum::<f64>(),
        "impacts_per_period_by_contact": per_contact,
        "impacts_per_second": per_contact.iter().sum::<f64>() / params.period(),
        "impacts_by_contact": after,
        "impacts_in_each_period": stats.impacts_by_period(done),
        "sticks": stats.sticks,
        "releases": stats.releases,
        "chatter_sequences": stats.chatter_sequences,
        "max_closing_speed_m_s": stats.max_closing_speed,
        "events_total": stats.events,
        "excitation_period_s": params.period(),
        "omega_rad_s": params.omega(),
        "omega_ratio": params.omega_ratio(),
    });
    let obj = out.as_object_mut().expect("a JSON object");
    if let (Some(e), Some(h)) = (&outcome.electrical, &spec.harvester) {
        let s = &e.power;
        obj.insert(
            "average_power_w".into(),
            json!(s.as_ref().map(|s| s.average_power_w)),
        );
        obj.insert(
            "energy_per_period_j".into(),
            json!(s.as_ref().map(|s| s.energy_per_period_j)),
        );
        obj.insert(
            "peak_current_a".into(),
            json!(s.as_ref().map(|s| s.peak_current_a)),
        );
        obj.insert(
            "peak_voltage_v".into(),
            json!(s.as_ref().map(|s| s.peak_voltage_v)),
        );
        let se = e.average_power_se(spec.transient_periods);
        obj.insert("average_power_se_w".into(), json!(se));
        // A 95 % confidence interval from the 10 batch means (with 10 periods or more):
        // Student's t with 9 degrees of freedom, t(0.975, 9) = 2.262.
        obj.insert(
            "average_power_ci95_w".into(),
            json!(
                s.as_ref()
                    .filter(|s| s.periods >= 10)
                    .zip(se)
                    .map(|(s, se)| { [s.average_power_w - T_975_9 * se, s.average_power_w + T_975_9 * se] })
            ),
        );
        obj.insert("power_curve".into(), json!(e.power_curve()));
        obj.insert(
            "energy_in_each_period_j".into(),
            json!(e.periods.iter().map(|p| p.energy_j).collect::<Vec<_>>()),
        );
        if h.params.load.kind() == LoadKind::Rectifier {
            obj.insert(
                "storage_voltage_at_period_end_v".into(),
                json!(e.periods.iter().map(|p| p.storage_voltage_v).collect::<Vec<_>>()),
            );
            obj.insert("time_to_target_s".into(), json!(e.time_to_target));
        }
        if let Some(margin) = &e.breakdown {
            obj.insert("air_breakdown".into(), json!(margin));
        }
        obj.insert("harvester".into(), json!(h.params));
        obj.insert("electrical_solver".into(), json!(format!("{:?}", e.solver)));
        if let Some(c) = &e.coupling {
            obj.insert("coupling_stats".into(), json!(c));
        }
    }
    if let Some(base) = base_motion_json(config, spec) {
        obj.insert("base_motion".into(), base);
    }
    obj.insert("nondimensional".into(), json!(params.nondimensional()));
    obj.insert("parameters".into(), json!(params));
    obj.insert("settings".into(), json!(config.table()));
    obj.insert("wall_time_s".into(), json!(wall_time_s));
    obj.insert("interrupted".into(), json!(outcome.ending == Ending::Stopped));
    obj.insert("error".into(), json!(failure_text(outcome)));
    out
}

/// Adds a run's triboelectric figures of merit ([`crate::merit`]) to its `summary`: the keys
/// `cmeo_energy_per_cycle_j` (J), `fom_s` (dimensionless), `breakdown_limited_energy_per_cycle_j`
/// (J), `energy_per_cycle_j` (J, the run's own), `energy_fraction_of_cmeo` (dimensionless) and
/// `merit` (the whole [`MeritReport`](crate::merit::MeritReport): the stroke, the cycles per
/// period, the CMEO cycle's corners in the V–Q plane); all `null` without a harvester or with
/// fewer than two states after the transient.
pub fn insert_merit(summary: &mut serde_json::Value, merit: Option<&crate::merit::MeritReport>) {
    let Some(obj) = summary.as_object_mut() else {
        return;
    };
    obj.insert(
        "cmeo_energy_per_cycle_j".into(),
        json!(merit.map(|m| m.cmeo_energy_per_cycle_j)),
    );
    obj.insert("fom_s".into(), json!(merit.and_then(|m| m.fom_s)));
    obj.insert(
        "breakdown_limited_energy_per_cycle_j".into(),
        json!(merit.and_then(|m| m.breakdown_limited_energy_per_cycle_j)),
    );
    obj.insert(
        "energy_per_cycle_j".into(),
        json!(merit.and_then(|m| m.energy_per_cycle_j)),
    );
    obj.insert(
        "energy_fraction_of_cmeo".into(),
        json!(merit.and_then(|m| m.energy_fraction_of_cmeo)),
    );
    obj.insert("merit".into(), json!(merit));
}

/// Student's t quantile t(0.975) with 9 degrees of freedom: the 95 % interval of a mean of
/// 10 batch means is ± this × their standard error.
const T_975_9: f64 = 2.262_157_162_8;

/// What a run of `spec` (read from `config`) states about its base motion when it is not
/// the chain's own `A sin ωt` (empty then), as (name, value) lines: `kind`, `run_as` (how
/// the engine ran it), the lines of [`BaseMotion::summary`](crate::excitation::BaseMotion::summary)
/// (spline knots and error bounds, record scaling and baseline correction) and, for a
/// multisine or a random signal, what the engine ran on: `piece_degree`, `piece_intervals`,
/// `piece_displacement_error_bound_m`, `piece_velocity_error_bound_m_s`. summary.json holds
/// them as its `base_motion` object.
pub fn base_motion_lines(config: &Config, spec: &RunSpec) -> Vec<(String, String)> {
    use crate::excitation::BaseMotion;
    let Some(b) = &spec.base_motion else {
        return Vec::new();
    };
    let mut out = vec![(
        "kind".to_string(),
        config.excitation().kind().as_str().to_string(),
    )];
    let on_pieces = "exact per-interval forces k_i y + c_i y' of degree-7 Chebyshev interpolants of the \
                     harmonics' displacement and velocity (a closed-form multisine in the engine is a later step)";
    let run_as = match &**b {
        BaseMotion::Harmonics(h) if crate::dynamics::as_chain_harmonic(h, &spec.chain).is_some() => {
            "the harmonic excitation A sin ωt (closed form)".to_string()
        }
        BaseMotion::Harmonics(h) => {
            // The pieces of a multisine are built for the run's length (as the engine does).
            let end = (spec.periods as f64 * spec.chain.period()).max(spec.chain.period());
            if let Ok(a) = crate::excitation::piece_accuracy(h, end, crate::dynamics::multisine_tolerance(h))
            {
                out.extend(crate::excitation::pieces_summary(&a));
            }
            on_pieces.to_string()
        }
        BaseMotion::Pieces(_) => on_pieces.to_string(),
        BaseMotion::Spline(_) => "exact per-interval cubic forces k_i y + c_i y' of the spline".to_string(),
    };
    out.push(("run_as".into(), run_as));
    out.extend(b.summary());
    out
}

/// [`base_motion_lines`] as a JSON object (`None` under the chain's own harmonic): the
/// `base_motion` object of summary.json, sweep.json and map.json.
pub fn base_motion_json(config: &Config, spec: &RunSpec) -> Option<serde_json::Value> {
    let lines = base_motion_lines(config, spec);
    (!lines.is_empty())
        .then(|| serde_json::Value::Object(lines.into_iter().map(|(k, v)| (k, json!(v))).collect()))
}

/// summary.json's `motion` object (null for a run that did not complete): `motion`,
/// `period` (0 unless periodic), `residual`, `residual_period`, `settle_periods`,
/// `settle_ending`, `settle_rate`, `settle_periods_needed`, `newton` (period and residual
/// of a shot orbit), `lyapunov_max_1_s`, `lyapunov_spread_1_s`, `section_curve_ratio`,
/// `label_source` (`reached` or `shot` for a periodic motion), `coexisting` (period and
/// largest multiplier modulus of a stable orbit near the run that the run does not approach).
pub fn motion_json(m: Option<&MotionReport>) -> serde_json::Value {
    let Some(m) = m else {
        return serde_json::Value::Null;
    };
    let finite = |x: f64| x.is_finite().then_some(x);
    let mut j = json!({
        "motion": m.motion.as_str(),
        "period": if m.motion == Motion::Periodic { m.residual_period } else { 0 },
        "residual": finite(m.residual),
        "residual_period": m.residual_period,
        "settle_periods": m.settle_periods,
        "settle_ending": m.settle_ending.as_str(),
        "settle_rate": m.rate,
        "settle_periods_needed": m.periods_needed,
        "newton": m.shot.map(|(p, r)| json!({"period": p, "residual": r})),
        "lyapunov_max_1_s": m.lyapunov.map(|l| l.0).and_then(finite),
        "lyapunov_spread_1_s": m.lyapunov.map(|l| l.1).and_then(finite),
        "section_curve_ratio": m.curve_ratio,
        "label_source": m.label_source.map(|s| s.as_str()),
        "coexisting": m.coexisting.map(|(p, r)| json!({"period": p, "max_abs_multiplier": r})),
    });
    if let Some(skipped) = m.lyapunov_skipped {
        j["lyapunov_skipped"] = json!(skipped.to_string());
    }
    j
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
        let s = run_summary(&config, &spec, &outcome, 0.5);
        assert_eq!(s["periods"], 12);
        assert_eq!(
            s["impacts"],
            outcome.stats.impacts_after_transient().iter().sum::<u64>()
        );
        assert_eq!(s["error"], serde_json::Value::Null);
        assert_eq!(s["interrupted"], false);
        assert!(s["average_power_w"].as_f64().unwrap() > 0.0);

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
        assert_eq!(run_summary(&tight, &spec, &outcome, 0.0)["error"], text.as_str());
    }
}
