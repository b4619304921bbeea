//! `simulate --plot` on the impact oscillator (no harvester, so no electrical figures with
//! data) exited 1 with "no finite data to plot", half the plots made and the summary never
//! printed. A figure with nothing to draw is now skipped with a note.

use super::util::{config_file, stderr, tempdir, vibrotribo};

#[test]
fn plot_with_nothing_to_draw_keeps_the_run() {
    let dir = tempdir();
    let out = dir.path().join("io");
    let io = config_file("impact_oscillator.toml");
    let o = vibrotribo(&[
        "simulate",
        io.to_str().unwrap(),
        "-q",
        "--plot",
        "--out",
        out.to_str().unwrap(),
        "--set",
        "run.periods=30",
        "--set",
        "run.transient_periods=10",
    ]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(text.contains("simulated 30 periods"), "{text}");
    assert!(out.join("summary.json").exists());
    assert!(out.join("phase_x1.png").exists(), "{text}");
}

#[test]
fn undefined_figures_are_empty_fields() {
    let dir = tempdir();
    let out = dir.path().join("at");
    let o = vibrotribo(&[
        "attractors",
        "--param",
        "omega_ratio",
        "--from",
        "0.8",
        "--to",
        "0.8",
        "--steps",
        "1",
        "--samples",
        "1",
        "--transient",
        "10",
        "--recorded",
        "10",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    for name in ["attractors.csv", "expected_power.csv"] {
        let text = std::fs::read_to_string(out.join(name)).unwrap();
        for bad in ["NaN", "inf"] {
            assert!(!text.contains(bad), "{name} holds {bad}:\n{text}");
        }
        // One start: the standard error of the expected power is undefined, so empty.
        if name == "expected_power.csv" {
            let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
            assert_eq!(row[2], "", "{text}");
        }
    }
}
