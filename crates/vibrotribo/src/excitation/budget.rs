//! [`WorkBudget`]: how much work building a base motion may do, and when to give up.
//!
//! Building a random signal's piecewise polynomials evaluates every harmonic at the nodes of
//! every interval: its cost is the number of harmonics times the number of intervals
//! ([`build_cost`]). A wide band over a long duration (0.001–5000 Hz: 89 759 harmonics over
//! 106 668 intervals, about 10¹⁰ evaluations, minutes) is refused before it starts above
//! [`MAX_PIECE_EVALUATIONS`] unless [`WorkBudget::allow_large`], and the build polls
//! [`WorkBudget::stop`] as it goes.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::error::SignalError;

/// Most harmonic × interval evaluations a base motion's build does without being allowed
/// large jobs: 10⁹, about half a minute on one core.
pub const MAX_PIECE_EVALUATIONS: f64 = 1e9;

/// Intervals between two looks at the stop flag while building.
pub(super) const POLL_INTERVALS: usize = 64;

/// How much work building a base motion may do, and a flag that stops it.
#[derive(Debug, Clone, Default)]
pub struct WorkBudget {
    /// Build beyond [`MAX_PIECE_EVALUATIONS`] (the command line's `--allow-large`).
    pub allow_large: bool,
    /// Set (by a signal handler, another thread) to stop a build in progress: it then
    /// returns [`SignalError::Stopped`]. Read every 64 intervals.
    pub stop: Option<Arc<AtomicBool>>,
}

impl PartialEq for WorkBudget {
    /// Budgets say how a base motion is built, not what it is: any two are equal, so that
    /// configurations compare by their content.
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

impl WorkBudget {
    /// A budget that allows any size and never stops (signals whose size is bounded by
    /// their own limits, such as a multisine's harmonics).
    pub fn unlimited() -> Self {
        WorkBudget {
            allow_large: true,
            stop: None,
        }
    }

    /// Refuses a build of `harmonics` harmonics over `intervals` intervals above
    /// [`MAX_PIECE_EVALUATIONS`] unless large builds are allowed.
    pub fn check(&self, harmonics: usize, intervals: usize) -> Result<(), SignalError> {
        if build_cost(harmonics, intervals) > MAX_PIECE_EVALUATIONS && !self.allow_large {
            return Err(SignalError::Costly { harmonics, intervals });
        }
        Ok(())
    }

    /// Whether the stop flag is set.
    pub fn stopped(&self) -> bool {
        self.stop.as_ref().is_some_and(|s| s.load(Ordering::Relaxed))
    }
}

/// Harmonic × interval evaluations of building `harmonics` harmonics over `intervals`
/// intervals.
pub fn build_cost(harmonics: usize, intervals: usize) -> f64 {
    harmonics as f64 * intervals as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_costly_build_is_refused_unless_allowed() {
        let b = WorkBudget::default();
        assert!(b.check(1000, 1000).is_ok());
        let e = b.check(89_759, 106_668).unwrap_err().to_string();
        assert!(
            e.contains("89759 harmonics") && e.contains("106668 intervals"),
            "{e}"
        );
        assert!(WorkBudget::unlimited().check(89_759, 106_668).is_ok());
        let flag = Arc::new(AtomicBool::new(false));
        let b = WorkBudget {
            allow_large: false,
            stop: Some(flag.clone()),
        };
        assert!(!b.stopped());
        flag.store(true, Ordering::Relaxed);
        assert!(b.stopped());
    }
}
