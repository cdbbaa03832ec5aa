//! The plan of a frame ([`step_within`](super::step_within)), decided before the work
//! starts: how its budget is split (the frontier's deadline, the time kept back for the
//! work after it), how many candidates it can answer at all, and, per candidate pair,
//! which route answers it ([`PairPlan`]). The time kept back comes from the scene's
//! measured [`FrameCosts`]: the frame's *tail* (each pair left when the clock stops still
//! gets its conservative answer, and every record is published) is reserved out of the
//! budget, and re-estimated before each pair.

use super::costs::FrameCosts;
use super::{MIN_PARALLEL_MESH_PAIRS, MIN_PARALLEL_WALKS, Query};
use crate::budget::{Abandon, Budget, Stop, WORK_PER_CLOCK_READ, WorkClock};
pub use crate::budget::{Deadline, Unlimited, VisitBudget};
use crate::narrow::dispatch::{self, Route};
use crate::narrow::{MeshShape, Shape};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Time the budgeted mesh–mesh frontier leaves, besides the frame's tail, for the pairs
/// answered off it exactly (closed forms, GJK/EPA, convex–mesh walks) and the exact
/// contacts of finished touching mesh pairs: 100 µs, or a quarter of the time left after
/// the tail when that is less.
///
/// Why this much: the narrow phase of a few hundred primitive pairs takes about that
/// (`benches/narrow_phase.rs`); the frontier's own unpolled work (a round's sort, its
/// answer pass) is reserved apart, per waiting entry ([`FrontierClock`]). A small budget keeps three
/// quarters for the frontier (with the whole reserve, a 100 µs frame left it nothing:
/// every mesh pair at level 0; the pairs off the frontier keep to the deadline on their
/// own).
pub const FRONTIER_RESERVE: Duration = Duration::from_micros(100);

/// The share of the time left after the broad phase that a scene's first budgeted frame
/// keeps in reserve, its costs not measured yet ([`FrameCosts::mandatory_ns`] is `None`).
/// Everything runs cold on that frame (code, the pairs' memory records, result lists that
/// grow, shared memory not touched yet), and the plan paces by priors. On the demo's first
/// frame (2-core VM, 1,000 µs budget) ingest took 10 times its warm time, the broad phase 10
/// times, a tail pair 0.6–1.1 µs against 0.1–0.3 warm. It was late by 37–104 µs in 3 runs
/// of 3 with neither this reserve nor the cold priors of [`FrameCosts`], by 20 µs in 1 run
/// of 5 with the priors alone, and in none of 23 with both.
pub const COLD_RESERVE: f64 = 0.25;

/// The deadline a cold frame works to at `now`: [`COLD_RESERVE`] of the time left kept
/// back (a deadline already past stays as it is).
fn cold_deadline(deadline: Instant, now: Instant) -> Instant {
    let left = deadline.saturating_duration_since(now);
    deadline - left.mul_f64(COLD_RESERVE)
}

/// Candidate pairs a frame with a deadline answers even when their conservative answers do
/// not fit the time left (the frame's cap to its time): 256, a few tens of microseconds of
/// conservative answers. A frame whose deadline is already past when its pairs start (its
/// receipt waited behind another scene's frame, or the OS descheduled it) is late whatever
/// it does; with this floor a scene of a few hundred pairs still gets every pair answered,
/// conservatively, rather than an empty sample. Only pair explosions are cut to the time.
pub const MIN_ANSWERED_PAIRS: usize = 256;

/// The deadline of a frontier starting at `start` inside a frame ending at
/// `frame_deadline` whose tail ([`FrameCosts::tail_ns`]) takes `tail`: earlier by the tail
/// and by [`FRONTIER_RESERVE`] or a quarter of the time left after the tail, whichever is
/// less. A deadline already past stays past.
#[must_use]
pub fn frontier_deadline(start: Instant, frame_deadline: Instant, tail: Duration) -> Deadline {
    let left = frame_deadline
        .saturating_duration_since(start)
        .saturating_sub(tail);
    let reserve = tail + FRONTIER_RESERVE.min(left / 4);
    Deadline(frame_deadline.checked_sub(reserve).unwrap_or(start))
}

/// The frontier's budget in a frame: its deadline ([`frontier_deadline`]), less the time
/// the entries left waiting will take once it stops (their answers and a round's sort,
/// [`FrameCosts::pending_entry_ps`] each), so the frontier stops growing while extracting
/// its answers still fits.
/// It also stops once its [`Abandon`] flag is raised.
#[derive(Debug, Clone)]
pub struct FrontierClock {
    /// When the frontier's work must end, its answers extracted.
    pub deadline: Deadline,
    /// What one waiting entry costs after the frontier stops, picoseconds.
    pub ps_per_pending_entry: u64,
    /// Raised when the frame's work is to stop now.
    pub abandon: Abandon,
}

impl Budget for FrontierClock {
    fn allows(&mut self, visits: u64) -> bool {
        !self.abandon.is_raised() && self.deadline.allows(visits)
    }

    fn allows_pending(&mut self, _visits: u64, pending: u64) -> bool {
        if self.abandon.is_raised() {
            return false;
        }
        let reserve =
            Duration::from_nanos(pending.saturating_mul(self.ps_per_pending_entry) / 1000);
        Instant::now()
            .checked_add(reserve)
            .is_some_and(|done| done < self.deadline.0)
    }

    fn deadline(&self) -> Option<Instant> {
        Some(self.deadline.0)
    }
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
    /// A direct pair that walks a tree (see [`pool_work`]), read from the worker pool's
    /// outcome.
    PooledWalk,
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
/// pairs, and when the work after the frontier stops.
pub(super) struct FramePlan {
    /// A limited budget on a frame at the current poses: mesh pairs go through the
    /// frontier, and pairs off it keep to the deadline.
    pub(super) limited: bool,
    /// The worker pool answered the frame's mesh pairs.
    pub(super) pool: bool,
    /// The frame's deadline, when its budget has one.
    deadline: Option<Instant>,
    /// An unlimited frame's slice: when its work stops for the caller to run it again
    /// elsewhere ([`step_sliced`](super::step_sliced)).
    slice: Option<Instant>,
}

impl FramePlan {
    /// The plan of a frame asking `query` under `budget` (the pool decided later, by
    /// [`wants_pool`](Self::wants_pool)). A `cold` frame (its scene's costs not measured
    /// yet) keeps [`COLD_RESERVE`] of the time left in reserve: its work ends that much
    /// before the deadline.
    pub(super) fn new(
        budget: &dyn Budget,
        query: Query,
        slice: Option<Instant>,
        cold: bool,
    ) -> Self {
        let limited = !budget.is_unlimited() && query.at_current_poses();
        let now = Instant::now();
        Self {
            limited,
            pool: false,
            // Time of impact keeps to the deadline whatever the frame asks.
            deadline: budget
                .deadline()
                .map(|d| if cold { cold_deadline(d, now) } else { d }),
            slice: slice.filter(|_| budget.is_unlimited()),
        }
    }

    /// When the frame's work must end, the tail included (the deadline, less the cold
    /// reserve on a cold frame); `None` without a deadline.
    pub(super) fn deadline(&self) -> Option<Instant> {
        self.deadline
    }

    /// The frame's one clock for everything after the frontier: the pair loop, the narrow
    /// routes' long steps inside a pair (a convex shape's walk of a mesh, EPA, exact
    /// mesh–mesh contacts) and time of impact. With a deadline, [`pace`](Self::pace) keeps
    /// its stop the frame's tail before it, so a pair started just before then stops soon
    /// after; it never stops without a deadline. The pipeline keeps it in
    /// [`NarrowScratch::clock`](crate::narrow::dispatch::NarrowScratch::clock), where the
    /// dispatcher's routes poll it. It stops at once when `abandon` is raised, deadline or
    /// not, and an unlimited frame's at the end of its slice.
    pub(super) fn clock(&self, abandon: &Abandon) -> WorkClock {
        let stop = self.deadline.or(self.slice).map_or(Stop::Never, Stop::At);
        WorkClock::new(stop).abandonable(abandon.clone())
    }

    /// Moves `clock`'s stop to the frame's deadline less its tail from here
    /// ([`FrameCosts::tail_ns`] of `pairs_left` pairs and `records` records so far): the
    /// work after the clock stops still ends by the deadline. No effect without a deadline.
    pub(super) fn pace(
        &self,
        clock: &mut WorkClock,
        costs: &FrameCosts,
        pairs_left: usize,
        records: usize,
    ) {
        if let Some(deadline) = self.deadline {
            let tail = Duration::from_nanos(costs.tail_ns(pairs_left, records));
            clock.move_stop(deadline.checked_sub(tail).unwrap_or_else(Instant::now));
        }
    }

    /// The time left for the frame's work from now, nanoseconds (`None` without a
    /// deadline).
    fn left_ns(&self) -> Option<u64> {
        self.deadline.map(|d| {
            let left = d.saturating_duration_since(Instant::now());
            u64::try_from(left.as_nanos()).unwrap_or(u64::MAX)
        })
    }

    /// Drops the candidates (current ones kept first, then swept ones) whose conservative
    /// answers and records alone would not fit the time left ([`FrameCosts::pairs_that_fit`]),
    /// keeping at least [`MIN_ANSWERED_PAIRS`]; returns how many it dropped. The frame then
    /// answers a sample of its pairs, and says so. No effect without a deadline.
    pub(super) fn cap_to_time<T>(
        &self,
        costs: &FrameCosts,
        candidates: &mut Vec<T>,
        swept: &mut Vec<T>,
    ) -> usize {
        let Some(left) = self.left_ns() else {
            return 0;
        };
        let all = candidates.len() + swept.len();
        let fits = costs
            .pairs_that_fit(all, left)
            .max(MIN_ANSWERED_PAIRS.min(all));
        let kept = fits.min(candidates.len());
        candidates.truncate(kept);
        swept.truncate(fits - kept);
        all - fits
    }

    /// Whether this frame may use the worker pool at all: never under a limited budget
    /// (the frontier runs on one thread) nor in a slice (the pool's pairs are not polled).
    pub(super) fn allows_pool(&self) -> bool {
        !self.limited && self.slice.is_none()
    }

    /// Whether a frame with these pairs to answer on the pool (each its [`PoolWork`]) uses
    /// the worker pool: when [`allows_pool`](Self::allows_pool), and only with at least
    /// [`MIN_PARALLEL_MESH_PAIRS`] mesh pairs or [`MIN_PARALLEL_WALKS`] walks, a mesh pair
    /// counting as `MIN_PARALLEL_WALKS / MIN_PARALLEL_MESH_PAIRS` walks.
    pub(super) fn wants_pool(&self, mut needed: impl Iterator<Item = PoolWork>) -> bool {
        const MESH_PAIR_WALKS: usize = MIN_PARALLEL_WALKS / MIN_PARALLEL_MESH_PAIRS;
        let mut walks = 0;
        self.allows_pool()
            && needed.any(|work| {
                walks += match work {
                    PoolWork::MeshPair => MESH_PAIR_WALKS,
                    PoolWork::Walk => 1,
                };
                walks >= MIN_PARALLEL_WALKS
            })
    }

    /// The route of a pair of shapes `sa`, `sb` (`separated` when a kept separation or the
    /// hulls proved it apart). Polls the frame's `clock` only for pairs it may cut short.
    pub(super) fn pair<'s>(
        &self,
        sa: &'s Shape,
        sb: &'s Shape,
        separated: bool,
        clock: &mut WorkClock,
    ) -> PairPlan<'s> {
        match dispatch::route(sa, sb) {
            _ if separated => PairPlan::Separated,
            Route::Direct if self.pool && pool_work(sa, sb).is_some() => PairPlan::PooledWalk,
            Route::Direct
                if !dispatch::exact_costs_no_more_than_boxes(sa, sb)
                    && !clock.allows(pair_work(sa, sb)) =>
            {
                PairPlan::Conservative
            }
            Route::Direct => PairPlan::Direct,
            Route::MeshMesh(ma, mb) if self.limited => PairPlan::Frontier(ma, mb),
            Route::MeshMesh(..) if self.pool => PairPlan::Pooled,
            // An exact mesh search starts only while the frame is not abandoned and its
            // slice, if any, lasts (then its proximity, overlap and distance searches and
            // its contacts poll the clock leaf pair by leaf pair).
            Route::MeshMesh(..) if !clock.allows(WORK_PER_CLOCK_READ) => PairPlan::Conservative,
            Route::MeshMesh(ma, mb) => PairPlan::MeshMesh(ma, mb),
        }
    }
}

/// What answering a pair costs the worker pool, for the pairs it takes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PoolWork {
    /// Mesh–mesh: the tandem searches.
    MeshPair,
    /// A convex shape or a compound against a mesh or a compound: one walk of a tree
    /// (every part pair of a compound).
    Walk,
}

/// The pool's work for a pair of shapes `sa`, `sb`; `None` for the pairs answered on the
/// calling thread (closed forms, GJK/EPA between convex shapes: cheaper than a job).
pub(super) fn pool_work(sa: &Shape, sb: &Shape) -> Option<PoolWork> {
    use Shape::{Compound as K, Mesh as M};
    match (sa, sb) {
        (M(_), M(_)) => Some(PoolWork::MeshPair),
        (M(_) | K(_), _) | (_, M(_) | K(_)) => Some(PoolWork::Walk),
        _ => None,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cold_frame_keeps_a_quarter_of_its_time_left_in_reserve() {
        let now = Instant::now();
        let deadline = now + Duration::from_millis(400);
        assert_eq!(
            cold_deadline(deadline, now),
            now + Duration::from_millis(300)
        );
        // Past its deadline, the reserve moves nothing.
        assert_eq!(cold_deadline(now, deadline), now);
        // The plan applies it to cold frames with a deadline only.
        let far = now + Duration::from_secs(3600);
        let budget = Deadline(far);
        let warm = FramePlan::new(&budget, Query::CLOSE, None, false);
        assert_eq!(warm.deadline(), Some(far), "a warm frame works to it");
        let cold = FramePlan::new(&budget, Query::CLOSE, None, true);
        let kept = cold.deadline().expect("a deadline");
        // Planned a little after `now`: a little less time left, a little less kept back.
        assert!(
            cold_deadline(far, now) <= kept && kept < far - Duration::from_secs(800),
            "{kept:?}"
        );
        let unlimited = FramePlan::new(&Unlimited, Query::CLOSE, None, true);
        assert_eq!(unlimited.deadline(), None, "no deadline, nothing kept back");
    }

    #[test]
    fn the_frontier_clock_reserves_the_waiting_entries_time_before_its_deadline() {
        let mut clock = FrontierClock {
            deadline: Deadline(Instant::now() + Duration::from_millis(50)),
            ps_per_pending_entry: 1_000_000,
            abandon: Abandon::default(),
        };
        assert!(clock.allows(0) && clock.allows_pending(0, 0));
        assert!(clock.allows_pending(0, 1_000), "1 ms of entries fits in 50");
        assert!(
            !clock.allows_pending(0, 60_000),
            "60 ms of entries does not"
        );
        assert!(!clock.allows_pending(0, u64::MAX), "no overflow");
        assert_eq!(clock.deadline(), Some(clock.deadline.0));
        let mut past = FrontierClock {
            deadline: Deadline(Instant::now()),
            ps_per_pending_entry: 0,
            abandon: Abandon::default(),
        };
        assert!(!past.allows_pending(0, 0) && !past.allows(0));
        let abandoned = FrontierClock {
            abandon: Abandon::new(),
            ..clock
        };
        let mut abandoned_clock = abandoned.clone();
        assert!(abandoned_clock.allows(0) && abandoned_clock.allows_pending(0, 0));
        abandoned.abandon.raise();
        assert!(!abandoned_clock.allows(0) && !abandoned_clock.allows_pending(0, 0));
    }

    #[test]
    fn the_frontier_deadline_leaves_the_tail_and_the_reserve_or_a_quarter_of_the_rest() {
        let now = Instant::now();
        let none = Duration::ZERO;
        let frame = now + Duration::from_millis(2);
        assert_eq!(
            frontier_deadline(now, frame, none).0 + FRONTIER_RESERVE,
            frame
        );
        let tail = Duration::from_micros(50);
        assert_eq!(
            frontier_deadline(now, frame, tail).0 + FRONTIER_RESERVE + tail,
            frame
        );
        let small = now + Duration::from_micros(200);
        assert_eq!(
            frontier_deadline(now, small, none).0,
            now + Duration::from_micros(150)
        );
        // 200 µs, 40 of them the tail: a quarter of the other 160 more.
        assert_eq!(
            frontier_deadline(now, small, Duration::from_micros(40)).0,
            now + Duration::from_micros(120)
        );
        // A tail longer than the frame leaves the frontier nothing.
        let long = Duration::from_micros(300);
        assert!(frontier_deadline(now, small, long).0 <= now);
        // A deadline already past (before the frame started) stays where it is.
        let past = now.checked_sub(Duration::from_micros(10)).unwrap_or(now);
        assert_eq!(frontier_deadline(now, past, none).0, past);
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
