//! Configuration documents: defaults, overrides, derived and indexed keys, and errors that
//! name the key; and a fuzz test of the reader (random TOML documents and `key=value`
//! overrides: no panic, every error names a key it was given).

use vibrotribo::config::{Config, ConfigError, apply_overrides, known_keys, parse_value};
use vibrotribo::electrical::{Load, TransducerMode};
use vibrotribo::{ChainParams, Frequency};

fn with_sets(text: &str, sets: &[&str]) -> Result<Config, ConfigError> {
    let mut c = Config::from_toml_str(text)?;
    apply_overrides(&mut c, sets)?;
    Ok(c)
}

#[test]
fn defaults_are_the_paper_case() {
    let c = Config::default();
    assert_eq!(c.chain(), &ChainParams::default());
    let spec = c.run_spec(false);
    assert_eq!((spec.periods, spec.transient_periods), (100, 50));
    assert_eq!(c.run().samples_per_period, 200);
    assert!(c.table().is_empty());
}

#[test]
fn scalars_broadcast_and_sets_apply() {
    let c = with_sets(
        "[oscillator]\nmasses = [0.05, 0.15]\nstiffness = 100\ngaps = 0.01\n",
        &["oscillator.damping=[0.1, 0.2]", "excitation.frequency_hz=5"],
    )
    .unwrap();
    let p = c.chain();
    assert_eq!(p.stiffness, vec![100.0, 100.0]);
    assert_eq!(p.gaps, vec![0.01]);
    assert_eq!(p.damping, vec![0.1, 0.2]);
    assert_eq!(p.excitation.frequency, Frequency::Hertz(5.0));
    // Two masses: the contact-separation transducer unless a mode is given.
    assert_eq!(c.harvester().mode, TransducerMode::ContactSeparation);
}

#[test]
fn indexed_and_derived_sets() {
    let c = with_sets("", &["oscillator.gaps[1]=0.03", "mass_ratio=3"]).unwrap();
    let p = c.chain();
    assert_eq!(p.gaps, vec![0.02, 0.03]);
    assert!((p.masses[1] - 3.0 * 0.048).abs() < 1e-15);
    let c = with_sets("", &["mass_ratio_m2_fixed=2", "gap_ratio=1.5"]).unwrap();
    let p = c.chain();
    assert_eq!(p.masses, vec![0.06, 0.12, 0.06]);
    assert!((p.gaps[1] - 0.03).abs() < 1e-15);
    let c = with_sets(
        "",
        &["harvester.load=rectifier", "harvester.storage_capacitance=2e-6"],
    )
    .unwrap();
    match c.harvester().load {
        Load::Rectifier(r) => assert_eq!(r.storage_capacitance, 2e-6),
        other => panic!("{other:?}"),
    }
}

#[test]
fn every_option_of_the_types_is_a_key() {
    let keys = known_keys();
    for k in [
        "options.max_impact_iterations",
        "electrical.atol_voltage",
        "harvester.diode_parallel_conductance",
        "run.initial_velocities",
    ] {
        assert!(keys.iter().any(|x| x == k), "{k} missing from {keys:?}");
    }
    let c = with_sets(
        "",
        &["options.max_impact_iterations=7", "electrical.atol_voltage=1e-9"],
    )
    .unwrap();
    assert_eq!(c.sim_options().max_impact_iterations, 7);
    assert_eq!(c.charge_options().atol_voltage, Some(1e-9));
}

#[test]
fn unknown_keys_are_named() {
    let e = with_sets("", &["oscillator.mases=[1,2]"])
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown parameter `oscillator.mases`"), "{e}");
    let e = with_sets("[oscillator]\nmases = [0.1, 0.2]\n", &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown field `mases`"), "{e}");
    let e = with_sets("[oscilator]\n", &[]).unwrap_err().to_string();
    assert!(e.contains("unknown field `oscilator`"), "{e}");
}

/// A tree built outside TOML text (a Python dict) with a key the schema lacks: an unknown
/// key, named as a key.
#[test]
fn unknown_keys_of_a_tree_are_named() {
    for (text, key) in [
        ("[oscillator]\nmases = [0.1, 0.2]\n", "oscillator.mases"),
        ("[oscilator]\nmasses = [0.1, 0.2]\n", "oscilator.masses"),
        ("[run]\nperiods = 10\n[harvester]\nloads = 1\n", "harvester.loads"),
        ("mass_ratio = 3\n", "mass_ratio"),
    ] {
        let table: toml::Table = toml::from_str(text).unwrap();
        match Config::from_table(table) {
            Err(ConfigError::UnknownKey { key: k, .. }) => assert_eq!(k, key),
            other => panic!("{text}: expected the unknown key {key}, got {other:?}"),
        }
    }
    // A known key with a bad type stays a type error.
    let table: toml::Table = toml::from_str("[run]\nperiods = \"many\"\n").unwrap();
    let e = Config::from_table(table).unwrap_err();
    assert!(matches!(e, ConfigError::Type { .. }), "{e:?}");
    assert!(e.to_string().contains("run.periods"), "{e}");
}

#[test]
fn bad_values_are_named_by_their_keys() {
    let cases: &[(&str, &[&str], &str)] = &[
        (
            "[oscillator]\nmasses = [0.1, -0.2, 0.1]\n",
            &[],
            "oscillator.masses[1] = -0.2",
        ),
        (
            "[excitation]\nomega_ratio = 0.7\nfrequency_hz = 3\n",
            &[],
            "not both",
        ),
        (
            "[run]\nperiods = 10\ntransient_periods = 10\n",
            &[],
            "run.transient_periods",
        ),
        ("", &["oscillator.gaps[5]=1"], "index 5 out of range"),
        ("[oscillator]\nmasses = \"heavy\"\n", &[], "masses"),
        ("", &["run.periods=-1"], "run.periods"),
        ("", &["harvester.load=battery"], "harvester.load"),
        ("", &["harvester.area=-1"], "harvester.area = -1"),
        ("", &["electrical.rtol=1"], "electrical.rtol = 1"),
        (
            "",
            &["options.chatter_tolerance=0"],
            "options.chatter_tolerance = 0",
        ),
        (
            "",
            &["run.initial_velocities[1]=nan"],
            "run.initial_velocities[1] = NaN",
        ),
        (
            "",
            &["run.initial_positions=[0, 0.05, 0]"],
            "initial positions interpenetrate at contact 1",
        ),
        (
            "",
            &["oscillator.stiffness=[1, 2]"],
            "oscillator.stiffness has 2 entries, expected 3",
        ),
        (
            "",
            &["oscillator.masses=[0.1, 0.1]", "harvester.mode=freestanding"],
            "harvester.mode",
        ),
        ("", &["omega_ratio"], "expected key=value"),
    ];
    for (text, sets, expected) in cases {
        let e = with_sets(text, sets).unwrap_err().to_string();
        assert!(
            e.contains(expected),
            "{text:?} {sets:?}: expected {expected:?} in {e:?}"
        );
    }
}

#[test]
fn overrides_are_validated_together() {
    // Each alone is invalid with the other's default; together they are fine.
    let c = with_sets(
        "[run]\ntransient_periods = 50\n",
        &["run.periods=20", "run.transient_periods=10"],
    )
    .unwrap();
    assert_eq!((c.run().periods, c.run().transient()), (20, 10));
    let c = with_sets(
        "",
        &["oscillator.masses=[0.1, 0.2]", "oscillator.stiffness=[100, 200]"],
    )
    .unwrap();
    assert_eq!(c.chain().stiffness, vec![100.0, 200.0]);
}

#[test]
fn a_failed_set_leaves_the_configuration_unchanged() {
    let mut c = Config::default();
    let before = c.clone();
    assert!(c.set("oscillator.masses[1]", (-1.0).into()).is_err());
    assert_eq!(c, before);
}

// ---------------------------------------------------------------------------------------
// Fuzz: random documents and overrides.

/// xorshift64*: a small deterministic generator (fixed seeds below).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[self.below(xs.len())]
    }
}

const TYPOS: &[&str] = &["mases", "gapz", "Masses", "", "omega", "load_resistence", "x[1]"];
const SECTIONS: &[&str] = &[
    "oscillator",
    "excitation",
    "run",
    "options",
    "harvester",
    "electrical",
    "oscilator",
    "misc",
];

/// A random TOML value as text: numbers of every kind, strings, booleans, arrays, tables.
fn value(rng: &mut Rng, depth: u32) -> String {
    match rng.below(if depth > 1 { 9 } else { 11 }) {
        0 => rng.pick(&["0", "1", "-1", "3", "100", "2", "0.5"]).to_string(),
        1 => format!("{:e}", f64::from_bits(rng.next()) % 1e3),
        2 => rng
            .pick(&[
                "nan",
                "inf",
                "-inf",
                "1e308",
                "-1e-320",
                "1e11",
                "18446744073709551615",
            ])
            .to_string(),
        3 => format!("{}", (rng.next() % 2000) as f64 / 1000.0),
        4 => format!(
            "\"{}\"",
            rng.pick(&[
                "resistor",
                "rectifier",
                "open",
                "exact",
                "paper",
                "freestanding",
                "contact_separation",
                "x",
                ""
            ])
        ),
        5 => rng.pick(&["true", "false"]).to_string(),
        6 | 7 => {
            let n = rng.below(5);
            let items: Vec<String> = (0..n)
                .map(|_| format!("{}", (rng.next() % 300) as f64 / 1000.0))
                .collect();
            format!("[{}]", items.join(", "))
        }
        8 => format!("{}", (rng.next() % 100) as f64 * 1e-3),
        9 => format!("[{}, {}]", value(rng, depth + 1), value(rng, depth + 1)),
        _ => format!("{{ a = {} }}", value(rng, depth + 1)),
    }
}

fn key(rng: &mut Rng, keys: &[String]) -> String {
    match rng.below(6) {
        0 => rng.pick(TYPOS).to_string(),
        1 => format!("{}[{}]", keys[rng.below(keys.len())], rng.below(5)),
        _ => keys[rng.below(keys.len())].clone(),
    }
}

/// The stem of a key by which an error may name it: its last segment without an index or
/// the `initial_` prefix (`run.initial_positions[1]` → `positions`).
fn stem(key: &str) -> String {
    let last = key.rsplit('.').next().unwrap_or(key);
    let last = last.split('[').next().unwrap_or(last);
    last.trim_start_matches("initial_").to_string()
}

fn names_one_of(message: &str, keys: &[String]) -> bool {
    keys.iter().any(|k| {
        let s = stem(k);
        (!s.is_empty() && message.contains(&s)) || message.contains(k.as_str())
    }) || message.contains("masses") // a chain too short for a key is named by its masses
}

fn random_document(rng: &mut Rng, keys: &[String]) -> (String, Vec<String>) {
    let mut used = Vec::new();
    let mut text = String::new();
    let mut sections: Vec<&str> = (0..rng.below(4)).map(|_| rng.pick(SECTIONS)).collect();
    sections.sort_unstable();
    sections.dedup();
    for section in sections {
        text.push_str(&format!("[{section}]\n"));
        used.push(section.to_string());
        let mut names: Vec<String> = (0..rng.below(4))
            .map(|_| {
                let k = key(rng, keys);
                k.rsplit('.')
                    .next()
                    .unwrap_or(&k)
                    .split('[')
                    .next()
                    .unwrap_or("")
                    .to_string()
            })
            .filter(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
            .collect();
        names.sort();
        names.dedup();
        for name in names {
            text.push_str(&format!("{name} = {}\n", value(rng, 0)));
            used.push(format!("{section}.{name}"));
        }
    }
    (text, used)
}

fn fuzz(cases: usize, seed: u64) {
    let mut keys = known_keys();
    keys.extend(
        vibrotribo::config::DERIVED_KEYS
            .iter()
            .map(|(k, _)| k.to_string()),
    );
    let mut rng = Rng(seed);
    let (mut ok, mut refused) = (0, 0);
    for case in 0..cases {
        if case % 2 == 0 {
            let (text, used) = random_document(&mut rng, &keys);
            match std::panic::catch_unwind(|| Config::from_toml_str(&text)) {
                Err(_) => panic!("case {case}: reading panicked on\n{text}"),
                Ok(Ok(_)) => ok += 1,
                Ok(Err(e)) => {
                    refused += 1;
                    let m = e.to_string();
                    let syntax = matches!(e, ConfigError::Syntax { .. });
                    assert!(
                        syntax || names_one_of(&m, &used),
                        "case {case}: the error names none of {used:?}:\n{m}\n--- document:\n{text}"
                    );
                }
            }
        } else {
            let sets: Vec<(String, String)> = (0..1 + rng.below(3))
                .map(|_| (key(&mut rng, &keys), value(&mut rng, 0)))
                .collect();
            let result = std::panic::catch_unwind(|| {
                let mut c = Config::default();
                for (k, v) in &sets {
                    if let Err(e) = c.set(k, parse_value(v)) {
                        return Err((k.clone(), e));
                    }
                }
                Ok(c)
            });
            match result {
                Err(_) => panic!("case {case}: overrides panicked: {sets:?}"),
                Ok(Ok(_)) => ok += 1,
                Ok(Err((k, e))) => {
                    refused += 1;
                    let m = e.to_string();
                    assert!(
                        names_one_of(&m, std::slice::from_ref(&k)),
                        "case {case}: setting {k} failed without naming it: {m}"
                    );
                }
            }
        }
    }
    println!("{cases} cases: {ok} accepted, {refused} refused with the key named");
    assert!(
        ok > cases / 50,
        "the generator should produce some valid cases ({ok})"
    );
    assert!(refused > cases / 10, "and many invalid ones ({refused})");
}

/// 10⁵ cases (about 2 s): half documents, half sequences of overrides.
#[test]
fn random_documents_and_overrides_never_panic_and_name_their_key() {
    fuzz(100_000, 0x9E37_79B9_7F4A_7C15);
}
