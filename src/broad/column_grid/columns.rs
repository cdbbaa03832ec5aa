//! The column grid's storage: each level's table of columns, each column's bodies sorted
//! along the sweep axis with its search index, and where a body is listed.

use super::{WIDTH_PER_REACH, floor_to_i64, low_end, prefetch};
use crate::bounding::Aabb;
use crate::math::DVec3;

/// A body as its column stores it: its box and slot.
#[derive(Debug, Clone, Copy)]
pub(super) struct Entry {
    pub(super) bounds: Aabb,
    pub(super) slot: u32,
}

/// Entries per block of a column's search index.
pub(super) const BLOCK: usize = 16;

/// One bucket of a level's table: its bodies sorted by the low end of their boxes on the
/// sweep axis (`low[i]` is `entries[i].bounds.min[sweep]`, kept apart for the search), and
/// the search index `starts[k] = low[BLOCK · k]`.
#[derive(Debug, Clone, Default)]
pub(super) struct Column {
    pub(super) low: Vec<f64>,
    pub(super) entries: Vec<Entry>,
    pub(super) starts: Vec<f64>,
}

impl Column {
    /// Number of entries whose low end is below `x` (`low.partition_point(|v| v < x)`):
    /// the blocks starting below `x`, counted, then the entries below `x` in the last of
    /// them. Each count is a sum of independent compares where a binary search makes one
    /// dependent probe per halving.
    #[inline]
    pub(super) fn count_below(&self, x: f64) -> usize {
        let blocks = if self.starts.len() <= 4 * BLOCK {
            self.starts.iter().map(|&v| usize::from(v < x)).sum()
        } else {
            self.starts.partition_point(|&v| v < x)
        };
        let Some(block) = blocks.checked_sub(1) else {
            return 0;
        };
        // low[first] < x, and low[first + BLOCK] >= x when it exists.
        let first = block * BLOCK;
        let last = (first + BLOCK).min(self.low.len());
        first
            + self.low[first..last]
                .iter()
                .map(|&v| usize::from(v < x))
                .sum::<usize>()
    }

    /// Recomputes the search index from entry `from` on.
    pub(super) fn index_from(&mut self, from: usize) {
        let blocks = self.low.len().div_ceil(BLOCK);
        self.starts.truncate(blocks);
        for k in from / BLOCK..blocks {
            let v = self.low[k * BLOCK];
            match self.starts.get_mut(k) {
                Some(start) => *start = v,
                None => self.starts.push(v),
            }
        }
    }

    /// Index of `slot`'s entry, whose low end on the sweep axis is `low`.
    pub(super) fn find(&self, low: f64, slot: u32) -> usize {
        let start = self.count_below(low);
        let found = self.entries[start..]
            .iter()
            .position(|e| e.slot == slot)
            .map(|i| start + i);
        debug_assert!(found.is_some(), "slot {slot} not in its column");
        found.unwrap_or(0)
    }

    /// Inserts `entry` in order.
    pub(super) fn insert(&mut self, low: f64, entry: Entry) {
        let at = self.low.partition_point(|&x| x <= low);
        self.low.insert(at, low);
        self.entries.insert(at, entry);
        self.index_from(at);
    }

    pub(super) fn remove(&mut self, at: usize) {
        self.low.remove(at);
        self.entries.remove(at);
        self.index_from(at);
    }

    /// Sets entry `at` to `entry` (low end `low`) and swaps it into order.
    pub(super) fn replace(&mut self, mut at: usize, low: f64, entry: Entry) {
        self.low[at] = low;
        self.entries[at] = entry;
        let (mut first, mut last) = (at, at);
        while at > 0 && self.low[at - 1] > low {
            self.low.swap(at - 1, at);
            self.entries.swap(at - 1, at);
            at -= 1;
        }
        first = first.min(at);
        while at + 1 < self.low.len() && self.low[at + 1] < low {
            self.low.swap(at, at + 1);
            self.entries.swap(at, at + 1);
            at += 1;
        }
        last = last.max(at);
        // The index entries of the blocks whose first entry changed.
        for k in first.div_ceil(BLOCK)..=last / BLOCK {
            self.starts[k] = self.low[k * BLOCK];
        }
    }
}

/// The three axes: the columns split `u` and `v`, each column is sorted along `sweep`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Axes {
    pub(super) sweep: usize,
    pub(super) u: usize,
    pub(super) v: usize,
}

impl Axes {
    pub(super) fn with_sweep(sweep: usize) -> Self {
        Self {
            sweep,
            u: (sweep + 1) % 3,
            v: (sweep + 2) % 3,
        }
    }
}

/// Columns of one size.
#[derive(Debug, Clone)]
pub(super) struct Level {
    /// Largest extent, on every axis, of a body of this level, metres.
    pub(super) reach: f64,
    /// `1 / column width`, per metre.
    pub(super) inv_width: f64,
    /// The table is `2^bits_u` buckets along `u` by `mask_v + 1` along `v`.
    pub(super) bits_u: u32,
    pub(super) mask_u: u64,
    pub(super) mask_v: u64,
    pub(super) columns: Vec<Column>,
    /// Bodies at this level.
    pub(super) count: usize,
}

/// Where an entry is: its bucket in its level's table and its index in that column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Place {
    pub(super) bucket: usize,
    pub(super) at: usize,
}

/// Where a body is listed: its index in the oversized list (`None` only if the lists are
/// broken, which `validate` reports), or its level and place.
#[derive(Debug, Clone, Copy)]
pub(super) enum Listing {
    Oversized(Option<usize>),
    Column { level: usize, place: Place },
}

/// Consecutive column indices along one axis, as buckets: `first` and how many (at most
/// the table's size along the axis, so none is visited twice).
#[derive(Debug, Clone, Copy)]
pub(super) struct Run {
    pub(super) first: u64,
    pub(super) len: u64,
}

impl Run {
    pub(super) fn new(low: f64, high: f64, inv_width: f64, mask: u64) -> Self {
        let (a, b) = (
            floor_to_i64(low * inv_width),
            floor_to_i64(high * inv_width),
        );
        let len = (i128::from(b) - i128::from(a) + 1).clamp(0, i128::from(mask) + 1) as u64;
        Self {
            first: a as u64,
            len,
        }
    }

    pub(super) fn bucket(&self, i: u64, mask: u64) -> u64 {
        self.first.wrapping_add(i) & mask
    }
}

impl Level {
    pub(super) fn new(reach: f64) -> Self {
        Self {
            reach,
            inv_width: 1.0 / (WIDTH_PER_REACH * reach),
            bits_u: 0,
            mask_u: 0,
            mask_v: 0,
            columns: vec![Column::default()],
            count: 0,
        }
    }

    /// Sizes the (empty) table for bodies whose low corners span `span_u × span_v` metres.
    ///
    /// The table has `2^a × 2^b` buckets, column `(i, j)` in bucket `(i mod 2^a, j mod
    /// 2^b)`: neighbouring columns are neighbouring buckets, and the table never needs
    /// growing, as columns farther apart than its size share a bucket (their bodies are told
    /// apart by the box test, at some cost in candidates). It covers the level's bodies'
    /// spread without aliasing, at most about two buckets per body.
    pub(super) fn size_table(&mut self, span_u: f64, span_v: f64) {
        let cells = |span: f64| {
            let c = (span * self.inv_width).ceil() + 2.0;
            if c.is_finite() && c < 1e6 {
                (c as u64).next_power_of_two()
            } else {
                1 << 20
            }
        };
        let (mut nu, mut nv) = (cells(span_u), cells(span_v));
        let cap = (2 * self.count as u64).max(16).next_power_of_two();
        while nu * nv > cap {
            if nu >= nv {
                nu /= 2;
            } else {
                nv /= 2;
            }
        }
        self.bits_u = nu.trailing_zeros();
        self.mask_u = nu - 1;
        self.mask_v = nv - 1;
        self.columns = vec![Column::default(); (nu * nv) as usize];
    }

    /// Bucket of the column holding a box whose low corner is `min`.
    pub(super) fn home(&self, min: DVec3, axes: Axes) -> usize {
        let u = floor_to_i64(min[axes.u] * self.inv_width) as u64 & self.mask_u;
        let v = floor_to_i64(min[axes.v] * self.inv_width) as u64 & self.mask_v;
        (u | (v << self.bits_u)) as usize
    }

    /// Calls `f(bucket, column, low, high)` for every column of this level that may hold a
    /// body whose box meets `window`, with the run `[low, high]` of low ends along the sweep
    /// axis such a body's entry has (a superset: [`low_end`] rounds down).
    #[inline]
    pub(super) fn for_each_column(
        &self,
        window: &Aabb,
        axes: Axes,
        mut f: impl FnMut(usize, &Column, f64, f64),
    ) {
        let low = |axis: usize| low_end(window.min[axis], self.reach);
        let runs = [axes.u, axes.v].map(|axis| (low(axis), window.max[axis]));
        let ru = Run::new(runs[0].0, runs[0].1, self.inv_width, self.mask_u);
        let rv = Run::new(runs[1].0, runs[1].1, self.inv_width, self.mask_v);
        let (low_sweep, high_sweep) = (low(axes.sweep), window.max[axes.sweep]);
        for j in 0..rv.len {
            let row = rv.bucket(j, self.mask_v) << self.bits_u;
            for i in 0..ru.len {
                let bucket = (row | ru.bucket(i, self.mask_u)) as usize;
                f(bucket, &self.columns[bucket], low_sweep, high_sweep);
            }
        }
    }

    /// Calls `f` with every entry of this level whose box may meet `window`: whose low corner
    /// is within [`low_end`] of `window` on every axis. Entries outside `window` may be
    /// passed too.
    #[inline]
    pub(super) fn for_each_near(
        &self,
        window: &Aabb,
        axes: Axes,
        mut f: impl FnMut(&Entry, Place),
    ) {
        self.for_each_column(window, axes, |bucket, column, low_sweep, high_sweep| {
            let start = column.count_below(low_sweep);
            for (at, (x, entry)) in column.low[start..]
                .iter()
                .zip(&column.entries[start..])
                .enumerate()
            {
                if *x > high_sweep {
                    break;
                }
                f(
                    entry,
                    Place {
                        bucket,
                        at: start + at,
                    },
                );
            }
        });
    }

    /// Starts fetching the first entries a [`for_each_near`](Self::for_each_near) over
    /// `window` will read, so that a query issued a few moves later finds them in cache. A
    /// hint only: reads the columns' search index, changes nothing.
    #[inline]
    pub(super) fn prefetch_near(&self, window: &Aabb, axes: Axes) {
        self.for_each_column(window, axes, |_, column, low_sweep, _| {
            let first = column
                .entries
                .as_ptr()
                .wrapping_add(column.count_below(low_sweep));
            for line in 0..PREFETCH_LINES {
                prefetch(first.cast::<u8>().wrapping_add(64 * line));
            }
        });
    }
}

/// Cache lines of a column's entries [`Level::prefetch_near`] fetches from the first a query
/// reads: about the three or four entries a query of a body of the level's own size scans.
pub(super) const PREFETCH_LINES: usize = 3;
