//! Running a grid job's points: checks before the run, parallel chunks with a progress bar
//! and a clean stop on SIGINT/SIGTERM, the worker threads, and size estimates.

use std::ops::ControlFlow;

use anyhow::{Context, Result, anyhow, bail};
use vibrotribo::study::PointResult;
use vibrotribo::sweep::{Delivery, PointRunner, SweepError, is_stopped, run_chunks};

use crate::limits;
use crate::progress::{Progress, interrupted};

/// Checks every point of a grid (`keys` gives each point's settings); the error names the
/// first bad point.
pub fn check_all<'k, P>(
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)>,
) -> Result<()> {
    for p in points {
        let k = keys(p);
        runner.configure(&k).with_context(|| {
            k.iter()
                .map(|(key, v)| format!("{key} = {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        })?;
    }
    Ok(())
}

/// Runs `points` in parallel chunks (see [`vibrotribo::sweep::run_grid`]), calling `write`
/// with each point's result in grid order and with `None` after each chunk, ticking a
/// progress bar (label, points done before, points in all) and stopping on SIGINT/SIGTERM
/// after the current chunk, or at the first point the runner's cancel hook stopped (not
/// written), keeping what was written. Returns how many were written.
pub fn run_points<'k, P, W>(
    runner: &PointRunner,
    points: &[P],
    keys: impl Fn(&P) -> Vec<(&'k str, f64)> + Sync,
    progress: (&str, u64, u64),
    quiet: bool,
    mut write: W,
) -> Result<usize>
where
    P: Sync,
    W: FnMut(Option<(&P, &Result<PointResult, SweepError>)>) -> Result<()>,
{
    run_chunked(
        points,
        |p| runner.run(&keys(p), None),
        is_stopped,
        progress,
        quiet,
        |d| match d {
            Some((p, r)) => write(Some((p, &r))),
            None => write(None),
        },
    )
}

/// Runs `work` on `points` in parallel chunks ([`vibrotribo::sweep::run_chunks`]), calling
/// `write` with each result in order and with `None` after each chunk, with a progress bar
/// (label, points done before, points in all) and a stop after the current chunk on
/// SIGINT/SIGTERM, or at the first result that `stopped` says holds nothing (a point its
/// work stopped part-way: neither it nor any after it is written). Returns how many were
/// written.
pub fn run_chunked<P, R, W, F>(
    points: &[P],
    work: W,
    stopped: impl Fn(&R) -> bool,
    (what, before, total): (&str, u64, u64),
    quiet: bool,
    mut write: F,
) -> Result<usize>
where
    P: Sync,
    R: Send,
    W: Fn(&P) -> R + Sync,
    F: FnMut(Option<(&P, R)>) -> Result<()>,
{
    let progress = Progress::new(total, what, quiet).starting_at(before);
    let mut failure = None;
    let mut done = 0;
    run_chunks(points, rayon::current_num_threads() * 4, work, |d| {
        let (written, checkpoint) = match d {
            Delivery::Point(_, r) if stopped(&r) => return ControlFlow::Break(()),
            Delivery::Point(p, r) => {
                progress.inc(1);
                done += 1;
                (write(Some((p, r))), false)
            }
            Delivery::Chunk(_) => (write(None), true),
        };
        if let Err(e) = written {
            failure = Some(e);
            return ControlFlow::Break(());
        }
        if checkpoint && interrupted() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    progress.finish();
    match failure {
        Some(e) => Err(e),
        None => Ok(done),
    }
}

/// Installs the worker-thread count (once per process).
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    if let Some(n) = threads {
        if n == 0 {
            bail!("--threads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| anyhow!("cannot set up {n} threads: {e}"))?;
    }
    Ok(())
}

/// Checks that a grid's values are distinct: rows are keyed by their value.
pub fn check_distinct(what: &str, values: &[f64]) -> Result<()> {
    let mut seen = std::collections::HashSet::new();
    for v in values {
        if !seen.insert(v.to_bits()) {
            bail!("{what}: the grid repeats the value {v} (use --steps 1 for a single value)");
        }
    }
    Ok(())
}

/// Estimated bytes written per point of a sweep or map (the orbit rows dominate).
pub fn estimate_point_output(runner: &PointRunner, orbit: bool) -> f64 {
    let o = runner.options();
    let n = runner.masses() as f64;
    let orbit_bytes = if orbit {
        o.recorded_periods as f64 * (n + 2.0) * limits::CSV_NUMBER_BYTES
    } else {
        0.0
    };
    orbit_bytes + (n + 8.0) * limits::CSV_NUMBER_BYTES
}

/// Estimated memory of one point's run (stroboscopic samples and per-period counts).
pub fn estimate_point_memory(runner: &PointRunner) -> f64 {
    vibrotribo::study::limits::point_memory_bytes(runner.options(), runner.masses())
}
