//! Printing to a closed pipe (`| head`) or a full disk (`> /dev/full`) panicked with "failed
//! printing to stdout" and a backtrace.

use std::process::{Command, Stdio};

fn short_run() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_vibrotribo"));
    c.args([
        "simulate",
        "-q",
        "--set",
        "run.periods=4",
        "--set",
        "run.transient_periods=2",
    ]);
    c
}

#[test]
fn closed_pipe_exits_quietly() {
    let mut child = short_run()
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes away before the first line is written.
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.is_empty(), "a closed pipe is no error: {err}");
}

#[test]
fn full_disk_is_one_line_error() {
    if !std::path::Path::new("/dev/full").exists() {
        return;
    }
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let o = short_run().stdout(full).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("cannot write to standard output"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}
