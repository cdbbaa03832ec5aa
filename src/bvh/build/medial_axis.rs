//! Medial-axis builder: the triangles grouped along the surface's medial axis, the second of
//! the two sphere-tree constructions (Hubbard 1996; Bradshaw & O'Sullivan, "Adaptive
//! medial-axis approximation for sphere-tree construction", ACM TOG 23(1), 2004, who report
//! it bounds about twice as tightly as the octree for the same number of spheres).
//!
//! Each triangle is given the inscribed ball touching it at its centroid
//! ([`medial_balls`]); the ball's centre is a point of the medial axis. A node is split at
//! the median of its triangles' *ball centres* along their widest axis while those centres
//! spread over at least [`MEDIAL_SPREAD`] of the node's extent: the cut then runs across the
//! medial axis, so a tube is sliced into rings and a plate into pieces holding both faces,
//! and each side is a stretch of the axis whose sphere hugs the solid (the triangles of a
//! ring lie on its medial ball). Once the centres bunch up (the node's triangles face one
//! medial ball, a blob seen from its centre), the node is split at the median of its
//! triangles' centroids instead, into patches of that ball's surface.
//!
//! Every node's sphere is then fitted to its triangles ([`super::fit_topology`]), so the
//! tree bounds the surface whatever the medial approximation made of it (an open surface
//! has no inside, and its balls stop at the start radius: the rule then splits by
//! centroids).

use super::top_down::{split_at_median_by, split_recursively};
use super::{BuildPrimitive, Topology};
use crate::geometry::Triangle;
use crate::geometry::mesh::medial_balls;
use crate::math::{DVec3, bounds_of};

/// Extent of a node's ball centres, over the extent of its centroids, from which the node is
/// cut across the medial axis (below it, into surface patches).
pub const MEDIAL_SPREAD: f64 = 0.5;

/// Builds the topology by medial-axis splits of `triangles` (see the [module docs](self)).
pub(super) fn build(
    triangles: &[Triangle],
    primitives: &[BuildPrimitive],
    leaf_size: u32,
) -> Topology {
    let centres: Vec<DVec3> = medial_balls(triangles).iter().map(|b| b.center).collect();
    let centroid = |i: u32| primitives[i as usize].centroid;
    let centre = |i: u32| centres[i as usize];
    split_recursively(primitives.len(), leaf_size, (), |order, ()| {
        let (centroid_extent, _) = widest(order, centroid);
        let (centre_extent, axis) = widest(order, centre);
        let mid = if centre_extent >= MEDIAL_SPREAD * centroid_extent && centre_extent > 0.0 {
            split_at_median_by(order, |i| centre(i)[axis])
        } else {
            let (_, axis) = widest(order, centroid);
            split_at_median_by(order, |i| centroid(i)[axis])
        };
        (mid, [(), ()])
    })
}

/// The largest extent of the points `point` gives the indices, metres, and its axis.
fn widest(order: &[u32], point: impl Fn(u32) -> DVec3) -> (f64, usize) {
    let (lo, hi) = bounds_of(order.iter().map(|&i| point(i)));
    let extent = hi - lo;
    (extent.max_element(), extent.max_position())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TriMesh;

    /// Whether every node down to `depth` holds triangles of both the outer and the inner
    /// half of a torus's tube (a slice across the core circle) rather than a patch of one.
    fn slices_across_the_tube(
        topology: &Topology,
        triangles: &[Triangle],
        depth: u32,
        major: f64,
    ) -> bool {
        let outer = |i: u32| {
            let c = triangles[i as usize].centroid();
            c.truncate().length() > major
        };
        let mut stack = vec![(0usize, 0u32)];
        while let Some((i, d)) = stack.pop() {
            let node = topology.nodes[i];
            let [start, end] = node.span;
            let members = &topology.order[start as usize..end as usize];
            if !(members.iter().any(|&t| outer(t)) && members.iter().any(|&t| !outer(t))) {
                return false;
            }
            if d < depth && node.count == 0 {
                stack.extend([
                    (node.first as usize, d + 1),
                    (node.first as usize + 1, d + 1),
                ]);
            }
        }
        true
    }

    /// On a fat torus the medial rule cuts across the core circle (every node of the top
    /// five levels holds inner and outer triangles: 16 rings), where splitting the
    /// centroids at their median has cut the tube into inner and outer patches by then.
    /// Below, a ring is shorter along the circle than half its width, and the rule turns to
    /// patches (`MEDIAL_SPREAD`).
    #[test]
    fn a_torus_is_sliced_across_its_core_circle() {
        let (major, minor) = (1.0, 0.6);
        let mesh = TriMesh::torus(major, minor, 64, 32);
        let triangles: Vec<Triangle> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle(i))
            .collect();
        let primitives: Vec<BuildPrimitive> = triangles.iter().map(BuildPrimitive::of).collect();
        let medial = build(&triangles, &primitives, 1);
        assert!(slices_across_the_tube(&medial, &triangles, 4, major));
        let median =
            super::super::top_down::build(&primitives, super::super::BuildStrategy::Median, 1);
        assert!(!slices_across_the_tube(&median, &triangles, 4, major));
    }
}
