//! A convex shape against a triangle mesh, through the mesh's BVH: only the triangles whose
//! bounding volumes can matter are tested, each by a per-triangle query the caller gives
//! (a closed form for spheres, capsules and boxes, GJK for the other convex shapes).
//!
//! The shape enters the traversal as one bounding volume of the tree's type, in its own
//! frame (A); the mesh's tree is in B's frame, placed by `pose_ab`. Meshes are surfaces:
//! the per-triangle query decides what "penetrating" a triangle means, and the mesh answer
//! is the minimum over its triangles.

use crate::bounding::BoundingVolume;
use crate::budget::WorkClock;
use crate::bvh::Bvh;
use crate::bvh::tandem::RankedPair;
use crate::geometry::Triangle;
use crate::math::{Isometry, Pose};
use std::collections::BinaryHeap;
use std::ops::ControlFlow;

/// Units of [`WorkClock`] work one triangle query counts for (a closed-form
/// shape–triangle test costs a few closed-form pairs; GJK more).
pub const TRIANGLE_WORK: u64 = 4;

/// Scratch of the traversals (no allocation once grown).
#[derive(Debug, Default)]
pub struct ConvexMeshWorkspace {
    ranked: BinaryHeap<RankedPair>,
    stack: Vec<u32>,
}

impl ConvexMeshWorkspace {
    /// An empty workspace.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }
}

/// The smallest value of `triangle_value` over the mesh's triangles (each given with its id
/// in the mesh and in A's frame), skipping every subtree whose lower bound
/// `node_bound(volume)` on the shape's distance to it exceeds the best value so far (or 0,
/// while the best is negative: a deeper penetration can hide in any subtree that overlaps
/// the shape) or `limit` (metres; `f64::INFINITY` for the exact minimum). `None` for a mesh
/// with no triangle, or when no subtree comes within `limit`; a returned value above
/// `limit` is only an upper bound.
///
/// `node_bound` gets a node's volume in B's frame (the mesh's) and must answer a lower
/// bound, metres, on the distance between the shape and anything inside it, 0 where they
/// may touch ([`volume_bound`] makes one from a volume around the shape).
///
/// `triangle_value(id, triangle, threshold)` must never be below the true distance between
/// the shape and the triangle minus its own error (a signed distance, or a distance clamped
/// at 0), so that the volumes' lower bounds stay valid for it; it may answer `None` when it
/// proves the value above `threshold` (metres, the walk's current pruning bound: such a
/// triangle cannot change the answer), skipping its exact query.
///
/// Every triangle whose value is `≤ 0` is visited when `limit ≥ 0` (the walk stops only at
/// subtrees whose lower bound is positive), so a caller may collect the triangles the shape
/// touches during this walk instead of walking again.
pub fn nearest_triangle<B, T>(
    node_bound: impl Fn(&B) -> f64,
    tree: &Bvh<B>,
    pose_ab: &Pose,
    limit: f64,
    workspace: &mut ConvexMeshWorkspace,
    triangle_value: impl FnMut(u32, &Triangle, f64) -> Option<(f64, T)>,
) -> Option<(f64, T)>
where
    B: BoundingVolume,
{
    let walk = nearest_triangle_within(
        node_bound,
        tree,
        pose_ab,
        limit,
        &mut WorkClock::default(),
        workspace,
        triangle_value,
    );
    debug_assert!(
        walk.unvisited_lower.is_none(),
        "an unlimited clock never stops"
    );
    walk.best
}

/// What [`nearest_triangle_within`] found before it finished or its clock stopped it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walk<T> {
    /// The smallest value found, with its answer (as [`nearest_triangle`]'s).
    pub best: Option<(f64, T)>,
    /// When the clock stopped the walk: the least lower bound of the subtrees it left,
    /// metres, so the true minimum is at least the smaller of this and `best`'s value.
    /// `None` when the walk finished.
    pub unvisited_lower: Option<f64>,
}

/// [`nearest_triangle`], polling `clock` before each leaf ([`TRIANGLE_WORK`] units per
/// triangle). Stopped, it returns what it found and the least lower bound of what it left:
/// the leaves are visited nearest first, so that bound only grows with more work.
pub fn nearest_triangle_within<B, T>(
    node_bound: impl Fn(&B) -> f64,
    tree: &Bvh<B>,
    pose_ab: &Pose,
    limit: f64,
    clock: &mut WorkClock,
    workspace: &mut ConvexMeshWorkspace,
    mut triangle_value: impl FnMut(u32, &Triangle, f64) -> Option<(f64, T)>,
) -> Walk<T>
where
    B: BoundingVolume,
{
    let mut walk = Walk {
        best: None,
        unvisited_lower: None,
    };
    if tree.triangle_count() == 0 {
        return walk;
    }
    let iso_ab = pose_ab.to_isometry();
    let nodes = tree.nodes();
    let bound = |node: usize| node_bound(&nodes[node].bv);
    let best = &mut walk.best;
    let heap = &mut workspace.ranked;
    heap.clear();
    heap.push(RankedPair {
        bound: bound(0),
        a: 0,
        b: 0,
    });
    // Above this a subtree or triangle cannot change the answer (see the docs).
    let threshold = |best: &Option<(f64, T)>| {
        best.as_ref()
            .map_or(limit, |(value, _)| value.max(0.0).min(limit))
    };
    let prune = |bound: f64, best: &Option<(f64, T)>| bound > threshold(best);
    // The largest bound popped so far bounds everything left: each entry left was in the
    // heap, hence no nearer, when that one was popped, or descends from one that was (a
    // fitted child volume may reach nearer than its parent's, but its triangles cannot).
    let mut floor = f64::NEG_INFINITY;
    while let Some(entry) = heap.pop() {
        if prune(entry.bound, best) {
            break;
        }
        floor = floor.max(entry.bound);
        let node = &nodes[entry.a as usize];
        if node.is_leaf() {
            if !clock.allows(TRIANGLE_WORK * node.slots().len() as u64) {
                walk.unvisited_lower = Some(floor);
                break;
            }
            for slot in node.slots() {
                let triangle = tree.triangles()[slot].transformed(&iso_ab);
                let Some((value, answer)) =
                    triangle_value(tree.triangle_id(slot), &triangle, threshold(best))
                else {
                    continue;
                };
                if best.as_ref().is_none_or(|(b, _)| value < *b) {
                    *best = Some((value, answer));
                }
            }
            continue;
        }
        for child in node.children() {
            let child_bound = bound(child);
            if !prune(child_bound, best) {
                heap.push(RankedPair {
                    bound: child_bound,
                    a: child as u32,
                    b: 0,
                });
            }
        }
    }
    walk
}

/// The node bound of [`nearest_triangle`] for a shape inside `shape_bv` (A's frame): the
/// two volumes' lower bound, the shape's placed in B's frame by `pose_ab`'s inverse.
pub fn volume_bound<B: BoundingVolume>(shape_bv: &B, pose_ab: &Pose) -> impl Fn(&B) -> f64 {
    let iso_ba = pose_ab.inverse().to_isometry();
    move |node| node.distance_lower_bound(shape_bv, &iso_ba)
}

/// Calls `visit` with every triangle (A's frame, with its id in the mesh) whose leaf volume
/// overlaps the shape's volume `shape_bv` at `pose_ab`, until `visit` breaks. Returns
/// whether it broke.
pub fn for_each_overlapping_triangle<B>(
    shape_bv: &B,
    tree: &Bvh<B>,
    pose_ab: &Pose,
    workspace: &mut ConvexMeshWorkspace,
    mut visit: impl FnMut(u32, &Triangle) -> ControlFlow<()>,
) -> bool
where
    B: BoundingVolume,
{
    if tree.triangle_count() == 0 {
        return false;
    }
    let iso_ab: Isometry = pose_ab.to_isometry();
    let iso_ba = pose_ab.inverse().to_isometry();
    let nodes = tree.nodes();
    let stack = &mut workspace.stack;
    stack.clear();
    stack.push(0);
    while let Some(index) = stack.pop() {
        let node = &nodes[index as usize];
        if !node.bv.overlaps(shape_bv, &iso_ba) {
            continue;
        }
        if node.is_leaf() {
            for slot in node.slots() {
                let triangle = tree.triangles()[slot].transformed(&iso_ab);
                if visit(tree.triangle_id(slot), &triangle).is_break() {
                    return true;
                }
            }
        } else {
            stack.extend(node.children().map(|c| c as u32));
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::{Obb, Rss};
    use crate::bvh::BuildParams;
    use crate::math::DVec3;
    use crate::narrow::closest_points::closest_point_triangle;
    use crate::test_support::{meshes, point_in_cube, rng, rotation};
    use rand::Rng;

    /// Signed distance from a ball to a triangle (negative: the ball reaches past it).
    fn ball_triangle(center: DVec3, radius: f64, t: &Triangle) -> f64 {
        center.distance(closest_point_triangle(center, t.a, t.b, t.c)) - radius
    }

    /// A ball as a bounding volume of type `B`: fitted to the 6 extreme points and the 8
    /// corners of its box grown to contain it (a box contains the ball).
    fn ball_bv<B: BoundingVolume>(center: DVec3, radius: f64) -> B {
        let corners: Vec<DVec3> = (0..8)
            .map(|i| {
                center
                    + DVec3::new(
                        if i & 1 == 0 { -radius } else { radius },
                        if i & 2 == 0 { -radius } else { radius },
                        if i & 4 == 0 { -radius } else { radius },
                    )
            })
            .collect();
        B::fit_points(&corners)
    }

    /// Balls against a torus mesh: the traversal's minimum equals brute force over every
    /// triangle, for both tree types, with both touching and far balls.
    #[test]
    fn the_nearest_triangle_equals_brute_force_over_every_triangle() {
        let mesh = meshes::torus(1.0, 0.3, 32, 12);
        let rss = Bvh::<Rss>::from_mesh(&mesh, &BuildParams::BINNED_SAH);
        let obb = Bvh::<Obb>::from_mesh(&mesh, &BuildParams::BINNED_SAH);
        let triangles = meshes::triangles(&mesh);
        let mut rng = rng(111);
        let mut workspace = ConvexMeshWorkspace::new();
        let (mut penetrating, mut apart) = (0, 0);
        for case in 0..1000 {
            let pose_ab = Pose::new(point_in_cube(&mut rng, 1.5), rotation(&mut rng));
            let iso = pose_ab.to_isometry();
            let (center, radius) = (point_in_cube(&mut rng, 1.5), rng.random_range(0.01..0.8));
            let truth = triangles
                .iter()
                .map(|t| ball_triangle(center, radius, &t.transformed(&iso)))
                .fold(f64::INFINITY, f64::min);
            let found_rss = nearest_triangle(
                volume_bound(&ball_bv::<Rss>(center, radius), &pose_ab),
                &rss,
                &pose_ab,
                f64::INFINITY,
                &mut workspace,
                |_, t, _| Some((ball_triangle(center, radius, t), ())),
            )
            .unwrap()
            .0;
            let found_obb = nearest_triangle(
                volume_bound(&ball_bv::<Obb>(center, radius), &pose_ab),
                &obb,
                &pose_ab,
                f64::INFINITY,
                &mut workspace,
                |_, t, _| Some((ball_triangle(center, radius, t), ())),
            )
            .unwrap()
            .0;
            // With a limit: the same answer when it is within the limit, else nothing or
            // an upper bound above it.
            let limit = rng.random_range(0.0..0.5);
            let limited = nearest_triangle(
                volume_bound(&ball_bv::<Rss>(center, radius), &pose_ab),
                &rss,
                &pose_ab,
                limit,
                &mut workspace,
                // Triangles whose plane alone keeps the ball beyond the threshold are
                // skipped, as the pipeline's walk does.
                |_, t, threshold| {
                    let n = (t.b - t.a).cross(t.c - t.a).normalize_or_zero();
                    let plane_gap = n.dot(center - t.a).abs() - radius;
                    (plane_gap <= threshold).then(|| (ball_triangle(center, radius, t), ()))
                },
            )
            .map(|(d, ())| d);
            if truth <= limit {
                assert_eq!(limited, Some(truth), "case {case}");
            } else {
                assert!(limited.is_none_or(|d| d > limit), "case {case}");
            }
            assert_eq!(found_rss, truth, "case {case}");
            assert_eq!(found_obb, truth, "case {case}");
            if truth < 0.0 {
                penetrating += 1;
            } else {
                apart += 1;
            }
            // The overlap walk finds every triangle the ball reaches.
            let mut reached = Vec::new();
            for_each_overlapping_triangle(
                &ball_bv::<Obb>(center, radius),
                &obb,
                &pose_ab,
                &mut workspace,
                |id, t| {
                    if ball_triangle(center, radius, t) <= 0.0 {
                        reached.push(id);
                    }
                    ControlFlow::Continue(())
                },
            );
            let expected = triangles
                .iter()
                .filter(|t| ball_triangle(center, radius, &t.transformed(&iso)) <= 0.0)
                .count();
            assert_eq!(reached.len(), expected, "case {case}");
        }
        assert!(penetrating > 100 && apart > 100, "{penetrating} / {apart}");
    }
}
