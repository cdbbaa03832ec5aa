//! One frame of collision work over a scene: broad phase, then per candidate pair the best
//! answer the engine has.
//!
//! # Design note: determinism and ordering
//! The same scene and flags give the same report: the broad phase yields pairs sorted by
//! `(a, b)`, each pair is answered independently in that order, and nothing depends on
//! timing. Budgeted (time-critical) traversal joins with issue #7 behind this same seam.
//!
//! # What is exact today
//! Sphere–sphere (closed form) and mesh–mesh (exact BVH distance, meshes as surfaces:
//! intersecting meshes report 0) pairs are exact. Every other pair of shape kinds gets the
//! conservative answer DESIGN §5 prescribes for a truncated traversal at level 0: the
//! distance between the two world boxes (a lower bound), with the boxes' diagonals as error
//! bound, and the report says [`Completeness::Truncated`]. TODO(#5): the narrow phase for
//! every pair of shape kinds replaces that.

use crate::bounding::Aabb;
use crate::broad::{CandidatePair, Proxy, pairs_brute_force};
use crate::math::{DVec3, Pose, conservative_slack};
use crate::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshMeshWorkspace, distance_mesh_mesh,
};
use crate::scene::{Body, BodyId, Scene, Shape};
use std::collections::HashMap;

/// The answer for one close pair, world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairResult {
    /// The smaller body id.
    pub a: u32,
    /// The larger body id.
    pub b: u32,
    /// Signed distance, metres (negative = penetration).
    pub distance: f64,
    /// `|distance − true distance| ≤ error_bound`, metres.
    pub error_bound: f64,
    /// Witness on A, world frame.
    pub point_a: DVec3,
    /// Witness on B, world frame.
    pub point_b: DVec3,
    /// Unit normal from A to B, world frame.
    pub normal: DVec3,
    /// Whether the answer is exact (to `error_bound` rounding) or the conservative box answer.
    pub exact: bool,
}

/// Whether a frame's answers are all exact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Completeness {
    /// Every pair exact.
    Exact,
    /// Some pairs carry a conservative answer from level `level` of their hierarchies.
    Truncated {
        /// The shallowest level any pair stopped at (0 = world boxes).
        level: u32,
    },
}

/// State of [`step`] kept across frames: scratch space (no allocation once grown) and the
/// warm-start cache of every mesh–mesh pair that was a candidate last frame.
#[derive(Debug, Default)]
pub struct PipelineWorkspace {
    proxies: Vec<Proxy>,
    candidates: Vec<CandidatePair>,
    mesh: MeshMeshWorkspace,
    /// Closest triangle pair of each mesh–mesh candidate, for the next frame's first bound.
    /// Pairs that stop being candidates are forgotten; a pair that appears inserts once.
    mesh_caches: HashMap<CandidatePair, DistanceCache>,
}

/// Runs one frame: every pair of bodies within the sum of their margins (filters and
/// static pairs excluded), answered and passed to `sink` in `(a, b)` order.
pub fn step(
    scene: &Scene,
    workspace: &mut PipelineWorkspace,
    mut sink: impl FnMut(&PairResult),
) -> Completeness {
    scene.proxies(&mut workspace.proxies);
    pairs_brute_force(&workspace.proxies, &mut workspace.candidates);
    let mut completeness = Completeness::Exact;
    let candidates = &workspace.candidates;
    workspace
        .mesh_caches
        .retain(|pair, _| candidates.binary_search(pair).is_ok());
    for pair in candidates {
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        let result = answer(
            scene,
            pair,
            a,
            b,
            &mut workspace.mesh,
            &mut workspace.mesh_caches,
        );
        if !result.exact {
            completeness = Completeness::Truncated { level: 0 };
        }
        // A box answer's distance is a lower bound: the pair is reported whenever the true
        // distance may be within the margins (conservative).
        if result.distance <= a.margin + b.margin {
            sink(&result);
        }
    }
    completeness
}

fn body(scene: &Scene, id: u32) -> &Body {
    scene
        .body(BodyId(id))
        .expect("the broad phase reports live bodies")
}

fn shape<'s>(scene: &'s Scene, body: &Body) -> &'s Shape {
    scene
        .shape(body.shape)
        .expect("bodies name registered shapes")
}

fn answer(
    scene: &Scene,
    pair: &CandidatePair,
    a: &Body,
    b: &Body,
    mesh: &mut MeshMeshWorkspace,
    mesh_caches: &mut HashMap<CandidatePair, DistanceCache>,
) -> PairResult {
    match (shape(scene, a), shape(scene, b)) {
        (Shape::Sphere(sa), Shape::Sphere(sb)) => {
            let (ca, cb) = (a.pose.position, b.pose.position);
            let normal = (cb - ca).try_normalize().unwrap_or(DVec3::X);
            PairResult {
                a: pair.a,
                b: pair.b,
                distance: ca.distance(cb) - sa.radius - sb.radius,
                error_bound: conservative_slack(
                    ca.abs().max_element() + cb.abs().max_element() + sa.radius + sb.radius,
                ),
                point_a: ca + normal * sa.radius,
                point_b: cb - normal * sb.radius,
                normal,
                exact: true,
            }
        }
        (Shape::Mesh(ma), Shape::Mesh(mb)) => {
            let pose_ab = Pose::relative(&a.pose, &b.pose);
            let d = distance_mesh_mesh(
                &ma.distance_tree,
                &mb.distance_tree,
                &pose_ab,
                &DistanceParams::EXACT,
                mesh_caches.entry(*pair).or_default(),
                mesh,
            );
            let (point_a, point_b) = (
                a.pose.transform_point(d.point_a),
                a.pose.transform_point(d.point_b),
            );
            PairResult {
                a: pair.a,
                b: pair.b,
                distance: d.distance,
                error_bound: d.error_bound,
                point_a,
                point_b,
                normal: (point_b - point_a).try_normalize().unwrap_or(DVec3::X),
                exact: true,
            }
        }
        _ => box_answer(pair, &a.world_bounds, &b.world_bounds),
    }
}

/// The conservative answer from two world boxes: their distance (a lower bound of the
/// shapes' distance) with the sum of their diagonals as error bound.
fn box_answer(pair: &CandidatePair, a: &Aabb, b: &Aabb) -> PairResult {
    let point_a = b.center().clamp(a.min, a.max);
    let point_b = point_a.clamp(b.min, b.max);
    let gap = (a.min - b.max).max(b.min - a.max).max(DVec3::ZERO);
    PairResult {
        a: pair.a,
        b: pair.b,
        distance: gap.length(),
        error_bound: (a.max - a.min).length() + (b.max - b.min).length(),
        point_a,
        point_b,
        normal: (b.center() - a.center())
            .try_normalize()
            .unwrap_or(DVec3::X),
        exact: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cuboid, Sphere};
    use crate::scene::{BodyDesc, CollisionFilter, Motion, SceneLimits, ShapeId};
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    fn add(scene: &mut Scene, shape: Shape, at: DVec3, margin: f64) -> BodyId {
        let shape = scene.register_shape(shape).unwrap();
        let desc = BodyDesc {
            shape,
            pose: Pose::from_translation(at),
            motion: Motion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: Some(margin),
        };
        scene.add_body(&desc).unwrap()
    }

    #[test]
    fn sphere_scenes_report_exactly_the_pairs_within_their_margins() {
        let mut rng = rng(71);
        let (mut reported, mut skipped) = (0, 0);
        for case in 0..100 {
            let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
            let spheres: Vec<(DVec3, f64, f64)> = (0..rng.random_range(2..40))
                .map(|_| {
                    (
                        point_in_cube(&mut rng, 1.2),
                        rng.random_range(0.05..0.6),
                        rng.random_range(0.0..0.3),
                    )
                })
                .collect();
            for &(c, r, m) in &spheres {
                add(&mut scene, Shape::Sphere(Sphere::new(r)), c, m);
            }
            let mut results = Vec::new();
            let completeness = step(&scene, &mut PipelineWorkspace::default(), |r| {
                results.push(*r)
            });
            assert_eq!(completeness, Completeness::Exact);
            assert!(
                results
                    .windows(2)
                    .all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b)),
                "case {case}: ordered"
            );
            for i in 0..spheres.len() {
                for j in i + 1..spheres.len() {
                    let ((ci, ri, mi), (cj, rj, mj)) = (spheres[i], spheres[j]);
                    let truth = ci.distance(cj) - ri - rj;
                    let found = results.iter().find(|r| (r.a, r.b) == (i as u32, j as u32));
                    if truth <= mi + mj {
                        let r = found.unwrap_or_else(|| panic!("case {case}: pair {i},{j} missed"));
                        assert!(
                            (r.distance - truth).abs() <= r.error_bound.max(1e-12),
                            "case {case}"
                        );
                        assert!(
                            (r.normal.length() - 1.0).abs() < 1e-12 && r.normal.dot(cj - ci) >= 0.0
                        );
                        assert!(
                            (r.point_a.distance(ci) - ri).abs() < 1e-9
                                && (r.point_b.distance(cj) - rj).abs() < 1e-9
                        );
                        reported += 1;
                    } else {
                        assert!(found.is_none(), "case {case}: far pair {i},{j} reported");
                        skipped += 1;
                    }
                }
            }
        }
        assert!(
            reported > 500 && skipped > 500,
            "reported {reported}, skipped {skipped}"
        );
    }

    #[test]
    fn mesh_pairs_warm_started_across_frames_keep_the_cold_exact_distance() {
        use crate::scene::MeshShape;
        use crate::test_support::{meshes, rotation};
        use std::sync::Arc;
        let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(1.0, 0.25, 24, 12))));
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let a = add(&mut scene, torus.clone(), DVec3::ZERO, 0.5);
        let b = add(&mut scene, torus, DVec3::X, 0.5);
        let (Some(Shape::Mesh(mesh)), mut rng) = (scene.shape(ShapeId(0)).cloned(), rng(73)) else {
            unreachable!()
        };
        let mut workspace = PipelineWorkspace::default();
        let (mut touching, mut apart) = (0, 0);
        for frame in 0..60 {
            let pose_b = Pose::new(point_in_cube(&mut rng, 1.6), rotation(&mut rng));
            scene.set_pose(b, pose_b).unwrap();
            let mut results = Vec::new();
            step(&scene, &mut workspace, |r| results.push(*r));
            let cold = distance_mesh_mesh(
                &mesh.distance_tree,
                &mesh.distance_tree,
                &Pose::relative(&scene.body(a).unwrap().pose, &pose_b),
                &DistanceParams::EXACT,
                &mut DistanceCache::new(),
                &mut MeshMeshWorkspace::new(),
            );
            match results.as_slice() {
                [r] => {
                    assert_eq!(r.distance, cold.distance, "frame {frame}");
                    touching += usize::from(r.distance == 0.0);
                }
                [] => {
                    assert!(
                        cold.distance > 1.0,
                        "frame {frame}: missed at {}",
                        cold.distance
                    );
                    apart += 1;
                }
                more => panic!("frame {frame}: {} results for one pair", more.len()),
            }
        }
        assert!(
            touching > 5 && apart + (60 - touching) > 5,
            "touching {touching}, apart {apart}"
        );
    }

    #[test]
    fn pairs_without_an_exact_narrow_phase_get_a_conservative_box_answer() {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let a = add(
            &mut scene,
            Shape::Sphere(Sphere::new(0.5)),
            DVec3::ZERO,
            0.1,
        );
        let b = add(
            &mut scene,
            Shape::Cuboid(Cuboid::new(DVec3::splat(0.5))),
            DVec3::new(1.05, 0.3, 0.0),
            0.1,
        );
        let mut results = Vec::new();
        let completeness = step(&scene, &mut PipelineWorkspace::default(), |r| {
            results.push(*r)
        });
        assert_eq!(completeness, Completeness::Truncated { level: 0 });
        assert_eq!(results.len(), 1);
        let r = results[0];
        assert_eq!((r.a, r.b, r.exact), (a.0, b.0, false));
        // True distance: sphere centre to the box face x = 0.55, minus the radius.
        let truth = 0.55 - 0.5;
        assert!(r.distance <= truth && (r.distance - truth).abs() <= r.error_bound);
    }
}
