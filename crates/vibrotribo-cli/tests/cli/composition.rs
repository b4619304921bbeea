//! Every base motion with every electrical model and every kind of stop, through `simulate`
//! and `sweep`: each combination runs, or is refused with a message that names the
//! combination and the reason. The outcomes are the table of docs/guide/src/composition.md,
//! which this test writes with `VIBROTRIBO_BLESS=1` and otherwise checks up to date (the
//! Python tests run the same combinations and compare with it).

use std::path::{Path, PathBuf};

use crate::util::*;

/// The base motions: name, `[excitation]` table (the chain's reference Ω = 0.7 as in the
/// default case), and extra `[run]` keys.
fn motions(record: &Path) -> Vec<(&'static str, String, &'static str)> {
    vec![
        ("sine", String::new(), ""),
        (
            "multisine",
            "kind = \"multisine\"\nharmonics = [{amplitude = 0.05, ratio = 1}, {amplitude = 0.01, ratio = 2.3, phase = 1}]\n"
                .into(),
            "",
        ),
        (
            "chirp",
            "kind = \"chirp\"\namplitude = 0.05\nf_start_hz = 3\nf_end_hz = 6\n".into(),
            "",
        ),
        (
            "random",
            "kind = \"random\"\nrms_acceleration = 40\nf_low_hz = 2\nf_high_hz = 20\nseed = 14\n".into(),
            "",
        ),
        (
            "record",
            format!(
                "kind = \"record\"\nfile = \"{}\"\nquantity = \"acceleration\"\npeak_acceleration = 9.8\n",
                record.display()
            ),
            "",
        ),
    ]
}

/// The electrical models: name, `[harvester]` keys, and whether the commands get
/// `--mechanics-only`.
const MODELS: [(&str, &str, bool); 3] = [
    ("mechanics only", "", true),
    ("one-way", "voc_model = \"exact\"\n", false),
    (
        "two-way",
        "voc_model = \"exact\"\ncoupling = \"two_way\"\n",
        false,
    ),
];

/// The stops: name and `[oscillator.stops.upper]` table (a stop placed 30 mm above the top mass).
const STOPS: [(&str, &str); 3] = [
    ("none", ""),
    ("fixed", "gap = 0.03\nrestitution = 0.8\nframe = \"fixed\"\n"),
    (
        "moving with the base",
        "gap = 0.03\nrestitution = 0.8\nframe = \"base\"\n",
    ),
];

/// Periods of every run: 1 of transient, 2 recorded.
const PERIODS: u64 = 3;

/// What a command made of one combination.
enum Outcome {
    Runs,
    Refused(String),
}

impl Outcome {
    fn cell(&self) -> String {
        match self {
            Outcome::Runs => "runs".into(),
            Outcome::Refused(why) => format!("refused: {}", why.replace('|', "\\|")),
        }
    }
}

/// The error line of a failed command (without the `Error: ` prefix).
fn error_line(o: &std::process::Output) -> String {
    let err = stderr(o);
    let line = err
        .lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or_default()
        .trim();
    line.strip_prefix("Error: ").unwrap_or(line).to_string()
}

/// Checks a refusal: it names the base motion and the reason, and did not panic.
fn refused(o: &std::process::Output, motion: &str, what: &str) -> Outcome {
    let err = stderr(o);
    assert!(!err.contains("panicked"), "{what} panicked: {err}");
    let line = error_line(o);
    assert!(
        line.contains(motion) && line.contains("frame = \"base\""),
        "{what}: the refusal names neither the combination nor its reason: {err}"
    );
    Outcome::Refused(line)
}

fn simulate(config: &Path, mechanics_only: bool, electrical: bool, motion: &str, what: &str) -> Outcome {
    let dir = tempdir();
    let mut args = vec![
        "simulate",
        config.to_str().unwrap(),
        "--out",
        dir.path().to_str().unwrap(),
        "--quiet",
    ];
    if mechanics_only {
        args.push("--mechanics-only");
    }
    let o = vibrotribo(&args);
    if !o.status.success() {
        return refused(&o, motion, what);
    }
    let summary: serde_json::Value = serde_json::from_str(&read(dir.path(), "summary.json")).unwrap();
    assert_eq!(summary["periods"], PERIODS, "{what}: {summary}");
    assert!(summary["impacts"].as_u64().is_some(), "{what}: {summary}");
    let power = summary["average_power_w"].as_f64();
    if electrical {
        // A harvester that delivered energy: the load's average power is positive and finite.
        let p = power.unwrap_or_else(|| panic!("{what}: no power in {summary}"));
        assert!(p > 0.0 && p.is_finite(), "{what}: power {p}");
    } else {
        assert!(power.is_none(), "{what}: power without a harvester: {summary}");
    }
    let (_, rows) = read_csv(&dir.path().join("trajectory.csv"));
    assert!(rows.len() > PERIODS as usize, "{what}: {} samples", rows.len());
    Outcome::Runs
}

fn sweep(config: &Path, mechanics_only: bool, electrical: bool, motion: &str, what: &str) -> Outcome {
    let dir = tempdir();
    let mut args = vec![
        "sweep",
        config.to_str().unwrap(),
        "--param",
        "oscillator.restitution",
        "--from",
        "0.7",
        "--to",
        "0.8",
        "--steps",
        "2",
        "--transient",
        "1",
        "--recorded",
        "2",
        "--settle",
        "fixed",
        "--out",
        dir.path().to_str().unwrap(),
        "--quiet",
    ];
    if mechanics_only {
        args.push("--mechanics-only");
    }
    let o = vibrotribo(&args);
    if !o.status.success() {
        return refused(&o, motion, what);
    }
    let (header, rows) = read_csv(&dir.path().join("summary.csv"));
    assert_eq!(rows.len(), 2, "{what}");
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    for r in &rows {
        if let Some(e) = header.iter().position(|h| h == "error") {
            assert!(r[e].is_empty(), "{what}: point failed: {}", r[e]);
        }
        let power = &r[col("average_power_w")];
        if electrical {
            let p: f64 = power
                .parse()
                .unwrap_or_else(|_| panic!("{what}: power {power:?}"));
            assert!(p > 0.0 && p.is_finite(), "{what}: power {p}");
        } else {
            assert!(power.is_empty(), "{what}: power without a harvester");
        }
    }
    Outcome::Runs
}

/// The guide's page this test keeps.
fn page() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/guide/src/composition.md")
}

const HEADER: &str = "# What composes with what

Every base motion (`excitation.kind`) with every electrical model (`--mechanics-only`, the
one-way model, `harvester.coupling = \"two_way\"`) and every kind of rigid stop
(`[oscillator.stops.upper]`, fixed in space or moving with the base), through `simulate` and
`sweep`. The base motion drives the engine itself (the sine through its closed-form response,
any other motion as the exact forces `k_i y + c_i y'` of each of its intervals), so two-way
coupling, stops and sweeps run under every motion; a stop that moves with the base follows
the sine `A sin ωt` only and is refused under any other motion, with the reason.

This table is written by the test `composition` of the command line's tests
(`VIBROTRIBO_BLESS=1 cargo test -p vibrotribo-cli --test cli composition` to write it again),
which runs every row for 3 periods; the Python tests run the same combinations and compare
with it.

| base motion | mechanics | stop | `simulate` | `sweep` |
| --- | --- | --- | --- | --- |
";

#[test]
fn every_base_motion_composes_with_every_model_and_stop() {
    let dir = tempdir();
    let record = config_file("records/rjob_vertical_acceleration.csv");
    let mut table = String::from(HEADER);
    for (motion, excitation, run) in motions(&record) {
        for (model, harvester, mechanics_only) in MODELS {
            for (stop, stops) in STOPS {
                let what = format!("{motion} × {model} × stop {stop}");
                let mut text = format!(
                    "[excitation]\n{excitation}[harvester]\n{harvester}[run]\nperiods = {PERIODS}\ntransient_periods = 1\nsamples_per_period = 20\n{run}"
                );
                if !stops.is_empty() {
                    text.push_str(&format!("[oscillator.stops.upper]\n{stops}"));
                }
                let config = dir.path().join("case.toml");
                std::fs::write(&config, &text).unwrap();
                let electrical = !mechanics_only;
                let a = simulate(&config, mechanics_only, electrical, motion, &what);
                let b = sweep(&config, mechanics_only, electrical, motion, &what);
                // Only a stop moving with the base under another motion than the sine is
                // meaningless to the engine; everything else must run.
                let meaningless = stop == "moving with the base" && motion != "sine";
                for (command, outcome) in [("simulate", &a), ("sweep", &b)] {
                    assert_eq!(
                        matches!(outcome, Outcome::Refused(_)),
                        meaningless,
                        "{command}, {what}: {}",
                        outcome.cell()
                    );
                }
                table.push_str(&format!(
                    "| {motion} | {model} | {stop} | {} | {} |\n",
                    a.cell(),
                    b.cell()
                ));
            }
        }
    }
    let path = page();
    if std::env::var_os("VIBROTRIBO_BLESS").is_some_and(|v| v == "1") {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &table).unwrap();
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == table,
        "{} is not the table this test finds (VIBROTRIBO_BLESS=1 writes it):\n{table}",
        path.display()
    );
}
