//! Sweep points set typed parameters: every key a [`Param`] sets directly gives the same
//! configuration as writing the value into the TOML tree and reading it again; integer keys
//! can be swept; a derived key that needs two masses is an error on one, never a panic; and a
//! record file is read once per command, however many points a sweep has.

use std::ops::ControlFlow;
use std::path::PathBuf;

use toml::Value;
use vibrotribo::config::{Config, Param};
use vibrotribo::excitation::record_reads;
use vibrotribo::study::PointOptions;
use vibrotribo::sweep::{Delivery, PointRunner, run_grid};

fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

/// The typed path and the TOML path agree: the whole configuration (the tree it records,
/// the document, the chain, the initial state, the harvester) is equal, for each key the
/// typed path handles, on a chain with forces and on one starting relative to the base.
#[test]
fn typed_parameters_equal_the_toml_path() {
    let bases = [
        Config::default(),
        Config::from_toml_str(
            "[oscillator]\nmasses = [0.05, 0.15, 0.08, 0.05]\ngaps = 0.01\nforces = -0.4\n\
             [excitation]\nfrequency_hz = 6.0\n[run]\nstart_relative_to_base = true\n",
        )
        .unwrap(),
    ];
    let cases: [(&str, f64); 14] = [
        ("mass_ratio", 3.5),
        ("mass_ratio_m2_fixed", 2.5),
        ("gap_ratio", 1.5),
        ("gap", 0.012),
        ("omega_ratio", 0.81),
        ("excitation.omega_ratio", 0.63),
        ("frequency_hz", 4.5),
        ("excitation.frequency_hz", 5.5),
        ("amplitude", 0.05),
        ("excitation.amplitude", 0.07),
        ("restitution", 0.6),
        ("oscillator.gaps[1]", 0.03),
        ("oscillator.masses[2]", 0.2),
        ("oscillator.forces[0]", -0.3),
    ];
    for base in &bases {
        for (key, value) in cases {
            let param = Param::new(base, key).unwrap();
            let typed = base.with_values(&[(&param, value)]).unwrap();
            let tree = base.with(key, Value::Float(value)).unwrap();
            assert_eq!(typed, tree, "{key} = {value}");
        }
        // Two keys in order, as a map's point sets them.
        let (x, y) = (
            Param::new(base, "omega_ratio").unwrap(),
            Param::new(base, "mass_ratio").unwrap(),
        );
        let typed = base.with_values(&[(&x, 0.75), (&y, 2.0)]).unwrap();
        let mut tree = base.clone();
        tree.set_all([
            ("omega_ratio", Value::Float(0.75)),
            ("mass_ratio", Value::Float(2.0)),
        ])
        .unwrap();
        assert_eq!(typed, tree);
        // A bad value is the same error either way.
        let param = Param::new(base, "oscillator.masses[1]").unwrap();
        let typed = base.with_values(&[(&param, -1.0)]).unwrap_err();
        let tree = base.with("oscillator.masses[1]", Value::Float(-1.0)).unwrap_err();
        assert_eq!(typed, tree);
        assert!(typed.to_string().contains("oscillator.masses[1]"), "{typed}");
    }
}

/// On a single mass the derived keys between masses and gaps are errors naming the key,
/// through a sweep's parameter and through `--set` alike.
#[test]
fn derived_keys_need_their_masses() {
    let one = Config::from_path(&repo("configs/impact_oscillator.toml")).unwrap();
    for key in ["mass_ratio", "mass_ratio_m2_fixed", "gap_ratio"] {
        let e = Param::new(&one, key).unwrap_err();
        assert!(e.to_string().contains(key), "{e}");
        let e = one.with(key, Value::Float(2.0)).unwrap_err();
        assert!(e.to_string().contains(key), "{e}");
    }
    let e = Param::new(&Config::default(), "oscillator.gaps[2]").unwrap_err();
    assert!(e.to_string().contains("index 2 out of range"), "{e}");
}

/// An integer key (`excitation.seed` of a random base motion) takes the sweep's whole
/// numbers as integers: the point is the configuration with that seed; a fraction is refused
/// naming the key.
#[test]
fn integer_keys_can_be_swept() {
    let random = "[excitation]\nkind = \"random\"\nrms_acceleration = 5.0\nf_low_hz = 3.0\nf_high_hz = 9.0\n\
                  [run]\nperiods = 4\ntransient_periods = 2\n";
    let base = Config::from_toml_str(random).unwrap();
    let seed = Param::new(&base, "excitation.seed").unwrap();
    let point = base.with_values(&[(&seed, 3.0)]).unwrap();
    assert_eq!(point, base.with("excitation.seed", Value::Integer(3)).unwrap());
    assert_ne!(point.base_motion().unwrap(), base.base_motion().unwrap());
    let e = base.with_values(&[(&seed, 0.5)]).unwrap_err();
    assert!(e.to_string().contains("excitation.seed"), "{e}");
}

/// A sweep of 50 values of a record configuration reads the record once, when the
/// configuration is read: the process's count of reads of that file
/// ([`record_reads`]) is 1 after reading the configuration, and still 1 after the 50 points
/// have run in parallel chunks (as the commands run them) and the configuration's base motion
/// and run were built again for the checks a command makes; reading the configuration again
/// counts a second read (the count is not stuck).
#[test]
fn a_record_is_read_once_per_command() {
    let dir = std::env::temp_dir().join(format!("vibrotribo-record-once-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("records")).unwrap();
    let record = dir.join("records/rjob_vertical_acceleration.csv");
    std::fs::copy(repo("configs/records/rjob_vertical_acceleration.csv"), &record).unwrap();
    std::fs::copy(repo("configs/record_default.toml"), dir.join("record.toml")).unwrap();
    assert_eq!(record_reads(&record), 0);
    let mut base = Config::from_path(&dir.join("record.toml")).unwrap();
    assert_eq!(record_reads(&record), 1);
    base.set_all([
        ("run.periods", Value::Integer(3)),
        ("run.transient_periods", Value::Integer(1)),
    ])
    .unwrap();
    let options = PointOptions {
        transient_periods: 1,
        recorded_periods: 2,
        ..PointOptions::default()
    };
    let runner = PointRunner::new(base, options, true);
    let values: Vec<f64> = (0..50).map(|j| 0.5 + 0.008 * j as f64).collect();
    let mut done = 0;
    let delivered = run_grid(
        &runner,
        &values,
        |v| vec![("restitution", *v)],
        8,
        |d| {
            if let Delivery::Point(v, r) = d {
                assert!(r.is_ok(), "restitution = {v}: {r:?}");
                done += 1;
            }
            ControlFlow::Continue(())
        },
    );
    assert_eq!((delivered, done), (50, 50));
    assert!(runner.base().base_motion().is_ok());
    let _ = runner.base().run_spec(true);
    assert_eq!(
        record_reads(&record),
        1,
        "the record was read again by a point or a check"
    );
    Config::from_path(&dir.join("record.toml")).unwrap();
    assert_eq!(record_reads(&record), 2);
    std::fs::remove_dir_all(&dir).unwrap();
}
