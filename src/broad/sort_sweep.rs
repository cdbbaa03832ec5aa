//! Sort and sweep in grid columns: the sweep runs along the axis where the box centres
//! spread most, but separately within each *column* of a square grid laid over the other
//! two axes, so a proxy meets only the proxies near it on all three axes. A stateless broad
//! phase: it takes the whole proxy list every frame and keeps only scratch space, its
//! order of the proxies on the sweep axis and its measure of their spread and size, so it
//! costs about the same whatever moved. The automatic choice ([`choose`](super::choose))
//! takes it when most bodies move fast for their size.
//!
//! A plain one-axis sweep meets about `n^(2/3)` boxes per box for `n` spread through a
//! cube; a column a few typical boxes wide holds only a few that overlap a box's interval.
//! Boxes sharing one range on an axis ("dice on a table") cost no more: that axis is never
//! the widest-spread one, and the shared range does not matter to the columns.
//!
//! # One frame
//! 1. The sweep axis `s` (largest variance of the centres) and the column axes `u`, `v`.
//! 2. The column grid (`lay_grid`), kept while its shape (axis and column edge) is and the
//!    boxes stay within a column of it; the shape is measured again after
//!    [`RESHAPE_FRAMES`] frames or when the proxy count changes: a stale one only costs
//!    time, as any grid lists every box in every column it meets. A box beyond the grid is
//!    listed in its edge columns, which is exact; one wider than [`BIG_COLUMNS`] columns on
//!    `u` or `v` is *big*: tested against every proxy instead.
//! 3. The columns, each ascending by low end on `s`: *kept* from the last frame's when at
//!    most one proxy in [`KEPT_MOVES_PER`] changed columns (`relist_kept_columns`), else
//!    *listed* afresh in the kept order of the proxies on `s` (`refresh_order`,
//!    `list_in_columns`).
//! 4. Each column is swept: entry `i` meets the entries after it whose low end is at most
//!    its high end. A pair meeting in several columns is reported from one only: the column
//!    holding the low corner of the two boxes' `u`, `v` overlap. The entries carry each box
//!    rounded outward to `f32` (a rounded gap is an exact one), so the sweep and the `u`,
//!    `v` test read only the column, branch-free over blocks of entries
//!    (`ColumnEntries::candidates`); the proxies are read for the pairs that pass, for the
//!    exact box test and [`Proxy::may_pair`].
//! 5. Big proxies against everything, the pairs sorted (`pair_sort.rs`: a radix sort).
//!
//! Ties: a column index is `⌊(x − origin) / c⌋`, computed by a map monotone in `x`, so boxes
//! touching on a column boundary share a column; the pair rule is
//! [`Aabb::intersects`](crate::bounding::Aabb::intersects) (closed boxes), as in every
//! broad phase. Costs: `O(n + s + columns + e + t + k)` for `s` insertion-sort shifts (the
//! order's `O(n)`: past a cap the radix sort takes over), `e` column entries, `t` interval
//! tests in the columns and `k` pairs; no allocation once the scratch has grown.

use super::key_sort::KeySort;
use super::pair_sort::sort_pairs;
use super::radix::RadixScratch;
use super::{CandidatePair, Proxy};
use crate::bounding::{Aabb, BoundingVolume};
use crate::math::{DVec3, f32_round_down, f32_round_up};

/// Column edge over the 75th percentile of the boxes' larger extent on the column axes.
///
/// Wider columns list each box in fewer columns (fewer entries to fill and sweep, fewer
/// pairs met twice) but give each entry more sweep candidates; the sweep's cost is its
/// mispredicted branches more than its candidates (`examples/broad_bench`).
pub const COLUMN_EDGE_PER_BOX: f64 = 4.0;
/// The column grid is at most this many columns per proxy: the column edge is raised until
/// it is (`lay_grid`), so tiny far-apart boxes do not make a huge empty grid.
pub const MAX_COLUMNS_PER_PROXY: usize = 4;
/// A box spanning more columns than this on a column axis is tested against every proxy.
pub const BIG_COLUMNS: u64 = 4;
/// Frames the sweep axis and the column edge are kept before they are measured again
/// (sooner when the proxy count changes).
pub const RESHAPE_FRAMES: u32 = 8;
/// The columns are kept from the last frame when at most one proxy in this many is listed
/// in other columns than then (module docs, step 3).
pub const KEPT_MOVES_PER: usize = 32;

/// The column grid of the last frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Grid {
    /// Sweep axis; the column axes are the other two, in increasing order.
    axis: usize,
    /// Column axes.
    u: usize,
    v: usize,
    /// Low corner of the grid on `u`, `v`, metres.
    origin: [f64; 2],
    /// `1 / c`, per metre.
    inv: f64,
    /// Columns along `u` and `v`.
    count: [u64; 2],
}

impl Grid {
    /// The column index along `u` (`k = 0`) or `v` (`k = 1`) of coordinate `x`, clamped to
    /// the grid.
    #[inline]
    fn cell(&self, k: usize, x: f64) -> u64 {
        // Non-negative for boxes inside the grid: the truncating conversion is the floor.
        (((x - self.origin[k]) * self.inv).max(0.0) as u64).min(self.count[k] - 1)
    }

    /// First and last column of `p` on each column axis.
    #[inline]
    fn range(&self, p: &Proxy) -> [[u64; 2]; 2] {
        self.range_of(&self.ends(&p.bounds))
    }

    /// First and last column on each column axis of a box given by [`Self::ends`].
    #[inline]
    fn range_of(&self, ends: &[f64; 6]) -> [[u64; 2]; 2] {
        [
            [self.cell(0, ends[2]), self.cell(0, ends[3])],
            [self.cell(1, ends[4]), self.cell(1, ends[5])],
        ]
    }

    /// `b`'s low and high ends on the sweep axis, then on `u`, then on `v`, metres. (Read
    /// through arrays: a `DVec3` indexed by a run-time axis is a chain of branches.)
    #[inline(always)]
    fn ends(&self, b: &Aabb) -> [f64; 6] {
        let (min, max) = (b.min.to_array(), b.max.to_array());
        [
            min[self.axis],
            max[self.axis],
            min[self.u],
            max[self.u],
            min[self.v],
            max[self.v],
        ]
    }
}

/// A proxy's box rounded outward to `f32`, metres: `[low, high]` on the sweep axis, then on
/// `u`, then on `v`. Two boxes whose rounded forms are apart on an axis are apart there
/// exactly, so the sweep rejects on these and reads the exact boxes (the proxies, at
/// random) only for the pairs that pass.
type RoundedBox = [f32; 6];

/// A box's [`Grid::ends`], rounded outward. Always inlined:
/// called, its result is stored and read back through a stalled store forwarding (module
/// docs, step 4).
#[inline(always)]
fn rounded_box(ends: &[f64; 6]) -> RoundedBox {
    std::array::from_fn(|k| {
        if k % 2 == 0 {
            f32_round_down(ends[k])
        } else {
            f32_round_up(ends[k])
        }
    })
}

/// Lanes of the sweep's blocks: it tests an entry against this many later entries of its
/// column at once, every test of every lane without a branch (the entries are stored one
/// array per field, so the compares vectorise), and branches only on the lanes that pass
/// and on whether the run goes on past the block, which it rarely does
/// (`examples/broad_bench` measures the block width).
const LANES: usize = 16;
// The block's lane mask is a `u32`, and `1 << LANES` must not overflow it.
const _: () = assert!(LANES < u32::BITS as usize);

/// [`ColumnEntries::first`] bit: the entry's column is the proxy's first on `u`.
const FIRST_ON_U: u32 = 1;
/// [`ColumnEntries::first`] bit: the entry's column is the proxy's first on `v`.
const FIRST_ON_V: u32 = 2;

/// The column entries, grouped by column, each column ascending on its low end on the
/// sweep axis; one array per field, so the sweep loads [`LANES`] entries' field at once.
/// Every array holds [`LANES`] padding entries past the last column (never a pair: their
/// low end is `+∞`), so a block starting at any entry stays inside them.
#[derive(Debug, Clone, Default)]
struct ColumnEntries {
    /// The rounded boxes ([`RoundedBox`]), one array per end.
    ends: [Vec<f32>; 6],
    /// [`FIRST_ON_U`] and [`FIRST_ON_V`]: whether the entry's column is the proxy's first
    /// on each column axis (for the one-column-per-pair rule).
    first: Vec<u32>,
    /// Index into the proxies.
    proxy: Vec<u32>,
}

impl ColumnEntries {
    /// Room for `total` entries (their contents left as they are, for the caller to
    /// overwrite), followed by the [`LANES`] padding entries.
    fn resize(&mut self, total: usize) {
        for (k, end) in self.ends.iter_mut().enumerate() {
            // Low ends +∞ and high ends −∞: the padding meets nothing.
            let pad = if k % 2 == 0 {
                f32::INFINITY
            } else {
                f32::NEG_INFINITY
            };
            end.resize(total + LANES, pad);
            end[total..].fill(pad);
        }
        self.first.resize(total + LANES, 0);
        self.first[total..].fill(0);
        self.proxy.resize(total + LANES, u32::MAX);
        self.proxy[total..].fill(u32::MAX);
    }

    fn set(&mut self, at: usize, rounded: &RoundedBox, first: u32, proxy: u32) {
        for (end, &x) in self.ends.iter_mut().zip(rounded) {
            end[at] = x;
        }
        self.first[at] = first;
        self.proxy[at] = proxy;
    }

    /// Sorts entries `start..end` by their low end on the sweep axis, by insertion.
    fn sort_column(&mut self, start: usize, end: usize) {
        for k in start + 1..end {
            let key = self.ends[0][k];
            if self.ends[0][k - 1].total_cmp(&key).is_le() {
                continue;
            }
            let (rounded, first, proxy) = (self.rounded(k), self.first[k], self.proxy[k]);
            let mut m = k;
            while m > start && self.ends[0][m - 1].total_cmp(&key).is_gt() {
                for end in &mut self.ends {
                    end[m] = end[m - 1];
                }
                self.first[m] = self.first[m - 1];
                self.proxy[m] = self.proxy[m - 1];
                m -= 1;
            }
            for (end, &x) in self.ends.iter_mut().zip(&rounded) {
                end[m] = x;
            }
            self.first[m] = first;
            self.proxy[m] = proxy;
        }
    }

    fn rounded(&self, at: usize) -> RoundedBox {
        std::array::from_fn(|k| self.ends[k][at])
    }

    /// Bit `k` set when entry `i` and entry `j + k` may be a pair reported from this
    /// column: the later entry's interval on the sweep axis starts within `i`'s, the
    /// column is the first of both on each column axis for at least one of them (the
    /// column of the overlap's low corner: on each axis the larger of their first columns,
    /// as the floor of a maximum is the maximum of the floors), and their rounded boxes
    /// meet on `u` and `v`. Entries at `end` and past it (another column, or padding) are
    /// masked off. Branch-free: the lanes' compares vectorise.
    #[inline]
    fn candidates(&self, i: usize, j: usize, end: usize) -> u32 {
        let lanes =
            |k: usize| -> &[f32; LANES] { self.ends[k][j..j + LANES].try_into().expect("padded") };
        let (s_lo, u_lo, u_hi, v_lo, v_hi) = (lanes(0), lanes(2), lanes(3), lanes(4), lanes(5));
        let first: &[u32; LANES] = self.first[j..j + LANES].try_into().expect("padded");
        let e = self.rounded(i);
        let e_first = self.first[i];
        let mut mask = 0u32;
        for k in 0..LANES {
            let hit = (s_lo[k] <= e[1])
                & ((e_first | first[k]) == FIRST_ON_U | FIRST_ON_V)
                & (e[2] <= u_hi[k])
                & (u_lo[k] <= e[3])
                & (e[4] <= v_hi[k])
                & (v_lo[k] <= e[5]);
            mask |= u32::from(hit) << k;
        }
        let inside = end.saturating_sub(j).min(LANES);
        mask & ((1u32 << inside) - 1)
    }
}

/// One proxy on the grid, measured in one pass over the proxies so the later passes, which
/// go in sweep order, read this small array instead of the proxies.
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    /// Its rounded box.
    rounded: RoundedBox,
    /// First and last column on `u`, then on `v`; `first[0] == u32::MAX` for a big proxy.
    first: [u32; 2],
    last: [u32; 2],
}

impl Slot {
    /// First and last column on `u`, then on `v`: what a proxy's listing depends on.
    fn columns(&self) -> [u32; 4] {
        [self.first[0], self.last[0], self.first[1], self.last[1]]
    }

    /// [`FIRST_ON_U`] and [`FIRST_ON_V`] of the proxy's entry in column `(cu, cv)`.
    fn first_bits(&self, cu: u32, cv: u32) -> u32 {
        (if cu == self.first[0] { FIRST_ON_U } else { 0 })
            | (if cv == self.first[1] { FIRST_ON_V } else { 0 })
    }
}

/// Scratch of the sweep, and its order of the proxies kept between frames.
#[derive(Debug, Clone, Default)]
pub struct SortAndSweep {
    grid: Grid,
    /// `(slot, proxy index)` of every proxy, ascending by the slot's low end on the sweep
    /// axis: kept between frames and insertion-sorted (linear when bodies move
    /// coherently), so the columns filled in this order come out sorted. The whole slot
    /// rides along, so the filling reads it in order rather than looking it up at random
    /// (a cache miss per proxy in large scenes).
    /// Left as it is in frames whose columns are kept (module docs, step 3).
    order: Vec<(Slot, u32)>,
    /// Start of each column's entries in `entries` (one more than the columns).
    starts: Vec<u32>,
    /// The column entries.
    entries: ColumnEntries,
    /// Each proxy on the grid.
    slots: Vec<Slot>,
    /// Indices of the big proxies.
    big: Vec<u32>,
    /// The grid and proxy count the columns were listed for, if they can be kept.
    listed: Option<(Grid, usize)>,
    /// Each proxy's first and last columns (`u` then `v`) as listed.
    listed_ranges: Vec<[u32; 4]>,
    /// Scratch of [`Self::relist_kept_columns`]: whether each proxy changed columns (a
    /// flag read per entry), the ones that did, the entries they add (column,
    /// proxy, first bits), the new column starts, and the other buffer of the entries.
    changed: Vec<bool>,
    moved: Vec<u32>,
    added: Vec<(u32, u32, u32)>,
    new_starts: Vec<u32>,
    spare: ColumnEntries,
    /// Frames whose columns were kept, and the proxies those moved to other columns.
    kept_frames: usize,
    kept_moves: usize,
    /// The axis `order` is sorted on.
    order_axis: usize,
    /// Extents, for the column size.
    extents: Vec<f64>,
    /// The sweep axis and typical box of the last measurement.
    shape: Option<Shape>,
    /// Scratch of the pairs' radix sort.
    sorted: RadixScratch<CandidatePair>,
    /// Scratch of `order`'s sort.
    order_sort: KeySort<(Slot, u32)>,
    /// The proxies' overall bounds, as the last [`Self::measure_slots`] measured them: when
    /// a kept shape's grid no longer holds the boxes, the new grid is laid on the bounds
    /// that measurement found, sparing a pass over the proxies.
    bounds_seen: Option<(DVec3, DVec3)>,
}

/// What [`SortAndSweep`] measures of the proxies to lay its grid, kept for
/// [`RESHAPE_FRAMES`] frames.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Shape {
    axis: usize,
    /// 75th percentile of the boxes' larger extent on the column axes, metres.
    p75: f64,
    /// Proxies measured (another count measures again).
    proxies: usize,
    /// Frames since measured.
    age: u32,
}

impl SortAndSweep {
    /// An empty sweep.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Every pair of `proxies` whose grown boxes overlap (touching counts) and that may pair,
    /// once each with `a < b`, in increasing `(a, b)` order, written to `out` (cleared
    /// first): exactly the pairs of [`pairs_brute_force`](super::pairs_brute_force).
    ///
    /// # Allocation
    /// None once the scratch and `out` have grown to the proxy and pair counts.
    pub fn pairs(&mut self, proxies: &[Proxy], out: &mut Vec<CandidatePair>) {
        out.clear();
        if proxies.len() < 2 {
            self.grid = Grid::default();
            self.shape = None;
            self.bounds_seen = None;
            self.order.clear();
            self.starts.clear();
            self.entries.resize(0);
            self.slots.clear();
            self.big.clear();
            self.listed = None;
            return;
        }
        let (axis, p75, kept) = self.shape_for(proxies);
        // A kept shape keeps the grid while the boxes stay within a column of it (measured
        // on it first); else it is laid on the bounds that measurement found, or, for a
        // shape measured anew, on this frame's overall bounds.
        let grid_kept = kept && self.listed.is_some() && self.measure_slots(proxies);
        if !grid_kept {
            let (low, high) = match self.bounds_seen.filter(|_| kept) {
                Some(bounds) => bounds,
                None => overall_bounds(proxies),
            };
            self.grid = lay_grid(axis, p75, low, high, proxies.len());
            if !self.measure_slots(proxies) {
                let (low, high) = self.bounds_seen.expect("measured");
                self.grid = lay_grid(axis, p75, low, high, proxies.len());
                self.measure_slots(proxies);
            }
        }
        if !self.relist_kept_columns() {
            self.refresh_order(proxies.len());
            self.list_in_columns();
            self.note_listing();
        }
        let columns = self.starts.len() - 1;
        for column in 0..columns {
            let (start, end) = (
                self.starts[column] as usize,
                self.starts[column + 1] as usize,
            );
            for i in start..end {
                let reach = self.entries.ends[1][i];
                let p = &proxies[self.entries.proxy[i] as usize];
                let mut j = i + 1;
                loop {
                    let mut hits = self.entries.candidates(i, j, end);
                    while hits != 0 {
                        let f = j + hits.trailing_zeros() as usize;
                        hits &= hits - 1;
                        let q = &proxies[self.entries.proxy[f] as usize];
                        if p.may_pair(q) && p.bounds.intersects(&q.bounds) {
                            out.push(CandidatePair::of(p.body, q.body));
                        }
                    }
                    // The column is ascending: the run goes on only if the block's last
                    // entry still starts within `i`'s interval.
                    j += LANES;
                    if j >= end || self.entries.ends[0][j - 1] > reach {
                        break;
                    }
                }
            }
        }
        for &bi in &self.big {
            let b = &proxies[bi as usize];
            for (qi, q) in proxies.iter().enumerate() {
                // Big–big pairs once: from the later big proxy.
                let q_big = self.slots[qi].first[0] == u32::MAX;
                if q_big && qi >= bi as usize {
                    continue;
                }
                if b.may_pair(q) && b.bounds.intersects(&q.bounds) {
                    out.push(CandidatePair::of(b.body, q.body));
                }
            }
        }
        sort_pairs(out, &mut self.sorted);
    }

    /// The sweep axis and the 75th percentile of the boxes' larger extent on the column
    /// axes for `proxies` (at least two), and whether they were kept from an earlier frame.
    fn shape_for(&mut self, proxies: &[Proxy]) -> (usize, f64, bool) {
        match self.shape {
            Some(shape) if shape.proxies == proxies.len() && shape.age < RESHAPE_FRAMES => {
                self.shape = Some(Shape {
                    age: shape.age + 1,
                    ..shape
                });
                (shape.axis, shape.p75, true)
            }
            _ => {
                let axis = widest_spread_axis(proxies);
                let (u, v) = column_axes(axis);
                self.extents.clear();
                self.extents.extend(proxies.iter().map(|p| {
                    let e = p.bounds.extents();
                    e[u].max(e[v])
                }));
                let at = self.extents.len() * 3 / 4;
                let (_, &mut p75, _) = self.extents.select_nth_unstable_by(at, f64::total_cmp);
                self.shape = Some(Shape {
                    axis,
                    p75,
                    proxies: proxies.len(),
                    age: 0,
                });
                (axis, p75, false)
            }
        }
    }

    /// Measures every proxy on `self.grid` into `slots`, lists the big ones and keeps the
    /// proxies' overall bounds in `bounds_seen`; whether the grid covers those bounds to
    /// within a column on each side (boxes beyond it are listed in its edge columns: exact,
    /// but crowded when many are).
    fn measure_slots(&mut self, proxies: &[Proxy]) -> bool {
        let grid = self.grid;
        self.slots.clear();
        self.big.clear();
        let (mut low, mut high) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for (i, p) in proxies.iter().enumerate() {
            low = low.min(p.bounds.min);
            high = high.max(p.bounds.max);
            let ends = grid.ends(&p.bounds);
            let [[u0, u1], [v0, v1]] = grid.range_of(&ends);
            let big = u1 - u0 >= BIG_COLUMNS || v1 - v0 >= BIG_COLUMNS;
            if big {
                self.big.push(i as u32);
            }
            self.slots.push(Slot {
                rounded: rounded_box(&ends),
                first: if big {
                    [u32::MAX; 2]
                } else {
                    [u0 as u32, v0 as u32]
                },
                last: [u1 as u32, v1 as u32],
            });
        }
        self.bounds_seen = Some((low, high));
        let edge = 1.0 / grid.inv;
        [(grid.u, 0), (grid.v, 1)].into_iter().all(|(axis, k)| {
            let end = grid.origin[k] + grid.count[k] as f64 * edge;
            low[axis] >= grid.origin[k] - edge && high[axis] <= end + edge
        })
    }

    /// Fills `starts` and `entries` from `slots`: a counting sort of the column entries
    /// (each box is listed in every column its `u`, `v` extent meets, 1 to 4 mostly),
    /// filled in sweep order so each column comes out ascending with no sort of its own.
    fn list_in_columns(&mut self) {
        let grid = self.grid;
        let columns = (grid.count[0] * grid.count[1]) as usize;
        let width = grid.count[1] as usize;
        self.starts.clear();
        self.starts.resize(columns + 1, 0);
        for slot in self.slots.iter().filter(|s| s.first[0] != u32::MAX) {
            for cu in slot.first[0]..=slot.last[0] {
                let row = cu as usize * width;
                for cv in slot.first[1]..=slot.last[1] {
                    self.starts[row + cv as usize + 1] += 1;
                }
            }
        }
        for k in 1..=columns {
            self.starts[k] += self.starts[k - 1];
        }
        let total = self.starts[columns] as usize;
        self.entries.resize(total);
        // Fill each column from its end backwards, taking the proxies in descending order on
        // the sweep axis: every column comes out ascending, and `starts` ends at the column
        // starts.
        for &(slot, i) in self.order.iter().rev() {
            if slot.first[0] == u32::MAX {
                continue;
            }
            for cu in slot.first[0]..=slot.last[0] {
                let row = cu as usize * width;
                for cv in slot.first[1]..=slot.last[1] {
                    let column = row + cv as usize;
                    self.starts[column + 1] -= 1;
                    let at = self.starts[column + 1] as usize;
                    self.entries
                        .set(at, &slot.rounded, slot.first_bits(cu, cv), i);
                }
            }
        }
        // `starts[k + 1]` now holds column k's start; shift back to one more than columns.
        self.starts.copy_within(1.., 0);
        self.starts[columns] = total as u32;
    }

    /// Notes the columns just listed as keepable: the grid, the count and each proxy's
    /// columns (a big proxy's first column `u32::MAX`: it is in none).
    fn note_listing(&mut self) {
        self.listed = Some((self.grid, self.slots.len()));
        self.listed_ranges.clear();
        self.listed_ranges
            .extend(self.slots.iter().map(Slot::columns));
    }

    /// Lists the columns from last frame's, when the grid and the proxy count are the same
    /// and few proxies changed columns: each entry's box is read again from its slot, the
    /// proxies that changed columns are taken out of their old ones and added to their new
    /// ones, and each column is sorted by insertion (its entries keep close to their last
    /// order). `false`, changing nothing, when it cannot.
    fn relist_kept_columns(&mut self) -> bool {
        let n = self.slots.len();
        if self.listed != Some((self.grid, n)) {
            return false;
        }
        self.moved.clear();
        self.changed.clear();
        self.changed.resize(n, false);
        for (i, (slot, was)) in self.slots.iter().zip(&self.listed_ranges).enumerate() {
            if slot.columns() != *was {
                self.moved.push(i as u32);
                self.changed[i] = true;
            }
        }
        if self.moved.len() > n / KEPT_MOVES_PER {
            return false;
        }
        let width = self.grid.count[1] as usize;
        let columns = self.starts.len() - 1;
        // New column sizes: the old, less the moved proxies' old entries, plus their new.
        self.new_starts.clear();
        self.new_starts
            .extend(self.starts.windows(2).map(|w| w[1] - w[0]));
        self.new_starts.push(0);
        self.added.clear();
        for &i in &self.moved {
            let [u0, u1, v0, v1] = self.listed_ranges[i as usize];
            // A big proxy is in no column, before or after.
            let was_listed = u0 != u32::MAX;
            for cu in (u0..=u1).filter(|_| was_listed) {
                for cv in v0..=v1 {
                    self.new_starts[cu as usize * width + cv as usize] -= 1;
                }
            }
            let slot = &self.slots[i as usize];
            let listed = slot.first[0] != u32::MAX;
            for cu in (slot.first[0]..=slot.last[0]).filter(|_| listed) {
                for cv in slot.first[1]..=slot.last[1] {
                    let column = cu as usize * width + cv as usize;
                    self.new_starts[column] += 1;
                    self.added.push((column as u32, i, slot.first_bits(cu, cv)));
                }
            }
        }
        self.added.sort_unstable();
        // Counts to starts, one more than the columns.
        let mut start = 0;
        for count in &mut self.new_starts {
            (start, *count) = (start + *count, start);
        }
        let total = self.new_starts[columns] as usize;
        self.spare.resize(total);
        let mut added = self.added.iter().peekable();
        for column in 0..columns {
            let mut at = self.new_starts[column] as usize;
            for k in self.starts[column] as usize..self.starts[column + 1] as usize {
                let i = self.entries.proxy[k];
                if self.changed[i as usize] {
                    continue;
                }
                let first = self.entries.first[k];
                self.spare
                    .set(at, &self.slots[i as usize].rounded, first, i);
                at += 1;
            }
            while let Some(&&(c, i, first)) = added.peek() {
                if c as usize != column {
                    break;
                }
                self.spare
                    .set(at, &self.slots[i as usize].rounded, first, i);
                at += 1;
                added.next();
            }
            debug_assert_eq!(at, self.new_starts[column + 1] as usize);
            self.spare.sort_column(self.new_starts[column] as usize, at);
        }
        std::mem::swap(&mut self.entries, &mut self.spare);
        std::mem::swap(&mut self.starts, &mut self.new_starts);
        for &i in &self.moved {
            let slot = &self.slots[i as usize];
            self.listed_ranges[i as usize] = slot.columns();
        }
        self.kept_frames += 1;
        self.kept_moves += self.moved.len();
        true
    }

    /// Frames so far whose columns were kept from the last frame's, and the proxies that
    /// moved to other columns in them.
    #[must_use]
    pub fn kept_counts(&self) -> (usize, usize) {
        (self.kept_frames, self.kept_moves)
    }

    /// Brings `order` up to date with `proxies` on the sweep axis: rebuilt when the axis
    /// changed; otherwise entries past the new proxy count are dropped, every entry's slot
    /// read again (entries are indices, so a proxy that changed place, e.g. by a caller's
    /// `swap_remove`, is simply re-read) and new indices appended. Then sorted by
    /// [`KeySort`]: by insertion while the proxies keep close to their last order, by a
    /// radix sort when they do not (`key_sort.rs` gives the rule).
    fn refresh_order(&mut self, n: usize) {
        let slots = &self.slots;
        let rebuild = self.grid.axis != self.order_axis || self.order.is_empty();
        if rebuild {
            self.order.clear();
            self.order_axis = self.grid.axis;
        } else {
            // The order holds the indices below the last count: only fewer proxies
            // leave some out of range.
            if self.order.len() > n {
                self.order.retain(|&(_, i)| (i as usize) < n);
            }
            for entry in &mut self.order {
                entry.0 = slots[entry.1 as usize];
            }
        }
        let kept = self.order.len();
        self.order.extend(
            slots
                .iter()
                .enumerate()
                .skip(kept)
                .map(|(i, &s)| (s, i as u32)),
        );
        self.order_sort
            .sort(&mut self.order, |entry| entry.0.rounded[0]);
    }

    /// Checks the scratch of the last [`Self::pairs`] call against `proxies`, which must be
    /// its slice: every proxy is big (wider than [`BIG_COLUMNS`] columns) or listed exactly
    /// in the columns its box meets, with its low end on the sweep axis; each column is
    /// ascending. The pairs themselves are checked by comparing with
    /// [`pairs_brute_force`](super::pairs_brute_force).
    ///
    /// # Errors
    /// A description of the first violated invariant.
    pub fn validate(&self, proxies: &[Proxy]) -> Result<(), String> {
        if proxies.len() < 2 {
            return Ok(());
        }
        let grid = self.grid;
        let columns = (grid.count[0] * grid.count[1]) as usize;
        if self.starts.len() != columns + 1 || self.slots.len() != proxies.len() {
            return Err(format!(
                "{} column starts for {columns} columns, {} slots for {} proxies",
                self.starts.len(),
                self.slots.len(),
                proxies.len()
            ));
        }
        let mut listed = vec![0usize; proxies.len()];
        for column in 0..columns {
            let (a, b) = (
                self.starts[column] as usize,
                self.starts[column + 1] as usize,
            );
            let (cu, cv) = (column as u64 / grid.count[1], column as u64 % grid.count[1]);
            for at in a..b {
                let (rounded, i) = (self.entries.rounded(at), self.entries.proxy[at]);
                let low = rounded[0];
                let p = proxies
                    .get(i as usize)
                    .ok_or(format!("proxy {i} out of range"))?;
                let [[u0, u1], [v0, v1]] = grid.range(p);
                if !(u0..=u1).contains(&cu) || !(v0..=v1).contains(&cv) {
                    return Err(format!(
                        "proxy {i} listed in column ({cu}, {cv}) it does not meet"
                    ));
                }
                if rounded != rounded_box(&grid.ends(&p.bounds)) {
                    return Err(format!(
                        "proxy {i}: stale box (low end {low}) in column ({cu}, {cv})"
                    ));
                }
                let first =
                    if cu == u0 { FIRST_ON_U } else { 0 } | if cv == v0 { FIRST_ON_V } else { 0 };
                if self.entries.first[at] != first {
                    return Err(format!(
                        "proxy {i}: wrong first-column bits in column ({cu}, {cv})"
                    ));
                }
                if at > a && self.entries.ends[0][at - 1].total_cmp(&low).is_gt() {
                    return Err(format!(
                        "column ({cu}, {cv}) out of order at entry {}",
                        at - a
                    ));
                }
                listed[i as usize] += 1;
            }
        }
        for (i, p) in proxies.iter().enumerate() {
            let [[u0, u1], [v0, v1]] = grid.range(p);
            let big = u1 - u0 >= BIG_COLUMNS || v1 - v0 >= BIG_COLUMNS;
            let expected = if big {
                0
            } else {
                ((u1 - u0 + 1) * (v1 - v0 + 1)) as usize
            };
            if listed[i] != expected || big != self.big.contains(&(i as u32)) {
                return Err(format!(
                    "proxy {i} listed {} times, expected {expected}",
                    listed[i]
                ));
            }
        }
        Ok(())
    }
}

/// The column axes of sweep axis `axis`: the other two, in increasing order.
fn column_axes(axis: usize) -> (usize, usize) {
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    (u.min(v), u.max(v))
}

/// The smallest box holding every proxy's box.
fn overall_bounds(proxies: &[Proxy]) -> (DVec3, DVec3) {
    proxies
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(low, high), p| {
            (low.min(p.bounds.min), high.max(p.bounds.max))
        })
}

/// The column grid of `n` proxies (at least two) swept along `axis`, with columns
/// [`COLUMN_EDGE_PER_BOX`] times `p75` wide (or wider: at most [`MAX_COLUMNS_PER_PROXY`]
/// columns a proxy), over the box from `low` to `high`.
fn lay_grid(axis: usize, p75: f64, low: DVec3, high: DVec3, n: usize) -> Grid {
    let (u, v) = column_axes(axis);
    let lo = [low[u], low[v]];
    let span = [high[u] - low[u], high[v] - low[v]];
    // A few typical boxes; never so fine that the grid outgrows the proxies.
    let area_per_column = span[0].max(f64::MIN_POSITIVE) * span[1].max(f64::MIN_POSITIVE)
        / (MAX_COLUMNS_PER_PROXY * n) as f64;
    let mut c = (COLUMN_EDGE_PER_BOX * p75).max(area_per_column.sqrt());
    if !(c.is_finite() && c > 0.0) {
        c = span[0].max(span[1]).max(1.0);
    }
    let cap = (MAX_COLUMNS_PER_PROXY * n) as u64 + 4;
    loop {
        let inv = 1.0 / c;
        // The last column holds the largest coordinate: the same map as `Grid::cell`.
        let count = |k: usize| ((span[k] * inv).max(0.0) as u64).saturating_add(1);
        let grid = Grid {
            axis,
            u,
            v,
            origin: lo,
            inv,
            count: [count(0), count(1)],
        };
        // Rounding can leave the product a little over the cap; widen until it is not.
        if grid.count[0].saturating_mul(grid.count[1]) <= cap {
            return grid;
        }
        c *= 1.5;
    }
}

/// The axis (0, 1, 2) along which the proxies' box centres have the largest variance (the sweep
/// axis; ties go to the lower axis). The automatic choice measures clustering along it too.
pub(crate) fn widest_spread_axis(proxies: &[Proxy]) -> usize {
    if proxies.is_empty() {
        return 0;
    }
    let n = proxies.len() as f64;
    let mean = proxies
        .iter()
        .fold(crate::math::DVec3::ZERO, |s, p| s + p.bounds.center())
        / n;
    let variance = proxies.iter().fold(crate::math::DVec3::ZERO, |s, p| {
        let d = p.bounds.center() - mean;
        s + d * d
    });
    if variance.x >= variance.y && variance.x >= variance.z {
        0
    } else if variance.y >= variance.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::Aabb;
    use crate::broad::{CollisionFilter, pairs_brute_force};
    use crate::math::DVec3;
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    fn random_proxy(rng: &mut crate::test_support::TestRng, body: u32, spread: f64) -> Proxy {
        Proxy {
            body,
            bounds: crate::broad::conformance::random_box(rng, spread, 10),
            is_static: rng.random_range(0..5) == 0,
            filter: CollisionFilter {
                group: 1 << rng.random_range(0..3),
                mask: rng.random_range(1..8),
            },
        }
    }

    /// One frame of `sweep` over `proxies` checked against brute force and `validate()`;
    /// the frame's pair count.
    fn frame_against_brute_force(sweep: &mut SortAndSweep, proxies: &[Proxy], what: &str) -> usize {
        let (mut expected, mut found) = (Vec::new(), Vec::new());
        pairs_brute_force(proxies, &mut expected);
        sweep.pairs(proxies, &mut found);
        assert_eq!(found, expected, "{what}");
        if let Err(e) = sweep.validate(proxies) {
            panic!("{what}: {e}");
        }
        expected.len()
    }

    /// Coherent motion with occasional teleports, insertions and removals: the sweep's pairs
    /// equal brute force's every frame.
    #[test]
    fn sweep_pairs_equal_brute_force_over_coherent_frames() {
        let mut rng = rng(91);
        let mut sweep = SortAndSweep::new();
        let (mut total_pairs, mut empty_frames) = (0usize, 0usize);
        for scene in 0..20 {
            let spread = [2.0, 10.0, 40.0][scene % 3];
            let mut proxies: Vec<Proxy> = (0..rng.random_range(0..150))
                .map(|i| random_proxy(&mut rng, i * 2 + 1, spread))
                .collect();
            let mut next_id = 1000;
            for frame in 0..100 {
                for p in &mut proxies {
                    let step = if rng.random_range(0..50) == 0 {
                        point_in_cube(&mut rng, spread) - p.bounds.center() // teleport
                    } else {
                        point_in_cube(&mut rng, 0.05)
                    };
                    p.bounds = Aabb::new(p.bounds.min + step, p.bounds.max + step);
                }
                if rng.random_range(0..10) == 0 && !proxies.is_empty() {
                    let i = rng.random_range(0..proxies.len());
                    proxies.swap_remove(i);
                }
                if rng.random_range(0..10) == 0 {
                    proxies.push(random_proxy(&mut rng, next_id, spread));
                    next_id += 1;
                }
                let pairs = frame_against_brute_force(
                    &mut sweep,
                    &proxies,
                    &format!("scene {scene} frame {frame}"),
                );
                total_pairs += pairs;
                empty_frames += usize::from(pairs == 0);
            }
        }
        assert!(
            total_pairs > 10_000 && empty_frames > 10,
            "pairs {total_pairs}, empty frames {empty_frames}"
        );
    }

    /// Boxes drifting across column boundaries, with bursts of teleports now and then: the
    /// columns are kept through most frames, with proxies moved between them, and listed
    /// afresh after the bursts; every frame's pairs equal brute force and the listing
    /// validates.
    #[test]
    fn kept_columns_follow_drifting_boxes_exactly() {
        let mut rng = rng(93);
        let mut sweep = SortAndSweep::new();
        let mut proxies: Vec<Proxy> = (0..400).map(|i| random_proxy(&mut rng, i, 8.0)).collect();
        let frames = 600;
        let mut total_pairs = 0;
        for frame in 0..frames {
            let burst = frame % 97 == 50;
            for p in &mut proxies {
                let step = if burst && rng.random_range(0..10) == 0 {
                    point_in_cube(&mut rng, 8.0) - p.bounds.center()
                } else {
                    point_in_cube(&mut rng, 0.1)
                };
                p.bounds = Aabb::new(p.bounds.min + step, p.bounds.max + step);
            }
            total_pairs +=
                frame_against_brute_force(&mut sweep, &proxies, &format!("frame {frame}"));
        }
        let (kept, moves) = sweep.kept_counts();
        assert!(
            kept > frames / 2 && kept < frames - 10 && moves > kept,
            "{kept} of {frames} frames kept their columns, {moves} proxies moved in them"
        );
        assert!(total_pairs > 20_000, "pairs {total_pairs}");
    }

    /// The axis and column edge kept from an earlier frame only cost time: boxes that
    /// shrink, grow a hundredfold, flatten onto another axis or fly off between
    /// measurements still pair exactly as brute force says. (Each step scales or shifts
    /// the whole scene, which keeps its pairs: the grid laid for the old scene is what is
    /// tested.)
    #[test]
    fn a_kept_axis_and_edge_never_change_the_pairs() {
        let mut rng = rng(92);
        let mut sweep = SortAndSweep::new();
        let (mut expected, mut found) = (Vec::new(), Vec::new());
        let (mut total_pairs, mut unpaired, mut kept) = (0usize, 0usize, 0usize);
        for scene in 0..40 {
            let mut proxies: Vec<Proxy> = (0..rng.random_range(40..120))
                .map(|i| random_proxy(&mut rng, i, 5.0))
                .collect();
            for frame in 0..24 {
                let (scale, squash, drift) = match rng.random_range(0..4) {
                    0 => (DVec3::splat(0.01), DVec3::ONE, DVec3::ZERO),
                    1 => (DVec3::splat(100.0), DVec3::ONE, DVec3::ZERO),
                    2 => {
                        let mut squash = DVec3::ONE;
                        squash[rng.random_range(0..3)] = 1e-3;
                        (DVec3::ONE, squash, DVec3::ZERO)
                    }
                    _ => (DVec3::ONE, DVec3::ONE, point_in_cube(&mut rng, 1e4)),
                };
                for p in &mut proxies {
                    let (c, h) = (p.bounds.center(), p.bounds.half_extents());
                    let (c, h) = (c * squash * scale.x + drift, h * scale * squash);
                    p.bounds = Aabb::new(c - h, c + h);
                }
                let before = sweep.shape;
                pairs_brute_force(&proxies, &mut expected);
                sweep.pairs(&proxies, &mut found);
                assert_eq!(found, expected, "scene {scene} frame {frame}");
                kept += usize::from(before.is_some() && sweep.shape.is_some_and(|s| s.age > 0));
                total_pairs += expected.len();
                unpaired += proxies
                    .iter()
                    .filter(|p| !expected.iter().any(|q| q.a == p.body || q.b == p.body))
                    .count();
            }
        }
        assert!(
            total_pairs > 1_000 && unpaired > 1_000 && kept > 500,
            "pairs {total_pairs}, unpaired boxes {unpaired}, frames on a kept shape {kept}"
        );
    }

    #[test]
    fn boxes_touching_at_one_point_or_stacked_on_one_coordinate_pair() {
        let unit = |x: f64, y: f64| Proxy {
            body: 0,
            bounds: Aabb::new(DVec3::new(x, y, 0.0), DVec3::new(x + 1.0, y + 1.0, 1.0)),
            is_static: false,
            filter: CollisionFilter::ALL,
        };
        // Corner to corner, and forty boxes sharing the same low end on every axis (one
        // run of the sweep spanning several blocks of `LANES` entries).
        let mut proxies = vec![unit(0.0, 0.0), unit(1.0, 1.0)];
        proxies.extend((0..40).map(|_| unit(5.0, 5.0)));
        for (i, p) in proxies.iter_mut().enumerate() {
            p.body = i as u32;
        }
        let (mut expected, mut found) = (Vec::new(), Vec::new());
        pairs_brute_force(&proxies, &mut expected);
        SortAndSweep::new().pairs(&proxies, &mut found);
        assert_eq!(found, expected);
        assert_eq!(found.len(), 1 + 40 * 39 / 2);
        const { assert!(40 > 2 * LANES) };
    }
}
