//! `--resume` of a finished job whose data file was deleted or cut reported `"complete": true`
//! with the rows missing; `merge` checked the row counts, resume did not. A second job into
//! an --out directory holding another job's results mixed their files.

use super::util::{stderr, sweep_args, tempdir, vibrotribo};

#[test]
fn resume_refuses_a_cut_or_deleted_file() {
    let dir = tempdir();
    let out = dir.path().join("sw");
    let o = vibrotribo(&sweep_args(out.to_str().unwrap(), &["--settle", "fixed"]));
    assert!(o.status.success(), "{}", stderr(&o));
    let orbit = out.join("orbit.csv");
    let text = std::fs::read_to_string(&orbit).unwrap();
    let cut: String = text.lines().take(3).map(|l| format!("{l}\n")).collect();
    std::fs::write(&orbit, cut).unwrap();
    let o = vibrotribo(&sweep_args(
        out.to_str().unwrap(),
        &["--settle", "fixed", "--resume"],
    ));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("orbit.csv holds 2 rows"), "{err}");
    std::fs::remove_file(&orbit).unwrap();
    let o = vibrotribo(&sweep_args(
        out.to_str().unwrap(),
        &["--settle", "fixed", "--resume"],
    ));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("orbit.csv"), "{}", stderr(&o));
}

#[test]
fn out_holding_another_job_is_refused_without_force() {
    let dir = tempdir();
    let out = dir.path().join("d");
    let d = out.to_str().unwrap();
    let short = ["--set", "run.periods=6", "--set", "run.transient_periods=2"];
    let mut sim = vec!["simulate", "-q", "--out", d];
    sim.extend_from_slice(&short);
    assert!(vibrotribo(&sim).status.success());
    // The same run again is no other job.
    assert!(vibrotribo(&sim).status.success());
    let mut two = sim.clone();
    two.extend_from_slice(&[
        "--set",
        "oscillator.masses=[0.05,0.05]",
        "--set",
        "oscillator.gaps=[0.02]",
    ]);
    let o = vibrotribo(&two);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("another job") && stderr(&o).contains("--force"),
        "{}",
        stderr(&o)
    );
    let o = vibrotribo(&sweep_args(d, &["--settle", "fixed"]));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("summary.json"), "{}", stderr(&o));
    two.push("--force");
    let o = vibrotribo(&two);
    assert!(o.status.success(), "{}", stderr(&o));
}
