//! `vibrotribo chirp` (frequency-sweep experiments) against truth from outside the
//! chirp code: the quasi-static branches of `sweep --continuation up|down` (the harmonic
//! closed-form engine, one steady state per Ω), the closed-form grazing frequency and
//! response of the linear oscillator, and the steady amplitude of `simulate` runs.
//!
//! The case: one mass on a spring (ζ = 2 %, ω_n = √(k/m) = 48.99 rad/s) below a rigid stop
//! fixed at 50 mm, base amplitude A = 10 mm (`configs/impact_oscillator.toml` with
//! `oscillator.stops.upper.gap = 0.05`), the textbook impact-oscillator hysteresis: the
//! non-impacting motion (absolute amplitude A·T(Ω), T the transmissibility) grazes the stop
//! where A·T(Ω) = gap, at Ω_g = 1.09332 above resonance, and the impacting period-1 branch
//! extends beyond it up to a fold near Ω = 1.44. Sweeping up the motion stays on the impacting
//! branch to the fold and drops; sweeping down it stays on the non-impacting branch to
//! grazing and then impacts.
//!
//! Tolerances from the sweep rate r (Ω per second) and the decay time τ = 1/(ζ ω_n) = 1.02 s:
//! the down jump is the grazing of a linear motion whose amplitude lags the steady one by at
//! most about τ, so it comes at most r·τ below the quasi-static jump; the up jump is the slow
//! passage through a fold (saddle-node), which a sweep delays by O((r·τ)^{2/3}) (Haberman
//! 1979), so it comes above the quasi-static fold by less than (r·τ)^{2/3}. Away from the
//! jumps the amplitude X lags the steady one by at most r·τ in Ω: |ΔX| ≤ |dX/dΩ|·r·τ.

use std::path::Path;

use crate::util::*;

const GAP: f64 = 0.05;
const AMPLITUDE: f64 = 0.01;
const ZETA: f64 = 0.02;
/// 1/(ζ ω_n), s: ω_n = √(120/0.05).
const TAU: f64 = 1.0 / (ZETA * 48.989_794_855_663_56);

fn config() -> String {
    config_file("impact_oscillator.toml")
        .to_str()
        .unwrap()
        .to_string()
}

const GAP_SET: &str = "oscillator.stops.upper.gap=0.05";

/// The steady relative amplitude |x − y| of the non-impacting motion, A Ω²/√((1−Ω²)² + (2ζΩ)²).
fn linear_amplitude(omega: f64) -> f64 {
    AMPLITUDE * omega * omega / ((1.0 - omega * omega).powi(2) + (2.0 * ZETA * omega).powi(2)).sqrt()
}

/// The grazing Ω of the non-impacting motion above resonance: A·T(Ω) = gap, by bisection.
fn grazing_omega() -> f64 {
    let excess = |o: f64| {
        let d = 2.0 * ZETA * o;
        AMPLITUDE * ((1.0 + d * d) / ((1.0 - o * o).powi(2) + d * d)).sqrt() - GAP
    };
    let (mut a, mut b) = (1.01, 1.3);
    for _ in 0..100 {
        let m = 0.5 * (a + b);
        if excess(m) > 0.0 { a = m } else { b = m }
    }
    a
}

/// The Ω where a continuation sweep's impacts per period first change: the middle of the
/// last value before and the first after.
fn continuation_jump(direction: &str, from: &str, to: &str, steps: &str, extra: &[&str]) -> f64 {
    let dir = tempdir();
    let c = config();
    let mut args = vec![
        "sweep",
        &c,
        "--set",
        GAP_SET,
        "--param",
        "omega_ratio",
        "--from",
        from,
        "--to",
        to,
        "--steps",
        steps,
        "--continuation",
        direction,
        "--settle",
        "fixed",
        "--transient",
        "300",
        "--recorded",
        "20",
        "--mechanics-only",
        "-q",
        "--out",
        dir.path().to_str().unwrap(),
    ];
    args.extend(extra);
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&dir.path().join("summary.csv"));
    let ci = h.iter().position(|c| c == "impacts_per_period").unwrap();
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r[0].parse().unwrap(), r[ci].parse().unwrap()))
        .collect();
    let first = pts[0].1;
    let k = pts
        .iter()
        .position(|p| p.1 != first)
        .unwrap_or_else(|| panic!("no jump in the {direction} continuation: {pts:?}"));
    // Before the jump the branch is clean: period 1, one impact or none.
    assert!(first == 0.0 || first == 1.0, "{pts:?}");
    0.5 * (pts[k - 1].0 + pts[k].0)
}

struct ChirpOut {
    dir: tempfile::TempDir,
    json: serde_json::Value,
}

fn chirp(duration: &str) -> ChirpOut {
    let dir = tempdir();
    let c = config();
    let o = vibrotribo(&[
        "chirp",
        &c,
        "--set",
        GAP_SET,
        "--from",
        "0.8",
        "--to",
        "1.6",
        "--duration",
        duration,
        "--mechanics-only",
        "-q",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = manifest(dir.path(), "chirp.json");
    ChirpOut { dir, json }
}

fn jump_of(c: &ChirpOut, direction: &str) -> f64 {
    c.json[direction]["jump"]["omega_ratio"].as_f64().unwrap()
}

/// The response rows of `direction`: (Ω, amplitude1, impacts).
fn response(dir: &Path, direction: &str) -> Vec<(f64, f64, u64)> {
    let (h, rows) = read_csv(&dir.join("response.csv"));
    assert_eq!(
        h,
        [
            "direction",
            "cycle",
            "time_s",
            "omega_ratio",
            "frequency_hz",
            "amplitude1_m",
            "impacts"
        ],
        "mechanics only: no power column"
    );
    rows.iter()
        .filter(|r| r[0] == direction)
        .map(|r| {
            (
                r[3].parse().unwrap(),
                r[5].parse().unwrap(),
                r[6].parse().unwrap(),
            )
        })
        .collect()
}

/// The steady relative amplitude (max − min)/2 of x1 − y over the last period of a
/// `simulate` run at Ω started at the stop (x1 = gap, at rest: it lands on the impacting
/// branch between the jumps), sampled 2000 times a period.
fn impacting_amplitude(omega: f64) -> f64 {
    let dir = tempdir();
    let set = format!("excitation.omega_ratio={omega}");
    let o = vibrotribo(&[
        "simulate",
        &config(),
        "--set",
        GAP_SET,
        "--set",
        &set,
        "--set",
        "run.initial_positions=[0.05]",
        "--set",
        "run.samples_per_period=2000",
        "--mechanics-only",
        "-q",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let s = manifest(dir.path(), "summary.json");
    assert_eq!(
        s["impacts_per_period"], 1.0,
        "Ω = {omega}: on the impacting branch"
    );
    let (h, rows) = read_csv(&dir.path().join("trajectory.csv"));
    let (cx, cy) = (
        h.iter().position(|c| c == "x1_m").unwrap(),
        h.iter().position(|c| c == "y_m").unwrap(),
    );
    let d: Vec<f64> = rows[rows.len() - 2001..]
        .iter()
        .map(|r| r[cx].parse::<f64>().unwrap() - r[cy].parse::<f64>().unwrap())
        .collect();
    0.5 * (d.iter().cloned().fold(f64::MIN, f64::max) - d.iter().cloned().fold(f64::MAX, f64::min))
}

/// A 60 s chirp each way over Ω = 0.8…1.6 (r = 0.0133 per s, r·τ = 0.0136): the up chirp
/// jumps just above the up continuation's fold and the down chirp just below the down
/// continuation's grazing jump, within the tolerances of the module docs; the two jumps
/// are far apart (hysteresis); away from the jumps each direction's amplitude is the steady
/// one of its own branch (impacting up, non-impacting down between the jumps).
#[test]
fn chirps_up_and_down_jump_where_the_continuation_sweeps_jump() {
    // Quasi-static jumps, Ω steps of 0.001. The up sweep starts at the stop (x1 = gap) to be
    // on the impacting branch at Ω = 1.2; the down sweep from rest at 1.3, non-impacting.
    let up_c = continuation_jump(
        "up",
        "1.2",
        "1.5",
        "301",
        &["--set", "run.initial_positions=[0.05]"],
    );
    let down_c = continuation_jump("down", "1.04", "1.3", "261", &[]);
    let graze = grazing_omega();
    println!("continuation jumps: up {up_c:.4}, down {down_c:.4}; closed-form grazing {graze:.5}");
    assert!(
        (down_c - graze).abs() <= 0.0006,
        "down jump {down_c} vs grazing {graze}"
    );
    assert!(up_c > 1.4 && up_c < 1.48, "{up_c}");

    let c = chirp("60");
    let rate = 0.8 / 60.0;
    assert_eq!(c.json["sweep_rate_omega_per_s"].as_f64().unwrap(), rate);
    let (up, down) = (jump_of(&c, "up"), jump_of(&c, "down"));
    let rt = rate * TAU;
    println!(
        "chirp jumps: up {up:.4} (delay {:+.4}, bound (rτ)^(2/3) = {:.4}), down {down:.4} (delay {:+.4}, bound rτ = {rt:.4})",
        up - up_c,
        rt.powf(2.0 / 3.0),
        down - down_c
    );
    // A finite sweep rate delays each jump in the direction of the sweep.
    assert!(up > up_c && up - up_c < rt.powf(2.0 / 3.0), "up {up} vs {up_c}");
    assert!(down < down_c && down_c - down < rt, "down {down} vs {down_c}");
    // Hysteresis: the up jump is far above the down jump (0.35 quasi-statically).
    assert!(up - down > 0.3, "{up} {down}");
    assert!(c.json["up"]["jump"]["size_m"].as_f64().unwrap() < 0.0);
    assert_eq!(c.json["hysteresis"]["width"].as_f64().unwrap(), up - down);
    assert_eq!(c.json["base_motion"], serde_json::Value::Null);
    assert_eq!(c.json["up"]["base_motion"]["kind"], "chirp");

    // Impacts: the up chirp impacts all the way to its jump, the down chirp none above its jump.
    let (ru, rd) = (response(c.dir.path(), "up"), response(c.dir.path(), "down"));
    assert!(
        ru.iter()
            .filter(|r| r.0 > 1.1 && r.0 < up - 0.01)
            .all(|r| r.2 >= 1)
    );
    assert!(rd.iter().filter(|r| r.0 > down_c + 0.005).all(|r| r.2 == 0));

    // Amplitudes away from the jumps: the chirp's cycle nearest Ω against the steady one.
    let (x12, x13) = (impacting_amplitude(1.2), impacting_amplitude(1.3));
    let impact_slope = (x13 - x12) / 0.1;
    let nearest = |rows: &[(f64, f64, u64)], o: f64| {
        *rows
            .iter()
            .min_by(|a, b| (a.0 - o).abs().total_cmp(&(b.0 - o).abs()))
            .unwrap()
    };
    let linear_slope = |o: f64| (linear_amplitude(o + 1e-6) - linear_amplitude(o - 1e-6)) / 2e-6;
    let mut worst: f64 = 0.0;
    for (rows, omega, steady, slope) in [
        (&ru, 0.85, None, None),
        (&rd, 0.85, None, None),
        (&ru, 1.2, Some(x12), Some(impact_slope)),
        (&ru, 1.3, Some(x13), Some(impact_slope)),
        (&rd, 1.2, None, None),
        (&rd, 1.3, None, None),
        (&ru, 1.55, None, None),
        (&rd, 1.55, None, None),
    ] {
        let (o, x, _) = nearest(rows, omega);
        // Non-impacting: the closed form at the cycle's own Ω; impacting: the simulate value
        // at Ω, moved along the branch's slope to the cycle's Ω.
        let (truth, slope) = match (steady, slope) {
            (Some(s), Some(k)) => (s + k * (o - omega), k),
            _ => (linear_amplitude(o), linear_slope(o)),
        };
        let bound = slope.abs() * rt + 1e-3 * truth;
        println!(
            "Ω = {o:.4}: chirp {x:.6} m, steady {truth:.6} m, relative {:+.2e}, bound {:.2e}",
            (x - truth) / truth,
            bound / truth
        );
        assert!(
            (x - truth).abs() <= bound,
            "Ω = {o}: {x} vs {truth} (bound {bound})"
        );
        worst = worst.max((x - truth).abs() / truth);
    }
    println!("largest relative amplitude difference {worst:.2e}");
}

/// The delays scale as the module docs say: slowing the sweep 4× (60 s → 240 s) shrinks the
/// down (grazing) delay about 4× (linear lag) and the up (fold) delay about 4^{2/3} = 2.52×.
#[test]
fn the_jump_delays_scale_with_the_sweep_rate() {
    // The continuation jumps the test above finds (1.440 | 1.441 and 1.094 | 1.093).
    let (up_c, down_c) = (1.4405, 1.0935);
    let (fast, slow) = (chirp("60"), chirp("240"));
    let du = (jump_of(&fast, "up") - up_c) / (jump_of(&slow, "up") - up_c);
    let dd = (down_c - jump_of(&fast, "down")) / (down_c - jump_of(&slow, "down"));
    println!("delay ratios 60 s / 240 s: up {du:.3} (fold: 2.52), down {dd:.3} (linear lag: 4)");
    assert!((du - 4f64.powf(2.0 / 3.0)).abs() < 0.4, "{du}");
    assert!((dd - 4.0).abs() < 0.8, "{dd}");
}

/// With a harvester the response has a power column, positive where the masses impact; the
/// picture is drawn; `vibrotribo plot` redraws it.
#[test]
fn chirp_with_a_harvester_writes_power_and_plots() {
    let dir = tempdir();
    let d = dir.path().to_str().unwrap();
    let o = vibrotribo(&[
        "chirp",
        "--from",
        "0.6",
        "--to",
        "0.8",
        "--duration",
        "10",
        "-q",
        "--out",
        d,
        "--plot",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&dir.path().join("response.csv"));
    assert_eq!(h.len(), 5 + 3 + 2);
    assert_eq!(h[h.len() - 1], "power_w");
    assert!(rows.iter().any(|r| r[0] == "down"));
    for r in &rows {
        let impacts: u64 = r[8].parse().unwrap();
        let p: f64 = r[9].parse().unwrap();
        assert!(p >= 0.0 && (impacts == 0 || p > 0.0), "{r:?}");
    }
    let png = std::fs::read(dir.path().join("response.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    std::fs::remove_file(dir.path().join("response.svg")).unwrap();
    let o = vibrotribo(&["plot", d]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("response.svg").exists());
}

#[test]
fn bad_chirp_input_is_named() {
    let c = config();
    let base = ["chirp", &c, "--set", GAP_SET, "--mechanics-only", "-q"];
    let cases: &[(&[&str], &str)] = &[
        (
            &["--from", "1.2", "--to", "1.0", "--duration", "60"],
            "--from: 1.2 must be below",
        ),
        (
            &["--from", "0", "--to", "1.0", "--duration", "60"],
            "--from: 0 must be",
        ),
        (
            &["--from", "0.8", "--to", "nan", "--duration", "60"],
            "--to: NaN must be",
        ),
        (
            &["--from", "0.8", "--to", "1.6", "--duration", "-1"],
            "--duration: -1 must be",
        ),
        (
            &["--from", "0.8", "--to", "1.6", "--duration", "0.5"],
            "--duration: 0.5 s holds 4.68 cycles",
        ),
        (
            &["--from", "0.8", "--to", "1.6", "--duration", "6000"],
            "spline knots",
        ),
        (
            &[
                "--from",
                "0.8",
                "--to",
                "1.6",
                "--duration",
                "60",
                "--amplitude",
                "0",
            ],
            "--amplitude: 0 must be",
        ),
        (
            &[
                "--from",
                "0.8",
                "--to",
                "1.6",
                "--duration",
                "60",
                "--jump-window",
                "0",
            ],
            "--jump-window",
        ),
        (
            &[
                "--from",
                "0.8",
                "--to",
                "1.6",
                "--duration",
                "60",
                "--sweep",
                "cubic",
            ],
            "linear or logarithmic",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = base.to_vec();
        args.extend_from_slice(extra);
        let o = vibrotribo(&args);
        assert!(!o.status.success(), "{extra:?} should fail");
        let err = stderr(&o);
        assert!(
            err.contains(expected),
            "{extra:?}: expected {expected:?} in {err:?}"
        );
        assert!(!err.contains("panicked"), "{extra:?} panicked: {err}");
    }
    // The knots error names the duration too.
    let mut args = base.to_vec();
    args.extend_from_slice(&["--from", "0.8", "--to", "1.6", "--duration", "6000"]);
    assert!(stderr(&vibrotribo(&args)).contains("--duration: 6000 s"));
    // A base motion that is not harmonic is not replaced silently.
    let record = config_file("record_default.toml");
    let o = vibrotribo(&[
        "chirp",
        record.to_str().unwrap(),
        "--from",
        "0.5",
        "--to",
        "1",
        "--duration",
        "20",
    ]);
    assert!(stderr(&o).contains("excitation.kind"), "{}", stderr(&o));
}
