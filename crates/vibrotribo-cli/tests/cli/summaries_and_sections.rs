//! `summary.json` is one type, the library's `report::RunSummary`: the file `simulate` writes
//! for each configuration (the four of `configs/`, one-way and two-way coupling, mechanics
//! only, a rigid stop, a rectifier, settling, random and recorded base motion) reads as that
//! type and writes back byte for byte, naming its command. The Poincaré sections written
//! beside it are the run's own: the stroboscopic section is the trajectory's samples at
//! t = nT after the transient, bit for bit, and the impact section is the impacts of
//! `events.csv` after the transient (stops included), as two independent writers record them.

use std::path::Path;

use vibrotribo::report::RunSummary;

use super::util::{config_file, read_csv, stderr, tempdir, vibrotribo};

/// A random base motion (2–20 Hz, seeded) with a fixed upper stop at a 30 mm gap above the top
/// mass.
const RANDOM: &str = "[excitation]\nkind = \"random\"\nrms_acceleration = 40\nf_low_hz = 2\nf_high_hz = 20\nseed = 14\n\
                      [oscillator.stops.upper]\ngap = 0.03\nrestitution = 0.8\nframe = \"fixed\"\n";

/// Runs `simulate ARGS --out DIR` and returns DIR's `summary.json` as text.
fn simulate(dir: &Path, args: &[&str]) -> String {
    let mut all = vec!["simulate", "-q", "--out", dir.to_str().unwrap()];
    all.extend(args);
    let o = vibrotribo(&all);
    assert!(o.status.success(), "simulate {args:?}: {}", stderr(&o));
    std::fs::read_to_string(dir.join("summary.json")).unwrap()
}

/// The runs: a name and the arguments of `simulate`.
fn runs(random: &Path) -> Vec<(&'static str, Vec<String>)> {
    let short = ["--set", "run.periods=12", "--set", "run.transient_periods=4"];
    let with = |config: Option<String>, extra: &[&str]| -> Vec<String> {
        let mut v: Vec<String> = config.into_iter().collect();
        v.extend(short.iter().chain(extra).map(|s| s.to_string()));
        v
    };
    let file = |name: &str| Some(config_file(name).display().to_string());
    let two_way = [
        "--set",
        "harvester.coupling=two_way",
        "--set",
        "harvester.voc_model=exact",
    ];
    vec![
        ("default", with(None, &[])),
        ("chatter", with(file("chatter.toml"), &[])),
        (
            "impact oscillator (a stop)",
            with(file("impact_oscillator.toml"), &[]),
        ),
        ("record", with(file("record_default.toml"), &[])),
        ("mechanics only", with(None, &["--mechanics-only"])),
        ("two-way", with(None, &two_way)),
        ("rectifier", with(None, &["--set", "harvester.load=rectifier"])),
        ("settle auto", with(None, &["--settle", "auto"])),
        (
            "random, two-way, a stop",
            with(Some(random.display().to_string()), &two_way),
        ),
        ("record, two-way", with(file("record_default.toml"), &two_way)),
    ]
}

#[test]
fn every_summary_reads_and_writes_back_byte_for_byte() {
    let tmp = tempdir();
    let random = tmp.path().join("random.toml");
    std::fs::write(&random, RANDOM).unwrap();
    for (k, (name, args)) in runs(&random).into_iter().enumerate() {
        let dir = tmp.path().join(format!("run{k}"));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let text = simulate(&dir, &args);
        let summary: RunSummary = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"));
        let again = serde_json::to_string_pretty(&summary).unwrap() + "\n";
        assert!(
            again == text,
            "{name}: summary.json written back differs:\n{again}\n---\n{text}"
        );
        assert!(text.starts_with("{\n  \"command\": \"simulate\","), "{name}");
        // The optional groups are there exactly where they belong.
        assert_eq!(
            summary.electrical.is_some(),
            name != "mechanics only" && name != "impact oscillator (a stop)",
            "{name}"
        );
        assert_eq!(
            summary.base_motion.is_some(),
            name.starts_with("record") || name.starts_with("random"),
            "{name}"
        );
        assert_eq!(
            summary.settle_cap_periods.is_some(),
            name == "settle auto",
            "{name}"
        );
    }
}

/// The numbers of a CSV column.
fn column(path: &Path, name: &str) -> Vec<String> {
    let (h, rows) = read_csv(path);
    let c = h
        .iter()
        .position(|x| x == name)
        .unwrap_or_else(|| panic!("{}: no {name}", path.display()));
    rows.iter().map(|r| r[c].clone()).collect()
}

#[test]
fn the_sections_are_the_runs_own_samples_and_impacts() {
    let tmp = tempdir();
    let random = tmp.path().join("random.toml");
    std::fs::write(&random, RANDOM).unwrap();
    let io = config_file("impact_oscillator.toml").display().to_string();
    let random = random.display().to_string();
    let short = ["--set", "run.periods=12", "--set", "run.transient_periods=4"];
    for (name, config, extra) in [
        ("default", None, vec!["--set", "run.samples_per_period=40"]),
        ("impact oscillator", Some(io.as_str()), short.to_vec()),
        ("random with a stop", Some(random.as_str()), short.to_vec()),
    ] {
        let args: Vec<&str> = config.into_iter().chain(extra).collect();
        let dir = tmp.path().join(name.replace(' ', "_"));
        let summary: RunSummary = serde_json::from_str(&simulate(&dir, &args)).unwrap();
        let (transient, spp) = {
            let t = column(&dir.join("trajectory.csv"), "time_s");
            let spp = t
                .iter()
                .position(|x| x.parse::<f64>().unwrap() >= summary.excitation_period_s * (1.0 - 1e-12))
                .unwrap();
            (summary.transient_periods as usize, spp)
        };
        // The summary states the run's sampling: the trajectory's row at t = T.
        assert_eq!(summary.samples_per_period, Some(spp as u64), "{name}");
        // Stroboscopic section: the trajectory's rows j = n·spp for n ≥ the transient.
        let (th, trows) = read_csv(&dir.join("trajectory.csv"));
        let (sh, srows) = read_csv(&dir.join("poincare_strobe.csv"));
        let expected: Vec<&Vec<String>> = trows.iter().step_by(spp).skip(transient).collect();
        assert_eq!(srows.len(), expected.len(), "{name}: strobe rows");
        assert!(!srows.is_empty(), "{name}: no strobe row");
        for (n, (s, t)) in srows.iter().zip(&expected).enumerate() {
            assert_eq!(s[0], (transient + n).to_string(), "{name}: period");
            for (k, col) in sh.iter().enumerate().skip(1) {
                let c = th.iter().position(|x| x == col).unwrap();
                assert_eq!(s[k], t[c], "{name}: {col} at period {}", transient + n);
            }
        }
        // Impact section: the impacts of events.csv from the transient's end on.
        let start = summary.transient_periods as f64 * summary.excitation_period_s;
        let (eh, erows) = read_csv(&dir.join("events.csv"));
        let at = |n: &str| eh.iter().position(|x| x == n).unwrap();
        let impacts: Vec<[String; 3]> = erows
            .iter()
            .filter(|r| r[at("kind")] == "impact" && r[at("time_s")].parse::<f64>().unwrap() >= start)
            .map(|r| {
                [
                    r[at("time_s")].clone(),
                    r[at("contact")].clone(),
                    r[at("rel_velocity_m_s")].clone(),
                ]
            })
            .collect();
        let (ih, irows) = read_csv(&dir.join("poincare_impacts.csv"));
        let got: Vec<[String; 3]> = irows
            .iter()
            .map(|r| {
                let c = |n: &str| r[ih.iter().position(|x| x == n).unwrap()].clone();
                [c("time_s"), c("contact"), c("rel_velocity_m_s")]
            })
            .collect();
        assert_eq!(got, impacts, "{name}: impact section");
        assert!(!got.is_empty(), "{name}: no impact after the transient");
        // The stop's impacts are in it (contact N for the lower stop, N + 1 for the upper).
        let masses = summary.parameters.len();
        let stop_hits = summary.impacts_by_contact[masses.saturating_sub(1)..]
            .iter()
            .sum::<u64>();
        let stop_rows = got
            .iter()
            .filter(|r| r[1].parse::<usize>().unwrap() >= masses)
            .count() as u64;
        assert_eq!(stop_rows, stop_hits, "{name}: impacts on a stop");
        if name != "default" {
            assert!(
                stop_hits > 0,
                "{name}: the stop is never hit, the check proves nothing"
            );
        }
    }
}
