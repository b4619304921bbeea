//! `vibrotribo basins` and `vibrotribo attractors`: one attractor for a chain that never
//! touches, the two coexisting orbits of the paper's Fig. 7 (R_δ = 1.09), outputs identical
//! for 1 and 2 threads, for sharded and merged jobs and after a cut and `--resume`.

use std::path::Path;

use super::util::*;

/// A basins job over (x₂, v₂) of Fig. 7's chain at R_δ = 1.09, with `extra`.
fn basins(dir: &Path, extra: &[&str]) -> Vec<String> {
    basins_of(dir, "300", extra)
}

fn basins_of(dir: &Path, transient: &str, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "basins",
        "-q",
        "--set",
        "oscillator.masses=[0.09,0.12,0.09]",
        "--set",
        "gap_ratio=1.09",
        "--x",
        "run.initial_positions[1]",
        "--x-from",
        "-0.02",
        "--x-to",
        "0.018",
        "--y",
        "run.initial_velocities[1]",
        "--y-from",
        "-3",
        "--y-to",
        "3",
        "--grid",
        "5x6",
        "--transient",
        transient,
        "--recorded",
        "32",
        "--mechanics-only",
        "--out",
        dir.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn run(args: &[String]) -> String {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&a);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

const FILES: [&str; 4] = ["starts.csv", "basins.csv", "attractors.csv", "basins.json"];

#[test]
fn an_impact_free_chain_has_one_basin() {
    let root = tempdir();
    let d = root.path().join("free");
    // Gaps of 10 m (set after the gap ratio): nothing ever touches.
    let out = run(&basins_of(&d, "500", &["--set", "oscillator.gaps=[10.0,10.0]"]));
    assert!(out.contains("1 attractors"), "{out}");
    let (h, rows) = read_csv(&d.join("basins.csv"));
    assert_eq!(
        h,
        [
            "x",
            "y",
            "attractor",
            "period",
            "impacts_per_period",
            "average_power_w"
        ]
    );
    assert_eq!(rows.len(), 30);
    assert!(
        rows.iter().all(|r| r[2] == "1" && r[3] == "1" && r[4] == "0"),
        "{rows:?}"
    );
    let (_, a) = read_csv(&d.join("attractors.csv"));
    assert_eq!(a.len(), 1);
    assert_eq!(a[0][3], "1");
}

#[test]
fn the_bistable_case_threads_shards_and_resume_give_the_same_files() {
    let root = tempdir();
    let one = root.path().join("one");
    let out = run(&basins(&one, &["--threads", "1", "--plot"]));
    println!("{out}");
    let (_, a) = read_csv(&one.join("attractors.csv"));
    let mut impacts: Vec<&str> = a.iter().map(|r| r[5].as_str()).collect();
    impacts.sort_unstable();
    assert_eq!(impacts, ["2", "4"], "{a:?}");
    let fractions: f64 = a.iter().map(|r| r[3].parse::<f64>().unwrap()).sum();
    assert!((fractions - 1.0).abs() < 1e-12);
    assert!(one.join("basins.png").exists() && one.join("basins.svg").exists());
    let two = root.path().join("two");
    run(&basins(&two, &["--threads", "2"]));
    files_equal(&one, &two, &FILES);
    // Three shards merged.
    let merged = root.path().join("merged");
    let mut merge = vec![
        "merge".to_string(),
        "--out".into(),
        merged.to_str().unwrap().into(),
    ];
    for i in 0..3 {
        let dir = root.path().join(format!("sh{i}"));
        run(&basins(&dir, &["--shard", &format!("{i}/3")]));
        assert!(!dir.join("basins.csv").exists(), "a shard does not classify");
        merge.push(dir.to_str().unwrap().into());
    }
    run(&merge);
    files_equal(&one, &merged, &FILES);
    // Cut as a kill -9 could leave it, then resumed.
    let cut_dir = root.path().join("cut");
    copy_dir(&one, &cut_dir);
    for f in ["basins.csv", "attractors.csv", "basins.png", "basins.svg"] {
        std::fs::remove_file(cut_dir.join(f)).unwrap();
    }
    cut(&cut_dir, "starts.csv", &[], 2, "basins.json", 0.55, 0.0);
    run(&basins(&cut_dir, &["--resume"]));
    files_equal(&one, &cut_dir, &FILES);
    // `plot` of the directory classifies and draws it again, identically.
    let o = vibrotribo(&["plot", cut_dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    files_equal(&one, &cut_dir, &FILES);
}

#[test]
fn basins_keys_must_be_initial_conditions() {
    let root = tempdir();
    let d = root.path().join("bad");
    let mut args = basins(&d, &[]);
    let i = args.iter().position(|a| a == "run.initial_positions[1]").unwrap();
    args[i] = "omega_ratio".into();
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&a);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("basins vary initial conditions"),
        "{}",
        stderr(&o)
    );
    args[i] = "run.initial_positions[3]".into();
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&a);
    assert!(stderr(&o).contains("index 3 out of range"), "{}", stderr(&o));
}

fn attractors(dir: &Path, threads: &str) -> Vec<String> {
    [
        "attractors",
        "-q",
        "--set",
        "oscillator.masses=[0.09,0.12,0.09]",
        "--param",
        "gap_ratio",
        "--from",
        "1.08",
        "--to",
        "1.12",
        "--steps",
        "3",
        "--samples",
        "8",
        "--seed",
        "3",
        "--transient",
        "200",
        "--recorded",
        "32",
        "--threads",
        threads,
        "--out",
        dir.to_str().unwrap(),
        "--plot",
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn attractors_across_a_parameter_with_expected_power() {
    let root = tempdir();
    let (one, two) = (root.path().join("one"), root.path().join("two"));
    run(&attractors(&one, "1"));
    run(&attractors(&two, "2"));
    files_equal(
        &one,
        &two,
        &["attractors.csv", "expected_power.csv", "attractors.json"],
    );
    assert!(one.join("attractor_fractions.png").exists() && one.join("attractor_power.png").exists());
    let (h, rows) = read_csv(&one.join("attractors.csv"));
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let (_, expected) = read_csv(&one.join("expected_power.csv"));
    assert_eq!(expected.len(), 3);
    for e in &expected {
        let here: Vec<&Vec<String>> = rows.iter().filter(|r| r[0] == e[0]).collect();
        let f: f64 = here
            .iter()
            .map(|r| r[col("fraction")].parse::<f64>().unwrap())
            .sum();
        assert!((f - 1.0).abs() < 1e-12, "fractions at {} sum to {f}", e[0]);
        let weighted: f64 = here
            .iter()
            .filter(|r| r[col("starts")] != "0")
            .map(|r| {
                r[col("fraction")].parse::<f64>().unwrap() * r[col("average_power_w")].parse::<f64>().unwrap()
            })
            .sum();
        let p: f64 = e[1].parse().unwrap();
        assert!((p - weighted).abs() < 1e-9 * p, "{p} vs {weighted}");
    }
}
