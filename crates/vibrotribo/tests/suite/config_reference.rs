//! The configuration reference in the user guide (`docs/guide/src/reference/configuration.md`)
//! is the one the library generates, and the allowed values it states are the ones validation
//! enforces: a value just outside a key's stated range is refused with an error naming the key.

use vibrotribo::config::{Allowed, Config, KEY_DOCS, reference_markdown};

const PAGE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../docs/guide/src/reference/configuration.md"
);

#[test]
fn committed_reference_is_up_to_date() {
    let committed = std::fs::read_to_string(PAGE).unwrap_or_default();
    let generated = reference_markdown();
    assert!(
        committed == generated,
        "docs/guide/src/reference/configuration.md is out of date: regenerate it with\n  \
         cargo run -p vibrotribo-cli -- config-reference > docs/guide/src/reference/configuration.md"
    );
}

/// The configuration a key is validated in: rectifier keys need the rectifier.
fn base_for(key: &str) -> Config {
    let name = key.rsplit('.').next().unwrap_or(key);
    let rectifier = name.starts_with("storage_") || name.starts_with("diode_") || name == "target_voltage";
    if rectifier {
        Config::default()
            .with("harvester.load", "rectifier".into())
            .unwrap()
    } else {
        Config::default()
    }
}

/// The key as set: an array key by its second element.
fn settable(key: &str) -> String {
    let arrays = [
        "masses",
        "stiffness",
        "damping",
        "gaps",
        "dielectric_thickness",
        "relative_permittivity",
    ];
    match key.rsplit('.').next() {
        Some(name) if arrays.contains(&name) => format!("{key}[1]"),
        _ => key.to_string(),
    }
}

/// Values just outside the allowed range, and one inside.
fn probes(allowed: Allowed) -> Option<(Vec<toml::Value>, toml::Value)> {
    Some(match allowed {
        Allowed::Positive => (vec![0.0.into(), (-1.0).into()], 0.5.into()),
        Allowed::NonNegative => (vec![(-1e-3).into()], 0.0.into()),
        Allowed::Between(a, b) => (
            vec![(b + (b - a)).into(), (a - (b - a)).into()],
            ((a + b) / 2.0).into(),
        ),
        Allowed::IntegerAtLeast(n) if n >= 1 => (
            vec![toml::Value::Integer(n as i64 - 1)],
            toml::Value::Integer(n as i64 + 1),
        ),
        Allowed::OneOf(names) if names != ["true", "false"] => {
            (vec!["no_such_value".into()], names[0].into())
        }
        _ => return None,
    })
}

#[test]
fn stated_ranges_are_enforced() {
    // Keys of other excitation kinds than the sine need their kind's configuration; the stops
    // need a stop; frequency_hz replaces omega_ratio. Those are left to their own tests.
    let skipped = |k: &str| {
        (k.starts_with("excitation.") && !["excitation.amplitude", "excitation.omega_ratio"].contains(&k))
            || k.starts_with("oscillator.stops.")
    };
    let mut checked = 0;
    for d in KEY_DOCS.iter().filter(|d| !skipped(d.key)) {
        let Some((outside, inside)) = probes(d.allowed) else {
            continue;
        };
        let key = settable(d.key);
        let base = base_for(d.key);
        for v in outside {
            match base.with(&key, v.clone()) {
                Ok(_) => panic!(
                    "{key} = {v} is outside {:?} but was accepted",
                    d.allowed.describe()
                ),
                Err(e) => {
                    let name = key.rsplit('.').next().unwrap();
                    assert!(
                        e.to_string().contains(name),
                        "{key} = {v}: the error does not name the key: {e}"
                    );
                }
            }
        }
        if let Err(e) = base.with(&key, inside.clone()) {
            panic!(
                "{key} = {inside} is inside {} but was refused: {e}",
                d.allowed.describe()
            );
        }
        checked += 1;
    }
    assert!(checked >= 30, "only {checked} keys were probed");
}
