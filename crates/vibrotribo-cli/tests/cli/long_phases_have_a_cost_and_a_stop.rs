//! Long phases ran without an estimate and ignored SIGTERM: a random excitation over
//! 0.001–5000 Hz built 89 759 harmonics over 106 668 intervals (minutes) without a word, and
//! a chain of 2000 masses spent more than ten minutes in the motion classification's Lyapunov
//! run. The build is now refused past its documented cost unless `--allow-large` and stops on
//! SIGTERM; the classification of a chain too large for it is skipped with the reason.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::util::{stderr, tempdir, vibrotribo};

/// The settings of a flat random excitation over `f_low`–`f_high` Hz for `duration` s.
fn random(f_low: &str, f_high: &str, duration: &str) -> Vec<String> {
    [
        "excitation.kind=\"random\"".to_string(),
        "excitation.rms_acceleration=1.0".into(),
        format!("excitation.f_low_hz={f_low}"),
        format!("excitation.f_high_hz={f_high}"),
        format!("excitation.duration_s={duration}"),
        "run.periods=4".into(),
        "run.transient_periods=2".into(),
    ]
    .into_iter()
    .flat_map(|s| ["--set".to_string(), s])
    .collect()
}

/// Harmonics of the grid k/D inside [f_low, f_high] (counted here, not by the program).
fn grid_count(f_low: f64, f_high: f64, duration: f64) -> u64 {
    ((f_high * duration).floor() - (f_low * duration).ceil().max(1.0) + 1.0) as u64
}

#[test]
fn random_excitation_too_costly_to_build_is_refused_with_its_size() {
    let mut args = vec!["simulate".to_string(), "-q".into()];
    args.extend(random("0.001", "5000", "20"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let harmonics = grid_count(0.001, 5000.0, 20.0);
    assert_eq!(harmonics, 100_000);
    assert!(err.contains(&format!("{harmonics} harmonics")), "{err}");
    assert!(
        err.contains("intervals") && err.contains("--allow-large"),
        "{err}"
    );
    assert!(err.contains("limit of 1e9"), "{err}");
}

#[test]
fn random_excitation_within_the_limit_still_runs() {
    let mut args = vec!["simulate".to_string(), "-q".into()];
    args.extend(random("5", "50", "20"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = vibrotribo(&args);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// SIGTERM while an allowed, large random excitation is being built: the program stops
/// there (status 143) and says so, instead of finishing the build first.
#[test]
fn sigterm_stops_a_large_random_excitation_build() {
    let dir = tempdir();
    let mut args = vec!["simulate".to_string(), "-q".into(), "--allow-large".into()];
    args.extend(random("0.001", "5000", "20"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_vibrotribo"))
        .args(&args)
        .current_dir(dir.path())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_secs(2));
    let _ = Command::new("kill")
        .arg("-15")
        .arg(child.id().to_string())
        .status();
    // A bound against a hang, not a timing claim: the unpolled build took minutes.
    let asked = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if asked.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let mut err = String::new();
    use std::io::Read;
    child.stderr.take().unwrap().read_to_string(&mut err).unwrap();
    let status = status.expect("the build did not stop within a minute of SIGTERM");
    assert_eq!(status.code(), Some(143), "{err}");
    assert!(
        err.contains("interrupted") && err.contains("base motion"),
        "{err}"
    );
}
