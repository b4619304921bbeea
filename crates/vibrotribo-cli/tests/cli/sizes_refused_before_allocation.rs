//! Sizes a user's input sets were allocated without an estimate: a damping of 1e9 N·s/m made
//! the charge solver's gap expansion ask for 10 GB and abort; `load-sweep --vq-points 1e9` and
//! `export-spice --dt-fraction 1e-12` aborted too. Each is now refused first, by name.

use super::util::{stderr, tempdir, vibrotribo};

const SHORT: [&str; 4] = ["--set", "run.periods=4", "--set", "run.transient_periods=2"];

fn with_short<'a>(args: &[&'a str]) -> Vec<&'a str> {
    let mut v = args.to_vec();
    v.extend_from_slice(&SHORT);
    v
}

#[test]
fn heavy_damping_is_refused_by_the_charge_solver() {
    let o = vibrotribo(&with_short(&[
        "simulate",
        "-q",
        "--set",
        "oscillator.damping=1e9",
    ]));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("charge solver cannot follow the gaps"), "{err}");
    assert!(err.contains("--mechanics-only"), "{err}");
}

#[test]
fn vq_points_beyond_memory_are_refused() {
    let dir = tempdir();
    let out = dir.path().join("ls");
    let o = vibrotribo(&with_short(&[
        "load-sweep",
        "-q",
        "--steps",
        "2",
        "--vq-points",
        "1000000000",
        "--out",
        out.to_str().unwrap(),
    ]));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--vq-points") && err.contains("--allow-large"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is written before the refusal");
}

#[test]
fn pwl_points_beyond_memory_are_refused() {
    let dir = tempdir();
    let run = dir.path().join("run");
    let o = vibrotribo(&with_short(&["simulate", "-q", "--out", run.to_str().unwrap()]));
    assert!(o.status.success(), "{}", stderr(&o));
    let o = vibrotribo(&["export-spice", run.to_str().unwrap(), "--dt-fraction", "1e-12"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--dt-fraction") && err.contains("--allow-large"),
        "{err}"
    );
}
