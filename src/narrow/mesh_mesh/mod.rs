//! Exact mesh–mesh queries: collision, all contacts, distance and tolerance, by tandem BVH
//! traversal.
//!
//! Both meshes are given as [`Bvh`]s over their triangles, each in its own local frame, and
//! compared under `pose_ab` (B's frame expressed in A's). Node pairs are culled with the
//! volume type's own test ([`crate::bvh::tandem`]), and a leaf of one large triangle against
//! a small node by the triangle itself (`leaf_triangle.rs`); surviving triangle pairs are decided by
//! the exact primitives of [`crate::narrow::triangle_triangle`] on A's triangle and B's
//! triangle mapped into A's frame by [`Triangle::transformed`](crate::geometry::Triangle::transformed).
//! Because every volume test is conservative, the answers are *identical* to a brute-force
//! loop over all triangle pairs that maps B's triangles the same way: same boolean, same set
//! of intersecting pairs, same minimum distance.
//!
//! | query | answer | stops |
//! |---|---|---|
//! | [`intersects_mesh_mesh`] | do any two triangles intersect (closed sets: touching counts)? | at the first intersecting pair |
//! | [`contacts_mesh_mesh`] | every intersecting triangle pair, with its intersection segment and a normal | when the sink says so |
//! | [`distance_mesh_mesh`] | smallest triangle–triangle distance, witnesses, error bound | at distance 0 |
//! | [`within_distance_mesh_mesh`] | is the distance at most `d`? | at the first pair within `d` |
//! | [`proximity_mesh_mesh`] | the same, and a lower bound of the distance when not | at the first pair within `d` |
//!
//! The four the pipeline runs (all but `within_distance_mesh_mesh`) have a `_within` form
//! that polls a [`WorkClock`] before each pair of leaves (each
//! step of the distance search) and says when it stopped unfinished; the plain forms run
//! it with an unlimited clock.
//!
//! Meshes are surfaces here: a mesh wholly inside a closed mesh does not intersect it, and
//! the distance of intersecting meshes is `0.0`, not a penetration depth.
//!
//! Which volume type pays off for which query is measured in `benches/mesh_pair.rs` and
//! `examples/pair_queries.rs`: OBB-like volumes cull overlap tests best, RSS-like volumes give
//! the tightest distance bounds.
//!
//! Every function takes a [`MeshMeshWorkspace`] for its traversal stack and does not allocate
//! once that workspace has grown to the deepest descent.

mod collide;
mod distance;
pub mod frontier;
mod leaf_triangle;

pub use collide::{
    TRIANGLE_PAIR_WORK, contacts_mesh_mesh, contacts_mesh_mesh_within, intersects_mesh_mesh,
    intersects_mesh_mesh_within,
};
pub use distance::{
    Proximity, TRIANGLE_DISTANCE_WORK, cached_pair_within, distance_mesh_mesh,
    distance_mesh_mesh_within, precedes_in_ties, proximity_mesh_mesh, proximity_mesh_mesh_within,
    rounding_bound, within_distance_mesh_mesh,
};

use crate::budget::WorkClock;
use crate::bvh::Bvh;
use crate::bvh::tandem::RankedPair;
use crate::geometry::Triangle;
use crate::math::{DVec3, Isometry};
use std::collections::BinaryHeap;
use std::ops::ControlFlow;

/// Scratch space of the mesh–mesh queries; reuse one per thread.
#[derive(Debug, Default, Clone)]
pub struct MeshMeshWorkspace {
    pairs: Vec<[u32; 2]>,
    ranked: BinaryHeap<RankedPair>,
}

impl MeshMeshWorkspace {
    /// An empty workspace (it grows on first use).
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }
}

/// One intersecting triangle pair, in A's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleContact {
    /// The triangle of A and of B, as indices into each mesh's own triangle list.
    pub triangles: [u32; 2],
    /// The intersection of the two closed triangles is this segment (both ends equal when it
    /// is a point; for coplanar overlapping triangles, the longest segment of the overlap
    /// region found by [`intersection_segment_triangle_triangle`](crate::narrow::intersection_segment_triangle_triangle)).
    pub segment: [DVec3; 2],
    /// The segment's midpoint: the contact point, metres, A's frame.
    pub point: DVec3,
    /// Unit normal pointing from A to B: A's triangle normal (the direction that separates B
    /// from A's surface locally), or B's reversed when A's triangle has zero area, or
    /// [`FALLBACK_NORMAL`] when both have.
    pub normal: DVec3,
}

/// The normal of a contact between two zero-area triangles (no direction is better).
pub const FALLBACK_NORMAL: DVec3 = DVec3::Z;

/// The smallest distance between two meshes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshDistance {
    /// Distance, metres, `≥ 0`; `0.0` when the meshes intersect. Within `error_bound` of the
    /// true minimum over all triangle pairs.
    pub distance: f64,
    /// Witness on A's surface, A's frame.
    pub point_a: DVec3,
    /// Witness on B's surface, A's frame (`point_a.distance(point_b) == distance`).
    pub point_b: DVec3,
    /// The triangles holding the witnesses, as indices into each mesh's own triangle list.
    pub triangles: [u32; 2],
    /// `|distance − true distance| ≤ error_bound`, metres: the tolerance asked for through
    /// [`DistanceParams`] plus the rounding of the computation.
    pub error_bound: f64,
}

/// Tolerances of [`distance_mesh_mesh`] (FCL's `abs_err`, `rel_err`): the search may stop
/// once no untried pair can beat the best distance found by more than
/// `max(abs_err, rel_err · distance)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceParams {
    /// Absolute tolerance, metres, `≥ 0`.
    pub abs_err: f64,
    /// Relative tolerance, `≥ 0`.
    pub rel_err: f64,
}

impl DistanceParams {
    /// The exact minimum (to rounding).
    pub const EXACT: Self = Self {
        abs_err: 0.0,
        rel_err: 0.0,
    };

    /// Whether a node pair whose distance is at least `bound` can be skipped when `best` has
    /// been found: it cannot improve `best` by more than the tolerance.
    #[must_use]
    #[inline]
    pub(crate) fn can_skip(&self, bound: f64, best: f64) -> bool {
        best <= 0.0 || bound >= best - self.abs_err || bound * (1.0 + self.rel_err) >= best
    }
}

impl Default for DistanceParams {
    fn default() -> Self {
        Self::EXACT
    }
}

/// Warm start of [`distance_mesh_mesh`] for one pair of meshes: remembers the closest
/// triangle pair of the last query, whose distance under the next pose is a good first
/// bound when poses change little between frames. Keep one per mesh pair; a cache used with
/// another pair is harmless (only slower), since its slots are checked against the meshes.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct DistanceCache {
    /// Leaf slots (not triangle ids) of the last closest pair in A and B.
    slots: Option<[u32; 2]>,
}

impl DistanceCache {
    /// A cache that remembers nothing yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }
}

/// Whether `clock` allows the triangle pairs of leaf `leaf_a` of `a` and leaf `leaf_b` of
/// `b`, `per_pair` units each: the one poll of the `_within` searches before a leaf pair.
fn clock_allows_leaf_pair<B>(
    clock: &mut WorkClock,
    (a, b): (&Bvh<B>, &Bvh<B>),
    [leaf_a, leaf_b]: [usize; 2],
    per_pair: u64,
) -> bool {
    let tests = a.nodes()[leaf_a].slots().len() * b.nodes()[leaf_b].slots().len();
    clock.allows(per_pair * tests as u64)
}

/// Calls `visit(slot_a, triangle_a, slot_b, triangle_b)` for every triangle pair of leaf
/// `leaf_a` of `a` and leaf `leaf_b` of `b`, with B's triangle mapped into A's frame by
/// `iso` (once per triangle of B), until `visit` breaks.
#[inline]
fn for_each_triangle_pair<B, V>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    [leaf_a, leaf_b]: [usize; 2],
    iso: &Isometry,
    mut visit: V,
) -> ControlFlow<()>
where
    V: FnMut(usize, &Triangle, usize, &Triangle) -> ControlFlow<()>,
{
    for sb in b.nodes()[leaf_b].slots() {
        let tri_b = b.triangles()[sb].transformed(iso);
        for sa in a.nodes()[leaf_a].slots() {
            visit(sa, &a.triangles()[sa], sb, &tri_b)?;
        }
    }
    ControlFlow::Continue(())
}
