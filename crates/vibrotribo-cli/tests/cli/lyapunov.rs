//! `vibrotribo lyapunov` and `sweep --lyapunov`: the file contracts, agreement between the
//! two, and sweeps with the column sharded, merged and resumed byte for byte.

use std::path::Path;

use super::util::*;
use vibrotribo::sweep::MOTION_COLUMNS;

fn json(dir: &Path, name: &str) -> serde_json::Value {
    serde_json::from_str(&read(dir, name)).unwrap()
}

#[test]
fn lyapunov_writes_the_spectrum_largest_first_with_minus_infinity_as_null() {
    let root = tempdir();
    let d = root.path().join("default");
    let o = vibrotribo(&[
        "lyapunov",
        "--periods",
        "200",
        "--transient",
        "100",
        "--out",
        d.to_str().unwrap(),
        "--plot",
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let j = json(&d, "lyapunov.json");
    let e: Vec<f64> = j["exponents"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert_eq!(e.len(), 6);
    assert!(e.windows(2).all(|w| w[0] >= w[1]), "{e:?}");
    // The default case's stable orbit: λ1 = ln|μ1|/T ≈ −1.32 1/s (tests/lyapunov.rs).
    assert!((e[0] + 1.32).abs() < 0.01, "{e:?}");
    assert_eq!(j["periods"], 200);
    assert_eq!(j["spread"].as_array().unwrap().len(), 6);
    assert!(d.join("lyapunov_running.png").exists());
    // The chatter case sticks every period: two exponents are −∞, written as null.
    let c = root.path().join("chatter");
    let o = vibrotribo(&[
        "lyapunov",
        config_file("chatter.toml").to_str().unwrap(),
        "--periods",
        "100",
        "--transient",
        "100",
        "--out",
        c.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("λ6 = −∞"), "{out}");
    let j = json(&c, "lyapunov.json");
    assert_eq!(j["collapsed"], 2);
    assert!(j["exponents"][4].is_null() && j["exponents"][5].is_null());
    assert!(j["exponents"][3].is_f64());
}

fn sweep(dir: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "sweep",
        "-q",
        "--param",
        "gap_ratio",
        "--from",
        "1.38",
        "--to",
        "1.46",
        "--steps",
        "9",
        "--set",
        "oscillator.masses=[0.09,0.12,0.09]",
        "--transient",
        "60",
        "--recorded",
        "40",
        "--mechanics-only",
        "--out",
        dir.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn run(args: &[String]) {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&a);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

#[test]
fn sweep_lyapunov_adds_two_columns_and_agrees_with_the_lyapunov_command() {
    let root = tempdir();
    let plain = root.path().join("plain");
    let with = root.path().join("with");
    // A fixed transient, as the `lyapunov` command has.
    run(&sweep(&plain, &["--settle", "fixed"]));
    run(&sweep(&with, &["--lyapunov", "--plot", "--settle", "fixed"]));
    // The other files, the leading and the motion columns are those of a sweep without the
    // option; the two Lyapunov columns come between.
    files_equal(&plain, &with, &["orbit.csv", "impacts.csv"]);
    let (a, b) = (read(&plain, "summary.csv"), read(&with, "summary.csv"));
    let motion = MOTION_COLUMNS.len();
    for (p, w) in a.lines().zip(b.lines()) {
        let (p, w): (Vec<&str>, Vec<&str>) = (p.split(',').collect(), w.split(',').collect());
        assert_eq!(w.len(), p.len() + 2);
        assert_eq!(p[..p.len() - motion], w[..p.len() - motion]);
        assert_eq!(p[p.len() - motion..], w[w.len() - motion..]);
    }
    let (h, rows) = read_csv(&with.join("summary.csv"));
    let at = h.len() - motion - 2;
    assert_eq!(h[at..at + 2], ["lyapunov_max_1_s", "lyapunov_spread_1_s"]);
    assert!(with.join("lyapunov.png").exists());
    // The value R_δ = 1.42 alone, through `lyapunov` with the same transient and periods.
    let row = rows.iter().find(|r| r[0] == "1.42").unwrap();
    let one = root.path().join("one");
    run(&[
        "lyapunov",
        "-q",
        "--set",
        "oscillator.masses=[0.09,0.12,0.09]",
        "--set",
        "gap_ratio=1.42",
        "--transient",
        "60",
        "--periods",
        "40",
        "--out",
        one.to_str().unwrap(),
    ]
    .map(String::from));
    let j = json(&one, "lyapunov.json");
    let swept: f64 = row[at].parse().unwrap();
    let alone = j["largest"].as_f64().unwrap();
    assert!((swept - alone).abs() <= 1e-12 * alone.abs(), "{swept} vs {alone}");
}

#[test]
fn sweep_lyapunov_shards_merge_and_resume_byte_for_byte() {
    let root = tempdir();
    let whole = root.path().join("whole");
    run(&sweep(&whole, &["--lyapunov"]));
    let merged = root.path().join("merged");
    let mut merge = vec![
        "merge".to_string(),
        "--out".into(),
        merged.to_str().unwrap().into(),
    ];
    for i in 0..2 {
        let dir = root.path().join(format!("sh{i}"));
        run(&sweep(&dir, &["--lyapunov", "--shard", &format!("{i}/2")]));
        merge.push(dir.to_str().unwrap().into());
    }
    run(&merge);
    let files = ["orbit.csv", "impacts.csv", "summary.csv", "sweep.json"];
    files_equal(&whole, &merged, &files);
    let cut_dir = root.path().join("cut");
    copy_dir(&whole, &cut_dir);
    cut(
        &cut_dir,
        "summary.csv",
        &["orbit.csv", "impacts.csv"],
        1,
        "sweep.json",
        0.45,
        0.5,
    );
    run(&sweep(&cut_dir, &["--lyapunov", "--resume"]));
    files_equal(&whole, &cut_dir, &files);
    // Resuming without the option is another job.
    let mut args = sweep(&cut_dir, &["--resume"]);
    args.retain(|a| a != "--lyapunov");
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&a);
    assert!(
        !o.status.success() && stderr(&o).contains("different job"),
        "{}",
        stderr(&o)
    );
}
