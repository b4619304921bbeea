//! A caller's request to stop a long search for orbits: a hook polled by Newton's method at
//! every iteration, by the transient before shooting at every piece of flow, and by the
//! continuation at every step, so that a program can stop them within a step of a signal.

use std::fmt;
use std::ops::ControlFlow;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use crate::dynamics::{Event, Flow, Observer, StateView, Verdict};

/// A hook that says whether the computation it is given to should stop (default: never).
///
/// Cloning shares the hook. Two `Cancel`s always compare equal: the hook is not a numerical
/// setting, so options that differ only in it describe the same computation.
///
/// ```
/// use std::sync::Arc;
/// use std::sync::atomic::{AtomicBool, Ordering};
/// use vibrotribo::orbits::{Cancel, OrbitError, ShootingOptions, find_periodic_orbit};
/// use vibrotribo::{ChainParams, ChainState};
///
/// let stop = Arc::new(AtomicBool::new(true));
/// let options = ShootingOptions { cancel: Cancel::flag(stop), ..ShootingOptions::default() };
/// let r = find_periodic_orbit(&ChainParams::default(), &ChainState::at_rest(3), 1, &options);
/// assert_eq!(r.unwrap_err(), OrbitError::Cancelled);
/// ```
#[derive(Clone, Default)]
pub struct Cancel(Option<Arc<dyn Fn() -> bool + Send + Sync>>);

impl Cancel {
    /// A hook that never asks to stop.
    pub fn never() -> Self {
        Cancel(None)
    }

    /// Stops when `hook` returns `true` (it is called at every checkpoint: keep it cheap, or
    /// rate-limit it inside).
    pub fn new(hook: impl Fn() -> bool + Send + Sync + 'static) -> Self {
        Cancel(Some(Arc::new(hook)))
    }

    /// Stops once `flag` is set (by a signal handler, another thread, …).
    pub fn flag(flag: Arc<AtomicBool>) -> Self {
        Cancel::new(move || flag.load(Ordering::Relaxed))
    }

    /// Whether the computation is to stop now.
    pub fn requested(&self) -> bool {
        self.0.as_ref().is_some_and(|hook| hook())
    }
}

impl fmt::Debug for Cancel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Cancel(hook)"
        } else {
            "Cancel(never)"
        })
    }
}

impl PartialEq for Cancel {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// An observer that passes everything on to `inner` and stops the run when `cancel` asks.
pub(crate) struct Polled<'a, O> {
    pub inner: O,
    pub cancel: &'a Cancel,
}

impl<O: Observer> Observer for Polled<'_, O> {
    fn flow(&mut self, flow: &Flow<'_>) {
        self.inner.flow(flow)
    }
    fn event(&mut self, event: &Event, state: &StateView<'_>) {
        self.inner.event(event, state)
    }
    fn proceed(&mut self) -> Verdict {
        if self.cancel.requested() {
            return Ok(ControlFlow::Break(()));
        }
        self.inner.proceed()
    }
}
