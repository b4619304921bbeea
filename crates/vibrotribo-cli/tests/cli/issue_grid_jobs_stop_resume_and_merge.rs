//! `merge` rejected complete, valid shards (grid values read back from sweep.json one
//! ulp off); a shard rerun killed by SIGTERM left the old `"complete": true` beside cut CSVs,
//! and `merge` then produced an incomplete result with exit 0; SIGTERM was not handled,
//! interrupted runs exited 0, and nothing could be resumed.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use super::util::*;

/// A sweep of the chatter-prone default case, `steps` values of Ω in [0.55, 0.95].
fn sweep(dir: &Path, steps: &str, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "sweep",
        "-q",
        "--param",
        "omega_ratio",
        "--from",
        "0.55",
        "--to",
        "0.95",
        "--steps",
        steps,
        "--transient",
        "40",
        "--recorded",
        "12",
        "--out",
        dir.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn run(args: &[String]) -> std::process::Output {
    let a: Vec<&str> = args.iter().map(String::as_str).collect();
    vibrotribo(&a)
}

const SWEEP_FILES: [&str; 4] = ["orbit.csv", "impacts.csv", "summary.csv", "sweep.json"];

#[test]
fn merge_accepts_the_shards_of_the_issue_and_equals_the_unsharded_run() {
    // The issue's grid (0.55..0.95, 24 steps): values such as 0.6195652173913043 did not
    // survive a JSON round trip without exact float parsing.
    let root = tempdir();
    let whole = root.path().join("whole");
    assert!(run(&sweep(&whole, "24", &[])).status.success());
    let mut merge = vec!["merge".to_string(), "--out".into()];
    let merged = root.path().join("merged");
    merge.push(merged.to_str().unwrap().into());
    for i in 0..3 {
        let dir = root.path().join(format!("sh{i}"));
        let o = run(&sweep(&dir, "24", &["--shard", &format!("{i}/3")]));
        assert!(o.status.success(), "{}", stderr(&o));
        merge.push(dir.to_str().unwrap().into());
    }
    let o = run(&merge);
    assert!(o.status.success(), "{}", stderr(&o));
    files_equal(&whole, &merged, &SWEEP_FILES);
    let m = manifest(&merged, "sweep.json");
    assert_eq!(m["complete"], true);
    assert_eq!(m["rows"]["summary.csv"], 24);
}

/// Starts `args` and sends `signal` once the job has started (its manifest says
/// `"complete": false`) and `dir/file` holds more than `rows` lines.
fn interrupt_after(
    args: &[String],
    dir: &Path,
    file: &str,
    rows: usize,
    signal: &str,
) -> std::process::ExitStatus {
    let mut child: Child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = Instant::now();
    loop {
        let started_job =
            std::fs::read_to_string(dir.join("sweep.json")).is_ok_and(|m| m.contains("\"complete\": false"));
        let n = std::fs::read_to_string(dir.join(file)).map_or(0, |t| t.lines().count());
        if started_job && n > rows {
            break;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("finished ({status}) before it could be interrupted: make the job longer");
        }
        assert!(started.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
    let pid = child.id().to_string();
    assert!(
        Command::new("kill")
            .args([signal, &pid])
            .status()
            .unwrap()
            .success()
    );
    child.wait().unwrap()
}

#[test]
fn signals_stop_cleanly_mark_incomplete_and_resume_to_the_uninterrupted_result() {
    let root = tempdir();
    let whole = root.path().join("whole");
    assert!(run(&sweep(&whole, "1000", &["--threads", "1"])).status.success());
    for (signal, code) in [("-TERM", 143), ("-INT", 130)] {
        let dir = root.path().join(format!("cut{code}"));
        let args = sweep(&dir, "1000", &["--threads", "1"]);
        let status = interrupt_after(&args, &dir, "summary.csv", 3, signal);
        assert_eq!(status.code(), Some(code), "{signal}");
        let m = manifest(&dir, "sweep.json");
        assert_eq!(m["complete"], false, "{signal}");
        let done = m["done"].as_u64().unwrap();
        assert!((3..1000).contains(&done), "{signal}: done = {done}");
        // merge refuses it and leaves nothing behind.
        let out = root.path().join(format!("merged{code}"));
        let o = vibrotribo(&["merge", dir.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        assert!(!o.status.success());
        assert!(!out.exists(), "merge left {}", out.display());
        let mut resume = args.clone();
        resume.push("--resume".into());
        let o = run(&resume);
        assert!(o.status.success(), "{}", stderr(&o));
        files_equal(&whole, &dir, &SWEEP_FILES);
    }
}

#[test]
fn a_rerun_shard_killed_is_incomplete_and_merge_refuses_it() {
    let root = tempdir();
    let s0 = root.path().join("s0");
    let s1 = root.path().join("s1");
    assert!(
        run(&sweep(&s0, "1000", &["--shard", "0/2", "--threads", "1"]))
            .status
            .success()
    );
    assert!(
        run(&sweep(&s1, "1000", &["--shard", "1/2", "--threads", "1"]))
            .status
            .success()
    );
    // Rerun shard 1 and kill it as a Slurm time limit would.
    let status = interrupt_after(
        &sweep(&s1, "1000", &["--shard", "1/2", "--threads", "1"]),
        &s1,
        "summary.csv",
        2,
        "-TERM",
    );
    assert_eq!(status.code(), Some(143));
    let out = root.path().join("merged");
    let o = vibrotribo(&[
        "merge",
        s0.to_str().unwrap(),
        s1.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("incomplete"), "{}", stderr(&o));
    assert!(!out.exists());
}

#[test]
fn resume_after_a_cut_at_any_point_is_byte_identical() {
    let root = tempdir();
    for continuation in ["none", "up"] {
        let whole = root.path().join(format!("whole-{continuation}"));
        let extra = ["--continuation", continuation];
        assert!(run(&sweep(&whole, "30", &extra)).status.success());
        let cuts = [
            (0.0, 0.0),
            (0.013, 0.5),
            (0.31, 0.0),
            (0.5, 0.999),
            (0.77, 0.3),
            (0.999, 0.7),
        ];
        for (k, (fraction, beyond)) in cuts.into_iter().enumerate() {
            let dir = root.path().join(format!("cut-{continuation}-{k}"));
            copy_dir(&whole, &dir);
            cut(
                &dir,
                "summary.csv",
                &["orbit.csv", "impacts.csv"],
                1,
                "sweep.json",
                fraction,
                beyond,
            );
            if continuation == "up" {
                // A checkpoint older than the rows: the rows beyond it are recomputed.
                std::fs::write(dir.join("checkpoint.json"), r#"{"done": 0, "state": null}"#).unwrap();
            }
            let mut args = sweep(&dir, "30", &extra);
            args.push("--resume".into());
            let o = run(&args);
            assert!(o.status.success(), "{continuation} {fraction}: {}", stderr(&o));
            files_equal(&whole, &dir, &SWEEP_FILES);
            assert!(!dir.join("checkpoint.json").exists());
        }
    }
    // Another job's directory is not resumed.
    let whole = root.path().join("whole-none");
    let mut args = sweep(&whole, "31", &[]);
    args.push("--resume".into());
    let o = run(&args);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("different job"), "{}", stderr(&o));
}

#[test]
fn merge_refuses_files_that_do_not_hold_their_counted_rows() {
    let root = tempdir();
    let (s0, s1) = (root.path().join("s0"), root.path().join("s1"));
    assert!(run(&sweep(&s0, "12", &["--shard", "0/2"])).status.success());
    assert!(run(&sweep(&s1, "12", &["--shard", "1/2"])).status.success());
    let orbit = s1.join("orbit.csv");
    let text = std::fs::read_to_string(&orbit).unwrap();
    let cut_at = text[..text.len() / 2].rfind('\n').unwrap() + 1;
    std::fs::write(&orbit, &text[..cut_at]).unwrap();
    let out = root.path().join("merged");
    let o = vibrotribo(&[
        "merge",
        s0.to_str().unwrap(),
        s1.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("orbit.csv holds"), "{}", stderr(&o));
    assert!(!out.exists());
}

fn map(dir: &Path, extra: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "map",
        "-q",
        "--x",
        "omega_ratio",
        "--x-from",
        "0.6",
        "--x-to",
        "0.8",
        "--x-steps",
        "5",
        "--y",
        "mass_ratio",
        "--y-from",
        "2",
        "--y-to",
        "3",
        "--y-steps",
        "3",
        "--transient",
        "30",
        "--recorded",
        "10",
        "--out",
        dir.to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec();
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

#[test]
fn maps_shard_merge_and_resume() {
    let root = tempdir();
    let whole = root.path().join("whole");
    assert!(run(&map(&whole, &[])).status.success());
    let mut merge = vec!["merge".to_string()];
    for i in 0..3 {
        let dir = root.path().join(format!("m{i}"));
        assert!(run(&map(&dir, &["--shard", &format!("{i}/3")])).status.success());
        merge.push(dir.to_str().unwrap().into());
    }
    let merged = root.path().join("merged");
    merge.extend(["--out".into(), merged.to_str().unwrap().into()]);
    let o = run(&merge);
    assert!(o.status.success(), "{}", stderr(&o));
    files_equal(&whole, &merged, &["map.csv", "map.json"]);
    let cutdir = root.path().join("cut");
    copy_dir(&whole, &cutdir);
    cut(&cutdir, "map.csv", &[], 2, "map.json", 0.6, 0.0);
    let mut args = map(&cutdir, &[]);
    args.push("--resume".into());
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    files_equal(&whole, &cutdir, &["map.csv", "map.json"]);
}
