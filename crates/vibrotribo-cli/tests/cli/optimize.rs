//! `vibrotribo optimize` against known optima (the default case's optimal load, found by
//! `load-sweep` as 54.1 GΩ), `simulate best.toml` against the objective, `--resume` after an
//! interruption against the uninterrupted search, and its errors.

use std::process::{Command, Stdio};

use crate::util::{stderr, tempdir, vibrotribo};

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

const LOAD: [&str; 8] = [
    "optimize",
    "--vary",
    "harvester.load_resistance=1e9..1e12",
    "--particles",
    "6",
    "--swarm-iterations",
    "3",
    "--quiet",
];

/// The default case's load optimum in one variable, and best.toml runs to the objective.
#[test]
fn load_optimum_of_the_default_case() {
    let dir = tempdir();
    let out = dir.path().join("o");
    let mut args = LOAD.to_vec();
    args.extend(["--local-iterations", "15", "--out", out.to_str().unwrap()]);
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = json(&out.join("optimize.json"));
    let r = m["best"]["harvester.load_resistance"].as_f64().unwrap();
    assert!(
        (r / 54.1e9 - 1.0).abs() < 0.01,
        "optimal load {r:e} Ω, load-sweep finds 54.1 GΩ"
    );
    let objective = m["objective"].as_f64().unwrap();
    assert!(!m["history"].as_array().unwrap().is_empty());
    let sim = dir.path().join("s");
    let o = vibrotribo(&[
        "simulate",
        out.join("best.toml").to_str().unwrap(),
        "--out",
        sim.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = json(&sim.join("summary.json"))["average_power_w"]
        .as_f64()
        .unwrap();
    assert!(
        (p - objective).abs() <= 1e-12 * objective,
        "simulate best.toml: {p} W, optimize: {objective} W"
    );
}

/// Interrupted (SIGINT) after a few designs and resumed: the same optimize.json as a search
/// never interrupted, which is itself what the seed gives twice.
#[test]
fn resume_after_interruption_gives_the_uninterrupted_result() {
    let dir = tempdir();
    let run = |out: &std::path::Path, extra: &[&str]| -> Vec<String> {
        let mut args: Vec<String> = LOAD.iter().map(|s| s.to_string()).collect();
        for a in ["--local-iterations", "6", "--seed", "5", "--out"] {
            args.push(a.into());
        }
        args.push(out.to_str().unwrap().into());
        args.extend(extra.iter().map(|s| s.to_string()));
        for a in ["--set", "run.periods=60", "--set", "run.transient_periods=40"] {
            args.push(a.into());
        }
        args
    };
    let strs = |v: &[String]| -> Vec<String> { v.to_vec() };
    let call = |v: Vec<String>| vibrotribo(&v.iter().map(String::as_str).collect::<Vec<_>>());
    let whole = dir.path().join("whole");
    let o = call(run(&whole, &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    let cut = dir.path().join("cut");
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(strs(&run(&cut, &[])))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let lines = cut.join("evaluations.jsonl");
    let mut interrupted = false;
    for _ in 0..6000 {
        let n = std::fs::read_to_string(&lines).map_or(0, |t| t.lines().count());
        if n >= 5 {
            let pid = child.id().to_string();
            Command::new("kill").args(["-INT", &pid]).status().unwrap();
            interrupted = true;
            break;
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let status = child.wait().unwrap();
    assert!(interrupted, "the search ended before it could be interrupted");
    assert_eq!(status.code(), Some(130), "exit status after SIGINT");
    assert!(!cut.join("optimize.json").exists());
    let o = call(run(&cut, &["--resume"]));
    assert!(o.status.success(), "{}", stderr(&o));
    let (a, b) = (
        json(&whole.join("optimize.json")),
        json(&cut.join("optimize.json")),
    );
    assert_eq!(a["best"], b["best"]);
    assert_eq!(a["objective"], b["objective"]);
    assert_eq!(a["history"], b["history"]);
    // Starting over in a directory that holds a search is refused.
    let o = call(run(&cut, &[]));
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--resume"), "{}", stderr(&o));
}

/// A bad range, an unknown key, an impossible or unmet constraint: errors that name them.
#[test]
fn errors_name_the_problem() {
    let dir = tempdir();
    let out = dir.path().join("e");
    let out = out.to_str().unwrap();
    for (args, expect) in [
        (
            vec!["--vary", "harvester.load_resistance=1e12..1e9"],
            "harvester.load_resistance",
        ),
        (
            vec!["--vary", "oscillator.no_such_key=1..2"],
            "oscillator.no_such_key",
        ),
        (
            vec!["--vary", "mass_ratio=2..3", "--constraint", "breakdown_ratio<=-1"],
            "breakdown_ratio",
        ),
        (
            vec!["--vary", "mass_ratio=2..3", "--objective", "most_power"],
            "most_power",
        ),
        (
            vec![
                "--vary",
                "harvester.load_resistance=1e9..1e10",
                "--constraint",
                "max_displacement<=0.001",
                "--particles",
                "2",
                "--swarm-iterations",
                "0",
                "--local-iterations",
                "0",
                "--set",
                "run.periods=20",
                "--set",
                "run.transient_periods=10",
            ],
            "max_displacement<=0.001",
        ),
    ] {
        let mut all = vec!["optimize", "--quiet", "--out", out];
        all.extend(args.iter().copied());
        let o = vibrotribo(&all);
        assert!(!o.status.success(), "{all:?} succeeded");
        assert!(stderr(&o).contains(expect), "{all:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("panicked"), "{}", stderr(&o));
        let _ = std::fs::remove_dir_all(out);
    }
}

/// The mass-ratio optimum of `optimize-mass-ratio` at Ω = 0.72 (the paper's Figs. 14–16)
/// recovered by `optimize --vary mass_ratio` within the grid step of its R_m grid (0.1). The
/// range is R_m 2.4–5, where the motion is regular (period 1 or quasi-periodic, six impacts
/// per period) and the power smooth; from R_m ≈ 5.1 on it is chaotic, its power a noisy
/// average over the recorded periods whose largest grid value neither a grid nor a search
/// can pin down.
#[test]
fn mass_ratio_optimum_at_omega_0_72() {
    let dir = tempdir();
    let grid = dir.path().join("grid");
    let o = vibrotribo(&[
        "optimize-mass-ratio",
        "--omega-from",
        "0.72",
        "--omega-to",
        "0.72",
        "--omega-steps",
        "1",
        "--rm-from",
        "2.4",
        "--rm-to",
        "5",
        "--rm-steps",
        "27",
        "--out",
        grid.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(grid.join("optimum.csv")).unwrap();
    let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    let on_grid: f64 = row[1].parse().unwrap();
    assert_eq!(row[3], "false", "the grid's optimum is inside its range");
    let out = dir.path().join("o");
    let o = vibrotribo(&[
        "optimize",
        "--set",
        "excitation.omega_ratio=0.72",
        "--vary",
        "mass_ratio=2.4..5",
        "--particles",
        "6",
        "--swarm-iterations",
        "3",
        "--local-iterations",
        "15",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let found = json(&out.join("optimize.json"))["best"]["mass_ratio"]
        .as_f64()
        .unwrap();
    println!("optimize-mass-ratio: R_mo = {on_grid}; optimize: R_m = {found}");
    assert!(
        (found - on_grid).abs() <= 0.1,
        "optimize finds R_m = {found}, optimize-mass-ratio {on_grid} (grid step 0.1)"
    );
}
