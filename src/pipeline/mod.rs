//! One frame of collision work over a scene, in the order of its stages
//! ([`step_within`]; [`step`] is the unlimited budget):
//!
//! 1. **broad phase** (`broad_sync.rs`): the kept broad phase synced with the scene's change
//!    log gives the candidate pairs; the swept boxes give the `TOI` candidates;
//! 2. **plan** (`plan.rs`): the budget split (the frontier's deadline, the reserve for the
//!    rest) and, per pair, which route answers it;
//! 3. **mid phase**: kept separations and the meshes' hulls prove mesh pairs apart with no
//!    traversal (`separation.rs`); under a limited budget the frontier refines the rest
//!    (`frontier_run.rs`);
//! 4. **narrow phase** (`pair_loop.rs`; the answers in `answer.rs`, on the worker pool for
//!    many mesh pairs or tree walks on an unbudgeted frame, `workers.rs`, and by the pool's
//!    helper thread for many convex pairs to answer afresh, `helper.rs`): each
//!    candidate's answer by its route, or its kept answer;
//! 5. **time of impact** (`toi.rs`);
//!
//! and, across frames, what each pair remembers (`pair_memory.rs`). What each [`Query`] flag
//! reports, and the contacts of each pair kind, is on [`Query`].
//!
//! # Answers kept between frames
//! A candidate pair whose two bodies did not change since it was last answered (same
//! [`Body::version`](crate::scene::Body::version)s, same scene, same query) gets that
//! answer again, contacts included, without running any query: resting bodies cost only
//! the broad phase. The frame is identical to one that answers them afresh (tested). Only
//! exact answers are kept; [`StepReport::reused_pairs`] counts them.
//!
//! # Separations kept between frames
//! A mesh–mesh pair found farther apart than its margins leaves a separation behind
//! (`separation.rs`): a lower bound of its distance, proved by the search that found it
//! apart (the tolerance query's dropped node pairs and tested triangles, or the frontier's),
//! and the pair's relative pose then. While no query asks the distance, a later frame
//! answers that pair "apart" with no traversal as long as the bound, less how far the
//! relative motion since could have moved any point of one body relative to the other,
//! still exceeds the margins: the exact answer, so such frames equal traversed ones (up to
//! the witnesses of tied minima, whose warm starts differ; tested). Pairs that moved more
//! are searched again, and leave a new separation when found apart. Under a budget they
//! are taken off the frontier. [`StepReport::separated_pairs`] counts them.

//! # Separations proved by the hulls
//! A mesh–mesh pair with no kept separation is first tested by its meshes' convex hulls
//! ([`MeshHull::gap`](crate::narrow::mesh_hull::MeshHull::gap): GJK between the hulls,
//! then the slab between them as the proof): hulls apart by more than the margins prove
//! the meshes apart, and leave a separation like any other proof. A pair whose hulls meet
//! is remembered with its relative pose and not tested again at that pose (a resting pair,
//! a resumed frontier). Under a limited budget the tests spend the frontier's budget, one
//! visit each, polled every second test: a budget of nothing tests nothing.
//! [`StepReport::hull_tests`] counts them, `separated_pairs` the pairs they and the kept
//! separations answered.

//! # Design note: determinism and ordering
//! The same scene and query give the same results: the broad phase yields pairs sorted by
//! `(a, b)`, each pair is answered independently in that order, and nothing depends on
//! timing (only [`StepReport`]'s timings do). Under a budget ([`step_within`]) the answers
//! also depend on how much of it the frame had: the same for the same counted budget (and
//! the same workspace history, since a resting scene's frontier resumes), never worse with
//! more.
//!
//! # What is exact
//! Every pair of shape kinds has an exact narrow phase (`dispatch.rs`; meshes as surfaces:
//! intersecting meshes report 0). The conservative answer DESIGN §5 prescribes for a
//! traversal truncated at level 0 (the distance between the two world boxes, a lower bound,
//! with the boxes' diagonals as error bound, "may touch" when the boxes touch, and the
//! report saying [`Completeness::Truncated`]) is given only under a budget, to a pair of
//! convex shapes whose turn comes after the deadline, and when the worker pool fails to
//! answer a pair; a mesh pair cut short gets the frontier's tighter bounds instead.
//!
//! # Allocation
//! None once the workspace and the output have grown to the largest frame, except one
//! pair-memory record when a pair first becomes a candidate, and the kept broad phase's
//! own: a rebuild (or an `Auto` measurement) allocates it anew, and the stateful
//! kinds' pair sets and hash cells allocate as pairs and occupied cells appear.

mod answer;
mod broad_sync;
mod costs;
mod frontier_run;
mod helper;
mod pair_loop;
mod pair_memory;
mod plan;
mod separation;
mod toi;
pub mod workers;

pub use crate::budget::{Abandon, Budget};
pub use crate::narrow::dispatch::PathCounts;
pub use costs::FrameCosts;
use pair_loop::answer_candidates;
pub use plan::{
    COLD_RESERVE, Deadline, FRONTIER_RESERVE, FrontierClock, MIN_ANSWERED_PAIRS, Unlimited,
    VisitBudget, frontier_deadline,
};
use plan::{FramePlan, PoolWork, mandatory_work_fits};
pub use toi::{PairToi, TOI_TOLERANCE};

use crate::broad::{BroadPhaseKind, BroadPhaseStats, CandidatePair};
use crate::math::DVec3;
use crate::narrow::MeshShape;
use crate::narrow::Shape;
use crate::narrow::contact::Manifold;
use crate::narrow::dispatch::{self, NarrowScratch, Route};
use crate::narrow::mesh_mesh::DistanceCache;
use crate::narrow::mesh_mesh::frontier::{FrontierAnswer, FrontierStats, FrontierWorkspace};
use crate::scene::{Body, BodyId, Scene};
use answer::{Answer, MeshScratch};
pub use broad_sync::AUTO_REMEASURE_FRAMES;
use broad_sync::BroadSync;
use frontier_run::{FrontierRun, run_frontier};
use pair_memory::PairMemories;
use separation::mark_separated;
use std::sync::Arc;
use std::time::{Duration, Instant};
use toi::answer_tois;
use workers::{JobScratch, PairJob, PairOutcome};
pub use workers::{MIN_PARALLEL_MESH_PAIRS, MIN_PARALLEL_WALKS, WorkerPool};

/// What a frame asks for; at least one flag should be set, or the frame reports nothing.
///
/// # What a query asks (DESIGN §4)
/// The broad phase yields *candidate pairs*: bodies whose world boxes, grown by their
/// margins, overlap (never static–static, filtered by group/mask). Each flag selects pairs
/// among them; the frame reports the union, once per pair, in `(a, b)` order:
///
/// | flag | pairs reported | what it costs for meshes |
/// |---|---|---|
/// | [`Query::close`] | distance ≤ the sum of the two margins; signed distance, witnesses, normal A→B | exact distance |
/// | [`Query::overlap`] | the shapes touch or intersect (distance ≤ 0) | [`intersects_mesh_mesh`](crate::narrow::mesh_mesh::intersects_mesh_mesh), stops at the first proof |
/// | [`Query::distance`] | every candidate pair, also beyond the margins, with its exact signed distance | exact distance |
/// | [`Query::contacts`] | touching pairs, each with its manifold ([`ContactPoint`]s, at most [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS)) | every intersecting triangle pair ([`contacts_mesh_mesh`](crate::narrow::mesh_mesh::contacts_mesh_mesh)), then [`reduce_manifold`](crate::narrow::reduce_manifold) |
/// | [`Query::toi`] | pairs that come within their margins during the frame's motion, each with its time of impact ([`PairToi`], in [`FrameResults::tois`]) | exact distance per conservative-advancement step |
///
/// Flags combine: `CLOSE | CONTACTS` reports the close pairs, and the touching ones among
/// them carry contacts. `OVERLAP` adds nothing to `CLOSE` or `DISTANCE` (their records
/// already say it: distance ≤ 0). A pair record always has `a`, `b`, `distance`,
/// `error_bound`; when neither `CLOSE` nor `DISTANCE` is asked, a mesh pair's record says
/// distance 0 (intersecting surfaces) and takes its witnesses and normal from its first
/// contact, or, with `OVERLAP` alone, has none: points and normal all zero (a zero normal
/// means "not computed"). Sphere–sphere records are always complete (closed form).
///
/// Contacts per pair kind:
/// - sphere–sphere: one point, the witnesses, `distance = −depth`;
/// - mesh–mesh: the ends of every intersection segment of the two surfaces, reduced by
///   [`reduce_manifold`](crate::narrow::reduce_manifold) to the extremes, each with `point_a == point_b` and depth 0 (meshes
///   are surfaces: intersecting meshes touch along curves and have no inside to measure a
///   depth in). One normal for the manifold: the sum of the intersecting triangles' normals
///   on A (A→B), one per segment end, normalised (when they cancel exactly, the normal at
///   the first kept point);
/// - box-answer pairs: one conservative point, the box witnesses and normal, distance 0
///   (depth unknown) with the box error bound, which covers the true depth.
///
/// [`PairResult::first_contact`] and [`PairResult::contact_count`] locate a pair's contacts
/// in [`FrameResults::contacts`]; each [`ContactPoint::pair`] names its pair back.
///
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Query {
    /// Pairs whose shapes touch or intersect.
    pub overlap: bool,
    /// Pairs within the sum of their margins, with signed distance and witnesses.
    pub close: bool,
    /// Every candidate pair's exact signed distance.
    pub distance: bool,
    /// Contact manifolds of touching pairs.
    pub contacts: bool,
    /// Time of impact over the frame's motion (see the [module docs](self)).
    pub toi: bool,
}

impl Query {
    /// Nothing asked.
    pub const NONE: Self = Self {
        overlap: false,
        close: false,
        distance: false,
        contacts: false,
        toi: false,
    };
    /// Only `overlap`.
    pub const OVERLAP: Self = Self {
        overlap: true,
        ..Self::NONE
    };
    /// Only `close`.
    pub const CLOSE: Self = Self {
        close: true,
        ..Self::NONE
    };
    /// Only `distance`.
    pub const DISTANCE: Self = Self {
        distance: true,
        ..Self::NONE
    };
    /// Only `contacts`.
    pub const CONTACTS: Self = Self {
        contacts: true,
        ..Self::NONE
    };
    /// Only `toi`.
    pub const TOI: Self = Self {
        toi: true,
        ..Self::NONE
    };

    /// Both queries' flags.
    #[must_use]
    pub const fn union(self, other: Self) -> Self {
        Self {
            overlap: self.overlap || other.overlap,
            close: self.close || other.close,
            distance: self.distance || other.distance,
            contacts: self.contacts || other.contacts,
            toi: self.toi || other.toi,
        }
    }

    /// Whether any flag answered at the current poses (all but `toi`) is set.
    const fn at_current_poses(self) -> bool {
        self.overlap || self.close || self.distance || self.contacts
    }

    /// Whether a pair with this answer and these margins is reported.
    fn reports(self, answer: &Answer, margins: f64) -> bool {
        // A box answer's distance is a lower bound and its `touching` a "may touch": the
        // pair is reported whenever the truth may qualify (conservative).
        self.distance
            || (self.close && answer.result.distance <= margins)
            || ((self.overlap || self.contacts) && answer.touching)
    }
}

/// The answer for one reported pair, world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairResult {
    /// The smaller body id.
    pub a: u32,
    /// The larger body id.
    pub b: u32,
    /// Signed distance, metres (negative = penetration).
    pub distance: f64,
    /// `|distance − true distance| ≤ error_bound`, metres.
    pub error_bound: f64,
    /// Witness on A, world frame (zero when not computed, see the module docs).
    pub point_a: DVec3,
    /// Witness on B, world frame (zero when not computed).
    pub point_b: DVec3,
    /// Unit normal from A to B, world frame (zero when not computed).
    pub normal: DVec3,
    /// Whether the answer is exact (to `error_bound` rounding) or the conservative box answer.
    pub exact: bool,
    /// Index of the pair's first contact in [`FrameResults::contacts`] (0 when none).
    pub first_contact: u32,
    /// Number of the pair's contacts, at most [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS).
    pub contact_count: u32,
}

/// One point of a pair's contact manifold, world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Index of its pair in [`FrameResults::pairs`].
    pub pair: u32,
    /// Contact point on A's surface, metres.
    pub point_a: DVec3,
    /// Contact point on B's surface, metres.
    pub point_b: DVec3,
    /// Unit normal from A to B (one per manifold).
    pub normal: DVec3,
    /// `−depth`, metres (≤ 0).
    pub distance: f64,
    /// `|distance − true distance| ≤ error_bound`, metres.
    pub error_bound: f64,
}

/// The reported pairs, their contacts and times of impact, reused across frames (cleared
/// by [`step`]).
#[derive(Debug, Default)]
pub struct FrameResults {
    /// Reported pairs in `(a, b)` order.
    pub pairs: Vec<PairResult>,
    /// Every reported pair's contacts, in pair order.
    pub contacts: Vec<ContactPoint>,
    /// With [`Query::toi`]: the pairs that come within contact during the frame's motion,
    /// in `(a, b)` order.
    pub tois: Vec<PairToi>,
}

impl FrameResults {
    /// Records written so far: pairs, contacts and times of impact.
    #[must_use]
    pub fn record_count(&self) -> usize {
        self.pairs.len() + self.contacts.len() + self.tois.len()
    }
}

/// Whether a frame's answers are all exact: `Truncated` at the shallowest level any pair
/// stopped at (0 = world boxes) when some pairs carry a conservative answer.
pub use crate::budget::Completeness;

/// What [`step`] did: completeness, stage timings, counts.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StepReport {
    /// Whether every answer is exact.
    pub completeness: Completeness,
    /// Broad phase (proxies and candidate pairs; with `toi` also the swept ones),
    /// nanoseconds.
    pub broad_ns: u64,
    /// Narrow phase (every candidate's answer and manifold, and time of impact),
    /// nanoseconds.
    pub narrow_ns: u64,
    /// Candidate pairs from the broad phase over the current boxes (0 when only `toi` is
    /// asked).
    pub candidates: u32,
    /// With `toi`: candidate pairs from the broad phase over the swept boxes (a superset of
    /// `candidates`), else 0.
    pub toi_candidates: u32,
    /// Time-of-impact records (`results.tois.len()`).
    pub tois: u32,
    /// Reported pairs (`results.pairs.len()`).
    pub pairs: u32,
    /// Contact points (`results.contacts.len()`).
    pub contacts: u32,
    /// The broad phase that found `candidates`; `None` when only `toi` was asked (the kept
    /// broad phase did not run).
    pub broad_kind: Option<BroadPhaseKind>,
    /// Bodies the kept broad phase re-read this frame: those in the scene's change log, or
    /// every body when it was rebuilt (see the [module docs](self)); 0 when it did not run.
    pub broad_updates: u32,
    /// With [`BroadPhaseChoice::Auto`](crate::broad::BroadPhaseChoice::Auto), the statistics measured this frame, from which
    /// [`choose`](crate::broad::choose) picked `broad_kind`; `None` on frames that kept the last pick.
    pub broad_stats: Option<BroadPhaseStats>,
    /// Narrow-phase queries by path: which stages the frame entered (a scene of spheres
    /// and capsules never enters BVH or EPA code: `paths.bvh() == 0`, `paths.epa == 0`).
    /// Reused answers (`reused_pairs`) take no path.
    pub paths: PathCounts,
    /// Candidate pairs answered by last frame's answer, neither body having changed (see
    /// the [module docs](self)).
    pub reused_pairs: u32,
    /// Candidate pairs the pool's helper thread answered on the other core (a budgeted or
    /// unbudgeted frame with many convex pairs to answer afresh: `helper.rs`).
    pub helped_pairs: u32,
    /// Mesh–mesh candidate pairs answered "apart" with no traversal: by a separation an
    /// earlier frame proved, their relative motion since being smaller than its slack, or
    /// by their convex hulls this frame (see the [module docs](self)); they take no path
    /// and no frontier visit.
    pub separated_pairs: u32,
    /// Hull tests run this frame (mesh–mesh pairs with no kept separation; under a limited
    /// budget, each spends one of the frontier's visits).
    pub hull_tests: u32,
    /// The budgeted frontier with the hull tests before it ([`step_within`] with a
    /// limited budget), nanoseconds; 0 when it did not run (unbudgeted, the hull tests are
    /// part of `narrow_ns`). Not part of `narrow_ns`.
    pub mid_ns: u64,
    /// The frontier's counters of this frame (visits, rounds begun, bound and triangle
    /// tests, polls; a resumed frontier counts only this frame's share); all 0 when it did
    /// not run.
    pub frontier: FrontierStats,
    /// Mesh–mesh pairs the frontier left unfinished: answered conservatively (see
    /// [`step_within`]); 0 when it did not run.
    pub truncated_pairs: u32,
    /// Time-of-impact candidates the frame's deadline came before, answered by the start
    /// boxes ([`PairToi::exact`] `false`); a search the deadline stopped is not counted
    /// here (it reports `reached = false`) but makes the frame truncated too.
    pub truncated_tois: u32,
    /// Candidate pairs (and swept candidates) the broad phase found beyond the scene's
    /// [`SceneLimits::max_pairs_per_frame`](crate::scene::SceneLimits::max_pairs_per_frame),
    /// or beyond what the frame's deadline leaves time to answer even conservatively
    /// ([`FrameCosts::pairs_that_fit`], at least [`MIN_ANSWERED_PAIRS`]), not answered this
    /// frame: the frame's pairs are then a sample, and a pair left out may touch.
    pub dropped_candidates: u32,
    /// Set when the frame was not started: its budget could not hold the scene's
    /// uninterruptible work (the broad phase and publishing, [`FrameCosts`]), whose
    /// measured nanoseconds this is. The frame answers nothing and is `Truncated` at level
    /// 0; a budget of at least this (plus ingest) lets the next frames run.
    pub budget_too_small: Option<u64>,
}

/// State of [`step`] kept across frames: scratch space (no allocation once grown), the
/// broad phase's order, the warm-start cache of every mesh–mesh pair that was a candidate
/// last frame, and the worker pool when there is one.
#[derive(Debug, Default)]
pub struct PipelineWorkspace {
    /// The broad phases kept in sync with the scene (`broad_sync.rs`).
    broad: BroadSync,
    candidates: Vec<CandidatePair>,
    /// This thread's mesh–mesh scratch.
    mesh: MeshScratch,
    /// What each candidate pair keeps between frames (`pair_memory.rs`).
    memory: PairMemories,
    /// Per candidate (same index): whether a kept separation answers it this frame.
    separated: Vec<bool>,
    /// Answers a frame's mesh–mesh pairs and tree walks in parallel (see [`workers`]).
    workers: Option<Arc<WorkerPool>>,
    /// The pairs for the pool this frame (candidate slot and work), found once.
    pool_slots: Vec<(u32, PoolWork)>,
    /// The pool's answers of this frame, by candidate slot.
    outcomes: Vec<PairOutcome>,
    /// Scratch of the pool's jobs this thread answers.
    job_scratch: JobScratch,
    /// The dispatcher's scratch (GJK/EPA, convex–mesh traversal).
    narrow: NarrowScratch,
    /// One pair's manifold, before it joins the frame's contacts.
    manifold: Manifold,
    /// Candidate pairs of the swept boxes.
    toi_candidates: Vec<CandidatePair>,
    /// The budgeted frontier's state (frames with a limited budget).
    frontier: FrontierWorkspace,
    /// The frontier's answers of this frame, in candidate order of its pairs.
    frontier_answers: Vec<FrontierAnswer>,
    /// The candidate pairs the frontier answered this frame, in its order.
    frontier_pairs: Vec<CandidatePair>,
    /// What the frontier last ran over, to resume it next frame.
    frontier_run: FrontierRun,
    /// The scene's uninterruptible stages, measured (the daemon adds its publishing).
    costs: FrameCosts,
    /// Raised to abandon the frame's work at its next poll ([`Self::abandon_on`]).
    abandon: Abandon,
    /// The end of an unlimited frame's slice, during [`step_sliced`].
    slice: Option<Instant>,
    /// Candidates the last frame answered afresh (neither kept nor proven apart): whether
    /// this one is worth the pool's helper ([`helper::MIN_HELPED_PAIRS`]).
    fresh_last_frame: usize,
}

impl PipelineWorkspace {
    /// Starts a frame: `results` emptied, the dispatcher's counters reset, and the pairs'
    /// memory stamping the pairs this frame visits.
    fn begin_frame(&mut self, results: &mut FrameResults) {
        self.memory.begin_frame();
        results.pairs.clear();
        results.contacts.clear();
        results.tois.clear();
        self.narrow.paths = PathCounts::default();
    }

    /// Records how long the caller took to write and publish a frame's results of
    /// `records` records (pairs, contacts, times of impact), nanoseconds: part of the work
    /// a frame of this scene cannot skip ([`FrameCosts`]).
    pub fn note_publish(&mut self, ns: u64, records: u64) {
        self.costs.note_publish(ns, records);
    }

    /// This workspace for a caller that publishes every frame's results and tells how long
    /// that took ([`note_publish`](Self::note_publish)), as the daemon does: until it
    /// has, each budgeted frame reserves a cold publish ([`FrameCosts::publishing`]).
    #[must_use]
    pub fn publishing(mut self) -> Self {
        self.costs = FrameCosts::publishing();
        self
    }

    /// A workspace that answers mesh–mesh pairs and tree walks on `workers` too (when a
    /// frame has at least [`MIN_PARALLEL_MESH_PAIRS`] mesh pairs or [`MIN_PARALLEL_WALKS`]
    /// walks). Results are identical with or without.
    #[must_use]
    pub fn with_workers(workers: Arc<WorkerPool>) -> Self {
        Self {
            workers: Some(workers),
            ..Self::default()
        }
    }

    /// This workspace with every frame's work stopped at its next poll once `abandon` is
    /// raised (the daemon raises a scene's when its owner is gone): the frontier, the pair
    /// loop, the narrow routes' long steps, the pool's mesh pairs and time of impact, as if
    /// the deadline had come, with conservative answers marked `Truncated`; an unlimited
    /// frame then is not exact. What no poll interrupts (the broad phase, the work between
    /// two polls) runs to its end.
    #[must_use]
    pub fn abandon_on(mut self, abandon: Abandon) -> Self {
        self.abandon = abandon;
        self
    }

    /// This workspace with its budgeted frontier polling the budget once at least `visits`
    /// (`≥ 1`) visits were made since the last poll (default
    /// [`DEFAULT_POLL_EVERY`](crate::narrow::mesh_mesh::frontier::DEFAULT_POLL_EVERY)); 1 lets tests stop
    /// it at every interruption point.
    #[must_use]
    pub fn with_frontier_poll_every(mut self, visits: u64) -> Self {
        self.frontier = FrontierWorkspace::with_poll_every(visits);
        self
    }

    /// This workspace with its budgeted frontier processing its entries in `order` (the
    /// default, stages by width, is what the pipeline is meant to run; the others are the
    /// baselines `examples/time_vs_error --order` measures it against).
    #[must_use]
    pub fn with_frontier_order(
        mut self,
        order: crate::narrow::mesh_mesh::frontier::RoundOrder,
    ) -> Self {
        self.frontier = std::mem::take(&mut self.frontier).with_order(order);
        self
    }
}

/// Runs one frame over `scene`: the pairs `query` asks for (see the [module docs](self)),
/// with their contacts, written to `results` (cleared first). Every answer exact: this is
/// [`step_within`] with an [`Unlimited`] budget.
pub fn step(
    scene: &Scene,
    query: Query,
    workspace: &mut PipelineWorkspace,
    results: &mut FrameResults,
) -> StepReport {
    step_within(scene, query, &mut Unlimited, workspace, results)
}

/// [`step`], stopped at `slice_end` if it is not done by then: the daemon's first try of a
/// frame without a deadline, on its frame thread, before it hands a frame that takes
/// longer to a thread of its own. Returns `None` when the slice ended first: the results
/// are then incomplete and must not be used; the scene is untouched and `workspace` still
/// valid, so [`step`] run next over the same scene gives the exact answers (faster, by
/// what the slice kept). Otherwise exactly [`step`]'s report and results. The worker pool
/// is not used; a mesh pair's exact search stops at the slice's end too (it polls the
/// frame's clock leaf pair by leaf pair).
pub fn step_sliced(
    scene: &Scene,
    query: Query,
    slice_end: Instant,
    workspace: &mut PipelineWorkspace,
    results: &mut FrameResults,
) -> Option<StepReport> {
    workspace.slice = Some(slice_end);
    let report = step(scene, query, workspace, results);
    workspace.slice = None;
    // An unlimited frame is truncated only by its slice, or when it was abandoned (then the
    // conservative answers are the frame's answers).
    let sliced_out = matches!(report.completeness, Completeness::Truncated { .. })
        && !workspace.abandon.is_raised();
    (!sliced_out).then_some(report)
}

/// [`step`] under a budget (DESIGN §5): the frame's mesh–mesh pairs are answered through
/// one budgeted breadth-first frontier ([`frontier`](crate::narrow::mesh_mesh::frontier)) over all of them, and those it could
/// not finish get conservative answers.
///
/// # With an unlimited budget
/// ([`Budget::is_unlimited`]): exactly [`step`]'s answers, by the same exact per-pair
/// queries (warm-started, on the worker pool when there is one).
///
/// # With a limited budget
/// Before the per-pair loop, every mesh–mesh candidate pair not answered by a kept answer
/// or a kept separation joins one frontier run, refined with the trees its meshes chose
/// ([`QueryVolume::for_pair`](crate::narrow::QueryVolume::for_pair): OBBs for box-like
/// parts, RSSs for curved ones), with
/// threshold the pair's margin sum (`CLOSE`, `OVERLAP`,
/// `CONTACTS`) or, when `DISTANCE` is asked, an upper bound of the pair's distance: the
/// distance of one triangle pair (the closest a previous budgeted frame found for it, else
/// the first triangles; one triangle test outside the budget). The frontier then prunes
/// with that bound and each pair's best distance so far, and gives the exact distance when
/// it finishes. (With a threshold of `+∞` instead, breadth-first order finds no distance
/// before the leaves and descends every node pair: about 1.5× the visits on the test
/// piles, and still about 50× those of `CLOSE`: `DISTANCE` is the costly query under a
/// budget.) The frontier runs on the calling thread under `budget`; a [`Deadline`] is
/// moved earlier ([`frontier_deadline`]) by the frame's tail (below) and by
/// [`FRONTIER_RESERVE`] or a quarter of the rest, to leave time for the rest of the frame.
///
/// When last frame's frontier was cut short and every one of its pairs is still a
/// candidate with both bodies unchanged (same scene, same query), it *resumes* where it
/// stopped instead of starting over: a pair too costly for one frame's budget is refined
/// frame after frame while its bodies rest, and reaches its exact answer after as many
/// visits as one unlimited run. Then, per pair:
/// - a pair the frontier finished gets the exact record (distance, witnesses, normal from
///   the witnesses, as [`step`] gives; only the witnesses may name another triangle pair
///   at the same distance) and, when `CONTACTS` is asked and it touches, the exact
///   mesh–mesh contacts;
/// - a pair it left unfinished may qualify: it is reported by the usual rule with
///   `distance` the frontier's lower bound (never above the true distance), its error
///   bound (`true ≤ distance + error_bound`), `exact = false`, "may touch" when that
///   bound is `≤ 0` (with one conservative contact point when `CONTACTS` is asked, as the
///   box answers give), and the frame is [`Completeness::Truncated`] at the shallowest
///   level of any such pair. No pair that qualifies is ever left out.
///
/// Only exact answers are kept for reuse ([`PipelineWorkspace`]): a truncated pair is
/// refined again next frame. [`StepReport`] carries the frontier's counters
/// ([`StepReport::frontier`], [`StepReport::truncated_pairs`]) and time
/// ([`StepReport::mid_ns`]).
///
/// The pairs outside the frontier (closed forms, GJK/EPA, convex–mesh walks) keep to a
/// wall-clock deadline too: once it is within the frame's *tail* (the conservative answers
/// of the pairs left and the publishing of every record, by the scene's measured
/// [`FrameCosts::tail_ns`], re-estimated before each pair; the clock is read every few
/// pairs), each remaining one gets a conservative answer (level 0), counted in
/// [`StepReport::truncated_pairs`]: capsules and cuboids among themselves their
/// [`DistanceBound`](crate::narrow::contact::DistanceBound)s (exact distances where the
/// separating axes find them apart within their margins, a lower bound from the axes
/// beyond them, exact depth where the cores overlap; tens to hundreds of nanoseconds), the
/// others their margin-grown world boxes' answer (distance between the boxes, their
/// diagonals as error bound, "may touch" when they touch). A sphere against a
/// sphere, capsule or cuboid stays exact: its closed form costs no more than a box answer.
/// A pair already started keeps to the same clock inside its query
/// ([`NarrowScratch::clock`](crate::narrow::dispatch::NarrowScratch::clock)): a convex
/// shape's walk of a mesh and EPA stop there with bounds on the distance
/// ([`Reached::Bounded`](crate::narrow::Reached)), answered as the separating-axis bounds
/// are, and so do the exact contacts of touching mesh pairs. Counted budgets leave them
/// exact. A frame with more candidates than even their conservative answers fit in the
/// time left after the broad phase ([`FrameCosts::pairs_that_fit`]) answers the first
/// that fit, counted in [`StepReport::dropped_candidates`]. A frame of a scene whose costs
/// are not measured yet (its first) runs cold and keeps [`COLD_RESERVE`] of its time
/// left in reserve. Not yet budgeted: the broad
/// phase and time of impact's single distance queries run to completion whatever the
/// budget. The worker pool is not used for a budgeted frontier (one thread).
///
/// # Allocation
/// As [`step`], plus, with a limited budget, one list of the frame's frontier pairs (it
/// borrows the scene's trees) and one seed entry when a mesh pair first gets a witness.
pub fn step_within(
    scene: &Scene,
    query: Query,
    budget: &mut dyn Budget,
    workspace: &mut PipelineWorkspace,
    results: &mut FrameResults,
) -> StepReport {
    let started = Instant::now();
    workspace.begin_frame(results);
    let bodies = scene.body_count();
    if let Err(needed) = mandatory_work_fits(&*budget, query, &workspace.costs, bodies) {
        workspace.costs.note_skipped();
        return StepReport {
            completeness: Completeness::Truncated { level: 0 },
            budget_too_small: Some(needed),
            ..StepReport::default()
        };
    }
    // A new broad phase is built only when it takes at most half the time left.
    let room = budget
        .deadline()
        .map(|d| d.saturating_duration_since(Instant::now()) / 2);
    let broad = workspace.broad.candidates(
        scene,
        query,
        room,
        &mut workspace.candidates,
        &mut workspace.toi_candidates,
    );
    let broad_ns = elapsed_ns(started);
    if !broad.rebuilt {
        workspace.costs.note_broad(bodies, broad_ns);
    }
    let started = Instant::now();
    let cold = workspace.costs.mandatory_ns(bodies).is_none();
    let mut plan = FramePlan::new(&*budget, query, workspace.slice, cold);
    let over_time = plan.cap_to_time(
        &workspace.costs,
        &mut workspace.candidates,
        &mut workspace.toi_candidates,
    );
    workspace.narrow.clock = plan.clock(&workspace.abandon);
    let (hull_tests, frontier) = mid_phase(scene, query, budget, &plan, started, workspace);
    let mid_ns = if plan.limited { elapsed_ns(started) } else { 0 };
    // Unbudgeted, the hull tests answer pairs as the narrow phase does: its time.
    let started = if plan.limited {
        Instant::now()
    } else {
        started
    };
    plan.pool = answer_on_pool(scene, query, &plan, workspace);
    let tally = answer_candidates(scene, query, &plan, workspace, results);
    let tois = answer_tois(scene, &plan, workspace, results);
    let completeness = if tois.expired {
        tally.completeness.truncated_at(0)
    } else {
        tally.completeness
    };
    StepReport {
        completeness,
        broad_ns,
        narrow_ns: elapsed_ns(started),
        candidates: index(workspace.candidates.len()),
        toi_candidates: index(workspace.toi_candidates.len()),
        pairs: index(results.pairs.len()),
        contacts: index(results.contacts.len()),
        tois: index(results.tois.len()),
        broad_kind: broad.kind,
        broad_updates: index(broad.updates),
        broad_stats: broad.stats,
        paths: workspace.narrow.paths,
        reused_pairs: tally.reused,
        helped_pairs: tally.helped,
        separated_pairs: tally.separated,
        hull_tests: index(hull_tests as usize),
        mid_ns,
        frontier,
        truncated_pairs: tally.truncated,
        truncated_tois: tois.truncated,
        dropped_candidates: index(broad.dropped + over_time),
        budget_too_small: None,
    }
}

/// The mid phase: the hull tests and kept separations that prove mesh pairs apart
/// ([`mark_separated`]) and, under a limited budget, the frontier over the mesh pairs left
/// ([`run_frontier`]), on a deadline moved earlier by [`frontier_deadline`] so the rest of
/// the frame has time. Returns the hull tests made and the frontier's counters.
fn mid_phase(
    scene: &Scene,
    query: Query,
    budget: &mut dyn Budget,
    plan: &FramePlan,
    started: Instant,
    workspace: &mut PipelineWorkspace,
) -> (u64, FrontierStats) {
    if !plan.limited {
        let tests = mark_separated(scene, query, None, workspace);
        return (tests, FrontierStats::default());
    }
    let pairs = workspace.candidates.len() + workspace.toi_candidates.len();
    let tail = Duration::from_nanos(workspace.costs.typical_tail_ns(pairs, 0));
    let ps_per_pending_entry = workspace.costs.pending_entry_ps();
    let mut reserved = plan.deadline().map(|d| FrontierClock {
        deadline: frontier_deadline(started, d, tail),
        ps_per_pending_entry,
        abandon: workspace.abandon.clone(),
    });
    let frontier_budget: &mut dyn Budget = match reserved.as_mut() {
        Some(deadline) => deadline,
        None => budget,
    };
    // The hull tests spend the frontier's budget, a visit each: one settles a pair for the
    // price of a few visits.
    let visits_started = Instant::now();
    let tests = mark_separated(scene, query, Some(&mut *frontier_budget), workspace);
    let visited = workspace.candidates.len();
    workspace
        .costs
        .note_visits(elapsed_ns(visits_started), visited);
    let stats = run_frontier(scene, query, frontier_budget, tests, workspace);
    (tests, stats)
}

/// Answers the frame's mesh–mesh pairs and tree walks ([`plan::pool_work`]) on the worker
/// pool, into `workspace.outcomes`, when the plan lets it ([`FramePlan::wants_pool`]);
/// returns whether it did.
fn answer_on_pool(
    scene: &Scene,
    query: Query,
    plan: &FramePlan,
    workspace: &mut PipelineWorkspace,
) -> bool {
    let PipelineWorkspace {
        candidates,
        memory,
        separated,
        workers,
        pool_slots,
        outcomes,
        job_scratch,
        abandon,
        ..
    } = workspace;
    outcomes.clear();
    // A scene without a mesh or compound has no pair for the pool to look for.
    let Some(pool) = workers
        .as_ref()
        .filter(|_| scene.has_tree_shapes() && plan.allows_pool())
    else {
        return false;
    };
    // The pairs for the pool that no kept answer or separation answers: one look-up each.
    pool_slots.clear();
    pool_slots.extend(candidates.iter().enumerate().filter_map(|(slot, pair)| {
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        let work = plan::pool_work(shape(scene, a), shape(scene, b))?;
        let needed = !separated[slot] && memory.kept_answer(scene, pair, query).is_none();
        needed.then_some((index(slot), work))
    }));
    if !plan.wants_pool(pool_slots.iter().map(|&(_, work)| work)) {
        return false;
    }
    let jobs = pool_slots.iter().map(|&(slot, work)| {
        let pair = &candidates[slot as usize];
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        PairJob {
            slot,
            pair: *pair,
            a: *a,
            b: *b,
            shapes: (shape(scene, a).clone(), shape(scene, b).clone()),
            query,
            // Only a mesh pair has a warm start.
            cache: match work {
                PoolWork::MeshPair => memory.mesh_cache(pair),
                PoolWork::Walk => DistanceCache::new(),
            },
            abandon: abandon.clone(),
        }
    });
    pool.answer_all(jobs, outcomes, job_scratch);
    true
}

fn index(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

fn elapsed_ns(since: Instant) -> u64 {
    u64::try_from(since.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// The two meshes of a mesh–mesh candidate, else `None`.
fn mesh_pair<'s>(
    scene: &'s Scene,
    pair: &CandidatePair,
) -> Option<(&'s Arc<MeshShape>, &'s Arc<MeshShape>)> {
    let (a, b) = (body(scene, pair.a), body(scene, pair.b));
    match dispatch::route(shape(scene, a), shape(scene, b)) {
        Route::MeshMesh(ma, mb) => Some((ma, mb)),
        Route::Direct => None,
    }
}

fn body(scene: &Scene, id: u32) -> &Body {
    scene
        .body(BodyId(id))
        .expect("the broad phase reports live bodies")
}

fn shape<'s>(scene: &'s Scene, body: &Body) -> &'s Shape {
    scene
        .shape(body.shape)
        .expect("bodies name registered shapes")
}

#[cfg(test)]
mod tests;
