//! The budgeted breadth-first frontier: one global list of `(pair, node of A, node of B)`
//! entries over *all* mesh pairs of a frame, refined round by round under a [`Budget`], so
//! every pair degrades together when time runs out (DESIGN §5; Hubbard 1996, Dingliana &
//! O'Sullivan 2000).
//!
//! # The question
//! Each [`FrontierPair`] asks: *is the distance between the triangles of `a` and of `b`
//! (placed at `pose_ab`) at most `threshold` (metres), and if so, what is it?* The frontier
//! sees a pair only through [`PairTrees`], so one run may hold pairs of different volume
//! types.
//!
//! # The traversal
//! [`FrontierWorkspace::start`] puts one root entry per pair on the frontier. A round
//! takes its entries in increasing order of their distance lower bound (ties by pair, node
//! of A, node of B: deterministic). An entry beyond `threshold`, or not below the pair's
//! best exact distance so far, is dropped; two leaves run
//! [`distance_triangle_triangle`](crate::narrow::distance_triangle_triangle) on each
//! triangle pair; any other entry is replaced by its children on the side
//! [`descend_a`](crate::bvh::tandem::descend_a) picks, each with the larger of its own and
//! its parent's bound, joining the next round. Each bound and triangle test is one *visit*.
//! - **The probe.** A pair not yet proven close is first searched depth-first for a
//!   triangle pair within its threshold, for at most [`PROBE_VISITS`] visits
//!   ([`EXPECTED_PROBE_VISITS`] for a pair whose seed, last frame's proof, no longer holds);
//!   the entries left on its stack join the next round, so no visit is lost.
//! - **Decide first.** While a pair not proven close has entries waiting, the entries of
//!   pairs proven close wait, and so do the roots of pairs expected close until the stages
//!   reach [`EXPECTED_JOIN_CAP`]: only the first part of the question changes which pairs
//!   a frame reports.
//! - **Stages by width** ([`RoundOrder::CheapestPairsFirst`], the default): stage `k`
//!   refines only the pairs with at most `FIRST_CAP · 2ᵏ` entries in their round and sets
//!   the others aside, so the pairs cheapest to settle are settled first.
//!
//! The budget is polled between entries once at least `poll_every` visits
//! ([`DEFAULT_POLL_EVERY`]) were made since the last poll, never inside a triangle test.
//! When it refuses, [`FrontierWorkspace::run`] returns; calling it again resumes exactly
//! where it stopped, so a resumed run and a fresh run with the larger budget agree.
//!
//! # The answers ([`FrontierAnswer`])
//! - **Exact** when the pair has no live entry: its best triangle distance when within the
//!   threshold (the minimum over all triangle pairs), else proven apart.
//! - **Truncated { level }** otherwise, `level` the shallowest waiting depth: `maybe_close`
//!   (never reported apart before proven apart), `distance_lower` the smallest bound over
//!   its live, dropped and tested entries, a lower bound of the true distance.
//!
//! `distance_lower ≤ true ≤ distance_lower + error_bound`, the upper end from the best
//! triangle distance and each live entry's centres and stand-offs. More budget never makes
//! an answer worse: bounds only grow along a descent. `examples/time_vs_error` measures
//! precision against time; `benches/frontier.rs` the cost per visit.
//!
//! # Cost outside visits
//! Each round is sorted when it begins (`O(n log n)`, not polled); a set-aside entry is
//! sorted again in each stage it waits through. [`FrontierWorkspace::answers`] reads every
//! waiting entry. Neither is polled, so each poll tells the budget how many entries wait
//! ([`Budget::allows_pending`]): a wall-clock budget reserves their sort and answers, and
//! the frontier stops growing before extracting its answers would overrun the deadline.
//!
//! # Allocation
//! The workspace owns the two entry vectors (swapped every round), the per-pair state and
//! the per-round counters; none of them allocates once grown to the largest frame seen.
mod mesh_pair;
mod trees;

pub use mesh_pair::MeshPairTrees;
pub use trees::{FrontierPair, PairTrees, TreesAt};

use crate::budget::{Budget, Completeness};
use crate::math::DVec3;
use std::cmp::Ordering;

/// Visits between two budget polls unless set with [`FrontierWorkspace::with_poll_every`].
///
/// A poll of a [`Deadline`](crate::budget::Deadline) reads the clock (about 25 ns); a
/// visit costs 0.1 µs (a volume bound) to 0.5 µs (a triangle test): polling every 8 visits
/// keeps a run within a few microseconds of its deadline (`examples/time_vs_error`).
pub const DEFAULT_POLL_EVERY: u64 = 8;

/// Most visits of a pair's depth-first probe for a triangle pair within its threshold
/// (module docs, "The probe").
pub const PROBE_VISITS: u64 = 64;

/// Most visits of the probe of a pair expected close (module docs, "Decide first"): most
/// such pairs are still close, and one proven close waits, then passes its proof on as
/// next frame's seed; a longer probe pays where a short one would stop just short of the
/// proof (`examples/time_vs_error`, precision at counted budgets).
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

/// The frontier's answer for one pair, and why it is conservative.
///
/// A pair's *live* entries are its entries still waiting whose bound is at most `threshold`
/// and below its best exact distance. Write `best` for the smallest triangle-pair distance
/// computed so far (`+∞` when none), `floor` for the smallest bound of its entries dropped
/// for exceeding `threshold`, `live` for the smallest bound of its live entries.
/// - **Exact** when it has no live entry. If `best ≤ threshold`, `best` *is* the minimum
///   over all triangle pairs (every triangle pair lies under a dropped entry, a tested leaf
///   pair or an entry that could not beat `best`): `maybe_close`, `distance_lower =
///   distance_upper = best`, witnesses of that pair, `error_bound` = rounding. Otherwise
///   the pair is proven apart: `!maybe_close`, `distance_lower = min(floor, best) >
///   threshold`.
/// - **Truncated { level }** while it has live entries, `level` the shallowest depth
///   (descents from the root pair) among them: `maybe_close = true` (a pair is never
///   reported apart before it is proven apart, so there is no false negative),
///   `distance_lower = min(live, floor, best)`, a lower bound of the true distance because
///   every triangle pair lies under one of those three.
///
/// The *reported* distance is always `distance_lower` ([`FrontierAnswer::distance`]): never
/// more than the true distance (a truncated answer errs on the side of "closer"). The error
/// bound states how much closer at most: `error_bound = upper − distance_lower + rounding`,
/// with `upper` the smallest of `best` and, for the root pair and every live entry `(X, Y)`,
/// `|centre(X) − centre(Y)| + stand_off(X) + stand_off(Y)` — some point of each mesh lies
/// within its volume's stand-off of the volume's centre, so the true distance is at most
/// that. Hence `distance_lower ≤ true ≤ distance_lower + error_bound`, and
/// `true ≤ distance_upper` whenever a leaf pair was tested. For the thresholded question
/// alone, [`FrontierAnswer::clamped_error_bound`] bounds the error of `min(distance,
/// threshold)`.
///
/// More budget never makes an answer worse: processing an entry replaces its bound by
/// larger ones or by exact distances not below it (volume bounds are padded below the true
/// distance by more than the rounding of a triangle distance), so `distance_lower` never
/// decreases, and an Exact pair has nothing left to change.
///
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
/// [`RoundOrder::CheapestPairsFirst`] processes; each stage doubles it (the best of the
/// caps and growths `examples/time_vs_error --scene robot-chain` compares at small
/// budgets).
pub const FIRST_CAP: u32 = 2;

/// The stage cap at which the roots of pairs expected close stop waiting for the deciding
/// phase to end and join it (module docs, "Decide first"): late enough that the narrow
/// pairs are settled first, early enough that a stale seed's pair is not left undecided
/// (`examples/time_vs_error`).
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
                if !budget.allows_pending(self.stats.visits, self.waiting() as u64) {
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
///
/// # Example
/// ```
/// use proxima::bounding::Obb;
/// use proxima::budget::VisitBudget;
/// use proxima::narrow::mesh_mesh::frontier::{FrontierPair, FrontierWorkspace, query_frontier};
/// use proxima::bvh::{BuildParams, Bvh};
/// use proxima::geometry::TriMesh;
/// use proxima::math::{DVec3, Isometry};
///
/// let torus = Bvh::<Obb>::from_mesh(&TriMesh::torus(1.0, 0.3, 16, 8), &BuildParams::BINNED_SAH);
/// let pairs = [FrontierPair {
///     a: &torus,
///     b: &torus,
///     pose_ab: Isometry::from_translation(DVec3::new(2.65, 0.0, 0.0)),
///     threshold: 0.1,
///     seed: None,
/// }];
/// let (mut workspace, mut answers) = (FrontierWorkspace::new(), Vec::new());
/// // A small budget: a truncated, conservative answer.
/// query_frontier(&pairs, &mut VisitBudget(40), &mut workspace, &mut answers);
/// assert!(answers[0].maybe_close && !answers[0].is_exact());
/// // Resume without limit: the exact answer (the tori are 0.05 m apart).
/// assert!(workspace.run(&pairs, &mut VisitBudget(u64::MAX)));
/// workspace.answers(&pairs, &mut answers);
/// assert!(answers[0].is_exact() && answers[0].maybe_close);
/// assert!((answers[0].distance() - 0.05).abs() < 1e-2);
/// ```
///
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
mod tests;
