//! Skin grid: the [`ColumnGrid`] over every body's box grown by a *skin*, with each body's
//! skin neighbours listed, so that a body that moves within its grown box re-tests only
//! the few bodies on its list, and the grid hears of it only when it leaves that box.
//!
//! # Why
//! With a tenth of 100,000 bodies moving a little each frame, the column grid spends about
//! half a microsecond per move reading the columns around the body from the last-level
//! cache, although the body's pairs hardly change. Molecular dynamics keeps *Verlet
//! lists* for this, and Bullet's dynamic tree *fat boxes*: each body is filed under a box
//! larger than it by a skin, and the pairs of the larger boxes are a superset of the true
//! pairs that stays one until some body leaves its larger box.
//!
//! # How
//! - The grid holds each body's *fat box*: its box when last filed, grown on every side by
//!   its *skin*. Its pairs (fat boxes overlapping) are the *skin neighbours*; each body
//!   keeps the list of its own, each entry with whether the two true boxes overlap now.
//! - A moved body whose box is still inside its fat box only re-tests its neighbours'
//!   true boxes against its new one, and logs the pairs whose overlap changed. One that
//!   left it is filed again under a new fat box (a column grid move, whose pair changes
//!   add and remove neighbours), then re-tests its neighbours the same way.
//! - The pairs reported are the neighbours whose true boxes overlap: exactly the pairs of
//!   [`pairs_brute_force`](super::pairs_brute_force), since every true box lies inside its
//!   fat box, so two overlapping true boxes have overlapping fat boxes.
//!
//! # The skin
//! A thick skin means few refilings but more neighbours to re-test; the right thickness
//! depends on how fast the body moves, so each refiling sizes it anew: enough for
//! [`SKIN_FRAMES`] batches at the speed the body's centre moved since it was last filed,
//! at least [`MIN_SKIN`] and at most [`MAX_SKIN`] of its largest extent, and never so much
//! that the fat box outgrows the reach of the grid level the true box belongs at (a
//! bigger box would be filed one level up, where every query of the level below meets
//! it). A body filed for the first time gets [`FIRST_SKIN`] of its extent, within the same
//! level room. Each refiled skin is divided by a number between 0.5 and 1.5 drawn from the
//! body's id and the batch ([`SKIN_SPREAD`]), so that bodies which start moving together
//! do not keep leaving their skins in the same frames. First skins are not spread: a
//! thicker one would bridge gaps a resting body never crosses (stacked dice 0.23 m apart
//! gained neighbours across the gap: 241 → 1,000–1,200 µs a frame at 10,000 dice all
//! moving).
//!
//! # Costs (`d` neighbours a body has)
//! - A move inside the skin: `O(d)` box tests, reading the body's record (fat box and the
//!   first neighbours side by side) and its neighbours' boxes; in a batch of a large grid
//!   those are prefetched a few moves ahead, in both passes (the first, which tells the
//!   moves out of the skin, reads each record and writes each proxy; the second re-tests).
//!   Measured (`examples/broad_bench`, 100,000 bodies, 10 % moving, six alternating runs,
//!   medians): the first pass's prefetch took uniform from 5.17 to 4.12 ms a frame,
//!   clustered from 6.31 to 5.19.
//! - A move out of it: a column grid move (module docs of [`ColumnGrid`]) of the fat box,
//!   plus constant work per neighbour gained or lost (each entry knows its twin).
//! - Teleports leave the skin every time: the column grid alone is the better choice then.
//!
//! # Invariants (checked by [`SkinGrid::validate`])
//! - Every body's true box lies inside its fat box, and the grid holds exactly the fat
//!   boxes (its own invariants hold).
//! - The neighbour lists are symmetric, and hold exactly the pairs of overlapping fat
//!   boxes that may pair, each once per side; an entry's overlap flag says whether the
//!   true boxes overlap.
//! - The pair set is exactly the flagged neighbours: the brute-force pairs of the true
//!   boxes.

use super::body_map::Bodies;
use super::column_grid::ColumnGrid;
use super::pair_set::PairSet;
use super::{CandidatePair, CollisionFilter, Proxy, debug_assert_valid_bounds};
use crate::bounding::{Aabb, BoundingVolume};
use crate::math::splitmix64;
use std::collections::BTreeMap;

/// Skin on every side of a box filed for the first time, as a fraction of its largest
/// extent.
pub const FIRST_SKIN: f64 = 0.1;
/// Frames a refiled box's skin is sized to last, at the speed the body moved since it was
/// last filed.
pub const SKIN_FRAMES: f64 = 8.0;
/// Smallest and largest skin of a refiled box, as fractions of its largest extent.
///
/// The smallest is the first filing's: a slow body is better served by a skin many
/// frames thick, as a refiling (a column-grid query over the fat box) costs as much as
/// re-testing dozens of neighbours. Measured (`examples/broad_bench`, 10,000 bodies all
/// moving at a sixth of the bench speed, 5 mm a frame, medians of three alternating runs):
/// 0.02 → 0.1 took the uniform layout from 904 to 778 µs a frame and the clustered one
/// from 1,357 to 958; 0.2 was slower again (804 uniform); the 10 %-moving classes at
/// full speed, whose skins are above either floor, alike.
pub const MIN_SKIN: f64 = 0.1;
/// See [`MIN_SKIN`].
pub const MAX_SKIN: f64 = 0.5;
/// Width of the spread of skin thicknesses: each refiled skin is divided by a number drawn
/// uniformly from `[1 − SKIN_SPREAD / 2, 1 + SKIN_SPREAD / 2)`
/// by a hash of the body's id and the batch (module docs, "The skin"). Dividing, not
/// multiplying: a body leaves its skin at a rate inversely proportional to its thickness,
/// so the mean rate of refilings stays what [`SKIN_FRAMES`] asks for.
///
/// Without it, bodies that start moving together leave their skins together, every few
/// frames, for as long as they keep their speeds. Measured (`examples/broad_bench`,
/// 100,000 bodies, 10 % moving): without it, frame times swung between 1.0 and 10.5 ms to
/// the end of a 150-frame run; with it they settle at 3.5–5 ms after the first ten frames.
/// Four alternating runs of 120 frames on a host drifting ±20 %, medians of mean / p99 in
/// ms, without and with it: uniform 4.17 / 9.34 → 4.91 / 7.95, clustered 5.60 / 9.11 →
/// 5.09 / 7.14. The tail shrinks in both; the mean moves either way, within the drift.
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
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Neighbour {
    /// The neighbour's slot.
    slot: u32,
    /// Where the twin entry is in the neighbour's list.
    twin: u32,
    /// Whether the two true boxes overlap (the pair is in the pair set).
    overlaps: bool,
}

/// What a body keeps besides its true box: its fat box and its neighbours.
#[derive(Debug, Clone)]
struct Record {
    fat: Aabb,
    /// The batch the box was last filed in.
    filed_at: u32,
    list: Neighbours,
}

impl Record {
    /// A body filed for the first time with box `bounds`, in batch `batch`, in a grid whose
    /// level for it reaches `reach` metres (module docs, "The skin").
    fn first(bounds: &Aabb, batch: u32, reach: f64) -> Self {
        let extent = bounds.extents().max_element();
        Self {
            fat: grown_within(bounds, FIRST_SKIN * extent, reach),
            filed_at: batch,
            list: Neighbours::default(),
        }
    }

    /// Files the body again with box `bounds` in batch `batch`: the skin sized to last
    /// `factor` × [`SKIN_FRAMES`] batches at the speed its centre moved since the last
    /// filing, within [`MIN_SKIN`] and [`MAX_SKIN`] of its largest extent and the room
    /// below `reach` (module docs, "The skin").
    fn refile(&mut self, bounds: &Aabb, batch: u32, reach: f64, factor: f64) {
        let moved = (bounds.center() - self.fat.center()).abs().max_element();
        let batches = f64::from(batch.wrapping_sub(self.filed_at).max(1));
        let extent = bounds.extents().max_element();
        let wanted =
            (factor * SKIN_FRAMES * moved / batches).clamp(MIN_SKIN * extent, MAX_SKIN * extent);
        self.fat = grown_within(bounds, wanted, reach);
        self.filed_at = batch;
    }
}

/// `bounds` grown by `skin`, the skin cut to what keeps the grown box's largest extent,
/// as computed, within `reach` (at least that of `bounds`).
///
/// The cut to half the room is not enough on its own: the grown box's corners and its
/// extent are rounded, and a box whose skin fills its room exactly came out a few ulps wider
/// than `reach`. The column grid then filed it one level up, where every query of its own
/// level meets it: measured (`examples/broad_bench`, 100,000 uniform bodies, 10 % moving),
/// 580 bodies had leaked to a level of 4 columns after 50 frames, and a refiling met 54
/// candidates instead of 21. So the extent is checked as the grid computes it, and the
/// skin cut by the excess until it fits (once, in practice; no skin at all fits, as
/// `bounds` does).
fn grown_within(bounds: &Aabb, skin: f64, reach: f64) -> Aabb {
    debug_assert!(bounds.extents().max_element() <= reach);
    let mut skin = skin.min(0.5 * (reach - bounds.extents().max_element()));
    // A cut smaller than the corners' rounding may change nothing: cut at least that.
    let magnitude = bounds.min.abs().max(bounds.max.abs()).max_element() + skin;
    for _ in 0..4 {
        if skin <= 0.0 {
            break;
        }
        let fat = bounds.grown(skin);
        let excess = fat.extents().max_element() - reach;
        if excess <= 0.0 {
            return fat;
        }
        skin -= excess.max(4.0 * f64::EPSILON * magnitude);
    }
    *bounds
}

/// How many moves ahead a batch's retests prefetch (module docs, "Costs").
const PREFETCH_AHEAD: usize = 4;
/// Fewest bodies for which a batch's retests prefetch (below, the records and boxes stay
/// in the caches).
const PREFETCH_FROM_BODIES: usize = 30_000;

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
    /// Scratch: the slots a batch moved.
    moved: Vec<u32>,
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

    /// Number of bodies.
    #[must_use]
    pub fn len(&self) -> usize {
        self.bodies.len()
    }

    /// Whether there are no bodies.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.bodies.is_empty()
    }

    /// Whether `body` is present.
    #[must_use]
    pub fn contains(&self, body: u32) -> bool {
        self.bodies.contains(body)
    }

    /// The bodies as proxies (their true boxes), in slot order.
    #[must_use]
    pub fn proxies(&self) -> &[Proxy] {
        &self.bodies.proxies
    }

    /// Adds `body` with box `bounds` (metres; finite, `min <= max`). Inserting an id that
    /// is already present replaces that body.
    pub fn insert(&mut self, body: u32, bounds: Aabb, is_static: bool, filter: CollisionFilter) {
        debug_assert_valid_bounds(&bounds);
        if self.contains(body) {
            self.remove(body);
        }
        let extent = bounds.extents().max_element();
        let reach = self.grid.level_reach(extent);
        let record = Record::first(&bounds, self.batch, reach);
        let fat = record.fat;
        self.bodies.push(Proxy {
            body,
            bounds,
            is_static,
            filter,
        });
        self.records.push(record);
        self.grid.insert(body, fat, is_static, filter);
        self.apply_grid_edits();
    }

    /// Removes `body` and its pairs; `false` when it was not present.
    pub fn remove(&mut self, body: u32) -> bool {
        let Some(slot) = self.bodies.slot(body) else {
            return false;
        };
        self.grid.remove(body);
        self.apply_grid_edits();
        debug_assert!(self.records[slot].list.is_empty(), "all its pairs gone");
        self.bodies.unmap(body);
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
        self.bodies.swap_remove(slot);
        self.records.swap_remove(slot);
        true
    }

    /// Moves `body`'s box to `bounds` (metres; finite, `min <= max`) and refreshes its pairs
    /// (module docs). Updating a body that is not present is a contract violation
    /// (`debug_assert!`; ignored in release builds).
    pub fn update(&mut self, body: u32, bounds: Aabb) {
        self.update_all(&[(body, bounds)]);
    }

    /// [`update`](Self::update) of every `(body, bounds)` in `moves`; a body listed twice
    /// ends at its last box. The moves out of the skin go to the column grid as one batch.
    ///
    /// # Allocation
    /// None once the scratch buffers and the neighbour lists have grown to their peaks.
    pub fn update_all(&mut self, moves: &[(u32, Aabb)]) {
        self.refiled.clear();
        self.moved.clear();
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
            self.bodies.proxies[slot].bounds = bounds;
            self.moved.push(slot as u32);
            let record = &mut self.records[slot];
            if !encloses(&record.fat, &bounds) {
                let reach = self.grid.level_reach(bounds.extents().max_element());
                record.refile(&bounds, self.batch, reach, skin_factor(body, self.batch));
                self.refiled.push((body, record.fat));
            }
        }
        if !self.refiled.is_empty() {
            self.grid.update_all(&self.refiled);
            self.apply_grid_edits();
        }
        for k in 0..self.moved.len() {
            if prefetching {
                self.prefetch_retest(k);
            }
            self.retest(self.moved[k] as usize);
        }
    }

    /// Every pair of bodies whose boxes overlap (touching counts) and that may pair, once
    /// each with `a < b`, in increasing `(a, b)` order, written to `out` (cleared first):
    /// exactly the pairs of [`pairs_brute_force`](super::pairs_brute_force) over
    /// [`proxies`](Self::proxies).
    pub fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        out.clear();
        out.extend_from_slice(self.pairs.commit());
    }

    /// Checks every invariant (module docs). `O(n²)`: for tests.
    ///
    /// # Errors
    /// A description of the first violated invariant.
    pub fn validate(&self) -> Result<(), String> {
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
                if twin.is_none_or(|t| t.slot as usize != slot || t.overlaps != e.overlaps) {
                    return Err(format!("{}–{}: the twin entry is wrong", p.body, q.body));
                }
                if e.overlaps != p.bounds.intersects(&q.bounds) {
                    return Err(format!("{}–{} overlap flag stale", p.body, q.body));
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
                let overlaps = self.bodies.proxies[a]
                    .bounds
                    .intersects(&self.bodies.proxies[b].bounds);
                let (at_a, at_b) = (self.records[a].list.len(), self.records[b].list.len());
                self.records[a].list.push(Neighbour {
                    slot: b as u32,
                    twin: at_b as u32,
                    overlaps,
                });
                self.records[b].list.push(Neighbour {
                    slot: a as u32,
                    twin: at_a as u32,
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
            super::prefetch(&raw const self.records[slot]);
            super::prefetch(&raw const self.bodies.proxies[slot]);
        }
    }

    /// Starts loading what the retests [`PREFETCH_AHEAD`] and twice that many moves after
    /// the `k`-th of the batch read: the later one's record, the nearer one's neighbours'
    /// boxes.
    fn prefetch_retest(&self, k: usize) {
        if let Some(&far) = self.moved.get(k + 2 * PREFETCH_AHEAD) {
            super::prefetch(&raw const self.records[far as usize]);
        }
        if let Some(&near) = self.moved.get(k + PREFETCH_AHEAD) {
            for e in self.records[near as usize].list.iter() {
                super::prefetch(&raw const self.bodies.proxies[e.slot as usize]);
            }
        }
    }

    /// Re-tests slot `slot`'s true box against its neighbours' and logs every pair whose
    /// overlap changed.
    fn retest(&mut self, slot: usize) {
        let p = self.bodies.proxies[slot];
        for i in 0..self.records[slot].list.len() {
            let Neighbour {
                slot: other,
                twin,
                overlaps,
            } = self.records[slot].list[i];
            let q = &self.bodies.proxies[other as usize];
            let now = p.bounds.intersects(&q.bounds);
            if now == overlaps {
                continue;
            }
            let pair = CandidatePair::of(p.body, q.body);
            self.records[slot].list[i].overlaps = now;
            self.records[other as usize].list[twin as usize].overlaps = now;
            if now {
                self.pairs.insert(pair);
            } else {
                self.pairs.remove(pair);
            }
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

/// Whether `outer` holds all of `inner` (closed boxes): both of its corners.
fn encloses(outer: &Aabb, inner: &Aabb) -> bool {
    outer.contains_point(inner.min) && outer.contains_point(inner.max)
}

#[cfg(test)]
mod tests {
    use super::*;
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
            let fat = grown_within(&bounds, skin, reach);
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

    /// A refiled skin lasts the asked number of batches at the body's speed, within its
    /// bounds, and a fat box never outgrows the reach of its true box's level.
    #[test]
    fn a_refiled_skin_follows_the_speed_within_its_bounds_and_the_level_room() {
        let unit = Aabb::new(DVec3::ZERO, DVec3::ONE);
        let moved = |d: f64| Aabb::new(unit.min + DVec3::X * d, unit.max + DVec3::X * d);
        for (step, batches, reach, skin) in [
            // 2 cm a batch for 4 batches: 8 batches' worth.
            (0.08, 4, f64::INFINITY, 0.16),
            // Barely moving: the smallest skin; racing: the largest.
            (1e-6, 1, f64::INFINITY, MIN_SKIN),
            (10.0, 1, f64::INFINITY, MAX_SKIN),
            // The level reaches 1.1 m: 5 cm of room on each side.
            (0.04, 4, 1.1, 0.05),
            // No room at all.
            (0.04, 4, 1.0, 0.0),
        ] {
            let mut r = Record::first(&unit, 0, f64::INFINITY);
            assert_eq!(r.fat, unit.grown(FIRST_SKIN));
            let now = moved(step);
            r.refile(&now, batches, reach, 1.0);
            let got = (r.fat.extents().x - now.extents().x) / 2.0;
            assert!(
                (got - skin).abs() < 1e-12,
                "{step} {batches} {reach}: {got}"
            );
            assert!(encloses(&r.fat, &now));
            assert!(r.fat.extents().max_element() <= reach + 1e-12);
        }
        let cramped = Record::first(&unit, 0, 1.04);
        assert!((cramped.fat.extents().x - 1.04).abs() < 1e-12);
    }
}
