//! What a bifurcation map is asked for, its settings, and what it returns.

use thiserror::Error;

use crate::branch::BranchError;
use crate::config::ConfigError;
use crate::orbits::curve::{Codim2Point, CurveEnd, CurveError, CurveKind, CurvePoint};
use crate::orbits::{Bifurcation, Cancel, Continuation};

/// Most seed values of the second key.
pub const MAX_SEEDS: usize = 1000;

/// What map to compute: the plane of two keys and the values of the second key where
/// branches are continued in the first.
#[derive(Debug, Clone, PartialEq)]
pub struct MapRequest {
    /// The first key (along x): any key `continue` accepts.
    pub x: String,
    /// The range of the first key (either order).
    pub x_range: (f64, f64),
    /// The second key (along y).
    pub y: String,
    /// The range of the second key (either order).
    pub y_range: (f64, f64),
    /// Values of the second key, equally spaced over its range with both ends, at which the
    /// branches are continued in the first key (default 5).
    pub seeds: usize,
    /// Values of the first key, equally spaced over its range with both ends, at which each
    /// seed value's orbits are sought after a transient (default 5).
    pub x_starts: usize,
    /// The curves wanted (default all four kinds).
    pub kinds: Vec<CurveKind>,
}

impl MapRequest {
    /// A request for every kind of curve over `x_range` × `y_range` with 5 seed values.
    pub fn new(x: &str, x_range: (f64, f64), y: &str, y_range: (f64, f64)) -> Self {
        MapRequest {
            x: x.to_string(),
            x_range,
            y: y.to_string(),
            y_range,
            seeds: 5,
            x_starts: 5,
            kinds: CurveKind::ALL.to_vec(),
        }
    }
}

/// How the branches are found and the curves followed.
#[derive(Debug, Clone, PartialEq)]
pub struct BifmapOptions {
    /// Excitation periods simulated from the configured initial state before shooting for
    /// the first orbit of each branch (default 200).
    pub transient: u32,
    /// Period of the first orbit of each branch, in excitation periods (default `None`:
    /// detected after the transient).
    pub period: Option<u32>,
    /// Period doublings followed onto the doubled branch along each seed's branches
    /// (default 1: the curves of period-P and period-2P orbits).
    pub doublings: u32,
    /// Most points per branch of a seed (default 1000).
    pub branch_points: usize,
    /// Most points of each half of a curve (from its seed towards either end of the second
    /// key's range; default 200).
    pub curve_points: usize,
    /// Most curves traced (default 64): bifurcations found beyond are counted in
    /// [`BifurcationMap::untraced`], not followed.
    pub max_curves: usize,
    /// Polled by the branches and curves: when it asks, the map stops with what it has
    /// ([`BifurcationMap::complete`] false). Default: never.
    pub cancel: Cancel,
}

impl Default for BifmapOptions {
    fn default() -> Self {
        BifmapOptions {
            transient: 200,
            period: None,
            doublings: 1,
            branch_points: 1000,
            curve_points: 200,
            max_curves: 64,
            cancel: Cancel::never(),
        }
    }
}

/// What became of one start of a seed value: the orbit found after the transient at one
/// value of the first key, continued towards one end of its range.
#[derive(Debug, Clone, PartialEq)]
pub struct Seed {
    /// The second key's value.
    pub y: f64,
    /// The first key's value of the start.
    pub x_start: f64,
    /// The end of the first key's range the branch was continued towards.
    pub x_end: f64,
    /// What was found.
    pub outcome: SeedOutcome,
}

/// What a start of a seed value gave.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SeedOutcome {
    /// The branches (the first orbit's and the period-doubled ones).
    Branches(Continuation),
    /// The start's orbit lies on a branch of an earlier start of the same seed value (the
    /// index of that [`Seed`]): not followed again.
    OnBranch(usize),
    /// No periodic orbit at the start, or the branch could not be followed: why.
    Failed(BranchError),
}

impl Seed {
    /// The branches, if it has any.
    pub fn branches(&self) -> Option<&Continuation> {
        match &self.outcome {
            SeedOutcome::Branches(c) => Some(c),
            _ => None,
        }
    }

    /// Why there are no branches, with the chain of its causes (`a: b: c`); `None` when
    /// there are or the start lies on an earlier branch.
    pub fn error_text(&self) -> Option<String> {
        let SeedOutcome::Failed(e) = &self.outcome else {
            return None;
        };
        let mut text = e.to_string();
        let mut cause = std::error::Error::source(e);
        while let Some(c) = cause {
            text.push_str(&format!(": {c}"));
            cause = c.source();
        }
        Some(text)
    }
}

/// Why one half of a curve ended.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum HalfEnd {
    /// The curve's own end ([`CurveEnd`]: the range end, a sequence change, …).
    Curve(CurveEnd),
    /// The curve left the plane of the map (its last point within 5 % of the range of an
    /// edge, and the next step outside): it goes on beyond.
    LeftMap {
        /// The first key at the last point.
        x: f64,
        /// The second key at the last point.
        y: f64,
    },
    /// The caller asked the map to stop ([`BifmapOptions::cancel`]).
    Stopped,
    /// The curve could not be started from its seed (the defining system has no solution
    /// there).
    NoStart(CurveError),
}

/// A bifurcation curve of the map: its two halves, from the seed where it was located
/// towards both ends of the second key's range, joined.
#[derive(Debug, Clone, PartialEq)]
pub struct MapCurve {
    /// The condition followed.
    pub kind: CurveKind,
    /// Period of the orbits, in excitation periods.
    pub period: u32,
    /// Grazing curves: the contact, 0-based.
    pub contact: Option<usize>,
    /// Index of the seed (into [`BifurcationMap::seeds`]) whose branch it was located on.
    pub seed: usize,
    /// The bifurcation located there.
    pub located: Bifurcation,
    /// The points in order along the curve: the half towards the first end of the second
    /// key's range reversed, then the half towards its other end. Their `arclength` is
    /// signed: negative on the first half, zero at the seed.
    pub points: Vec<CurvePoint>,
    /// Codimension-two points in the same order.
    pub codim2: Vec<Codim2Point>,
    /// Why each half ended: towards the first end of the second key's range, then towards
    /// the other (`None` where the seed sits on that end).
    pub ends: [Option<HalfEnd>; 2],
    /// Other bifurcations located on seed branches that lie on this curve (the curve was
    /// found again there and not traced twice).
    pub found_again: usize,
}

/// A bifurcation of a kind asked for, located on a seed's branch, and the curve it lies on.
#[derive(Debug, Clone, PartialEq)]
pub struct LocatedPoint {
    /// Index of the seed (into [`BifurcationMap::seeds`]).
    pub seed: usize,
    /// The second key's value (the seed value).
    pub y: f64,
    /// The first key's value.
    pub x: f64,
    /// The curve kind.
    pub kind: CurveKind,
    /// Period of its branch, in excitation periods.
    pub period: u32,
    /// Grazing: the contact, 0-based.
    pub contact: Option<usize>,
    /// Index of the curve it lies on (into [`BifurcationMap::curves`]): the one traced from
    /// it, or the one traced earlier that passes through it; `None` if it was not followed
    /// ([`BifurcationMap::untraced`], or the map was stopped first).
    pub curve: Option<usize>,
}

/// A device's bifurcation map in two keys.
#[derive(Debug, Clone, PartialEq)]
pub struct BifurcationMap {
    /// The first key, canonical (see [`canonical_key`](crate::curve::canonical_key)).
    pub x: String,
    /// The second key, canonical.
    pub y: String,
    /// The starts of each seed value and what they gave, in order of the seed values, then
    /// of the starts.
    pub seeds: Vec<Seed>,
    /// The bifurcations of the kinds asked for located on the seeds' branches (one found by
    /// both branches of a seed value listed once), in the order of the seeds.
    pub located: Vec<LocatedPoint>,
    /// The curves, in the order they were traced.
    pub curves: Vec<MapCurve>,
    /// Bifurcations of the kinds asked for that were not followed: beyond
    /// [`BifmapOptions::max_curves`].
    pub untraced: usize,
    /// Whether everything asked for was computed: `false` when the caller stopped the map.
    pub complete: bool,
}

/// Progress of a map, reported as it goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Stage {
    /// `done` of `total` seed values followed.
    Seeds {
        /// Seed values done.
        done: usize,
        /// Seed values in all.
        total: usize,
    },
    /// `done` of `total` halves of curves traced so far (the total grows as seeds bring new
    /// curves).
    Curves {
        /// Halves traced.
        done: usize,
        /// Halves known.
        total: usize,
    },
}

/// Why a map could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum BifmapError {
    /// A value of a key makes an invalid configuration.
    #[error("{key} = {value}")]
    Value {
        /// The key.
        key: String,
        /// The value at fault.
        value: f64,
        /// Why the configuration is invalid.
        #[source]
        source: ConfigError,
    },
    /// A key cannot vary this configuration.
    #[error(transparent)]
    Key(#[from] ConfigError),
    /// The two keys set one quantity.
    #[error("{x} and {y} set the same quantity: a map needs two different parameters")]
    SameKey {
        /// The first key.
        x: String,
        /// The second key.
        y: String,
    },
    /// A range is not finite or empty.
    #[error("the range of {key} must be finite and not empty, got {from} to {to}")]
    Range {
        /// The key.
        key: String,
        /// One end.
        from: f64,
        /// The other end.
        to: f64,
    },
    /// The number of seed values or of starts per seed value is out of bounds.
    #[error("the number of {what} must be between {least} and {MAX_SEEDS}, got {value}")]
    Seeds {
        /// `seed values` or `starts per seed value`.
        what: &'static str,
        /// The least allowed.
        least: usize,
        /// The value given.
        value: usize,
    },
    /// A count option is below its least value.
    #[error("{name} must be at least {least}, got {value}")]
    Count {
        /// The option.
        name: &'static str,
        /// Its least value.
        least: usize,
        /// The value given.
        value: usize,
    },
    /// No curve kind was asked for.
    #[error("no curve kind asked for: give one or more of fold, period_doubling, neimark_sacker, grazing")]
    NoKinds,
}

/// An upper estimate of the memory a map's seed branches and curves take, bytes, for a chain
/// of `masses` masses and `contacts` contacts: two continuations per start, of 16 branches
/// each (the first and its period-doubled ones, [`ContinuationOptions::max_branches`]'s
/// default) of `branch_points` points, and `max_curves` curves of two halves of
/// `curve_points` points.
///
/// [`ContinuationOptions::max_branches`]: crate::orbits::ContinuationOptions::max_branches
pub fn memory_bytes(request: &MapRequest, options: &BifmapOptions, masses: usize, contacts: usize) -> f64 {
    // State, multipliers (complex), counts and the rest of an orbit's record.
    let per = (8 * 4 * masses + 16 * 4 * masses + 8 * contacts + 160) as f64;
    let starts = request.seeds as f64 * request.x_starts as f64;
    let branches = 2.0 * starts * 16.0 * options.branch_points as f64;
    let curves = 2.0 * options.max_curves as f64 * options.curve_points as f64;
    (branches + curves) * per
}
