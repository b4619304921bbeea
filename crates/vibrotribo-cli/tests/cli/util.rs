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
