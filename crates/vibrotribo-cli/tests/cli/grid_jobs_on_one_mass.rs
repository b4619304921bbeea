//! `sweep` (and `map`, `basins`, `attractors`) on the single-mass impact oscillator exited 0
//! with every point failed ("freestanding needs two gaps"); `simulate` ran it mechanics only.

use super::util::{config_file, read_csv, stderr, tempdir, vibrotribo};

#[test]
fn sweep_of_one_mass_runs_mechanics_only() {
    let dir = tempdir();
    let out = dir.path().join("sw");
    let io = config_file("impact_oscillator.toml");
    let o = vibrotribo(&[
        "sweep",
        io.to_str().unwrap(),
        "--param",
        "omega_ratio",
        "--from",
        "2.4",
        "--to",
        "2.5",
        "--steps",
        "2",
        "--transient",
        "20",
        "--recorded",
        "10",
        "--settle",
        "fixed",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (h, rows) = read_csv(&out.join("summary.csv"));
    let err = h.iter().position(|c| c == "error").unwrap();
    let impacts = h.iter().position(|c| c == "impacts_per_period").unwrap();
    assert_eq!(rows.len(), 2);
    for r in &rows {
        assert!(r[err].is_empty(), "point failed: {r:?}");
        // One impact per period on the stop: the impact oscillator's period-1 orbit.
        let n: f64 = r[impacts].parse().unwrap();
        assert!(n > 0.0, "{r:?}");
    }
    let manifest = std::fs::read_to_string(out.join("sweep.json")).unwrap();
    assert!(manifest.contains("\"mechanics_only\": true"), "{manifest}");
}
