//! Keeping the server's memory flat under a stream of superseded requests.
//!
//! Every computation runs on one of the runtime's blocking threads, and glibc's allocator
//! gives each thread that allocates its own arena (up to eight per core). Memory freed inside
//! those arenas stays with the process, so without a limit the resident size climbs with the
//! number of abandoned parameter changes (`bench/serve --abandoned` reads it). The server
//! therefore limits the allocator to two arenas when it starts ([`limit_arenas`], unless the
//! environment sets `MALLOC_ARENA_MAX` or the `glibc.malloc.arena_max` tunable) and, after
//! each computation, hands the free pages back to the system ([`release_soon`]: one
//! `malloc_trim` at a time, on a blocking thread, after the answer). Elsewhere than glibc both
//! do nothing.

use std::sync::atomic::{AtomicBool, Ordering};

/// Arenas the allocator may keep: one for the runtime's threads, one for a computation.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const ARENAS: i32 = 2;

/// Limits glibc's allocator to [`ARENAS`] arenas, unless the environment chose a limit.
/// Call before the runtime starts its threads.
pub fn limit_arenas() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    if !arena_limit_in_environment() {
        // SAFETY: `mallopt` only sets an allocator parameter; M_ARENA_MAX takes any positive
        // count, and arenas created before the call are kept.
        unsafe {
            libc::mallopt(libc::M_ARENA_MAX, ARENAS);
        }
    }
}

/// Whether `MALLOC_ARENA_MAX` or `GLIBC_TUNABLES=…glibc.malloc.arena_max=…` is set: the
/// user's choice stands.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
fn arena_limit_in_environment() -> bool {
    std::env::var_os("MALLOC_ARENA_MAX").is_some()
        || std::env::var("GLIBC_TUNABLES").is_ok_and(|t| t.contains("glibc.malloc.arena_max"))
}

/// Whether a release is queued or running (at most one at a time: a burst of requests
/// queues one).
static PENDING: AtomicBool = AtomicBool::new(false);

/// Returns the allocator's free pages to the system once the current work has moved on: a
/// `malloc_trim(0)` on a blocking thread, unless one is already queued. Call from inside the
/// server's runtime.
pub fn release_soon() {
    if PENDING.swap(true, Ordering::AcqRel) {
        return;
    }
    tokio::task::spawn_blocking(|| {
        PENDING.store(false, Ordering::Release);
        #[cfg(all(target_os = "linux", target_env = "gnu"))]
        // SAFETY: `malloc_trim` only returns free memory to the system; it is thread-safe.
        unsafe {
            libc::malloc_trim(0);
        }
    });
}
