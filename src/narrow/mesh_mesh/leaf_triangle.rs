//! A large triangle's own test against a small node of the other tree, in place of its
//! leaf volume's.
//!
//! # Why
//! A leaf of one triangle is bounded by a rectangle (RSS) or a box (OBB) around it: at least
//! twice the triangle's area, the rest empty. A large flat triangle (a floor, a tray, a CAD
//! face) against a detailed mesh then passes every node of the other tree that comes near
//! that empty half, down to its leaves, whose triangles are all far: a 2 m two-triangle
//! plate at 0.75 m from the Stanford bunny (69,451 triangles) took 36 ms a distance query
//! in trees of one triangle a leaf (`examples/fcl_peer`, `plate-bunny`).
//!
//! The daemon's trees hold up to two a leaf ([`MESH_TREE_PARAMS`](crate::narrow::MESH_TREE_PARAMS)),
//! which bound that plate's square exactly; a triangle left alone in its leaf still needs
//! the test. One large triangle against the bunny (the plate's poses, same run,
//! 2026-12-02): distance 271 µs mean and 28 ms at worst without it, 32 µs and 0.8 ms with it.
//!
//! Measured and not kept: the test on every leaf, over its triangles. It helps leaves of two
//! that are not a rectangle (a fan of four around a centre: distance 47 → 27 µs mean) but
//! costs leaves their volume already bounds exactly: the plate's all-contacts query 63 →
//! 90 µs, its boolean 0.67 → 1.13 µs.
//!
//! # The test
//! When one node of a pair is a leaf of one triangle at least [`LEAF_TRIANGLE_RATIO`] times
//! the other node's size, the other node's geometry lies in the ball around its volume's
//! centre of radius its [`size`](crate::bounding::BoundingVolume::size) (a diameter or more),
//! so the triangle's distance to that centre, less the radius and a rounding slack, is a
//! lower bound on the distance between the triangle and anything under the node. Queries
//! take the larger of it and the two volumes' bound; the overlap tests drop a pair it puts
//! apart. Both stay conservative, so every answer is unchanged.

use crate::bounding::BoundingVolume;
use crate::bvh::{Bvh, BvhNode};
use crate::geometry::Triangle;
use crate::math::{DVec3, Isometry, conservative_slack};
use crate::narrow::closest_points::closest_point_triangle;

/// How much larger (by size) than the other node a single triangle's leaf must be for the
/// triangle itself to be tested. Near 1 the ball around the other node is no tighter than
/// its volume and the closest-point query only adds cost; at 4 it cost pairs of detailed
/// meshes 5–15 % (`examples/fcl_peer`, env-rob and bunny-fandisk), at 16 it keeps the
/// plate's gain in one-triangle-leaf trees (distance mean 930 → 70 µs) while env-rob's collision queries still pay
/// up to about 10 %, near this machine's drift (2026-12-02).
pub(super) const LEAF_TRIANGLE_RATIO: f64 = 16.0;

/// The two trees of a query, at their relative pose, for the leaf-triangle test.
pub(super) struct LeafTriangles<'t, B> {
    pub a: &'t Bvh<B>,
    pub b: &'t Bvh<B>,
    /// B's frame in A's.
    pub iso: &'t Isometry,
}

impl<B: BoundingVolume> LeafTriangles<'_, B> {
    /// A lower bound, metres, on the distance between the triangles under node `x` of A
    /// and node `y` of B, by the module's test; `-∞` when neither node is a leaf of one
    /// triangle large enough against the other (or both are leaves: their triangles are
    /// measured next anyway).
    #[inline]
    pub fn lower_bound(&self, x: &BvhNode<B>, y: &BvhNode<B>) -> f64 {
        let single = |n: &BvhNode<B>| n.is_leaf() && n.slots().len() == 1;
        if single(x) && !y.is_leaf() && x.size >= LEAF_TRIANGLE_RATIO * y.size {
            let centre = self.iso.transform_point(y.bv.center());
            self.ball_bound(&self.a.triangles()[x.slots().start], centre, y.size)
        } else if single(y) && !x.is_leaf() && y.size >= LEAF_TRIANGLE_RATIO * x.size {
            let centre = self.iso.inverse_transform_point(x.bv.center());
            self.ball_bound(&self.b.triangles()[y.slots().start], centre, x.size)
        } else {
            f64::NEG_INFINITY
        }
    }

    /// The node test of the collision queries: the two volumes overlap and the module's
    /// test does not put the triangles under `x` and `y` apart.
    #[inline]
    pub fn overlaps(&self, x: &BvhNode<B>, y: &BvhNode<B>) -> bool {
        x.bv.overlaps(&y.bv, self.iso) && self.lower_bound(x, y) <= 0.0
    }

    /// The node bound of the distance queries, metres: the volumes' bound
    /// ([`BoundingVolume::distance_lower_bound_within`]), raised by the module's test.
    #[inline]
    pub fn distance_lower_bound_within(&self, x: &BvhNode<B>, y: &BvhNode<B>, limit: f64) -> f64 {
        let bound = x.bv.distance_lower_bound_within(&y.bv, self.iso, limit);
        self.raise(bound, x, y, limit)
    }

    /// `bound` (the volumes' bound of `x` and `y`, however computed) raised by the module's
    /// test while it is under `limit`; at or past `limit` the pair is pruned either way.
    #[inline]
    pub fn raise(&self, bound: f64, x: &BvhNode<B>, y: &BvhNode<B>, limit: f64) -> f64 {
        if bound >= limit {
            bound
        } else {
            bound.max(self.lower_bound(x, y))
        }
    }

    /// The distance from `triangle` to the ball of `radius` around `centre` (same frame,
    /// the centre moved there by the pose), less a slack for the rounding of that move and
    /// of the closest point.
    #[inline]
    fn ball_bound(&self, triangle: &Triangle, centre: DVec3, radius: f64) -> f64 {
        let nearest = closest_point_triangle(centre, triangle.a, triangle.b, triangle.c);
        let magnitude = centre.abs().max_element()
            + nearest.abs().max_element()
            + self.iso.translation.abs().max_element()
            + radius;
        centre.distance(nearest) - radius - conservative_slack(magnitude)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::Rss;
    use crate::bvh::BuildParams;
    use crate::math::Pose;
    use crate::narrow::distance_triangle_triangle;
    use crate::test_support::{meshes, point_in_cube, rng, rotation};

    /// A two-triangle plate against every node of a fine sphere's tree, at random poses:
    /// the bound never exceeds the distance from the plate's triangle to any triangle under
    /// the node, and it beats the volumes' own bound on some of them (nodes near the
    /// empty half of the triangle's rectangle: about 1,900 of 44,000 here).
    #[test]
    fn the_leaf_triangle_bound_holds_and_beats_the_volumes_near_a_big_triangle() {
        let plate = Bvh::<Rss>::from_mesh(&meshes::grid(1.0, 1), &BuildParams::BINNED_SAH);
        let sphere =
            Bvh::<Rss>::from_mesh(&meshes::uv_sphere(0.3, 24, 16), &BuildParams::BINNED_SAH);
        let mut r = rng(99);
        let (mut tighter, mut tested) = (0, 0);
        for _ in 0..40 {
            let pose = Pose::new(point_in_cube(&mut r, 1.2), rotation(&mut r));
            let iso = pose.to_isometry();
            let leaf = LeafTriangles {
                a: &plate,
                b: &sphere,
                iso: &iso,
            };
            let leaves = plate.nodes().iter().filter(|n| n.is_leaf());
            for x in leaves {
                let triangle = &plate.triangles()[x.slots().start];
                for (i, y) in sphere.nodes().iter().enumerate() {
                    let bound = leaf.lower_bound(x, y);
                    if bound == f64::NEG_INFINITY {
                        continue;
                    }
                    tested += 1;
                    let span = sphere_span(&sphere, i);
                    let truth = (span.0..span.1)
                        .map(|s| {
                            let t = sphere.triangles()[s].transformed(&iso);
                            distance_triangle_triangle(triangle, &t).distance
                        })
                        .fold(f64::INFINITY, f64::min);
                    assert!(bound <= truth, "bound {bound} above the distance {truth}");
                    tighter += usize::from(bound > x.bv.distance_lower_bound(&y.bv, &iso));
                }
            }
        }
        assert!(
            tested > 10_000 && tighter > tested / 50,
            "{tighter} of {tested} tighter"
        );
    }

    /// The triangle slots under node `i`: its leaves' slots are contiguous.
    fn sphere_span(tree: &Bvh<Rss>, i: usize) -> (usize, usize) {
        let node = &tree.nodes()[i];
        if node.is_leaf() {
            return (node.slots().start, node.slots().end);
        }
        let [l, r] = node.children();
        (sphere_span(tree, l).0, sphere_span(tree, r).1)
    }
}
