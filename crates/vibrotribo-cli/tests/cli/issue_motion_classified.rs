//! Every sweep point classified honestly. A default-case sweep (`--from 0.4 --to 1.6
//! --steps 300`) called Ω = 1.20–1.45 non-periodic after a fixed 50 transient periods; with
//! the default `--settle auto` a few of those values come out `periodic`, period 1, as a
//! 600-period transient shows them to be.

use super::util::*;

/// Values of that sweep's grid in Ω = 1.20–1.45 (j = 200, 212, 237, 261 of 0…299).
const VALUES: [usize; 4] = [200, 212, 237, 261];

fn grid_value(j: usize) -> f64 {
    0.4 + (1.6 - 0.4) * j as f64 / 299.0
}

fn sweep_one(dir: &std::path::Path, omega: f64, extra: &[&str]) -> Vec<(String, String)> {
    let value = omega.to_string();
    let mut args = vec![
        "sweep",
        "-q",
        "--param",
        "omega_ratio",
        "--from",
        &value,
        "--to",
        &value,
        "--steps",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ];
    let config = config_file("default.toml");
    args.insert(1, config.to_str().unwrap());
    args.extend_from_slice(extra);
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&dir.join("summary.csv"));
    h.into_iter().zip(rows[0].clone()).collect()
}

fn cell<'a>(row: &'a [(String, String)], name: &str) -> &'a str {
    &row.iter().find(|(h, _)| h == name).unwrap().1
}

#[test]
fn default_case_high_omega_is_periodic_once_settled() {
    for j in VALUES {
        let omega = grid_value(j);
        assert!((1.2..=1.45).contains(&omega));
        let dir = tempdir();
        let auto = sweep_one(dir.path(), omega, &[]);
        assert_eq!(cell(&auto, "motion"), "periodic", "Ω = {omega}: {auto:?}");
        assert_eq!(cell(&auto, "period"), "1", "Ω = {omega}: {auto:?}");
        // The truth of the issue: a 600-period fixed transient.
        let long = tempdir();
        let fixed = sweep_one(long.path(), omega, &["--settle", "fixed", "--transient", "600"]);
        assert_eq!(cell(&fixed, "period"), "1", "Ω = {omega}: {fixed:?}");
        let (a, b): (f64, f64) = (
            cell(&auto, "average_power_w").parse().unwrap(),
            cell(&fixed, "average_power_w").parse().unwrap(),
        );
        assert!((a - b).abs() < 1e-6 * b, "Ω = {omega}: {a} vs {b}");
        let m = manifest(dir.path(), "sweep.json");
        assert_eq!(m["settle"], "auto");
        assert_eq!(m["settle_cap_periods"], 2000);
    }
    // The fixed default transient (50 periods) is what misled: not periodic there.
    let dir = tempdir();
    let fixed = sweep_one(dir.path(), grid_value(225), &["--settle", "fixed"]);
    assert_eq!(cell(&fixed, "period"), "0", "{fixed:?}");
    assert_eq!(cell(&fixed, "motion"), "settling", "{fixed:?}");
    assert!(cell(&fixed, "settle_periods_needed").parse::<f64>().unwrap() > 0.0);
}

/// `simulate` reports the motion in summary.json, with the power's standard error.
#[test]
fn simulate_reports_the_motion() {
    let dir = tempdir();
    let o = vibrotribo(&[
        "simulate",
        "-q",
        "--settle",
        "auto",
        "--set",
        "run.samples_per_period=4",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = manifest(dir.path(), "summary.json");
    assert_eq!(s["motion"]["motion"], "periodic", "{}", s["motion"]);
    assert_eq!(s["motion"]["period"], 1);
    assert_eq!(s["settle"], "auto");
    // A periodic motion delivers the same energy every period.
    assert!(s["average_power_se_w"].as_f64().unwrap() < 1e-9 * s["average_power_w"].as_f64().unwrap());
}
