//! Helpers of the command-line tests: running the binary, temporary directories, files.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn vibrotribo(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(args)
        .output()
        .expect("cannot run vibrotribo")
}

pub fn tempdir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(String::from).collect()).collect();
    (header, rows)
}

pub fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../vibrotribo/tests/data/reference")
}

pub fn config_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../configs")
        .join(name)
}

pub fn sweep_args<'a>(dir: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "sweep",
        "--param",
        "excitation.omega_ratio",
        "--from",
        "0.55",
        "--to",
        "0.8",
        "--steps",
        "7",
        "--transient",
        "30",
        "--recorded",
        "24",
        "--out",
        dir,
        "--quiet",
    ];
    args.extend_from_slice(extra);
    args
}

pub fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(name).display()))
}

/// Panics with the first differing line if any of `names` differs between `a` and `b`.
pub fn files_equal(a: &Path, b: &Path, names: &[&str]) {
    for name in names {
        let (x, y) = (read(a, name), read(b, name));
        if x != y {
            let line = x.lines().zip(y.lines()).position(|(p, q)| p != q);
            panic!(
                "{name} differs between {} and {} (first differing line {line:?}; {} vs {} lines)",
                a.display(),
                b.display(),
                x.lines().count(),
                y.lines().count()
            );
        }
    }
}

/// A JSON manifest of a job directory.
pub fn manifest(dir: &Path, name: &str) -> serde_json::Value {
    serde_json::from_str(&read(dir, name)).unwrap()
}

pub fn set_len(path: &Path, len: u64) {
    let f = std::fs::OpenOptions::new().write(true).open(path).unwrap();
    f.set_len(len).unwrap();
}

/// Cuts a finished job's files as a SIGKILL could leave them, and marks the job unfinished.
/// The protocol writes a point's index row (in `index`) only once its other rows are on
/// disk: the index file is cut at `fraction` of its length, and each data file (`data`,
/// whose first `key_fields` fields name the point) at a place past the rows of the points
/// whose index rows remain, `beyond` of the way to its end.
pub fn cut(
    dir: &Path,
    index: &str,
    data: &[&str],
    key_fields: usize,
    manifest_name: &str,
    fraction: f64,
    beyond: f64,
) {
    let key = |line: &str| line.split(',').take(key_fields).collect::<Vec<_>>().join(",");
    let path = dir.join(index);
    let text = std::fs::read_to_string(&path).unwrap();
    let len = (text.len() as f64 * fraction) as usize;
    set_len(&path, len as u64);
    let kept: std::collections::HashSet<String> = text[..len]
        .split_inclusive('\n')
        .skip(1)
        .filter(|l| l.ends_with('\n'))
        .map(key)
        .collect();
    for name in data {
        let path = dir.join(name);
        let text = std::fs::read_to_string(&path).unwrap();
        let mut end = text.find('\n').unwrap() + 1;
        for line in text[end..].split_inclusive('\n') {
            if !kept.contains(&key(line)) {
                break;
            }
            end += line.len();
        }
        set_len(&path, (end as f64 + (text.len() - end) as f64 * beyond) as u64);
    }
    let mut m = manifest(dir, manifest_name);
    m["complete"] = false.into();
    std::fs::write(dir.join(manifest_name), m.to_string()).unwrap();
}

/// Copies the files of directory `from` into `to`.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}
