//! A mesh's convex hull as a proof of separation: every point of a mesh lies in its hull,
//! so two meshes whose hulls are apart by more than a threshold are apart by more than it,
//! with no traversal of their trees.
//!
//! The proof is a slab: GJK finds a direction between the two hulls, and one support call
//! per hull along it measures the gap between the planes that bound them. Two allowances
//! keep it a lower bound of the meshes' distance: the hull's support search answers within
//! its construction tolerance of the maximum over its vertices (it is convex to tolerance),
//! and a mesh vertex left out of the hull lies within [`MeshHull::outside`] of it (measured
//! once, by GJK from each vertex).

use crate::geometry::{ConvexPolyhedron, Segment, SupportMap, TriMesh};
use crate::math::{DVec3, Isometry, conservative_slack};
use crate::narrow::gjk::{GjkCache, GjkOutcome, GjkParams, gjk_distance};
use std::collections::HashSet;

/// A mesh's convex hull and how far outside it any of the mesh's vertices lies.
#[derive(Debug, Clone)]
pub struct MeshHull {
    hull: ConvexPolyhedron,
    /// Largest distance from a mesh vertex to the hull, metres: an upper bound (GJK's
    /// distance, which converges from above), 0 for meshes whose vertices all lie in it.
    outside: f64,
}

impl MeshHull {
    /// The hull of `mesh`'s vertices; `None` for a flat or degenerate mesh (a hull of
    /// lower dimension proves little and GJK's support search needs a solid). The hull plus
    /// one GJK per vertex inside it: offline work, as the trees are.
    #[must_use]
    pub fn of(mesh: &TriMesh) -> Option<Self> {
        let hull = ConvexPolyhedron::try_from_points(mesh.vertices()).ok()?;
        if hull.dimension() != 3 {
            return None;
        }
        let params = GjkParams::default();
        // A hull vertex is one of the mesh's vertices, on the hull: distance 0, no GJK (a
        // round mesh has nearly all of its vertices there; GJK for each took 1.1 s of an
        // 80,000-vertex UV sphere's registration).
        let key = |p: &DVec3| p.to_array().map(f64::to_bits);
        let on_hull: HashSet<[u64; 3]> = hull.vertices().iter().map(key).collect();
        let outside = mesh
            .vertices()
            .iter()
            .filter(|p| !on_hull.contains(&key(p)))
            .map(|&p| {
                // A segment from `p` to itself: the point, as a support map.
                let result = gjk_distance(
                    &hull,
                    &Segment::new(p, p),
                    &Isometry::IDENTITY,
                    &params,
                    &mut GjkCache::default(),
                );
                // `v` joins a point of the hull to `p`: its length is at least `p`'s
                // distance to the hull, whatever the outcome.
                result.v.length()
            })
            .fold(0.0, f64::max);
        Some(Self { hull, outside })
    }

    /// The largest distance from a vertex of the mesh to its hull, metres.
    #[must_use]
    pub fn outside(&self) -> f64 {
        self.outside
    }

    /// A lower bound of the distance between the mesh of `self` and the mesh of `other`
    /// placed by `pose_ab` (B's frame in A's), metres, rounding included; `None` when GJK
    /// finds the hulls touching or overlapping (or does not converge). `cache` is the
    /// pair's warm start, kept between frames.
    #[must_use]
    pub fn gap(&self, other: &Self, pose_ab: &Isometry, cache: &mut GjkCache) -> Option<f64> {
        let (a, b) = (&self.hull, &other.hull);
        let result = gjk_distance(a, b, pose_ab, &GjkParams::default(), cache);
        if result.outcome != GjkOutcome::Separated {
            return None;
        }
        // `v` points from B's closest point to A's: A lies beyond the slab's far plane.
        let n = result.v.try_normalize()?;
        let a_low = a.support(-n);
        let b_high = pose_ab.transform_point(b.support(pose_ab.inverse_transform_vector(n)));
        let gap = n.dot(a_low) - n.dot(b_high);
        let allowances = a.tolerance() + self.outside + b.tolerance() + other.outside;
        let scale = a_low.abs().max_element() + b_high.abs().max_element();
        Some(gap - allowances - conservative_slack(scale))
    }
}

#[cfg(test)]
#[path = "mesh_hull_tests.rs"]
mod tests;
