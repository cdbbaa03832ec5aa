//! The budget of a frame ([`step_within`](super::step_within)): the frontier's [`Budget`]
//! trait and its kinds, re-exported, and the time kept back from a deadline for the work
//! that follows the budgeted traversal.

use std::time::{Duration, Instant};

pub use crate::bvh::frontier::{Budget, Deadline, Unlimited, VisitBudget};

/// Time kept back from a frame's deadline for what follows the budgeted mesh–mesh
/// frontier: the pairs answered outside it (closed forms, GJK/EPA, convex–mesh walks), the
/// exact contacts of finished touching mesh pairs, the records of truncated pairs, and
/// the daemon's writing and publishing of the result frame. 100 µs.
///
/// Why this much: the latency target is the budget plus 50 µs at p99.9. Publishing
/// (loan, write, send, notify) is part of a raw iceoryx2 round trip, measured at 78 µs p50
/// and 128 µs p99 there and back on the 2-core VM (README, `ipc_latency`), so about half
/// of that one way; the rest of the narrow phase for a few hundred primitive pairs is of
/// the same order (closed forms 3–900 ns, GJK 0.5–7 µs per pair, README). Not measured
/// on budgeted frames yet: to be replaced by the value `examples/time_vs_error.rs`
/// measures from the daemon's `stage_ns[NARROW]` and `stage_ns[PUBLISH]` (release builds;
/// tests here never measure time).
pub const FRONTIER_RESERVE: Duration = Duration::from_micros(100);

/// The deadline of the frontier inside a frame ending at `frame_deadline`:
/// [`FRONTIER_RESERVE`] earlier. A frame with less than the reserve left gets a deadline
/// already past: its frontier does no work and every mesh pair is answered at level 0.
#[must_use]
pub fn frontier_deadline(frame_deadline: Instant) -> Deadline {
    Deadline(
        frame_deadline
            .checked_sub(FRONTIER_RESERVE)
            .unwrap_or(frame_deadline),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frontier_deadline_is_the_frame_deadline_less_the_reserve() {
        let now = Instant::now();
        let frame = now + Duration::from_millis(2);
        assert_eq!(frontier_deadline(frame).0 + FRONTIER_RESERVE, frame);
        assert_eq!(
            frontier_deadline(frame).deadline(),
            Some(frame - FRONTIER_RESERVE)
        );
    }

    #[test]
    fn only_deadlines_name_an_instant_and_only_unlimited_is_unlimited() {
        assert_eq!(VisitBudget(5).deadline(), None);
        assert_eq!(Unlimited.deadline(), None);
        assert!(Unlimited.is_unlimited());
        assert!(!VisitBudget(u64::MAX).is_unlimited());
        assert!(!Deadline(Instant::now()).is_unlimited());
    }
}
