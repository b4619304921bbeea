//! Progress bars on a terminal, and SIGINT/SIGTERM handling that lets a run stop cleanly.
//!
//! The first SIGINT (Ctrl-C) or SIGTERM (`kill`, a Slurm time limit) sets a flag that long
//! loops read at their checkpoints ([`interrupted`]): they stop there, write a consistent
//! result marked incomplete, and return [`Interrupted`], which `main` turns into the exit
//! status of the signal (130 for SIGINT, 143 for SIGTERM). A second signal exits at once.

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use indicatif::{ProgressBar, ProgressStyle};
use signal_hook::consts::{SIGINT, SIGTERM};

/// The flags the signal handlers set.
struct Flags {
    any: Arc<AtomicBool>,
    term: Arc<AtomicBool>,
}

static FLAGS: OnceLock<Flags> = OnceLock::new();

/// Exit status after SIGINT.
pub const EXIT_SIGINT: u8 = 130;
/// Exit status after SIGTERM.
pub const EXIT_SIGTERM: u8 = 143;

/// Installs the SIGINT and SIGTERM handlers (once).
pub fn install_interrupt_handler() -> std::io::Result<()> {
    let flags = FLAGS.get_or_init(|| Flags {
        any: Arc::new(AtomicBool::new(false)),
        term: Arc::new(AtomicBool::new(false)),
    });
    for (signal, status) in [(SIGINT, EXIT_SIGINT), (SIGTERM, EXIT_SIGTERM)] {
        // Registered first, so that it sees the flag's value from before this signal: a second
        // signal of either kind exits at once.
        signal_hook::flag::register_conditional_shutdown(signal, i32::from(status), Arc::clone(&flags.any))?;
        signal_hook::flag::register(signal, Arc::clone(&flags.any))?;
    }
    signal_hook::flag::register(SIGTERM, Arc::clone(&flags.term))?;
    Ok(())
}

/// Whether a SIGINT or SIGTERM asked the program to stop.
pub fn interrupted() -> bool {
    FLAGS.get().is_some_and(|f| f.any.load(Ordering::SeqCst))
}

/// The flag a SIGINT or SIGTERM sets, for the library's long phases that poll one (a base
/// motion's build, the motion classification); `None` before the handlers are installed.
pub fn stop_flag() -> Option<Arc<AtomicBool>> {
    FLAGS.get().map(|f| Arc::clone(&f.any))
}

/// The exit status for the signal that stopped the program: 143 after SIGTERM, else 130.
pub fn interrupt_status() -> u8 {
    match FLAGS.get() {
        Some(f) if f.term.load(Ordering::SeqCst) => EXIT_SIGTERM,
        _ => EXIT_SIGINT,
    }
}

/// A command stopped at a checkpoint because of SIGINT or SIGTERM, after writing a
/// consistent result marked incomplete. `what` says what was kept and how to continue.
#[derive(Debug)]
pub struct Interrupted {
    /// What was kept, e.g. "the files hold the 12 values finished; --resume continues".
    pub what: String,
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "interrupted: {}", self.what)
    }
}

impl std::error::Error for Interrupted {}

/// `Err(Interrupted)` with `what` if a signal asked to stop, else `Ok`.
pub fn check_interrupt(what: impl FnOnce() -> String) -> anyhow::Result<()> {
    if interrupted() {
        Err(Interrupted { what: what() }.into())
    } else {
        Ok(())
    }
}

/// Watches a run of the library's run layer: one step of a progress bar per period, and a
/// checkpoint that stops the run after SIGINT/SIGTERM.
pub struct Watch {
    /// The bar, one step per period.
    pub progress: Progress,
}

impl vibrotribo::study::RunObserver for Watch {
    fn period(&mut self, _periods: u64, _state: &vibrotribo::StateView<'_>) -> std::ops::ControlFlow<()> {
        self.progress.inc(1);
        if interrupted() {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    }
}

/// A progress bar drawn only when stderr is a terminal.
pub struct Progress {
    bar: Option<ProgressBar>,
}

impl Progress {
    /// A bar for `len` steps labelled `what`; hidden if `quiet` or not on a terminal.
    pub fn new(len: u64, what: &str, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new(len);
            bar.set_style(
                ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} {per_sec} eta {eta}")
                    .expect("valid template")
                    .progress_chars("=> "),
            );
            bar.set_message(what.to_string());
            bar
        });
        Progress { bar }
    }

    /// Starts at `pos` steps already done (a resumed job).
    pub fn starting_at(self, pos: u64) -> Self {
        if let Some(b) = &self.bar {
            b.set_position(pos);
            b.reset_eta();
        }
        self
    }

    /// Advances by `n` steps.
    pub fn inc(&self, n: u64) {
        if let Some(b) = &self.bar {
            b.inc(n);
        }
    }

    /// Sets the number of steps in all (a job whose size grows as it goes).
    pub fn set_len(&self, len: u64) {
        if let Some(b) = &self.bar {
            b.set_length(len);
        }
    }

    /// Sets the steps done.
    pub fn set_position(&self, pos: u64) {
        if let Some(b) = &self.bar {
            b.set_position(pos);
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

impl Progress {
    /// A spinner with the elapsed time, labelled `what`, for a computation of unknown length;
    /// hidden if `quiet` or not on a terminal.
    pub fn spinner(what: &str, quiet: bool) -> Self {
        let bar = (!quiet && std::io::stderr().is_terminal()).then(|| {
            let bar = ProgressBar::new_spinner();
            bar.set_style(
                ProgressStyle::with_template("{msg:>12} {spinner} {elapsed}").expect("valid template"),
            );
            bar.set_message(what.to_string());
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
            bar
        });
        Progress { bar }
    }
}

/// A cancel hook for the library's orbit solvers that asks them to stop after SIGINT/SIGTERM.
pub fn orbit_cancel() -> vibrotribo::orbits::Cancel {
    vibrotribo::orbits::Cancel::new(interrupted)
}
