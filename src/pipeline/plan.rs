//! The plan of a frame ([`step_within`](super::step_within)), decided before the work
//! starts: how its budget is split (the frontier's deadline, the time kept back for the
//! work after it) and, per candidate pair, which route answers it ([`PairPlan`]).

use super::costs::FrameCosts;
use super::{MIN_PARALLEL_MESH_PAIRS, Query};
use crate::budget::{Budget, Stop, WORK_PER_CLOCK_READ, WorkClock};
pub use crate::budget::{Deadline, Unlimited, VisitBudget};
use crate::narrow::dispatch::{self, Route};
use crate::narrow::{MeshShape, Shape};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Time kept back from a frame's deadline for what follows the budgeted mesh–mesh
/// frontier: the pairs answered outside it (closed forms, GJK/EPA, convex–mesh walks), the
/// exact contacts of finished touching mesh pairs, the records of truncated pairs, and
/// the daemon's writing and publishing of the result frame. 100 µs.
///
/// Why this much: publishing (loan, write, send, notify) is about half a raw iceoryx2 round
/// trip (`examples/ipc_latency`), and the rest of the narrow phase for a few hundred
/// primitive pairs is of the same order (`benches/narrow_phase.rs`). The quarter of
/// [`frontier_deadline`] is the frontier's own slack as much as the tail's: its overrun of
/// its deadline (a round's sort is not polled) must not push the frame past its own
/// (`examples/time_vs_error`).
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

/// Whether a frame asking `query` under `budget` can hold its uninterruptible work
/// (`costs`, measured on its scene of `bodies` bodies) from now: `Err` with that work's
/// nanoseconds when its deadline comes first. Frames without a deadline, or not at the
/// current poses, and scenes not measured yet always fit.
pub(super) fn mandatory_work_fits(
    budget: &dyn Budget,
    query: Query,
    costs: &FrameCosts,
    bodies: usize,
) -> Result<(), u64> {
    let (Some(deadline), Some(needed)) = (budget.deadline(), costs.mandatory_ns(bodies)) else {
        return Ok(());
    };
    let fits =
        !query.at_current_poses() || Instant::now() + Duration::from_nanos(needed) <= deadline;
    if fits { Ok(()) } else { Err(needed) }
}

/// How a frame answers one candidate pair that no kept answer covers; decided before any of
/// the pair's work runs.
#[derive(Debug)]
pub(super) enum PairPlan<'s> {
    /// Proven apart by a kept separation or its meshes' hulls (`separation.rs`).
    Separated,
    /// The frame's deadline is near: its distance bounds' or world boxes' conservative
    /// answer.
    Conservative,
    /// Exact, by the dispatcher: a closed form, GJK/EPA or a convex–mesh walk.
    Direct,
    /// Mesh–mesh, read from the budgeted frontier's answer.
    Frontier(&'s Arc<MeshShape>, &'s Arc<MeshShape>),
    /// Mesh–mesh, read from the worker pool's outcome.
    Pooled,
    /// Mesh–mesh, the exact tandem queries on this thread.
    MeshMesh(&'s Arc<MeshShape>, &'s Arc<MeshShape>),
}

impl PairPlan<'_> {
    /// Whether the pair's mesh–mesh search runs this frame, so its answer may leave or
    /// lapse the pair's separation.
    pub(super) fn searches_mesh_pair(&self) -> bool {
        matches!(self, Self::Frontier(..) | Self::Pooled | Self::MeshMesh(..))
    }
}

/// The frame's plan: whether its budget is limited, whether the pool answers its mesh
/// pairs, and the clock of the pairs answered off the frontier.
pub(super) struct FramePlan {
    /// A limited budget on a frame at the current poses: mesh pairs go through the
    /// frontier, and pairs off it keep to the deadline.
    pub(super) limited: bool,
    /// The worker pool answered the frame's mesh pairs.
    pub(super) pool: bool,
    /// Pairs off the frontier's route keep to the frame's deadline: once it is near, the
    /// rest get conservative answers.
    pair_clock: WorkClock,
    /// The frame's deadline, when it keeps to one (`limited`).
    deadline: Option<Instant>,
}

impl FramePlan {
    /// The plan of a frame asking `query` under `budget` (the pool decided later, by
    /// [`wants_pool`](Self::wants_pool)).
    pub(super) fn new(budget: &dyn Budget, query: Query) -> Self {
        let limited = !budget.is_unlimited() && query.at_current_poses();
        let deadline = budget.deadline().filter(|_| limited);
        Self {
            limited,
            pool: false,
            pair_clock: pair_clock(deadline),
            deadline,
        }
    }

    /// The clock the narrow routes poll inside one pair (a convex shape's walk of a mesh,
    /// EPA): the pairs' deadline, so a pair started just before it stops soon after.
    pub(super) fn narrow_clock(&self) -> WorkClock {
        pair_clock(self.deadline)
    }

    /// Whether a frame with these mesh pairs to answer uses the worker pool: never under a
    /// limited budget (the frontier runs on one thread), and only with at least
    /// [`MIN_PARALLEL_MESH_PAIRS`] of them.
    pub(super) fn wants_pool<T>(&self, mut needed: impl Iterator<Item = T>) -> bool {
        !self.limited
            && needed.by_ref().take(MIN_PARALLEL_MESH_PAIRS).count() == MIN_PARALLEL_MESH_PAIRS
    }

    /// The route of a pair of shapes `sa`, `sb` (`separated` when a kept separation or the
    /// hulls proved it apart). Reads the pair clock only for pairs it may cut short.
    pub(super) fn pair<'s>(
        &mut self,
        sa: &'s Shape,
        sb: &'s Shape,
        separated: bool,
    ) -> PairPlan<'s> {
        match dispatch::route(sa, sb) {
            _ if separated => PairPlan::Separated,
            Route::Direct
                if !dispatch::exact_costs_no_more_than_boxes(sa, sb)
                    && !self.pair_clock.allows(pair_work(sa, sb)) =>
            {
                PairPlan::Conservative
            }
            Route::Direct => PairPlan::Direct,
            Route::MeshMesh(ma, mb) if self.limited => PairPlan::Frontier(ma, mb),
            Route::MeshMesh(..) if self.pool => PairPlan::Pooled,
            Route::MeshMesh(ma, mb) => PairPlan::MeshMesh(ma, mb),
        }
    }
}

/// Units of [`WorkClock`] work a direct pair counts for: 1 for the closed forms of capsules
/// and cuboids (about 100 ns), a whole clock read's worth for GJK/EPA and convex–mesh walks
/// (microseconds to tens of them), so the clock is read before each of those.
fn pair_work(a: &Shape, b: &Shape) -> u64 {
    use Shape::{Capsule as C, Cuboid as B, Sphere as S};
    match (a, b) {
        (S(_) | C(_) | B(_), S(_) | C(_) | B(_)) => 1,
        _ => WORK_PER_CLOCK_READ,
    }
}

/// Time kept back from a frame's deadline for writing and publishing its results, when the
/// pairs off the frontier are cut short (`PairClock`). 30 µs: an estimate of the daemon's
/// publish stage (loan, write, send, notify) on the 2-core VM, to be replaced by a measured
/// value.
pub const PUBLISH_RESERVE: Duration = Duration::from_micros(30);

/// The clock of the work after the frontier (the per-pair loop, the narrow routes' long
/// steps, time of impact): it stops [`PUBLISH_RESERVE`] before the frame's deadline, reading
/// the time every few pairs ([`WorkClock`]); unlimited without a deadline.
pub(super) fn pair_clock(frame_deadline: Option<Instant>) -> WorkClock {
    WorkClock::new(frame_deadline.map_or(Stop::Never, |d| {
        Stop::At(d.checked_sub(PUBLISH_RESERVE).unwrap_or(d))
    }))
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
