//! Ctrl-C while the library computes without the GIL: at the run layer's checkpoints (the
//! end of a period of a run, the end of a chunk of sweep points, each value of a continued
//! sweep) the GIL is taken briefly and Python's pending signal handlers are run; the
//! exception one raises (`KeyboardInterrupt`) stops the computation and is raised to the
//! caller.

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use pyo3::prelude::*;
use vibrotribo::StateView;
use vibrotribo::study::RunObserver;

/// Period checkpoints closer than this skip the check (taking the GIL every period of a
/// fast run would cost more than the run).
const INTERVAL: Duration = Duration::from_millis(20);

/// Watches for a Python exception raised by a signal handler.
pub struct Signals {
    last: Instant,
    raised: Option<PyErr>,
}

impl Signals {
    /// No signal seen yet.
    pub fn new() -> Self {
        Signals {
            last: Instant::now(),
            raised: None,
        }
    }

    /// Runs Python's pending signal handlers: whether one raised (the computation is to stop).
    pub fn check(&mut self) -> bool {
        if self.raised.is_none() {
            self.last = Instant::now();
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                self.raised = Some(e);
            }
        }
        self.raised.is_some()
    }

    /// [`check`](Self::check) if the last check is older than [`INTERVAL`].
    pub fn check_now_and_then(&mut self) -> bool {
        if self.raised.is_none() && self.last.elapsed() < INTERVAL {
            return false;
        }
        self.check()
    }

    /// The exception a signal handler raised, if one did.
    pub fn result(self) -> PyResult<()> {
        match self.raised {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }
}

impl RunObserver for Signals {
    fn period(&mut self, _periods: u64, _state: &StateView<'_>) -> ControlFlow<()> {
        if self.check_now_and_then() {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    }
}

/// A cancel hook for the orbit solvers that runs Python's signal handlers (at most every
/// [`INTERVAL`]), and the watcher that keeps the exception one raised.
pub fn cancel_hook() -> (
    vibrotribo::orbits::Cancel,
    std::sync::Arc<std::sync::Mutex<Signals>>,
) {
    let signals = std::sync::Arc::new(std::sync::Mutex::new(Signals::new()));
    let shared = std::sync::Arc::clone(&signals);
    let cancel = vibrotribo::orbits::Cancel::new(move || {
        // A poisoned lock (a panic while checking) stops the computation.
        shared.lock().map_or(true, |mut s| s.check_now_and_then())
    });
    (cancel, signals)
}

/// The exception the signal handlers raised through a [`cancel_hook`], if one did.
pub fn cancel_result(signals: &std::sync::Mutex<Signals>) -> PyResult<()> {
    match signals.lock() {
        Ok(mut s) => match s.raised.take() {
            Some(e) => Err(e),
            None => Ok(()),
        },
        Err(_) => Err(pyo3::exceptions::PyKeyboardInterrupt::new_err("interrupted")),
    }
}
