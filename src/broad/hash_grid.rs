//! Hierarchical hash grid (Mirtich, "Efficient algorithms for two-phase collision
//! detection", 1997; Ericson, *Real-Time Collision Detection*, §7.1.6): a stateful broad
//! phase of several uniform grids of cubic cells whose sizes grow geometrically, each body
//! stored at the one level whose cells fit its box, the occupied cells hashed per level, and
//! the overlapping-pair set kept between frames so that a body that did not move costs
//! nothing.
//!
//! # Invariants
//! - Level `k` has cubic cells of edge `min_cell · ratioᵏ` metres, `ratio ≥ 2`
//!   ([`HashGrid::with_levels`], or chosen by [`HashGrid::new`] from its first
//!   [`AUTO_SAMPLE`] bodies). A body lives at the finest level whose cell edge is at least
//!   its box's largest extent, where its box covers at most 8 cells (27 at worst,
//!   `CellRange`). A body larger than the coarsest cell, and every body while the levels
//!   are not chosen, is *oversized*: kept in a list, tested against every body.
//! - A body is listed in the cells its box covers at its own level and, flagged as coming
//!   *from a finer level*, at every coarser level. So a body `b` at level `L` meets every
//!   box that can overlap its own among: the bodies listed in its cells at `L` (those of `L`
//!   and the finer ones near it), the unflagged ones in its cells at every coarser level
//!   that has bodies of its own, and the oversized ones (for an oversized `b`, every body).
//!   A pair is found from either side, never by searching the many cells of a finer level.
//! - Cells only prune, and conservatively: the map from a coordinate to its cell is
//!   monotone, so boxes that overlap or touch share a cell at every level (`CellRange::of`).
//!   The pair rule is [`Aabb::intersects`] (closed boxes) and
//!   [`Proxy::may_pair`](super::Proxy::may_pair), as in every broad phase.
//! - The pair set holds exactly those pairs of the stored boxes.
//!
//! # Costs (`n` bodies, `k` pairs in the set, `c` candidates a body gathers)
//! - [`update`](HashGrid::update): `O(c)` box tests, each candidate once, and up to 8 hash
//!   look-ups (27 at worst) per level at or above its own, twice when it left or entered a
//!   cell there; only those levels' cell lists change. `O(n)` for an oversized body, and
//!   every body gathers every oversized one. A body not updated costs nothing.
//! - [`insert`](HashGrid::insert), [`remove`](HashGrid::remove): one such query and up to 8
//!   cell-list edits per level at or above its own (the [`AUTO_SAMPLE`]-th insertion places
//!   every body once).
//! - [`pairs`](HashGrid::pairs): `O(k + e log e)` for `e` pair changes (`pair_set.rs`).
//!
//! # Input, and when to choose it
//! Bounds are trusted: finite with `min <= max` (the [`Aabb`] invariant), checked by
//! `debug_assert!`. The automatic choice ([`choose`](super::choose)) never takes it: on
//! every measured class another kind is faster. It stays available as a fixed choice.

use std::collections::HashMap;
use std::hash::{BuildHasher, Hash, Hasher};

use super::body_map::Bodies;
use super::pair_set::PairSet;
use super::stateful::{StatefulBroadPhase, stateful_api};
use super::{CandidatePair, floor_to_i64};
use crate::bounding::{Aabb, BoundingVolume};

/// Cell-size ratio between consecutive levels chosen by [`HashGrid::new`].
pub const DEFAULT_RATIO: f64 = 2.0;
/// Bodies [`HashGrid::new`] waits for before choosing its levels from their sizes.
pub const AUTO_SAMPLE: usize = 64;
/// Most levels a grid may have.
pub const MAX_LEVELS: usize = 32;

/// `level_of` value of a body in the oversized list: larger than the coarsest cell, or
/// any body while the levels are not chosen. Each is tested against every body, and every
/// body against it, so a few huge bodies (a floor, a table, a terrain box) do not force a
/// level whose cells hold everything; many of them make each of their moves `O(n)`.
const OVERSIZED: u8 = u8::MAX;
/// Flag on a cell entry: the body is listed there from a finer level (module docs,
/// "Invariants"); the low 31 bits are its slot.
const FROM_FINER: u32 = 1 << 31;

/// Integer coordinates of one cell of one level.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Cell([i64; 3]);

impl Hash for Cell {
    #[inline]
    fn hash<H: Hasher>(&self, state: &mut H) {
        for c in self.0 {
            state.write_i64(c);
        }
    }
}

/// Builds a [`CellHasher`] seeded with the level, so equal coordinates of different levels
/// hash apart.
#[derive(Debug, Clone, Copy)]
struct BuildCellHasher {
    seed: u64,
}

impl BuildHasher for BuildCellHasher {
    type Hasher = CellHasher;

    #[inline]
    fn build_hasher(&self) -> CellHasher {
        CellHasher {
            state: self.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15),
        }
    }
}

/// FxHash-style absorb (rotate, xor, multiply) of each cell coordinate from a seed that is
/// the level, with a SplitMix64 finaliser: every input bit reaches the high bits the map's
/// control bytes use and the low bits its bucket index uses.
#[derive(Debug, Clone, Copy)]
struct CellHasher {
    state: u64,
}

impl CellHasher {
    #[inline]
    fn absorb(&mut self, word: u64) {
        self.state = (self.state.rotate_left(23) ^ word).wrapping_mul(0x517C_C1B7_2722_0A95);
    }
}

impl Hasher for CellHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.absorb(u64::from(b));
        }
    }

    #[inline]
    fn write_i64(&mut self, value: i64) {
        self.absorb(value as u64);
    }

    #[inline]
    fn finish(&self) -> u64 {
        crate::math::splitmix64(self.state)
    }
}

/// The cells a box covers at one level: `lo[axis] ..= hi[axis]`.
///
/// At most 3 per axis for a box no wider than the cell, even far from the origin: on an
/// axis where the box has positive extent, the extent is at least one ulp of its
/// coordinates and at most the cell edge, so `coordinate / edge` stays below 2⁵⁴, where
/// products are spaced at most 2 apart and the two ends' cell indices still differ by at
/// most 2 (checked by `debug_assert!` on every registration).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct CellRange {
    lo: [i64; 3],
    hi: [i64; 3],
}

impl CellRange {
    /// The cells of edge `1 / inv` that the closed box `bounds` meets (conservative: a box
    /// ending exactly on a boundary meets the cells on both sides).
    ///
    /// A coordinate `x` is in cell `⌊x / edge⌋`, computed as `⌊x · inv⌋` and clamped to
    /// `i64`. That map is monotone (rounded products by a positive constant and floors
    /// never reverse an order), so when two boxes overlap or touch on an axis
    /// (`a.min ≤ b.max`, `b.min ≤ a.max`) their cell ranges on that axis overlap too,
    /// whatever the rounding: touching boxes share a cell at every level. `-0.0` and `0.0`
    /// fall in the same cell.
    #[inline]
    fn of(bounds: &Aabb, inv: f64) -> Self {
        let cell = |x: f64| floor_to_i64(x * inv);
        Self {
            lo: [0, 1, 2].map(|axis| cell(bounds.min[axis])),
            hi: [0, 1, 2].map(|axis| cell(bounds.max[axis])),
        }
    }

    /// Number of cells, saturated.
    #[inline]
    fn count(&self) -> u128 {
        (0..3)
            .map(|axis| (i128::from(self.hi[axis]) - i128::from(self.lo[axis]) + 1) as u128)
            .fold(1u128, u128::saturating_mul)
    }

    /// Calls `f` for every cell of the range.
    #[inline]
    fn for_each(&self, mut f: impl FnMut(Cell)) {
        for x in self.lo[0]..=self.hi[0] {
            for y in self.lo[1]..=self.hi[1] {
                for z in self.lo[2]..=self.hi[2] {
                    f(Cell([x, y, z]));
                }
            }
        }
    }
}

/// Entries a cell holds in place before it moves them to the heap.
const INLINE_ENTRIES: usize = 5;

/// The entries of one cell. Most cells hold a few bodies: those are stored in the table's
/// own slot, so a look-up that finds the cell has its entries without chasing a pointer (a
/// cache miss per look-up when every list was a `Vec`); a crowded cell spills to the heap.
#[derive(Debug, Clone)]
enum CellList {
    Inline {
        len: u32,
        items: [u32; INLINE_ENTRIES],
    },
    Heap(Vec<u32>),
}

impl Default for CellList {
    fn default() -> Self {
        Self::Inline {
            len: 0,
            items: [0; INLINE_ENTRIES],
        }
    }
}

impl CellList {
    #[inline]
    fn push(&mut self, entry: u32) {
        match self {
            Self::Inline { len, items } if (*len as usize) < INLINE_ENTRIES => {
                items[*len as usize] = entry;
                *len += 1;
            }
            Self::Inline { items, .. } => {
                let mut spilled = items.to_vec();
                spilled.push(entry);
                *self = Self::Heap(spilled);
            }
            Self::Heap(list) => list.push(entry),
        }
    }

    /// Removes entry `i`, moving the last into its place. A spilled list stays on the heap
    /// (no churn for a cell whose population hovers around the inline size).
    #[inline]
    fn swap_remove(&mut self, i: usize) {
        match self {
            Self::Inline { len, items } => {
                *len -= 1;
                items[i] = items[*len as usize];
            }
            Self::Heap(list) => {
                list.swap_remove(i);
            }
        }
    }
}

/// Equal entries in the same order, wherever they are stored.
impl PartialEq for CellList {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl std::ops::Deref for CellList {
    type Target = [u32];

    #[inline]
    fn deref(&self) -> &[u32] {
        match self {
            Self::Inline { len, items } => &items[..*len as usize],
            Self::Heap(list) => list,
        }
    }
}

impl std::ops::DerefMut for CellList {
    #[inline]
    fn deref_mut(&mut self) -> &mut [u32] {
        match self {
            Self::Inline { len, items } => &mut items[..*len as usize],
            Self::Heap(list) => list,
        }
    }
}

/// One uniform grid of the hierarchy.
#[derive(Debug, Clone)]
struct Level {
    /// Cell edge, metres.
    size: f64,
    /// `1 / size`.
    inv: f64,
    /// Occupied cells → slots of this level's bodies whose box meets the cell.
    cells: HashMap<Cell, CellList, BuildCellHasher>,
    /// Slots of the bodies stored at this level.
    members: Vec<u32>,
}

/// Hierarchical hash grid over bodies identified by `u32` ids; see the module docs for the
/// levels, the oversized list, the tie rule and the costs. Same body-level API and output
/// contract as [`IncrementalSap`](super::IncrementalSap).
#[derive(Debug, Clone)]
pub struct HashGrid {
    /// Finest first; empty until chosen (then every body is oversized).
    levels: Vec<Level>,
    /// The bodies, densely by slot; `bodies.proxies[s].bounds` is what the cells hold.
    bodies: Bodies,
    /// Level of each slot, or [`OVERSIZED`].
    level_of: Vec<u8>,
    /// Index of each slot in its level's (or the oversized) member list.
    member_at: Vec<u32>,
    /// Slots of the oversized bodies.
    oversized: Vec<u32>,
    /// The pairs whose boxes overlap and that may pair, `a < b`.
    pairs: PairSet,
    /// Per slot, the query stamp that last gathered it (no candidate tested twice).
    seen: Vec<u32>,
    /// Current query stamp, never 0.
    stamp: u32,
    /// Candidate slots of the current query.
    scratch: Vec<u32>,
}

impl Default for HashGrid {
    fn default() -> Self {
        Self::new()
    }
}

impl HashGrid {
    /// An empty grid that chooses its levels from its first [`AUTO_SAMPLE`] bodies, so that
    /// a body's box covers about 3 to 8 cells of its level; until then every body is
    /// oversized (all pairs tested: the right algorithm for so few).
    #[must_use]
    pub fn new() -> Self {
        Self {
            levels: Vec::new(),
            bodies: Bodies::default(),
            level_of: Vec::new(),
            member_at: Vec::new(),
            oversized: Vec::new(),
            pairs: PairSet::default(),
            seen: Vec::new(),
            stamp: 1,
            scratch: Vec::new(),
        }
    }

    /// An empty grid with `count` levels of cell edges `min_cell · ratioᵏ` metres.
    ///
    /// # Panics
    /// Unless `min_cell > 0`, `ratio ≥ 2`, `1 ≤ count ≤ MAX_LEVELS` and the coarsest edge is
    /// finite.
    #[must_use]
    pub fn with_levels(min_cell: f64, ratio: f64, count: usize) -> Self {
        let mut grid = Self::new();
        grid.set_levels(min_cell, ratio, count);
        grid
    }

    /// Cell edges of the levels, finest first, metres; empty while [`new`](Self::new) is
    /// still waiting for its sample.
    pub fn cell_sizes(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        self.levels.iter().map(|l| l.size)
    }

    /// The level `body` is stored at (`Some(None)` when it is oversized), `None` when absent.
    #[must_use]
    pub fn level(&self, body: u32) -> Option<Option<usize>> {
        let slot = self.bodies.slot(body)?;
        let level = self.level_of[slot];
        Some((level != OVERSIZED).then_some(usize::from(level)))
    }

    /// Builds the levels (see [`with_levels`](Self::with_levels) for the panics).
    fn set_levels(&mut self, min_cell: f64, ratio: f64, count: usize) {
        assert!(
            min_cell.is_finite() && min_cell > 0.0,
            "min_cell must be positive: {min_cell}"
        );
        assert!(
            ratio.is_finite() && ratio >= 2.0,
            "ratio must be ≥ 2: {ratio}"
        );
        assert!(
            (1..=MAX_LEVELS).contains(&count),
            "level count must be in 1..={MAX_LEVELS}: {count}"
        );
        let mut size = min_cell;
        self.levels = (0..count)
            .map(|k| {
                let level = Level {
                    size,
                    inv: 1.0 / size,
                    cells: HashMap::with_hasher(BuildCellHasher { seed: k as u64 }),
                    members: Vec::new(),
                };
                size *= ratio;
                level
            })
            .collect();
        let coarsest = self.levels[count - 1].size;
        assert!(
            coarsest.is_finite() && self.levels[count - 1].inv > 0.0,
            "coarsest cell {coarsest} m out of range"
        );
    }

    /// The automatic level choice, then every body placed: at the [`AUTO_SAMPLE`]-th
    /// insertion, `min_cell` is twice the 10th percentile of the bodies' positive largest
    /// extents (1 m if all are points), `ratio` is 2 and `count` the fewest levels whose
    /// coarsest cell is at least 4 × the largest extent seen (two spare levels for larger
    /// bodies later), at most [`MAX_LEVELS`]. A body's cell is then 1 to 2 times its extent
    /// at its level (more at level 0), so its box covers about 3 to 8 cells; cells of just
    /// its size would make most boxes straddle 8, and unit dice on a table would sit exactly
    /// at a level boundary, split over two levels.
    fn choose_levels_from_bodies(&mut self) {
        let mut extents: Vec<f64> = self
            .bodies
            .proxies
            .iter()
            .map(|p| p.bounds.extents().max_element())
            .filter(|&e| e > 0.0)
            .collect();
        extents.sort_unstable_by(f64::total_cmp);
        let (min_cell, largest) = match (extents.get(extents.len() / 10), extents.last()) {
            (Some(&p10), Some(&largest)) => (2.0 * p10, largest),
            _ => (1.0, 1.0),
        };
        let mut count = 1;
        let mut coarsest = min_cell;
        while coarsest < 4.0 * largest && count < MAX_LEVELS {
            coarsest *= DEFAULT_RATIO;
            count += 1;
        }
        self.set_levels(min_cell, DEFAULT_RATIO, count);
        self.oversized.clear();
        for slot in 0..self.bodies.proxies.len() {
            self.level_of[slot] = self.level_for(&self.bodies.proxies[slot].bounds);
            self.register(slot);
        }
    }

    /// The level a box belongs at: the finest whose cell edge is at least its largest extent,
    /// or [`OVERSIZED`].
    fn level_for(&self, bounds: &Aabb) -> u8 {
        let extent = bounds.extents().max_element();
        self.levels
            .iter()
            .position(|l| extent <= l.size)
            .map_or(OVERSIZED, |k| k as u8)
    }

    fn members(&self, level: u8) -> &Vec<u32> {
        if level == OVERSIZED {
            &self.oversized
        } else {
            &self.levels[usize::from(level)].members
        }
    }

    fn members_mut(&mut self, level: u8) -> &mut Vec<u32> {
        if level == OVERSIZED {
            &mut self.oversized
        } else {
            &mut self.levels[usize::from(level)].members
        }
    }

    /// Lists slot `slot` among its level's members, and in the cells its stored box covers
    /// at its level and, flagged [`FROM_FINER`], at every coarser level.
    fn register(&mut self, slot: usize) {
        let level = self.level_of[slot];
        let members = self.members_mut(level);
        let at = members.len() as u32;
        members.push(slot as u32);
        self.member_at[slot] = at;
        if level != OVERSIZED {
            let bounds = self.bodies.proxies[slot].bounds;
            for k in usize::from(level)..self.levels.len() {
                self.list_at(slot, k, &bounds, usize::from(level));
            }
        }
    }

    /// Adds slot `slot` (at level `own`) to the cells `bounds` covers at level `k ≥ own`.
    fn list_at(&mut self, slot: usize, k: usize, bounds: &Aabb, own: usize) {
        let grid = &mut self.levels[k];
        let range = CellRange::of(bounds, grid.inv);
        debug_assert!(
            range.count() <= 27,
            "a box spans {range:?} at level {k} ≥ its own"
        );
        let entry = slot as u32 | if k > own { FROM_FINER } else { 0 };
        range.for_each(|cell| grid.cells.entry(cell).or_default().push(entry));
    }

    /// Removes slot `slot` from the cells `bounds` covers at level `k`.
    fn unlist_at(&mut self, slot: usize, k: usize, bounds: &Aabb) {
        let grid = &mut self.levels[k];
        CellRange::of(bounds, grid.inv).for_each(|cell| {
            let list = grid.cells.get_mut(&cell).expect("registered cell exists");
            let i = list
                .iter()
                .position(|&e| (e & !FROM_FINER) as usize == slot)
                .expect("registered in its cell");
            list.swap_remove(i);
            if list.is_empty() {
                grid.cells.remove(&cell);
            }
        });
    }

    /// Undoes [`register`](Self::register) (from the stored box and level).
    fn unregister(&mut self, slot: usize) {
        let level = self.level_of[slot];
        let at = self.member_at[slot] as usize;
        let members = self.members_mut(level);
        members.swap_remove(at);
        if let Some(&moved) = members.get(at) {
            self.member_at[moved as usize] = at as u32;
        }
        if level != OVERSIZED {
            let bounds = self.bodies.proxies[slot].bounds;
            for k in usize::from(level)..self.levels.len() {
                self.unlist_at(slot, k, &bounds);
            }
        }
    }

    /// Renames slot `from`'s registrations to `to` (the last slot filling a freed one).
    fn rename(&mut self, from: usize, to: usize) {
        let level = self.level_of[from];
        let at = self.member_at[from] as usize;
        self.members_mut(level)[at] = to as u32;
        if level != OVERSIZED {
            let bounds = self.bodies.proxies[from].bounds;
            for grid in &mut self.levels[usize::from(level)..] {
                CellRange::of(&bounds, grid.inv).for_each(|cell| {
                    let list = grid.cells.get_mut(&cell).expect("registered cell exists");
                    for e in list
                        .iter_mut()
                        .filter(|e| (**e & !FROM_FINER) as usize == from)
                    {
                        *e = to as u32 | (*e & FROM_FINER);
                    }
                });
            }
        }
    }

    /// Starts a new query: clears the candidates and moves to a fresh stamp.
    fn next_stamp(&mut self) {
        self.scratch.clear();
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.stamp = 1;
        }
    }

    /// Adds to `scratch` every body other than `slot` that a body at `level` with box
    /// `bounds` could overlap (module docs, "Invariants"), each once per stamp.
    fn gather(&mut self, slot: usize, bounds: &Aabb, level: u8) {
        let Self {
            levels,
            oversized,
            seen,
            stamp,
            scratch,
            ..
        } = self;
        let (stamp, n) = (*stamp, seen.len() as u32);
        let mut take = |s: u32| {
            let i = s as usize;
            if i != slot && seen[i] != stamp {
                seen[i] = stamp;
                scratch.push(s);
            }
        };
        if level == OVERSIZED {
            for s in 0..n {
                take(s);
            }
            return;
        }
        for &s in oversized.iter() {
            take(s);
        }
        let level = usize::from(level);
        for (k, grid) in levels.iter().enumerate().skip(level) {
            // Coarser levels: only their own bodies (finer ones are listed at `level`).
            let own_only = k > level;
            if own_only && grid.members.is_empty() {
                continue;
            }
            CellRange::of(bounds, grid.inv).for_each(|cell| {
                if let Some(list) = grid.cells.get(&cell) {
                    for &e in list.iter() {
                        if !(own_only && e & FROM_FINER != 0) {
                            take(e & !FROM_FINER);
                        }
                    }
                }
            });
        }
    }

    /// Whether boxes `a` and `b` at `level` would gather from the same cells.
    fn same_query_cells(&self, a: &Aabb, b: &Aabb, level: u8) -> bool {
        level == OVERSIZED
            || self
                .levels
                .iter()
                .enumerate()
                .skip(usize::from(level))
                .all(|(k, grid)| {
                    (grid.members.is_empty() && k != usize::from(level))
                        || CellRange::of(a, grid.inv) == CellRange::of(b, grid.inv)
                })
    }

    /// Sets each gathered candidate's pair with `slot` from the current boxes, logging only
    /// the pairs that changed: a pair was in the set exactly when `old` (slot's box before
    /// this update; `None` for a new body) met the candidate's box, which did not move.
    fn refresh(&mut self, slot: usize, old: Option<&Aabb>) {
        let p = self.bodies.proxies[slot];
        for &other in &self.scratch {
            let q = &self.bodies.proxies[other as usize];
            if !p.may_pair(q) {
                continue;
            }
            let was = old.is_some_and(|old| old.intersects(&q.bounds));
            let is = p.bounds.intersects(&q.bounds);
            if was != is {
                let key = CandidatePair::of(p.body, q.body);
                if is {
                    self.pairs.insert(key);
                } else {
                    self.pairs.remove(key);
                }
            }
        }
    }
}

stateful_api!(HashGrid);

impl StatefulBroadPhase for HashGrid {
    fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    fn bodies_mut(&mut self) -> &mut Bodies {
        &mut self.bodies
    }

    /// Registered at its level (or, at the [`AUTO_SAMPLE`]-th body, every body placed as
    /// the levels are chosen), then its pairs found by one query.
    fn file(&mut self, slot: usize) {
        let bounds = self.bodies.proxies[slot].bounds;
        debug_assert!(slot < FROM_FINER as usize, "too many bodies");
        self.level_of.push(self.level_for(&bounds));
        self.member_at.push(0);
        self.seen.push(0);
        if self.levels.is_empty() && self.bodies.proxies.len() == AUTO_SAMPLE {
            self.choose_levels_from_bodies();
        } else {
            self.register(slot);
        }
        self.next_stamp();
        self.gather(slot, &bounds, self.level_of[slot]);
        self.refresh(slot, None);
    }

    fn unfile(&mut self, slot: usize) {
        self.next_stamp();
        let p = self.bodies.proxies[slot];
        self.gather(slot, &p.bounds, self.level_of[slot]);
        for &other in &self.scratch {
            let q = &self.bodies.proxies[other as usize];
            if p.may_pair(q) && p.bounds.intersects(&q.bounds) {
                self.pairs.remove(CandidatePair::of(p.body, q.body));
            }
        }
        self.unregister(slot);
    }

    fn swap_remove_slot(&mut self, slot: usize) {
        let last = self.bodies.len() - 1;
        if slot != last {
            self.rename(last, slot);
        }
        self.level_of.swap_remove(slot);
        self.member_at.swap_remove(slot);
        self.seen.swap_remove(slot);
    }

    /// Refreshes its pairs: gathers the candidates of its old box and, if it changed level
    /// or left or entered a cell at some level queried, of its new box too. Every old pair
    /// shares a cell with the old box and every new pair with the new box, so testing these
    /// candidates against both boxes leaves the set exact ([`refresh`](HashGrid::refresh)).
    /// A body that moved within its cells changes no cell list and re-tests only the bodies
    /// in its cells: its close pairs.
    #[inline]
    fn relocate(&mut self, slot: usize, bounds: Aabb) {
        let old = self.bodies.proxies[slot].bounds;
        let (old_level, new_level) = (self.level_of[slot], self.level_for(&bounds));
        self.next_stamp();
        self.gather(slot, &old, old_level);
        if old_level != new_level || !self.same_query_cells(&old, &bounds, old_level) {
            self.gather(slot, &bounds, new_level);
        }
        if old_level != new_level {
            self.unregister(slot);
            self.bodies.proxies[slot].bounds = bounds;
            self.level_of[slot] = new_level;
            self.register(slot);
        } else {
            // Same level: only the levels whose cells it left or entered change.
            if old_level != OVERSIZED {
                let own = usize::from(old_level);
                for k in own..self.levels.len() {
                    let inv = self.levels[k].inv;
                    if CellRange::of(&old, inv) != CellRange::of(&bounds, inv) {
                        self.unlist_at(slot, k, &old);
                        self.list_at(slot, k, &bounds, own);
                    }
                }
            }
            self.bodies.proxies[slot].bounds = bounds;
        }
        self.refresh(slot, Some(&old));
    }

    fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        self.pairs.list(out);
    }

    /// Checks every invariant: the slot table and id map agree; stored boxes are finite and
    /// not inverted; each body is at the level its box calls for (oversized when none, or
    /// while the levels are not chosen), listed once among that level's members at the
    /// recorded index, and in exactly the cells its box covers at its level and (flagged
    /// `FROM_FINER`) at every coarser one, once each, with no empty or foreign cell
    /// entries; and the pair set equals [`pairs_brute_force`](super::pairs_brute_force) over
    /// the stored boxes.
    fn validate(&self) -> Result<(), String> {
        self.bodies.check()?;
        let n = self.bodies.len();
        if [self.level_of.len(), self.member_at.len(), self.seen.len()] != [n; 3] {
            return Err(format!("{n} proxies, per-slot tables disagree"));
        }
        let mut entries = vec![0usize; self.levels.len()];
        for (slot, p) in self.bodies.proxies.iter().enumerate() {
            let b = &p.bounds;
            if !(b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()) {
                return Err(format!("body {} has invalid bounds {b:?}", p.body));
            }
            let level = self.level_of[slot];
            if level != self.level_for(b) {
                return Err(format!(
                    "body {} at level {level}, its box {b:?} calls for {}",
                    p.body,
                    self.level_for(b)
                ));
            }
            let members = self.members(level);
            let at = self.member_at[slot] as usize;
            if members.get(at) != Some(&(slot as u32)) {
                return Err(format!("body {} not listed at member index {at}", p.body));
            }
            if level == OVERSIZED {
                continue;
            }
            let own = usize::from(level);
            let mut bad = None;
            for (k, grid) in self.levels.iter().enumerate().skip(own) {
                let entry = slot as u32 | if k > own { FROM_FINER } else { 0 };
                CellRange::of(b, grid.inv).for_each(|cell| {
                    entries[k] += 1;
                    let here = grid.cells.get(&cell).map_or(0, |list| {
                        list.iter()
                            .filter(|&&e| e & !FROM_FINER == slot as u32)
                            .count()
                    });
                    let flagged = grid.cells.get(&cell).is_some_and(|l| l.contains(&entry));
                    if (here != 1 || !flagged) && bad.is_none() {
                        bad = Some(format!(
                            "body {} listed {here} times in level {k} cell {cell:?} \
                             (own level {own}, correctly flagged: {flagged})",
                            p.body
                        ));
                    }
                });
            }
            if let Some(e) = bad {
                return Err(e);
            }
        }
        let listed: usize = self.levels.iter().map(|l| l.members.len()).sum();
        if listed + self.oversized.len() != n {
            return Err(format!(
                "{listed} + {} members, {n} bodies",
                self.oversized.len()
            ));
        }
        for (k, grid) in self.levels.iter().enumerate() {
            let stored: usize = grid.cells.values().map(|l| l.len()).sum();
            if stored != entries[k] || grid.cells.values().any(|l| l.is_empty()) {
                return Err(format!(
                    "level {k}: {stored} cell entries (or an empty cell), bodies cover {}",
                    entries[k]
                ));
            }
        }
        self.pairs.check_against_brute_force(&self.bodies.proxies)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::{CollisionFilter, pairs_brute_force};
    use crate::math::DVec3;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;
    use std::collections::BTreeSet;

    fn cube(lo: DVec3, size: f64) -> Aabb {
        Aabb::new(lo, lo + DVec3::splat(size))
    }

    use crate::broad::conformance::{self, pairs_of, unit_at};

    /// The cells of `level` that list `body`.
    fn cells_of(grid: &HashGrid, body: u32, level: usize) -> Vec<[i64; 3]> {
        let slot = grid.bodies.slot(body).unwrap() as u32;
        let mut cells: Vec<[i64; 3]> = grid.levels[level]
            .cells
            .iter()
            .filter(|(_, list)| list.contains(&slot))
            .map(|(cell, _)| cell.0)
            .collect();
        cells.sort_unstable();
        cells
    }

    #[test]
    fn boxes_ending_on_a_cell_boundary_are_in_the_cells_on_both_sides_and_touching_boxes_pair() {
        // Level 0: 1 m cells, level 1: 2 m, level 2: 4 m.
        let mut grid = HashGrid::with_levels(1.0, 2.0, 3);
        grid.insert(0, unit_at(0.0, 0.0, 0.0), false, CollisionFilter::ALL);
        // Both ends of [0, 1] lie on boundaries: cells 0 and 1 on every axis.
        assert_eq!(grid.level(0), Some(Some(0)));
        let mut expected = Vec::new();
        for x in 0..2 {
            for y in 0..2 {
                for z in 0..2 {
                    expected.push([x, y, z]);
                }
            }
        }
        assert_eq!(cells_of(&grid, 0, 0), expected);
        grid.insert(1, unit_at(1.0, 0.0, 0.0), false, CollisionFilter::ALL); // face
        grid.insert(2, unit_at(1.0, 1.0, 0.0), false, CollisionFilter::ALL); // edge with 0
        grid.insert(3, unit_at(-1.0, -1.0, -1.0), false, CollisionFilter::ALL); // corner
        // Level 1, touching 0 and 2 at x = 2 and 1 at its face x = 2.
        grid.insert(
            4,
            cube(DVec3::new(2.0, 0.0, 0.0), 2.0),
            false,
            CollisionFilter::ALL,
        );
        // Level 2, touching 3 only at its corner (-1, -1, -1).
        grid.insert(
            5,
            cube(DVec3::splat(-5.0), 4.0),
            false,
            CollisionFilter::ALL,
        );
        assert_eq!(grid.level(4), Some(Some(1)));
        assert_eq!(grid.level(5), Some(Some(2)));
        let all = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 4), (2, 4), (3, 5)];
        assert_eq!(pairs_of(&mut grid), all);
        // One ulp apart on each side, by motion; then back to touching, by motion.
        let up = |x: f64| f64::from_bits(x.to_bits() + 1);
        grid.update(1, unit_at(up(1.0), 0.0, 0.0));
        grid.update(5, cube(DVec3::splat(-5.0 - 4.0 * f64::EPSILON), 4.0));
        assert_eq!(
            pairs_of(&mut grid),
            [(0, 2), (0, 3), (1, 2), (1, 4), (2, 4)]
        );
        grid.update(4, cube(DVec3::new(up(2.0), 0.0, 0.0), 2.0));
        assert_eq!(pairs_of(&mut grid), [(0, 2), (0, 3), (1, 2)]);
        grid.update(1, unit_at(1.0, 0.0, 0.0));
        grid.update(4, cube(DVec3::new(2.0, 0.0, 0.0), 2.0));
        grid.update(5, cube(DVec3::splat(-5.0), 4.0));
        assert_eq!(pairs_of(&mut grid), all);
    }

    #[test]
    fn negative_zero_and_zero_share_a_cell_and_tie_as_in_aabb_intersects() {
        let mut grid = HashGrid::with_levels(1.0, 2.0, 2);
        let a = Aabb::new(DVec3::splat(-1.0), DVec3::splat(-0.0));
        let b = Aabb::new(DVec3::splat(0.0), DVec3::splat(1.0));
        assert!(a.intersects(&b));
        grid.insert(0, a, false, CollisionFilter::ALL);
        grid.insert(1, b, false, CollisionFilter::ALL);
        assert!(cells_of(&grid, 0, 0).contains(&[0, 0, 0]));
        assert_eq!(pairs_of(&mut grid), [(0, 1)]);
        grid.update(1, Aabb::new(DVec3::splat(3.0), DVec3::splat(4.0)));
        assert_eq!(pairs_of(&mut grid), []);
        grid.update(1, b);
        assert_eq!(pairs_of(&mut grid), [(0, 1)]);
    }

    #[test]
    fn zero_size_bodies_sit_in_one_cell_per_boundary_side_and_pair_when_they_touch() {
        let mut grid = HashGrid::with_levels(0.5, 2.0, 3);
        let point = |x: f64| Aabb::new(DVec3::splat(x), DVec3::splat(x));
        grid.insert(7, point(0.5), false, CollisionFilter::ALL);
        grid.insert(8, point(0.5), false, CollisionFilter::ALL);
        grid.insert(9, point(1.0), false, CollisionFilter::ALL); // corner of the unit box
        grid.insert(10, point(1.5), false, CollisionFilter::ALL);
        grid.insert(3, unit_at(0.0, 0.0, 0.0), false, CollisionFilter::ALL);
        // A point is one cell even on a boundary; the unit box (level 1) covers 2 per axis.
        assert_eq!(grid.level(7), Some(Some(0)));
        assert_eq!(cells_of(&grid, 7, 0), [[1, 1, 1]]);
        assert_eq!(grid.level(3), Some(Some(1)));
        assert_eq!(cells_of(&grid, 3, 1).len(), 8);
        assert_eq!(pairs_of(&mut grid), [(3, 7), (3, 8), (3, 9), (7, 8)]);
        // Points walking across each other, the box's faces and cell boundaries, exactly.
        let mut seen = [0; 2];
        for step in 0..=24 {
            let x = f64::from(step) * 0.0625;
            grid.update(10, point(1.5 - x));
            grid.update(7, point(x));
            let mut expected = Vec::new();
            pairs_brute_force(grid.proxies(), &mut expected);
            let mut found = Vec::new();
            grid.pairs(&mut found);
            assert_eq!(found, expected, "step {step}");
            grid.validate().unwrap();
            seen[usize::from(found.contains(&CandidatePair::of(7, 10)))] += 1;
        }
        assert!(seen[0] > 0 && seen[1] > 0, "{seen:?}");
    }

    #[test]
    fn bodies_larger_than_the_coarsest_cell_are_oversized_and_pair_with_all_they_touch() {
        // Coarsest cell 4 m.
        let mut grid = HashGrid::with_levels(1.0, 2.0, 3);
        let floor = Aabb::new(DVec3::new(-50.0, -50.0, -1.0), DVec3::new(50.0, 50.0, 0.0));
        let wall = Aabb::new(DVec3::new(10.0, -50.0, -1.0), DVec3::new(11.0, 50.0, 20.0));
        grid.insert(100, floor, true, CollisionFilter::ALL);
        grid.insert(101, wall, false, CollisionFilter::ALL);
        assert_eq!(grid.level(100), Some(None));
        assert_eq!(grid.level(101), Some(None));
        // A static oversized ramp through the floor.
        let ramp = Aabb::new(DVec3::new(-20.0, -3.0, -5.0), DVec3::new(20.0, 3.0, 2.0));
        grid.insert(102, ramp, true, CollisionFilter::ALL);
        assert!(ramp.intersects(&floor));
        assert!(grid.levels.iter().all(|l| l.cells.is_empty()));
        let mut rng = rng(808);
        for id in 0..60u32 {
            let lo = point_in_cube(&mut rng, 12.0);
            grid.insert(
                id,
                cube(lo, rng.random_range(0.0..4.0)),
                false,
                CollisionFilter::ALL,
            );
        }
        let (mut with_floor, mut with_wall) = (0, 0);
        for frame in 0..200 {
            for id in 0..60u32 {
                let b = grid.bodies.proxies[grid.bodies.slot(id).unwrap()].bounds;
                let s = point_in_cube(&mut rng, 0.5);
                grid.update(id, Aabb::new(b.min + s, b.max + s));
            }
            // The wall slides, shrinks to fit a level and grows back.
            let x = 10.0 * (f64::from(frame) * 0.1).sin();
            let wall = if frame % 50 == 25 {
                unit_at(x, 0.0, 0.0)
            } else {
                Aabb::new(DVec3::new(x, -50.0, -1.0), DVec3::new(x + 1.0, 50.0, 20.0))
            };
            grid.update(101, wall);
            for (a, b) in pairs_of(&mut grid) {
                with_floor += usize::from(b == 100);
                with_wall += usize::from(b == 101);
                assert!(
                    (a, b) != (100, 102),
                    "static floor pairs with the static ramp"
                );
            }
        }
        assert!(
            with_floor > 1_000 && with_wall > 1_000,
            "{with_floor} {with_wall}"
        );
    }

    #[test]
    fn a_removed_id_can_be_reinserted_with_new_bounds_kind_and_filter() {
        let mut grid = HashGrid::with_levels(0.5, 2.0, 4);
        // The replacement is a body of another level.
        conformance::removed_ids_come_back_with_new_bounds_kind_and_filter(
            &mut grid,
            cube(DVec3::splat(-9.0), 3.0),
        );
        assert_eq!(grid.level(2), Some(Some(3)));
        conformance::removing_every_body_empties_it(&mut grid);
        assert!(
            grid.levels
                .iter()
                .all(|l| l.cells.is_empty() && l.members.is_empty())
        );
    }

    #[test]
    fn static_bodies_never_pair_with_each_other_however_they_overlap() {
        let boxed = |rng: &mut TestRng| {
            let c = point_in_cube(rng, 1.0);
            let h = DVec3::splat(rng.random_range(0.0..1.0));
            Aabb::new(c - h, c + h)
        };
        let mut grid = HashGrid::new();
        conformance::static_bodies_never_pair_with_each_other(
            &mut grid,
            &mut rng(606),
            100,
            boxed,
            10_000,
        );
        assert!(grid.cell_sizes().len() > 1);
    }

    /// Sizes spanning seven orders of magnitude over 24 levels (and beyond: oversized), with
    /// bodies changing level as they move; every operation is validated, and both ways of
    /// looking at finer levels (their cells, or all their bodies) are used.
    #[test]
    fn many_levels_with_sizes_over_seven_orders_of_magnitude_agree_with_brute_force() {
        let mut grid = HashGrid::with_levels(1e-3, 2.0, 24);
        let coarsest = grid.cell_sizes().last().unwrap();
        assert!((8_000.0..9_000.0).contains(&coarsest), "{coarsest}");
        let mut rng = rng(909);
        // Half the sizes log-uniform, half crowded into three adjacent levels.
        let random_box = |rng: &mut TestRng| {
            let size = if rng.random_bool(0.5) {
                10f64.powf(rng.random_range(-3.5..4.2))
            } else {
                rng.random_range(0.5..4.0)
            };
            let c = point_in_cube(rng, 2.0) * size.max(1.0).sqrt();
            Aabb::new(c, c + DVec3::splat(size))
        };
        let (mut finer_pairs, mut level_changes, mut pairs) = (0, 0, 0);
        let mut levels_used = BTreeSet::new();
        for id in 0..200u32 {
            grid.insert(id, random_box(&mut rng), false, CollisionFilter::ALL);
        }
        for op in 0..3_000 {
            let id = rng.random_range(0..200u32);
            let slot = grid.bodies.slot(id).unwrap();
            let old = grid.bodies.proxies[slot].bounds;
            let bounds = if rng.random_bool(0.7) {
                let s = point_in_cube(&mut rng, 0.2 * old.extents().max_element().max(1e-3));
                Aabb::new(old.min + s, old.max + s)
            } else {
                random_box(&mut rng)
            };
            let level = grid.level_for(&bounds);
            level_changes += usize::from(level != grid.level_of[slot]);
            levels_used.insert(level);
            grid.update(id, bounds);
            grid.validate().unwrap_or_else(|e| panic!("op {op}: {e}"));
            let mut now = Vec::new();
            grid.pairs(&mut now);
            // Pairs whose bodies sit at different levels: found through the flagged entries.
            finer_pairs += now
                .iter()
                .filter(|p| grid.level(p.a) != grid.level(p.b))
                .count();
            pairs += now.len();
        }
        assert!(levels_used.len() >= 20, "{levels_used:?}");
        assert!(levels_used.contains(&OVERSIZED), "{levels_used:?}");
        assert!(level_changes > 500, "{level_changes}");
        assert!(
            finer_pairs > 5_000 && pairs > 10_000,
            "{finer_pairs} {pairs}"
        );
    }

    #[test]
    fn new_chooses_its_levels_from_the_first_sixty_four_bodies() {
        let mut grid = HashGrid::new();
        // Extents 0.1, 0.2, ..., 6.3 m and one point.
        for id in 0..63u32 {
            let size = f64::from(id) * 0.1;
            grid.insert(
                id,
                cube(DVec3::splat(f64::from(id)), size),
                false,
                CollisionFilter::ALL,
            );
            assert_eq!(grid.cell_sizes().len(), 0);
            assert_eq!(grid.level(id), Some(None));
        }
        grid.validate().unwrap();
        grid.insert(63, cube(DVec3::ZERO, 10.0), false, CollisionFilter::ALL);
        // 63 positive extents 0.1 ..= 6.3 and 10: the 10th percentile is extents[6] = 0.7 m,
        // twice that is 1.4 m; cells 1.4 · 2ᵏ up to at least 40 m: 1.4 · 2⁵ = 44.8 m, 6 levels.
        let sizes: Vec<f64> = grid.cell_sizes().collect();
        assert_eq!(sizes.len(), 6);
        assert!((sizes[0] - 1.4).abs() < 1e-12, "{sizes:?}");
        assert_eq!(grid.level(0), Some(Some(0))); // the point
        assert_eq!(grid.level(63), Some(Some(3))); // 10 m in 11.2 m cells
        assert!(grid.oversized.is_empty());
        grid.validate().unwrap();
        // A later body beyond the coarsest cell is oversized; the levels stay.
        grid.insert(64, cube(DVec3::ZERO, 50.0), false, CollisionFilter::ALL);
        assert_eq!(grid.level(64), Some(None));
        assert_eq!(grid.cell_sizes().len(), 6);
        assert_eq!(pairs_of(&mut grid).len(), grid.pairs.len());
    }

    /// Bodies a trillion metres out (where one ulp is about a millimetre, the level-0 cell)
    /// and at ±1e300 m (cell indices saturate at the ends of `i64`) still pair exactly.
    #[test]
    fn far_from_the_origin_boxes_span_few_cells_and_pair_exactly() {
        let mut grid = HashGrid::with_levels(1e-3, 2.0, 8);
        let mut rng = rng(1_010);
        let base = DVec3::new(1e12, -1e12, 3e11);
        let ulp = 1e12f64.to_bits();
        let far_box = |rng: &mut TestRng| {
            let lo = DVec3::new(
                f64::from_bits(ulp + rng.random_range(0..40)),
                -f64::from_bits(ulp + rng.random_range(0..40)),
                base.z + f64::from(rng.random_range(0..40)) * 2f64.powi(-14),
            );
            let ulps = f64::from(rng.random_range(0..6)) * 2f64.powi(-13);
            Aabb::new(lo, lo + DVec3::splat(ulps))
        };
        for id in 0..60u32 {
            grid.insert(id, far_box(&mut rng), false, CollisionFilter::ALL);
        }
        let edge = Aabb::new(DVec3::splat(1e300), DVec3::splat(1e300));
        grid.insert(60, edge, false, CollisionFilter::ALL);
        grid.insert(61, edge, false, CollisionFilter::ALL);
        grid.insert(
            62,
            Aabb::new(DVec3::splat(-1e300), DVec3::splat(-1e300)),
            false,
            CollisionFilter::ALL,
        );
        let mut pairs = 0;
        for op in 0..1_000 {
            let id = rng.random_range(0..60u32);
            grid.update(id, far_box(&mut rng));
            grid.validate().unwrap_or_else(|e| panic!("op {op}: {e}"));
            pairs += grid.pairs.len();
        }
        // Cells of one ulp (level 0) to four: `coordinate / edge` near 2⁵³, boxes of 0 to 4
        // ulps; the registration check (at most 3 cells per axis) holds throughout.
        let ulp = 2f64.powi(-13);
        let mut tiny = HashGrid::with_levels(ulp, 2.0, 3);
        for op in 0..2_000u32 {
            let lo = DVec3::new(
                f64::from_bits(1e12f64.to_bits() + rng.random_range(0..16)),
                -f64::from_bits(1e12f64.to_bits() + rng.random_range(0..16)),
                f64::from_bits(2f64.powi(40).to_bits() - rng.random_range(0..16)),
            );
            let size = ulp * f64::from(rng.random_range(0..5));
            tiny.insert(
                op % 40,
                Aabb::new(lo, lo + DVec3::splat(size)),
                false,
                CollisionFilter::ALL,
            );
            tiny.validate()
                .unwrap_or_else(|e| panic!("tiny op {op}: {e}"));
        }
        assert!(grid.pairs.contains(&CandidatePair::of(60, 61)));
        assert!(!grid.pairs.contains(&CandidatePair::of(60, 62)));
        assert!(pairs > 5_000, "{pairs}");
    }

    #[test]
    #[should_panic(expected = "ratio must be ≥ 2")]
    fn a_level_ratio_below_two_is_refused() {
        let _ = HashGrid::with_levels(1.0, 1.5, 3);
    }

    #[test]
    fn a_body_moving_within_its_cells_changes_no_cell_list_and_idle_bodies_keep_their_pairs() {
        let mut grid = HashGrid::with_levels(1.0, 2.0, 3);
        grid.insert(0, cube(DVec3::splat(0.1), 0.5), false, CollisionFilter::ALL);
        grid.insert(1, cube(DVec3::splat(0.4), 0.5), false, CollisionFilter::ALL);
        grid.insert(2, cube(DVec3::splat(0.2), 3.0), false, CollisionFilter::ALL);
        let before = grid.levels[0].cells.clone();
        assert_eq!(pairs_of(&mut grid), [(0, 1), (0, 2), (1, 2)]);
        // Within cell (0, 0, 0), apart from 1 and back.
        grid.update(0, cube(DVec3::splat(0.0), 0.3));
        assert_eq!(grid.levels[0].cells, before);
        assert_eq!(pairs_of(&mut grid), [(0, 2), (1, 2)]);
        grid.update(0, cube(DVec3::splat(0.1), 0.5));
        assert_eq!(grid.levels[0].cells, before);
        // Across a boundary: the lists change.
        grid.update(0, cube(DVec3::splat(0.6), 0.5));
        assert_ne!(grid.levels[0].cells, before);
        assert_eq!(pairs_of(&mut grid), [(0, 1), (0, 2), (1, 2)]);
    }

    #[test]
    fn the_fast_floor_equals_the_library_floor_everywhere_including_huge_and_signed_zero() {
        let mut rng = rng(0xf1);
        let specials = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            1.0 - f64::EPSILON,
            -1.0 + f64::EPSILON,
            2f64.powi(52) + 0.5,
            -(2f64.powi(52)) - 1.0,
            2f64.powi(62),
            -(2f64.powi(63)),
            2f64.powi(63),
            -(2f64.powi(64)),
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        let randoms = (0..100_000).map(|_| {
            let x: f64 = rng.random_range(-1.0..1.0);
            x * 10f64.powi(rng.random_range(-5..25))
        });
        for x in specials.into_iter().chain(randoms) {
            assert_eq!(floor_to_i64(x), x.floor() as i64, "{x:e}");
        }
    }

    #[test]
    fn cell_hashes_spread_neighbouring_cells_over_low_and_high_bits() {
        let build = BuildCellHasher { seed: 3 };
        let (mut low, mut high) = (BTreeSet::new(), BTreeSet::new());
        for x in -8..8 {
            for y in -8..8 {
                for z in -8..8 {
                    let h = build.hash_one(Cell([x, y, z]));
                    low.insert(h & 0xFFF);
                    high.insert(h >> 52);
                }
            }
        }
        // 4,096 cells into 4,096 buckets: a random function fills about 63 %.
        assert!(
            low.len() > 2_400 && high.len() > 2_400,
            "{} {}",
            low.len(),
            high.len()
        );
        let other_level = BuildCellHasher { seed: 4 };
        assert_ne!(
            build.hash_one(Cell([0; 3])),
            other_level.hash_one(Cell([0; 3]))
        );
    }

    /// Random boxes on an exact grid of 1/4 m (many equal coordinates, ends on cell
    /// boundaries), moved, teleported, removed and inserted one at a time, through the
    /// automatic level choice; the invariants hold after every operation.
    #[test]
    fn validate_holds_after_every_single_operation_on_a_tie_heavy_grid() {
        let mut rng = rng(707);
        let mut grid = HashGrid::new();
        let grid_box = |rng: &mut TestRng| {
            let lo = DVec3::new(
                f64::from(rng.random_range(-8..8)),
                f64::from(rng.random_range(-8..8)),
                f64::from(rng.random_range(-8..8)),
            ) * 0.25;
            let size = if rng.random_range(0..50) == 0 {
                DVec3::splat(40.0)
            } else {
                DVec3::new(
                    f64::from(rng.random_range(0..5)),
                    f64::from(rng.random_range(0..5)),
                    f64::from(rng.random_range(0..5)),
                ) * 0.25
            };
            Aabb::new(lo, lo + size)
        };
        let mut present: Vec<u32> = Vec::new();
        let mut total_pairs = 0;
        for op in 0..4_000 {
            let filter = CollisionFilter {
                group: 1 << rng.random_range(0..2),
                mask: rng.random_range(1..4),
            };
            match rng.random_range(0..10) {
                0..=2 if present.len() < 90 => {
                    let id = rng.random_range(0..120);
                    let is_static = rng.random_range(0..3) == 0;
                    grid.insert(id, grid_box(&mut rng), is_static, filter);
                    if !present.contains(&id) {
                        present.push(id);
                    }
                }
                3 if !present.is_empty() && grid.cell_sizes().len() > 0 => {
                    let i = rng.random_range(0..present.len());
                    assert!(grid.remove(present.swap_remove(i)));
                }
                _ if !present.is_empty() => {
                    let id = present[rng.random_range(0..present.len())];
                    grid.update(id, grid_box(&mut rng));
                }
                _ => {}
            }
            grid.validate().unwrap_or_else(|e| panic!("op {op}: {e}"));
            total_pairs += grid.pairs.len();
        }
        assert!(grid.cell_sizes().len() > 1);
        assert!(!grid.oversized.is_empty());
        assert!(total_pairs > 20_000, "{total_pairs}");
    }
}
