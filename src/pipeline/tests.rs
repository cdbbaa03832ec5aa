use super::*;
use crate::bounding::Aabb;
use crate::budget::{Stop, WorkClock};
use crate::geometry::{Capsule, Cuboid, Cylinder, Sphere};
use crate::math::Pose;
use crate::narrow::MeshShape;
use crate::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshMeshWorkspace, contacts_mesh_mesh, distance_mesh_mesh,
    intersects_mesh_mesh,
};
use crate::narrow::{MANIFOLD_POINTS, reduce_manifold};
use crate::scene::{BodyDesc, CollisionFilter, Motion, SceneLimits};
use crate::test_support::{meshes, point_in_cube, rng, rotation};
use rand::Rng;
use std::ops::ControlFlow;
use std::sync::Arc;
use std::time::{Duration, Instant};

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

/// Every non-empty combination of the four flags.
fn every_query() -> impl Iterator<Item = Query> {
    (1u32..16).map(|bits| Query {
        overlap: bits & 1 != 0,
        close: bits & 2 != 0,
        distance: bits & 4 != 0,
        contacts: bits & 8 != 0,
        toi: false,
    })
}

fn run(scene: &Scene, query: Query, workspace: &mut PipelineWorkspace) -> FrameResults {
    let mut results = FrameResults::default();
    let report = step(scene, query, workspace, &mut results);
    assert_eq!(report.pairs as usize, results.pairs.len());
    assert_eq!(report.contacts as usize, results.contacts.len());
    assert!(report.candidates >= report.pairs);
    assert_links(&results);
    results
}

/// Pairs in `(a, b)` order; each pair's contacts are exactly the ones that name it, in
/// one run, in pair order, at most `MANIFOLD_POINTS`.
fn assert_links(results: &FrameResults) {
    assert!(
        results
            .pairs
            .windows(2)
            .all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b))
    );
    let mut next = 0;
    for (i, p) in results.pairs.iter().enumerate() {
        assert!(p.contact_count as usize <= MANIFOLD_POINTS);
        if p.contact_count == 0 {
            assert_eq!(p.first_contact, 0);
            continue;
        }
        assert_eq!(p.first_contact as usize, next);
        next += p.contact_count as usize;
        for c in &results.contacts[p.first_contact as usize..next] {
            assert_eq!(c.pair as usize, i);
        }
    }
    assert_eq!(next, results.contacts.len());
}

#[test]
fn sphere_scenes_report_exactly_what_each_query_asks_against_the_closed_form() {
    let mut rng = rng(71);
    let mut seen = [0usize; 4]; // close, far-but-candidate, touching, contacts
    for case in 0..60 {
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
        let mut workspace = PipelineWorkspace::default();
        for query in every_query() {
            let results = run(&scene, query, &mut workspace);
            for i in 0..spheres.len() {
                for j in i + 1..spheres.len() {
                    let ((ci, ri, mi), (cj, rj, mj)) = (spheres[i], spheres[j]);
                    let truth = ci.distance(cj) - ri - rj;
                    // The broad phase's candidates: margin-grown boxes overlap.
                    let reach = DVec3::splat(1.0);
                    let candidate =
                        ((ci - cj).abs() - (ri + mi + rj + mj) * reach).max_element() <= 0.0;
                    let wanted = (query.distance && candidate)
                        || (query.close && truth <= mi + mj)
                        || ((query.overlap || query.contacts) && truth <= 0.0);
                    let found = results
                        .pairs
                        .iter()
                        .find(|r| (r.a, r.b) == (i as u32, j as u32));
                    let Some(r) = found else {
                        assert!(!wanted, "case {case} {query:?}: pair {i},{j} missed");
                        continue;
                    };
                    assert!(wanted, "case {case} {query:?}: pair {i},{j} not asked");
                    assert!((r.distance - truth).abs() <= r.error_bound.max(1e-12));
                    assert!(
                        (r.normal.length() - 1.0).abs() < 1e-12 && r.normal.dot(cj - ci) >= 0.0
                    );
                    assert!(
                        (r.point_a.distance(ci) - ri).abs() < 1e-9
                            && (r.point_b.distance(cj) - rj).abs() < 1e-9
                    );
                    if query.contacts && truth <= 0.0 {
                        assert_eq!(r.contact_count, 1);
                        let c = results.contacts[r.first_contact as usize];
                        assert_eq!(
                            (c.point_a, c.point_b, c.normal),
                            (r.point_a, r.point_b, r.normal)
                        );
                        assert_eq!(c.distance, r.distance);
                        assert!(c.distance <= 0.0);
                        seen[3] += 1;
                    } else {
                        assert_eq!(r.contact_count, 0);
                    }
                    seen[0] += usize::from(truth <= mi + mj);
                    seen[1] += usize::from(truth > mi + mj);
                    seen[2] += usize::from(truth <= 0.0);
                }
            }
        }
    }
    assert!(seen.iter().all(|&n| n > 500), "seen {seen:?}");
}

fn torus_scene() -> (Scene, BodyId, BodyId, Arc<MeshShape>) {
    let torus = Arc::new(MeshShape::new(meshes::torus(1.0, 0.25, 24, 12)));
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let a = add(&mut scene, Shape::Mesh(torus.clone()), DVec3::ZERO, 0.5);
    let b = add(&mut scene, Shape::Mesh(torus.clone()), DVec3::X, 0.5);
    (scene, a, b, torus)
}

/// Tori and spheres moving coherently: a workspace with a worker pool gives exactly the
/// results of one without, frame after frame (warm starts included), for every query.
#[test]
fn the_worker_pool_changes_nothing_but_who_answers() {
    let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.6, 0.15, 20, 8))));
    let shapes: Vec<Shape> = (0..10)
        .map(|i| {
            if i % 3 == 2 {
                Shape::Sphere(Sphere::new(0.3))
            } else {
                torus.clone()
            }
        })
        .collect();
    let (pooled, contact_frames) = compare_with_pool(&shapes, 1.5, 79);
    assert!(
        pooled > 200 && contact_frames > 10,
        "pairs through the pool {pooled}, frames with contacts {contact_frames}"
    );
}

/// The same with two tori among many convex shapes: the pool takes the convex–mesh walks
/// (more than [`MIN_PARALLEL_WALKS`] a frame, with fewer than [`MIN_PARALLEL_MESH_PAIRS`]
/// mesh pairs), and the results, contacts and paths are those of one thread.
#[test]
fn the_worker_pool_takes_convex_mesh_walks_and_changes_nothing() {
    let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.6, 0.15, 20, 8))));
    let mut shapes = vec![torus.clone(), torus];
    for i in 0..40 {
        shapes.push(match i % 4 {
            0 => Shape::Sphere(Sphere::new(0.2)),
            1 => Shape::Cuboid(Cuboid::new(DVec3::new(0.2, 0.1, 0.15))),
            2 => Shape::Capsule(Capsule::new(0.15, 0.1)),
            _ => Shape::Cylinder(Cylinder::new(0.1, 0.15)),
        });
    }
    let (pooled, contact_frames) = compare_with_pool(&shapes, 1.0, 83);
    assert!(
        pooled > 120 * MIN_PARALLEL_WALKS && contact_frames > 30,
        "pairs through the pool {pooled}, frames with contacts {contact_frames}"
    );
}

/// Bodies of `shapes` in a cube of half side `half`, moved coherently for 120 frames and
/// answered with and without a worker pool of 2, every query in turn: identical results,
/// contacts and reports. Returns the pairs the pool answered and the frames with contacts.
fn compare_with_pool(shapes: &[Shape], half: f64, seed: u64) -> (usize, usize) {
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let mut rng = rng(seed);
    let bodies: Vec<BodyId> = shapes
        .iter()
        .map(|shape| {
            add(
                &mut scene,
                shape.clone(),
                point_in_cube(&mut rng, half),
                0.2,
            )
        })
        .collect();
    let pool = Arc::new(WorkerPool::new(2));
    let queries = [
        Query::CLOSE.union(Query::CONTACTS),
        Query::DISTANCE,
        Query::OVERLAP,
    ];
    let (mut serial, mut parallel) = (
        PipelineWorkspace::default(),
        PipelineWorkspace::with_workers(pool),
    );
    let (mut expected, mut found) = (FrameResults::default(), FrameResults::default());
    let (mut pooled, mut contact_frames) = (0, 0);
    for frame in 0..120 {
        for &body in &bodies {
            let pose = scene.body(body).unwrap().pose;
            let moved = Pose::new(
                (pose.position + point_in_cube(&mut rng, 0.08)).clamp_length_max(half * 1.2),
                rotation(&mut rng).slerp(pose.rotation, 0.9),
            );
            scene.set_pose(body, moved).unwrap();
        }
        let query = queries[frame % queries.len()];
        let a = step(&scene, query, &mut serial, &mut expected);
        let b = step(&scene, query, &mut parallel, &mut found);
        assert_same_frame((&a, &expected), (&b, &found), frame);
        pooled += parallel.outcomes.len();
        contact_frames += usize::from(!found.contacts.is_empty());
    }
    (pooled, contact_frames)
}

/// Two workspaces' answers to the same frame `frame` (its report and results each) are
/// the same records, contacts, completeness, counts and paths.
fn assert_same_frame(
    (a, expected): (&StepReport, &FrameResults),
    (b, found): (&StepReport, &FrameResults),
    frame: usize,
) {
    assert_eq!(found.pairs, expected.pairs, "frame {frame}");
    assert_eq!(found.contacts, expected.contacts, "frame {frame}");
    assert_eq!(
        (a.completeness, a.candidates, a.pairs, a.contacts, a.paths),
        (b.completeness, b.candidates, b.pairs, b.contacts, b.paths),
        "frame {frame}"
    );
}

/// Moves every body of `scene` by up to 0.1 m per axis, kept within 1.4 m of the origin,
/// and turns it to a random orientation.
fn shake(scene: &mut Scene, rng: &mut crate::test_support::TestRng) {
    let ids: Vec<BodyId> = scene.bodies().map(|(id, _)| id).collect();
    for id in ids {
        let pose = scene.body(id).unwrap().pose;
        let moved = (pose.position + point_in_cube(rng, 0.1)).clamp_length_max(1.4);
        scene.set_pose(id, Pose::new(moved, rotation(rng))).unwrap();
    }
}

/// A frame abandoned from its start (its owner gone) is conservative, never wrong: every
/// pair the exact frame reports is reported, at a distance no greater (a lower bound, within
/// its error bound), and a pair it calls exact has the exact answer; on the pool or not.
/// A flag never raised changes nothing.
#[test]
fn an_abandoned_frame_answers_conservatively_and_misses_nothing() {
    let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.6, 0.15, 20, 8))));
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let mut rng = rng(131);
    for i in 0..12 {
        let shape = match i % 4 {
            0 => Shape::Sphere(Sphere::new(0.3)),
            1 => Shape::Cuboid(Cuboid::new(DVec3::new(0.3, 0.2, 0.4))),
            _ => torus.clone(),
        };
        add(&mut scene, shape, point_in_cube(&mut rng, 1.2), 0.2);
    }
    let raised = Abandon::new();
    raised.raise();
    let pool = Arc::new(WorkerPool::new(2));
    let mut exact = PipelineWorkspace::default();
    let mut never_raised = PipelineWorkspace::default().abandon_on(Abandon::new());
    let mut abandoned = [
        PipelineWorkspace::default().abandon_on(raised.clone()),
        PipelineWorkspace::with_workers(pool).abandon_on(raised),
    ];
    let queries = [
        Query::CLOSE.union(Query::CONTACTS),
        Query::DISTANCE,
        Query::OVERLAP,
    ];
    let (mut truncated_frames, mut approximate_pairs, mut touching) = (0, 0, 0);
    for frame in 0..60 {
        shake(&mut scene, &mut rng);
        let query = queries[frame % queries.len()];
        let truth = run(&scene, query, &mut exact);
        assert_eq!(run(&scene, query, &mut never_raised).pairs, truth.pairs);
        touching += truth.pairs.iter().filter(|p| p.distance <= 0.0).count();
        for workspace in &mut abandoned {
            let mut found = FrameResults::default();
            let report = step_within(&scene, query, &mut Unlimited, workspace, &mut found);
            assert_links(&found);
            for pair in &truth.pairs {
                let seen = found.pairs.iter().find(|p| (p.a, p.b) == (pair.a, pair.b));
                let seen = seen.unwrap_or_else(|| panic!("frame {frame}: missed {pair:?}"));
                if seen.exact {
                    assert_eq!(seen.distance, pair.distance, "frame {frame}");
                } else {
                    assert!(
                        seen.distance <= pair.distance + 1e-12
                            && pair.distance - seen.distance <= seen.error_bound + 1e-12,
                        "frame {frame}: {seen:?} against {pair:?}"
                    );
                }
            }
            let approximate = found.pairs.iter().filter(|p| !p.exact).count();
            approximate_pairs += approximate;
            if approximate > 0 {
                assert!(matches!(
                    report.completeness,
                    Completeness::Truncated { .. }
                ));
                truncated_frames += 1;
            }
        }
    }
    assert!(
        truncated_frames > 60 && approximate_pairs > 200 && touching > 20,
        "truncated frames {truncated_frames}, approximate pairs {approximate_pairs}, \
         touching pairs {touching}"
    );
}

/// A frame tried in a slice either gives exactly the exact frame's results, or says the
/// slice ended; then the exact frame run next on the same workspace gives exactly the
/// results of a workspace that never sliced, frame after frame.
#[test]
fn a_sliced_frame_is_exact_or_stops_and_the_frame_run_again_is_exact() {
    let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.6, 0.15, 20, 8))));
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let mut rng = rng(173);
    for i in 0..10 {
        let shape = match i % 3 {
            0 => Shape::Sphere(Sphere::new(0.3)),
            _ => torus.clone(),
        };
        add(&mut scene, shape, point_in_cube(&mut rng, 1.2), 0.2);
    }
    let (mut never_sliced, mut sliced) =
        (PipelineWorkspace::default(), PipelineWorkspace::default());
    let queries = [
        Query::CLOSE.union(Query::CONTACTS),
        Query::DISTANCE,
        Query::OVERLAP.union(Query::TOI),
    ];
    let (mut stopped, mut finished) = (0, 0);
    for frame in 0..90 {
        shake(&mut scene, &mut rng);
        let query = queries[frame % queries.len()];
        let truth = run(&scene, query, &mut never_sliced);
        // Every third frame gets a slice that has already ended, the others an hour.
        let slice_end = if frame % 3 == 0 {
            Instant::now()
        } else {
            Instant::now() + Duration::from_secs(3600)
        };
        let mut found = FrameResults::default();
        match step_sliced(&scene, query, slice_end, &mut sliced, &mut found) {
            Some(report) => {
                finished += 1;
                assert_eq!(report.completeness, Completeness::Exact, "frame {frame}");
            }
            None => {
                stopped += 1;
                found = run(&scene, query, &mut sliced);
            }
        }
        assert_eq!(found.pairs, truth.pairs, "frame {frame}");
        assert_eq!(found.contacts, truth.contacts, "frame {frame}");
        assert_eq!(found.tois, truth.tois, "frame {frame}");
        scene.end_frame();
    }
    assert!(
        stopped > 10 && finished > 40,
        "stopped {stopped}, finished {finished}"
    );
}

#[test]
fn mesh_pairs_answer_each_query_as_the_mesh_queries_do_directly() {
    let (mut scene, a, b, mesh) = torus_scene();
    let mut rng = rng(73);
    let mut workspace = PipelineWorkspace::default();
    let (mut touching, mut close, mut far) = (0, 0, 0);
    for frame in 0..80 {
        let pose_b = Pose::new(point_in_cube(&mut rng, 2.2), rotation(&mut rng));
        scene.set_pose(b, pose_b).unwrap();
        let (mut proxies, mut candidates) = (Vec::new(), Vec::new());
        scene.proxies(&mut proxies);
        crate::broad::pairs_brute_force(&proxies, &mut candidates);
        let candidate = !candidates.is_empty();
        let pose_a = scene.body(a).unwrap().pose;
        let pose_ab = Pose::relative(&pose_a, &pose_b);
        let cold = distance_mesh_mesh(
            &mesh.distance_tree,
            &mesh.distance_tree,
            &pose_ab,
            &DistanceParams::EXACT,
            &mut DistanceCache::new(),
            &mut MeshMeshWorkspace::new(),
        );
        let intersects = intersects_mesh_mesh(
            &mesh.overlap_tree,
            &mesh.overlap_tree,
            &pose_ab,
            &mut MeshMeshWorkspace::new(),
        );
        let mut segment_ends = Vec::new();
        contacts_mesh_mesh(
            &mesh.overlap_tree,
            &mesh.overlap_tree,
            &pose_ab,
            &mut MeshMeshWorkspace::new(),
            |c| {
                segment_ends.extend(c.segment.map(|p| pose_a.transform_point(p)));
                ControlFlow::Continue(())
            },
        );
        assert_eq!(intersects, cold.distance == 0.0, "frame {frame}");
        assert_eq!(intersects, !segment_ends.is_empty(), "frame {frame}");
        touching += usize::from(intersects);
        close += usize::from(cold.distance <= 1.0);
        far += usize::from(candidate && cold.distance > 1.0);
        for query in every_query() {
            let results = run(&scene, query, &mut workspace);
            let wanted = (query.distance && candidate)
                || (query.close && cold.distance <= 1.0)
                || ((query.overlap || query.contacts) && intersects);
            let r = match (results.pairs.as_slice(), wanted) {
                ([r], true) => r,
                ([], false) => continue,
                (pairs, _) => panic!("frame {frame} {query:?}: {} pairs", pairs.len()),
            };
            assert!(r.exact);
            if query.close || query.distance {
                // Warm-started across frames and queries, the exact distance is the cold one.
                assert_eq!(r.distance, cold.distance, "frame {frame}");
                assert_eq!(
                    (r.point_a, r.point_b),
                    (
                        pose_a.transform_point(cold.point_a),
                        pose_a.transform_point(cold.point_b)
                    )
                );
            } else {
                assert_eq!(r.distance, 0.0);
            }
            if !(query.contacts && intersects) {
                assert_eq!(r.contact_count, 0);
                continue;
            }
            let range = r.first_contact as usize..(r.first_contact + r.contact_count) as usize;
            let manifold = &results.contacts[range];
            let mut kept = Vec::new();
            reduce_manifold(&segment_ends, &mut kept);
            assert_eq!(manifold.len(), kept.len(), "frame {frame}");
            assert!(!manifold.is_empty());
            for (c, &i) in manifold.iter().zip(&kept) {
                assert_eq!((c.point_a, c.point_b), (segment_ends[i], segment_ends[i]));
                assert_eq!((c.distance, c.normal), (0.0, manifold[0].normal));
                assert!((c.normal.length() - 1.0).abs() < 1e-12);
            }
            if !(query.close || query.distance) {
                assert_eq!(
                    (r.point_a, r.normal),
                    (manifold[0].point_a, manifold[0].normal)
                );
            }
        }
    }
    assert!(
        touching > 5 && close - touching > 3 && far > 3,
        "{touching} {close} {far}"
    );
}

#[test]
fn overlap_alone_proves_mesh_contact_without_witnesses() {
    let (mut scene, _, b, _) = torus_scene();
    scene
        .set_pose(b, Pose::from_translation(DVec3::new(0.3, 0.0, 0.0)))
        .unwrap();
    let results = run(&scene, Query::OVERLAP, &mut PipelineWorkspace::default());
    let [r] = results.pairs.as_slice() else {
        panic!("{} pairs", results.pairs.len())
    };
    assert_eq!((r.distance, r.error_bound), (0.0, 0.0));
    assert_eq!(
        (r.point_a, r.point_b, r.normal),
        (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO)
    );
    assert!(results.contacts.is_empty());
}

/// One shape of every kind, in random poses: every pair is answered exactly, the same
/// whichever body is A (distance equal, normal reversed, witnesses swapped), with a
/// world-frame answer equal to the query run in A's frame and mapped by A's pose, and
/// both touching and separated pairs occur.
#[test]
fn every_pair_of_shape_kinds_is_exact_and_the_same_from_either_side() {
    use crate::geometry::{Capsule, Cone, ConvexPolyhedron, Cylinder};
    let hull: Vec<DVec3> = meshes::uv_sphere(0.4, 6, 4).vertices().to_vec();
    let kinds = [
        Shape::Sphere(Sphere::new(0.3)),
        Shape::Capsule(Capsule::new(0.3, 0.2)),
        Shape::Cuboid(Cuboid::new(DVec3::new(0.3, 0.2, 0.4))),
        Shape::Cylinder(Cylinder::new(0.3, 0.25)),
        Shape::Cone(Cone::new(0.3, 0.3)),
        Shape::Convex(Arc::new(ConvexPolyhedron::try_from_points(&hull).unwrap())),
        Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.4, 0.12, 16, 8)))),
    ];
    let mut rng = rng(83);
    let mut workspace = PipelineWorkspace::default();
    let mut scratch = NarrowScratch::default();
    let (mut touching, mut apart) = (0, 0);
    for case in 0..700 {
        let (i, j) = (case % kinds.len(), (case / kinds.len()) % kinds.len());
        let (pa, pb) = (
            Pose::new(point_in_cube(&mut rng, 3.0), rotation(&mut rng)),
            Pose::new(point_in_cube(&mut rng, 0.6), rotation(&mut rng)),
        );
        let pb = Pose::new(pa.position + pb.position, pb.rotation);
        let answer =
            |first: &Shape, second: &Shape, p1: Pose, p2: Pose, ws: &mut PipelineWorkspace| {
                let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
                add(&mut scene, first.clone(), DVec3::ZERO, 10.0);
                add(&mut scene, second.clone(), DVec3::ZERO, 10.0);
                scene.set_pose(BodyId(0), p1).unwrap();
                scene.set_pose(BodyId(1), p2).unwrap();
                let results = run(&scene, Query::CLOSE.union(Query::CONTACTS), ws);
                assert_eq!(
                    results.pairs.len(),
                    1,
                    "case {case}: margins cover the pair"
                );
                (results.pairs[0], results.contacts.clone())
            };
        let (ab, contacts) = answer(&kinds[i], &kinds[j], pa, pb, &mut workspace);
        let (ba, _) = answer(&kinds[j], &kinds[i], pb, pa, &mut workspace);
        assert!(ab.exact, "case {case}");
        let tol = 1e-7;
        assert!(
            (ab.distance - ba.distance).abs() <= tol,
            "case {case} ({i},{j}): {} vs {}",
            ab.distance,
            ba.distance
        );
        assert!(
            (ab.normal + ba.normal).length() <= 1e-5 || ab.distance <= 0.0,
            "case {case}"
        );
        assert!((ab.normal.length() - 1.0).abs() < 1e-9, "case {case}");
        // World answer = A-frame answer mapped by A's pose.
        let local = dispatch::distance(
            &kinds[i],
            &kinds[j],
            &Pose::relative(&pa, &pb),
            f64::INFINITY,
            &mut scratch,
        );
        assert!(
            (local.distance - ab.distance).abs() <= 1e-12 + ab.error_bound,
            "case {case}"
        );
        assert!(
            pa.transform_point(local.point_a).distance(ab.point_a) <= 1e-9,
            "case {case}"
        );
        if ab.distance <= 0.0 {
            assert!(
                !contacts.is_empty(),
                "case {case} ({i},{j}): touching without contacts"
            );
            assert!(
                contacts
                    .iter()
                    .all(|c| c.distance <= 1e-9 && c.normal.is_finite())
            );
            touching += 1;
        } else {
            assert!(contacts.is_empty(), "case {case}");
            apart += 1;
        }
    }
    assert!(
        touching > 100 && apart > 100,
        "touching {touching}, apart {apart}"
    );
}

/// Boxes and capsules with small margins, CLOSE only: a pair is reported exactly when
/// its closed-form distance is within the margins, with that distance (pairs GJK proves
/// farther than the margins skip the closed form, and must never hide a close one).
#[test]
fn close_pairs_of_boxes_and_capsules_are_exactly_those_within_their_margins() {
    use crate::geometry::Capsule;
    use crate::narrow::pairs;
    let mut rng = rng(89);
    let mut workspace = PipelineWorkspace::default();
    let (mut reported, mut skipped_candidates) = (0, 0);
    for case in 0..3_000 {
        let shape = |rng: &mut crate::test_support::TestRng| {
            if rng.random_range(0..2) == 0 {
                Shape::Cuboid(Cuboid::new(DVec3::new(
                    rng.random_range(0.05..0.5),
                    rng.random_range(0.05..0.5),
                    rng.random_range(0.05..0.5),
                )))
            } else {
                Shape::Capsule(Capsule::new(
                    rng.random_range(0.0..0.5),
                    rng.random_range(0.02..0.3),
                ))
            }
        };
        let (sa, sb) = (shape(&mut rng), shape(&mut rng));
        let (ma, mb) = (rng.random_range(0.0..0.1), rng.random_range(0.0..0.1));
        let (pa, pb) = (
            Pose::new(point_in_cube(&mut rng, 0.2), rotation(&mut rng)),
            Pose::new(point_in_cube(&mut rng, 0.9), rotation(&mut rng)),
        );
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        add(&mut scene, sa.clone(), DVec3::ZERO, ma);
        add(&mut scene, sb.clone(), DVec3::ZERO, mb);
        scene.set_pose(BodyId(0), pa).unwrap();
        scene.set_pose(BodyId(1), pb).unwrap();
        let mut results = FrameResults::default();
        let report = step(&scene, Query::CLOSE, &mut workspace, &mut results);
        let iso = Pose::relative(&pa, &pb).to_isometry();
        let truth = match (&sa, &sb) {
            (Shape::Cuboid(x), Shape::Cuboid(y)) => pairs::distance_cuboid_cuboid(x, y, &iso),
            (Shape::Capsule(x), Shape::Cuboid(y)) => pairs::distance_capsule_cuboid(x, y, &iso),
            (Shape::Cuboid(x), Shape::Capsule(y)) => {
                let d = pairs::distance_capsule_cuboid(y, x, &iso.inverse());
                d.flipped(&iso)
            }
            (Shape::Capsule(x), Shape::Capsule(y)) => pairs::distance_capsule_capsule(x, y, &iso),
            _ => unreachable!(),
        }
        .distance;
        match results.pairs.as_slice() {
            [r] => {
                assert!(
                    truth <= ma + mb + 1e-12,
                    "case {case}: far pair {truth} reported"
                );
                assert!((r.distance - truth).abs() <= 1e-12, "case {case}");
                reported += 1;
            }
            [] => {
                assert!(
                    truth > ma + mb - 1e-12,
                    "case {case}: close pair {truth} missed"
                );
                skipped_candidates += report.candidates as usize;
            }
            more => panic!("case {case}: {} pairs", more.len()),
        }
    }
    assert!(
        reported > 300 && skipped_candidates > 300,
        "reported {reported}, candidates beyond their margins {skipped_candidates}"
    );
}

/// The worker pool's fallback (a pair whose query panicked) is the box answer: a lower
/// bound of the distance within its error bound, a contact covering the depth.
#[test]
fn the_box_answer_is_conservative() {
    let sphere = Aabb::new(DVec3::splat(-0.5), DVec3::splat(0.5));
    let cube_at = |x: f64| {
        Aabb::new(
            DVec3::new(x - 0.5, -0.2, -0.5),
            DVec3::new(x + 0.5, 0.8, 0.5),
        )
    };
    let pair = CandidatePair { a: 0, b: 1 };
    let mut contacts = Vec::new();
    let far = answer::boxes(&pair, &sphere, &cube_at(1.05), Query::CLOSE, &mut contacts);
    // True distance: sphere centre to the box face x = 0.55, minus the radius.
    let truth = 0.55 - 0.5;
    assert!(!far.result.exact && !far.touching);
    assert!(far.result.distance <= truth && truth - far.result.distance <= far.result.error_bound);
    let near = answer::boxes(
        &pair,
        &sphere,
        &cube_at(0.8),
        Query::CONTACTS,
        &mut contacts,
    );
    let depth = 0.5 - (0.8 - 0.5);
    assert!(near.touching && contacts.len() == 1);
    assert!(contacts[0].distance == 0.0 && depth <= contacts[0].error_bound);
}

/// A small body near the edge of a wide floor gets the floor's normal, not the direction
/// between the centres.
#[test]
fn box_answers_take_their_normal_from_the_axis_that_separates_soonest() {
    for (height, a_below) in [(0.45, true), (0.55, true), (0.45, false), (0.55, false)] {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let floor = Shape::Cuboid(Cuboid::new(DVec3::new(5.0, 5.0, 0.25)));
        let ball = Shape::Sphere(Sphere::new(0.2));
        let (floor_at, ball_at) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(4.5, -4.0, height));
        // Body ids follow insertion: the first added is A.
        if a_below {
            add(&mut scene, floor, floor_at, 0.1);
            add(&mut scene, ball, ball_at, 0.1);
        } else {
            add(&mut scene, ball, ball_at, 0.1);
            add(&mut scene, floor, floor_at, 0.1);
        }
        let mut results = FrameResults::default();
        step(
            &scene,
            Query::CLOSE,
            &mut PipelineWorkspace::default(),
            &mut results,
        );
        let expected = if a_below { DVec3::Z } else { -DVec3::Z };
        assert_eq!(results.pairs.len(), 1, "height {height}");
        assert_eq!(
            results.pairs[0].normal, expected,
            "height {height}, A below {a_below}"
        );
    }
}

#[test]
fn a_warm_workspace_answers_frame_after_frame_without_growing() {
    let (mut scene, _, b, _) = torus_scene();
    let mut rng = rng(75);
    let poses: Vec<Pose> = (0..20)
        .map(|_| Pose::new(point_in_cube(&mut rng, 1.0), rotation(&mut rng)))
        .collect();
    let all = Query::CLOSE.union(Query::CONTACTS).union(Query::DISTANCE);
    let (mut workspace, mut results) = (PipelineWorkspace::default(), FrameResults::default());
    let capacities = |w: &PipelineWorkspace, r: &FrameResults| {
        (
            w.mesh.capacities(),
            w.candidates.capacity(),
            r.pairs.capacity(),
            r.contacts.capacity(),
        )
    };
    for &pose in &poses {
        scene.set_pose(b, pose).unwrap();
        step(&scene, all, &mut workspace, &mut results);
    }
    let warm = capacities(&workspace, &results);
    for &pose in &poses {
        scene.set_pose(b, pose).unwrap();
        step(&scene, all, &mut workspace, &mut results);
        assert_eq!(capacities(&workspace, &results), warm);
    }
}

/// Spheres wandering in and out of each other's boxes, some resting, one removed and
/// one added midway: after every frame the kept answers are exactly the frame's
/// candidates (all answered exactly), whichever were reused or answered anew, and
/// both happen.
#[test]
fn kept_answers_are_exactly_the_frame_candidates() {
    let mut scene = Scene::try_new(0.01, SceneLimits::STANDARD).unwrap();
    let mut rng = rng(76);
    let mut bodies: Vec<BodyId> = (0..12)
        .map(|_| {
            let radius = rng.random_range(0.1..0.4);
            add(
                &mut scene,
                Shape::Sphere(Sphere::new(radius)),
                point_in_cube(&mut rng, 1.5),
                0.05,
            )
        })
        .collect();
    let mut workspace = PipelineWorkspace::default();
    let (mut reused, mut fresh, mut dropped) = (0, 0, 0);
    for frame in 0..60 {
        if frame == 30 {
            scene.remove_body(bodies.remove(0)).unwrap();
            let sphere = Shape::Sphere(Sphere::new(0.3));
            bodies.push(add(&mut scene, sphere, DVec3::ZERO, 0.05));
        }
        for &body in &bodies {
            if rng.random_bool(0.5) {
                let pose = Pose::from_translation(point_in_cube(&mut rng, 1.5));
                scene.set_pose(body, pose).unwrap();
            }
        }
        let before = workspace.memory.kept_pairs().count();
        let mut results = FrameResults::default();
        let report = step(&scene, Query::CLOSE, &mut workspace, &mut results);
        let mut kept: Vec<CandidatePair> = workspace.memory.kept_pairs().copied().collect();
        kept.sort_unstable();
        assert_eq!(kept, workspace.candidates, "frame {frame}");
        // The one forgetting rule: no pair keeps a record past a frame it was not a
        // candidate of, whatever its record holds.
        assert!(
            workspace
                .memory
                .recorded_pairs()
                .all(|pair| workspace.candidates.binary_search(pair).is_ok()),
            "frame {frame}"
        );
        reused += report.reused_pairs;
        fresh += report.candidates - report.reused_pairs;
        dropped += usize::from(before > workspace.candidates.len());
        scene.end_frame();
    }
    assert!(
        reused > 0 && fresh > 0 && dropped > 0,
        "{reused} {fresh} {dropped}"
    );
}

#[test]
fn a_frame_is_truncated_at_the_shallowest_level_of_its_pairs() {
    let mut c = Completeness::Exact;
    for (level, expected) in [(3, 3), (5, 3), (1, 1), (2, 1)] {
        c = c.truncated_at(level);
        assert_eq!(c, Completeness::Truncated { level: expected });
    }
}

/// A pile-up with more candidate pairs than the scene's per-frame limit: the frame answers
/// the first `max_pairs_per_frame` of the broad phase's list, exactly as an uncapped frame
/// answers them, and counts the rest as dropped; under the limit nothing is dropped.
#[test]
fn a_frame_answers_at_most_its_pair_limit_and_counts_what_it_dropped() {
    let build = |max_pairs_per_frame| {
        let limits = SceneLimits {
            max_pairs_per_frame,
            ..SceneLimits::STANDARD
        };
        let mut scene = Scene::try_new(0.0, limits).unwrap();
        let mut rng = rng(2904);
        for _ in 0..60 {
            let at = point_in_cube(&mut rng, 0.2);
            add(&mut scene, Shape::Sphere(Sphere::new(0.3)), at, 0.0);
        }
        scene
    };
    let run = |scene: &Scene| {
        let mut results = FrameResults::default();
        let report = step(
            scene,
            Query::CLOSE.union(Query::CONTACTS),
            &mut PipelineWorkspace::default(),
            &mut results,
        );
        (report, results)
    };
    let (whole, all) = run(&build(u32::MAX));
    let every = whole.candidates as usize;
    assert_eq!(every, 60 * 59 / 2, "every sphere overlaps every other");
    assert_eq!((whole.dropped_candidates, all.pairs.len()), (0, every));
    for cap in [0, 1, 100, every as u32 - 1, every as u32] {
        let (report, capped) = run(&build(cap));
        assert_eq!(report.candidates, cap, "cap {cap}");
        assert_eq!(report.dropped_candidates as usize, every - cap as usize);
        assert_eq!(capped.pairs, all.pairs[..cap as usize], "cap {cap}");
        assert_eq!(
            capped.contacts.len(),
            capped.pairs.len(),
            "one contact each"
        );
    }
}

/// A frame whose deadline cannot hold the scene's measured uninterruptible work is not
/// started: it answers nothing, says so with that work's nanoseconds, and leaves the next
/// frames (with a budget that fits, or none) exactly as they would have been.
#[test]
fn a_frame_too_short_for_the_broad_phase_and_publishing_is_not_started() {
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let mut rng = rng(2905);
    for _ in 0..50 {
        let at = point_in_cube(&mut rng, 1.0);
        add(&mut scene, Shape::Sphere(Sphere::new(0.2)), at, 0.0);
    }
    let query = Query::CLOSE.union(Query::CONTACTS);
    let workspace = &mut PipelineWorkspace::default();
    let results = &mut FrameResults::default();
    let (exact, exact_results) = {
        let mut fresh = FrameResults::default();
        let report = step(&scene, query, &mut PipelineWorkspace::default(), &mut fresh);
        (report, fresh)
    };
    assert!(exact.pairs > 0);
    let in_an_hour = || Deadline(Instant::now() + Duration::from_secs(3600));
    let already_due = || Deadline(Instant::now());
    // Not measured yet: even a frame already due starts. The first builds the broad phase
    // (a rebuild is not what later frames cost, so it is not measured); the second syncs
    // it and is measured.
    for _ in 0..2 {
        let unmeasured = step_within(&scene, query, &mut already_due(), workspace, results);
        assert_eq!(unmeasured.budget_too_small, None);
    }
    workspace.note_publish(1_000, 0);
    // Measured: a due frame is not started.
    let skipped = step_within(&scene, query, &mut already_due(), workspace, results);
    let needed = skipped.budget_too_small.expect("the frame is not started");
    assert!(needed >= 1_000, "publishing is part of it: {needed}");
    assert_eq!(skipped.completeness, Completeness::Truncated { level: 0 });
    assert!(results.pairs.is_empty() && results.contacts.is_empty());
    // A frame with room, and an unbudgeted one, answer as the exact run does.
    let roomy = step_within(&scene, query, &mut in_an_hour(), workspace, results);
    assert_eq!(roomy.budget_too_small, None);
    assert_eq!(results.pairs, exact_results.pairs);
    let unbudgeted = step(&scene, query, workspace, results);
    assert_eq!(unbudgeted.budget_too_small, None);
    assert_eq!(results.contacts, exact_results.contacts);
}

/// A mesh pair's exact route stopped mid-search by its clock (a slice that ended, an owner
/// gone), in its proximity, overlap or distance search or its contacts, answers
/// conservatively: a lower bound of the true distance within its error bound, marked
/// inexact, touching whenever the exact answer touches; with enough work it is the exact
/// answer. Counted clocks, growing by a quarter each run.
#[test]
fn a_mesh_pair_whose_search_stops_answers_conservatively() {
    let torus = Arc::new(MeshShape::new(meshes::torus(0.6, 0.15, 20, 8)));
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let a = add(
        &mut scene,
        Shape::Mesh(Arc::clone(&torus)),
        DVec3::ZERO,
        0.1,
    );
    let b = add(&mut scene, Shape::Mesh(Arc::clone(&torus)), DVec3::X, 0.1);
    let pair = CandidatePair::of(a.0, b.0);
    let mut rng = rng(77);
    let (mut stopped, mut touching, mut apart) = (0, 0, 0);
    let answer = |scene: &Scene, query, stop| {
        let (ba, bb) = (body(scene, pair.a), body(scene, pair.b));
        let mut clock = WorkClock::new(stop);
        let mut contacts = Vec::new();
        let found = answer::mesh_mesh(
            &pair,
            (ba, &torus),
            (bb, &torus),
            query,
            &mut DistanceCache::default(),
            (&mut answer::MeshScratch::default(), &mut clock),
            &mut contacts,
        );
        (found, contacts)
    };
    let queries = [
        Query::CLOSE.union(Query::CONTACTS),
        Query::CLOSE.union(Query::OVERLAP),
        Query::DISTANCE,
    ];
    for case in 0..60 {
        let pose = Pose::new(point_in_cube(&mut rng, 0.9), rotation(&mut rng));
        scene.set_pose(b, pose).unwrap();
        // Under `CLOSE` a pair beyond its margins says `+∞`; the bounds are checked against
        // the true distance.
        let true_distance = torus
            .distance_to(
                &torus,
                &pose,
                &mut DistanceCache::default(),
                &mut MeshMeshWorkspace::default(),
            )
            .distance;
        for query in queries {
            let (exact, _) = answer(&scene, query, Stop::Never);
            assert!(exact.result.exact);
            if exact.touching {
                touching += 1;
            } else {
                apart += 1;
            }
            let mut work = 0;
            loop {
                let (found, contacts) = answer(&scene, query, Stop::AfterWork(work));
                if found.result.exact {
                    assert_eq!(found.result, exact.result, "case {case}: {work} units");
                    break;
                }
                stopped += 1;
                let seen = found.result;
                assert!(
                    seen.distance <= true_distance + 1e-12
                        && true_distance - seen.distance <= seen.error_bound + 1e-12,
                    "case {case}, {work} units: {seen:?} against {true_distance}"
                );
                assert!(
                    !exact.touching || found.touching,
                    "case {case}: missed contact"
                );
                assert_eq!(contacts.is_empty(), !(found.touching && query.contacts));
                work = (work + work / 4).max(work + 8);
                assert!(work < 100_000_000, "case {case}: never finished");
            }
        }
    }
    assert!(
        stopped > 300 && touching > 10 && apart > 10,
        "stopped {stopped}, touching {touching}, apart {apart}"
    );
}

/// 80 convex bodies of every convex kind packed in a 1.6 m cube: about a hundred
/// candidate pairs a frame, most touching.
fn convex_crowd(seed: u64) -> (Scene, Vec<BodyId>, crate::test_support::TestRng) {
    use crate::geometry::{Cone, ConvexPolyhedron};
    let hull: Vec<DVec3> = meshes::uv_sphere(0.2, 6, 4).vertices().to_vec();
    let hull = Arc::new(ConvexPolyhedron::try_from_points(&hull).unwrap());
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let mut rng = rng(seed);
    let bodies = (0..80)
        .map(|i| {
            let shape = match i % 6 {
                0 => Shape::Sphere(Sphere::new(0.15)),
                1 => Shape::Capsule(Capsule::new(0.15, 0.1)),
                2 => Shape::Cuboid(Cuboid::new(DVec3::new(0.15, 0.1, 0.2))),
                3 => Shape::Cylinder(Cylinder::new(0.15, 0.12)),
                4 => Shape::Cone(Cone::new(0.15, 0.15)),
                _ => Shape::Convex(Arc::clone(&hull)),
            };
            add(&mut scene, shape, point_in_cube(&mut rng, 0.8), 0.02)
        })
        .collect();
    (scene, bodies, rng)
}

/// Moves and turns every body a little, as a settling pile does: no answer can be kept.
fn jostle(scene: &mut Scene, bodies: &[BodyId], rng: &mut crate::test_support::TestRng) {
    for &body in bodies {
        let pose = scene.body(body).unwrap().pose;
        let moved = Pose::new(
            (pose.position + point_in_cube(rng, 0.02)).clamp_length_max(0.9),
            rotation(rng).slerp(pose.rotation, 0.95),
        );
        scene.set_pose(body, moved).unwrap();
    }
}

/// A crowd of convex bodies all moving: with the pool's helper answering pairs from the
/// back, every frame's records, contacts and paths are those of one thread, unbudgeted
/// and under a deadline too far to stop anything; the helper and the pair loop each
/// answer a share (the helper waited for, so that it does on a busy machine too).
#[test]
fn the_pair_helper_changes_nothing_but_who_answers() {
    let (mut scene, bodies, mut rng) = convex_crowd(211);
    let pool = Arc::new(WorkerPool::with_helper(
        1,
        Some(helper::PairHelper::eager()),
    ));
    let (mut alone, mut helped) = (
        PipelineWorkspace::default(),
        PipelineWorkspace::with_workers(pool),
    );
    let (mut expected, mut found) = (FrameResults::default(), FrameResults::default());
    let (mut by_helper, mut fresh, mut contacts) = (0, 0, 0);
    for frame in 0..80 {
        jostle(&mut scene, &bodies, &mut rng);
        let query = if frame % 2 == 0 {
            Query::CLOSE.union(Query::CONTACTS)
        } else {
            Query::DISTANCE.union(Query::CONTACTS)
        };
        let (a, b) = if frame % 4 < 2 {
            (
                step(&scene, query, &mut alone, &mut expected),
                step(&scene, query, &mut helped, &mut found),
            )
        } else {
            let far = || Deadline(Instant::now() + Duration::from_secs(60));
            (
                step_within(&scene, query, &mut far(), &mut alone, &mut expected),
                step_within(&scene, query, &mut far(), &mut helped, &mut found),
            )
        };
        assert_same_frame((&a, &expected), (&b, &found), frame);
        by_helper += b.helped_pairs;
        fresh += b.candidates - b.reused_pairs - b.separated_pairs;
        contacts += b.contacts;
    }
    assert!(
        by_helper > 500 && by_helper < fresh && contacts > 1000,
        "pairs answered by the helper {by_helper} of {fresh} afresh, contacts {contacts}"
    );
}

/// A helper held mid-pair (as if preempted) never holds up the frame: the pair loop
/// answers the pair the helper holds itself, every frame ends with the records of one
/// thread, and nothing the held helper claimed is taken from it.
#[test]
fn a_held_pair_helper_never_delays_the_frame() {
    let gate: helper::Gate = Arc::default();
    let pool = Arc::new(WorkerPool::with_helper(
        1,
        Some(helper::PairHelper::held(Arc::clone(&gate))),
    ));
    let (done_tx, done_rx) = std::sync::mpsc::channel();
    let frames = std::thread::spawn(move || {
        let (mut scene, bodies, mut rng) = convex_crowd(223);
        let (mut alone, mut helped) = (
            PipelineWorkspace::default(),
            PipelineWorkspace::with_workers(pool),
        );
        let (mut expected, mut found) = (FrameResults::default(), FrameResults::default());
        let mut fresh = 0;
        // The first frame's last pair is held; later frames find the helper still held.
        for frame in 0..4 {
            jostle(&mut scene, &bodies, &mut rng);
            let query = Query::CLOSE.union(Query::CONTACTS);
            step(&scene, query, &mut alone, &mut expected);
            let report = step(&scene, query, &mut helped, &mut found);
            assert_eq!(found.pairs, expected.pairs, "frame {frame}");
            assert_eq!(found.contacts, expected.contacts, "frame {frame}");
            assert_eq!(report.helped_pairs, 0, "frame {frame}: the helper is held");
            fresh += report.candidates - report.reused_pairs;
        }
        done_tx.send(fresh).unwrap();
    });
    // A pair loop that waited for the held helper would never send: the gate opens only
    // after the frames, or after a wait no frame of 80 bodies comes near.
    let fresh = done_rx.recv_timeout(Duration::from_secs(120));
    let (open, opened) = &*gate;
    *open.lock().unwrap() = true;
    opened.notify_all();
    frames.join().unwrap();
    let fresh = fresh.expect("the frames ended while the helper was held");
    assert!(
        fresh > 4 * helper::MIN_HELPED_PAIRS as u32,
        "{fresh} pairs answered afresh"
    );
}
