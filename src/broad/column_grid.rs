//! Column grid: a stateful broad phase for large scenes where a fraction of the bodies moves
//! each frame. Each body is stored once, in one column of a hierarchy of 2-D grids, and each
//! column keeps its bodies sorted along the third axis, so a moved body re-tests only the
//! few bodies of the 1 to 4 columns around it, each run found by a search of the column.
//!
//! # Invariants
//! - Level `k` holds the bodies whose largest box extent is at most its *reach*
//!   `reach₀ · 4ᵏ` (and above the level below), in columns `2 · reach₀ · 4ᵏ` wide, each
//!   body once, in the column of its box's *low corner*, each column sorted by low end on
//!   the sweep axis. Bodies wider than the coarsest reach, and every body until the levels
//!   are chosen (`ColumnGrid::rebuild`), are *oversized*: in a list every query tests.
//! - So the bodies of a level whose boxes can meet a window `W` have their low corner in
//!   `[W.min − reach, W.max]` on each axis: a rectangle of columns (1 or 2 per axis for a
//!   body of the same level) and a run of each column's list. No candidate is met twice.
//! - The columns only prune, and conservatively: the low end of the window is rounded down
//!   (`low_end`) and column indices are `⌊x / width⌋` by a monotone map, so any low corner
//!   at or above that end falls in a column at or after the window's first. A pair is
//!   reported by [`Aabb::intersects`] on the stored boxes and [`Proxy::may_pair`], as in
//!   every broad phase; zero-size boxes, boxes ending on a column boundary and `-0.0` need
//!   no special case.
//! - A body whose pairs must be refreshed (inserted, moved, removed) queries its old and
//!   new boxes (`query_windows`), and each candidate is tested against both: the pair was in
//!   the set exactly when the old box met the candidate's stored box, and is now when the
//!   new one does; only a change is logged. Bodies are updated one at a time, so a
//!   candidate's stored box is the one the pair set already reflects.
//!
//! # Costs (`n` bodies, `k` pairs, `c` candidates a query meets)
//! - [`update`](ColumnGrid::update): one query (`O(c)`, plus a search of the column's index
//!   for each column visited at each level with bodies) and the body's move in its column
//!   list: in place when it stays in its column (a few swaps if it passed a neighbour on the
//!   sweep axis), else a removal and an insertion, `O(column length)`. An oversized body's
//!   own query scans every level's columns under its box, `O(n)` at worst, and every query
//!   tests every oversized body.
//! - [`insert`](ColumnGrid::insert), [`remove`](ColumnGrid::remove): the same, and for an
//!   insertion an `O(n log n)` rebuild each time the body count has more than doubled.
//! - [`pairs`](ColumnGrid::pairs): `O(k + e log e)` for `e` pair changes (`pair_set.rs`).
//!
//! Bounds are trusted: finite with `min <= max` (the [`Aabb`] invariant), checked by
//! `debug_assert!`. The automatic choice ([`choose`](super::choose)) takes it for scenes
//! that teleport, where every jump would leave a [`SkinGrid`](super::SkinGrid)'s skin.

use super::body_map::Bodies;
use super::pair_set::PairSet;
use super::stateful::{StatefulBroadPhase, stateful_api};
use super::{CandidatePair, Proxy, debug_assert_valid_bounds, floor_to_i64, prefetch};
use crate::bounding::{Aabb, BoundingVolume};

mod columns;
use columns::{Axes, BLOCK, Entry, Level, Listing, Place};

/// Bodies held before the first rebuild chooses the levels (all oversized until then: all
/// pairs tested, the right algorithm for so few).
pub const AUTO_SAMPLE: usize = 64;
/// Most levels.
pub const MAX_LEVELS: usize = 16;
/// Reach of level `k + 1` over level `k`.
const REACH_RATIO: f64 = 4.0;
/// Column width over the level's reach.
const WIDTH_PER_REACH: f64 = 2.0;
/// Largest share of bodies the finest level may leave to coarser ones (the 90th percentile).
const FINEST_QUANTILE: f64 = 0.9;
/// Finest reach taken as the largest extent when that is within this factor of the quantile.
const ONE_LEVEL_SPREAD: f64 = 1.5;
/// How many moves ahead [`ColumnGrid::update_all`] prefetches a move's query.
const PREFETCH_AHEAD: usize = 4;
/// Fewest bodies for which [`ColumnGrid::update_all`] prefetches: below, the columns stay
/// in the 2 MiB L2 cache and prefetching only adds work (`examples/broad_bench`).
const PREFETCH_FROM_BODIES: usize = 30_000;
/// What [`ColumnGrid::level_for`] says of a body wider than every level's reach.
const OVERSIZED: u8 = u8::MAX;

/// The windows a body whose box goes from `old` to `new` (`None`: not present) queries:
/// their union when they overlap, else each box on its own, as the union of a jump's two
/// boxes may span the world. A body meeting only the old box is met only in its window, one
/// meeting only the new box only in its: each pair change is found once either way.
fn query_windows(old: Option<&Aabb>, new: Option<&Aabb>) -> [Option<Aabb>; 2] {
    match (old, new) {
        (Some(a), Some(b)) if a.intersects(b) => [Some(a.merged(b)), None],
        _ => [old.copied(), new.copied()],
    }
}

/// `x − reach`, rounded down past any rounding error: the exact difference with `reach`
/// raised by a relative 1e-9 (more than the rounding of an extent computed as
/// `max − min`), stepped one representable value down (more than the subtraction's own
/// rounding). See the module docs, "Invariants".
#[inline]
fn low_end(x: f64, reach: f64) -> f64 {
    (x - reach * (1.0 + 1e-9)).next_down()
}

/// Column grid over bodies identified by `u32` ids; see the module docs. Same body-level API
/// and output contract as [`IncrementalSap`](super::IncrementalSap) and
/// [`HashGrid`](super::HashGrid).
#[derive(Debug, Clone)]
pub struct ColumnGrid {
    /// Finest first; empty until the first rebuild (every body oversized until then).
    levels: Vec<Level>,
    axes: Axes,
    /// The bodies, densely by slot; `bodies.proxies[s].bounds` is what its column holds.
    bodies: Bodies,
    /// Slots of the oversized bodies.
    oversized: Vec<u32>,
    /// The pairs whose boxes overlap and that may pair, `a < b`.
    pairs: PairSet,
    /// Body count at the last rebuild (0: never built).
    built_at: usize,
    /// [`update_all`](Self::update_all)'s moves.
    batch: Vec<BatchMove>,
    /// Per slot, the number of the last batch that moved it and the index of that move.
    last_move: Vec<(u32, u32)>,
    /// Number of the current (or last) batch; never 0 (the number `last_move` starts at).
    batch_number: u32,
    /// Fewest bodies for which `update_all` prefetches: [`PREFETCH_FROM_BODIES`] (tests
    /// lower it to run the prefetching path on small grids).
    prefetch_from_bodies: usize,
}

/// One move of an [`update_all`](ColumnGrid::update_all) batch.
#[derive(Debug, Clone, Copy)]
struct BatchMove {
    /// The body's record before the batch.
    old: Proxy,
    /// Its box after.
    new: Aabb,
    slot: u32,
    /// Whether this is the body's last move in the batch (the only one applied).
    last: bool,
}

impl Default for ColumnGrid {
    fn default() -> Self {
        Self::new()
    }
}

impl ColumnGrid {
    /// An empty grid; its levels are chosen at the [`AUTO_SAMPLE`]-th body, and again
    /// whenever the body count has more than doubled since.
    #[must_use]
    pub fn new() -> Self {
        Self {
            levels: Vec::new(),
            axes: Axes::with_sweep(0),
            bodies: Bodies::default(),
            oversized: Vec::new(),
            pairs: PairSet::default(),
            built_at: 0,
            batch: Vec::new(),
            last_move: Vec::new(),
            batch_number: 0,
            prefetch_from_bodies: PREFETCH_FROM_BODIES,
        }
    }

    /// A grid holding `proxies` (distinct ids), built at once: placed in sorted columns in
    /// `O(n log n)`, then each body's pairs found by one query.
    #[must_use]
    pub fn from_proxies(proxies: &[Proxy]) -> Self {
        let mut grid = Self::new();
        for p in proxies {
            debug_assert_valid_bounds(&p.bounds);
            let slot = grid.bodies.push(*p);
            grid.last_move.push((0, 0));
            grid.oversized.push(slot as u32);
        }
        if grid.bodies.len() >= AUTO_SAMPLE {
            grid.rebuild();
        }
        for slot in 0..grid.bodies.len() {
            let p = grid.bodies.proxies[slot];
            grid.for_each_candidate(&p.bounds, slot, |pairs, proxies, bounds, other| {
                let q = &proxies[other];
                if other > slot && p.bounds.intersects(bounds) && p.may_pair(q) {
                    pairs.insert(CandidatePair::of(p.body, q.body));
                }
            });
        }
        grid
    }

    /// [`update`](Self::update) of every `(body, bounds)` in `moves`; a body listed twice
    /// ends at its last box. The same pair set as updating one by one in the given order.
    ///
    /// Two passes: the first reads every moved body's record (independent look-ups the
    /// processor overlaps), the second moves them. In a grid of 30,000 bodies or more, each
    /// pass starts fetching what it reads four moves on, so that the cache misses overlap
    /// this move's work: the first pass the record, the second the first entries of the
    /// query.
    ///
    /// # Allocation
    /// None once the batch buffer has grown to the largest batch.
    pub fn update_all(&mut self, moves: &[(u32, Aabb)]) {
        let mut batch = std::mem::take(&mut self.batch);
        batch.clear();
        self.batch_number = self.batch_number.wrapping_add(1);
        if self.batch_number == 0 {
            self.last_move.fill((0, 0));
            self.batch_number = 1;
        }
        let prefetching = self.bodies.len() >= self.prefetch_from_bodies;
        for (k, &(body, bounds)) in moves.iter().enumerate() {
            debug_assert_valid_bounds(&bounds);
            if let Some(ahead) = moves
                .get(k + PREFETCH_AHEAD)
                .filter(|_| prefetching)
                .and_then(|&(body, _)| self.bodies.slot(body))
            {
                prefetch(&raw const self.bodies.proxies[ahead]);
                prefetch(&raw const self.last_move[ahead]);
            }
            let Some(slot) = self.bodies.slot(body) else {
                debug_assert!(false, "update of absent body {body}");
                continue;
            };
            let at = batch.len() as u32;
            let (number, earlier) =
                std::mem::replace(&mut self.last_move[slot], (self.batch_number, at));
            if number == self.batch_number {
                // Only a body's last move counts: its pairs depend on its final box alone.
                batch[earlier as usize].last = false;
            }
            batch.push(BatchMove {
                old: self.bodies.proxies[slot],
                new: bounds,
                slot: slot as u32,
                last: true,
            });
        }
        for (k, m) in batch.iter().enumerate() {
            if let Some(next) = batch
                .get(k + PREFETCH_AHEAD)
                .filter(|n| prefetching && n.last)
            {
                self.prefetch_query(&next.old.bounds, &next.new);
            }
            if m.last {
                self.move_slot(m.slot as usize, &m.old, m.new);
            }
        }
        self.batch = batch;
    }

    /// Starts fetching what the query of a move from `old` to `new` will read first
    /// ([`Level::prefetch_near`]).
    fn prefetch_query(&self, old: &Aabb, new: &Aabb) {
        for window in query_windows(Some(old), Some(new)).iter().flatten() {
            for level in self.levels.iter().filter(|l| l.count > 0) {
                level.prefetch_near(window, self.axes);
            }
        }
    }

    /// Moves slot `slot`, whose stored record is `old`, to box `bounds`: its pairs
    /// refreshed, then its listing moved.
    fn move_slot(&mut self, slot: usize, old: &Proxy, bounds: Aabb) {
        let own = self.refresh(old, Some(&old.bounds), Some(&bounds), slot);
        let old = old.bounds;
        let level = self.level_for(&bounds);
        let (axes, was) = (self.axes, self.level_for(&old));
        if was == level && level != OVERSIZED {
            let grid = &mut self.levels[usize::from(level)];
            let (from, to) = (grid.home(old.min, axes), grid.home(bounds.min, axes));
            if from == to {
                let column = &mut grid.columns[from];
                let at = match own {
                    Some(place) if place.bucket == from => place.at,
                    _ => column.find(old.min[axes.sweep], slot as u32),
                };
                debug_assert_eq!(column.entries[at].slot as usize, slot);
                let entry = Entry {
                    bounds,
                    slot: slot as u32,
                };
                column.replace(at, bounds.min[axes.sweep], entry);
                self.bodies.proxies[slot].bounds = bounds;
                return;
            }
        }
        self.unplace(slot);
        self.bodies.proxies[slot].bounds = bounds;
        self.place(slot);
    }

    /// Moves the changes of the pair set since the last call (or the last
    /// [`pairs`](Self::pairs)) to `out`: each pair and whether its boxes now overlap, in
    /// the order they happened. For a caller that keeps the pairs itself (the
    /// [`SkinGrid`](super::SkinGrid)); once it is used, [`pairs`](Self::pairs) no longer
    /// lists the pair set, and [`validate_listing`](Self::validate_listing) is the check.
    pub(crate) fn take_pair_edits(&mut self, out: &mut Vec<(CandidatePair, bool)>) {
        self.pairs.take_edits(out);
    }

    /// [`validate`](Self::validate) but for the pair set (for a grid whose pair edits are
    /// taken by its caller).
    ///
    /// # Errors
    /// A description of the first violated invariant.
    pub(crate) fn validate_listing(&self) -> Result<(), String> {
        self.bodies.check()?;
        let n = self.bodies.len();
        if self.last_move.len() != n {
            return Err(format!("{n} proxies, per-slot tables disagree"));
        }
        for (slot, p) in self.bodies.proxies.iter().enumerate() {
            let b = &p.bounds;
            if !(b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()) {
                return Err(format!("body {} has invalid bounds {b:?}", p.body));
            }
            let level = self.level_for(b);
            let listed = if level == OVERSIZED {
                self.oversized
                    .iter()
                    .filter(|&&s| s as usize == slot)
                    .count()
            } else {
                let grid = &self.levels[usize::from(level)];
                let column = &grid.columns[grid.home(b.min, self.axes)];
                column
                    .entries
                    .iter()
                    .filter(|e| e.slot as usize == slot && e.bounds == *b)
                    .count()
            };
            if listed != 1 {
                return Err(format!(
                    "body {} listed {listed} times where it belongs",
                    p.body
                ));
            }
        }
        let mut stored = self.oversized.len();
        for (k, grid) in self.levels.iter().enumerate() {
            let here: usize = grid.columns.iter().map(|c| c.entries.len()).sum();
            if here != grid.count {
                return Err(format!(
                    "level {k} holds {here} entries, counts {}",
                    grid.count
                ));
            }
            for column in &grid.columns {
                let keys = column.entries.iter().map(|e| e.bounds.min[self.axes.sweep]);
                let index = column.low.iter().step_by(BLOCK).copied();
                if column.low.len() != column.entries.len()
                    || !column.low.iter().copied().eq(keys)
                    || !column.low.is_sorted()
                    || !column.starts.iter().copied().eq(index)
                {
                    return Err(format!("level {k}: a column is out of order"));
                }
            }
            stored += here;
        }
        if stored != n {
            return Err(format!("{stored} entries stored, {n} bodies"));
        }
        Ok(())
    }

    /// The reach of the level a box of largest extent `extent` (metres) belongs at: the
    /// largest extent a box can grow to and stay there; `+∞` for an oversized box (and
    /// before the first rebuild).
    pub(crate) fn level_reach(&self, extent: f64) -> f64 {
        self.level_index(extent)
            .map_or(f64::INFINITY, |k| self.levels[k].reach)
    }

    /// The finest level whose reach is at least `extent` (metres), if any.
    fn level_index(&self, extent: f64) -> Option<usize> {
        self.levels.iter().position(|l| extent <= l.reach)
    }

    /// The level a box belongs at: the finest whose reach is at least its largest extent,
    /// or [`OVERSIZED`] (always, before the first rebuild).
    fn level_for(&self, bounds: &Aabb) -> u8 {
        self.level_index(bounds.extents().max_element())
            .map_or(OVERSIZED, |k| k as u8)
    }

    /// Calls `f(pairs, proxies, bounds, slot)` with the stored box and slot of every body
    /// other than `skip` whose box meets `window`, each once; returns where `skip` itself
    /// was met (a query over a window holding its stored box meets it), if it was.
    ///
    /// Tests every oversized body and queries every level that holds bodies: at a coarser
    /// level than the window's it meets few, larger columns, at a finer one the small bodies
    /// near it.
    #[inline]
    fn for_each_candidate(
        &mut self,
        window: &Aabb,
        skip: usize,
        mut f: impl FnMut(&mut PairSet, &[Proxy], &Aabb, usize),
    ) -> Option<Place> {
        let Self {
            levels,
            axes,
            bodies,
            oversized,
            pairs,
            ..
        } = self;
        let proxies = &bodies.proxies[..];
        for &s in oversized.iter() {
            let bounds = &proxies[s as usize].bounds;
            if s as usize != skip && bounds.intersects(window) {
                f(pairs, proxies, bounds, s as usize);
            }
        }
        let mut own = None;
        for level in levels.iter().filter(|l| l.count > 0) {
            level.for_each_near(window, *axes, |entry, place| {
                let s = entry.slot as usize;
                if entry.bounds.intersects(window) {
                    if s != skip {
                        f(pairs, proxies, &entry.bounds, s);
                    } else {
                        own = Some(place);
                    }
                }
            });
        }
        own
    }

    /// Logs the pair changes of body `p` (at slot `slot`) whose box goes from `old` to `new`
    /// (`None`: not present), against every other body's stored box (module docs,
    /// "Invariants"). Returns where the query met the body's own stored entry, if it
    /// did.
    #[inline]
    fn refresh(
        &mut self,
        p: &Proxy,
        old: Option<&Aabb>,
        new: Option<&Aabb>,
        slot: usize,
    ) -> Option<Place> {
        let mut changes = |pairs: &mut PairSet, proxies: &[Proxy], bounds: &Aabb, other: usize| {
            let was = old.is_some_and(|b| b.intersects(bounds));
            let is = new.is_some_and(|b| b.intersects(bounds));
            if was != is {
                let q = &proxies[other];
                if p.may_pair(q) {
                    if is {
                        pairs.insert(CandidatePair::of(p.body, q.body));
                    } else {
                        pairs.remove(CandidatePair::of(p.body, q.body));
                    }
                }
            }
        };
        let mut own = None;
        for window in query_windows(old, new).iter().flatten() {
            own = own.or(self.for_each_candidate(window, slot, &mut changes));
        }
        own
    }

    /// Lists slot `slot` where its stored box says: at the level its size calls for, in
    /// the column of its low corner.
    fn place(&mut self, slot: usize) {
        let bounds = self.bodies.proxies[slot].bounds;
        let level = self.level_for(&bounds);
        if level == OVERSIZED {
            self.oversized.push(slot as u32);
            return;
        }
        let grid = &mut self.levels[usize::from(level)];
        let home = grid.home(bounds.min, self.axes);
        let entry = Entry {
            bounds,
            slot: slot as u32,
        };
        grid.columns[home].insert(bounds.min[self.axes.sweep], entry);
        grid.count += 1;
    }

    /// Where slot `slot` is listed, found from its stored box.
    fn listing(&self, slot: usize) -> Listing {
        let bounds = self.bodies.proxies[slot].bounds;
        let level = self.level_for(&bounds);
        if level == OVERSIZED {
            let at = self.oversized.iter().position(|&s| s as usize == slot);
            debug_assert!(at.is_some(), "slot {slot} not in the oversized list");
            return Listing::Oversized(at);
        }
        let grid = &self.levels[usize::from(level)];
        let bucket = grid.home(bounds.min, self.axes);
        let at = grid.columns[bucket].find(bounds.min[self.axes.sweep], slot as u32);
        Listing::Column {
            level: usize::from(level),
            place: Place { bucket, at },
        }
    }

    /// Undoes [`place`](Self::place) (from the stored box).
    fn unplace(&mut self, slot: usize) {
        match self.listing(slot) {
            Listing::Oversized(i) => {
                if let Some(i) = i {
                    self.oversized.swap_remove(i);
                }
            }
            Listing::Column { level, place } => {
                let grid = &mut self.levels[level];
                grid.columns[place.bucket].remove(place.at);
                grid.count -= 1;
            }
        }
    }

    /// Renames slot `from`'s listing to `to` (the last slot filling a freed one).
    fn rename(&mut self, from: usize, to: usize) {
        match self.listing(from) {
            Listing::Oversized(i) => {
                if let Some(i) = i {
                    self.oversized[i] = to as u32;
                }
            }
            Listing::Column { level, place } => {
                self.levels[level].columns[place.bucket].entries[place.at].slot = to as u32;
            }
        }
    }

    /// Chooses the axes and levels from every body and lists each afresh: the sweep axis is
    /// the one along which the box centres spread the most (the columns split the other
    /// two); `reach₀` is the 90th percentile of the bodies' positive largest extents, or the
    /// largest extent when that is within 1.5 × of it (one level for a narrow spread of
    /// sizes); levels are added until the coarsest reach is at least 4 × the largest extent
    /// (up to [`MAX_LEVELS`]).
    fn rebuild(&mut self) {
        self.axes = Axes::with_sweep(super::sort_sweep::widest_spread_axis(&self.bodies.proxies));
        let mut extents: Vec<f64> = self
            .bodies
            .proxies
            .iter()
            .map(|p| p.bounds.extents().max_element())
            .filter(|&e| e > 0.0)
            .collect();
        extents.sort_unstable_by(f64::total_cmp);
        let quantile = ((extents.len() as f64 * FINEST_QUANTILE) as usize).min(extents.len());
        let (finest, largest) = match (extents.get(quantile.saturating_sub(1)), extents.last()) {
            (Some(&q), Some(&largest)) if largest <= ONE_LEVEL_SPREAD * q => (largest, largest),
            (Some(&q), Some(&largest)) => (q, largest),
            _ => (1.0, 1.0),
        };
        let mut reach = finest;
        self.levels = vec![Level::new(reach)];
        while reach < 4.0 * largest && self.levels.len() < MAX_LEVELS {
            reach *= REACH_RATIO;
            self.levels.push(Level::new(reach));
        }
        self.oversized.clear();
        let axes = self.axes;
        let mut spans = vec![
            (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY
            );
            self.levels.len()
        ];
        for slot in 0..self.bodies.len() {
            let bounds = self.bodies.proxies[slot].bounds;
            let level = self.level_for(&bounds);
            if level == OVERSIZED {
                self.oversized.push(slot as u32);
                continue;
            }
            let k = usize::from(level);
            self.levels[k].count += 1;
            let (u, v) = (bounds.min[axes.u], bounds.min[axes.v]);
            let s = &mut spans[k];
            *s = (s.0.min(u), s.1.max(u), s.2.min(v), s.3.max(v));
        }
        for (level, s) in self.levels.iter_mut().zip(&spans) {
            let span = |lo: f64, hi: f64| if hi >= lo { hi - lo } else { 0.0 };
            level.size_table(span(s.0, s.1), span(s.2, s.3));
        }
        for slot in 0..self.bodies.len() {
            let bounds = self.bodies.proxies[slot].bounds;
            let level = self.level_for(&bounds);
            if level == OVERSIZED {
                continue;
            }
            let grid = &mut self.levels[usize::from(level)];
            let home = grid.home(bounds.min, axes);
            let column = &mut grid.columns[home];
            column.entries.push(Entry {
                bounds,
                slot: slot as u32,
            });
        }
        for column in self.levels.iter_mut().flat_map(|l| l.columns.iter_mut()) {
            column.entries.sort_unstable_by(|a, b| {
                a.bounds.min[axes.sweep].total_cmp(&b.bounds.min[axes.sweep])
            });
            column.low = column
                .entries
                .iter()
                .map(|e| e.bounds.min[axes.sweep])
                .collect();
            column.index_from(0);
        }
        self.built_at = self.bodies.len();
    }
}

stateful_api!(ColumnGrid);

impl StatefulBroadPhase for ColumnGrid {
    fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    fn bodies_mut(&mut self) -> &mut Bodies {
        &mut self.bodies
    }

    /// Its pairs found by one query, then placed in its column; the levels chosen again
    /// at the [`AUTO_SAMPLE`]-th body and whenever the count has doubled since.
    fn file(&mut self, slot: usize) {
        self.last_move.push((0, 0));
        let p = self.bodies.proxies[slot];
        self.refresh(&p, None, Some(&p.bounds), slot);
        self.place(slot);
        let n = self.bodies.len();
        if (self.built_at == 0 && n >= AUTO_SAMPLE) || (self.built_at > 0 && n > 2 * self.built_at)
        {
            self.rebuild();
        }
    }

    fn unfile(&mut self, slot: usize) {
        let p = self.bodies.proxies[slot];
        self.refresh(&p, Some(&p.bounds), None, slot);
        self.unplace(slot);
    }

    fn swap_remove_slot(&mut self, slot: usize) {
        let last = self.bodies.len() - 1;
        if slot != last {
            self.rename(last, slot);
        }
        self.last_move.swap_remove(slot);
    }

    /// Refreshes its pairs (module docs, "Invariants").
    #[inline]
    fn relocate(&mut self, slot: usize, bounds: Aabb) {
        let old = self.bodies.proxies[slot];
        self.move_slot(slot, &old, bounds);
    }

    fn update_all(&mut self, moves: &[(u32, Aabb)]) {
        Self::update_all(self, moves);
    }

    fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        self.pairs.list(out);
    }

    /// Checks every invariant: the slot table and id map agree; stored boxes are finite and
    /// not inverted; each body is at the level its box calls for (oversized before the first
    /// rebuild), listed exactly once: in the oversized list, or in its home column with its
    /// stored box; every column sorted; and the pair set equals [`pairs_brute_force`](super::pairs_brute_force) over
    /// the stored boxes.
    fn validate(&self) -> Result<(), String> {
        self.validate_listing()?;
        self.pairs.check_against_brute_force(&self.bodies.proxies)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::CollisionFilter;
    use crate::broad::conformance::{self, pairs_of};
    use crate::math::DVec3;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    /// A box at `offset` + a random point of the cube of half-size `spread`: one in 16 a
    /// point, one in 16 on a 0.5 m lattice (ends on column boundaries, touching
    /// neighbours), one in 32 huge, the rest with half-extents log-uniform over 1 mm–1 m.
    fn random_box(rng: &mut TestRng, offset: DVec3, spread: f64) -> Aabb {
        let c = offset + point_in_cube(rng, spread);
        let h = match rng.random_range(0..32) {
            0 | 1 => DVec3::ZERO,
            2 | 3 => {
                let snap = |x: f64| (x / 0.5).round() * 0.5;
                let c = DVec3::new(snap(c.x), snap(c.y), snap(c.z));
                return Aabb::new(c, c + DVec3::splat(0.5 * rng.random_range(1..4) as f64));
            }
            4 => DVec3::splat(rng.random_range(5.0..40.0)),
            _ => DVec3::from_array(std::array::from_fn(|_| {
                rng.random_range(1e-3f64.ln()..0.0).exp()
            })),
        };
        Aabb::new(c - h, c + h)
    }

    fn random_filter(rng: &mut TestRng) -> CollisionFilter {
        CollisionFilter {
            group: 1 << rng.random_range(0..3),
            mask: rng.random_range(1..8),
        }
    }

    #[test]
    fn a_removed_id_can_be_reinserted_with_new_bounds_kind_and_filter() {
        let mut grid = ColumnGrid::new();
        conformance::removed_ids_come_back_with_new_bounds_kind_and_filter(
            &mut grid,
            Aabb::new(DVec3::splat(-9.0), DVec3::splat(-6.0)),
        );
        conformance::removing_every_body_empties_it(&mut grid);
    }

    #[test]
    fn static_bodies_never_pair_with_each_other_however_they_overlap() {
        let boxed = |rng: &mut TestRng| {
            let c = point_in_cube(rng, 1.0);
            let h = DVec3::splat(rng.random_range(0.0..1.0));
            Aabb::new(c - h, c + h)
        };
        let mut grid = ColumnGrid::new();
        conformance::static_bodies_never_pair_with_each_other(
            &mut grid,
            &mut rng(706),
            100,
            boxed,
            10_000,
        );
        assert!(!grid.levels.is_empty());
    }

    /// Far from the origin and near it, seeded frames of small moves, teleports, resizes
    /// across levels, insertions and removals, with each frame's moves applied one by one
    /// to one grid and as one batch (with repeated bodies) to another: both validate
    /// against brute force every frame and agree; pairs appear and disappear, and bodies
    /// sit at several levels, oversized, and in tables whose buckets alias far columns.
    #[test]
    fn one_by_one_and_batched_moves_agree_with_brute_force_far_and_near_the_origin() {
        let mut rng = rng(707);
        let (mut created, mut destroyed, mut repeated) = (0usize, 0usize, 0usize);
        let (mut multi_level, mut oversized, mut aliased) = (false, false, false);
        for scene in 0..8 {
            let offset = [DVec3::ZERO, DVec3::new(1e7, -3e6, 2e5)][scene % 2];
            let spread = [4.0, 30.0, 400.0, 10.0][scene % 4];
            let mut truth: Vec<Proxy> = (0..150)
                .map(|i| Proxy {
                    body: 3 * i + 1,
                    bounds: random_box(&mut rng, offset, spread),
                    is_static: rng.random_range(0..5) == 0,
                    filter: random_filter(&mut rng),
                })
                .collect();
            let mut single = ColumnGrid::new();
            for p in &truth {
                single.insert(p.body, p.bounds, p.is_static, p.filter);
            }
            let mut batched = ColumnGrid::from_proxies(&truth);
            // Prefetching changes no result: the batched grid runs it, the single one not.
            batched.prefetch_from_bodies = 0;
            let (mut before, mut a, mut b) = (Vec::new(), Vec::new(), Vec::new());
            single.pairs(&mut before);
            let mut moves = Vec::new();
            for frame in 0..40 {
                moves.clear();
                for p in truth.iter_mut().filter(|p| !p.is_static) {
                    if rng.random_range(0..2) == 0 {
                        continue;
                    }
                    p.bounds = if rng.random_range(0..20) == 0 {
                        random_box(&mut rng, offset, spread)
                    } else {
                        let d = point_in_cube(&mut rng, 0.05 * spread.sqrt());
                        Aabb::new(p.bounds.min + d, p.bounds.max + d)
                    };
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
                    let i = rng.random_range(0..truth.len());
                    let gone = truth.swap_remove(i);
                    assert!(single.remove(gone.body) && batched.remove(gone.body));
                }
                if rng.random_range(0..3) == 0 {
                    let bounds = if rng.random_range(0..5) == 0 {
                        // Wider than any level chosen so far: oversized.
                        let c = offset + point_in_cube(&mut rng, spread);
                        Aabb::new(c - DVec3::splat(1e4), c + DVec3::splat(1e4))
                    } else {
                        random_box(&mut rng, offset, spread)
                    };
                    let p = Proxy {
                        body: 10_000 + (scene * 100 + frame) as u32,
                        bounds,
                        is_static: false,
                        filter: random_filter(&mut rng),
                    };
                    single.insert(p.body, p.bounds, p.is_static, p.filter);
                    batched.insert(p.body, p.bounds, p.is_static, p.filter);
                    truth.push(p);
                }
                single
                    .validate()
                    .unwrap_or_else(|e| panic!("{scene}/{frame}: {e}"));
                batched
                    .validate()
                    .unwrap_or_else(|e| panic!("{scene}/{frame}: {e}"));
                single.pairs(&mut a);
                batched.pairs(&mut b);
                assert_eq!(a, b, "scene {scene} frame {frame}");
                created += a
                    .iter()
                    .filter(|p| before.binary_search(p).is_err())
                    .count();
                destroyed += before
                    .iter()
                    .filter(|p| a.binary_search(p).is_err())
                    .count();
                std::mem::swap(&mut before, &mut a);
                for grid in [&single, &batched] {
                    multi_level |= grid.levels.iter().filter(|l| l.count > 0).count() > 1;
                    oversized |= !grid.oversized.is_empty() && !grid.levels.is_empty();
                    aliased |= grid.levels.iter().any(|l| {
                        let columns = |axis: usize| {
                            let homes: Vec<i64> = grid
                                .bodies
                                .proxies
                                .iter()
                                .map(|p| floor_to_i64(p.bounds.min[axis] * l.inv_width))
                                .collect();
                            homes.iter().max().unwrap() - homes.iter().min().unwrap()
                        };
                        columns(grid.axes.u) > l.mask_u as i64
                            || columns(grid.axes.v) > l.mask_v as i64
                    });
                }
            }
        }
        assert!(created > 500 && destroyed > 500, "{created} {destroyed}");
        assert!(repeated > 100, "{repeated}");
        assert!(
            multi_level && oversized && aliased,
            "{multi_level} {oversized} {aliased}"
        );
    }

    /// A grid built at once lists the same pairs as one filled by insertion, and the
    /// levels it chooses follow the sizes: one level for a narrow spread, more for a wide
    /// one.
    #[test]
    fn built_at_once_equals_inserted_one_by_one_and_levels_follow_the_sizes() {
        let mut rng = rng(708);
        for (spread_of_sizes, levels_with_bodies) in [(1.2f64, 1), (1000.0, 2)] {
            let proxies: Vec<Proxy> = (0..500)
                .map(|i| {
                    let h = rng.random_range(0.0f64..spread_of_sizes.ln()).exp() * 0.1;
                    let c = point_in_cube(&mut rng, 5.0);
                    Proxy {
                        body: i,
                        bounds: Aabb::new(c - DVec3::splat(h), c + DVec3::splat(h)),
                        is_static: false,
                        filter: CollisionFilter::ALL,
                    }
                })
                .collect();
            let mut built = ColumnGrid::from_proxies(&proxies);
            let mut inserted = ColumnGrid::new();
            for p in &proxies {
                inserted.insert(p.body, p.bounds, p.is_static, p.filter);
            }
            built.validate().unwrap();
            inserted.validate().unwrap();
            let (mut a, mut b) = (Vec::new(), Vec::new());
            built.pairs(&mut a);
            inserted.pairs(&mut b);
            assert_eq!(a, b);
            assert!(!a.is_empty());
            let used = built.levels.iter().filter(|l| l.count > 0).count();
            assert!(
                (used == 1) == (levels_with_bodies == 1),
                "size spread {spread_of_sizes}: {used} levels"
            );
        }
        assert_eq!(pairs_of(&mut ColumnGrid::new()), []);
    }
}
