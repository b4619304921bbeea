//! Rigid stops (`[oscillator.stops.upper]`, `[oscillator.stops.lower]`): `simulate` and
//! `periodic` on the textbook impact oscillator (`configs/impact_oscillator.toml`), the contact
//! numbering of the files, and clear errors that name the key for bad stop keys and values.

use super::util::*;

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn config() -> String {
    config_file("impact_oscillator.toml")
        .to_str()
        .unwrap()
        .to_string()
}

#[test]
fn simulate_with_a_stop_numbers_it_after_the_masses_contacts() {
    let dir = tempdir();
    let c = config();
    let o = vibrotribo(&["simulate", &c, "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = read_csv(&dir.path().join("events.csv"));
    assert_eq!(header[..4], ["time_s", "kind", "contact", "rel_velocity_m_s"]);
    assert!(!rows.is_empty());
    // One mass: contact 1 is the lower stop (absent), contact 2 the upper stop. At rest the
    // mass touches the stop (gap 0), sticks while the base presses it there, then impacts.
    assert!(rows.iter().all(|r| r[2] == "2"), "{rows:?}");
    assert!(rows.iter().filter(|r| r[1] == "impact").count() > 150, "{rows:?}");
    let s = json(&dir.path().join("summary.json"));
    assert_eq!(s["impacts_per_period"], 1.0, "{s}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("m1–upper stop: 1.00"), "{out}");
}

#[test]
fn periodic_with_a_stop_has_the_closed_form_determinant() {
    let dir = tempdir();
    let c = config();
    let o = vibrotribo(&["periodic", &c, "--out", dir.path().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = json(&dir.path().join("periodic.json"));
    assert_eq!(p["period"], 1);
    assert_eq!(p["stable"], true);
    assert_eq!(p["impacts_per_period"], 1.0);
    // det of the monodromy matrix = r² e^{−2ζω_n T} (c/m = 2ζω_n), from the file's values.
    let (m, c_damp, r, omega_ratio) = (0.05f64, 0.09798f64, 0.8f64, 2.5f64);
    let wn = (120.0 / m).sqrt();
    let period = 2.0 * std::f64::consts::PI / (omega_ratio * wn);
    let want = r * r * (-c_damp / m * period).exp();
    let ms = p["multipliers"].as_array().unwrap();
    let z: Vec<(f64, f64)> = ms
        .iter()
        .map(|v| (v[0].as_f64().unwrap(), v[1].as_f64().unwrap()))
        .collect();
    let det = z[0].0 * z[1].0 - z[0].1 * z[1].1;
    assert!((det - want).abs() < 1e-9, "det {det} vs {want}");
}

fn fails_naming(extra_toml: &str, set: &[&str], needles: &[&str]) {
    let dir = tempdir();
    let path = dir.path().join("c.toml");
    let text = std::fs::read_to_string(config()).unwrap() + extra_toml;
    std::fs::write(&path, text).unwrap();
    let mut args = vec!["simulate", path.to_str().unwrap()];
    for s in set {
        args.extend(["--set", s]);
    }
    let o = vibrotribo(&args);
    assert!(!o.status.success(), "accepted {extra_toml} {set:?}");
    let err = stderr(&o);
    for n in needles {
        assert!(
            err.contains(n),
            "error for {extra_toml:?} {set:?} lacks {n:?}: {err}"
        );
    }
}

#[test]
fn bad_stop_keys_give_clear_errors() {
    fails_naming("[oscillator.stops.lower]\ngapp = 0.01\n", &[], &["gapp"]);
    fails_naming("[oscillator.stops.lower]\ngap = 0.01\n", &[], &["restitution"]);
    fails_naming(
        "",
        &["oscillator.stops.upper.restitution=1.5"],
        &["oscillator.stops.upper.restitution"],
    );
    fails_naming(
        "",
        &["oscillator.stops.upper.gap=-0.01"],
        &["oscillator.stops.upper.gap"],
    );
    fails_naming(
        "",
        &["oscillator.stops.upper.frame=moving"],
        &["oscillator.stops.upper.frame", "base"],
    );
    fails_naming(
        "",
        &["oscillator.stops.middle.gap=0.1"],
        &["oscillator.stops.middle.gap"],
    );
    fails_naming("", &["run.initial_positions=[0.01]"], &["beyond the upper stop"]);
    // Without a stop a single mass is not a chain.
    let dir = tempdir();
    let path = dir.path().join("single.toml");
    std::fs::write(&path, "[oscillator]\nmasses = [0.05]\n").unwrap();
    let o = vibrotribo(&["simulate", path.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("at least 2 masses"), "{}", stderr(&o));
}
