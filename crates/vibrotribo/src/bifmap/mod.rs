//! A device's bifurcation map in two configuration keys: its fold, period-doubling,
//! Neimark–Sacker and grazing curves in a plane of parameters ([`bifurcation_map`]), for
//! drawing over the power map of the same plane (what the command line's `bifmap` and
//! Python's `bifmap` compute).
//!
//! # Method
//!
//! 1. **Seeds.** At `seeds` values `y_j` of the second key, equally spaced over its range
//!    with both ends, the configuration's periodic orbit is sought after a transient from
//!    the configured initial state at `x_starts` values of the first key, equally spaced with
//!    both ends. Each orbit found that lies on no branch followed from an earlier start of
//!    the same `y_j` (same period, and its state, at one of its phases, within the extent of
//!    the branch's bracketing segment plus 10⁻³ of the chain's length and speed scales) is
//!    continued in the first key towards both ends of its range
//!    ([`continue_config`](crate::branch::continue_config): pseudo-arclength through folds,
//!    crossing grazings and sticking, switching onto period-doubled branches). Each branch
//!    locates its folds, period doublings, Neimark–Sacker points and grazings. The seed
//!    values run in parallel.
//! 2. **Curves.** Seed value by seed value, from the first end of the second key's range,
//!    every located bifurcation of a kind asked for that lies on no curve traced so far is
//!    followed in the second key from `y_j` towards both ends of its range
//!    ([`continue_curve`](crate::orbits::curve::continue_curve): the periodic orbit plus the
//!    bifurcation condition, by pseudo-arclength in both keys), and the two halves are
//!    joined. A bifurcation lies on a traced curve of the same kind, period and contact when
//!    a segment of the curve crosses `y_j` within the segment's own extent in the first key
//!    (plus 10⁻⁴ of its range) of it: the curve was found again and is counted, not traced
//!    twice. The halves of one seed value run in parallel.
//! 3. **Ends.** A half ends where `curve` ends it (the range end, the orbit's event sequence
//!    changing — a codimension-two point where the curve meets a grazing curve —, a
//!    degenerate condition, the point limit, a step the corrector cannot take), or where it
//!    leaves the plane widened by 5 % of each range: the family of chains refuses points
//!    beyond, so the corrector fails at the edge and the half is marked
//!    [`HalfEnd::LeftMap`]. The codimension-two points of every curve (where it meets
//!    another condition or a sequence change) are kept with it.
//!
//! Curves are found only from the bifurcations that the seed branches meet: a curve that
//! crosses no seed value on a branch reached from the configured initial state at one of
//! the starts is not found. More seed values and starts find more.

mod run;
mod seeds;
mod table;
mod trace;
mod types;

pub use run::{bifurcation_map, validate};
pub use table::{Rows, codim2_rows, curve_rows, located_rows};
pub use types::{
    BifmapError, BifmapOptions, BifurcationMap, HalfEnd, LocatedPoint, MAX_SEEDS, MapCurve, MapRequest, Seed,
    SeedOutcome, Stage, memory_bytes,
};
