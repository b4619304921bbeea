//! Stopping computations nobody waits for: a newer request of the same kind supersedes an
//! older one, a client that goes away (its response dropped) stops its work, and SIGINT or
//! SIGTERM stop everything. Long loops poll [`Ticket::stopped`].
//!
//! "Newer" is decided by the request's `seq` when it carries one (a number the client
//! increases with each request it sends; the page sends its clock in microseconds), so a
//! request that was sent earlier but reaches the server later never supersedes the newest:
//! it is refused at once. A request without `seq` is newer than every request that arrived
//! before it.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// The generation counter of one kind of request (the run view, the orbit diagram, …): each
/// new request takes the next number, and a running one whose number is no longer the last
/// is superseded.
#[derive(Debug, Default)]
pub struct Lane {
    latest: Arc<AtomicU64>,
    /// The highest `seq` taken so far (0: none).
    newest_seq: Mutex<u64>,
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

/// A request whose `seq` is not above the newest its lane has taken: it was sent before a
/// request already being answered.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outdated;

impl Lane {
    /// A ticket for a new request, superseding every older one of this lane, and its guard;
    /// [`Outdated`] when `seq` is not above the newest `seq` taken (the lane is unchanged).
    pub fn take(&self, seq: Option<u64>) -> Result<(Ticket, Guard), Outdated> {
        let mut newest = self.newest_seq.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(seq) = seq {
            if seq <= *newest {
                return Err(Outdated);
            }
            *newest = seq;
        }
        let mine = self.latest.fetch_add(1, Ordering::SeqCst) + 1;
        drop(newest);
        let gone = Arc::new(AtomicBool::new(false));
        Ok((
            Ticket {
                latest: Arc::clone(&self.latest),
                mine,
                gone: Arc::clone(&gone),
            },
            Guard { gone },
        ))
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
        let (first, _g1) = lane.take(None).unwrap();
        assert!(!first.stopped());
        let (second, g2) = lane.take(None).unwrap();
        assert!(first.stopped() && !second.stopped());
        drop(g2);
        assert!(second.stopped());
    }

    #[test]
    fn a_request_sent_earlier_but_taken_later_is_refused_and_supersedes_nothing() {
        let lane = Lane::default();
        let (newest, _g) = lane.take(Some(20)).unwrap();
        assert_eq!(lane.take(Some(10)).map(|_| ()), Err(Outdated));
        assert_eq!(lane.take(Some(20)).map(|_| ()), Err(Outdated));
        assert!(!newest.stopped(), "an outdated request stopped the newest");
        let (newer, _g2) = lane.take(Some(21)).unwrap();
        assert!(newest.stopped() && !newer.stopped());
    }
}
