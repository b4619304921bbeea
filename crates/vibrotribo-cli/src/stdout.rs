//! Standard output that survives its reader. Every `print!` and `println!` of the program
//! goes through [`write`]: the two macros defined here shadow the standard ones in every
//! module declared after this one (see `main.rs`).
//!
//! - A closed pipe (`vibrotribo simulate | head -c 100`) ends the printing quietly: the
//!   command goes on, writes its files, and exits with its own status.
//! - Any other failure (a full disk behind `> file`, `> /dev/full`) also ends the printing;
//!   [`finish`] then reports it as one error line and the program exits with status 1.

use std::io::{ErrorKind, Write};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};

/// Standard output failed: nothing more is printed.
static CLOSED: AtomicBool = AtomicBool::new(false);

/// The first failure other than a closed pipe.
static FAILURE: OnceLock<String> = OnceLock::new();

/// `print!` through [`write`].
macro_rules! print {
    ($($arg:tt)*) => {
        $crate::stdout::write(format_args!($($arg)*), false)
    };
}

/// `println!` through [`write`].
macro_rules! println {
    () => {
        $crate::stdout::write(format_args!(""), true)
    };
    ($($arg:tt)*) => {
        $crate::stdout::write(format_args!($($arg)*), true)
    };
}

/// Writes `args` (and a newline if `newline`) to standard output, unless it failed before.
pub fn write(args: std::fmt::Arguments<'_>, newline: bool) {
    if CLOSED.load(Ordering::Relaxed) {
        return;
    }
    let mut out = std::io::stdout().lock();
    let written = out
        .write_fmt(args)
        .and_then(|()| if newline { out.write_all(b"\n") } else { Ok(()) });
    if let Err(e) = written {
        failed(&e);
    }
}

/// Records a failure of standard output.
fn failed(e: &std::io::Error) {
    CLOSED.store(true, Ordering::Relaxed);
    if e.kind() != ErrorKind::BrokenPipe {
        let _ = FAILURE.set(e.to_string());
    }
}

/// Flushes standard output; an error naming the failure if it could not be written (a closed
/// pipe is no error).
pub fn finish() -> anyhow::Result<()> {
    if !CLOSED.load(Ordering::Relaxed)
        && let Err(e) = std::io::stdout().lock().flush()
    {
        failed(&e);
    }
    match FAILURE.get() {
        Some(e) => anyhow::bail!("cannot write to standard output: {e}"),
        None => Ok(()),
    }
}
