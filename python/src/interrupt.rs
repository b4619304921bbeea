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

/// Runs `work` (a configuration's read, which may build a long random base motion) on a
/// worker thread with a stop flag, while this thread waits with the GIL released and runs
/// Python's signal handlers every [`INTERVAL`]: the exception one raises sets the flag (the
/// build stops at its next look at it, within 64 intervals of the signal) and is raised here
/// once the worker has ended.
pub fn interruptibly<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&std::sync::Arc<std::sync::atomic::AtomicBool>) -> T + Send,
{
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::mpsc::{RecvTimeoutError, channel};
    let flag = std::sync::Arc::new(AtomicBool::new(false));
    let (tx, rx) = channel();
    // Waited on with the GIL released (a receiver is not shared between threads by itself).
    let rx = std::sync::Mutex::new(rx);
    let wait = |timeout: Option<Duration>| {
        let rx = rx.lock().map_err(|_| RecvTimeoutError::Disconnected)?;
        match timeout {
            Some(t) => rx.recv_timeout(t),
            None => rx.recv().map_err(|_| RecvTimeoutError::Disconnected),
        }
    };
    std::thread::scope(|s| {
        let worker_flag = std::sync::Arc::clone(&flag);
        s.spawn(move || {
            let _ = tx.send(work(&worker_flag));
        });
        loop {
            match py.detach(|| wait(Some(INTERVAL))) {
                Ok(done) => return Ok(done),
                Err(RecvTimeoutError::Timeout) => {
                    if let Err(e) = py.check_signals() {
                        flag.store(true, Ordering::Relaxed);
                        let _ = py.detach(|| wait(None));
                        return Err(e);
                    }
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(pyo3::exceptions::PyRuntimeError::new_err(
                        "the configuration's reader ended without an answer",
                    ));
                }
            }
        }
    })
}
