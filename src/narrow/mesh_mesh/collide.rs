//! Collision queries: does any triangle pair intersect, and which ones do.

use super::leaf_triangle::LeafTriangles;
use super::{
    FALLBACK_NORMAL, MeshMeshWorkspace, TriangleContact, clock_allows_leaf_pair,
    for_each_triangle_pair,
};
use crate::bounding::BoundingVolume;
use crate::budget::WorkClock;
use crate::bvh::Bvh;
use crate::bvh::tandem::for_each_leaf_pair;
use crate::math::Pose;
use crate::narrow::{intersection_segment_triangle_triangle, intersects_triangle_triangle};
use std::ops::ControlFlow;

/// Whether any triangle of `a` intersects any triangle of `b` placed at `pose_ab` (closed
/// triangles: touching counts). Stops at the first intersecting pair.
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
#[must_use]
pub fn intersects_mesh_mesh<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    workspace: &mut MeshMeshWorkspace,
) -> bool {
    WorkClock::run_to_end(|clock| intersects_mesh_mesh_within(a, b, pose_ab, workspace, clock))
}

/// [`intersects_mesh_mesh`], polling `clock` before each pair of leaves
/// ([`TRIANGLE_PAIR_WORK`] units per triangle pair): `None` when the clock stopped it
/// before it found an intersecting pair (the meshes may then intersect or not).
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
#[must_use]
pub fn intersects_mesh_mesh_within<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    workspace: &mut MeshMeshWorkspace,
    clock: &mut WorkClock,
) -> Option<bool> {
    let iso = pose_ab.to_isometry();
    let leaf = LeafTriangles { a, b, iso: &iso };
    let mut stopped = false;
    let flow = for_each_leaf_pair(
        a,
        b,
        &mut workspace.pairs,
        |x, y| leaf.overlaps(x, y),
        |la, lb| {
            if !clock_allows_leaf_pair(clock, (a, b), [la, lb], TRIANGLE_PAIR_WORK) {
                stopped = true;
                return ControlFlow::Break(());
            }
            for_each_triangle_pair(a, b, [la, lb], &iso, |_, tri_a, _, tri_b| {
                if intersects_triangle_triangle(tri_a, tri_b) {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
        },
    );
    (!stopped).then_some(flow.is_break())
}

/// Reports every intersecting triangle pair of `a` and `b` placed at `pose_ab` to `sink`, in
/// A's frame, until `sink` returns `Break`. Each pair is reported once; the order is the
/// traversal's (deterministic for the same input).
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent (the sink may allocate).
pub fn contacts_mesh_mesh<B, S>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    workspace: &mut MeshMeshWorkspace,
    sink: S,
) where
    B: BoundingVolume,
    S: FnMut(TriangleContact) -> ControlFlow<()>,
{
    let finished =
        contacts_mesh_mesh_within(a, b, pose_ab, workspace, &mut WorkClock::default(), sink);
    debug_assert!(finished, "an unlimited clock never stops");
}

/// Units of [`WorkClock`] work one triangle pair's intersection test counts for.
pub const TRIANGLE_PAIR_WORK: u64 = 2;

/// [`contacts_mesh_mesh`], polling `clock` before each pair of leaves
/// ([`TRIANGLE_PAIR_WORK`] units per triangle pair); returns `false` when the clock stopped
/// it, with the pairs reported so far (a subset of the intersecting ones, each real).
pub fn contacts_mesh_mesh_within<B, S>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    workspace: &mut MeshMeshWorkspace,
    clock: &mut WorkClock,
    mut sink: S,
) -> bool
where
    B: BoundingVolume,
    S: FnMut(TriangleContact) -> ControlFlow<()>,
{
    let iso = pose_ab.to_isometry();
    let leaf = LeafTriangles { a, b, iso: &iso };
    let mut stopped = false;
    let _ = for_each_leaf_pair(
        a,
        b,
        &mut workspace.pairs,
        |x, y| leaf.overlaps(x, y),
        |la, lb| {
            if !clock_allows_leaf_pair(clock, (a, b), [la, lb], TRIANGLE_PAIR_WORK) {
                stopped = true;
                return ControlFlow::Break(());
            }
            for_each_triangle_pair(a, b, [la, lb], &iso, |sa, tri_a, sb, tri_b| {
                let Some((p, q)) = intersection_segment_triangle_triangle(tri_a, tri_b) else {
                    return ControlFlow::Continue(());
                };
                let normal = tri_a
                    .normal()
                    .or_else(|| tri_b.normal().map(|n| -n))
                    .unwrap_or(FALLBACK_NORMAL);
                sink(TriangleContact {
                    triangles: [a.triangle_id(sa), b.triangle_id(sb)],
                    segment: [p, q],
                    point: p.midpoint(q),
                    normal,
                })
            })
        },
    );
    !stopped
}
