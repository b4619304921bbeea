//! `trajectory.csv` sometimes lacked its last sample (j·T/spp rounded past the end);
//! the air-breakdown ratio depended on `samples_per_period` and was missing without `--out`;
//! sizes had no limits (`samples_per_period=1e11` filled memory, `--steps 1e11` aborted);
//! negative option values needed `--from=-0.01`; `plot nothere` said the directory held no
//! results; a killed `simulate` left no `summary.json`.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::util::*;

#[test]
fn trajectory_has_its_last_sample() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&["simulate", "-q", "--set", "oscillator.stiffness=1e6", "--out", d]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = read_csv(&dir.path().join("trajectory.csv"));
    assert_eq!(rows.len(), 100 * 200 + 1);
    let summary: serde_json::Value = serde_json::from_str(&read(dir.path(), "summary.json")).unwrap();
    let end = 100.0 * summary["excitation_period_s"].as_f64().unwrap();
    let last: f64 = rows.last().unwrap()[0].parse().unwrap();
    assert_eq!(last, end, "the last sample is at the end of the run");
}

fn breakdown_line(stdout: &[u8]) -> String {
    String::from_utf8_lossy(stdout)
        .lines()
        .find(|l| l.contains("V_breakdown"))
        .unwrap_or_else(|| panic!("no air-breakdown line in {}", String::from_utf8_lossy(stdout)))
        .to_string()
}

#[test]
fn air_breakdown_does_not_depend_on_sampling_and_needs_no_files() {
    let no_files = vibrotribo(&["simulate", "-q"]);
    assert!(no_files.status.success());
    let line = breakdown_line(&no_files.stdout);
    for spp in ["1", "7", "200"] {
        let dir = tempdir();
        let o = vibrotribo(&[
            "simulate",
            "-q",
            "--set",
            &format!("run.samples_per_period={spp}"),
            "--out",
            dir.path().to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(breakdown_line(&o.stdout), line, "samples_per_period = {spp}");
        let summary: serde_json::Value = serde_json::from_str(&read(dir.path(), "summary.json")).unwrap();
        let ratio = summary["air_breakdown"]["worst_ratio"].as_f64().unwrap();
        assert!((0.9..1.0).contains(&ratio), "{ratio}");
    }
}

#[test]
fn sizes_beyond_sane_limits_are_refused_with_the_estimate() {
    let dir = tempdir();
    let out = dir.path().join("big");
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            [
                "simulate",
                "-q",
                "--set",
                "run.samples_per_period=100000000000",
                "--out",
            ]
            .map(String::from)
            .into_iter()
            .chain([out.to_str().unwrap().to_string()])
            .collect(),
            "trajectory.csv would be about",
        ),
        (
            ["simulate", "-q", "--set", "run.periods=1000000000000"]
                .map(String::from)
                .to_vec(),
            "GiB of memory",
        ),
        (
            [
                "sweep",
                "-q",
                "--param",
                "omega_ratio",
                "--from",
                "0.5",
                "--to",
                "1",
                "--steps",
                "100000000000",
            ]
            .map(String::from)
            .to_vec(),
            "--steps asks for 1.000e11 grid points",
        ),
        (
            [
                "map",
                "-q",
                "--x",
                "omega_ratio",
                "--x-from",
                "0.5",
                "--x-to",
                "1",
                "--x-steps",
                "1000000",
                "--y",
                "mass_ratio",
                "--y-from",
                "1",
                "--y-to",
                "3",
                "--y-steps",
                "1000000",
            ]
            .map(String::from)
            .to_vec(),
            "grid points",
        ),
    ];
    for (args, expected) in cases {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let started = Instant::now();
        let o = vibrotribo(&a);
        assert!(!o.status.success(), "{args:?} ran");
        assert!(stderr(&o).contains(expected), "{args:?}: {}", stderr(&o));
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "{args:?} took long to refuse"
        );
        assert!(!out.exists(), "{args:?} wrote files");
    }
}

#[test]
fn negative_values_and_missing_directories_are_plain() {
    let o = vibrotribo(&[
        "sweep",
        "-q",
        "--param",
        "amplitude",
        "--from",
        "-0.01",
        "--to",
        "0.02",
        "--steps",
        "3",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("excitation.amplitude = -0.01: must not be negative"),
        "{}",
        stderr(&o)
    );
    let o = vibrotribo(&["plot", "nothere"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("nothere does not exist"), "{}", stderr(&o));
}

#[test]
fn a_terminated_simulate_writes_a_summary_marked_interrupted() {
    let dir = tempdir();
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args([
            "simulate",
            "-q",
            "--set",
            "run.periods=5000000",
            "--set",
            "run.samples_per_period=1",
            "--out",
            dir.path().to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let started = Instant::now();
    while std::fs::metadata(dir.path().join("trajectory.csv")).map_or(0, |m| m.len()) < 100_000 {
        assert!(child.try_wait().unwrap().is_none(), "finished too early");
        assert!(started.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args(["-TERM", &pid])
            .status()
            .unwrap()
            .success()
    );
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(143));
    let summary: serde_json::Value = serde_json::from_str(&read(dir.path(), "summary.json")).unwrap();
    assert_eq!(summary["interrupted"], true);
    let periods = summary["periods"].as_u64().unwrap();
    assert!(periods > 0 && periods < 5_000_000);
    // The files hold exactly the periods the summary reports.
    let (_, rows) = read_csv(&dir.path().join("trajectory.csv"));
    assert_eq!(rows.len() as u64, periods + 1);
}
