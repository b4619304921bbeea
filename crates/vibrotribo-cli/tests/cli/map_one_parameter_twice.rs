//! `map --x omega_ratio --y omega_ratio` ran and wrote the y value's result for every x.

use super::util::{stderr, vibrotribo};

#[test]
fn map_refuses_one_parameter_on_both_axes() {
    for (x, y) in [
        ("omega_ratio", "omega_ratio"),
        ("omega_ratio", "excitation.omega_ratio"),
        ("omega_ratio", "frequency_hz"),
    ] {
        let o = vibrotribo(&[
            "map",
            "--x",
            x,
            "--x-from",
            "0.5",
            "--x-to",
            "0.6",
            "--x-steps",
            "2",
            "--y",
            y,
            "--y-from",
            "0.5",
            "--y-to",
            "0.6",
            "--y-steps",
            "2",
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{x} {y}: {err}");
        assert!(err.contains("set the same quantity"), "{err}");
    }
}
