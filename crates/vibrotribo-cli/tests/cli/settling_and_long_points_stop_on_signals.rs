//! `simulate --settle auto` settled without looking at SIGINT/SIGTERM, and a sweep's points
//! ran to their end before a signal took effect (a point of 2·10⁶ transient periods held the
//! sweep for an hour). The settling and every point poll the stop flag at each period: the
//! run stops with the signal's status and a consistent result marked incomplete (a stopped
//! point is not written; `--resume` computes it).

use std::io::Read;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use super::util::*;

/// Runs the binary, sends `signal` after `after`, and waits for it, failing if it has not
/// ended a minute after the signal (a bound against a hang, not a timing claim).
fn signalled(args: &[&str], after: Duration, signal: &str) -> (ExitStatus, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(after);
    let _ = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status();
    let asked = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if asked.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("{args:?} did not stop within a minute of {signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let mut err = String::new();
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    (status, err)
}

/// `args` stopped by `signal` while it runs: the delay grows from 0.3 s until the program
/// had installed its handlers (it exits with a status, not killed by the signal).
fn interrupted(args: &[&str], signal: &str) -> (ExitStatus, String) {
    let mut after = Duration::from_millis(300);
    for _ in 0..8 {
        let (status, err) = signalled(args, after, signal);
        assert!(
            !status.success(),
            "{args:?} finished before {signal}: make it longer"
        );
        if status.code().is_some() {
            return (status, err);
        }
        after *= 2;
    }
    panic!("{args:?}: every {signal} came before the handlers (last delay {after:?})");
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Fig. 19's window, which never repeats: `--settle auto` settles until the (huge) transient
/// has passed, far longer than the test waits.
fn long_settling(dir: &str) -> Vec<String> {
    [
        "simulate",
        "--settle",
        "auto",
        "--settle-cap",
        "100000000",
        "--set",
        "omega_ratio=0.3",
        "--set",
        "oscillator.masses=[0.05,0.2105,0.05]",
        "--set",
        "run.transient_periods=50000000",
        "--set",
        "run.periods=50000100",
        "--set",
        "run.samples_per_period=1",
        "--mechanics-only",
        "-q",
        "--allow-large",
        "--out",
        dir,
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn simulate_settling_stops_on_a_signal_and_says_so() {
    let root = tempdir();
    for (signal, code) in [("-INT", 130), ("-TERM", 143)] {
        let dir = root.path().join(&signal[1..]);
        let args = long_settling(dir.to_str().unwrap());
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (status, err) = interrupted(&args, signal);
        assert_eq!(status.code(), Some(code), "{signal}: {err}");
        assert!(err.contains("interrupted: while settling"), "{err}");
        let s = json(&dir.join("summary.json"));
        assert_eq!(s["interrupted"], true, "{s}");
        assert_eq!(s["interrupted_while"], "settling", "{s}");
        assert_eq!(s["periods"], 0, "{s}");
        let settled = s["settle_periods"].as_u64().unwrap();
        assert!(settled > 0 && settled < 50_000_000, "{s}");
        // The files hold their headers and no row: no period of the run was computed.
        for name in ["events.csv", "trajectory.csv"] {
            let (header, rows) = read_csv(&dir.join(name));
            assert!(!header.is_empty() && rows.is_empty(), "{name}: {rows:?}");
        }
        // The directory holds this job: the same command may write there again.
        assert_eq!(s["settings"]["run"]["transient_periods"], 50_000_000, "{s}");
        // The summary is a run summary like any other: `plot` and Python read it.
        let typed: vibrotribo::report::RunSummary =
            serde_json::from_value(s.clone()).expect("summary.json reads as a RunSummary");
        assert_eq!(typed.settle, "auto", "{s}");
        assert_eq!(typed.settle_cap_periods, Some(100_000_000), "{s}");
        assert!(typed.motion.is_none() && typed.electrical.is_none(), "{s}");
        assert_eq!(typed.impacts_in_each_period, Vec::<u32>::new(), "{s}");
    }
}

#[test]
fn a_sweep_stops_inside_a_long_point_and_writes_nothing_of_it() {
    let root = tempdir();
    let dir = root.path().join("out");
    let args = [
        "sweep",
        "-q",
        "--param",
        "omega_ratio",
        "--from",
        "0.7",
        "--to",
        "0.8",
        "--steps",
        "2",
        "--settle",
        "fixed",
        "--transient",
        "2000000",
        "--recorded",
        "10",
        "--mechanics-only",
        "--out",
        dir.to_str().unwrap(),
    ];
    let (status, err) = interrupted(&args, "-INT");
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted") && err.contains("--resume"), "{err}");
    let m = json(&dir.join("sweep.json"));
    assert_eq!(m["complete"], false, "{m}");
    assert_eq!(m["done"], 0, "{m}");
    for name in ["summary.csv", "orbit.csv", "impacts.csv"] {
        let (header, rows) = read_csv(&dir.join(name));
        assert!(!header.is_empty() && rows.is_empty(), "{name}: {rows:?}");
    }
}

/// A chirp of 5000 s: its base motion's spline (millions of knots, built for each chirp)
/// takes longer than the test waits; SIGINT stops the build.
#[test]
fn a_chirp_stops_while_building_its_base_motion() {
    let root = tempdir();
    let dir = root.path().join("out");
    let args = [
        "chirp",
        "-q",
        "--from",
        "0.5",
        "--to",
        "1.0",
        "--duration",
        "5000",
        "--mechanics-only",
        "--out",
        dir.to_str().unwrap(),
    ];
    let (status, err) = interrupted(&args, "-INT");
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    // Stopped before the first chirp ran: nothing, or chirp.json marked incomplete.
    if let Ok(text) = std::fs::read_to_string(dir.join("chirp.json")) {
        let m: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(m["complete"], false, "{m}");
    }
}
