//! The choice of which broad phase a scene runs.
//!
//! [`BroadPhaseStats::measure`] summarises a scene's proxies (body count, fraction moving,
//! spread of sizes, clustering along the sweep axis) and [`choose`] maps the summary to a
//! kind: what a scene with [`BroadPhaseChoice::Auto`] runs.

use super::sort_sweep::widest_spread_axis;
#[cfg(doc)]
use super::{
    BroadPhase, BroadPhaseChoice, ColumnGrid, HashGrid, IncrementalSap, SkinGrid, SortAndSweep,
};
use super::{BroadPhaseKind, Proxy};
use crate::bounding::Aabb;

/// What the automatic choice looks at, measured on a scene's proxies
/// ([`BroadPhaseStats::measure`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BroadPhaseStats {
    /// Number of bodies.
    pub bodies: usize,
    /// Fraction of the bodies that changed (moved, added, re-filtered) in the measured
    /// frame, in `[0, 1]`; 0 with no bodies.
    pub moving_fraction: f64,
    /// `p90 / p10` of the boxes' largest edge lengths: 1 when all are alike; infinite when
    /// at least 10 % of the boxes are points and some are not; 1 with no bodies or when
    /// both percentiles are 0.
    pub size_spread: f64,
    /// Pairs of boxes whose intervals overlap (touching counts) on the axis where the box
    /// centres spread most, divided by the number of bodies: about the mean number of
    /// neighbours a body's interval meets there, a clustering measure (0 with no bodies).
    pub sweep_overlap_ratio: f64,
    /// Fraction of the recent updates that were far moves ([`MoveCounts`]);
    /// [`measure`](Self::measure) sets 0 (it sees one frame's boxes, not their motion) and
    /// [`with_moves`](Self::with_moves) fills it in from the kept broad phase.
    pub far_move_fraction: f64,
    /// Mean relative shift of the recent updates ([`MoveCounts::mean_shift`]); as
    /// [`far_move_fraction`](Self::far_move_fraction), 0 until
    /// [`with_moves`](Self::with_moves).
    pub mean_shift: f64,
    /// The 75th percentile of the boxes' largest edge lengths, metres: the typical box.
    pub typical_edge: f64,
    /// Mean shift of the recent updates in metres ([`MoveCounts::mean_distance`]) over
    /// [`typical_edge`](Self::typical_edge): how far the bodies move for the typical box
    /// (1 when that box is a point and they move, 0 when they do not). What the rule reads
    /// ([`choose`]); 0 until [`with_moves`](Self::with_moves).
    pub typical_shift: f64,
}

/// What a broad phase's updates were like ([`BroadPhase::take_move_counts`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MoveCounts {
    /// Updates counted.
    pub moves: u64,
    /// How many of them were *far moves*: the box's centre moved farther, on some axis,
    /// than the box's largest edge (a jump across its own size, which a sweep and prune
    /// pays for in endpoint swaps with every body passed).
    pub far_moves: u64,
    /// Sum over the updates of the *relative shift*: the farthest the centre moved on one
    /// axis over the box's largest edge, at most 1 (a far move counts 1; so does any move
    /// of a zero-size box).
    pub shift_sum: f64,
    /// Sum over the updates of the farthest the centre moved on one axis, metres.
    pub distance_sum: f64,
}

impl MoveCounts {
    /// Counts the move of a box from `old` to `new`.
    pub fn add(&mut self, old: &Aabb, new: &Aabb) {
        let shift = (((new.min + new.max) - (old.min + old.max)).abs() * 0.5).max_element();
        let edge = (old.max - old.min).max_element();
        self.moves += 1;
        self.far_moves += u64::from(shift > edge);
        self.distance_sum += shift;
        // A far move (a zero-size box's too: `shift / 0` is infinite) counts 1.
        if shift > 0.0 {
            self.shift_sum += (shift / edge).min(1.0);
        }
    }

    /// Fraction of the updates that were far moves; 0 with none.
    #[must_use]
    pub fn far_fraction(&self) -> f64 {
        self.per_move(self.far_moves as f64)
    }

    /// Mean of the farthest the centre moved on one axis per update, metres; 0 with none.
    #[must_use]
    pub fn mean_distance(&self) -> f64 {
        self.per_move(self.distance_sum)
    }

    /// Mean relative shift per update, in `[0, 1]`; 0 with none.
    #[must_use]
    pub fn mean_shift(&self) -> f64 {
        self.per_move(self.shift_sum)
    }

    /// `sum` over the updates counted; 0 with none.
    fn per_move(&self, sum: f64) -> f64 {
        if self.moves == 0 {
            0.0
        } else {
            sum / self.moves as f64
        }
    }
}

impl BroadPhaseStats {
    /// Measures `proxies`, of which `moved` changed this frame (clamped to the count).
    /// `O(n log n)`; allocates two scratch lists.
    ///
    /// Percentiles are nearest-rank on the sorted values: `p_q = v[round(q · (n − 1))]`.
    #[must_use]
    pub fn measure(proxies: &[Proxy], moved: usize) -> Self {
        let n = proxies.len();
        if n == 0 {
            return Self {
                bodies: 0,
                moving_fraction: 0.0,
                size_spread: 1.0,
                sweep_overlap_ratio: 0.0,
                far_move_fraction: 0.0,
                mean_shift: 0.0,
                typical_edge: 0.0,
                typical_shift: 0.0,
            };
        }
        let mut sizes: Vec<f64> = proxies
            .iter()
            .map(|p| (p.bounds.max - p.bounds.min).max_element())
            .collect();
        sizes.sort_unstable_by(f64::total_cmp);
        let percentile = |q: f64| sizes[(q * (n - 1) as f64).round() as usize];
        let (p10, p75, p90) = (percentile(0.1), percentile(0.75), percentile(0.9));
        let size_spread = if p90 == 0.0 { 1.0 } else { p90 / p10 };
        Self {
            bodies: n,
            moving_fraction: moved.min(n) as f64 / n as f64,
            size_spread,
            sweep_overlap_ratio: interval_overlaps(proxies, widest_spread_axis(proxies)) as f64
                / n as f64,
            far_move_fraction: 0.0,
            mean_shift: 0.0,
            typical_edge: p75,
            typical_shift: 0.0,
        }
    }

    /// These statistics with the motion measures taken from a broad phase's `counts`.
    #[must_use]
    pub fn with_moves(self, counts: &MoveCounts) -> Self {
        Self {
            far_move_fraction: counts.far_fraction(),
            mean_shift: counts.mean_shift(),
            typical_shift: {
                let distance = counts.mean_distance();
                if distance == 0.0 {
                    0.0
                } else if self.typical_edge == 0.0 {
                    1.0
                } else {
                    distance / self.typical_edge
                }
            },
            ..self
        }
    }
}

/// Above this fraction of bodies changing per frame, moving faster than [`CREEPING`], the
/// stateless sort and sweep (which costs the same whatever moved) is chosen.
pub const MOSTLY_MOVING: f64 = 0.5;
/// Shift per update for the typical box ([`BroadPhaseStats::typical_shift`]) up to which
/// bodies count as creeping and the skin grid keeps them even when most move: where the
/// skin grid and the sort and sweep cross, on the uniform and the clustered layouts alike.
pub const CREEPING: f64 = 0.011;
/// Above this fraction of far moves among the updates, a scene counts as teleporting: every
/// jump leaves its skin, which costs the skin grid a refiling.
pub const TELEPORTING: f64 = 0.01;
/// Size spread ([`BroadPhaseStats::size_spread`]) above which a scene of fewer than
/// [`FEW_BODIES`] keeps the skin grid even when most of its bodies move fast: fitted to the
/// bench's clustered layout (spread 5.9) against its uniform one (1.5) and its dice (1.0).
pub const WIDE_SIZE_SPREAD: f64 = 4.0;
/// See [`WIDE_SIZE_SPREAD`]: where the two kinds cross on the clustered layout with all
/// bodies moving at full speed.
pub const FEW_BODIES: usize = 6_000;

/// The broad phase a scene with [`BroadPhaseChoice::Auto`] runs, given its statistics:
///
/// 1. more than [`MOSTLY_MOVING`] of the bodies changing per frame, and moving more than
///    [`CREEPING`] for the typical box ([`BroadPhaseStats::typical_shift`]): [`SortAndSweep`],
///    unless the scene has fewer than [`FEW_BODIES`] bodies of sizes spread wider than
///    [`WIDE_SIZE_SPREAD`] and is not teleporting (line 2): then the skin grid;
/// 2. more than [`TELEPORTING`] of the updates far moves: [`ColumnGrid`] (a jump costs it
///    two queries, and always leaves a skin);
/// 3. else [`SkinGrid`].
///
/// The skin grid re-tests a moved body against its few listed neighbours and refiles it only
/// when it leaves its skin: the fastest while few bodies move or they creep. Sort and sweep
/// costs the same whatever moved and wins once most bodies move fast for their size. A
/// teleporting scene has a shift for the typical box far over [`CREEPING`], so when most of
/// its bodies move the first line takes it.
///
/// The [`IncrementalSap`] and the [`HashGrid`] are never chosen: on every measured class one
/// of the three above is faster; they stay available as fixed choices.
/// [`BroadPhaseStats::sweep_overlap_ratio`] is measured and reported
/// ([`StepReport::broad_stats`](crate::pipeline::StepReport)) but not read: no threshold on
/// it picks a faster kind.
///
/// `examples/broad_bench` measures the thresholds: every kind on the same frames of the
/// uniform, clustered and stacked layouts (`--speed-scale` for slower bodies,
/// `--one-at-a-time` for each kind alone on the core).
pub fn choose(stats: &BroadPhaseStats) -> BroadPhaseKind {
    let fast = stats.moving_fraction > MOSTLY_MOVING && stats.typical_shift > CREEPING;
    let teleporting = stats.far_move_fraction > TELEPORTING;
    // Few bodies of widely spread sizes stay in the skin grid, unless teleporting.
    let skin_keeps =
        stats.bodies < FEW_BODIES && stats.size_spread > WIDE_SIZE_SPREAD && !teleporting;
    if fast && !skin_keeps {
        BroadPhaseKind::SortAndSweep
    } else if teleporting {
        BroadPhaseKind::ColumnGrid
    } else {
        BroadPhaseKind::SkinGrid
    }
}

/// Pairs `i < j` whose closed intervals on `axis` overlap, counted without enumerating
/// them: interval `i` meets every `j` whose min is `≤ max_i`, except those whose max is
/// `< min_i` (which also have their min `≤ max_i`).
fn interval_overlaps(proxies: &[Proxy], axis: usize) -> u64 {
    let mut mins: Vec<f64> = proxies.iter().map(|p| p.bounds.min[axis]).collect();
    let mut maxs: Vec<f64> = proxies.iter().map(|p| p.bounds.max[axis]).collect();
    mins.sort_unstable_by(f64::total_cmp);
    maxs.sort_unstable_by(f64::total_cmp);
    let twice: u64 = proxies
        .iter()
        .map(|p| {
            let (lo, hi) = (p.bounds.min[axis], p.bounds.max[axis]);
            let starts_before_end = mins.partition_point(|&m| m <= hi);
            let ends_before_start = maxs.partition_point(|&m| m < lo);
            // Minus itself.
            (starts_before_end - ends_before_start - 1) as u64
        })
        .sum();
    twice / 2
}

#[cfg(test)]
#[path = "select_tests.rs"]
mod tests;
