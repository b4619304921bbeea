//! The up and down sweeps of a frequency response, run side by side, and the response they
//! and the branches make together.

use std::ops::ControlFlow;
use std::sync::atomic::{AtomicBool, Ordering};

use super::branches::{BranchFailure, BranchSeeding, ResponseBranch, follow_branches};
use super::error::ResponseError;
use crate::analysis::{AnalysisError, Bandwidth, half_power_bandwidth};
use crate::config::Param;
use crate::model::ChainState;
use crate::study::{Direction, PointResult};
use crate::sweep::{PointRunner, SweepError};

/// What a frequency response computes besides its two sweeps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ResponseOptions {
    /// Continuation of the branches the sweeps found ([`BranchSeeding`]); `None` (default):
    /// the sweeps only.
    pub branches: Option<BranchSeeding>,
}

/// A step of a frequency response, reported as it finishes (to count progress and to stop).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ResponseStep {
    /// One value of a sweep.
    Value(Direction),
    /// One continuation of a branch (from a seed towards one end of the range).
    Continuation,
    /// The power on one point of a continued branch.
    BranchPower,
}

/// The hook a response reports its steps to; [`ControlFlow::Break`] stops it at the next
/// step (the results so far are kept, marked incomplete). Called from two threads at once
/// (the two sweeps run side by side).
pub type ResponseHook<'a> = &'a (dyn Fn(ResponseStep) -> ControlFlow<()> + Sync);

/// One sweep of a response: the values in one direction, each started from the final state
/// of the one before.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseSweep {
    /// Which way it ran (`Up`: the values in increasing order).
    pub direction: Direction,
    /// The result of each value, in the order of the values (increasing); `None` where the
    /// sweep stopped before reaching it.
    pub results: Vec<Option<Result<PointResult, SweepError>>>,
}

impl ResponseSweep {
    /// `(value, average power in W)` of the values that ran and have a power, in increasing
    /// order of the value.
    pub fn power(&self, values: &[f64]) -> Vec<(f64, f64)> {
        values
            .iter()
            .zip(&self.results)
            .filter_map(|(&v, r)| {
                let p = r.as_ref()?.as_ref().ok()?.average_power_w?;
                p.is_finite().then_some((v, p))
            })
            .collect()
    }

    /// Values computed (failed ones included).
    pub fn done(&self) -> usize {
        self.results.iter().filter(|r| r.is_some()).count()
    }

    /// Values whose run failed.
    pub fn failed(&self) -> usize {
        self.results.iter().filter(|r| matches!(r, Some(Err(_)))).count()
    }
}

/// A frequency response: average power against a parameter from an up and a down sweep and,
/// if asked, on the branches of periodic orbits that continuation follows from the periodic
/// motions the sweeps found.
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyResponse {
    /// The swept key.
    pub key: String,
    /// Its values, increasing.
    pub values: Vec<f64>,
    /// The up sweep.
    pub up: ResponseSweep,
    /// The down sweep.
    pub down: ResponseSweep,
    /// The branches followed, in the order they were found (empty unless asked).
    pub branches: Vec<ResponseBranch>,
    /// Continuations that could not start or failed.
    pub branch_failures: Vec<BranchFailure>,
    /// Periodic sweep values on no branch followed that were not continued, because
    /// [`BranchSeeding::max_seeds`] seeds had been continued already.
    pub seeds_skipped: usize,
    /// Whether everything asked for was computed (false when the hook stopped it).
    pub complete: bool,
}

impl FrequencyResponse {
    /// The sweep of `direction`.
    pub fn sweep(&self, direction: Direction) -> &ResponseSweep {
        match direction {
            Direction::Up => &self.up,
            Direction::Down => &self.down,
        }
    }

    /// The peak and half-power band of one sweep.
    pub fn sweep_bandwidth(&self, direction: Direction) -> Result<Bandwidth, AnalysisError> {
        half_power_bandwidth(&[&self.sweep(direction).power(&self.values)])
    }

    /// The peak and half-power band of the envelope of both sweeps and the stable points of
    /// every branch ([`half_power_bandwidth`]): at each value the most power any motion the
    /// device can settle on delivers there.
    pub fn bandwidth(&self) -> Result<Bandwidth, AnalysisError> {
        let mut all = vec![self.up.power(&self.values), self.down.power(&self.values)];
        all.extend(self.branches.iter().flat_map(ResponseBranch::stable_runs));
        let refs: Vec<&[(f64, f64)]> = all.iter().map(Vec::as_slice).collect();
        half_power_bandwidth(&refs)
    }
}

/// Checks the values (finite, strictly increasing) and that each makes a valid configuration.
fn check_values(runner: &PointRunner, param: &Param, values: &[f64]) -> Result<(), ResponseError> {
    if values.is_empty() {
        return Err(ResponseError::NoValues);
    }
    for (index, &value) in values.iter().enumerate() {
        if !value.is_finite() || (index > 0 && value <= values[index - 1]) {
            return Err(ResponseError::BadValues { index, value });
        }
        runner.base().with_values(&[(param, value)])?;
    }
    Ok(())
}

/// One sweep: the values in `direction`, each from the previous one's final state (a failed
/// value passes on the state it was given), until the end or a stop.
fn run_sweep(
    runner: &PointRunner,
    param: &Param,
    values: &[f64],
    direction: Direction,
    (each, stop): (ResponseHook<'_>, &AtomicBool),
) -> ResponseSweep {
    let mut results: Vec<Option<Result<PointResult, SweepError>>> = vec![None; values.len()];
    let mut order: Vec<usize> = (0..values.len()).collect();
    if direction == Direction::Down {
        order.reverse();
    }
    let mut state: Option<ChainState> = None;
    for j in order {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let r = runner.run_values(&[(param, values[j])], state.as_ref());
        if let Ok(p) = &r {
            state = Some(p.final_state.clone());
        }
        results[j] = Some(r);
        if each(ResponseStep::Value(direction)).is_break() {
            stop.store(true, Ordering::SeqCst);
        }
    }
    ResponseSweep { direction, results }
}

/// The frequency response of `runner`'s configuration in `key` over `values` (finite,
/// increasing): an up sweep (the values in order) and a down sweep (in reverse), each value
/// started from the final state of the one before so that coexisting motions show as
/// hysteresis; the two sweeps run side by side on two threads. With
/// [`ResponseOptions::branches`], the branches of periodic orbits through the periodic
/// motions the sweeps found are then followed by continuation ([`BranchSeeding`]).
///
/// `each` is told every step and may stop the response: the values and branches computed
/// are returned, [`FrequencyResponse::complete`] false.
pub fn frequency_response(
    runner: &PointRunner,
    key: &str,
    values: &[f64],
    options: &ResponseOptions,
    each: ResponseHook<'_>,
) -> Result<FrequencyResponse, ResponseError> {
    // Each value starts at t = 0 from the previous one's final state: the same phase of the
    // base motion only if it is periodic.
    runner.base().check_periodic("the frequency response's sweeps")?;
    if let Some(seeding) = &options.branches {
        seeding.validate()?;
        runner
            .base()
            .check_uncoupled("the frequency response's branches")?;
    }
    let param = runner.param(key)?;
    check_values(runner, &param, values)?;
    let stop = AtomicBool::new(false);
    let (up, down) = std::thread::scope(|s| {
        let up = s.spawn(|| run_sweep(runner, &param, values, Direction::Up, (each, &stop)));
        let down = run_sweep(runner, &param, values, Direction::Down, (each, &stop));
        // A panic in the up sweep is a bug: re-raised here, as it would be on one thread.
        let up = up.join().unwrap_or_else(|p| std::panic::resume_unwind(p));
        (up, down)
    });
    let mut response = FrequencyResponse {
        key: key.to_string(),
        values: values.to_vec(),
        up,
        down,
        branches: Vec::new(),
        branch_failures: Vec::new(),
        seeds_skipped: 0,
        complete: false,
    };
    if stop.load(Ordering::SeqCst) {
        return Ok(response);
    }
    if let Some(seeding) = &options.branches {
        let followed = follow_branches(runner.base(), &response, seeding, each);
        response.branches = followed.branches;
        response.branch_failures = followed.failures;
        response.seeds_skipped = followed.seeds_skipped;
        response.complete = followed.complete;
    } else {
        response.complete = true;
    }
    Ok(response)
}
