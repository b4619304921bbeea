//! Integration tests of the `vibrotribo` binary: file contracts, and clear errors on bad input.
//! One test target; each fixed bug has its own module (`issue_*.rs`) opening with what broke.

mod basins;
mod bifmap;
mod chirp;
mod closed_pipe_and_full_disk;
mod composition;
mod continue_and_periodic_stop_on_signals;
mod excitation;
mod export_spice_stays_in_its_run;
mod grid_jobs_on_one_mass;
mod hostile;
mod issue_grid_jobs_stop_resume_and_merge;
mod issue_motion_classified;
mod issue_plot_without_out;
mod issue_simulate_output_edges;
mod long_phases_have_a_cost_and_a_stop;
mod lyapunov;
mod map_one_parameter_twice;
mod messages_name_the_problem;
mod optimize;
mod periodic_orbits;
mod plot_dir_draws_every_kind;
mod plot_skips_empty_figures;
mod response;
mod resume_checks_files;
mod serve;
mod settling_and_long_points_stop_on_signals;
mod sizes_refused_before_allocation;
mod stops;
mod summaries_and_sections;
mod util;

use std::path::Path;

use util::*;

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
    // The impacts are those of the independent reference (crates/vibrotribo/tests/data/reference).
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
    let cfg = config_file("chatter.toml");
    let out = dir.path().join("out");
    let o = vibrotribo(&[
        "simulate",
        cfg.to_str().unwrap(),
        "--set",
        "run.periods=20",
        "--set",
        "run.transient_periods=10",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["chatter_sequences"].as_u64().unwrap() > 0);
    assert!(summary["sticks"].as_u64().unwrap() > 0);
    let (_, rows) = read_csv(&out.join("events.csv"));
    assert!(rows.iter().any(|r| r[1] == "chatter"));
}

/// `configs/default.toml` spells out every key with its default; it must describe exactly the
/// run vibrotribo makes with no configuration file (the user guide's configuration reference
/// is generated from the same defaults, `tests/config_reference.rs`).
#[test]
fn documented_default_config_is_the_default() {
    let dir = tempdir();
    let run = |cfg: Option<&str>, out: &Path| {
        let mut args = vec!["simulate"];
        args.extend(cfg);
        let out_arg = out.to_str().unwrap();
        args.extend([
            "--out",
            out_arg,
            "--set",
            "run.periods=20",
            "--set",
            "run.transient_periods=10",
        ]);
        let o = vibrotribo(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        std::fs::read_to_string(out.join("events.csv")).unwrap()
    };
    let config = config_file("default.toml");
    let from_file = run(Some(config.to_str().unwrap()), &dir.path().join("a"));
    let built_in = run(None, &dir.path().join("b"));
    assert_eq!(from_file, built_in);
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
            "interpenetrate at contact 1",
        ),
        (
            &["simulate", "--set", "run.periods=0"],
            "invalid run.periods = 0: must be at least 1",
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

#[test]
fn electrical_outputs_match_the_reference_power() {
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
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("trajectory.csv"));
    for col in ["q_c", "i_a", "v_v", "c_f", "voc_v"] {
        assert!(
            header.iter().any(|h| h == col),
            "trajectory.csv lacks {col}: {header:?}"
        );
    }
    let ci = header.iter().position(|h| h == "c_f").unwrap();
    let first_c: f64 = rows[0][ci].parse().unwrap();
    // C = ε0 S / (d0 + D1 + D2) at the start: d0 = 2 × 0.1 mm / 2.0, D = 20 mm each.
    let expected = 8.8541878128e-12 * 0.01 / (1e-4 + 0.04);
    assert!(
        (first_c - expected).abs() < 1e-12 * expected,
        "{first_c} vs {expected}"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(reference_dir().join("default-case-summary.json")).unwrap(),
    )
    .unwrap();
    let ours = summary["average_power_w"].as_f64().unwrap();
    let theirs = reference["average_power_w"]["value"].as_f64().unwrap();
    assert!(
        (ours - theirs).abs() < 1e-6 * theirs,
        "average power {ours} vs reference {theirs}"
    );
    assert_eq!(summary["power_curve"].as_array().unwrap().len(), 40);
    for key in ["energy_per_period_j", "peak_current_a", "peak_voltage_v"] {
        assert!(summary[key].as_f64().unwrap() > 0.0, "{key}");
    }
    let ratio = summary["air_breakdown"]["worst_ratio"]
        .as_f64()
        .expect("air breakdown check");
    assert!(ratio > 0.0 && ratio.is_finite());
}

#[test]
fn rectifier_run_reports_storage_voltage() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "simulate",
        "--out",
        d,
        "--set",
        "harvester.load=rectifier",
        "--set",
        "harvester.target_voltage=10",
        "--set",
        "run.periods=12",
        "--set",
        "run.transient_periods=2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap()).unwrap();
    let vs: Vec<f64> = summary["storage_voltage_at_period_end_v"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(
        vs.windows(2).all(|w| w[1] >= w[0]),
        "a bridge only charges: {vs:?}"
    );
    let t = summary["time_to_target_s"].as_f64().expect("10 V reached");
    assert!(t > 0.0 && t < 12.0 * 0.1795196);
    let (header, _) = read_csv(&dir.path().join("trajectory.csv"));
    assert!(header.iter().any(|h| h == "vs_v"));
}

#[test]
fn load_sweep_finds_the_optimum_and_power_grows_with_r_below_it() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "load-sweep",
        "--out",
        d,
        "--from",
        "1e3",
        "--to",
        "1e13",
        "--steps",
        "11",
        "--set",
        "run.periods=12",
        "--set",
        "run.transient_periods=4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("load_sweep.csv"));
    assert_eq!(
        header,
        ["load_resistance_ohm", "average_power_w", "energy_per_period_j"]
    );
    let p: Vec<f64> = rows.iter().map(|r| r[1].parse().unwrap()).collect();
    // In the quasi-static regime (R·C ≪ the motion's time scale) P = R⟨(dQ_eq/dt)²⟩ ∝ R.
    assert!(
        (p[1] / p[0] - 10.0).abs() < 0.1,
        "P(10 kΩ)/P(1 kΩ) = {}",
        p[1] / p[0]
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("load_sweep.json")).unwrap()).unwrap();
    let best = json["optimum"]["average_power_w"].as_f64().unwrap();
    assert!(p.iter().all(|&x| x <= best * (1.0 + 1e-9)));
    assert!(!json["optimum_at_edge"].as_bool().unwrap());
    let (vq_header, vq) = read_csv(&dir.path().join("vq_cycle.csv"));
    assert_eq!(vq_header[..3], ["load_resistance_ohm", "time_s", "q_c"]);
    assert_eq!(vq.len(), 2 * 401);
}

#[test]
fn export_spice_writes_a_netlist_that_ngspice_agrees_with() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "simulate",
        "--out",
        d,
        "--set",
        "run.periods=6",
        "--set",
        "run.transient_periods=3",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = vibrotribo(&["export-spice", d, "--periods", "1", "--check"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let deck = std::fs::read_to_string(dir.path().join("harvester.cir")).unwrap();
    assert!(deck.contains("PWL(") && deck.contains("tran"), "{deck}");
    let out = String::from_utf8_lossy(&o.stdout);
    let rel: f64 = out
        .split("relative difference ")
        .nth(1)
        .and_then(|s| s.split(';').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no comparison in {out}"));
    assert!(rel.abs() < 1e-3, "ngspice differs by {rel}");
}

#[test]
fn bad_harvester_input_is_named() {
    let cases: &[(&[&str], &str)] = &[
        (&["simulate", "--set", "harvester.area=-1"], "harvester.area = -1"),
        (
            &["simulate", "--set", "harvester.load_resistance=-5"],
            "harvester.load_resistance",
        ),
        (
            &["simulate", "--set", "harvester.relative_permittivity=[2, 0]"],
            "harvester.relative_permittivity[1]",
        ),
        (
            &["simulate", "--set", "harvester.mode=sliding"],
            "unknown variant `sliding`",
        ),
        (
            &["simulate", "--set", "harvester.loadd=resistor"],
            "unknown parameter `harvester.loadd`",
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
    }
}

#[test]
fn sweep_output_does_not_depend_on_the_thread_count() {
    let (a, b) = (tempdir(), tempdir());
    for (dir, threads) in [(&a, "1"), (&b, "2")] {
        let o = vibrotribo(&sweep_args(dir.path().to_str().unwrap(), &["--threads", threads]));
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for name in ["orbit.csv", "impacts.csv", "summary.csv", "sweep.json"] {
        assert_eq!(
            read(a.path(), name),
            read(b.path(), name),
            "{name} differs between 1 and 2 threads"
        );
    }
    let (header, rows) = read_csv(&a.path().join("summary.csv"));
    assert_eq!(
        header[..6],
        [
            "param",
            "average_power_w",
            "impacts_per_period",
            "period",
            "chatter",
            "sticking"
        ]
    );
    assert_eq!(rows.len(), 7);
    let (oh, orows) = read_csv(&a.path().join("orbit.csv"));
    assert_eq!(oh, ["param", "period", "x1_m", "x2_m", "x3_m"]);
    assert_eq!(orows.len(), 7 * 24);
}

#[test]
fn shards_merge_into_exactly_the_unsharded_output() {
    let whole = tempdir();
    let o = vibrotribo(&sweep_args(whole.path().to_str().unwrap(), &[]));
    assert!(o.status.success(), "{}", stderr(&o));
    let shards: Vec<tempfile::TempDir> = (0..3).map(|_| tempdir()).collect();
    for (i, dir) in shards.iter().enumerate() {
        let shard = format!("{i}/3");
        let o = vibrotribo(&sweep_args(dir.path().to_str().unwrap(), &["--shard", &shard]));
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let merged = tempdir();
    let mut args = vec!["merge", "--out", merged.path().to_str().unwrap()];
    // Shards given in any order.
    for i in [2, 0, 1] {
        args.push(shards[i].path().to_str().unwrap());
    }
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["orbit.csv", "impacts.csv", "summary.csv", "sweep.json"] {
        assert_eq!(
            read(whole.path(), name),
            read(merged.path(), name),
            "merged {name} differs"
        );
    }
    // A missing shard is refused.
    let o = vibrotribo(&[
        "merge",
        "--out",
        merged.path().to_str().unwrap(),
        shards[0].path().to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("exactly once"), "{}", stderr(&o));
}

#[test]
fn sweep_rows_agree_with_separate_simulate_runs() {
    let sweep = tempdir();
    // A fixed transient: the sweep's window is then the simulate run's.
    let o = vibrotribo(&sweep_args(
        sweep.path().to_str().unwrap(),
        &["--settle", "fixed"],
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let (sh, srows) = read_csv(&sweep.path().join("summary.csv"));
    let (_, orows) = read_csv(&sweep.path().join("orbit.csv"));
    for row in [&srows[1], &srows[5]] {
        let value = &row[0];
        let run = tempdir();
        let set = format!("excitation.omega_ratio={value}");
        let o = vibrotribo(&[
            "simulate",
            "--out",
            run.path().to_str().unwrap(),
            "--set",
            &set,
            "--set",
            "run.periods=54",
            "--set",
            "run.transient_periods=30",
            "--set",
            "run.samples_per_period=10",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let summary: serde_json::Value = serde_json::from_str(&read(run.path(), "summary.json")).unwrap();
        let ipp: f64 = row[sh.iter().position(|h| h == "impacts_per_period").unwrap()]
            .parse()
            .unwrap();
        assert_eq!(
            ipp,
            summary["impacts_per_period"].as_f64().unwrap(),
            "impacts per period at Ω = {value}"
        );
        // Average power: the sweep starts the charge solver 20 periods before its window from
        // equilibrium, simulate at t = 0; at 100 kΩ the circuit forgets within microseconds.
        let p_sweep: f64 = row[1].parse().unwrap();
        let p_sim = summary["average_power_w"].as_f64().unwrap();
        assert!(
            (p_sweep - p_sim).abs() < 1e-6 * p_sim,
            "power at Ω = {value}: {p_sweep} vs {p_sim}"
        );
        // Stroboscopic samples: trajectory.csv rows at t = nT (every 10th row).
        let (_, trows) = read_csv(&run.path().join("trajectory.csv"));
        let ours: Vec<&Vec<String>> = orows.iter().filter(|r| &r[0] == value).collect();
        assert_eq!(ours.len(), 24);
        for o in ours {
            let n: usize = o[1].parse().unwrap();
            let t = &trows[n * 10];
            for i in 0..3 {
                let a: f64 = o[2 + i].parse().unwrap();
                let b: f64 = t[1 + i].parse().unwrap();
                assert!(
                    (a - b).abs() < 1e-12,
                    "x{} at period {n}, Ω = {value}: {a} vs {b}",
                    i + 1
                );
            }
        }
    }
}

#[test]
fn sweep_continuation_and_bad_input() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&sweep_args(d, &["--continuation", "down", "--mechanics-only"]));
    assert!(o.status.success(), "{}", stderr(&o));
    let (_, rows) = read_csv(&dir.path().join("summary.csv"));
    let values: Vec<f64> = rows.iter().map(|r| r[0].parse().unwrap()).collect();
    assert!(
        values.windows(2).all(|w| w[1] < w[0]),
        "down sweeps run downwards: {values:?}"
    );
    assert!(rows.iter().all(|r| r[1].is_empty()), "mechanics only: no power");
    let cases: &[(&[&str], &str)] = &[
        (
            &[
                "sweep",
                "--param",
                "oscillator.mass",
                "--from",
                "1",
                "--to",
                "2",
                "--steps",
                "3",
            ],
            "unknown parameter `oscillator.mass`",
        ),
        (
            &[
                "sweep",
                "--param",
                "mass_ratio",
                "--from",
                "1",
                "--to",
                "2",
                "--steps",
                "3",
                "--continuation",
                "up",
                "--shard",
                "0/2",
            ],
            "--shard needs --continuation none",
        ),
        (
            &[
                "sweep",
                "--param",
                "mass_ratio",
                "--from",
                "1",
                "--to",
                "2",
                "--steps",
                "3",
                "--shard",
                "2/2",
            ],
            "need 0 ≤ I < N",
        ),
        (
            &[
                "sweep",
                "--param",
                "restitution",
                "--from",
                "0.5",
                "--to",
                "1.5",
                "--steps",
                "3",
            ],
            "must lie in [0, 1]",
        ),
    ];
    for (args, expected) in cases {
        let o = vibrotribo(args);
        let err = stderr(&o);
        // A bad value inside the range is reported in that row, a bad first value up front.
        if o.status.success() {
            panic!("{args:?} should fail, stderr: {err}");
        }
        assert!(
            err.contains(expected),
            "{args:?}: expected {expected:?} in {err:?}"
        );
    }
}

#[test]
fn map_writes_a_grid_and_heat_maps() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "map",
        "--x",
        "omega_ratio",
        "--x-from",
        "0.6",
        "--x-to",
        "0.8",
        "--x-steps",
        "3",
        "--y",
        "mass_ratio",
        "--y-from",
        "2",
        "--y-to",
        "3",
        "--y-steps",
        "2",
        "--transient",
        "20",
        "--recorded",
        "10",
        "--out",
        d,
        "--plot",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("map.csv"));
    assert_eq!(
        header[..5],
        ["x", "y", "average_power_w", "impacts_per_period", "period"]
    );
    assert_eq!(rows.len(), 6);
    let png = std::fs::read(dir.path().join("map_average_power_w.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
}
