//! `vibrotribo response` and `band-response`: their files and manifests, the sweeps against
//! `sweep --continuation up|down` (the same points), `plot DIR`, a consistent incomplete
//! result after SIGINT, and errors that name the problem.

use std::process::{Command, Stdio};

use crate::util::{read_csv, stderr, tempdir, vibrotribo};

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The paper's chain at a 2 mm base amplitude, where an impacting and a non-impacting motion
/// coexist between Ω ≈ 0.70 and 0.79.
const HYSTERESIS: [&str; 2] = ["--set", "excitation.amplitude=0.002"];

/// The files and their contract; each sweep's powers are `sweep --continuation up|down`'s,
/// value for value; the branches follow the fold where the up sweep jumps; `plot DIR`
/// draws the picture again.
#[test]
fn files_agree_with_the_sweeps_and_plot_draws_them() {
    let dir = tempdir();
    let out = dir.path().join("r");
    let o = vibrotribo(&[
        "response",
        HYSTERESIS[0],
        HYSTERESIS[1],
        "--from",
        "0.7",
        "--to",
        "0.84",
        "--steps",
        "8",
        "--branches",
        "--out",
        out.to_str().unwrap(),
        "--plot",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&out.join("response.csv"));
    assert_eq!(
        h[..5],
        [
            "param",
            "power_up_w",
            "power_down_w",
            "power_se_up_w",
            "power_se_down_w"
        ]
    );
    assert_eq!(rows.len(), 8);
    for (direction, column) in [("up", 1), ("down", 2)] {
        let sweep = dir.path().join(direction);
        let o = vibrotribo(&[
            "sweep",
            HYSTERESIS[0],
            HYSTERESIS[1],
            "--param",
            "excitation.omega_ratio",
            "--from",
            "0.7",
            "--to",
            "0.84",
            "--steps",
            "8",
            "--continuation",
            direction,
            "--out",
            sweep.to_str().unwrap(),
            "-q",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let (_, srows) = read_csv(&sweep.join("summary.csv"));
        for s in &srows {
            let r = rows.iter().find(|r| r[0] == s[0]).unwrap();
            assert_eq!(r[column], s[1], "{direction} sweep at {}", s[0]);
        }
    }
    let m = json(&out.join("response.json"));
    assert_eq!(m["command"], "response");
    assert_eq!(m["complete"], true);
    assert_eq!(m["up"]["done"], 8);
    let band = &m["bandwidth"];
    assert!(band["peak_power_w"].as_f64().unwrap() > 0.0);
    // The up sweep rides the impacting motion to the fold; its band ends there.
    let folds: Vec<f64> = m["branches"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|b| b["bifurcations"].as_array().unwrap().clone())
        .filter(|f| f["kind"] == "fold")
        .map(|f| f["at"].as_f64().unwrap())
        .collect();
    assert!(folds.iter().any(|f| (0.78..0.80).contains(f)), "{folds:?}");
    let (bh, brows) = read_csv(&out.join("branches.csv"));
    assert_eq!(
        bh,
        [
            "branch",
            "period",
            "param",
            "stable",
            "power_w",
            "max_abs_multiplier",
            "impacts_per_period"
        ]
    );
    assert!(brows.len() > 20);
    let png = out.join("response.png");
    assert!(png.exists());
    std::fs::remove_file(&png).unwrap();
    let o = vibrotribo(&["plot", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(png.exists() && out.join("response.svg").exists());
}

/// SIGINT stops the sweeps at their next value: exit status 130, and files that hold the
/// values done, marked incomplete.
#[test]
fn sigint_leaves_a_consistent_incomplete_result() {
    let dir = tempdir();
    let out = dir.path().join("r");
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args([
            "response",
            "--from",
            "0.5",
            "--to",
            "1.0",
            "--steps",
            "400",
            "--recorded",
            "200",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(400));
    let pid = child.id().to_string();
    Command::new("kill").args(["-INT", &pid]).status().unwrap();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "exit status after SIGINT");
    let m = json(&out.join("response.json"));
    assert_eq!(m["complete"], false);
    let done = m["up"]["done"].as_u64().unwrap() + m["down"]["done"].as_u64().unwrap();
    let (_, rows) = read_csv(&out.join("response.csv"));
    assert_eq!(rows.len(), 400, "a row per value");
    let filled =
        rows.iter().filter(|r| !r[1].is_empty()).count() + rows.iter().filter(|r| !r[2].is_empty()).count();
    assert_eq!(filled as u64, done, "the values done have their power");
    assert!(done < 800);
    // The up sweep's from the start, the down sweep's from the end.
    let up: Vec<bool> = rows.iter().map(|r| !r[1].is_empty()).collect();
    assert!(
        up.windows(2).all(|w| w[0] || !w[1]),
        "up values are a run from --from"
    );
}

/// `band-response` on band-limited noise: files, manifest, picture.
#[test]
fn band_response_files() {
    let dir = tempdir();
    let cfg = dir.path().join("noise.toml");
    std::fs::write(
        &cfg,
        "[excitation]\nkind = \"random\"\nrms_acceleration = 20.0\nf_low_hz = 4.0\nf_high_hz = 8.0\nseed = 1\n\
         omega_ratio = 0.7\n[run]\nperiods = 20\ntransient_periods = 8\nstart_relative_to_base = true\n",
    )
    .unwrap();
    let out = dir.path().join("b");
    let o = vibrotribo(&[
        "band-response",
        cfg.to_str().unwrap(),
        "--from",
        "4",
        "--to",
        "10",
        "--steps",
        "4",
        "--seeds",
        "3",
        "--out",
        out.to_str().unwrap(),
        "--plot",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&out.join("response.csv"));
    assert_eq!(
        h[..5],
        ["centre_hz", "f_low_hz", "f_high_hz", "power_w", "power_se_w"]
    );
    assert_eq!(rows.len(), 4);
    // The band keeps the configured width, 4 Hz, centred on each value.
    assert_eq!(rows[0][1..3], ["2", "6"]);
    let (_, seeds) = read_csv(&out.join("seeds.csv"));
    assert_eq!(seeds.len(), 12);
    let m = json(&out.join("band_response.json"));
    assert_eq!(m["command"], "band-response");
    assert_eq!(m["seeds"], serde_json::json!([1, 2, 3]));
    assert!(out.join("response.png").exists());
}

/// Bad input is an error naming it, never a panic.
#[test]
fn errors_name_the_problem() {
    let dir = tempdir();
    let cfg = dir.path().join("noise.toml");
    std::fs::write(
        &cfg,
        "[excitation]\nkind = \"random\"\nrms_acceleration = 20.0\nf_low_hz = 4.0\nf_high_hz = 8.0\nomega_ratio = 0.7\n",
    )
    .unwrap();
    let noise = cfg.to_str().unwrap();
    let one_mass = crate::util::config_file("impact_oscillator.toml");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["response", "--from", "0.8", "--to", "0.6", "--steps", "3"],
            "--from below --to",
        ),
        (
            vec!["response", "--from", "0.6", "--to", "0.8", "--steps", "0"],
            "--steps",
        ),
        (
            vec![
                "response",
                "--param",
                "no.such_key",
                "--from",
                "0.6",
                "--to",
                "0.8",
                "--steps",
                "3",
            ],
            "no.such_key",
        ),
        (
            vec!["response", "--from", "-0.6", "--to", "0.8", "--steps", "3"],
            "excitation.omega_ratio",
        ),
        (
            vec!["response", noise, "--from", "0.6", "--to", "0.8", "--steps", "3"],
            "periodic",
        ),
        (
            vec![
                "response",
                one_mass.to_str().unwrap(),
                "--from",
                "0.6",
                "--to",
                "0.8",
                "--steps",
                "3",
            ],
            "no harvester",
        ),
        (
            vec![
                "response",
                "--from",
                "0.6",
                "--to",
                "0.8",
                "--steps",
                "3",
                "--branch-seeds",
                "0",
            ],
            "--branch-seeds",
        ),
        (
            vec!["response", "--from", "0.6", "--to", "0.8", "--steps", "100000000"],
            "--steps",
        ),
        (
            vec!["band-response", "--from", "4", "--to", "8", "--steps", "3"],
            "excitation.kind = \"random\"",
        ),
        (
            vec!["band-response", noise, "--from", "1", "--to", "8", "--steps", "3"],
            "half the width",
        ),
        (
            vec![
                "band-response",
                noise,
                "--from",
                "4",
                "--to",
                "8",
                "--steps",
                "3",
                "--width",
                "-1",
            ],
            "--width",
        ),
        (
            vec![
                "band-response",
                noise,
                "--from",
                "4",
                "--to",
                "8",
                "--steps",
                "3",
                "--seeds",
                "0",
            ],
            "--seeds",
        ),
    ];
    for (args, expected) in cases {
        let o = vibrotribo(&args);
        assert!(!o.status.success(), "{args:?} should fail");
        let err = stderr(&o);
        assert!(
            err.contains(expected),
            "{args:?}: expected {expected:?} in {err:?}"
        );
        assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    }
}
