//! What a continuation returns, and its settings.

use nalgebra::{Complex, DVector};

use super::super::error::NewtonFailure;
use super::super::shooting::ShootingOptions;
use crate::error::{ParamError, check, check_positive};
use crate::model::ChainState;
use crate::sensitivity::{NonSmoothPoint, state_vector};

/// Settings of [`continue_orbit`](super::continue_orbit).
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationOptions {
    /// First arclength step, in scaled units (state in L and L·ω, parameter in its range
    /// |to − from|). Default 0.02.
    pub initial_step: f64,
    /// Smallest step: a branch that cannot be continued with it ends with
    /// [`BranchEnd::StepFloor`]. Default 1e-6.
    pub min_step: f64,
    /// Largest step. Default 0.1.
    pub max_step: f64,
    /// Most points per branch ([`BranchEnd::MaxPoints`] beyond). Default 2000.
    pub max_points: usize,
    /// Most branches in all (the first plus those born at period doublings and branch
    /// points). Default 16.
    pub max_branches: usize,
    /// Period doublings to follow: at a period doubling of a branch of period 2^k·P with
    /// k < `doubling_depth` the doubled branch is followed too, so a cascade P → 2P → 4P …
    /// is followed `doubling_depth` levels deep. Default 3.
    pub doubling_depth: u32,
    /// Branch points to switch at: at a branch point of a branch born at fewer than
    /// `branch_point_depth` branch points, both branches leaving it are followed (the two
    /// halves of a symmetry-breaking pitchfork). Default 1.
    pub branch_point_depth: u32,
    /// Bifurcations and sequence changes are located to this accuracy in the parameter, in
    /// its unit. Default 1e-8.
    pub location_tolerance: f64,
    /// Scaled residual at which a corrector step has converged. Default 1e-11.
    pub corrector_tolerance: f64,
    /// Newton iterations per corrector step. Default 8.
    pub corrector_iterations: usize,
    /// Relative step of the central difference of the flow map in the parameter (the
    /// parameter column of the Jacobian). Default 1e-7.
    pub parameter_step: f64,
    /// Settings of the first orbit (Newton at `from`), of the simulations and of the
    /// sensitivities.
    pub shooting: ShootingOptions,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        ContinuationOptions {
            initial_step: 0.02,
            min_step: 1e-6,
            max_step: 0.1,
            max_points: 2000,
            max_branches: 16,
            doubling_depth: 3,
            branch_point_depth: 1,
            location_tolerance: 1e-8,
            corrector_tolerance: 1e-11,
            corrector_iterations: 8,
            parameter_step: 1e-7,
            shooting: ShootingOptions::default(),
        }
    }
}

impl ContinuationOptions {
    /// Checks the options.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_path(self.initial_step, self.min_step, self.max_step, self.max_points)?;
        check(
            "max_branches",
            self.max_branches as f64,
            self.max_branches >= 1,
            "must be positive",
        )?;
        check_positive("location_tolerance", self.location_tolerance)?;
        check_positive("corrector_tolerance", self.corrector_tolerance)?;
        check(
            "corrector_iterations",
            self.corrector_iterations as f64,
            self.corrector_iterations > 0,
            "must be positive",
        )?;
        check_positive("parameter_step", self.parameter_step)?;
        self.shooting.validate()
    }
}

/// Checks the step lengths and point budget that every pseudo-arclength path shares (a
/// branch, a bifurcation curve): positive steps with `min_step ≤ initial_step ≤ max_step`
/// and at least two points.
pub(in crate::orbits) fn check_path(
    initial_step: f64,
    min_step: f64,
    max_step: f64,
    max_points: usize,
) -> Result<(), ParamError> {
    check_positive("initial_step", initial_step)?;
    check_positive("min_step", min_step)?;
    check_positive("max_step", max_step)?;
    check(
        "max_step",
        max_step,
        min_step <= initial_step && initial_step <= max_step,
        "must satisfy min_step ≤ initial_step ≤ max_step",
    )?;
    check(
        "max_points",
        max_points as f64,
        max_points >= 2,
        "must be at least 2",
    )
}

/// One periodic orbit on a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchPoint {
    /// Parameter value.
    pub parameter: f64,
    /// Section state at t ≡ 0 (mod T): positions, m, and velocities, m/s.
    pub state: ChainState,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// Whether all multipliers lie inside the unit circle.
    pub stable: bool,
    /// Impacts per excitation period at each contact (chatter bounces included).
    pub impacts_per_period: Vec<f64>,
    /// The slowest impact that is not a chatter bounce: (contact, closing speed in m/s).
    pub min_closing_speed: Option<(usize, f64)>,
    /// Whether a contact sticks on the orbit.
    pub sticks: bool,
    /// Arclength from the branch's start, scaled units.
    pub arclength: f64,
}

impl BranchPoint {
    /// Whether `other` has the same impacts per period at each contact and the same sticking
    /// (a necessary condition for the two to lie on one smooth family).
    pub fn alike(&self, other: &BranchPoint) -> bool {
        self.impacts_per_period == other.impacts_per_period && self.sticks == other.sticks
    }

    /// Largest multiplier modulus.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |l| l.norm())
    }

    /// The state (at t ≡ 0) a fraction `s` of the way from this point to `other`.
    pub(super) fn towards(&self, other: &BranchPoint, s: f64) -> DVector<f64> {
        let z = state_vector(&self.state);
        &z + (state_vector(&other.state) - &z) * s
    }
}

/// What happens at a located bifurcation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum BifurcationKind {
    /// A real multiplier crosses +1 and the branch turns back in the parameter
    /// (saddle-node).
    Fold,
    /// A real multiplier crosses +1 without a turn in the parameter: a branch point, where
    /// a second branch crosses this one (a symmetry-breaking pitchfork, or a transcritical
    /// crossing). Found where `det([J; tᵀ])` changes sign, J the Jacobian
    /// `[Φ − I | ∂φ/∂p]` and t the step's tangent.
    BranchPoint,
    /// A real multiplier crosses −1: a branch of twice the period is born.
    PeriodDoubling,
    /// A complex pair crosses the unit circle at `exp(±i·angle)`.
    NeimarkSacker {
        /// Argument of the critical pair, rad (in (0, π)).
        angle: f64,
    },
    /// An impact at `contact` appears or disappears with closing speed → 0: the impact
    /// sequence changes. `appears` is true when the later side along the branch has it.
    Grazing {
        /// Contact, 0-based.
        contact: usize,
        /// Whether the impact exists after the point (along the branch).
        appears: bool,
    },
    /// Sticking at `contact` begins (`onset`) or ends along the branch.
    Sticking {
        /// Contact, 0-based.
        contact: usize,
        /// Whether sticking exists after the point (along the branch).
        onset: bool,
    },
    /// The event sequence changes otherwise (chatter appears, the order of impacts changes,
    /// or an impact appears with a closing speed that does not tend to zero).
    SequenceChange,
}

impl BifurcationKind {
    /// Its name in files: `fold`, `branch_point`, `period_doubling`, `neimark_sacker`,
    /// `grazing`, `sticking`, `sequence_change`.
    pub fn name(&self) -> &'static str {
        match self {
            BifurcationKind::Fold => "fold",
            BifurcationKind::BranchPoint => "branch_point",
            BifurcationKind::PeriodDoubling => "period_doubling",
            BifurcationKind::NeimarkSacker { .. } => "neimark_sacker",
            BifurcationKind::Grazing { .. } => "grazing",
            BifurcationKind::Sticking { .. } => "sticking",
            BifurcationKind::SequenceChange => "sequence_change",
        }
    }
}

/// A bifurcation located on a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Bifurcation {
    /// What happens.
    pub kind: BifurcationKind,
    /// Parameter value at the point.
    pub parameter: f64,
    /// Width of the final bracket in the parameter: the location's accuracy.
    pub precision: f64,
    /// The orbit at the point (for a sequence change: the last orbit before it along the
    /// branch).
    pub point: BranchPoint,
    /// For a sequence change: the first orbit after it.
    pub after: Option<BranchPoint>,
    /// For a period doubling: the index of the doubled branch in
    /// [`Continuation::branches`], if it was followed. For a branch point: the branch that
    /// leaves it one way.
    pub child: Option<usize>,
    /// For a branch point: the branch that leaves it the other way (at a symmetry-breaking
    /// pitchfork, the mirror image of `child`), if it was followed.
    pub other_child: Option<usize>,
    /// For a change of the event sequence the branch was continued through (a
    /// discontinuity-induced bifurcation): how it was crossed and what the square-root map
    /// predicts there.
    pub crossing: Option<Crossing>,
}

/// How a branch goes on through a change of its event sequence (grazing, sticking onset or
/// loss, chatter onset): the orbits on the two sides of the point, `point` and `after` of
/// its [`Bifurcation`], with their multipliers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// Persistence or non-smooth fold.
    pub kind: CrossingKind,
    /// What the one-dimensional square-root map of the grazing orbit predicts for the
    /// attractor beyond it (grazings only; `None` for other changes).
    pub nordmark: Option<NordmarkScenario>,
}

/// Whether the branch goes on through a discontinuity-induced bifurcation or turns back.
///
/// Feigin's rule for the square-root map: the orbit with the new sequence has a multiplier
/// that grows like the inverse of its grazing impact speed, so `det(Φ − I)` has the same
/// sign on both sides for a persistence and opposite signs at a non-smooth fold. The kind
/// is read from where the new orbit was found (beyond the point, or before it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum CrossingKind {
    /// The orbit with the new sequence exists beyond the point: the branch goes on in the
    /// same direction of the parameter.
    Persistence,
    /// The orbit with the new sequence exists on the same side as the old one: the two meet
    /// and end at the point, and the branch turns back in the parameter.
    NonSmoothFold,
}

/// The attractor near a grazing of a stable impact-free orbit, as Nordmark's
/// one-dimensional square-root map `x ↦ μ + λx (x ≤ 0), μ − √x (x > 0)` predicts it from
/// the dominant multiplier λ of that orbit at the grazing (Nordmark 1991; Chin, Ott, Nusse &
/// Grebogi 1994), for small μ > 0 (just past the grazing).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum NordmarkScenario {
    /// −1 < λ < 0: an orbit of twice the period with one impact in two periods.
    PeriodTwo,
    /// 0 < λ < 1/4: a period-adding sequence of periodic orbits with one impact per period
    /// and a number of impact-free periods that grows without bound as μ → 0.
    PeriodAdding,
    /// 1/4 ≤ λ < 2/3: period adding with chaotic bands between the periodic windows.
    PeriodAddingWithChaos,
    /// 2/3 ≤ λ < 1: a chaotic attractor born at the grazing.
    Chaos,
    /// The dominant multiplier is complex, zero, or not inside the unit circle: the
    /// one-dimensional map does not apply.
    Undetermined,
}

impl CrossingKind {
    /// Its name in files: `persistence` or `non_smooth_fold`.
    pub fn name(&self) -> &'static str {
        match self {
            CrossingKind::Persistence => "persistence",
            CrossingKind::NonSmoothFold => "non_smooth_fold",
        }
    }
}

impl NordmarkScenario {
    /// Its name in files: `period_two`, `period_adding`, `period_adding_with_chaos`, `chaos`
    /// or `undetermined`.
    pub fn name(&self) -> &'static str {
        match self {
            NordmarkScenario::PeriodTwo => "period_two",
            NordmarkScenario::PeriodAdding => "period_adding",
            NordmarkScenario::PeriodAddingWithChaos => "period_adding_with_chaos",
            NordmarkScenario::Chaos => "chaos",
            NordmarkScenario::Undetermined => "undetermined",
        }
    }

    /// The scenario for the multipliers of the impact-free orbit at the grazing (largest
    /// modulus first, as on a [`BranchPoint`]).
    pub fn of(multipliers: &[Complex<f64>]) -> Self {
        let Some(l) = multipliers.first() else {
            return NordmarkScenario::Undetermined;
        };
        // A complex pair (or a second multiplier as large) leaves no single dominant real
        // direction.
        let dominant = multipliers
            .get(1)
            .is_none_or(|m| m.norm() < (1.0 - 1e-9) * l.norm());
        if l.im.abs() > 1e-9 * l.norm().max(f64::MIN_POSITIVE) || !dominant {
            return NordmarkScenario::Undetermined;
        }
        match l.re {
            x if x > -1.0 && x < 0.0 => NordmarkScenario::PeriodTwo,
            x if x > 0.0 && x < 0.25 => NordmarkScenario::PeriodAdding,
            x if (0.25..2.0 / 3.0).contains(&x) => NordmarkScenario::PeriodAddingWithChaos,
            x if (2.0 / 3.0..1.0).contains(&x) => NordmarkScenario::Chaos,
            _ => NordmarkScenario::Undetermined,
        }
    }
}

/// Why a branch ended.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum BranchEnd {
    /// The branch left the parameter range at this value (a point there is the last).
    RangeEnd {
        /// The range end reached.
        parameter: f64,
    },
    /// [`ContinuationOptions::max_points`] points were computed.
    MaxPoints,
    /// The corrector failed down to the smallest step: a turning point it cannot follow, a
    /// non-smooth point ahead (`non_smooth`), or no orbit beyond.
    StepFloor {
        /// Parameter of the last point.
        parameter: f64,
        /// Why the last attempt failed.
        reason: NewtonFailure,
        /// Where the map was not differentiable, if that was the reason.
        non_smooth: Option<NonSmoothPoint>,
        /// Residuals of the last attempt.
        residuals: Vec<f64>,
    },
    /// The branch runs into a grazing it cannot cross: a smooth local minimum of the gap at
    /// `contact` tends to zero (last seen at `gap` m), and no orbit with the new impact was
    /// found on either side of it (neither a persistence nor a non-smooth fold).
    Grazing {
        /// Parameter of the last point.
        parameter: f64,
        /// Contact, 0-based.
        contact: usize,
        /// The smallest gap minimum at the last point, m.
        gap: f64,
    },
    /// A period doubling of a branch at the deepest level asked for
    /// ([`ContinuationOptions::doubling_depth`]): the cascade goes on beyond (towards a
    /// chaotic window), and the branch is not followed past it.
    CascadeDepth {
        /// Parameter of the period doubling.
        parameter: f64,
    },
    /// A multiplier crosses −1 (`det(Φ + I)` changes sign) between two orbits of the branch,
    /// but the crossing could not be located down to the smallest step: the locator's bracket
    /// stayed wider than [`ContinuationOptions::location_tolerance`], or the orbit it ended on
    /// has no real multiplier near −1 (a step onto another branch, or over a point where a
    /// multiplier passes through infinity). No period doubling is reported there, and the
    /// branch is not followed past it.
    Unlocated {
        /// Parameter of the last point.
        parameter: f64,
        /// The parameters of the locator's final bracket's ends.
        between: (f64, f64),
    },
    /// The doubled branch could not be started from its period doubling.
    SwitchFailed {
        /// Parameter of the period doubling.
        parameter: f64,
    },
    /// The branch of period 2P fell back onto the orbit of period P.
    Collapsed {
        /// Parameter of the point where it happened.
        parameter: f64,
    },
    /// The branch came back to one of its earlier points (its first one for a smooth closed
    /// curve, an isola; any one after a corner crossed at a change of the event sequence):
    /// from there on it repeats itself, and it is followed once round.
    Closed {
        /// Parameter of the point it came back to.
        parameter: f64,
    },
    /// The branch came back to one of its earlier points going the other way: past a change
    /// of the event sequence crossed (a short stretch of orbits with another sequence, left
    /// again at a second change) it is back on its own orbits, heading back along them, and
    /// from there on it would repeat them in reverse.
    Retraced {
        /// Parameter of the point it came back to.
        parameter: f64,
    },
    /// The branch reached a branch point found earlier on another branch (`branch`), where
    /// it crosses that one: the branches beyond leave that branch point and are followed
    /// from there.
    Rejoined {
        /// Parameter of the branch point.
        parameter: f64,
        /// The branch it lies on.
        branch: usize,
    },
    /// Past a change of its event sequence the branch runs onto a branch followed before
    /// (`branch`): its last point lies on that branch (on a chord between two of its
    /// consecutive points with the same impacts, in the scaled state and parameter), so from
    /// there on it would repeat that branch. Several families meet so where a grazing joins
    /// them, such as the two asymmetric orbits of a pitchfork and their symmetric parent.
    RunsOnto {
        /// Parameter of the last point.
        parameter: f64,
        /// The branch it runs onto.
        branch: usize,
    },
    /// The caller asked the continuation to stop
    /// ([`ShootingOptions::cancel`](crate::orbits::ShootingOptions::cancel), polled at every
    /// step): the branch is cut after its last point, and no further branch is followed.
    Stopped {
        /// Parameter of the last point (NaN if the branch has none).
        parameter: f64,
    },
}

impl BranchEnd {
    /// Its name in files: `range_end`, `max_points`, `step_floor`, `grazing`,
    /// `cascade_depth`, `unlocated`, `switch_failed`, `collapsed`, `closed`, `retraced`,
    /// `rejoined`, `runs_onto`, `stopped`.
    pub fn name(&self) -> &'static str {
        match self {
            BranchEnd::RangeEnd { .. } => "range_end",
            BranchEnd::MaxPoints => "max_points",
            BranchEnd::StepFloor { .. } => "step_floor",
            BranchEnd::Grazing { .. } => "grazing",
            BranchEnd::CascadeDepth { .. } => "cascade_depth",
            BranchEnd::Unlocated { .. } => "unlocated",
            BranchEnd::SwitchFailed { .. } => "switch_failed",
            BranchEnd::Collapsed { .. } => "collapsed",
            BranchEnd::Closed { .. } => "closed",
            BranchEnd::Retraced { .. } => "retraced",
            BranchEnd::Rejoined { .. } => "rejoined",
            BranchEnd::RunsOnto { .. } => "runs_onto",
            BranchEnd::Stopped { .. } => "stopped",
        }
    }

    /// The parameter where the branch ended (`None` for [`BranchEnd::MaxPoints`], which
    /// records none).
    pub fn parameter(&self) -> Option<f64> {
        match self {
            BranchEnd::RangeEnd { parameter }
            | BranchEnd::StepFloor { parameter, .. }
            | BranchEnd::Grazing { parameter, .. }
            | BranchEnd::CascadeDepth { parameter }
            | BranchEnd::Unlocated { parameter, .. }
            | BranchEnd::SwitchFailed { parameter }
            | BranchEnd::Collapsed { parameter }
            | BranchEnd::Closed { parameter }
            | BranchEnd::Retraced { parameter }
            | BranchEnd::Rejoined { parameter, .. }
            | BranchEnd::RunsOnto { parameter, .. }
            | BranchEnd::Stopped { parameter } => Some(*parameter),
            BranchEnd::MaxPoints => None,
        }
    }
}

/// One branch of periodic orbits.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Period of its orbits, in excitation periods.
    pub period: u32,
    /// Where it was born: (index of the parent branch, index of the period doubling or
    /// branch point in its `bifurcations`); `None` for the first branch.
    pub parent: Option<(usize, usize)>,
    /// The orbits in order along the branch.
    pub points: Vec<BranchPoint>,
    /// Bifurcations in order along the branch.
    pub bifurcations: Vec<Bifurcation>,
    /// Why it ended.
    pub end: BranchEnd,
}

/// The result of [`continue_orbit`](super::continue_orbit).
#[derive(Debug, Clone, PartialEq)]
pub struct Continuation {
    /// Name of the parameter.
    pub parameter: String,
    /// The branches: the first, then those born at period doublings and branch points in the
    /// order they were found.
    pub branches: Vec<Branch>,
    /// Whether every branch found was followed to its end: `false` when the caller stopped
    /// the continuation ([`BranchEnd::Stopped`], or period doublings left unfollowed).
    pub complete: bool,
}
