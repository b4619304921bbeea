//! Messages that named the wrong problem or none: a stiffness of 1e300 N/m was called an
//! "undamped resonance" (its squares overflow double precision); `--set
//! excitation.harmonics[0].amplitude=…` said "missing closing `]`" (an index into an array
//! of tables is not supported); `basins --recorded 1` ran every start into a failure and
//! explained nothing.

use super::util::{stderr, vibrotribo};

const SHORT: [&str; 4] = ["--set", "run.periods=6", "--set", "run.transient_periods=2"];

#[test]
fn stiffness_1e300_is_named_as_out_of_range_not_a_resonance() {
    let mut args = vec!["simulate", "-q", "--set", "oscillator.stiffness=1e300"];
    args.extend_from_slice(&SHORT);
    let o = vibrotribo(&args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("resonance"), "{err}");
    assert!(
        err.contains("overflows double precision") && err.contains("oscillator.stiffness"),
        "{err}"
    );
}

#[test]
fn an_indexed_table_key_says_what_is_supported() {
    let o = vibrotribo(&["simulate", "-q", "--set", "excitation.harmonics[0].amplitude=1"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("missing closing"), "{err}");
    assert!(
        err.contains("`.amplitude` after `excitation.harmonics[0]` is not supported"),
        "{err}"
    );
    // The form it proposes works.
    let mut args = vec![
        "simulate",
        "-q",
        "--set",
        "excitation.kind=\"multisine\"",
        "--set",
        "excitation.harmonics=[{amplitude = 0.001, ratio = 1.0}, {amplitude = 0.0005, ratio = 2.0}]",
    ];
    args.extend_from_slice(&SHORT);
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn basins_with_too_few_recorded_periods_is_refused() {
    let o = vibrotribo(&[
        "basins",
        "-q",
        "--x",
        "run.initial_positions[0]",
        "--x-from",
        "-0.01",
        "--x-to",
        "0.01",
        "--y",
        "run.initial_velocities[0]",
        "--y-from",
        "-0.1",
        "--y-to",
        "0.1",
        "--grid",
        "2x2",
        "--transient",
        "5",
        "--recorded",
        "1",
        "--settle",
        "fixed",
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--recorded 1") && err.contains("no start can be classified"),
        "{err}"
    );
}
