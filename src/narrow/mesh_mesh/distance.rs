//! Distance queries: the smallest triangle–triangle distance, and "within distance d?".

use super::leaf_triangle::LeafTriangles;
use super::{
    DistanceCache, DistanceParams, MeshDistance, MeshMeshWorkspace, clock_allows_leaf_pair,
    for_each_triangle_pair,
};
use crate::bounding::BoundingVolume;
use crate::budget::WorkClock;
use crate::bvh::Bvh;
use crate::bvh::tandem::{for_each_leaf_pair, nearest_leaf_pairs};
use crate::math::{Isometry, Pose, conservative_slack};
use crate::narrow::{TriangleDistance, distance_triangle_triangle};
use std::ops::ControlFlow;

/// The smallest distance between the triangles of `a` and of `b` placed at `pose_ab`, with
/// witness points in A's frame, by branch and bound over the two trees.
///
/// Of triangle pairs at the same smallest distance (a closest point on an edge or vertex
/// that several triangles share), the one named first by [`precedes_in_ties`] is reported, so the
/// witnesses do not depend on the order of the search (nor on the tree type); intersecting
/// meshes report the first intersecting pair found.
///
/// With [`DistanceParams::EXACT`] the distance is the brute-force minimum over all
/// triangle pairs (to rounding, stated in `error_bound`); looser params let the search stop
/// once nothing untried can improve the answer by more than the tolerance. `cache` holds the
/// last closest pair of this mesh pair: its distance under the new pose is the first bound
/// (warm start), and the new closest pair is stored back.
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
pub fn distance_mesh_mesh<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    params: &DistanceParams,
    cache: &mut DistanceCache,
    workspace: &mut MeshMeshWorkspace,
) -> MeshDistance {
    let mut unlimited = WorkClock::default();
    distance_mesh_mesh_within(a, b, pose_ab, params, cache, workspace, &mut unlimited)
}

/// [`distance_mesh_mesh`], polling `clock` before each step of the search
/// ([`WORK_PER_EXPANSION`](crate::bvh::tandem::WORK_PER_EXPANSION) units). When the clock stops it, the answer is the closest
/// triangle pair found so far, an upper bound of the distance, with an error bound that
/// reaches down to the search's lower bound (`distance − error_bound ≤ true distance ≤
/// distance`), and `clock.stopped()` says so. More work never loosens it.
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
pub fn distance_mesh_mesh_within<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    params: &DistanceParams,
    cache: &mut DistanceCache,
    workspace: &mut MeshMeshWorkspace,
    clock: &mut WorkClock,
) -> MeshDistance {
    let iso = pose_ab.to_isometry();
    let leaf = LeafTriangles { a, b, iso: &iso };
    let (ta, tb) = (a.triangles(), b.triangles());
    let pair_distance =
        |sa: usize, sb: usize| distance_triangle_triangle(&ta[sa], &tb[sb].transformed(&iso));

    // Start from the cached pair when it still names triangles of these meshes, else from
    // the first slots: any pair gives a valid first upper bound.
    let [start_a, start_b] = match cache.slots {
        Some([sa, sb]) if (sa as usize) < ta.len() && (sb as usize) < tb.len() => {
            [sa as usize, sb as usize]
        }
        _ => [0, 0],
    };
    let mut closest = (pair_distance(start_a, start_b), [start_a, start_b]);
    let nearest = nearest_leaf_pairs(
        a,
        b,
        &mut workspace.ranked,
        closest.0.distance,
        (
            |x, y, limit| leaf.distance_lower_bound_within(x, y, limit),
            |bound, best| params.can_skip(bound, best),
        ),
        clock,
        |la, lb| {
            for sb in b.nodes()[lb].slots() {
                for sa in a.nodes()[la].slots() {
                    let d = pair_distance(sa, sb);
                    let [ca, cb] = closest.1;
                    if d.distance < closest.0.distance
                        || (d.distance == closest.0.distance
                            && precedes_in_ties(
                                [a.triangle_id(sa), b.triangle_id(sb)],
                                [a.triangle_id(ca), b.triangle_id(cb)],
                            ))
                    {
                        closest = (d, [sa, sb]);
                    }
                }
            }
            closest.0.distance
        },
    );
    let (
        TriangleDistance {
            distance,
            point_a,
            point_b,
        },
        [sa, sb],
    ) = closest;
    debug_assert_eq!(nearest.best, distance);
    cache.slots = Some([sa as u32, sb as u32]);
    // Stopped, the untried pairs may be closer, down to the search's lower bound.
    let unsearched = (distance - nearest.lower_bound).max(0.0);
    MeshDistance {
        distance,
        point_a,
        point_b,
        triangles: [a.triangle_id(sa), b.triangle_id(sb)],
        error_bound: params.abs_err.max(params.rel_err * distance)
            + unsearched
            + rounding_bound(a, b, &iso),
    }
}

/// Whether some triangle of `a` and some triangle of `b` placed at `pose_ab` are at most
/// `max_distance` metres apart (`max_distance ≥ 0`; `0` is [`intersects_mesh_mesh`](super::intersects_mesh_mesh)
/// with distances instead of exact predicates). Stops at the first such pair.
/// [`proximity_mesh_mesh`] answers the same question with a distance bound when apart.
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
#[must_use]
pub fn within_distance_mesh_mesh<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    max_distance: f64,
    workspace: &mut MeshMeshWorkspace,
) -> bool {
    proximity_mesh_mesh(a, b, pose_ab, max_distance, workspace) == Proximity::Within
}

/// The answer of [`proximity_mesh_mesh`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Proximity {
    /// Some triangle pair is within the distance asked.
    Within,
    /// Every triangle pair is farther apart than the distance asked, and at least
    /// `lower_bound` metres apart (`lower_bound` is above the distance asked).
    Apart {
        /// A lower bound of the true distance between the meshes, metres: the smallest of
        /// the bounds of the node pairs the search dropped and of the triangle distances it
        /// computed (less their rounding), so as loose as the search was allowed to be.
        lower_bound: f64,
    },
}

/// [`within_distance_mesh_mesh`], which stops at the first triangle pair within
/// `max_distance`; when there is none, also a lower bound of the distance (see
/// [`Proximity::Apart`]). The bound is what lets a pair proven apart stay proven while it
/// moves less than its slack (the pipeline's kept separations).
///
/// The bound is only as tight as the search needed: node pairs are dropped as soon as
/// their (cheapest) bound exceeds `max_distance`. Proving more (dropping them only beyond
/// `max_distance` plus a few frames of the pair's motion, so that a separation lasts) was
/// measured on `examples/time_vs_error --scene robot-chain` and not kept: exact frames took
/// 1.2–12× as long for it, more than the frames it saved.
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
#[must_use]
pub fn proximity_mesh_mesh<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    max_distance: f64,
    workspace: &mut MeshMeshWorkspace,
) -> Proximity {
    WorkClock::run_to_end(|clock| {
        proximity_mesh_mesh_within(a, b, pose_ab, max_distance, workspace, clock)
    })
}

/// Units of [`WorkClock`] work one triangle pair's distance counts for (a few closed-form
/// pairs' worth).
pub const TRIANGLE_DISTANCE_WORK: u64 = 4;

/// [`proximity_mesh_mesh`], polling `clock` before each pair of leaves
/// ([`TRIANGLE_DISTANCE_WORK`] units per triangle pair): `None` when the clock stopped it
/// before it found a pair within `max_distance` or ruled them all out.
///
/// # Allocation
/// None once `workspace` has grown to the deepest descent.
#[must_use]
pub fn proximity_mesh_mesh_within<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    max_distance: f64,
    workspace: &mut MeshMeshWorkspace,
    clock: &mut WorkClock,
) -> Option<Proximity> {
    let iso = pose_ab.to_isometry();
    let leaf = LeafTriangles { a, b, iso: &iso };
    let rounding = rounding_bound(a, b, &iso);
    let mut stopped = false;
    // The smallest bound of everything ruled out so far (a `Cell`: both closures lower it).
    let floor = std::cell::Cell::new(f64::INFINITY);
    let flow = for_each_leaf_pair(
        a,
        b,
        &mut workspace.pairs,
        |x, y| {
            let bound = leaf.distance_lower_bound_within(x, y, max_distance);
            if bound > max_distance {
                floor.set(floor.get().min(bound));
                return false;
            }
            true
        },
        |la, lb| {
            if !clock_allows_leaf_pair(clock, (a, b), [la, lb], TRIANGLE_DISTANCE_WORK) {
                stopped = true;
                return ControlFlow::Break(());
            }
            for_each_triangle_pair(a, b, [la, lb], &iso, |_, tri_a, _, tri_b| {
                let distance = distance_triangle_triangle(tri_a, tri_b).distance;
                if distance <= max_distance {
                    ControlFlow::Break(())
                } else {
                    floor.set(floor.get().min(distance - rounding));
                    ControlFlow::Continue(())
                }
            })
        },
    );
    if stopped {
        None
    } else if flow.is_break() {
        Some(Proximity::Within)
    } else {
        Some(Proximity::Apart {
            lower_bound: floor.get(),
        })
    }
}

/// Whether the triangle pair `cache` remembers (the last closest pair of a distance search
/// over these trees) is within `max_distance` at `pose_ab`: then some pair is, and
/// [`proximity_mesh_mesh_within`] would answer [`Proximity::Within`] (it measures each pair
/// with the same function, placed the same way), for the price of one triangle pair.
/// `false` without a remembered pair, or one that names no triangle of these trees.
#[must_use]
pub fn cached_pair_within<B: BoundingVolume>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    pose_ab: &Pose,
    cache: &DistanceCache,
    max_distance: f64,
) -> bool {
    let (ta, tb) = (a.triangles(), b.triangles());
    match cache.slots {
        Some([sa, sb]) if (sa as usize) < ta.len() && (sb as usize) < tb.len() => {
            let tri_b = tb[sb as usize].transformed(&pose_ab.to_isometry());
            distance_triangle_triangle(&ta[sa as usize], &tri_b).distance <= max_distance
        }
        _ => false,
    }
}

/// Rounding error of a triangle–triangle distance between these meshes at this pose: a few
/// ulps of the largest coordinate involved (measured on the root volumes, so it depends on
/// the volume type a little; the pipeline states it from the RSS trees on every path).
#[must_use]
pub fn rounding_bound<B: BoundingVolume>(a: &Bvh<B>, b: &Bvh<B>, iso: &Isometry) -> f64 {
    let reach = |bv: &B| bv.center().abs().max_element() + bv.size();
    conservative_slack(
        reach(a.root_bv()) + reach(b.root_bv()) + iso.translation.abs().max_element(),
    )
}

/// Whether the triangle pair `x` (triangle ids of A, of B) comes before `y` in the order
/// that breaks ties between triangle pairs at the same distance: by A's id, then B's.
/// Every exact distance query breaks ties this way (this one and the budgeted frontier),
/// so they report the same witnesses.
#[must_use]
#[inline]
pub fn precedes_in_ties(x: [u32; 2], y: [u32; 2]) -> bool {
    x < y
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::{Obb, Rss};
    use crate::budget::Unlimited;
    use crate::bvh::BuildParams;
    use crate::geometry::Triangle;
    use crate::math::DVec3;
    use crate::narrow::mesh_mesh::frontier::{FrontierPair, FrontierWorkspace, query_frontier};
    use crate::test_support::{meshes, point_in_cube, rng, rotation};

    /// A flat fan of four triangles around the origin, and a triangle whose lowest vertex is
    /// 1 m above the origin: its closest point is the vertex every fan triangle shares, so
    /// the four triangle pairs tie exactly.
    fn tied_fan() -> (Vec<Triangle>, Vec<Triangle>) {
        let rim = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y];
        let fan = (0..4)
            .map(|i| Triangle::new(DVec3::ZERO, rim[i], rim[(i + 1) % 4]))
            .collect();
        let above = vec![Triangle::new(
            DVec3::Z,
            DVec3::new(0.5, 0.5, 2.0),
            DVec3::new(-0.5, 0.5, 2.0),
        )];
        (fan, above)
    }

    /// Whichever tied pair a search meets first (here: whichever it is warm-started from),
    /// every exact distance query reports the one [`precedes_in_ties`] names first, with
    /// the same witnesses: `distance_mesh_mesh` on box and rectangle-swept-sphere trees,
    /// and the budgeted frontier seeded with each tied pair.
    #[test]
    fn tied_closest_pairs_are_reported_the_same_whatever_the_search_order() {
        let (fan, above) = tied_fan();
        let distances: Vec<f64> = fan
            .iter()
            .map(|t| crate::narrow::distance_triangle_triangle(t, &above[0]).distance)
            .collect();
        assert!(distances.iter().all(|&d| d == 1.0), "{distances:?}");
        let expected = {
            let d = crate::narrow::distance_triangle_triangle(&fan[0], &above[0]);
            (d.point_a, d.point_b, [0, 0])
        };
        fn check<B: BoundingVolume>(
            fan: &[Triangle],
            above: &[Triangle],
            expected: (DVec3, DVec3, [u32; 2]),
        ) {
            let params = BuildParams::MEDIAN;
            let (a, b) = (
                Bvh::<B>::from_triangles(fan, &params),
                Bvh::<B>::from_triangles(above, &params),
            );
            for start in 0..fan.len() {
                let slot = a.slot_of(start as u32).expect("a triangle of the fan");
                let mut cache = DistanceCache {
                    slots: Some([slot as u32, 0]),
                };
                let d = distance_mesh_mesh(
                    &a,
                    &b,
                    &Pose::IDENTITY,
                    &DistanceParams::EXACT,
                    &mut cache,
                    &mut MeshMeshWorkspace::new(),
                );
                assert_eq!(d.distance, 1.0);
                assert_eq!(
                    (d.point_a, d.point_b, d.triangles),
                    expected,
                    "from {start}"
                );
                let pair = FrontierPair {
                    a: &a,
                    b: &b,
                    pose_ab: Isometry::IDENTITY,
                    threshold: 2.0,
                    seed: Some([start as u32, 0]),
                };
                let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
                assert!(query_frontier(&[pair], &mut Unlimited, &mut ws, &mut out));
                let w = out[0].witnesses.expect("within the threshold");
                assert_eq!(
                    (w.point_a, w.point_b, w.triangles),
                    expected,
                    "seed {start}"
                );
            }
        }
        check::<Obb>(&fan, &above, expected);
        check::<Rss>(&fan, &above, expected);
    }

    /// Two tori moving coherently, a distance search each frame keeping its cache: whenever
    /// the remembered pair is within the limit at the next pose, the proximity search
    /// answers "within" too (the pipeline skips it then), and the remembered pair is within
    /// on many frames and not on many others.
    #[test]
    fn a_cached_pair_within_the_limit_means_the_proximity_search_says_within() {
        let torus = meshes::torus(0.6, 0.15, 20, 8);
        let tree = Bvh::<Rss>::from_mesh(&torus, &BuildParams::BINNED_SAH);
        let mut rng = rng(2024);
        let mut workspace = MeshMeshWorkspace::default();
        let (mut within, mut not) = (0, 0);
        for run in 0..40 {
            let mut cache = DistanceCache::new();
            let mut pose = Pose::new(point_in_cube(&mut rng, 0.8), rotation(&mut rng));
            for frame in 0..50 {
                let limit = 0.05;
                if cached_pair_within(&tree, &tree, &pose, &cache, limit) {
                    within += 1;
                    let proximity = proximity_mesh_mesh(&tree, &tree, &pose, limit, &mut workspace);
                    assert_eq!(proximity, Proximity::Within, "run {run} frame {frame}");
                } else {
                    not += 1;
                }
                let _ = distance_mesh_mesh(
                    &tree,
                    &tree,
                    &pose,
                    &DistanceParams::EXACT,
                    &mut cache,
                    &mut workspace,
                );
                pose = Pose::new(
                    (pose.position + point_in_cube(&mut rng, 0.03)).clamp_length_max(1.0),
                    rotation(&mut rng).slerp(pose.rotation, 0.97),
                );
            }
        }
        assert!(within > 300 && not > 200, "{within} / {not}");
    }
}
