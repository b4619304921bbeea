//! `export-spice --name ../../escape.cir` wrote outside the run's directory, `--from-period`
//! past the run's end exported periods it never ran, a one-mass run failed with "pwl.values
//! has 0 entries", and `--check` of a two-way run compared a one-way replay with itself.

use super::util::{config_file, stderr, tempdir, vibrotribo};

fn run(dir: &std::path::Path, extra: &[&str]) -> String {
    let run = dir.join("run");
    let mut args = vec!["simulate", "-q", "--out", run.to_str().unwrap()];
    args.extend_from_slice(extra);
    args.extend_from_slice(&["--set", "run.periods=6", "--set", "run.transient_periods=2"]);
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    run.display().to_string()
}

#[test]
fn netlist_name_cannot_leave_the_run() {
    let dir = tempdir();
    let run = run(dir.path(), &[]);
    for name in ["../../escape.cir", "sub/x.cir", "..", ""] {
        let o = vibrotribo(&["export-spice", &run, "--name", name]);
        assert_eq!(o.status.code(), Some(1), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains("--name"), "{}", stderr(&o));
    }
    assert!(!dir.path().join("escape.cir").exists());
    let o = vibrotribo(&["export-spice", &run, "--periods", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.path().join("run/harvester.cir").exists());
}

#[test]
fn periods_past_the_run_are_refused() {
    let dir = tempdir();
    let run = run(dir.path(), &[]);
    let o = vibrotribo(&["export-spice", &run, "--from-period", "1000"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("ends past the run, which has 6 periods"), "{err}");
}

#[test]
fn one_mass_run_has_nothing_to_export() {
    let dir = tempdir();
    let io = config_file("impact_oscillator.toml");
    let run = dir.path().join("run");
    let o = vibrotribo(&[
        "simulate",
        io.to_str().unwrap(),
        "-q",
        "--out",
        run.to_str().unwrap(),
        "--set",
        "run.periods=6",
        "--set",
        "run.transient_periods=2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = vibrotribo(&["export-spice", run.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("one mass"), "{err}");
}

#[test]
fn two_way_run_is_refused() {
    let dir = tempdir();
    let run = run(
        dir.path(),
        &[
            "--set",
            "harvester.coupling=\"two_way\"",
            "--set",
            "harvester.voc_model=\"exact\"",
        ],
    );
    let o = vibrotribo(&["export-spice", &run, "--check"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("two-way"), "{err}");
}
