//! SIGINT/SIGTERM during `continue` and `periodic`: the library's orbit solvers poll the
//! signal flag at every continuation step and Newton iteration, so the commands stop with the
//! signal's exit status; `continue` writes the branches followed so far, consistent with each
//! other and marked `"complete": false`, and a finished run is marked `"complete": true`.

use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::Duration;

use super::util::*;

/// Runs the binary, sends `signal` after `after`, and waits for it.
fn interrupted(args: &[&str], after: Duration, signal: &str) -> (ExitStatus, String) {
    let (status, err) = run_and_signal(args, after, signal);
    assert!(
        !status.success(),
        "finished before the signal: make the run longer"
    );
    (status, err)
}

/// Runs the binary, sends `signal` after `after` (if it is still running), and waits for it.
fn run_and_signal(args: &[&str], after: Duration, signal: &str) -> (ExitStatus, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let pid = child.id().to_string();
    // A child that has already exited (a zombie until waited for) ignores the signal.
    Command::new("kill").args([signal, &pid]).status().unwrap();
    let o = child.wait_with_output().unwrap();
    (o.status, String::from_utf8_lossy(&o.stderr).into_owned())
}

/// `continue` with `args` stopped by `signal` after its first orbit and before its end: the
/// delay adapts to the machine's speed (shorter when the run ended first, longer when the
/// signal came before the first orbit was written).
fn continue_interrupted(args: &[&str], dir: &Path, signal: &str) -> (ExitStatus, String) {
    let mut after = Duration::from_millis(800);
    for _ in 0..12 {
        let _ = std::fs::remove_dir_all(dir);
        let (status, err) = run_and_signal(args, after, signal);
        if status.success() {
            after /= 2;
        } else if !dir.join("continue.json").exists() && err.contains("interrupted") {
            after = after * 3 / 2;
        } else {
            return (status, err);
        }
    }
    panic!("no delay stopped `continue` between its first orbit and its end (last {after:?})");
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Branches far longer than the test waits (the chatter case over a wide range: about a
/// minute of work, the first orbit found in a fraction of a second).
fn long_continuation(config: &str, dir: &str) -> Vec<String> {
    [
        "continue",
        config,
        "--param",
        "omega_ratio",
        "--from",
        "0.5",
        "--to",
        "1.0",
        "--transient",
        "50",
        "--max-points",
        "1000000",
        "--mechanics-only",
        "-q",
        "--out",
        dir,
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn continue_stopped_by_a_signal_writes_its_branches_marked_incomplete() {
    let root = tempdir();
    for (signal, code) in [("-INT", 130), ("-TERM", 143)] {
        let dir = root.path().join(&signal[1..]);
        let d = dir.to_str().unwrap();
        let config = config_file("chatter.toml");
        let args = long_continuation(config.to_str().unwrap(), d);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (status, err) = continue_interrupted(&args, &dir, signal);
        assert_eq!(status.code(), Some(code), "{signal}: {err}");
        assert!(err.contains("interrupted"), "{err}");
        let m = json(&dir.join("continue.json"));
        assert_eq!(m["complete"], false, "{m}");
        // The manifest and the table agree: one row per point of every branch listed.
        let (header, rows) = read_csv(&dir.join("branch.csv"));
        let listed: u64 = m["branches"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["points"].as_u64().unwrap())
            .sum();
        assert!(listed >= 1, "{m}");
        assert_eq!(rows.len() as u64, listed, "{m}");
        // The branch was cut inside its range, and says it was stopped.
        let p = header.iter().position(|h| h == "param").unwrap();
        let last: f64 = rows.last().unwrap()[p].parse().unwrap();
        assert!((0.5..1.0).contains(&last), "last point at {last}");
        let ends: Vec<&str> = m["branches"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["end"].as_str().unwrap())
            .collect();
        // A child branch named by a bifurcation is one of the branches written.
        let bifurcations = m["bifurcations"].as_array().unwrap();
        for b in bifurcations {
            if let Some(c) = b["child_branch"].as_u64() {
                assert!((c as usize) < ends.len(), "{b}");
            }
        }
        // Cut while following a branch, or between branches (a doubling left unfollowed).
        let unfollowed = bifurcations
            .iter()
            .any(|b| b["kind"] == "period_doubling" && b["child_branch"].is_null());
        assert!(
            ends.iter().any(|e| e.starts_with("stopped")) || unfollowed,
            "{ends:?}"
        );
    }
}

#[test]
fn continue_run_to_its_end_is_marked_complete() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "continue",
        "--param",
        "omega_ratio",
        "--from",
        "0.7",
        "--to",
        "0.72",
        "--transient",
        "50",
        "--mechanics-only",
        "-q",
        "--out",
        d,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(json(&dir.path().join("continue.json"))["complete"], true);
}

#[test]
fn periodic_stopped_during_its_transient_exits_with_the_signal_and_writes_nothing() {
    let dir = tempdir();
    let d = dir.path().join("out");
    let args = [
        "periodic",
        "--transient",
        "100000000",
        "--mechanics-only",
        "--quiet",
        "--out",
        d.to_str().unwrap(),
    ];
    let (status, err) = interrupted(&args, Duration::from_secs(1), "-INT");
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("nothing written"), "{err}");
    assert!(!d.join("periodic.json").exists());
}
