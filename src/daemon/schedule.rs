//! Which scene's waiting pose frame is answered next: earliest deadline first.
//!
//! A frame's deadline is its receipt plus its budget (DESIGN §5: the budget covers the
//! whole frame from its receipt). Frames with a budget go before frames without one, by
//! deadline; equal deadlines, and frames without a budget, go by receipt; full ties by the
//! order the caller lists them. The frame path holds at most one frame per scene, the oldest
//! (a scene's frames are answered in the order they came), so this orders scenes.
//!
//! Answering is not pre-emptive: a frame that has started runs to its own deadline, so a
//! frame received while it runs waits at most that long.

use std::time::{Duration, Instant};

/// When a waiting frame was received and the budget it carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameKey {
    /// When the daemon took the frame from its scene's subscriber.
    pub received: Instant,
    /// The frame's budget, nanoseconds (0: none).
    pub budget_ns: u64,
}

impl FrameKey {
    /// The frame's deadline: `None` without a budget, and for a budget too large for an
    /// [`Instant`] to hold (centuries), which counts as none.
    #[must_use]
    pub fn deadline(&self) -> Option<Instant> {
        if self.budget_ns == 0 {
            return None;
        }
        self.received
            .checked_add(Duration::from_nanos(self.budget_ns))
    }

    /// Smaller is more urgent: frames with a deadline first, by deadline, then by receipt.
    fn urgency(&self) -> (bool, Option<Instant>, Instant) {
        let deadline = self.deadline();
        (deadline.is_none(), deadline, self.received)
    }
}

/// The index of the most urgent of the `waiting` frames (index, key), `None` when there
/// are none; of equally urgent frames, the first listed.
///
/// # Allocation
/// None.
pub fn most_urgent(waiting: impl IntoIterator<Item = (usize, FrameKey)>) -> Option<usize> {
    waiting
        .into_iter()
        .min_by_key(|(_, key)| key.urgency())
        .map(|(index, _)| index)
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    /// Frames received `at_ms` after `t0` with `budget_ms` (0: none), listed in order.
    fn frames(t0: Instant, frames: &[(u64, u64)]) -> Vec<(usize, FrameKey)> {
        frames
            .iter()
            .enumerate()
            .map(|(i, &(at_ms, budget_ms))| {
                let received = t0 + Duration::from_millis(at_ms);
                let budget_ns = budget_ms * MS;
                (
                    i,
                    FrameKey {
                        received,
                        budget_ns,
                    },
                )
            })
            .collect()
    }

    #[test]
    fn the_earliest_deadline_goes_first_whatever_the_receipt_order() {
        let t0 = Instant::now();
        // Deadlines 10, 3 and 7 ms after t0.
        let waiting = frames(t0, &[(0, 10), (1, 2), (2, 5)]);
        assert_eq!(most_urgent(waiting.clone()), Some(1));
        // Answered in deadline order, one at a time, as the frame thread does.
        let mut left = waiting;
        let mut order = Vec::new();
        while let Some(next) = most_urgent(left.clone()) {
            order.push(next);
            left.retain(|&(i, _)| i != next);
        }
        assert_eq!(order, [1, 2, 0]);
    }

    #[test]
    fn frames_without_a_budget_go_after_every_frame_with_one_in_receipt_order() {
        let t0 = Instant::now();
        // The frames without a budget came first; the budgeted one's deadline is far off.
        let waiting = frames(t0, &[(2, 0), (0, 0), (5, 60_000)]);
        assert_eq!(most_urgent(waiting.clone()), Some(2));
        let unbudgeted: Vec<_> = waiting.into_iter().take(2).collect();
        assert_eq!(most_urgent(unbudgeted), Some(1));
    }

    #[test]
    fn equal_deadlines_go_by_receipt_and_full_ties_by_listing_order() {
        let t0 = Instant::now();
        // Both due 6 ms after t0; the second was received first.
        assert_eq!(most_urgent(frames(t0, &[(2, 4), (1, 5)])), Some(1));
        assert_eq!(most_urgent(frames(t0, &[(1, 5), (1, 5)])), Some(0));
    }

    #[test]
    fn a_budget_too_large_for_an_instant_counts_as_none_without_panicking() {
        let t0 = Instant::now();
        let huge = FrameKey {
            received: t0,
            budget_ns: u64::MAX,
        };
        let budgeted = FrameKey {
            received: t0 + Duration::from_secs(1),
            budget_ns: MS,
        };
        let deadline = huge.deadline();
        // Either it fits (about 584 years) or it counts as none: both go after 1 ms.
        assert!(deadline.is_none_or(|d| d > budgeted.deadline().unwrap()));
        assert_eq!(most_urgent([(0, huge), (1, budgeted)]), Some(1));
    }

    #[test]
    fn nothing_waiting_picks_nothing() {
        assert_eq!(most_urgent([]), None);
    }
}
