//! `--plot` without `--out` failed ("--plot needs --out DIR"), and no command said which
//! pictures it drew (`plot DIR` printed nothing on success). Now `--plot` alone writes into
//! `vibrotribo-out/COMMAND` and says so, and every picture drawn is listed.

use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

use super::util::*;

fn run_in(cwd: &Path, args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("cannot run vibrotribo");
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr(&o),
    )
}

/// The pictures the output lists (`drew N pictures in DIR: a, b (.png, .svg)`), as
/// `DIR/name.ext` paths, and the counts it states.
fn listed(stdout: &str) -> (BTreeSet<String>, usize) {
    let mut files = BTreeSet::new();
    let mut stated = 0;
    for line in stdout.lines().filter_map(|l| l.trim().strip_prefix("drew ")) {
        let (count, rest) = line.split_once(' ').unwrap();
        stated += count.parse::<usize>().unwrap();
        let rest = rest.split_once(" in ").unwrap().1;
        let (dir, rest) = rest.split_once(": ").unwrap();
        let (names, exts) = rest.rsplit_once(" (").unwrap();
        for name in names.split(", ") {
            for ext in exts.trim_end_matches(')').split(", ") {
                files.insert(format!("{dir}/{name}{ext}"));
            }
        }
    }
    (files, stated)
}

/// The picture files under `dir`, as `prefix/name.ext`.
fn pictures(dir: &Path, prefix: &str) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".png") || n.ends_with(".svg"))
        .map(|n| format!("{prefix}/{n}"))
        .collect()
}

#[test]
fn plot_without_out_writes_into_the_default_folder_and_lists_the_pictures() {
    let cwd = tempdir();
    let (ok, out, err) = run_in(
        cwd.path(),
        &[
            "simulate",
            "--plot",
            "--set",
            "run.periods=20",
            "--set",
            "run.transient_periods=10",
        ],
    );
    assert!(ok, "{err}");
    assert!(
        out.contains("no --out given, writing into vibrotribo-out/simulate"),
        "{out}"
    );
    let dir = cwd.path().join("vibrotribo-out/simulate");
    for f in ["events.csv", "trajectory.csv", "summary.json"] {
        assert!(dir.join(f).is_file(), "{f} missing; output:\n{out}");
    }
    let (listed, stated) = listed(&out);
    let on_disk = pictures(&dir, "vibrotribo-out/simulate");
    assert!(!on_disk.is_empty(), "no pictures drawn:\n{out}");
    assert_eq!(
        listed, on_disk,
        "the pictures listed are not the ones on disk:\n{out}"
    );
    assert_eq!(stated * 2, on_disk.len(), "{out}");
}

#[test]
fn plot_lists_what_it_drew() {
    let cwd = tempdir();
    let (ok, out, err) = run_in(
        cwd.path(),
        &[
            "sweep",
            "--param",
            "gap_ratio",
            "--from",
            "1.0",
            "--to",
            "1.2",
            "--steps",
            "3",
            "--transient",
            "20",
            "--recorded",
            "8",
            "--out",
            "sw",
            "--quiet",
        ],
    );
    assert!(ok, "{err}");
    assert!(
        !out.contains("drew"),
        "a sweep without --plot drew pictures:\n{out}"
    );
    assert!(pictures(&cwd.path().join("sw"), "sw").is_empty());
    let (ok, out, err) = run_in(cwd.path(), &["plot", "sw"]);
    assert!(ok, "{err}");
    let (listed, _) = listed(&out);
    let on_disk = pictures(&cwd.path().join("sw"), "sw");
    assert!(on_disk.len() >= 4, "{on_disk:?}");
    assert_eq!(listed, on_disk, "plot's list is not what it drew:\n{out}");
}
