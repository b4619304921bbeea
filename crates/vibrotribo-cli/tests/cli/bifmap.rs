//! `vibrotribo bifmap`: the curves it writes for the impact oscillator
//! (`configs/impact_oscillator.toml` with c = 0.02 N·s/m and an upper stop at a 1 mm gap)
//! against the closed form (Shaw & Holmes 1983: the grazing curve where the steady amplitude of the
//! impact-free motion equals the gap, the (1,1) orbit's doubling where `S Φ(T)` has a
//! multiplier −1); its power map against `vibrotribo map`'s, cell for cell; a stop by a
//! signal; bad input.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

#[path = "../../../vibrotribo/tests/suite/common/impact_oscillator.rs"]
mod impact_oscillator;

use impact_oscillator::ImpactOscillator;

use super::util::*;

const M: f64 = 0.05;
const K: f64 = 120.0;
const C: f64 = 0.02;
const A: f64 = 0.01;
const R: f64 = 0.8;

fn textbook(omega_ratio: f64, gap: f64) -> ImpactOscillator {
    ImpactOscillator {
        m: M,
        k: K,
        c: C,
        amplitude: A,
        omega: omega_ratio * (K / M).sqrt(),
        gap,
        r: R,
        moving: false,
    }
}

/// The steady amplitude of the impact-free motion, m.
fn steady_amplitude(omega_ratio: f64) -> f64 {
    let w = omega_ratio * (K / M).sqrt();
    A * (K * K + C * C * w * w).sqrt() / ((K - M * w * w).powi(2) + C * C * w * w).sqrt()
}

/// Where the closed-form (1,1) orbit at `gap` has a multiplier −1 between Ω = lo and hi (the
/// orbit with the largest impact speed: the one that doubles), by bisection.
fn closed_form_doubling(gap: f64, lo: f64, hi: f64) -> Option<f64> {
    let f = |w: f64| {
        let io = textbook(w, gap);
        let mut best: Option<impact_oscillator::OneOne> = None;
        for j in 0..48 {
            for v in [0.05, 0.2, 0.5] {
                if let Some(o) = io.one_one((io.period() * f64::from(j) / 48.0, v))
                    && best.is_none_or(|b| o.speed > b.speed)
                {
                    best = Some(o);
                }
            }
        }
        Some(io.doubling_function(&best?))
    };
    let (mut lo, mut hi) = (lo, hi);
    let f_lo = f(lo)?;
    if f_lo * f(hi)? > 0.0 {
        return None;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if f(mid)? * f_lo > 0.0 { lo = mid } else { hi = mid }
    }
    Some(0.5 * (lo + hi))
}

/// The impact oscillator's map in (Ω, gap), starting on the steady motion of Ω = 3.5.
fn oscillator_args(dir: &str) -> Vec<String> {
    let (x, v) = textbook(3.5, 0.001).xp(0.0);
    let config = config_file("impact_oscillator.toml");
    [
        "bifmap",
        config.to_str().unwrap(),
        "--set",
        "oscillator.damping=0.02",
        "--set",
        "oscillator.stops.upper.gap=0.001",
        "--set",
        &format!("run.initial_positions=[{x:e}]"),
        "--set",
        &format!("run.initial_velocities=[{v:e}]"),
        "--x",
        "omega_ratio",
        "--x-from",
        "2.35",
        "--x-to",
        "3.5",
        "--x-steps",
        "4",
        "--y",
        "oscillator.stops.upper.gap",
        "--y-from",
        "0.001",
        "--y-to",
        "0.0014",
        "--y-steps",
        "2",
        "--seeds",
        "2",
        "--x-starts",
        "2",
        "--kinds",
        "period_doubling,grazing",
        "--curve-points",
        "60",
        "--transient",
        "30",
        "--recorded",
        "16",
        "-q",
        "--out",
        dir,
    ]
    .map(String::from)
    .to_vec()
}

fn number(row: &[String], c: usize) -> f64 {
    row[c]
        .parse()
        .unwrap_or_else(|_| panic!("{} is not a number", row[c]))
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn the_impact_oscillators_curves_are_the_closed_forms() {
    let root = tempdir();
    let dir = root.path().join("io");
    let args = oscillator_args(dir.to_str().unwrap());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = json(&dir.join("bifmap.json"));
    assert_eq!(m["command"], "bifmap");
    assert_eq!(m["complete"], true, "{m}");
    let (h, rows) = read_csv(&dir.join("curves.csv"));
    let col = |name: &str| {
        h.iter()
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name}"))
    };
    let (cw, cg, ck, cp, cc) = (
        col("excitation.omega_ratio"),
        col("oscillator.stops.upper.gap"),
        col("kind"),
        col("period"),
        col("curve"),
    );
    // Each curve once: one grazing curve and one doubling curve of the one-impact orbit.
    let curves = m["curves"].as_array().unwrap();
    let of = |kind: &str, period: u64| {
        curves
            .iter()
            .filter(|c| c["kind"] == kind && c["period"].as_u64() == Some(period))
            .collect::<Vec<_>>()
    };
    assert_eq!(of("grazing", 1).len(), 1, "{m}");
    assert_eq!(of("period_doubling", 1).len(), 1, "{m}");
    let rows_of = |id: u64| -> Vec<&Vec<String>> {
        rows.iter()
            .filter(|r| r[cc].parse::<u64>().unwrap() == id)
            .collect()
    };
    let grazing = of("grazing", 1)[0];
    assert_eq!(grazing["contact"], 2, "the upper stop is contact 2 of one mass");
    assert_eq!(
        grazing["found_again"], 1,
        "the seed at 1.4 mm lies on the curve from 1 mm"
    );
    let g = rows_of(grazing["curve"].as_u64().unwrap());
    assert_eq!(g.len() as u64, grazing["points"].as_u64().unwrap());
    for r in &g {
        assert_eq!(r[ck], "grazing");
        let (w, gap) = (number(r, cw), number(r, cg));
        assert!(
            (steady_amplitude(w) - gap).abs() < 1e-10,
            "grazing at Ω = {w}: amplitude {} vs gap {gap}",
            steady_amplitude(w)
        );
    }
    let gaps: Vec<f64> = g.iter().map(|r| number(r, cg)).collect();
    assert!(gaps.iter().any(|&v| v <= 0.001 + 1e-12) && gaps.iter().any(|&v| v >= 0.0014 - 1e-12));
    let doubling = of("period_doubling", 1)[0];
    let d = rows_of(doubling["curve"].as_u64().unwrap());
    assert!(d.len() >= 3, "{} points", d.len());
    for r in d.iter().step_by((d.len() / 4).max(1)).chain(d.last()) {
        assert_eq!(number(r, cp), 1.0);
        let (w, gap) = (number(r, cw), number(r, cg));
        let want = closed_form_doubling(gap, w - 0.01, w + 0.01)
            .unwrap_or_else(|| panic!("no closed-form doubling near Ω = {w} at gap {gap}"));
        assert!(
            (w - want).abs() < 1e-6,
            "doubling at gap {gap}: Ω = {w} vs closed form {want}"
        );
    }
    // Every located bifurcation names the curve it lies on.
    let (lh, located) = read_csv(&dir.join("located.csv"));
    let lc = lh.iter().position(|c| c == "curve").unwrap();
    assert!(
        !located.is_empty() && located.iter().all(|r| !r[lc].is_empty()),
        "{located:?}"
    );
    // The power map has its grid; the directory draws.
    let (_, map) = read_csv(&dir.join("map.csv"));
    assert_eq!(map.len(), 8);
    let o = vibrotribo(&["plot", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("bifmap.png").exists() && dir.join("bifmap.svg").exists());
}

/// A cheap map of the paper's default case (a small power map, short runs), with the
/// option-value pairs of `extra` set (replacing the same options).
fn device_args<'a>(dir: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "bifmap",
        "--x",
        "omega_ratio",
        "--x-from",
        "0.6",
        "--x-to",
        "0.9",
        "--x-steps",
        "3",
        "--y",
        "gap_ratio",
        "--y-from",
        "1.0",
        "--y-to",
        "1.2",
        "--y-steps",
        "2",
        "--transient",
        "20",
        "--recorded",
        "12",
        "-q",
        "--out",
        dir,
    ];
    for pair in extra.chunks(2) {
        match args.iter().position(|a| *a == pair[0]) {
            Some(i) => args[i + 1] = pair[1],
            None => args.extend_from_slice(pair),
        }
    }
    args
}

#[test]
fn the_power_map_is_maps_cell_for_cell() {
    let root = tempdir();
    let (a, b) = (root.path().join("bifmap"), root.path().join("map"));
    let small = [
        "--seeds",
        "1",
        "--kinds",
        "fold",
        "--branch-points",
        "40",
        "--curve-points",
        "4",
    ];
    let o = vibrotribo(&device_args(a.to_str().unwrap(), &small));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = vibrotribo(&[
        "map",
        "--x",
        "omega_ratio",
        "--x-from",
        "0.6",
        "--x-to",
        "0.9",
        "--x-steps",
        "3",
        "--y",
        "gap_ratio",
        "--y-from",
        "1.0",
        "--y-to",
        "1.2",
        "--y-steps",
        "2",
        "--transient",
        "20",
        "--recorded",
        "12",
        "-q",
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (ha, ra) = read_csv(&a.join("map.csv"));
    let (hb, rb) = read_csv(&b.join("map.csv"));
    assert_eq!(ha, hb);
    assert_eq!(ra.len(), 6);
    assert_eq!(ra, rb, "the power maps differ");
    let p = ha.iter().position(|c| c == "average_power_w").unwrap();
    assert!(
        ra.iter().all(|r| r[p].parse::<f64>().is_ok_and(|v| v > 0.0)),
        "{ra:?}"
    );
}

#[test]
fn a_signal_stops_it_with_a_consistent_partial_result() {
    let root = tempdir();
    let dir = root.path().join("stopped");
    let d = dir.to_str().unwrap();
    // Far more work than the test waits for.
    let args = device_args(d, &["--seeds", "40", "--x-steps", "60", "--y-steps", "60"]);
    let child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(&args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{err}");
    assert!(err.contains("interrupted"), "{err}");
    let m = json(&dir.join("bifmap.json"));
    assert_eq!(m["complete"], false, "{m}");
    // The files agree with the manifest.
    let (_, rows) = read_csv(&dir.join("curves.csv"));
    let listed: u64 = m["curves"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["points"].as_u64().unwrap())
        .sum();
    assert_eq!(rows.len() as u64, listed, "{m}");
    let (_, map) = read_csv(&dir.join("map.csv"));
    assert_eq!(map.len() as u64, m["power_map"]["done"].as_u64().unwrap());
    assert!((map.len() as u64) < m["power_map"]["points"].as_u64().unwrap());
    assert!(
        m["seeds"].as_array().unwrap().len() < 80,
        "every seed was followed before the signal"
    );
    // An incomplete map is not drawn.
    let o = vibrotribo(&["plot", d]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("incomplete"), "{}", stderr(&o));
}

#[test]
fn bad_input_names_the_problem() {
    let root = tempdir();
    let d = root.path().join("bad");
    let d = d.to_str().unwrap();
    let cases: [(&[&str], &str); 9] = [
        (&["--kinds", "saddle"], "saddle"),
        (&["--seeds", "0"], "seed values"),
        (&["--x-starts", "1"], "starts per seed value"),
        (&["--period", "0"], "--period"),
        (&["--curve-points", "1"], "curve points"),
        (&["--y", "excitation.omega_ratio"], "same quantity"),
        (&["--y", "oscillator.no_such_key"], "no_such_key"),
        (&["--x-to", "0.6"], "range"),
        (&["--y-from", "-1"], "gap_ratio"),
    ];
    for (extra, needle) in cases {
        let o = vibrotribo(&device_args(d, extra));
        assert!(!o.status.success(), "{extra:?} was accepted");
        let e = stderr(&o);
        assert!(e.contains(needle), "{extra:?}: {e}");
        assert!(!e.contains("panicked"), "{extra:?}: {e}");
    }
    // A size far beyond reason is refused before anything runs.
    let o = vibrotribo(&device_args(d, &["--branch-points", "1000000000000"]));
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--allow-large"), "{}", stderr(&o));
}
