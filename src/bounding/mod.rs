//! Bounding volumes: sphere, AABB, OBB, k-DOP and the swept-sphere family (PSS, LSS, RSS).
//!
//! Every type implements [`BoundingVolume`], the one interface BVHs, the broad phase and the
//! time-critical traversal are written against. A volume lives in the local frame of the
//! shape it bounds; two volumes in different frames are compared under the relative pose
//! `pose_ab` (frame B expressed in frame A, see [`crate::math`]).
//!
//! | type | fit | overlap under a pose | distance bound |
//! |---|---|---|---|
//! | [`BoundingSphere`] (= [`Pss`]) | Welzl (exact), Ritter, PCA | exact | exact |
//! | [`Aabb`] | exact | B's box enclosed in an AABB of A's frame | along A's axes |
//! | [`Obb`] | Gottschalk: PCA of the hull's area-weighted facets | 15-axis SAT | max SAT gap |
//! | [`Kdop`] (14, 18, 26) | exact slabs | refit after rotation, then slabs | max slab gap |
//! | [`Lss`], [`Rss`] | PCA | exact core distance | exact core distance − radii |
//!
//! # Conservativeness
//! Fits pad outward by [`conservative_slack`](crate::math::conservative_slack) of the
//! coordinate scale so every fitted point passes [`BoundingVolume::contains_point`] despite
//! rounding; overlap tests add the same slack, so two volumes that share a point are never
//! reported apart. Tests in `tests/bounding_*.rs` check both over thousands of seeded cases.

mod aabb;
pub mod fit;
mod kdop;
mod obb;
mod sphere;
mod ssv;

pub use aabb::Aabb;
pub use kdop::{Kdop, Kdop14, Kdop18, Kdop26};
pub use obb::Obb;
pub use sphere::BoundingSphere;
pub use ssv::{Lss, Pss, Rss};

use crate::geometry::Triangle;
use crate::math::{DVec3, Isometry};

/// A convex volume that bounds some geometry, in that geometry's local frame.
///
/// # Contract
/// - `fit_*` returns a volume containing every input point (or triangle), padded so that
///   [`contains_point`](Self::contains_point) holds for each despite rounding. Inputs must
///   be non-empty and finite (meshes and hulls are validated before they are fitted).
/// - [`overlaps`](Self::overlaps) is conservative: when the two volumes share a point it
///   returns `true`. It may return `true` for volumes a little apart (AABB and k-DOP under a
///   rotation test an enclosing volume of B).
/// - [`distance_lower_bound`](Self::distance_lower_bound) never exceeds the true distance
///   between the two volumes (hence between anything they bound), and is `0` when they
///   overlap.
/// - Units: metres (volume in cubic metres).
pub trait BoundingVolume: Copy + std::fmt::Debug + Send + Sync + 'static {
    /// Short name for reports and bench ids (`"obb"`, `"kdop18"`, …).
    const NAME: &'static str;

    /// A volume containing every point. `points` must be non-empty and finite.
    #[must_use]
    fn fit_points(points: &[DVec3]) -> Self;

    /// A volume containing every triangle. `triangles` must be non-empty and finite.
    #[must_use]
    fn fit_triangles(triangles: &[Triangle]) -> Self;

    /// A volume containing both `self` and `other` (same frame).
    #[must_use]
    fn merged(&self, other: &Self) -> Self;

    /// Grows `self` to contain `other` (same frame).
    /// A volume containing `triangles` that keeps `self`'s orientation (OBB, LSS, RSS), for
    /// refitting a leaf after its vertices moved; other types fit afresh.
    #[must_use]
    #[inline]
    fn fit_triangles_in_frame(&self, triangles: &[Triangle]) -> Self {
        Self::fit_triangles(triangles)
    }

    /// A volume containing `a` and `b` that keeps `self`'s orientation (for the types that
    /// have one: OBB, LSS, RSS), for refits after motion: a few projections instead of a
    /// new fit, and as tight as [`merged`](Self::merged) while the contents have not turned.
    /// Types without an orientation return `a.merged(b)`.
    #[must_use]
    #[inline]
    fn merged_in_frame(&self, a: &Self, b: &Self) -> Self {
        a.merged(b)
    }

    #[inline]
    fn merge(&mut self, other: &Self) {
        *self = self.merged(other);
    }

    /// The volume moved by `pose` into the parent frame: exact for spheres, OBBs and
    /// swept-sphere volumes; for AABBs and k-DOPs, an enclosing volume of the moved one.
    #[must_use]
    fn transformed(&self, pose: &Isometry) -> Self;

    /// Conservative overlap of `self` (frame A) and `other` (frame B), with `pose_ab` the
    /// pose of B in A.
    #[must_use]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool;

    /// Overlap of two volumes in the same frame. Conservative like
    /// [`overlaps`](Self::overlaps); for every type,
    /// `a.overlaps(b, pose_ab) == a.intersects(&b.transformed(pose_ab))` up to rounding slack.
    #[must_use]
    #[inline]
    fn intersects(&self, other: &Self) -> bool {
        self.overlaps(other, &Isometry::IDENTITY)
    }

    /// A lower bound on the distance between `self` (frame A) and `other` (frame B), metres;
    /// `0` when they may overlap.
    #[must_use]
    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64;

    /// [`distance_lower_bound`](Self::distance_lower_bound) for a search that only cares
    /// whether the bound reaches `limit`: when it does, any lower bound `≥ limit` may be
    /// returned (a cheaper, looser one); below `limit` the result is the full bound.
    /// Branch-and-bound distance queries call this with the best distance found so far.
    #[must_use]
    #[inline]
    fn distance_lower_bound_within(&self, other: &Self, pose_ab: &Isometry, limit: f64) -> f64 {
        let _ = limit;
        self.distance_lower_bound(other, pose_ab)
    }

    /// [`distance_lower_bound_within`](Self::distance_lower_bound_within) of each volume of
    /// `pair` (frame A) against the one `other` (frame B): the two children of a node pair
    /// split on one side. Types whose bound first moves `other` into frame A (OBB) move it
    /// once for both.
    #[must_use]
    #[inline]
    fn distance_lower_bounds_within(
        pair: [&Self; 2],
        other: &Self,
        pose_ab: &Isometry,
        limit: f64,
    ) -> [f64; 2] {
        pair.map(|x| x.distance_lower_bound_within(other, pose_ab, limit))
    }

    /// Whether `point` (same frame) lies inside or on the volume. Exact up to rounding; no
    /// slack is added here (fits add it).
    #[must_use]
    fn contains_point(&self, point: DVec3) -> bool;

    /// The volume's centre (a point inside it), for ordering and splitting.
    #[must_use]
    fn center(&self) -> DVec3;

    /// Volume, cubic metres. Zero for flat or degenerate volumes (an RSS of zero radius, an
    /// OBB of a planar set).
    #[must_use]
    fn volume(&self) -> f64;

    /// A length (metres) measuring the volume's extent: its diameter, or an upper bound of it
    /// within a small constant factor. Builders and traversal orderings compare these.
    #[must_use]
    fn size(&self) -> f64;

    /// The stand-off, metres: an upper bound on how far any point of the volume can be from
    /// the (non-empty) geometry it bounds, i.e. on the one-sided Hausdorff distance from the
    /// volume to the geometry. When traversal stops at two volumes whose distance lower
    /// bound is `d`, the true distance lies in `[d, d_bv + stand_off_a + stand_off_b]`, with
    /// `d_bv` the exact distance between the volumes. This is the error bound of a truncated
    /// time-critical answer.
    #[must_use]
    fn stand_off(&self) -> f64;
}

/// Padding (metres) that keeps a volume moved by `pose` conservative: moving a centre `c`
/// rounds each coordinate by a few ulps of `|c|₁ + |t|`, and rotating the axes moves the
/// surface by a few ulps of the volume's `size`. Exact types (OBB, LSS, RSS) grow by this
/// so that every point of the original volume, moved, stays inside the moved volume.
#[must_use]
#[inline]
pub(crate) fn transform_slack(center: DVec3, pose: &Isometry, size: f64) -> f64 {
    crate::math::conservative_slack(
        center.abs().element_sum() + pose.translation.abs().max_element() + size,
    )
}
