//! The budget of a frame ([`step_within`](super::step_within)): the frontier's [`Budget`]
//! trait and its kinds, re-exported, and the time kept back from a deadline for the work
//! that follows the budgeted traversal.

use std::time::{Duration, Instant};

pub use crate::budget::{Budget, Deadline, Unlimited, VisitBudget};

/// Time kept back from a frame's deadline for what follows the budgeted mesh–mesh
/// frontier: the pairs answered outside it (closed forms, GJK/EPA, convex–mesh walks), the
/// exact contacts of finished touching mesh pairs, the records of truncated pairs, and
/// the daemon's writing and publishing of the result frame. 100 µs.
///
/// Why this much: the latency target is the budget plus 50 µs at p99.9. Publishing
/// (loan, write, send, notify) is part of a raw iceoryx2 round trip, measured at 78 µs p50
/// and 128 µs p99 there and back on the 2-core VM (README, `ipc_latency`), so about half
/// of that one way; the rest of the narrow phase for a few hundred primitive pairs is of
/// the same order (closed forms 3–900 ns, GJK 0.5–7 µs per pair, README).
///
/// Measured and not kept: a reserve measured per workspace, the held peak of recent
/// frames' time after their frontier plus 10 µs. On `examples/time_vs_error --scene
/// robot-chain` those frames spent about 5 µs there, so the frontier got 90 µs of a 100 µs
/// budget instead of 75; but its own overrun of its deadline (a round's sort, which is not
/// polled, and the answers) then made 45–70 of 300 frames miss a 200 µs budget (0–2 with
/// the quarter), for no gain in precision (0.84–0.91 against 0.88–0.91 at 100 µs, three
/// alternating runs). The quarter is the frontier's slack as much as the tail's.
pub const FRONTIER_RESERVE: Duration = Duration::from_micros(100);

/// The deadline of a frontier starting at `start` inside a frame ending at
/// `frame_deadline`: earlier by [`FRONTIER_RESERVE`] or by a quarter of the time left,
/// whichever is less. A small budget keeps three quarters for the frontier (with
/// the whole reserve, a 100 µs frame left it nothing: every mesh pair at level 0; the work
/// after the frontier shrinks with the frame, and the pairs off the frontier keep to the
/// deadline on their own). A deadline already past stays past.
#[must_use]
pub fn frontier_deadline(start: Instant, frame_deadline: Instant) -> Deadline {
    let budget = frame_deadline.saturating_duration_since(start);
    let reserve = FRONTIER_RESERVE.min(budget / 4);
    Deadline(
        frame_deadline
            .checked_sub(reserve)
            .unwrap_or(frame_deadline),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_frontier_deadline_is_the_frame_deadline_less_the_reserve_or_a_quarter_budget() {
        let now = Instant::now();
        let frame = now + Duration::from_millis(2);
        assert_eq!(frontier_deadline(now, frame).0 + FRONTIER_RESERVE, frame);
        assert_eq!(
            frontier_deadline(now, frame).deadline(),
            Some(frame - FRONTIER_RESERVE)
        );
        let small = now + Duration::from_micros(200);
        assert_eq!(
            frontier_deadline(now, small).0,
            now + Duration::from_micros(150)
        );
        // A deadline already past (before the frame started) stays where it is.
        let past = now.checked_sub(Duration::from_micros(10)).unwrap_or(now);
        assert_eq!(frontier_deadline(now, past).0, past);
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
