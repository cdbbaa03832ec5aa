//! The budgeted breadth-first frontier: one global list of `(pair, node of A, node of B)`
//! entries over *all* mesh pairs of a frame, refined round by round under a budget, so that
//! every pair degrades together when time runs out (DESIGN.md §5).
//!
//! # The question
//! Each [`FrontierPair`] asks: *is the distance between the triangles of `a` and of `b`
//! (placed at `pose_ab`) at most `threshold`, and if so, what is it?* The threshold is the
//! pair's margin sum, metres. The frontier sees a pair only through [`PairTrees`], so one
//! run may hold pairs of different volume types
//! ([`MeshPairTrees`](crate::pipeline::MeshPairTrees)).
//!
//! # The traversal
//! [`FrontierWorkspace::start`] puts one root entry per pair on the frontier (round 1).
//! A round takes the entries of the frontier in increasing order of their distance lower
//! bound (ties by pair index, then node of A, then node of B: deterministic), and for each
//! (unless a stage or the deciding phase sets it aside, below):
//! - a root entry, the first time, gets its own bound ([`BoundingVolume::distance_lower_bound_within`](crate::bounding::BoundingVolume::distance_lower_bound_within),
//!   one *visit*) and, when it is within the threshold and the pair has a
//!   [`FrontierPair::seed`], the seed's triangle test (one visit); then, unless the pair
//!   waits (below), a pair not yet proven close is searched by its *probe* (below);
//! - an entry whose bound exceeds `threshold` is dropped (that part is proven apart); one
//!   whose bound is not below the pair's best exact distance so far is dropped too (it
//!   cannot improve the minimum; no visit);
//! - an entry of two leaves runs [`distance_triangle_triangle`](crate::narrow::distance_triangle_triangle) on each triangle pair (one
//!   visit each), updating the pair's best exact distance and its witnesses;
//! - any other entry is replaced by its children on the side chosen by
//!   [`descend_a`](crate::bvh::tandem::descend_a): each child's bound is computed (one visit)
//!   and the child joins the *next* round unless it is dropped by the rules above. A
//!   child's bound is the larger of its own and its parent's (both bound the child's
//!   triangles), so bounds never decrease along a descent.
//!
//! So an entry carries its own tested bound (a child's is computed when it is created, not
//! when its round comes): the frontier holds only node pairs not yet proven apart, and a
//! truncated answer's lower bound is the tightest the visits made so far give. A root entry
//! stands at bound `0` until it is processed.
//!
//! # The probe
//! A pair's question has two parts: *is it within the threshold*, and *how close*. A
//! touching pair's volumes overlap all the way down, so the rounds reach a triangle pair
//! that proves it close only near the leaves, after visiting most of the overlap. The probe
//! finds one sooner: a depth-first search from the root entry, each step one entry as the
//! rounds process it (children dropped by the same rules; the child with the smaller bound
//! searched first, on a tie the one with the smaller upper bound, which for overlapping
//! volumes is the deeper overlap). It ends as soon as a triangle pair within the threshold
//! is found, or after [`PROBE_VISITS`] visits ([`EXPECTED_PROBE_VISITS`] for a pair
//! expected close, below); the entries left on its stack join the next round, so a
//! probe's visits are never lost: for a pair that is apart, they are part of the proof.
//! Steps are polled like entries, and a run stopped inside a probe resumes it.
//!
//! # Decide first
//! Only the first part changes which pairs a frame reports, so the undecided pairs are
//! settled first: while any entry of a pair not proven close is waiting (the *deciding*
//! phase), the entries of pairs proven close (a triangle pair within the threshold found)
//! wait in a list of their own, and so do the roots of pairs *expected* close: pairs that
//! came with a seed that is no longer within the threshold (the seed was last frame's
//! proof). An expected pair is still undecided, so it waits only until the stages (below)
//! reach a cap of [`EXPECTED_JOIN_CAP`]: its root then joins that stage, starting with its
//! probe. When no other entry is left, the waiting entries are refined (from the first
//! stage), an expected pair's root that has not joined starting with its probe. This
//! changes the order of work only: the answers are read from every waiting entry alike.
//!
//! A seed is worth keeping only as a proof: the pipeline keeps a pair's witnesses as its
//! next seed only when they are within its threshold, and drops it once the pair is proven
//! apart (a seed of a pair found apart would cost a triangle test every frame for
//! nothing). Measured on `examples/time_vs_error --scene robot-chain` (counted budgets, 300
//! frames, a chain of links touching each other and a room): the seeds of touching pairs
//! still held the next frame in 87–93 % of the frames, and touching pairs had taken 55–69 %
//! of every budget before; precision of the reported close pairs went 0.67 → 0.83 at 200
//! visits, 0.85 → 0.94 at 400 and 0.92 → 0.97 at 800. An earlier attempt set aside the
//! pairs proven close without the probe, while seeds were last frame's closest pair found,
//! close or not: touching pairs were then hardly ever proven close, and nothing changed.
//!
//! Where the visits go now (2026-11-24, same scene, 250 counted visits a frame, each
//! pair's answer against the exact one): 38 % to pairs proven apart, 17 % to pairs left
//! truncated that are apart (the false close pairs), 19 % to pairs proven close and 26 %
//! to pairs that are close but were not proven so. Of the 492 false close pairs (300
//! frames), 397 came with a seed that no longer held: they had been close, and waited as
//! expected close while they drew apart (9.5 visits each, against 97 for the others).
//! Taking a pair as expected close only while its seed is within `k` times the threshold
//! measured worse at small budgets (precision at 150 / 250 / 350 / 500 visits: `k` = 1,
//! 0.678 / 0.794 / 0.887 / 0.940; 2, 0.694 / 0.830 / 0.901 / 0.948; 3, 0.705 / 0.844 /
//! 0.912 / 0.948): the stale seeds of pairs still close then cost probes.
//!
//! Nor did a seed's age tell them apart: of 1,951 stale seeds (same scene, 300 frames),
//! 21 % belonged to pairs then apart, 5–15 % while the seed was within 10 times the
//! threshold and 31 % beyond it, 9–16 % while under 20 frames old and 33 % older (a seed
//! is renewed only by a proof, so a touching pair that waits keeps an old one). Taking a
//! pair as expected close only while its seed is under 1, 2 or 4 frames old measured
//! worse (0.691 / 0.826 / 0.897 / 0.943 for 1). Those pairs are not nearly touching: the
//! false close pairs were a median 0.11 m beyond their threshold, and 340 of the 397
//! stale-seeded ones had their root's bound and seed test only, the budget spent before
//! the deciding phase ended. Unlimited, such a pair is proven apart in a median of 29
//! visits, an undecided pair left false in 262. Hence [`EXPECTED_JOIN_CAP`]: the waiting
//! roots join once the stages turn to the wide pairs. Counted visits (400 frames, 200 /
//! 300 / 400 / 600 / 1,200 a frame): 0.810 / 0.879 / 0.934 / 0.957 / 0.992 waiting to the
//! end, 0.815 / 0.901 / 0.936 / 0.954 / 0.989 joining at a cap of 8 (at 4, 0.861 at 250
//! visits against 0.868 at 8; at 16, 0.867; at 32, 0.851). With deadlines (three
//! alternating runs of 400 frames, exact frames 233–263 µs at the median): 0.901–0.917
//! against 0.867–0.892 at 75 µs, 0.840–0.859 against 0.818–0.852 at 60 µs, 0.731–0.783
//! against 0.763–0.799 at 50 µs. On the mesh pile (200 frames,
//! 600 / 800 / 1,200 / 1,600 visits): 0.963 / 0.973 / 0.982 / 0.987 against 0.951 /
//! 0.966 / 0.989 / 0.994. Measured and not kept besides: expected roots joining the first
//! stage without a probe and waiting once set aside (0.713 / 0.805 / 0.896 / 0.937 at
//! 150 / 250 / 350 / 500 visits: pairs then proven close less often keep staler seeds);
//! after the deciding phase, the expected roots before the proven pairs' entries (0.736 /
//! 0.837 / 0.904 / 0.953); renewing a waiting pair's seed from the closest triangle pair
//! its visits found (0.735 / 0.837 / 0.903 / 0.950). With the join and
//! [`EXPECTED_PROBE_VISITS`] in place, the false close pairs left at 300 visits were
//! mostly still stale-seeded ones that a few visits would settle (148 of 384, a median
//! 19–25 visits each unlimited, given 3–15 before the budget ran out); giving them the
//! first stages without a probe, waiting once set aside until the join, with a probe from
//! their first entry then, measured worse again (0.719 / 0.770 / 0.806 / 0.828 / 0.909 /
//! 0.944 against 0.747 / 0.813 / 0.865 / 0.905 / 0.943 / 0.964 at 150 / 200 / 250 / 300 /
//! 400 / 600 visits).
//!
//! Also measured and not kept, precision at 150 / 250 / 350 / 500 visits against
//! 0.734 / 0.851 / 0.903 / 0.949: ending a probe at the first node pair whose volumes are
//! apart, 0.701 / 0.766 / 0.822 / 0.866 (at half
//! the threshold, 0.733 / 0.785 / 0.829 / 0.887: a probe's visits are part of a proof of
//! apart too); every root's bound before any probe, 0.738 / 0.848 / 0.902 / 0.949;
//! [`PROBE_VISITS`] of 16 or 32, at most 0.671 / 0.777 / 0.855 / 0.888; of 128,
//! 0.744 / 0.845 / 0.897 / 0.956.
//!
//! # Stages by width
//! Plain rounds give every pair one more level per round, so a wide pair (a link deep
//! inside an environment mesh, whose volumes overlap it for many levels) takes most of each
//! round while a narrow pair that a few more levels would prove apart waits its turn, and
//! is reported close when time runs out. The default order
//! ([`RoundOrder::CheapestPairsFirst`]) runs the rounds in *stages*: stage `k` processes
//! only the entries of pairs with at most `cap = FIRST_CAP · 2ᵏ` entries in their round and
//! sets the others aside unvisited; when no entry is left, the set-aside ones form the next
//! stage's first round. Every pair's root is processed in the first round (one entry each),
//! and every pair gets the same width of work per stage, so the pairs cheapest to settle
//! are settled first and the wide ones still degrade together. A set-aside entry keeps its
//! bound and depth: the answers read it like any waiting entry.
//!
//! Measured before the probe and the deciding phase (`examples/time_vs_error --scene
//! robot-chain`, 300 frames, three alternating runs each): precision of the reported close
//! pairs 0.79–0.84 with plain rounds and 0.914–0.915 in stages at 100 µs, 0.88 and 0.96 at
//! 200 µs, 0.64–0.67 and 0.74–0.78 at 50 µs. The mesh pile, where the pairs are alike,
//! measured the same either way. No order *within* a round changed anything (smallest or
//! largest bound first, fewest entries per pair first, pair order: 0.81–0.82 at 100 µs).
//!
//! The [`Budget`] is polled between entries once at least `poll_every` visits (default
//! [`DEFAULT_POLL_EVERY`]) were made since the last poll, never inside an entry (so never
//! inside a triangle test). When it refuses, [`FrontierWorkspace::run`] returns and the
//! entries left stand in for the unfinished work; calling `run` again resumes exactly where
//! it stopped, so a resumed run and a fresh run with the larger budget reach the same state
//! (for budgets, like [`VisitBudget`], that refuse from some visit count on).
//!
//! # The answers ([`FrontierAnswer`])
//! A pair's *live* entries are its entries still waiting whose bound is at most `threshold`
//! and below its best exact distance. Write `best` for the smallest triangle-pair distance
//! computed so far (`+∞` when none), `floor` for the smallest bound of its entries dropped
//! for exceeding `threshold`, `live` for the smallest bound of its live entries.
//! - **Exact** when it has no live entry. If `best ≤ threshold`, `best` *is* the minimum
//!   over all triangle pairs (every triangle pair lies under a dropped entry, a tested leaf
//!   pair or an entry that could not beat `best`): `maybe_close`, `distance_lower =
//!   distance_upper = best`, witnesses of that pair, `error_bound` = rounding. Otherwise
//!   the pair is proven apart: `!maybe_close`, `distance_lower = min(floor, best) >
//!   threshold`.
//! - **Truncated { level }** while it has live entries, `level` the shallowest depth
//!   (descents from the root pair) among them: `maybe_close = true` (a pair is never
//!   reported apart before it is proven apart, so there is no false negative),
//!   `distance_lower = min(live, floor, best)`, a lower bound of the true distance because
//!   every triangle pair lies under one of those three.
//!
//! The *reported* distance is always `distance_lower` ([`FrontierAnswer::distance`]): never
//! more than the true distance (a truncated answer errs on the side of "closer"). The error
//! bound states how much closer at most: `error_bound = upper − distance_lower + rounding`,
//! with `upper` the smallest of `best` and, for the root pair and every live entry `(X, Y)`,
//! `|centre(X) − centre(Y)| + stand_off(X) + stand_off(Y)` — some point of each mesh lies
//! within its volume's stand-off of the volume's centre, so the true distance is at most
//! that. Hence `distance_lower ≤ true ≤ distance_lower + error_bound`, and
//! `true ≤ distance_upper` whenever a leaf pair was tested. For the thresholded question
//! alone, [`FrontierAnswer::clamped_error_bound`] bounds the error of `min(distance,
//! threshold)`.
//!
//! More budget never makes an answer worse: processing an entry replaces its bound by
//! larger ones or by exact distances not below it (volume bounds are padded below the true
//! distance by more than the rounding of a triangle distance), so `distance_lower` never
//! decreases, and an Exact pair has nothing left to change.
//!
//! # Measured and not kept: carrying a pair's cut to the next frame
//! Each frame starts every pair from its root pair. The alternative, front tracking, was
//! built and measured (2026-11-24): each pair not proven close kept its *cut* (the node
//! pairs dropped beyond the threshold, the leaf pairs tested and the entries left
//! waiting, which together hold each triangle pair once), every bound lowered by the
//! relative drift since (lazily, through a running sum), and the next frame handed the
//! frontier only the node pairs the motion brought within the threshold, at most 16 per
//! pair (more: from the root), each re-tested before being refined. On
//! `examples/time_vs_error --scene robot-chain` (400 frames, alternating runs on one
//! host) it did more per visit: precision 0.851 → 0.921 at 250 counted visits and
//! 0.909 → 0.944 at 350. But the frames did not get better per microsecond: at 250
//! visits a frame took 13–20 µs longer (the carried entries took 9 rounds a frame where
//! the roots took 6.6, and carrying, starting and keeping the cuts of 17 pairs cost
//! 1–3 µs each), and 0.7 fewer pairs a frame were answered by a kept separation, because
//! a cut's bounds sit just beyond the threshold where a root pair's proof keeps a wide
//! slack. With a deadline, three alternating runs each: 0.87–0.90 against 0.84–0.90 at
//! 75 µs, 0.72–0.85 against 0.83–0.84 at 60 µs, 0.67–0.77 against 0.76–0.79 at 50 µs,
//! and 9–85 frames of 400 over budget against 3–12. At this scene's motion (links moving
//! up to 6 cm a frame against 4 cm margins) most of a cut is due again every frame. The
//! code is on the branch `experiment/carried-cuts` (commit b59a2e1).
//!
//! # Cost outside visits
//! Each round is sorted when it begins (`O(n log n)` for its `n` entries, created by at
//! most `n` visits of the round before; not polled); a set-aside entry is sorted again in
//! each stage it waits through (at most `log₂` of the widest round's entries stages), and
//! [`FrontierWorkspace::answers`] reads every waiting entry once.
//!
//! # Example
//! ```
//! use proxima::bounding::Obb;
//! use proxima::budget::VisitBudget;
//! use proxima::narrow::mesh_mesh::frontier::{FrontierPair, FrontierWorkspace, query_frontier};
//! use proxima::bvh::{BuildParams, Bvh};
//! use proxima::geometry::TriMesh;
//! use proxima::math::{DVec3, Isometry};
//!
//! let torus = Bvh::<Obb>::from_mesh(&TriMesh::torus(1.0, 0.3, 16, 8), &BuildParams::BINNED_SAH);
//! let pairs = [FrontierPair {
//!     a: &torus,
//!     b: &torus,
//!     pose_ab: Isometry::from_translation(DVec3::new(2.65, 0.0, 0.0)),
//!     threshold: 0.1,
//!     seed: None,
//! }];
//! let (mut workspace, mut answers) = (FrontierWorkspace::new(), Vec::new());
//! // A small budget: a truncated, conservative answer.
//! query_frontier(&pairs, &mut VisitBudget(40), &mut workspace, &mut answers);
//! assert!(answers[0].maybe_close && !answers[0].is_exact());
//! // Resume without limit: the exact answer (the tori are 0.05 m apart).
//! assert!(workspace.run(&pairs, &mut VisitBudget(u64::MAX)));
//! workspace.answers(&pairs, &mut answers);
//! assert!(answers[0].is_exact() && answers[0].maybe_close);
//! assert!((answers[0].distance() - 0.05).abs() < 1e-2);
//! ```
//!
//! # Allocation
//! The workspace owns the two entry vectors (swapped every round), the per-pair state and
//! the per-round counters; none of them allocates once grown to the largest frame seen.

mod trees;

pub use trees::{FrontierPair, PairTrees, TreesAt};

use crate::budget::{Budget, Completeness};
use crate::math::DVec3;
use std::cmp::Ordering;

/// Visits between two budget polls unless set with [`FrontierWorkspace::with_poll_every`].
///
/// A poll of a [`Deadline`] reads the clock (about 25 ns); a visit costs 0.1 µs (a volume
/// bound) to 0.5 µs (a triangle test). Measured with `examples/time_vs_error --scene
/// robot-chain` (300 frames, two runs each), once probes made a larger share of the visits
/// triangle tests: polling every 32 visits, 28–41 frames of a 75 µs budget and 103–126 of
/// a 50 µs one ended past the deadline; every 8, 11 and 45–50, with the same precision.
pub const DEFAULT_POLL_EVERY: u64 = 8;

/// Most visits of a pair's depth-first probe for a triangle pair within its threshold
/// (module docs, "The probe").
pub const PROBE_VISITS: u64 = 64;

/// Most visits of the probe of a pair expected close (module docs, "Decide first"): most
/// such pairs are still close, and one proven close waits, then passes its proof on as
/// next frame's seed. Measured with counted visits, against [`PROBE_VISITS`] for these
/// probes too: `examples/time_vs_error --scene robot-chain` (400 frames) at 200 / 250 /
/// 300 / 400 / 600 visits, 0.815 / 0.864 / 0.901 / 0.936 / 0.954 → 0.813 / 0.865 /
/// 0.905 / 0.943 / 0.964 (128: 0.815 / 0.866 / 0.907 / 0.942; 512 and unbounded as 256;
/// 32: 0.782 / 0.821 / 0.874 / 0.918); the mesh pile (200 frames) at 400 / 800 / 1,200 /
/// 1,600 visits, 0.925 / 0.966 / 0.989 / 0.994 → 0.932 / 0.975 / 0.993 / 0.999. Longer
/// probes for the other pairs measured worse (128: 0.807 / 0.841 / 0.877 / 0.933 on
/// robot-chain at 200–400 visits).
pub const EXPECTED_PROBE_VISITS: u64 = 256;

/// The closest triangle pair computed so far, A's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontierWitnesses {
    /// Point of A's triangle closest to B's.
    pub point_a: DVec3,
    /// Point of B's triangle closest to A's (equal to `point_a` when they intersect).
    pub point_b: DVec3,
    /// The two triangles, as indices into each mesh's own triangle list.
    pub triangles: [u32; 2],
}

/// The frontier's answer for one pair; see the [module docs](self) for exactly what each
/// field holds and why it is conservative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrontierAnswer {
    /// Exact, or truncated at some level.
    pub completeness: Completeness,
    /// `false` only when the pair is proven farther apart than its threshold.
    pub maybe_close: bool,
    /// A lower bound of the true distance, metres; the reported distance. Equal to the
    /// true distance for an Exact close pair.
    pub distance_lower: f64,
    /// The smallest exact triangle-pair distance computed (an upper bound of the true
    /// distance), when some leaf pair was tested.
    pub distance_upper: Option<f64>,
    /// The triangle pair realising `distance_upper` (the closest pair when the answer is
    /// Exact and close).
    pub witnesses: Option<FrontierWitnesses>,
    /// `distance_lower ≤ true ≤ distance_lower + error_bound`, metres.
    pub error_bound: f64,
    /// The pair's threshold, copied for [`clamped_error_bound`](Self::clamped_error_bound).
    pub threshold: f64,
}

impl FrontierAnswer {
    /// The reported distance: [`distance_lower`](Self::distance_lower).
    #[must_use]
    #[inline]
    pub fn distance(&self) -> f64 {
        self.distance_lower
    }

    /// Whether the traversal of this pair finished.
    #[must_use]
    #[inline]
    pub fn is_exact(&self) -> bool {
        self.completeness == Completeness::Exact
    }

    /// A bound of `|min(distance, threshold) − min(true, threshold)|`: the error that
    /// matters to the question "how close, if within threshold".
    #[must_use]
    #[inline]
    pub fn clamped_error_bound(&self) -> f64 {
        if self.distance_lower >= self.threshold {
            0.0
        } else {
            self.error_bound.min(self.threshold - self.distance_lower)
        }
    }
}

/// Counters of one traversal since [`FrontierWorkspace::start`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FrontierStats {
    /// Visits: bounding-volume tests plus triangle tests.
    pub visits: u64,
    /// Node-pair bound computations.
    pub bv_tests: u64,
    /// Triangle-pair distance computations.
    pub triangle_tests: u64,
    /// Rounds begun (the roots' round counts).
    pub rounds: u64,
    /// Budget polls.
    pub polls: u64,
}

/// A node pair waiting on the frontier.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    /// Lower bound of the distance between the triangles under the two nodes, metres
    /// (`0` for a root entry, whose bound is computed when it is processed).
    bound: f64,
    /// Index of the pair in the caller's slice.
    pair: u32,
    /// Node of A.
    a: u32,
    /// Node of B.
    b: u32,
    /// Descents from the root pair; `0` marks a root entry.
    depth: u32,
}

/// The processing order within a round: smallest bound first, then pair, node of A, node
/// of B (a total order: no two entries share all four).
#[inline]
fn entry_order(x: &Entry, y: &Entry) -> Ordering {
    x.bound
        .total_cmp(&y.bound)
        .then_with(|| (x.pair, x.a, x.b).cmp(&(y.pair, y.a, y.b)))
}

/// What the frontier knows about one pair besides its waiting entries.
#[derive(Debug, Clone, Copy)]
struct PairState {
    threshold: f64,
    /// Smallest triangle-pair distance computed, `+∞` when none.
    best: f64,
    witnesses: Option<FrontierWitnesses>,
    /// Smallest bound of the entries dropped for exceeding the threshold, `+∞` when none.
    floor: f64,
    /// Upper bound of the true distance from the two root volumes.
    root_upper: f64,
    /// Rounding of a triangle distance at this pair's scale.
    rounding: f64,
    /// Whether the root entry's bound and the seed were computed.
    root_done: bool,
    /// Whether the pair came with a seed ([`FrontierPair::seed`]): it is expected close,
    /// and waits with the decided pairs even when the seed is no longer within the
    /// threshold.
    expected_close: bool,
}

impl PairState {
    /// Whether the pair is proven within its threshold (a triangle pair within it found):
    /// only its distance is left to refine.
    #[inline]
    fn is_decided_close(&self) -> bool {
        self.best <= self.threshold
    }
}

/// Entries of one pair in a round that the first stage of
/// [`RoundOrder::CheapestPairsFirst`] processes; each stage doubles it. Measured with
/// `examples/time_vs_error --scene robot-chain`: a first cap of 1, 2, 4, 8 or 16 with growth
/// 2, 3 or 4 all gave 0.88–0.92 precision at 100 µs; 2 and 2 also did best at 50 µs
/// (0.73–0.79 against 0.68–0.73 for 4 and 4).
pub const FIRST_CAP: u32 = 2;

/// The stage cap at which the roots of pairs expected close stop waiting for the deciding
/// phase to end and join it (module docs, "Decide first"). Measured on robot-chain and the
/// mesh pile with 4, 8, 16 and 32 (module docs).
pub const EXPECTED_JOIN_CAP: u32 = 8;

// The stage caps are `FIRST_CAP · 2ᵏ`, and the join happens when one equals
// `EXPECTED_JOIN_CAP` (`FrontierWorkspace::next_round`): it must be one of them.
const _: () = assert!(
    EXPECTED_JOIN_CAP > FIRST_CAP
        && EXPECTED_JOIN_CAP.is_multiple_of(FIRST_CAP)
        && (EXPECTED_JOIN_CAP / FIRST_CAP).is_power_of_two()
);

/// Scratch space and state of the frontier; keep one per thread and reuse it every frame.
#[derive(Debug, Clone)]
pub struct FrontierWorkspace {
    /// The round being processed, sorted; `current[cursor..]` waits.
    current: Vec<Entry>,
    cursor: usize,
    /// Entries for the next round.
    next: Vec<Entry>,
    /// Entries set aside by the current stage ([`RoundOrder::CheapestPairsFirst`]).
    set_aside: Vec<Entry>,
    /// While `deciding`: the entries of pairs proven close, and the roots of pairs
    /// expected close, waiting for the undecided pairs to be settled.
    later: Vec<Entry>,
    /// Whether the undecided pairs are still being settled (module docs, "Decide first").
    deciding: bool,
    /// The depth-first probe under way: its stack (the last entry is searched next).
    probe: Vec<Entry>,
    /// The probe ends once `stats.visits` reaches this.
    probe_until: u64,
    /// Entries of one pair in a round above which its entries are set aside (`u32::MAX`
    /// for the orders without stages, which set nothing aside).
    cap: u32,
    /// Per pair, its entries in the current round (counted only in stages).
    round_entries: Vec<u32>,
    pairs: Vec<PairState>,
    stats: FrontierStats,
    /// Entries at the start of each round begun.
    entries_per_round: Vec<u64>,
    /// The budget is polled before the next entry once `visits` reaches this.
    next_poll: u64,
    poll_every: u64,
    order: RoundOrder,
}

/// The order the frontier's entries are processed in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum RoundOrder {
    /// Rounds in stages by width, each round smallest bound first; the default. A stage
    /// processes only the pairs with at most `cap` entries in their round; an entry of a
    /// wider pair is set aside unvisited. When no entry is left, `cap` doubles (from
    /// [`FIRST_CAP`]) and the set-aside entries form the next round (module docs, "Stages
    /// by width").
    #[default]
    CheapestPairsFirst,
    /// Plain breadth-first rounds, smallest lower bound first (then pair, node of A, node
    /// of B): every pair one level deeper per round (`--order bound`).
    SmallestBound,
    /// By pair, then node of A, node of B, ignoring the bounds: the baseline the default
    /// is measured against (`examples/time_vs_error --order pair`).
    Pair,
    /// Largest lower bound first: the entries nearest to being proven apart first, which
    /// is what removes false close pairs (`--order largest`).
    LargestBound,
}

impl Default for FrontierWorkspace {
    fn default() -> Self {
        Self::new()
    }
}

impl FrontierWorkspace {
    /// An empty workspace polling every [`DEFAULT_POLL_EVERY`] visits.
    #[must_use]
    pub fn new() -> Self {
        Self::with_poll_every(DEFAULT_POLL_EVERY)
    }

    /// This workspace processing its entries in `order`.
    #[must_use]
    pub fn with_order(mut self, order: RoundOrder) -> Self {
        self.order = order;
        self
    }

    /// An empty workspace polling the budget once at least `visits` (`≥ 1`) visits were
    /// made since the last poll.
    #[must_use]
    pub fn with_poll_every(visits: u64) -> Self {
        assert!(visits >= 1, "poll interval must be at least one visit");
        Self {
            current: Vec::new(),
            cursor: 0,
            next: Vec::new(),
            set_aside: Vec::new(),
            later: Vec::new(),
            deciding: true,
            probe: Vec::new(),
            probe_until: 0,
            cap: u32::MAX,
            round_entries: Vec::new(),
            pairs: Vec::new(),
            stats: FrontierStats::default(),
            entries_per_round: Vec::new(),
            next_poll: 0,
            poll_every: visits,
            order: RoundOrder::default(),
        }
    }

    /// Resets the frontier to one root entry per pair of `pairs` (round 1, no visit yet).
    /// Thresholds must be `≥ 0` (`+∞` allowed, NaN not).
    pub fn start<P: PairTrees>(&mut self, pairs: &[P]) {
        assert!(
            u32::try_from(pairs.len()).is_ok(),
            "too many pairs for one frontier"
        );
        self.current.clear();
        self.next.clear();
        self.set_aside.clear();
        self.later.clear();
        self.deciding = true;
        self.probe.clear();
        self.cap = self.first_cap();
        self.cursor = 0;
        self.pairs.clear();
        self.stats = FrontierStats::default();
        self.entries_per_round.clear();
        self.next_poll = 0;
        for (i, p) in pairs.iter().enumerate() {
            let threshold = p.threshold();
            debug_assert!(threshold >= 0.0, "threshold {threshold} of pair {i}");
            let (root_upper, rounding) = p.root_bounds();
            self.pairs.push(PairState {
                threshold,
                best: f64::INFINITY,
                witnesses: None,
                floor: f64::INFINITY,
                root_upper,
                rounding,
                root_done: false,
                expected_close: false,
            });
            self.current.push(Entry {
                bound: 0.0,
                pair: i as u32,
                a: 0,
                b: 0,
                depth: 0,
            });
        }
        self.begin_round();
    }

    /// Refines the frontier until it is empty (returns `true`) or `budget` refuses at a
    /// poll (returns `false`); calling again resumes. `pairs` must be the slice given to
    /// [`start`](Self::start).
    pub fn run<P: PairTrees, T: Budget + ?Sized>(&mut self, pairs: &[P], budget: &mut T) -> bool {
        debug_assert_eq!(pairs.len(), self.pairs.len(), "pairs differ from start");
        loop {
            let probing = !self.probe.is_empty();
            if !probing && self.cursor == self.current.len() && !self.next_round() {
                return true;
            }
            if self.stats.visits >= self.next_poll {
                self.stats.polls += 1;
                if !budget.allows(self.stats.visits) {
                    return false;
                }
                self.next_poll = self.stats.visits + self.poll_every;
            }
            if probing {
                let entry = self.probe.pop().expect("probing");
                self.probe_step(&pairs[entry.pair as usize], entry);
                continue;
            }
            let entry = self.current[self.cursor];
            self.cursor += 1;
            let state = &self.pairs[entry.pair as usize];
            if self.deciding && state.root_done && state.is_decided_close() {
                self.later.push(entry);
                continue;
            }
            if self.cap != u32::MAX && self.round_entries[entry.pair as usize] > self.cap {
                self.set_aside.push(entry);
                continue;
            }
            self.process(&pairs[entry.pair as usize], entry);
        }
    }

    /// Begins the next round when the current one is done: the entries created by the
    /// last; when none, the next stage (the set-aside entries, a wider cap); when none,
    /// the end of deciding (the waiting decided pairs, from the first cap). Returns `false`
    /// when nothing is left.
    fn next_round(&mut self) -> bool {
        if self.next.is_empty() {
            if self.set_aside.is_empty() {
                if self.later.is_empty() {
                    return false;
                }
                // Every undecided pair is settled: the decided ones are refined now.
                self.deciding = false;
                std::mem::swap(&mut self.set_aside, &mut self.later);
                self.cap = self.first_cap();
            } else {
                self.cap = self.cap.saturating_mul(2);
                if self.deciding && self.cap == EXPECTED_JOIN_CAP {
                    self.join_expected();
                }
            }
            std::mem::swap(&mut self.next, &mut self.set_aside);
        }
        std::mem::swap(&mut self.current, &mut self.next);
        self.next.clear();
        self.begin_round();
        true
    }

    /// Moves the waiting roots of pairs expected close (the waiting entries of pairs not
    /// proven close) to the stage about to begin; the proven pairs' entries keep waiting.
    fn join_expected(&mut self) {
        let pairs = &self.pairs;
        let undecided = |e: &Entry| !pairs[e.pair as usize].is_decided_close();
        self.set_aside
            .extend(self.later.iter().filter(|e| undecided(e)));
        self.later.retain(|e| !undecided(e));
    }

    /// The cap of a stage's first round (`u32::MAX`: no stages).
    fn first_cap(&self) -> u32 {
        match self.order {
            RoundOrder::CheapestPairsFirst => FIRST_CAP,
            _ => u32::MAX,
        }
    }

    /// Whether nothing is left on the frontier (every answer is Exact).
    #[must_use]
    pub fn is_finished(&self) -> bool {
        self.waiting() == 0
    }

    /// Counters since [`start`](Self::start).
    #[must_use]
    pub fn stats(&self) -> &FrontierStats {
        &self.stats
    }

    /// Entries on the frontier at the start of each round begun.
    #[must_use]
    pub fn entries_per_round(&self) -> &[u64] {
        &self.entries_per_round
    }

    /// Entries still waiting (live or not).
    #[must_use]
    pub fn waiting(&self) -> usize {
        self.current.len() - self.cursor
            + self.next.len()
            + self.set_aside.len()
            + self.later.len()
            + self.probe.len()
    }

    /// The answer for every pair, in order, into `out` (cleared first); see the
    /// [module docs](self). `pairs` must be the slice given to [`start`](Self::start).
    pub fn answers<P: PairTrees>(&self, pairs: &[P], out: &mut Vec<FrontierAnswer>) {
        debug_assert_eq!(pairs.len(), self.pairs.len(), "pairs differ from start");
        out.clear();
        // First pass: `out` holds, per pair, the live minimum bound (`distance_lower`),
        // shallowest depth (`Truncated`) and smallest centre bound (`error_bound`).
        out.extend(self.pairs.iter().map(|s| FrontierAnswer {
            completeness: Completeness::Exact,
            maybe_close: false,
            distance_lower: f64::INFINITY,
            distance_upper: None,
            witnesses: s.witnesses,
            error_bound: s.root_upper,
            threshold: s.threshold,
        }));
        let waiting = self.current[self.cursor..].iter().chain(&self.next);
        for e in waiting
            .chain(&self.set_aside)
            .chain(&self.later)
            .chain(&self.probe)
        {
            let state = &self.pairs[e.pair as usize];
            if !is_live(e.bound, state) {
                continue;
            }
            let upper = pairs[e.pair as usize].upper_bound([e.a, e.b]);
            let answer = &mut out[e.pair as usize];
            answer.distance_lower = answer.distance_lower.min(e.bound);
            answer.error_bound = answer.error_bound.min(upper);
            answer.completeness = answer.completeness.truncated_at(e.depth);
        }
        for (answer, state) in out.iter_mut().zip(&self.pairs) {
            let best = state.best;
            answer.distance_upper = best.is_finite().then_some(best);
            let upper = answer.error_bound.min(best);
            if answer.completeness == Completeness::Exact && best <= state.threshold {
                answer.maybe_close = true;
                answer.distance_lower = best;
                answer.error_bound = state.rounding;
            } else {
                answer.maybe_close = !answer.is_exact();
                answer.distance_lower = answer.distance_lower.min(state.floor).min(best);
                answer.error_bound = (upper - answer.distance_lower).max(0.0) + state.rounding;
            }
        }
    }

    /// Sorts the round just swapped in and counts it, and, in stages, each pair's entries
    /// in it.
    fn begin_round(&mut self) {
        if self.cap != u32::MAX {
            self.round_entries.clear();
            self.round_entries.resize(self.pairs.len(), 0);
            for e in &self.current {
                self.round_entries[e.pair as usize] += 1;
            }
        }
        match self.order {
            RoundOrder::CheapestPairsFirst | RoundOrder::SmallestBound => {
                self.current.sort_unstable_by(entry_order);
            }
            RoundOrder::Pair => self.current.sort_unstable_by_key(|x| (x.pair, x.a, x.b)),
            RoundOrder::LargestBound => self.current.sort_unstable_by(|x, y| entry_order(y, x)),
        }
        self.cursor = 0;
        self.stats.rounds += 1;
        self.entries_per_round.push(self.current.len() as u64);
    }

    /// Processes one entry (see the module docs); bounded work: one bound, two child
    /// bounds or one leaf pair's triangle tests; a root's first processing adds the seed's
    /// triangle test, and may begin a probe.
    fn process<P: PairTrees>(&mut self, pair: &P, mut entry: Entry) {
        let state = &mut self.pairs[entry.pair as usize];
        let nodes = [entry.a, entry.b];
        let leaves = pair.are_leaves(nodes);
        if entry.depth == 0 && !state.root_done {
            state.root_done = true;
            entry.bound = pair.bound(nodes, state.threshold);
            self.stats.visits += 1;
            self.stats.bv_tests += 1;
            if entry.bound > state.threshold {
                state.floor = state.floor.min(entry.bound);
                return;
            }
            if let Some((distance, witnesses)) = pair.seed_distance() {
                self.stats.visits += 1;
                self.stats.triangle_tests += 1;
                state.expected_close = true;
                state.best = distance;
                state.witnesses = Some(witnesses);
            }
            if self.deciding && !leaves && (state.is_decided_close() || state.expected_close) {
                self.later.push(entry);
                return;
            }
        }
        if !is_live(entry.bound, state) {
            return;
        }
        if leaves {
            test_leaf_pair(pair, nodes, state, &mut self.stats);
            return;
        }
        if entry.depth == 0 && !state.is_decided_close() {
            // The root of a pair not yet proven close: searched depth first for a proof.
            self.probe.push(entry);
            self.probe_until = self.stats.visits
                + if state.expected_close {
                    EXPECTED_PROBE_VISITS
                } else {
                    PROBE_VISITS
                };
            return;
        }
        let children = split(pair, state, &mut self.stats, entry);
        self.next.extend(children.into_iter().flatten());
    }

    /// One step of the probe under way on `entry`, the top of its stack (module docs,
    /// "The probe"): a leaf pair's triangle tests, or the entry's two children pushed so
    /// that the one with the smaller bound (on a tie, the smaller upper bound) is searched
    /// next. Once the pair is proven close or the probe has made its visits
    /// ([`PROBE_VISITS`], [`EXPECTED_PROBE_VISITS`] for a pair expected close), the probe
    /// ends: this entry and the rest of the stack join the next round.
    fn probe_step<P: PairTrees>(&mut self, pair: &P, entry: Entry) {
        let state = &mut self.pairs[entry.pair as usize];
        if !is_live(entry.bound, state) {
            return;
        }
        if state.is_decided_close() || self.stats.visits >= self.probe_until {
            self.next.push(entry);
            self.next.append(&mut self.probe);
            return;
        }
        let nodes = [entry.a, entry.b];
        if pair.are_leaves(nodes) {
            test_leaf_pair(pair, nodes, state, &mut self.stats);
            return;
        }
        let [x, y] = split(pair, state, &mut self.stats, entry);
        // The one searched next goes on top of the stack.
        let y_first = match (x, y) {
            (Some(x), Some(y)) if x.bound == y.bound => {
                pair.upper_bound([y.a, y.b]) < pair.upper_bound([x.a, x.b])
            }
            (Some(x), Some(y)) => y.bound < x.bound,
            _ => false,
        };
        let order = if y_first { [x, y] } else { [y, x] };
        self.probe.extend(order.into_iter().flatten());
    }
}

/// The children of `entry` (not a leaf pair) on the side [`PairTrees::split`] chooses, each
/// with its bound (one visit each; never below its parent's), `None` when dropped: beyond
/// the threshold (lowering the pair's floor) or unable to beat its best distance.
fn split<P: PairTrees>(
    pair: &P,
    state: &mut PairState,
    stats: &mut FrontierStats,
    entry: Entry,
) -> [Option<Entry>; 2] {
    let limit = state.threshold.min(state.best);
    pair.split([entry.a, entry.b], limit)
        .map(|([a, b], bound)| {
            stats.visits += 1;
            stats.bv_tests += 1;
            let bound = bound.max(entry.bound);
            if bound > state.threshold {
                state.floor = state.floor.min(bound);
                None
            } else {
                (bound < state.best).then_some(Entry {
                    bound,
                    pair: entry.pair,
                    a,
                    b,
                    depth: entry.depth + 1,
                })
            }
        })
}

/// Tests every triangle pair of the leaf pair `nodes`, one visit each, updating the pair's
/// best distance and its witnesses.
fn test_leaf_pair<P: PairTrees>(
    pair: &P,
    nodes: [u32; 2],
    state: &mut PairState,
    stats: &mut FrontierStats,
) {
    let tests = pair.test_leaves(nodes, &mut state.best, &mut state.witnesses);
    stats.visits += tests;
    stats.triangle_tests += tests;
}

/// Runs a fresh frontier over `pairs` under `budget` and writes every pair's answer to
/// `out`; returns whether every answer is Exact.
pub fn query_frontier<P: PairTrees, T: Budget + ?Sized>(
    pairs: &[P],
    budget: &mut T,
    workspace: &mut FrontierWorkspace,
    out: &mut Vec<FrontierAnswer>,
) -> bool {
    workspace.start(pairs);
    let finished = workspace.run(pairs, budget);
    workspace.answers(pairs, out);
    finished
}

/// Whether an entry with this bound can still change the pair's answer.
#[inline]
fn is_live(bound: f64, state: &PairState) -> bool {
    bound <= state.threshold && bound < state.best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::{BoundingVolume, Obb, Rss};
    use crate::budget::{Deadline, Unlimited, VisitBudget};
    use crate::bvh::{BuildParams, Bvh};
    use crate::geometry::TriMesh;
    use crate::math::Isometry;
    use crate::math::{DQuat, Pose};
    use crate::narrow::distance_triangle_triangle;
    use crate::narrow::mesh_mesh::{
        DistanceCache, DistanceParams, MeshDistance, MeshMeshWorkspace, distance_mesh_mesh,
    };
    use std::time::Instant;

    fn entry(bound: f64, pair: u32, a: u32, b: u32) -> Entry {
        Entry {
            bound,
            pair,
            a,
            b,
            depth: 1,
        }
    }

    /// Two tori (leaf size 4) at three poses: touching, a little apart, far apart.
    fn scene<B: BoundingVolume>() -> (Bvh<B>, Bvh<B>, Vec<Pose>) {
        let params = BuildParams::BINNED_SAH.with_leaf_size(4);
        let a = Bvh::from_mesh(&TriMesh::torus(1.0, 0.3, 16, 8), &params);
        let b = Bvh::from_mesh(&TriMesh::torus(0.8, 0.25, 12, 6), &params);
        let turn = DQuat::from_rotation_x(1.2);
        let poses = [0.9, 2.5, 6.0]
            .map(|x| Pose::new(DVec3::new(x, 0.1, 0.05), turn))
            .to_vec();
        (a, b, poses)
    }

    fn pairs<'a, B>(a: &'a Bvh<B>, b: &'a Bvh<B>, poses: &[Pose]) -> Vec<FrontierPair<'a, B>> {
        poses
            .iter()
            .map(|pose| FrontierPair {
                a,
                b,
                pose_ab: pose.to_isometry(),
                threshold: 0.3,
                seed: None,
            })
            .collect()
    }

    /// Records the visit counts it was polled at, and refuses from `limit` on.
    struct Recorder {
        limit: u64,
        polled_at: Vec<u64>,
    }

    impl Budget for Recorder {
        fn allows(&mut self, visits: u64) -> bool {
            self.polled_at.push(visits);
            visits < self.limit
        }
    }

    #[test]
    fn entries_are_ordered_by_smallest_bound_then_pair_then_nodes() {
        let mut entries = [
            entry(0.5, 0, 1, 1),
            entry(0.1, 2, 3, 4),
            entry(0.1, 1, 9, 9),
            entry(0.1, 1, 2, 7),
            entry(0.1, 1, 2, 5),
            entry(0.0, 3, 0, 0),
        ];
        entries.sort_unstable_by(entry_order);
        let keys: Vec<_> = entries.iter().map(|e| (e.pair, e.a, e.b)).collect();
        assert_eq!(
            keys,
            [
                (3, 0, 0),
                (1, 2, 5),
                (1, 2, 7),
                (1, 9, 9),
                (2, 3, 4),
                (0, 1, 1)
            ]
        );
    }

    #[test]
    fn every_round_is_processed_in_entry_order() {
        let (a, b, poses) = scene::<Obb>();
        let pairs = pairs(&a, &b, &poses);
        let mut ws = FrontierWorkspace::with_poll_every(1);
        ws.start(&pairs);
        let mut rounds_seen = 0;
        for limit in 1.. {
            let done = ws.run(&pairs, &mut VisitBudget(limit));
            if ws.cursor == 0 || done {
                assert!(ws.current.is_sorted_by(|x, y| entry_order(x, y).is_le()));
                rounds_seen += 1;
            }
            if done {
                break;
            }
        }
        assert!(rounds_seen >= 3, "{rounds_seen}");
    }

    #[test]
    fn the_budget_is_polled_between_batches_and_never_inside_a_leaf_pair() {
        let (a, b, poses) = scene::<Rss>();
        let pairs = pairs(&a, &b, &poses);
        let unlimited = {
            let mut ws = FrontierWorkspace::new();
            ws.start(&pairs);
            assert!(ws.run(&pairs, &mut Unlimited));
            ws.stats().visits
        };
        // The most one entry or probe step costs: a root's bound and seed test (and, were
        // the root a leaf pair, its tests), two child bounds, or a leaf pair's 4 × 4
        // triangle tests (leaf size 4).
        let entry_cost = 2 + 16;
        for poll_every in [1, 5, 32] {
            for limit in (0..unlimited + 40).step_by(7) {
                let mut ws = FrontierWorkspace::with_poll_every(poll_every);
                let mut budget = Recorder {
                    limit,
                    polled_at: Vec::new(),
                };
                ws.start(&pairs);
                let done = ws.run(&pairs, &mut budget);
                let visits = ws.stats().visits;
                assert_eq!(
                    budget.polled_at[0], 0,
                    "the first poll comes before any work"
                );
                for w in budget.polled_at.windows(2) {
                    assert!(w[1] >= w[0] + poll_every, "{poll_every}: {w:?}");
                    assert!(w[1] < w[0] + poll_every + entry_cost, "{poll_every}: {w:?}");
                }
                assert_eq!(ws.stats().polls, budget.polled_at.len() as u64);
                if done {
                    assert_eq!(visits, unlimited);
                } else {
                    assert!(visits >= limit, "stopped early: {visits} < {limit}");
                    assert_eq!(*budget.polled_at.last().unwrap(), visits);
                    assert!(visits < limit.max(1) + poll_every + entry_cost);
                }
            }
        }
    }

    #[test]
    fn a_zero_budget_or_a_past_deadline_does_no_work_and_answers_maybe_close() {
        let (a, b, poses) = scene::<Obb>();
        let pairs = pairs(&a, &b, &poses);
        let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
        let past = Instant::now();
        for finished in [
            query_frontier(&pairs, &mut VisitBudget(0), &mut ws, &mut out),
            query_frontier(&pairs, &mut Deadline(past), &mut ws, &mut out),
        ] {
            assert!(!finished);
            assert_eq!(ws.stats().visits, 0);
            assert_eq!(ws.entries_per_round(), [3]);
            for answer in &out {
                assert_eq!(answer.completeness, Completeness::Truncated { level: 0 });
                assert!(answer.maybe_close);
                assert_eq!(answer.distance_lower, 0.0);
                assert_eq!(answer.distance_upper, None);
                assert!(answer.error_bound.is_finite() && answer.error_bound > 0.0);
            }
        }
    }

    /// The exact mesh–mesh distance query's answer, cold.
    fn exact_distance(a: &Bvh<Rss>, b: &Bvh<Rss>, pose: &Pose) -> MeshDistance {
        distance_mesh_mesh(
            a,
            b,
            pose,
            &DistanceParams::EXACT,
            &mut DistanceCache::new(),
            &mut MeshMeshWorkspace::new(),
        )
    }

    #[test]
    fn an_unlimited_run_gives_the_exact_distance_query_answers() {
        let (a, b, poses) = scene::<Rss>();
        let pairs = pairs(&a, &b, &poses);
        let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
        assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut out));
        assert!(ws.is_finished());
        assert_eq!(ws.waiting(), 0);
        let stats = *ws.stats();
        assert_eq!(stats.visits, stats.bv_tests + stats.triangle_tests);
        assert_eq!(stats.rounds, ws.entries_per_round().len() as u64);
        let mut close = 0;
        for ((p, pose), answer) in pairs.iter().zip(&poses).zip(&out) {
            assert!(answer.is_exact());
            let exact = exact_distance(&a, &b, pose);
            assert_eq!(answer.maybe_close, exact.distance <= p.threshold);
            if answer.maybe_close {
                close += 1;
                assert_eq!(answer.distance_lower, exact.distance);
                assert_eq!(answer.distance_upper, Some(exact.distance));
                let w = answer.witnesses.unwrap();
                assert_eq!(w.point_a.distance(w.point_b), exact.distance);
            } else {
                assert!(answer.distance_lower > p.threshold);
                assert!(answer.distance_lower <= exact.distance);
                assert!(exact.distance <= answer.distance_lower + answer.error_bound);
            }
        }
        assert_eq!(
            close, 2,
            "touching and near pairs are close, the far one is not"
        );
    }

    #[test]
    fn an_infinite_threshold_gives_every_pairs_exact_distance() {
        let (a, b, poses) = scene::<Rss>();
        let mut pairs = pairs(&a, &b, &poses);
        for p in &mut pairs {
            p.threshold = f64::INFINITY;
        }
        let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
        assert!(!query_frontier(
            &pairs,
            &mut VisitBudget(30),
            &mut ws,
            &mut out
        ));
        assert!(
            out.iter()
                .all(|x| x.maybe_close && x.error_bound.is_finite())
        );
        assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut out));
        for (pose, answer) in poses.iter().zip(&out) {
            let exact = exact_distance(&a, &b, pose);
            assert!(answer.is_exact() && answer.maybe_close);
            assert_eq!(answer.distance_lower, exact.distance);
            assert_eq!(answer.clamped_error_bound(), answer.error_bound);
        }
        assert!(out[2].distance_lower > 1.0, "the far pair is far");
    }

    #[test]
    fn a_resumed_run_reaches_the_state_of_a_fresh_run_with_the_larger_budget() {
        let (a, b, poses) = scene::<Obb>();
        let pairs = pairs(&a, &b, &poses);
        let mut resumed = FrontierWorkspace::new();
        resumed.start(&pairs);
        let (mut fresh_out, mut resumed_out) = (Vec::new(), Vec::new());
        let mut fresh = FrontierWorkspace::new();
        for limit in (0..2000).step_by(13) {
            resumed.run(&pairs, &mut VisitBudget(limit));
            resumed.answers(&pairs, &mut resumed_out);
            query_frontier(&pairs, &mut VisitBudget(limit), &mut fresh, &mut fresh_out);
            // Polls differ (a refused poll is repeated on resuming); the work does not.
            let work = |s: &FrontierStats| FrontierStats { polls: 0, ..*s };
            assert_eq!(work(resumed.stats()), work(fresh.stats()), "{limit}");
            assert_eq!(resumed.entries_per_round(), fresh.entries_per_round());
            assert_eq!(resumed_out, fresh_out, "{limit}");
        }
    }

    /// Visits after which each pair's answer is first Exact, one visit a budget, and the
    /// final answers.
    fn settled_after(
        pairs: &[FrontierPair<'_, Obb>],
        order: RoundOrder,
    ) -> (Vec<u64>, Vec<FrontierAnswer>) {
        let mut ws = FrontierWorkspace::with_poll_every(1).with_order(order);
        ws.start(pairs);
        let (mut settled, mut out) = (vec![u64::MAX; pairs.len()], Vec::new());
        for limit in 0.. {
            let done = ws.run(pairs, &mut VisitBudget(limit));
            ws.answers(pairs, &mut out);
            for (at, answer) in settled.iter_mut().zip(&out) {
                if *at == u64::MAX && answer.is_exact() {
                    *at = ws.stats().visits;
                }
            }
            if done {
                break;
            }
        }
        (settled, out)
    }

    /// Visits after which `done` first holds of the answers, one visit a budget (and
    /// the final answers).
    fn visits_until(
        pairs: &[FrontierPair<'_, Obb>],
        done: impl Fn(&[FrontierAnswer]) -> bool,
    ) -> (u64, Vec<FrontierAnswer>) {
        let mut ws = FrontierWorkspace::with_poll_every(1);
        ws.start(pairs);
        let mut out = Vec::new();
        let mut at = None;
        for limit in 0.. {
            let finished = ws.run(pairs, &mut VisitBudget(limit));
            ws.answers(pairs, &mut out);
            if at.is_none() && done(&out) {
                at = Some(ws.stats().visits);
            }
            if finished {
                break;
            }
        }
        (at.expect("holds once every answer is exact"), out)
    }

    /// The exact answer of one pair on its own (its closest triangles, when within the
    /// threshold).
    fn alone(pair: &FrontierPair<'_, Obb>) -> FrontierAnswer {
        let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
        assert!(query_frontier(&[*pair], &mut Unlimited, &mut ws, &mut out));
        out[0]
    }

    /// A pair proven close by its seed, or expected close because it has one (seed no
    /// longer within the threshold), waits while an undecided pair is settled: that pair
    /// is answered exactly after its own visits plus the waiting root's bound and seed
    /// test, where without a seed the touching pair's probe comes first. The final answers
    /// are each pair's own.
    #[test]
    fn pairs_proven_or_expected_close_wait_while_an_undecided_pair_is_settled() {
        let (a, b, poses) = scene::<Obb>();
        let [touching, near] = pairs(&a, &b, &[poses[0], poses[1]])
            .try_into()
            .expect("two pairs");
        // The tori a little apart, 0.17 m, beyond a threshold of 0.1 m.
        let apart = FrontierPair {
            threshold: 0.1,
            ..near
        };
        assert!(!alone(&apart).maybe_close);
        let (undecided_alone, _) = visits_until(&[apart], |x| x[0].is_exact());
        let closest = alone(&touching).witnesses.expect("close").triangles;
        // A triangle pair of the touching tori farther apart than the threshold.
        let stale = [0, 0];
        let stale_distance = distance_triangle_triangle(
            &a.triangles()[a.slot_of(0).expect("id 0")],
            &b.triangles()[b.slot_of(0).expect("id 0")].transformed(&touching.pose_ab),
        )
        .distance;
        assert!(stale_distance > touching.threshold, "{stale_distance}");
        for seed in [closest, stale] {
            let seeded = FrontierPair {
                seed: Some(seed),
                ..touching
            };
            let both = [seeded, apart];
            let (settled, answers) = visits_until(&both, |x| x[1].is_exact());
            assert_eq!(settled, undecided_alone + 2, "seed {seed:?}");
            assert_eq!(answers[0].distance_lower, alone(&seeded).distance_lower);
            assert_eq!(answers[1], alone(&apart), "seed {seed:?}");
        }
        let (unseeded, _) = visits_until(&[touching, apart], |x| x[1].is_exact());
        assert!(
            unseeded > undecided_alone + 2,
            "{unseeded} {undecided_alone}"
        );
    }

    /// A pair expected close waits only until the stages reach [`EXPECTED_JOIN_CAP`]: beside
    /// a wide undecided pair (a small torus inside a large one, in its plane, apart all
    /// around the ring by a little more than the threshold), the touching pair with a
    /// stale seed is proven close before the wide pair is settled, where it would otherwise
    /// wait for it. The final answers are each pair's own.
    #[test]
    fn an_expected_pair_joins_the_deciding_phase_once_the_stages_reach_the_join_cap() {
        let (a, b, poses) = scene::<Obb>();
        let params = BuildParams::BINNED_SAH.with_leaf_size(4);
        let inner = Bvh::from_mesh(&TriMesh::torus(0.5, 0.15, 16, 8), &params);
        let wide = FrontierPair {
            a: &a,
            b: &inner,
            pose_ab: Isometry::IDENTITY,
            threshold: 0.02,
            seed: None,
        };
        let wide_alone = alone(&wide);
        assert!(!wide_alone.maybe_close);
        let widest = {
            let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
            query_frontier(&[wide], &mut Unlimited, &mut ws, &mut out);
            ws.entries_per_round().iter().copied().max()
        };
        assert!(
            widest > Some(u64::from(EXPECTED_JOIN_CAP)),
            "widest round {widest:?}"
        );
        let touching = FrontierPair {
            seed: Some([0, 0]),
            ..pairs(&a, &b, &poses[..1])[0]
        };
        let (seed_distance, _) = touching.seed_distance().expect("a seed");
        assert!(seed_distance > touching.threshold, "{seed_distance}");
        let both = [touching, wide];
        let proven =
            |x: &[FrontierAnswer]| x[0].distance_upper.is_some_and(|d| d <= x[0].threshold);
        let (first_visit, _) = visits_until(&both, |x| x[0].distance_upper.is_some());
        let (proven_at, _) = visits_until(&both, proven);
        let (settled, answers) = visits_until(&both, |x| x[1].is_exact());
        assert_eq!(first_visit, 2, "the root's bound and the stale seed's test");
        assert!(proven_at > first_visit, "proven by its probe, not its seed");
        assert!(
            proven_at < settled,
            "proven at {proven_at}, settled at {settled}"
        );
        assert_eq!(answers[0].distance_lower, alone(&touching).distance_lower);
        assert_eq!(answers[1], wide_alone);
    }

    /// The probe proves touching tori close (a triangle pair within the threshold) within
    /// its visits, where the rounds alone would first reach a leaf pair much later.
    #[test]
    fn the_probe_proves_a_touching_pair_close_within_its_visits() {
        let (a, b, poses) = scene::<Obb>();
        let touching = pairs(&a, &b, &poses[..1]);
        let proven =
            |x: &[FrontierAnswer]| x[0].distance_upper.is_some_and(|d| d <= x[0].threshold);
        let (at, answers) = visits_until(&touching, proven);
        // The root's bound, the probe, and the leaf pair it was testing when it ended.
        assert!(at <= 1 + PROBE_VISITS + 16, "{at}");
        assert!(answers[0].is_exact() && answers[0].maybe_close);
        let total = {
            let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
            query_frontier(&touching, &mut Unlimited, &mut ws, &mut out);
            ws.stats().visits
        };
        assert!(4 * at < total, "proven after {at} of {total} visits");
    }

    /// In stages, a pair that a few levels settle is not kept waiting by a wide one: the
    /// tori a little apart (pair 1) are answered exactly after under half the visits they
    /// wait in plain rounds, no pair later, and the final answers are the same.
    #[test]
    fn in_stages_a_narrow_pair_is_settled_before_a_wide_one_finishes() {
        let (a, b, poses) = scene::<Obb>();
        let pairs = pairs(&a, &b, &poses);
        let (plain, plain_answers) = settled_after(&pairs, RoundOrder::SmallestBound);
        let (staged, staged_answers) = settled_after(&pairs, RoundOrder::CheapestPairsFirst);
        assert!(
            2 * staged[1] < plain[1],
            "staged {staged:?}, plain {plain:?}"
        );
        assert!(
            staged.iter().zip(&plain).all(|(s, p)| s <= p),
            "{staged:?} {plain:?}"
        );
        assert_eq!(staged_answers, plain_answers);
    }

    #[test]
    fn an_empty_frame_finishes_at_once() {
        let pairs: [FrontierPair<'_, Obb>; 0] = [];
        let (mut ws, mut out) = (FrontierWorkspace::new(), vec![]);
        assert!(query_frontier(
            &pairs,
            &mut VisitBudget(0),
            &mut ws,
            &mut out
        ));
        assert!(out.is_empty() && ws.is_finished());
        assert_eq!(ws.stats().visits, 0);
    }

    #[test]
    fn single_triangle_meshes_are_answered_from_their_root_pair() {
        use crate::geometry::Triangle;
        let tri = Triangle::new(DVec3::ZERO, DVec3::X, DVec3::Y);
        let t = Bvh::<Obb>::from_triangles(&[tri], &BuildParams::MEDIAN);
        let pairs = [0.5, 2.0].map(|z| FrontierPair {
            a: &t,
            b: &t,
            pose_ab: Isometry::from_translation(DVec3::new(0.0, 0.0, z)),
            threshold: 1.0,
            seed: None,
        });
        let (mut ws, mut out) = (FrontierWorkspace::new(), vec![]);
        assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut out));
        // One bound per root, then one triangle test for the pair within threshold.
        assert_eq!(ws.stats().bv_tests, 2);
        assert_eq!(ws.stats().triangle_tests, 1);
        assert_eq!(ws.stats().rounds, 1);
        assert!(out[0].maybe_close && out[0].is_exact());
        let exact = distance_triangle_triangle(&tri, &tri.transformed(&pairs[0].pose_ab));
        assert_eq!(out[0].distance_lower, exact.distance);
        assert!((exact.distance - 0.5).abs() <= out[0].error_bound);
        assert!(!out[1].maybe_close && out[1].is_exact());
        assert!(out[1].distance_lower > 1.0 && out[1].distance_lower <= 2.0);
        assert_eq!(out[1].distance_upper, None);
        assert!(2.0 <= out[1].distance_lower + out[1].error_bound);
    }
}
