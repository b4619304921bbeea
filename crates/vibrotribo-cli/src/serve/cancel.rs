//! Stopping computations nobody waits for: a newer request of the same kind supersedes an
//! older one, a client that goes away (its response dropped) stops its work, and SIGINT or
//! SIGTERM stop everything. Long loops poll [`Ticket::stopped`].

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// The generation counter of one kind of request (the run view, the orbit diagram, …): each
/// new request takes the next number, and a running one whose number is no longer the last
/// is superseded.
#[derive(Debug, Default)]
pub struct Lane {
    latest: Arc<AtomicU64>,
}

/// The right of one request to keep computing.
#[derive(Debug, Clone)]
pub struct Ticket {
    latest: Arc<AtomicU64>,
    mine: u64,
    gone: Arc<AtomicBool>,
}

/// Marks its ticket stopped when dropped: held by the handler (or its response stream), so a
/// client that disconnects stops the work it asked for.
#[derive(Debug)]
pub struct Guard {
    gone: Arc<AtomicBool>,
}

impl Drop for Guard {
    fn drop(&mut self) {
        self.gone.store(true, Ordering::SeqCst);
    }
}

impl Lane {
    /// A ticket for a new request, superseding every older one of this lane, and its guard.
    pub fn take(&self) -> (Ticket, Guard) {
        let mine = self.latest.fetch_add(1, Ordering::SeqCst) + 1;
        let gone = Arc::new(AtomicBool::new(false));
        (
            Ticket {
                latest: Arc::clone(&self.latest),
                mine,
                gone: Arc::clone(&gone),
            },
            Guard { gone },
        )
    }
}

impl Ticket {
    /// Whether the work should stop: superseded, abandoned, or the server is stopping.
    pub fn stopped(&self) -> bool {
        self.latest.load(Ordering::SeqCst) != self.mine
            || self.gone.load(Ordering::SeqCst)
            || crate::progress::interrupted()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_newer_ticket_or_a_dropped_guard_stops_the_older() {
        let lane = Lane::default();
        let (first, _g1) = lane.take();
        assert!(!first.stopped());
        let (second, g2) = lane.take();
        assert!(first.stopped() && !second.stopped());
        drop(g2);
        assert!(second.stopped());
    }
}
