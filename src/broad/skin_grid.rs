//! Skin grid: the [`ColumnGrid`] over every body's box grown by a *skin*, with each body's
//! skin neighbours listed, so that a body that moves within its grown box re-tests only
//! the few bodies on its list, and the grid hears of it only when it leaves that box
//! (Verlet lists in molecular dynamics, fat boxes in Bullet's dynamic tree).
//!
//! # Invariants
//! - Every body's true box lies inside its *fat box*: its box when last filed, grown on
//!   every side by a skin sized at that filing (`Record::refile`). The grid holds the fat
//!   boxes.
//! - The *skin neighbours* are the pairs of overlapping fat boxes that may pair, listed on
//!   both sides, each entry flagged with whether the two true boxes overlap now. As every
//!   true box lies inside its fat box, two overlapping true boxes are neighbours: the
//!   flagged neighbours, the pairs reported, are exactly those of
//!   [`pairs_brute_force`](super::pairs_brute_force).
//! - Two boxes keep their relation (overlapping or apart) while their corners move less, in
//!   total, than the pair's *room*. Each pair shares its room between its two bodies as
//!   budgets of travel (`Share`), and what the two may still travel without a re-test fits
//!   in the room the pair has now.
//!
//! [`SkinGrid`]'s docs list every invariant its `validate` checks.
//!
//! # A move
//! - Inside its fat box: the body's travel grows by the move, and it re-tests only the
//!   neighbours whose budget that spends, logging the pairs whose overlap changed.
//! - Out of it: the body is filed again under a new fat box (a column grid move, whose pair
//!   changes add and remove neighbours), then re-tests all its neighbours.
//!
//! # Costs (`d` neighbours a body has)
//! - A move inside the skin: `O(d)` budget checks on the body's own record (fat box and
//!   first neighbours side by side), and a box test for each pair due, reading the
//!   neighbour's box.
//! - A move out of it: a column grid move of the fat box ([`ColumnGrid`]'s costs), a
//!   re-test of every neighbour, constant work per neighbour gained, and per neighbour lost
//!   a search of the shorter of the two lists.
//!
//! # When to choose it
//! When few bodies move, or they creep for their size ([`choose`](super::choose)). Every
//! teleport leaves its skin: the [`ColumnGrid`] alone is the better choice then.

use super::body_map::Bodies;
use super::column_grid::ColumnGrid;
use super::pair_set::PairSet;
use super::stateful::{StatefulBroadPhase, stateful_api};
use super::{CandidatePair, Proxy, debug_assert_valid_bounds};
use crate::bounding::{Aabb, BoundingVolume};
use crate::math::{DVec3, splitmix64};
use std::collections::{BTreeMap, VecDeque};

/// Skin on every side of a box filed for the first time, as a fraction of its largest
/// extent, within the room of its grid level (`Record::first`). Not spread as
/// [`SKIN_SPREAD`] spreads refilings: a thicker first skin would bridge gaps a resting body
/// never crosses.
pub const FIRST_SKIN: f64 = 0.1;
/// Frames a refiled box's skin reaches ahead of its motion, at the velocity the body
/// moved at since it was last filed (`Record::refile` sizes the skin), within [`MAX_SKIN`]
/// and the level's room: at 64, a body moving steadily gets about the most those allow.
/// Fewer refilings (each a column-grid query) outweigh the neighbours the longer skins
/// add (`examples/broad_bench`, `--speed-scale`).
pub const SKIN_FRAMES: f64 = 64.0;
/// Smallest skin ahead of a refiled box's motion, as a fraction of its largest extent.
///
/// A slow body is better served by a skin many frames thick, as a refiling (a column-grid
/// query over the fat box) costs as much as re-testing dozens of neighbours; a thicker one
/// bridges gaps the body never crosses (`examples/broad_bench`).
pub const MIN_SKIN: f64 = 0.1;
/// Skin behind a refiled box's motion, and on the axes it does not move along, as a
/// fraction of its largest extent: room to turn back or drift sideways.
pub const BACK_SKIN: f64 = 0.05;
/// Largest growth of a refiled box along an axis, as a fraction of its largest extent on
/// either side: its skin behind and ahead together are at most twice this.
///
/// Bodies fast for their size reach this cap before [`SKIN_FRAMES`] of motion, so it sets
/// how often they are refiled (`examples/broad_bench`, clustered layout).
pub const MAX_SKIN: f64 = 2.0;
/// Width of the spread of skin thicknesses: each refiling's [`SKIN_FRAMES`] is divided by
/// a number drawn uniformly from `[1 − SKIN_SPREAD / 2, 1 + SKIN_SPREAD / 2)`
/// by a hash of the body's id and the batch (`skin_factor`). Dividing, not
/// multiplying: a body leaves its skin at a rate inversely proportional to its thickness,
/// so the mean rate of refilings stays what [`SKIN_FRAMES`] asks for.
///
/// Without it, bodies that start moving together leave their skins together, every few
/// frames, for as long as they keep their speeds: the spread shortens the frame-time tail
/// (`examples/broad_bench`, p99).
pub const SKIN_SPREAD: f64 = 1.0;

/// The factor [`SKIN_SPREAD`] draws for `body`'s filing in batch `batch`: one over a hash
/// of the two mapped to `[1 − SKIN_SPREAD / 2, 1 + SKIN_SPREAD / 2)`; the same for the same
/// inputs, so runs are repeatable.
fn skin_factor(body: u32, batch: u32) -> f64 {
    let x = splitmix64(u64::from(body) << 32 | u64::from(batch));
    let unit = (x >> 11) as f64 / (1u64 << 53) as f64;
    1.0 / (1.0 + SKIN_SPREAD * (unit - 0.5))
}

/// A body's neighbour: another body whose fat box overlaps its own. Each pair is listed
/// on both sides, each entry knowing where its twin is, so that a body with thousands of
/// neighbours (a floor under a field of dice) updates or drops one in constant time.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Neighbour {
    /// The neighbour's slot.
    slot: u32,
    /// Where the twin entry is in the neighbour's list.
    twin: u32,
    /// The owner's [`Record::travel`] from which the pair is due a re-test when the owner
    /// moves: where its share of the pair's budget runs out ([`Share`]); `−∞` on the side
    /// that does not hold the pair's budget: any move re-tests.
    due_at: f32,
    /// This side's share of the pair's budget: the twins hold `Whole` and `None`, or
    /// `Half` each.
    share: Share,
    /// Whether the two true boxes overlap (the pair is in the pair set).
    overlaps: bool,
}

/// A side's share of a pair's budget. Two boxes keep their relation while their corners
/// move less, in total, than the pair's room ([`relation`]), so each pair shares its room
/// between its two bodies as budgets: each entry's [`Neighbour::due_at`] is the
/// [`Record::travel`] of its owner at which its share runs out, and a move re-tests only
/// the entries it has made due. The shares follow who moves ([`SkinGrid::retest`]):
/// - a pair whose bodies rest but for one gives it the *whole* room, and the resting side
///   is always due: a re-test by the mover renews its own entry only, and writes the twin
///   only when the overlap changed. A body moving among resting ones therefore reads its
///   own record and, for the few pairs due, its neighbours' boxes, and nothing else of
///   theirs;
/// - when the other side moves (it is always due), its re-test splits the room, *half*
///   each, writing both entries, if the holder moved in this batch or the last; so does
///   every re-test of a pair split so. If the holder rests, the re-tester takes it all
///   instead. Halves only where both sides move: a split pair's every re-test writes both
///   lists.
///
/// A new pair gives the whole room to the body refiled in the batch, the mover
/// ([`SkinGrid::apply_grid_edits`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
enum Share {
    /// Always due: the twin holds the whole budget.
    #[default]
    None,
    /// Half the room; the twin holds the other half.
    Half,
    /// The whole room; the twin is always due.
    Whole,
}

impl Share {
    /// The twin's share.
    fn twin(self) -> Self {
        match self {
            Self::None => Self::Whole,
            Self::Half => Self::Half,
            Self::Whole => Self::None,
        }
    }
}

/// What a body keeps besides its true box: its fat box and its neighbours.
#[derive(Debug, Clone)]
struct Record {
    fat: Aabb,
    /// The batch the box was last filed in.
    filed_at: u32,
    /// The centre of the true box when last filed (metres).
    filed_centre: DVec3,
    /// How far the body's box has travelled (metres, rounded up): the sum over its moves of
    /// the largest change of a corner coordinate. Set back to 0 now and then, its entries'
    /// [`Neighbour::due_at`] with it ([`REBASE_AFTER_EXTENTS`]).
    travel: f32,
    /// The batch the body last moved in (or was inserted in).
    moved_at: u32,
    list: Neighbours,
}

impl Record {
    /// A body filed for the first time with box `bounds`, in batch `batch`, in a grid whose
    /// level for it reaches `reach` metres: [`FIRST_SKIN`] of its largest extent on every
    /// side, within the room below `reach` ([`grown_within`]).
    fn first(bounds: &Aabb, batch: u32, reach: f64) -> Self {
        let skin = DVec3::splat(FIRST_SKIN * bounds.extents().max_element());
        Self {
            fat: grown_within(bounds, skin, skin, reach),
            filed_at: batch,
            filed_centre: bounds.center(),
            travel: 0.0,
            moved_at: batch,
            list: Neighbours::default(),
        }
    }

    /// Files the body again with box `bounds` in batch `batch`, its skin sized anew, per
    /// axis and side, from the velocity of its centre since the last filing:
    /// - *ahead* of the motion along an axis, as far as that velocity goes in `factor` ×
    ///   [`SKIN_FRAMES`] batches plus the skin behind, at least [`MIN_SKIN`] of the box's
    ///   largest extent;
    /// - *behind* it, and on an axis it does not move along, [`BACK_SKIN`];
    /// - the two together at most twice [`MAX_SKIN`];
    /// - all within the room below `reach`, the reach of the grid level the true box belongs
    ///   at ([`grown_within`]): a bigger fat box would be filed one level up, where every
    ///   query of the level below meets it. An axis without the room shares it in
    ///   proportion.
    ///
    /// A thick skin means few refilings but more neighbours; a skin where the body is not
    /// going is wasted. `factor` is [`skin_factor`]'s draw ([`SKIN_SPREAD`]).
    fn refile(&mut self, bounds: &Aabb, batch: u32, reach: f64, factor: f64) {
        let centre = bounds.center();
        let batches = f64::from(batch.wrapping_sub(self.filed_at).max(1));
        let ahead = (centre - self.filed_centre) * (factor * SKIN_FRAMES / batches);
        let extent = bounds.extents().max_element();
        let back = BACK_SKIN * extent;
        let front = (DVec3::splat(back) + ahead.abs()).clamp(
            DVec3::splat(MIN_SKIN * extent),
            DVec3::splat(2.0 * MAX_SKIN * extent - back),
        );
        let below = DVec3::select(ahead.cmplt(DVec3::ZERO), front, DVec3::splat(back));
        let above = DVec3::select(ahead.cmpgt(DVec3::ZERO), front, DVec3::splat(back));
        self.fat = grown_within(bounds, below, above, reach);
        self.filed_at = batch;
        self.filed_centre = centre;
        // Its neighbours are all re-tested after the refiling, which sets their budgets.
        self.travel = 0.0;
    }

    /// Sets the travel back to 0, every entry's budget with it (rounded down).
    fn rebase(&mut self) {
        let travel = f64::from(self.travel);
        for i in 0..self.list.len() {
            let entry = &mut self.list[i];
            entry.due_at = ((f64::from(entry.due_at) - travel) as f32).next_down();
        }
        self.travel = 0.0;
    }
}

/// `bounds` grown by `below` under its low corner and `above` over its high one (per
/// axis, metres, `≥ 0`), the growth cut to what keeps each axis's extent of the grown box,
/// as computed, within `reach` (at least that of `bounds`): an axis with too little room
/// is grown in proportion on its two sides.
///
/// The cut to the room is not enough on its own: the grown box's corners and its extent
/// are rounded, and a box whose skin fills its room exactly came out a few ulps wider than
/// `reach`. The column grid then filed it one level up, where every query of its own level
/// meets it, and such bodies pile up there. So the extents are checked as the grid computes them, and the
/// growth cut by the excess until it fits (once, in practice; no growth at all fits, as
/// `bounds` does).
fn grown_within(bounds: &Aabb, below: DVec3, above: DVec3, reach: f64) -> Aabb {
    debug_assert!(bounds.extents().max_element() <= reach);
    let room = DVec3::splat(reach) - bounds.extents();
    let total = below + above;
    let share = DVec3::select(total.cmpgt(room), room / total, DVec3::ONE);
    let (mut below, mut above) = (below * share, above * share);
    // A cut smaller than the corners' rounding may change nothing: cut at least that.
    let magnitude = bounds.min.abs().max(bounds.max.abs()).max_element() + total.max_element();
    for _ in 0..4 {
        let fat = Aabb::new(bounds.min - below, bounds.max + above);
        let excess = fat.extents() - DVec3::splat(reach);
        if excess.cmple(DVec3::ZERO).all() {
            return fat;
        }
        let cut = DVec3::select(
            excess.cmpgt(DVec3::ZERO),
            excess.max(DVec3::splat(4.0 * f64::EPSILON * magnitude)),
            DVec3::ZERO,
        );
        below = (below - cut).max(DVec3::ZERO);
        above = (above - cut).max(DVec3::ZERO);
    }
    *bounds
}

/// How many moves ahead a batch's retests prefetch a move's record, in grids of
/// [`PREFETCH_FROM_BODIES`] bodies or more.
const PREFETCH_AHEAD: usize = 4;
/// Fewest bodies for which a batch's retests prefetch (below, the records and boxes stay
/// in the caches).
const PREFETCH_FROM_BODIES: usize = 30_000;

/// Re-tests a batch keeps waiting while what they read is fetched, in grids large enough
/// to prefetch ([`PREFETCH_FROM_BODIES`]); in smaller ones each re-test runs at once
/// ([`SkinGrid::queue_retest`]).
const RETEST_AHEAD: usize = 8;

/// A body's travel is set back to 0 once it exceeds this many extents of its fat box, so
/// that the `f32` travel and budgets keep their precision (a body jittering inside its
/// skin forever).
const REBASE_AFTER_EXTENTS: f32 = 1024.0;

/// Entries a neighbour list holds in place before it spills to the heap.
const INLINE: usize = 4;

/// A neighbour list: the first [`INLINE`] entries in place (most bodies have no more:
/// 2.0–3.5 on average in the measured layouts), the rest in `spill`, so a move reads its
/// list from the record it reads its fat box from.
#[derive(Debug, Clone, Default)]
struct Neighbours {
    len: u32,
    inline: [Neighbour; INLINE],
    spill: Vec<Neighbour>,
}

impl Neighbours {
    fn len(&self) -> usize {
        self.len as usize
    }

    fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Bit `i` set when in-place entry `i` is due at `travel`: every in-place entry
    /// compared at once, without a branch.
    fn inline_due(&self, travel: f32) -> u32 {
        let mut due = 0;
        for (k, entry) in self.inline.iter().enumerate() {
            due |= u32::from(entry.due_at <= travel) << k;
        }
        due & ((1 << self.len().min(INLINE)) - 1)
    }

    fn push(&mut self, entry: Neighbour) {
        if self.len() < INLINE {
            self.inline[self.len()] = entry;
        } else {
            self.spill.push(entry);
        }
        self.len += 1;
    }

    /// Removes entry `i`, the last entry taking its place.
    fn swap_remove(&mut self, i: usize) {
        let last = self.len() - 1;
        self[i] = self[last];
        if last >= INLINE {
            self.spill.pop();
        }
        self.len -= 1;
    }

    /// Where entry `i` sits in memory, for a prefetch: found without reading the spill
    /// list's header when in place; the record's start otherwise.
    fn entry_address(&self, i: usize) -> *const Neighbour {
        self.inline.as_ptr().wrapping_add(i.min(INLINE - 1))
    }

    fn iter(&self) -> impl Iterator<Item = &Neighbour> {
        self.inline[..self.len().min(INLINE)]
            .iter()
            .chain(&self.spill)
    }
}

impl std::ops::Index<usize> for Neighbours {
    type Output = Neighbour;

    fn index(&self, i: usize) -> &Neighbour {
        debug_assert!(i < self.len());
        if i < INLINE {
            &self.inline[i]
        } else {
            &self.spill[i - INLINE]
        }
    }
}

impl std::ops::IndexMut<usize> for Neighbours {
    fn index_mut(&mut self, i: usize) -> &mut Neighbour {
        debug_assert!(i < self.len());
        if i < INLINE {
            &mut self.inline[i]
        } else {
            &mut self.spill[i - INLINE]
        }
    }
}

/// The skin grid (see the [module docs](self)).
///
/// # Invariants (checked by [`validate`](SkinGrid::validate))
/// - Every body's true box lies inside its fat box, and the grid holds exactly the fat
///   boxes (its own invariants hold).
/// - The neighbour lists are symmetric, and hold exactly the pairs of overlapping fat
///   boxes that may pair, each once per side; an entry's overlap flag says whether the
///   true boxes overlap.
/// - The two entries of a pair share its budget as whole and none (the latter always
///   due) or half each, and what the two may still travel fits in the pair's room now.
/// - The pair set is exactly the flagged neighbours: the brute-force pairs of the true
///   boxes.
#[derive(Debug, Clone, Default)]
pub struct SkinGrid {
    /// The fat boxes, filed; its pair edits are taken as neighbour changes.
    grid: ColumnGrid,
    /// The true boxes by slot, and each id's slot.
    bodies: Bodies,
    /// Per slot: the fat box the grid holds and the skin neighbours, side by side (a move
    /// reads both).
    records: Vec<Record>,
    /// The pairs of overlapping true boxes.
    pairs: PairSet,
    /// Scratch: a batch's moves out of the skin, and the grid's pair edits.
    refiled: Vec<(u32, Aabb)>,
    edits: Vec<(CandidatePair, bool)>,
    /// Scratch: the slots a batch refiled.
    refiled_slots: Vec<u32>,
    /// Scratch: pair re-tests waiting while what they read is fetched, as `(slot, entry)`.
    pending: VecDeque<(u32, u32)>,
    /// Batches of moves so far ([`update_all`](Self::update_all) calls), the clock the
    /// skins are sized by.
    batch: u32,
}

impl SkinGrid {
    /// An empty skin grid.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A skin grid holding `proxies` (distinct ids).
    #[must_use]
    pub fn from_proxies(proxies: &[Proxy]) -> Self {
        let mut skin = Self::new();
        let fat: Vec<Proxy> = proxies
            .iter()
            .map(|p| {
                debug_assert_valid_bounds(&p.bounds);
                skin.bodies.push(*p);
                let record = Record::first(&p.bounds, 0, f64::INFINITY);
                let bounds = record.fat;
                skin.records.push(record);
                Proxy { bounds, ..*p }
            })
            .collect();
        skin.grid = ColumnGrid::from_proxies(&fat);
        skin.apply_grid_edits();
        skin
    }

    /// [`update`](Self::update) of every `(body, bounds)` in `moves`; a body listed twice
    /// ends at its last box. The moves out of the skin go to the column grid as one batch.
    ///
    /// # Allocation
    /// None once the scratch buffers and the neighbour lists have grown to their peaks.
    pub fn update_all(&mut self, moves: &[(u32, Aabb)]) {
        self.refiled.clear();
        self.refiled_slots.clear();
        self.batch = self.batch.wrapping_add(1);
        let prefetching = self.bodies.len() >= PREFETCH_FROM_BODIES;
        for (k, &(body, bounds)) in moves.iter().enumerate() {
            debug_assert_valid_bounds(&bounds);
            if prefetching {
                self.prefetch_move(moves, k + PREFETCH_AHEAD);
            }
            let Some(slot) = self.bodies.slot(body) else {
                debug_assert!(false, "update of absent body {body}");
                continue;
            };
            let old = std::mem::replace(&mut self.bodies.proxies[slot].bounds, bounds);
            let record = &mut self.records[slot];
            record.travel = travelled(record.travel, &old, &bounds);
            record.moved_at = self.batch;
            if encloses(&record.fat, &bounds) {
                self.queue_due(slot, prefetching);
            } else {
                let reach = self.grid.level_reach(bounds.extents().max_element());
                record.refile(&bounds, self.batch, reach, skin_factor(body, self.batch));
                self.refiled.push((body, record.fat));
                self.refiled_slots.push(slot as u32);
            }
        }
        self.run_retests(0);
        if self.refiled.is_empty() {
            return;
        }
        self.grid.update_all(&self.refiled);
        self.apply_grid_edits();
        // A refiled body re-tests every neighbour: its list changed, and its travel
        // started again from 0.
        for k in 0..self.refiled_slots.len() {
            let slot = self.refiled_slots[k] as usize;
            for i in 0..self.records[slot].list.len() {
                self.queue_retest(slot, i, prefetching);
            }
        }
        self.run_retests(0);
    }

    /// Takes the grid's pair edits (neighbours gained and lost, in order) into the lists,
    /// and the lost neighbours' overlapping pairs out of the pair set.
    fn apply_grid_edits(&mut self) {
        let mut edits = std::mem::take(&mut self.edits);
        edits.clear();
        self.grid.take_pair_edits(&mut edits);
        for &(pair, present) in &edits {
            let (Some(a), Some(b)) = (self.bodies.slot(pair.a), self.bodies.slot(pair.b)) else {
                debug_assert!(false, "a pair edit of an absent body: {pair:?}");
                continue;
            };
            if present {
                let (overlaps, room) = relation(
                    &self.bodies.proxies[a].bounds,
                    &self.bodies.proxies[b].bounds,
                );
                let (at_a, at_b) = (self.records[a].list.len(), self.records[b].list.len());
                // The budget goes to a body refiled in this batch: it re-tests all its
                // neighbours next, keeping a whole budget without writing the twin.
                let a_holds = self.records[a].filed_at == self.batch
                    || self.records[b].filed_at != self.batch;
                let share_a = if a_holds { Share::Whole } else { Share::None };
                let (due_a, due_b) = (
                    due_at(self.records[a].travel, room, share_a),
                    due_at(self.records[b].travel, room, share_a.twin()),
                );
                self.records[a].list.push(Neighbour {
                    slot: b as u32,
                    twin: at_b as u32,
                    due_at: due_a,
                    share: share_a,
                    overlaps,
                });
                self.records[b].list.push(Neighbour {
                    slot: a as u32,
                    twin: at_a as u32,
                    due_at: due_b,
                    share: share_a.twin(),
                    overlaps,
                });
                if overlaps {
                    self.pairs.insert(pair);
                }
            } else {
                // Searched in the shorter list; the twin is found from it.
                let (x, y) = if self.records[a].list.len() <= self.records[b].list.len() {
                    (a, b)
                } else {
                    (b, a)
                };
                let Some(i) = self.records[x]
                    .list
                    .iter()
                    .position(|e| e.slot as usize == y)
                else {
                    debug_assert!(false, "a lost neighbour that was not listed: {pair:?}");
                    continue;
                };
                let Neighbour { twin, overlaps, .. } = self.records[x].list[i];
                self.drop_entry(x, i);
                self.drop_entry(y, twin as usize);
                if overlaps {
                    self.pairs.remove(pair);
                }
            }
        }
        self.edits = edits;
    }

    /// Starts loading what the `k`-th move of `moves`, if any, first reads and writes: the
    /// body's record (its fat box) and its proxy.
    fn prefetch_move(&self, moves: &[(u32, Aabb)], k: usize) {
        if let Some(slot) = moves.get(k).and_then(|&(body, _)| self.bodies.slot(body)) {
            let record = (&raw const self.records[slot]).cast::<u8>();
            for line in (0..size_of::<Record>())
                .step_by(64)
                .chain([size_of::<Record>() - 1])
            {
                super::prefetch(record.wrapping_add(line));
            }
            super::prefetch(&raw const self.bodies.proxies[slot]);
        }
    }

    /// Queues the re-test of every entry of `slot`'s list that its travel has made due
    /// ([`Share`]), first setting its travel back to 0 if it has grown
    /// past [`REBASE_AFTER_EXTENTS`] fat-box extents.
    fn queue_due(&mut self, slot: usize, prefetching: bool) {
        let record = &mut self.records[slot];
        let extent = record.fat.extents().max_element() as f32;
        if record.travel > REBASE_AFTER_EXTENTS * extent {
            record.rebase();
        }
        let travel = record.travel;
        let len = record.list.len();
        let mut due = record.list.inline_due(travel);
        while due != 0 {
            let i = due.trailing_zeros() as usize;
            due &= due - 1;
            self.queue_retest(slot, i, prefetching);
        }
        for i in INLINE..len {
            if self.records[slot].list[i].due_at <= travel {
                self.queue_retest(slot, i, prefetching);
            }
        }
    }

    /// Queues the re-test of entry `i` of `slot`'s list, starting to fetch what it reads
    /// (the neighbour's box and its twin entry) when `prefetching`, and runs the re-tests
    /// queued [`RETEST_AHEAD`] re-tests before (all of them when not prefetching).
    fn queue_retest(&mut self, slot: usize, i: usize, prefetching: bool) {
        if !prefetching {
            // Nothing waits in the queue: the re-test runs at once.
            debug_assert!(self.pending.is_empty());
            self.retest(slot, i);
            return;
        }
        let Neighbour {
            slot: other, twin, ..
        } = self.records[slot].list[i];
        super::prefetch(&raw const self.bodies.proxies[other as usize]);
        super::prefetch(
            self.records[other as usize]
                .list
                .entry_address(twin as usize),
        );
        self.pending.push_back((slot as u32, i as u32));
        self.run_retests(RETEST_AHEAD);
    }

    /// Runs the queued re-tests, oldest first, until at most `left` wait.
    fn run_retests(&mut self, left: usize) {
        while self.pending.len() > left {
            let Some((slot, i)) = self.pending.pop_front() else {
                break;
            };
            self.retest(slot as usize, i as usize);
        }
    }

    /// Re-tests entry `i` of `slot`'s list against the two true boxes as they are now,
    /// logs the pair if its overlap changed, and renews the budget ([`Share`]): a side
    /// holding the whole of it keeps it, and writes the twin entry only when the overlap
    /// changed; a side that moved while the twin held all or half of it splits it, half
    /// each, if the twin moved in this batch or the last, and else takes it all; either way
    /// writing the twin.
    fn retest(&mut self, slot: usize, i: usize) {
        let Neighbour {
            slot: other,
            twin,
            share,
            overlaps,
            ..
        } = self.records[slot].list[i];
        let (p, q) = (
            &self.bodies.proxies[slot],
            &self.bodies.proxies[other as usize],
        );
        let (now, room) = relation(&p.bounds, &q.bounds);
        if now != overlaps {
            let pair = CandidatePair::of(p.body, q.body);
            if now {
                self.pairs.insert(pair);
            } else {
                self.pairs.remove(pair);
            }
        }
        let was = share;
        let share = match was {
            Share::Whole => Share::Whole,
            // Moving while the twin holds some: split while it moves too, else take all.
            _ if self
                .batch
                .wrapping_sub(self.records[other as usize].moved_at)
                <= 1 =>
            {
                Share::Half
            }
            _ => Share::Whole,
        };
        let due = due_at(self.records[slot].travel, room, share);
        let entry = &mut self.records[slot].list[i];
        (entry.overlaps, entry.due_at, entry.share) = (now, due, share);
        if now != overlaps || was != Share::Whole {
            let other = &mut self.records[other as usize];
            let due = due_at(other.travel, room, share.twin());
            let entry = &mut other.list[twin as usize];
            (entry.overlaps, entry.due_at, entry.share) = (now, due, share.twin());
        }
    }

    /// Drops entry `i` of `slot`'s list: the last entry moves into its place, and that
    /// entry's twin learns where it went.
    fn drop_entry(&mut self, slot: usize, i: usize) {
        let list = &mut self.records[slot].list;
        let last = list.len() - 1;
        list.swap_remove(i);
        if i != last {
            let Neighbour {
                slot: other, twin, ..
            } = list[i];
            self.records[other as usize].list[twin as usize].twin = i as u32;
        }
    }
}

stateful_api!(SkinGrid);

impl StatefulBroadPhase for SkinGrid {
    fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    fn bodies_mut(&mut self) -> &mut Bodies {
        &mut self.bodies
    }

    /// Its first fat box filed in the grid, whose pair edits list its neighbours.
    fn file(&mut self, slot: usize) {
        let p = self.bodies.proxies[slot];
        let extent = p.bounds.extents().max_element();
        let reach = self.grid.level_reach(extent);
        let record = Record::first(&p.bounds, self.batch, reach);
        let fat = record.fat;
        self.records.push(record);
        self.grid.insert(p.body, fat, p.is_static, p.filter);
        self.apply_grid_edits();
    }

    fn unfile(&mut self, slot: usize) {
        self.grid.remove(self.bodies.proxies[slot].body);
        self.apply_grid_edits();
        debug_assert!(self.records[slot].list.is_empty(), "all its pairs gone");
    }

    fn swap_remove_slot(&mut self, slot: usize) {
        let last = self.bodies.len() - 1;
        if slot != last {
            // The last slot moves into the freed one: its neighbours' entries follow.
            for i in 0..self.records[last].list.len() {
                let Neighbour {
                    slot: other, twin, ..
                } = self.records[last].list[i];
                self.records[other as usize].list[twin as usize].slot = slot as u32;
            }
        }
        self.records.swap_remove(slot);
    }

    /// A batch of one move ([`update_all`](SkinGrid::update_all)).
    fn relocate(&mut self, slot: usize, bounds: Aabb) {
        let body = self.bodies.proxies[slot].body;
        self.update_all(&[(body, bounds)]);
    }

    fn update_all(&mut self, moves: &[(u32, Aabb)]) {
        Self::update_all(self, moves);
    }

    fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        self.pairs.list(out);
    }

    /// Checks every invariant ([`SkinGrid`]'s docs).
    fn validate(&self) -> Result<(), String> {
        self.bodies.check()?;
        self.grid.validate_listing()?;
        let n = self.bodies.len();
        if self.records.len() != n || self.grid.len() != n {
            return Err(format!("{n} bodies, per-slot tables or grid disagree"));
        }
        let mut filed = Vec::with_capacity(n);
        for (slot, p) in self.bodies.proxies.iter().enumerate() {
            let record = &self.records[slot];
            if record.list.iter().count() != record.list.len() {
                return Err(format!("body {}: its list miscounts", p.body));
            }
            if !encloses(&record.fat, &p.bounds) {
                return Err(format!("body {} outside its fat box", p.body));
            }
            filed.push(Proxy {
                bounds: record.fat,
                ..*p
            });
        }
        let mut held: Vec<Proxy> = self.grid.proxies().to_vec();
        held.sort_by_key(|p| p.body);
        filed.sort_by_key(|p| p.body);
        if held != filed {
            return Err("the grid does not hold exactly the fat boxes".into());
        }
        let mut fat_pairs = Vec::new();
        super::pairs_brute_force(&filed, &mut fat_pairs);
        let mut listed = BTreeMap::new();
        for (slot, record) in self.records.iter().enumerate() {
            let p = &self.bodies.proxies[slot];
            for e in record.list.iter() {
                let q = self.bodies.proxies.get(e.slot as usize).ok_or(format!(
                    "body {} lists slot {} out of range",
                    p.body, e.slot
                ))?;
                let other = &self.records[e.slot as usize].list;
                let twin = (e.twin < other.len).then(|| other[e.twin as usize]);
                let Some(twin) = twin.filter(|t| {
                    t.slot as usize == slot && t.overlaps == e.overlaps && t.share == e.share.twin()
                }) else {
                    return Err(format!("{}–{}: the twin entry is wrong", p.body, q.body));
                };
                if e.overlaps != p.bounds.intersects(&q.bounds) {
                    return Err(format!("{}–{} overlap flag stale", p.body, q.body));
                }
                // What the two may still travel without a re-test must fit in the room
                // the pair has now (`Share`); the side without the budget re-tests on any
                // move.
                let left = |entry: &Neighbour, owner: usize| {
                    f64::from(entry.due_at) - f64::from(self.records[owner].travel)
                };
                let (_, room) = relation(&p.bounds, &q.bounds);
                let both = left(e, slot) + left(&twin, e.slot as usize);
                if both > room * (1.0 + 1e-9)
                    || (e.share == Share::None && e.due_at != f32::NEG_INFINITY)
                {
                    return Err(format!(
                        "{}–{}: budgets of {both} m left, {room} m of room",
                        p.body, q.body
                    ));
                }
                *listed.entry(CandidatePair::of(p.body, q.body)).or_insert(0) += 1;
            }
        }
        if let Some((pair, times)) = listed.iter().find(|&(_, &times)| times != 2) {
            return Err(format!("{pair:?} listed {times} times, not once per side"));
        }
        if !listed.keys().copied().eq(fat_pairs.iter().copied()) {
            return Err("neighbour lists differ from the fat boxes' pairs".into());
        }
        self.pairs.check_against_brute_force(&self.bodies.proxies)
    }
}

/// Whether `outer` holds all of `inner` (closed boxes): both of its corners.
fn encloses(outer: &Aabb, inner: &Aabb) -> bool {
    outer.contains_point(inner.min) && outer.contains_point(inner.max)
}

/// Relative allowance for rounding in the travel budgets: far more than the few roundings
/// of a coordinate difference, a sum and a conversion to `f32`. Travel and budgets are
/// `f32`, rounded towards re-testing: travel up ([`travelled`]), budgets down
/// ([`due_at`]).
const BUDGET_ROUNDING: f64 = 1e-6;

/// Whether boxes `a` and `b` overlap (touching counts, as [`Aabb::intersects`]), and their
/// *room* (metres, `≥ 0`): how far their corner coordinates may move in total, the two
/// together, before that can change. For overlapping boxes, the least overlap of their
/// intervals over the three axes (moving that far keeps them touching); for separate
/// ones, the widest gap between them on an axis (they stay apart while they move less).
fn relation(a: &Aabb, b: &Aabb) -> (bool, f64) {
    // Per axis, ≥ 0 exactly when the intervals meet (a difference of doubles is exact in
    // sign); its magnitude is the overlap or the gap.
    let slack = (b.max - a.min).min(a.max - b.min).min_element();
    debug_assert_eq!(slack >= 0.0, a.intersects(b));
    (slack >= 0.0, slack.abs())
}

/// The [`Neighbour::due_at`] of an entry with share `share` of a pair's budget, its
/// owner having travelled `travel` when the pair is tested with room `room`: that share of
/// the room ahead, rounded down ([`Share`]); `−∞` for no share. With
/// no room it is below `travel`: any move re-tests.
fn due_at(travel: f32, room: f64, share: Share) -> f32 {
    let fraction = match share {
        Share::None => return f32::NEG_INFINITY,
        Share::Half => 0.5,
        Share::Whole => 1.0,
    };
    let ahead = room * fraction * (1.0 - BUDGET_ROUNDING);
    ((f64::from(travel) + ahead) as f32).next_down()
}

/// A body's [`Record::travel`] after its box moved from `old` to `new`: `travel` plus the
/// largest change of a corner coordinate, rounded up.
fn travelled(travel: f32, old: &Aabb, new: &Aabb) -> f32 {
    let step = (new.min - old.min)
        .abs()
        .max((new.max - old.max).abs())
        .max_element();
    ((f64::from(travel) + step * (1.0 + BUDGET_ROUNDING)) as f32).next_up()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::CollisionFilter;
    use crate::broad::conformance;
    use crate::broad::pairs_brute_force;
    use crate::math::DVec3;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    fn random_filter(rng: &mut TestRng) -> CollisionFilter {
        CollisionFilter {
            group: 1 << rng.random_range(0..3),
            mask: rng.random_range(1..8),
        }
    }

    /// A box about a random point of the cube of half-size `spread` at `offset`: one in 16
    /// a point, one in 32 huge, the rest with half-extents log-uniform over 1 cm–1 m.
    fn random_box(rng: &mut TestRng, offset: DVec3, spread: f64) -> Aabb {
        let c = offset + point_in_cube(rng, spread);
        let h = match rng.random_range(0..32) {
            0 | 1 => DVec3::ZERO,
            2 => DVec3::splat(rng.random_range(5.0..30.0)),
            _ => DVec3::from_array(std::array::from_fn(|_| {
                rng.random_range(1e-2f64.ln()..0.0).exp()
            })),
        };
        Aabb::new(c - h, c + h)
    }

    /// A body stepping away from a resting neighbour and back into it: its entry is
    /// re-tested only when its travel has spent the pair's room (some steps skip the test,
    /// some do it), and the pair is reported exactly while the boxes overlap (validated
    /// against brute force every step).
    #[test]
    fn a_moving_body_retests_a_resting_neighbour_only_when_its_budget_runs_out() {
        let at = unit_cube_at;
        let mut skin = SkinGrid::new();
        skin.insert(1, at(0.0), false, CollisionFilter::ALL);
        skin.insert(2, at(1.05), true, CollisionFilter::ALL);
        let (mut skipped, mut retested, mut reported) = (0, 0, 0);
        let path = (0..=8)
            .chain((-2..=14).rev())
            .map(|k| 0.04 - 0.01 * f64::from(k));
        for x in path {
            let slot = skin.bodies.slot(1).expect("present");
            let before = skin.records[slot].list.iter().next().map(|e| e.due_at);
            skin.update(1, at(x));
            skin.validate().expect("valid");
            let after = skin.records[slot].list.iter().next().map(|e| e.due_at);
            match (before, after) {
                (Some(b), Some(a)) if a == b => skipped += 1,
                (Some(_), Some(_)) => retested += 1,
                _ => {}
            }
            let reported_now = reports_a_pair(&mut skin);
            assert_eq!(reported_now, at(x).intersects(&at(1.05)), "at x = {x}");
            reported += usize::from(reported_now);
        }
        assert!(
            skipped > 3 && retested > 3,
            "{skipped} skipped, {retested} re-tested"
        );
        assert!(reported > 0, "the boxes never met");
    }

    /// Two bodies stepping in turn towards each other and apart: the pair's budget is
    /// split once both move, and the pair is reported exactly while the boxes overlap
    /// (validated against brute force, shares and budgets included, every step).
    #[test]
    fn two_moving_neighbours_split_the_budget_and_stay_exact() {
        let at = unit_cube_at;
        let mut skin = SkinGrid::new();
        skin.insert(1, at(0.0), false, CollisionFilter::ALL);
        skin.insert(2, at(1.06), false, CollisionFilter::ALL);
        let (mut halves, mut met, mut apart) = (0, 0, 0);
        for step in 0..40 {
            // Closing in for 10 steps of 6 mm a side, then parting, and again.
            let phase = f64::from(step % 20);
            let offset = 0.006 * if phase < 10.0 { phase } else { 20.0 - phase };
            let (x1, x2) = (offset, 1.06 - offset);
            skin.update_all(&[(1, at(x1))]);
            skin.update_all(&[(2, at(x2))]);
            skin.validate().expect("valid");
            let slot = skin.bodies.slot(1).expect("present");
            let shares = skin.records[slot].list.iter().map(|e| e.share);
            halves += shares.filter(|&s| s == Share::Half).count();
            let overlap = at(x1).intersects(&at(x2));
            assert_eq!(reports_a_pair(&mut skin), overlap, "step {step}");
            (met, apart) = (met + usize::from(overlap), apart + usize::from(!overlap));
        }
        assert!(halves > 0 && met > 0 && apart > 0, "{halves} {met} {apart}");
    }

    /// A skin asked to fill (or overfill) its room gives a fat box no wider than the reach,
    /// as the grid computes extents, and enclosing the true box; the room is used to within
    /// rounding. Near the origin and far from it, where the rounding is largest; the cut is
    /// needed in some cases (else the test proves nothing).
    #[test]
    fn a_skin_filling_its_room_keeps_the_fat_box_at_its_level() {
        let mut rng = rng(808);
        let mut cut = 0;
        for case in 0..20_000 {
            let offset = [DVec3::ZERO, DVec3::new(1e7, -3e6, 2e5)][case % 2];
            let c = offset + point_in_cube(&mut rng, 100.0);
            let h = DVec3::from_array(std::array::from_fn(|_| rng.random_range(0.0..1.0)));
            let bounds = Aabb::new(c - h, c + h);
            let extent = bounds.extents().max_element();
            let reach = extent * rng.random_range(1.0..2.0);
            let room = 0.5 * (reach - extent);
            let skin = room * rng.random_range(0.9..1.5);
            let fat = grown_within(&bounds, DVec3::splat(skin), DVec3::splat(skin), reach);
            assert!(fat.extents().max_element() <= reach, "case {case}");
            assert!(encloses(&fat, &bounds), "case {case}");
            let wanted = skin.min(room);
            let tolerance = 1e-12 * (1.0 + offset.abs().max_element());
            assert!(
                fat.extents().max_element() >= extent + 2.0 * wanted - tolerance,
                "case {case}: room left unused"
            );
            cut += usize::from(bounds.grown(wanted).extents().max_element() > reach);
        }
        assert!(
            cut > 100,
            "the plain half-room skin overflowed only {cut} times"
        );
    }

    /// The unit cube moved `x` metres along x.
    fn unit_cube_at(x: f64) -> Aabb {
        Aabb::new(DVec3::X * x, DVec3::ONE + DVec3::X * x)
    }

    /// Whether `skin` reports any pair.
    fn reports_a_pair(skin: &mut SkinGrid) -> bool {
        let mut pairs = Vec::new();
        skin.pairs(&mut pairs);
        !pairs.is_empty()
    }

    #[test]
    fn a_removed_id_can_be_reinserted_with_new_bounds_kind_and_filter() {
        let mut skin = SkinGrid::new();
        conformance::removed_ids_come_back_with_new_bounds_kind_and_filter(
            &mut skin,
            Aabb::new(DVec3::splat(-9.0), DVec3::splat(-6.0)),
        );
        conformance::removing_every_body_empties_it(&mut skin);
    }

    #[test]
    fn static_bodies_never_pair_with_each_other_however_they_overlap() {
        let boxed = |rng: &mut TestRng| {
            let c = point_in_cube(rng, 1.0);
            let h = DVec3::splat(rng.random_range(0.0..1.0));
            Aabb::new(c - h, c + h)
        };
        conformance::static_bodies_never_pair_with_each_other(
            &mut SkinGrid::new(),
            &mut rng(806),
            100,
            boxed,
            10_000,
        );
    }

    /// Far from the origin and near it, seeded frames of bodies drifting at their own
    /// speeds (some jumping, some resizing), insertions and removals, each frame's moves
    /// applied one by one to one skin grid and as one batch (with repeated bodies) to
    /// another built at once, under a floor every body may touch: both validate against
    /// brute force every frame and agree. Moves inside the skin and refilings both happen,
    /// pairs appear and disappear, and the floor's neighbour list spills past its inline
    /// entries.
    #[test]
    fn one_by_one_and_batched_moves_agree_with_brute_force_as_skins_come_and_go() {
        let mut rng = rng(807);
        let (mut created, mut destroyed, mut repeated) = (0usize, 0usize, 0usize);
        let (mut inside, mut refiled, mut spilled) = (0usize, 0usize, false);
        for scene in 0..8 {
            let offset = [DVec3::ZERO, DVec3::new(1e7, -3e6, 2e5)][scene % 2];
            let spread = [4.0, 30.0, 10.0, 2.0][scene % 4];
            let floor = Proxy {
                body: 0,
                bounds: Aabb::new(
                    offset - DVec3::new(spread, spread, 0.2),
                    offset + DVec3::new(spread, spread, 0.0),
                ),
                is_static: true,
                filter: CollisionFilter::ALL,
            };
            let mut truth: Vec<Proxy> = std::iter::once(floor)
                .chain((0..150).map(|i| Proxy {
                    body: 3 * i + 1,
                    bounds: random_box(&mut rng, offset, spread),
                    is_static: rng.random_range(0..6) == 0,
                    filter: random_filter(&mut rng),
                }))
                .collect();
            let speeds: Vec<f64> = (0..1000)
                .map(|_| rng.random_range(0.0..0.1) * spread.sqrt())
                .collect();
            let mut single = SkinGrid::new();
            for p in &truth {
                single.insert(p.body, p.bounds, p.is_static, p.filter);
            }
            let mut batched = SkinGrid::from_proxies(&truth);
            let (mut before, mut a, mut b) = (Vec::new(), Vec::new(), Vec::new());
            single.pairs(&mut before);
            let mut moves = Vec::new();
            for frame in 0..40 {
                moves.clear();
                for p in truth.iter_mut().filter(|p| !p.is_static) {
                    if rng.random_range(0..3) == 0 {
                        continue;
                    }
                    let slot = single.bodies.slot(p.body).unwrap();
                    let fat = single.records[slot].fat;
                    p.bounds = match rng.random_range(0..30) {
                        0 => random_box(&mut rng, offset, spread),
                        1 => p.bounds.grown(0.1),
                        _ => {
                            let d = point_in_cube(&mut rng, speeds[p.body as usize % 1000]);
                            Aabb::new(p.bounds.min + d, p.bounds.max + d)
                        }
                    };
                    if encloses(&fat, &p.bounds) {
                        inside += 1;
                    } else {
                        refiled += 1;
                    }
                    if rng.random_range(0..10) == 0 {
                        // A stale move first: the batch keeps the last.
                        moves.push((p.body, random_box(&mut rng, offset, spread)));
                        repeated += 1;
                    }
                    moves.push((p.body, p.bounds));
                    single.update(p.body, p.bounds);
                }
                batched.update_all(&moves);
                if rng.random_range(0..4) == 0 {
                    let i = rng.random_range(1..truth.len());
                    let gone = truth.swap_remove(i);
                    assert!(single.remove(gone.body) && batched.remove(gone.body));
                }
                if rng.random_range(0..3) == 0 {
                    let p = Proxy {
                        body: 10_000 + (scene * 100 + frame) as u32,
                        bounds: random_box(&mut rng, offset, spread),
                        is_static: false,
                        filter: random_filter(&mut rng),
                    };
                    single.insert(p.body, p.bounds, p.is_static, p.filter);
                    batched.insert(p.body, p.bounds, p.is_static, p.filter);
                    truth.push(p);
                }
                for grid in [&single, &batched] {
                    grid.validate()
                        .unwrap_or_else(|e| panic!("{scene}/{frame}: {e}"));
                    spilled |= grid.records.iter().any(|r| r.list.len() > INLINE);
                }
                single.pairs(&mut a);
                batched.pairs(&mut b);
                assert_eq!(a, b, "scene {scene} frame {frame}");
                let mut expected = Vec::new();
                pairs_brute_force(&truth, &mut expected);
                assert_eq!(a, expected, "scene {scene} frame {frame}");
                created += a
                    .iter()
                    .filter(|p| before.binary_search(p).is_err())
                    .count();
                destroyed += before
                    .iter()
                    .filter(|p| a.binary_search(p).is_err())
                    .count();
                std::mem::swap(&mut before, &mut a);
            }
        }
        assert!(
            created > 500 && destroyed > 500 && repeated > 100,
            "created {created}, destroyed {destroyed}, repeated {repeated}"
        );
        assert!(
            inside > 3_000 && refiled > 3_000 && spilled,
            "moves inside the skin {inside}, refilings {refiled}, spilled {spilled}"
        );
    }

    /// The spread's factors' reciprocals stay in their range, fill it, and are the same
    /// for the same body and batch.
    #[test]
    fn skin_factors_spread_over_their_range_and_repeat() {
        let (low, high) = (1.0 - SKIN_SPREAD / 2.0, 1.0 + SKIN_SPREAD / 2.0);
        let mut bins = [0usize; 10];
        for body in 0..1_000u32 {
            for batch in [0, 1, 2, 7, 1_000, u32::MAX] {
                let f = skin_factor(body, batch);
                assert_eq!(f, skin_factor(body, batch));
                let rate = 1.0 / f;
                assert!((low - 1e-12..high).contains(&rate), "{body} {batch}: {f}");
                bins[(((rate - low) / (high - low) * 10.0) as usize).min(9)] += 1;
            }
        }
        // 6,000 draws: about 600 a tenth of the range.
        assert!(bins.iter().all(|&n| (450..750).contains(&n)), "{bins:?}");
    }

    /// A refiled skin reaches ahead of the body's motion as far as it moved in the asked
    /// number of batches, plus the skin behind, at least the smallest skin ahead and at
    /// most the largest growth, with the skin behind on the other side and on the axes it
    /// does not move along; within the room of its true box's level (shared in proportion
    /// on an axis without enough). The fat box encloses the box and never outgrows the
    /// reach.
    #[test]
    fn a_refiled_skin_reaches_ahead_of_the_motion_within_its_bounds_and_the_level_room() {
        let (unit, moved) = (unit_cube_at(0.0), unit_cube_at);
        let back = BACK_SKIN;
        let fit = 0.1 / (back + 0.08 + back); // the share that fits in 0.1 m of room
        // Steps over 4 batches whose `SKIN_FRAMES` batches' worth is 16 cm and 8 cm.
        let (long, short) = (0.64 / SKIN_FRAMES, 0.32 / SKIN_FRAMES);
        // (step along x, batches, reach) → (below on x, above on x, each side on y and z).
        for ((step, batches, reach), (below, above, side)) in [
            // 16 cm ahead; backwards, behind.
            ((long, 4, f64::INFINITY), (back, back + 0.16, back)),
            ((-long, 4, f64::INFINITY), (back + 0.16, back, back)),
            // Barely moving: the smallest skin ahead; racing: the largest growth.
            ((1e-6, 1, f64::INFINITY), (back, MIN_SKIN, back)),
            (
                (10.0, 1, f64::INFINITY),
                (back, 2.0 * MAX_SKIN - back, back),
            ),
            // The level reaches 1.1 m: 10 cm of room on each axis.
            ((short, 4, 1.1), (back * fit, (back + 0.08) * fit, back)),
            // No room at all.
            ((short, 4, 1.0), (0.0, 0.0, 0.0)),
        ] {
            let mut r = Record::first(&unit, 0, f64::INFINITY);
            assert_eq!(r.fat, unit.grown(FIRST_SKIN));
            let now = moved(step);
            r.refile(&now, batches, reach, 1.0);
            let got_below = now.min - r.fat.min;
            let got_above = r.fat.max - now.max;
            let expected = [below, above, side, side, side, side];
            let got = [got_below.x, got_above.x, got_below.y, got_above.y];
            let got = got.into_iter().chain([got_below.z, got_above.z]);
            for (g, e) in got.zip(expected) {
                assert!(
                    (g - e).abs() < 1e-12,
                    "{step} {batches} {reach}: {g} for {e}"
                );
            }
            assert!(encloses(&r.fat, &now));
            assert!(r.fat.extents().max_element() <= reach);
        }
        let cramped = Record::first(&unit, 0, 1.04);
        assert!((cramped.fat.extents().x - 1.04).abs() < 1e-12);
    }
}
