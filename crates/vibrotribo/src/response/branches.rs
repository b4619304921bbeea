//! The branches of a frequency response: the periodic orbits the sweeps settled on, each
//! followed by pseudo-arclength continuation across the range ([`continue_config`]), through
//! folds onto the unstable parts that join coexisting motions, with the power on every point
//! ([`branch_powers`]).
//!
//! **Seeds.** Every value of the up sweep (in its order), then of the down sweep, whose motion
//! is periodic is a candidate: its final state (at a whole period, where the base's phase is
//! 0) and its period are the guess a continuation starts from. A candidate already on a
//! branch followed — a branch of its period has two neighbouring points around its value, one
//! of them stable, between whose powers the linear interpolation lies within
//! [`BranchSeeding::match_tolerance`] of its power — is not continued again; so each motion a
//! sweep found is followed once, and a motion only the down sweep reached (the other side of
//! a hysteresis loop) gets a branch of its own. A seed is continued towards both ends of the
//! range.

use super::error::ResponseError;
use super::sweeps::{FrequencyResponse, ResponseHook, ResponseStep};
use crate::analysis::{AnalysisError, Bandwidth, half_power_bandwidth};
use crate::branch::{BranchError, BranchOptions, branch_powers, continue_config};
use crate::config::Config;
use crate::orbits::{Bifurcation, BranchEnd, ContinuationOptions, OrbitError};
use crate::study::Direction;

/// The default [`BranchSeeding::max_seeds`].
pub const DEFAULT_MAX_SEEDS: usize = 8;

/// The default [`BranchSeeding::match_tolerance`].
pub const DEFAULT_MATCH_TOLERANCE: f64 = 0.02;

/// The default most points of a branch of a response (the continuation's `max_points`).
pub const DEFAULT_BRANCH_POINTS: usize = 500;

/// How the branches of a frequency response are seeded and followed.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchSeeding {
    /// Most seeds continued (each towards both ends of the range). Default
    /// [`DEFAULT_MAX_SEEDS`].
    pub max_seeds: usize,
    /// Relative difference of power under which a periodic sweep value counts as lying on a
    /// branch already followed (see the module's documentation). Default
    /// [`DEFAULT_MATCH_TOLERANCE`] (2 %: the power on a branch point is averaged over a few
    /// periods of the orbit after a short warm-up of the charge, the sweep's over its
    /// recorded window).
    pub match_tolerance: f64,
    /// The continuation's settings (default [`ContinuationOptions::default`] with at most
    /// [`DEFAULT_BRANCH_POINTS`] points per branch); the shooting's simulator settings are the
    /// configuration's. Its cancel hook is polled at every step.
    pub continuation: ContinuationOptions,
}

impl Default for BranchSeeding {
    fn default() -> Self {
        BranchSeeding {
            max_seeds: DEFAULT_MAX_SEEDS,
            match_tolerance: DEFAULT_MATCH_TOLERANCE,
            continuation: ContinuationOptions {
                max_points: DEFAULT_BRANCH_POINTS,
                ..ContinuationOptions::default()
            },
        }
    }
}

impl BranchSeeding {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), ResponseError> {
        if self.max_seeds == 0 {
            return Err(ResponseError::Option {
                name: "max_seeds",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if !(self.match_tolerance > 0.0 && self.match_tolerance < 1.0) {
            return Err(ResponseError::Option {
                name: "match_tolerance",
                value: self.match_tolerance,
                reason: "must lie in (0, 1)",
            });
        }
        self.continuation
            .validate()
            .map_err(|e| ResponseError::Config(e.into()))
    }
}

/// Where a branch was started: a periodic value of one of the sweeps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchSeed {
    /// The sweep it comes from.
    pub direction: Direction,
    /// The value of the parameter.
    pub value: f64,
    /// Its period, in excitation periods.
    pub period: u32,
}

/// One point of a branch of a response.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResponseBranchPoint {
    /// The value of the parameter.
    pub value: f64,
    /// Whether the orbit is stable (every Floquet multiplier inside the unit circle).
    pub stable: bool,
    /// Average power on the orbit, W (NaN where the charge solver failed, or not reached).
    pub power_w: f64,
    /// Largest modulus of the Floquet multipliers.
    pub max_abs_multiplier: f64,
    /// Impacts per excitation period, all contacts.
    pub impacts_per_period: f64,
}

/// A branch of periodic orbits of a response, in order along the branch.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseBranch {
    /// The sweep value it was started from.
    pub seed: BranchSeed,
    /// The end of the range it was continued towards.
    pub towards: f64,
    /// Period of its orbits, in excitation periods (twice the seed's on a branch born at a
    /// period doubling).
    pub period: u32,
    /// Its points.
    pub points: Vec<ResponseBranchPoint>,
    /// The bifurcations located along it, in order (a fold is where a sweep jumps off it).
    pub bifurcations: Vec<Bifurcation>,
    /// Why it ended.
    pub end: BranchEnd,
}

impl ResponseBranch {
    /// `(value, power in W)` of its stable points with a power, in order along the branch,
    /// in runs of consecutive points (an unstable stretch, or a point without a power, ends
    /// a run: the band is never interpolated across it).
    pub fn stable_runs(&self) -> Vec<Vec<(f64, f64)>> {
        let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut run: Vec<(f64, f64)> = Vec::new();
        for p in &self.points {
            if p.stable && p.power_w.is_finite() {
                run.push((p.value, p.power_w));
            } else if !run.is_empty() {
                runs.push(std::mem::take(&mut run));
            }
        }
        if !run.is_empty() {
            runs.push(run);
        }
        runs
    }

    /// The peak and half-power band of its stable points ([`half_power_bandwidth`] of its
    /// [`stable_runs`](Self::stable_runs)); an edge is `None` where the stable part ends
    /// above half the peak (at a fold, say, where the motion jumps to another branch).
    pub fn bandwidth(&self) -> Result<Bandwidth, AnalysisError> {
        let runs = self.stable_runs();
        let refs: Vec<&[(f64, f64)]> = runs.iter().map(Vec::as_slice).collect();
        half_power_bandwidth(&refs)
    }

    /// Whether a motion of `period` at `value` with power `power` lies on this branch: two
    /// neighbouring points around `value` (to within `slack` in the value: a range end is
    /// reached to rounding), one of them stable, whose powers interpolate to within
    /// `tolerance` of `power`, relative.
    fn holds(&self, period: u32, value: f64, power: f64, (tolerance, slack): (f64, f64)) -> bool {
        period == self.period
            && self.points.windows(2).any(|w| {
                let (a, b) = (w[0], w[1]);
                let (lo, hi) = (a.value.min(b.value) - slack, a.value.max(b.value) + slack);
                if !(lo <= value && value <= hi && (a.stable || b.stable)) {
                    return false;
                }
                let at = if hi > lo {
                    a.power_w + (b.power_w - a.power_w) * (value - a.value) / (b.value - a.value)
                } else {
                    a.power_w
                };
                (at - power).abs() <= tolerance * power.abs()
            })
    }
}

/// A continuation of a response that could not start or failed.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchFailure {
    /// The seed.
    pub seed: BranchSeed,
    /// The end of the range it was continued towards.
    pub towards: f64,
    /// Why.
    pub error: BranchError,
}

/// What [`follow_branches`] found.
pub(super) struct Followed {
    pub(super) branches: Vec<ResponseBranch>,
    pub(super) failures: Vec<BranchFailure>,
    pub(super) seeds_skipped: usize,
    pub(super) complete: bool,
}

/// The periodic values of the sweeps, up sweep first, each in its sweep's order: the
/// candidate seeds with their state, period and power.
fn candidates(response: &FrequencyResponse) -> Vec<(BranchSeed, crate::ChainState, f64)> {
    let mut out = Vec::new();
    for direction in [Direction::Up, Direction::Down] {
        let sweep = response.sweep(direction);
        let mut order: Vec<usize> = (0..response.values.len()).collect();
        if direction == Direction::Down {
            order.reverse();
        }
        for j in order {
            let Some(Ok(p)) = &sweep.results[j] else {
                continue;
            };
            let (Some(power), Ok(period)) = (p.average_power_w, u32::try_from(p.period())) else {
                continue;
            };
            if period == 0 || !power.is_finite() {
                continue;
            }
            let seed = BranchSeed {
                direction,
                value: response.values[j],
                period,
            };
            out.push((seed, p.final_state.clone(), power));
        }
    }
    out
}

/// The branches of the periodic motions of `response`'s sweeps (see the module's
/// documentation), on `config` continued in `response.key`.
pub(super) fn follow_branches(
    config: &Config,
    response: &FrequencyResponse,
    seeding: &BranchSeeding,
    each: ResponseHook<'_>,
) -> Followed {
    let mut out = Followed {
        branches: Vec::new(),
        failures: Vec::new(),
        seeds_skipped: 0,
        complete: true,
    };
    let (Some(&first), Some(&last)) = (response.values.first(), response.values.last()) else {
        return out;
    };
    let options = BranchOptions {
        continuation: seeding.continuation.clone(),
        ..BranchOptions::default()
    };
    let key = response.key.as_str();
    let mut seeds = 0;
    for (seed, state, power) in candidates(response) {
        let slack = 1e-9 * (last - first).abs();
        let on_branch =
            |b: &ResponseBranch| b.holds(seed.period, seed.value, power, (seeding.match_tolerance, slack));
        if out.branches.iter().any(on_branch) {
            continue;
        }
        if seeds == seeding.max_seeds {
            out.seeds_skipped += 1;
            continue;
        }
        seeds += 1;
        for towards in [last, first] {
            if towards == seed.value {
                continue;
            }
            let guess = Some((state.clone(), seed.period));
            let c = match continue_config(config, key, seed.value, towards, guess, &options) {
                Ok(c) => c,
                Err(BranchError::Continuation(OrbitError::Cancelled)) => {
                    out.complete = false;
                    return out;
                }
                Err(error) => {
                    out.failures.push(BranchFailure { seed, towards, error });
                    continue;
                }
            };
            let mut stopped = !c.complete;
            let powers = branch_powers(config, key, &c, || {
                let flow = each(ResponseStep::BranchPower);
                stopped |= flow.is_break();
                flow
            });
            for (b, pw) in c
                .branches
                .iter()
                .zip(powers.iter().chain(std::iter::repeat(&Vec::new())))
            {
                let points = b
                    .points
                    .iter()
                    .enumerate()
                    .map(|(k, p)| ResponseBranchPoint {
                        value: p.parameter,
                        stable: p.stable,
                        power_w: pw.get(k).copied().unwrap_or(f64::NAN),
                        max_abs_multiplier: p.spectral_radius(),
                        impacts_per_period: p.impacts_per_period.iter().sum(),
                    })
                    .collect();
                out.branches.push(ResponseBranch {
                    seed,
                    towards,
                    period: b.period,
                    points,
                    bifurcations: b.bifurcations.clone(),
                    end: b.end.clone(),
                });
            }
            stopped |= each(ResponseStep::Continuation).is_break();
            if stopped {
                out.complete = false;
                return out;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(value: f64, power_w: f64, stable: bool) -> ResponseBranchPoint {
        ResponseBranchPoint {
            value,
            stable,
            power_w,
            max_abs_multiplier: 0.5,
            impacts_per_period: 2.0,
        }
    }

    /// A branch holds a motion of its period whose power its neighbouring points interpolate
    /// to, on a stable part, and nothing else.
    #[test]
    fn a_branch_holds_the_motions_on_it() {
        let b = ResponseBranch {
            seed: BranchSeed {
                direction: Direction::Up,
                value: 0.7,
                period: 1,
            },
            towards: 0.9,
            period: 1,
            points: vec![
                point(0.7, 1.0, true),
                point(0.8, 2.0, true),
                point(0.85, 1.5, false),
                point(0.75, 0.5, false),
            ],
            bifurcations: Vec::new(),
            end: BranchEnd::MaxPoints,
        };
        let tol = (0.02, 1e-12);
        assert!(b.holds(1, 0.75, 1.5, tol));
        assert!(b.holds(1, 0.75, 1.52, tol));
        assert!(!b.holds(1, 0.75, 1.6, tol), "2 % off");
        assert!(!b.holds(2, 0.75, 1.5, tol), "another period");
        // Between 0.85 and 0.75 only unstable points: a motion there is not on the branch.
        assert!(!b.holds(1, 0.78, 0.5 + (0.03 / 0.1), tol));
        assert!(
            b.holds(1, 0.82, 1.8, tol),
            "between a stable and an unstable point"
        );
        // Just past the last point, by rounding.
        assert!(!b.holds(1, 0.7 - 1e-10, 1.0, tol));
        assert!(b.holds(1, 0.7 - 1e-13, 1.0, tol));
        assert_eq!(b.stable_runs(), vec![vec![(0.7, 1.0), (0.8, 2.0)]]);
    }
}
