//! `periodic`, `continue` and `sweep --floquet`: the file contracts, and the
//! results checked against independent runs of the simulator.

use super::util::*;

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn periodic_orbit_of_the_default_case_is_the_settled_motion() {
    let dir = tempdir();
    let o = vibrotribo(&["periodic", "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = json(&dir.path().join("periodic.json"));
    for key in [
        "period",
        "state",
        "multipliers",
        "stable",
        "impacts_per_period",
        "average_power_w",
    ] {
        assert!(p.get(key).is_some(), "periodic.json lacks {key}");
    }
    assert_eq!(p["period"], 1);
    assert_eq!(p["stable"], true);
    assert_eq!(p["impacts_per_period"], 6.0);
    let moduli: Vec<f64> = p["multipliers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m[0].as_f64().unwrap().hypot(m[1].as_f64().unwrap()))
        .collect();
    assert_eq!(moduli.len(), 6);
    assert!(
        moduli.windows(2).all(|w| w[0] >= w[1]),
        "largest first: {moduli:?}"
    );
    // The power on the orbit is the power of a long simulation settled onto it.
    let run = tempdir();
    let o = vibrotribo(&[
        "simulate",
        "-q",
        "--set",
        "run.periods=400",
        "--set",
        "run.transient_periods=300",
        "--out",
        run.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = json(&run.path().join("summary.json"));
    let (a, b) = (
        p["average_power_w"].as_f64().unwrap(),
        s["average_power_w"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 1e-6 * b, "orbit {a} W, settled run {b} W");
    // The state at the section is where that run is at a whole period.
    let (_, rows) = read_csv(&run.path().join("trajectory.csv"));
    let last = rows.last().unwrap();
    for i in 0..3 {
        let x: f64 = last[1 + i].parse().unwrap();
        let xo = p["state"][i].as_f64().unwrap();
        assert!((x - xo).abs() < 1e-9, "mass {i}: run {x} m, orbit {xo} m");
    }
}

#[test]
fn continuation_locates_the_neimark_sacker_point_where_periodic_changes_stability() {
    let dir = tempdir();
    let o = vibrotribo(&[
        "continue",
        "--param",
        "mass_ratio",
        "--from",
        "2.6",
        "--to",
        "3.0",
        "--mechanics-only",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("bifurcations.csv"));
    assert_eq!(header[..4], ["branch", "kind", "param", "precision"]);
    let ns: Vec<f64> = rows
        .iter()
        .filter(|r| r[1] == "neimark_sacker")
        .map(|r| r[2].parse().unwrap())
        .collect();
    assert_eq!(ns.len(), 1, "{rows:?}");
    let (bh, _) = read_csv(&dir.path().join("branch.csv"));
    assert_eq!(
        bh[..5],
        ["branch", "period", "param", "stable", "max_abs_multiplier"]
    );
    // Independently, shooting at either side of the point (from a simulated transient).
    let stable_at = |r: f64| {
        let d = tempdir();
        let o = vibrotribo(&[
            "periodic",
            "--mechanics-only",
            "--period",
            "1",
            "--set",
            &format!("mass_ratio={r}"),
            "--out",
            d.path().to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        json(&d.path().join("periodic.json"))["stable"].as_bool().unwrap()
    };
    assert!(stable_at(ns[0] - 0.01));
    assert!(!stable_at(ns[0] + 0.01));
}

#[test]
fn sweep_floquet_column_is_the_periodic_orbits_largest_multiplier() {
    let dir = tempdir();
    let o = vibrotribo(&[
        "sweep",
        "-q",
        "--param",
        "omega_ratio",
        "--from",
        "0.65",
        "--to",
        "0.75",
        "--steps",
        "3",
        "--transient",
        "200",
        "--recorded",
        "20",
        "--mechanics-only",
        "--floquet",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("summary.csv"));
    // The Floquet column comes before the motion columns.
    let at = header.len() - 1 - vibrotribo::sweep::MOTION_COLUMNS.len();
    assert_eq!(header[at], "max_abs_multiplier");
    let compared: Vec<&Vec<String>> = rows.iter().filter(|r| !r[at].is_empty()).collect();
    assert!(compared.len() >= 2, "{rows:?}");
    // Blank exactly where no period was detected.
    for r in &rows {
        assert_eq!(r[3] == "0", r[at].is_empty(), "{r:?}");
    }
    for r in compared {
        let w = &r[0];
        let sweep: f64 = r[at].parse().unwrap();
        let d = tempdir();
        let o = vibrotribo(&[
            "periodic",
            "--mechanics-only",
            "--set",
            &format!("omega_ratio={w}"),
            "--out",
            d.path().to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let p = json(&d.path().join("periodic.json"));
        let radius = p["multipliers"][0][0]
            .as_f64()
            .unwrap()
            .hypot(p["multipliers"][0][1].as_f64().unwrap());
        assert!(
            (sweep - radius).abs() < 1e-8,
            "Ω = {w}: sweep {sweep}, periodic {radius}"
        );
    }
}

#[test]
fn bad_orbit_input_is_an_error_not_a_hang() {
    let cases: &[(&[&str], &str)] = &[
        (&["periodic", "--period", "0"], "--period must be at least 1"),
        (
            // A non-periodic window (the paper's Fig. 19): Newton fails with its history.
            &[
                "periodic",
                "--set",
                "omega_ratio=0.3",
                "--set",
                "oscillator.masses=[0.05,0.2105,0.05]",
                "--period",
                "1",
                "--transient",
                "300",
            ],
            "residuals [",
        ),
        (
            &[
                "continue",
                "--param",
                "omega_ratio",
                "--from",
                "0.7",
                "--to",
                "0.7",
            ],
            "must be finite and different",
        ),
        (
            &["continue", "--param", "mass_ratio", "--from", "2", "--to", "-1"],
            "mass_ratio = -1",
        ),
    ];
    for (args, expected) in cases {
        let o = vibrotribo(args);
        assert!(!o.status.success(), "{args:?} should fail");
        assert!(stderr(&o).contains(expected), "{args:?}: {}", stderr(&o));
    }
}
