//! Base motions other than one sine on the command line: the shipped record
//! configuration runs and states its base motion; sweeps and maps run under it; the
//! stroboscopic tools refuse it, naming the reason.

use crate::util::*;

/// `configs/record_default.toml` (a seismic record scaled to a 1 g peak) runs for 5 periods;
/// summary.json states the base motion (kind, record scaling, baseline correction), and the
/// trajectory's base column is the record's displacement: its second difference over the
/// sample spacing h is the base acceleration, whose largest magnitude is the stated peak
/// (9.8 m/s², to the O(h²) of the difference and the baseline correction's size).
#[test]
fn the_record_configuration_simulates_and_states_its_base_motion() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let config = config_file("record_default.toml");
    let o = vibrotribo(&[
        "simulate",
        config.to_str().unwrap(),
        "--set",
        "run.periods=5",
        "--set",
        "run.transient_periods=2",
        "--set",
        "run.samples_per_period=2000",
        "--out",
        d,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        out.contains("base motion:") && out.contains("kind: record"),
        "{out}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    let b = &summary["base_motion"];
    assert_eq!(b["kind"], "record");
    assert_eq!(b["record_scale_factor"], "9.8e0");
    assert!(b["baseline_relative_size"].is_string(), "{b}");
    assert!(b["run_as"].as_str().unwrap().contains("k_i y + c_i y'"));
    let (header, rows) = read_csv(&dir.path().join("trajectory.csv"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (ct, cy) = (col("time_s"), col("y_m"));
    let t: Vec<f64> = rows.iter().map(|r| r[ct].parse().unwrap()).collect();
    let y: Vec<f64> = rows.iter().map(|r| r[cy].parse().unwrap()).collect();
    assert_eq!(t.len(), 5 * 2000 + 1);
    let h = t[1] - t[0];
    let peak = (1..y.len() - 1)
        .map(|j| ((y[j + 1] - 2.0 * y[j] + y[j - 1]) / (h * h)).abs())
        .fold(0.0, f64::max);
    // The first 0.9 s of the record hold its largest acceleration or not: the peak over them
    // is at most the stated one.
    assert!(peak > 0.1 && peak < 9.8 * 1.01, "peak base acceleration {peak}");
}

#[test]
fn sweeps_and_maps_run_under_a_record() {
    let config = config_file("record_default.toml");
    let c = config.to_str().unwrap();
    let dir = tempdir();
    let d = dir.path().join("sw");
    let o = vibrotribo(&[
        "sweep",
        c,
        "--param",
        "excitation.peak_acceleration",
        "--from",
        "5",
        "--to",
        "10",
        "--steps",
        "3",
        "--transient",
        "2",
        "--recorded",
        "3",
        "-q",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(manifest["base_motion"]["kind"], "record");
    assert_eq!(manifest["settle"], "fixed");
    let o = vibrotribo(&[
        "map",
        c,
        "--x",
        "excitation.peak_acceleration",
        "--x-from",
        "5",
        "--x-to",
        "10",
        "--x-steps",
        "2",
        "--y",
        "gap_ratio",
        "--y-from",
        "1",
        "--y-to",
        "1.5",
        "--y-steps",
        "2",
        "--transient",
        "2",
        "--recorded",
        "3",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn stroboscopic_tools_refuse_non_periodic_input() {
    let config = config_file("record_default.toml");
    let c = config.to_str().unwrap();
    let sweep = [
        "sweep",
        c,
        "--param",
        "excitation.peak_acceleration",
        "--from",
        "5",
        "--to",
        "6",
        "--steps",
        "2",
    ];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["periodic", c], "periodic orbits"),
        (vec!["lyapunov", c], "Lyapunov exponents"),
        ([&sweep[..], &["--floquet"]].concat(), "--floquet"),
        (
            [&sweep[..], &["--continuation", "up"]].concat(),
            "sweep --continuation",
        ),
        (vec!["simulate", c, "--settle", "auto"], "--settle auto"),
    ];
    for (args, what) in cases {
        let o = vibrotribo(&args);
        assert!(!o.status.success(), "{args:?}");
        let e = stderr(&o);
        assert!(
            e.contains(what) && e.contains("periodic with the reference period") && e.contains("record"),
            "{args:?}: {e}"
        );
    }
}

/// Under the record (non-periodic input) summary.json gives the average power with its
/// confidence interval over windows: recomputed here from `energy_in_each_period_j` (the
/// periods after the transient in 10 consecutive batches, the batch means' standard error
/// times Student's t(0.975, 9) = 2.262), and the impact rate per second from the impacts per
/// period and T.
#[test]
fn non_periodic_runs_state_power_with_its_interval_and_the_impact_rate() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let config = config_file("record_default.toml");
    let o = vibrotribo(&[
        "simulate",
        config.to_str().unwrap(),
        "--set",
        "excitation.peak_acceleration=98",
        "--set",
        "run.periods=40",
        "--set",
        "run.transient_periods=10",
        "--out",
        d,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    let period = s["excitation_period_s"].as_f64().unwrap();
    let energies: Vec<f64> = s["energy_in_each_period_j"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_f64().unwrap())
        .collect();
    assert_eq!(energies.len(), 40);
    let powers: Vec<f64> = energies[10..].iter().map(|e| e / period).collect();
    let mean = powers.iter().sum::<f64>() / 30.0;
    let batches: Vec<f64> = powers.chunks(3).map(|c| c.iter().sum::<f64>() / 3.0).collect();
    let var = batches.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / 9.0;
    let se = (var / 10.0).sqrt();
    let average = s["average_power_w"].as_f64().unwrap();
    assert!((average - mean).abs() <= 1e-12 * mean, "{average} vs {mean}");
    assert!(
        (s["average_power_se_w"].as_f64().unwrap() - se).abs() <= 1e-9 * se,
        "{s}"
    );
    let ci = s["average_power_ci95_w"].as_array().unwrap();
    let (lo, hi) = (ci[0].as_f64().unwrap(), ci[1].as_f64().unwrap());
    assert!((lo - (mean - 2.262 * se)).abs() < 1e-3 * se && (hi - (mean + 2.262 * se)).abs() < 1e-3 * se);
    assert!(se > 0.0, "a seismic record's windows differ");
    let rate = s["impacts_per_second"].as_f64().unwrap();
    let per_period = s["impacts_per_period"].as_f64().unwrap();
    assert!((rate - per_period / period).abs() <= 1e-12 * rate.max(1.0));
    assert!(per_period > 0.0, "the record at 10 g impacts");
}
