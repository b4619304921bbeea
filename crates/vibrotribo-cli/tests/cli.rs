//! Integration tests of the `vibrotribo` binary: file contracts, and clear errors on bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn vibrotribo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(args)
        .output()
        .expect("cannot run vibrotribo")
}

fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    (header, rows)
}

fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/reference")
}

#[test]
fn default_run_prints_a_summary() {
    let o = vibrotribo(&["simulate"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("6.00 impacts/period"), "{out}");
}

#[test]
fn output_files_follow_the_contract() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "simulate",
        "--out",
        d,
        "--set",
        "run.periods=40",
        "--set",
        "run.transient_periods=30",
        "--set",
        "run.samples_per_period=50",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("events.csv"));
    assert_eq!(header[..4], ["time_s", "kind", "contact", "rel_velocity_m_s"]);
    // The impacts are those of the independent reference (shared/reference).
    let text = std::fs::read_to_string(reference_dir().join("default-case-impacts.csv")).unwrap();
    let reference: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.trim().split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let impacts: Vec<&Vec<String>> = rows.iter().filter(|r| r[1] == "impact").collect();
    assert_eq!(impacts.len(), reference.len());
    for (r, ours) in reference.iter().zip(&impacts) {
        let t: f64 = ours[0].parse().unwrap();
        let v: f64 = ours[3].parse().unwrap();
        assert_eq!(ours[2], format!("{}", r[1] as usize));
        assert!((t - r[0]).abs() < 1e-9 && (v - r[2]).abs() < 1e-7 * r[2]);
    }
    let (header, rows) = read_csv(&dir.path().join("trajectory.csv"));
    assert_eq!(
        header[..7],
        ["time_s", "x1_m", "x2_m", "x3_m", "v1_m_s", "v2_m_s", "v3_m_s"]
    );
    assert_eq!(rows.len(), 40 * 50 + 1);
    let last: f64 = rows.last().unwrap()[0].parse().unwrap();
    assert!((last - 40.0 * 0.17951958020513104).abs() < 1e-12);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    for key in [
        "periods",
        "transient_periods",
        "impacts",
        "impacts_per_period",
        "sticks",
        "chatter_sequences",
    ] {
        assert!(summary.get(key).is_some(), "summary.json lacks {key}");
    }
    assert_eq!(summary["periods"], 40);
    assert_eq!(summary["impacts"], 60);
    assert_eq!(summary["impacts_per_period"], 6.0);
}

#[test]
fn chatter_case_from_a_config_file() {
    let dir = tempdir();
    let cfg = dir.path().join("chatter.toml");
    std::fs::write(
        &cfg,
        "[oscillator]\nmasses = [0.05, 0.15, 0.05]\ngaps = [0.005, 0.005]\n\n[excitation]\nomega_ratio = 0.60\n\n[run]\nperiods = 20\ntransient_periods = 10\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = vibrotribo(&["simulate", cfg.to_str().unwrap(), "--out", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["chatter_sequences"].as_u64().unwrap() > 0);
    assert!(summary["sticks"].as_u64().unwrap() > 0);
    let (_, rows) = read_csv(&out.join("events.csv"));
    assert!(rows.iter().any(|r| r[1] == "chatter"));
}

#[test]
fn bad_input_is_named() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["simulate", "--set", "oscillator.mases=[1,2,3]"],
            "unknown parameter `oscillator.mases`",
        ),
        (
            &["simulate", "--set", "oscillator.masses=[0.1,-0.2,0.1]"],
            "oscillator.masses[1] = -0.2",
        ),
        (
            &["simulate", "--set", "excitation.amplitude=nan"],
            "excitation.amplitude = NaN",
        ),
        (
            &["simulate", "--set", "oscillator.restitution=2"],
            "must lie in [0, 1]",
        ),
        (
            &["simulate", "--set", "oscillator.gaps=[0.02]"],
            "oscillator.gaps has 1 entries, expected 2",
        ),
        (
            &["simulate", "--set", "run.initial_positions=[0,0.05,0]"],
            "interpenetrates at contact 1",
        ),
        (
            &["simulate", "--set", "run.periods=0"],
            "run.periods must be at least 1",
        ),
        (&["simulate", "--set", "omega_ratio"], "expected key=value"),
        (
            &["simulate", "/no/such/file.toml"],
            "cannot read configuration /no/such/file.toml",
        ),
    ];
    for (args, expected) in cases {
        let o = vibrotribo(args);
        assert!(!o.status.success(), "{args:?} should fail");
        let err = stderr(&o);
        assert!(
            err.contains(expected),
            "{args:?}: expected {expected:?} in {err:?}"
        );
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    }
    let dir = tempdir();
    let cfg = dir.path().join("bad.toml");
    std::fs::write(&cfg, "[oscillator]\nmases = [0.1, 0.2]\n").unwrap();
    let o = vibrotribo(&["simulate", cfg.to_str().unwrap()]);
    assert!(stderr(&o).contains("unknown field `mases`"), "{}", stderr(&o));
    std::fs::write(&cfg, "[oscillator]\nmasses = [0.1, 0.2\n").unwrap();
    let o = vibrotribo(&["simulate", cfg.to_str().unwrap()]);
    assert!(stderr(&o).contains("not valid TOML"), "{}", stderr(&o));
}
