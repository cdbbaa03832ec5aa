//! Broad phase: which pairs of bodies can be close, from their world boxes.
//!
//! Each body enters as a [`Proxy`]: its world-space box already grown by its close-pair
//! margin, whether it is static, and its collision filter. A broad phase reports every pair
//! of proxies whose boxes overlap and that may pair (filters meet, not both static), each
//! once with `a < b`, in increasing `(a, b)` order. Overlap of margin-grown boxes is
//! conservative: two bodies within the sum of their margins always have overlapping grown
//! boxes, so the narrow phase never misses a close pair.
//!
//! [`brute_force`] tests every pair: the reference the faster broad phases are checked
//! against. [`sort_sweep`] sweeps the boxes along one axis within the columns of a grid over
//! the other two, testing only overlapping intervals; it takes the whole proxy list every
//! frame. [`incremental_sap`] is stateful: bodies are
//! inserted, updated and removed one by one, and it keeps sorted endpoint lists on all three
//! axes and the overlapping-pair set between frames, so a body that did not move costs
//! nothing. [`hash_grid`] has the same stateful API: a hierarchy of hashed uniform grids
//! whose cell sizes grow geometrically, each body stored in the few cells of the one level
//! that fits its size (bodies larger than the coarsest cell in an oversized list tested
//! against all), and the overlapping-pair set kept between frames, so a moved body re-tests
//! only the bodies in its cells; it does not degrade when boxes share a coordinate range
//! ("dice on a table"), which costs the three-axis sweep endpoint swaps. [`column_grid`] has
//! the same stateful API over a hierarchy of 2-D grids of columns, each body listed once,
//! in the column of its box's low corner, each column sorted along the third axis: a moved
//! body re-tests the bodies of the 1 to 4 columns around it, each run found by a binary
//! search, none met twice. [`skin_grid`] keeps the column grid over each body's box grown
//! by a skin, and each body's list of skin neighbours: a body that moves within its skin
//! re-tests only its listed neighbours, and the grid hears of it only when it leaves the
//! skin (Verlet lists, fat boxes).
//!
//! [`phase`] puts the five behind one stateful API ([`BroadPhase`]: insert, update, remove,
//! pairs), each over the one body table the stateful kinds share (`stateful.rs`), and
//! [`select`] chooses among them from measured scene statistics ([`BroadPhaseStats`],
//! [`choose`]); the pipeline keeps one per scene in sync with the scene's change log, so a
//! body that did not change is never touched.
//!
//! Every broad phase follows the same tie rule as [`Aabb::intersects`]: closed boxes, so
//! boxes touching at a face, edge or corner pair, and zero-size boxes are points.

mod body_map;
pub(crate) use body_map::PairMap;
pub mod brute_force;
pub mod column_grid;
#[cfg(test)]
mod conformance;
pub mod hash_grid;
pub mod incremental_sap;
mod key_sort;
mod pair_set;
mod pair_sort;
pub mod phase;
mod radix;
pub mod select;
pub mod skin_grid;
pub mod sort_sweep;
mod stateful;

pub use brute_force::pairs_brute_force;
pub use column_grid::ColumnGrid;
pub use hash_grid::HashGrid;
pub use incremental_sap::IncrementalSap;
pub use phase::{BroadPhase, BroadPhaseChoice, BroadPhaseKind};
pub use select::{BroadPhaseStats, MoveCounts, choose};
pub use skin_grid::SkinGrid;
pub use sort_sweep::SortAndSweep;

use crate::bounding::Aabb;
#[cfg(doc)]
use crate::bounding::BoundingVolume;

/// Which bodies may pair: `a` and `b` do when each one's group meets the other's mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CollisionFilter {
    /// Group bits of this body.
    pub group: u32,
    /// Groups this body pairs with.
    pub mask: u32,
}

impl CollisionFilter {
    /// Pairs with everything.
    pub const ALL: Self = Self {
        group: u32::MAX,
        mask: u32::MAX,
    };

    /// Whether bodies with filters `self` and `other` may pair (symmetric).
    #[must_use]
    #[inline]
    pub fn allows(&self, other: &Self) -> bool {
        self.group & other.mask != 0 && other.group & self.mask != 0
    }
}

/// One body as the broad phase sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proxy {
    /// The body's id.
    pub body: u32,
    /// World box of the body's shape grown by the body's margin on every side, metres.
    pub bounds: Aabb,
    /// Static bodies never pair with each other.
    pub is_static: bool,
    /// Which bodies it may pair with.
    pub filter: CollisionFilter,
}

impl Proxy {
    /// Whether `self` and `other` may pair at all: each group meets the other's mask and
    /// they are not both static.
    #[must_use]
    #[inline]
    pub fn may_pair(&self, other: &Self) -> bool {
        !(self.is_static && other.is_static) && self.filter.allows(&other.filter)
    }
}

/// A pair of bodies whose grown boxes overlap, `a < b`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CandidatePair {
    /// The smaller body id.
    pub a: u32,
    /// The larger body id.
    pub b: u32,
}

impl CandidatePair {
    /// The pair of two distinct ids, in either order (stored smaller first).
    #[must_use]
    #[inline]
    pub fn of(a: u32, b: u32) -> Self {
        Self {
            a: a.min(b),
            b: a.max(b),
        }
    }
}

/// The stateful broad phases' input check: bounds are trusted (finite, `min <= max`, the
/// [`Aabb`] invariant), and checked in debug builds.
#[inline]
fn debug_assert_valid_bounds(bounds: &Aabb) {
    debug_assert!(
        bounds.min.is_finite() && bounds.max.is_finite() && bounds.min.cmple(bounds.max).all(),
        "broad-phase bounds must be finite and not inverted: {bounds:?}"
    );
}

/// `⌊x⌋` clamped to `i64`, exactly (as `x.floor() as i64`), without the library call
/// `f64::floor` compiles to on baseline x86-64 (no SSE4.1 `roundsd`): the truncating
/// conversion, one lower for negative non-integers. Monotone, so a larger coordinate never
/// falls in an earlier cell or column.
#[inline]
fn floor_to_i64(x: f64) -> i64 {
    let t = x as i64;
    t.saturating_sub(i64::from((t as f64) > x))
}

/// Asks the processor to start loading the cache line holding `p` into its caches. A hint:
/// no effect on any result, whatever `p` is.
#[inline(always)]
pub(crate) fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads nothing the program sees and never faults, whatever the
    // address (it may be dangling or one past the end); SSE, which it needs, is part of the
    // x86_64 baseline.
    unsafe {
        core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
