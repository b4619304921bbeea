//! Errors of the sensitivity computation.

use crate::error::SimError;
use thiserror::Error;

/// A point where the flow map is not differentiable, found on the observed trajectory.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum NonSmoothPoint {
    /// An impact with (almost) no closing speed: the saltation matrix carries `1/v` and the
    /// flow map has a square-root singularity there (a nearby orbit misses the contact or
    /// hits it with speed ∝ √(distance)).
    #[error(
        "grazing impact at t = {time:.12} s, contact {} (between masses {} and {}): closing speed {speed:.3e} m/s",
        contact + 1, contact + 1, contact + 2
    )]
    Grazing {
        /// Time, s.
        time: f64,
        /// Contact, 0-based (between mass `contact` and `contact + 1`).
        contact: usize,
        /// Closing speed, m/s (0 for a touch).
        speed: f64,
    },
    /// Several contacts struck, released or closed at one instant (a simultaneous impact
    /// resolved pairwise, an impact while another contact touches, two releases at once):
    /// the outcome depends on the order in which nearby trajectories meet the contacts.
    #[error("simultaneous events at t = {time:.12} s at contacts {contacts:?} (0-based)")]
    Simultaneous {
        /// Time, s.
        time: f64,
        /// The contacts involved, 0-based.
        contacts: Vec<usize>,
    },
}

impl NonSmoothPoint {
    /// Time of the point, s.
    pub fn time(&self) -> f64 {
        match self {
            NonSmoothPoint::Grazing { time, .. } | NonSmoothPoint::Simultaneous { time, .. } => *time,
        }
    }
}

/// The sensitivity of a run could not be computed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SensitivityError {
    /// The simulation itself failed.
    #[error(transparent)]
    Sim(#[from] SimError),
    /// The trajectory passes a point where the flow map is not differentiable.
    #[error("the flow map is not differentiable here: {0}")]
    NonSmooth(NonSmoothPoint),
    /// The observer saw no flow (the run had zero length and nothing was observed).
    #[error("no flow was observed")]
    Empty,
    /// The run ended right after an event, before the flow that follows it, so the event's
    /// outcome (the new clusters) is unknown.
    #[error("the run ended at t = {time} s right after an event; run on past it")]
    Unfinished {
        /// Time of the event, s.
        time: f64,
    },
    /// The event sequence differs between the runs of a finite difference in a parameter:
    /// the step crosses a non-smooth point (grazing, sticking onset, ...).
    #[error(
        "the event sequence changes between parameter values {low} and {high}: the parameter \
         derivative does not exist there (or the step is too large)"
    )]
    SequenceChange {
        /// The lower parameter value.
        low: f64,
        /// The higher parameter value.
        high: f64,
    },
}

// Not `#[from]`: that would also make the inner error the `source()`, which the message
// already shows (a failure's chain printed it twice).
impl From<NonSmoothPoint> for SensitivityError {
    fn from(e: NonSmoothPoint) -> Self {
        SensitivityError::NonSmooth(e)
    }
}
