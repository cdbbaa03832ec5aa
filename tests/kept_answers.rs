//! A pair whose bodies did not change reuses its last answer (issue #7, "pairs whose
//! relative pose did not change reuse last frame's answer"): the frame is record for record
//! the frame a fresh workspace computes, the reuse count is exactly the candidate pairs of
//! unchanged bodies under an unchanged query, and those pairs run no query at all.

#[path = "support/mod.rs"]
mod support;

use proxima::geometry::{Capsule, ConvexPolyhedron, Cuboid, Cylinder, Sphere};
use proxima::math::{DVec3, Pose};
use proxima::narrow::{MeshShape, Shape};
use proxima::pipeline::{FrameResults, PathCounts, PipelineWorkspace, Query, step};
use proxima::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits};
use rand::Rng;
use std::collections::BTreeSet;
use std::sync::Arc;
use support::{meshes, point_in_cube, rng, rotation};

const FRAMES: usize = 300;
/// Half-size of the region the bodies live in, metres.
const HALF: f64 = 1.8;

#[test]
fn unchanged_pairs_reuse_their_answers_and_frames_equal_fresh_ones() {
    let mut rng = rng(0x6e_e9);
    let mut scene = Scene::try_new(0.05, SceneLimits::STANDARD).unwrap();
    let torus = Arc::new(MeshShape::new(meshes::torus(0.5, 0.15, 16, 8)));
    let hull = Arc::new(
        ConvexPolyhedron::try_from_points(
            &(0..16)
                .map(|_| point_in_cube(&mut rng, 0.35))
                .collect::<Vec<_>>(),
        )
        .unwrap(),
    );
    let (mut bodies, mut shapes): (Vec<BodyId>, Vec<_>) = (Vec::new(), Vec::new());
    for i in 0..30 {
        let shape = match i % 6 {
            0 => Shape::Sphere(Sphere::new(0.3)),
            1 => Shape::Capsule(Capsule::new(0.3, 0.2)),
            2 => Shape::Cuboid(Cuboid::new(DVec3::new(0.3, 0.2, 0.25))),
            3 => Shape::Cylinder(Cylinder::new(0.25, 0.2)),
            4 => Shape::Convex(Arc::clone(&hull)),
            _ => Shape::Mesh(Arc::clone(&torus)),
        };
        let shape = scene.register_shape(shape).unwrap();
        shapes.push(shape);
        let id = scene
            .add_body(&BodyDesc {
                shape,
                pose: Pose::new(point_in_cube(&mut rng, HALF), rotation(&mut rng)),
                motion: if i % 7 == 0 {
                    Motion::Static
                } else {
                    Motion::Dynamic
                },
                filter: CollisionFilter::ALL,
                margin: None,
            })
            .unwrap();
        bodies.push(id);
    }
    // DISTANCE first: it reports every candidate, so the exact reuse count is checkable.
    let queries = [
        Query::DISTANCE,
        Query::CLOSE.union(Query::CONTACTS),
        Query::OVERLAP.union(Query::CONTACTS),
    ];
    let mut kept = PipelineWorkspace::default();
    let (mut got, mut want) = (FrameResults::default(), FrameResults::default());
    let (mut reused_total, mut fresh_total, mut quiet_frames) = (0, 0, 0);
    let mut last_query = queries[0];
    let (mut last_pairs, mut exact_checks, mut replaced) = (BTreeSet::new(), 0, 0);
    for frame in 0..FRAMES {
        // A few bodies change each frame (none on some frames); the query changes now and
        // then, which must stop all reuse for that frame.
        let mut changed = BTreeSet::new();
        let movers = if rng.random_bool(0.2) {
            0
        } else {
            rng.random_range(1..6)
        };
        for _ in 0..movers {
            let id = bodies[rng.random_range(0..bodies.len())];
            let action = rng.random_range(0.0..1.0);
            if action < 0.8 {
                let pose = Pose::new(point_in_cube(&mut rng, HALF), rotation(&mut rng));
                scene.set_pose(id, pose).unwrap();
            } else if action < 0.9 {
                // Replaced in place: another shape, same pose, and the removed body's id.
                // Its old answers must not be kept (the slot's body has a new version).
                let old = scene.remove_body(id).unwrap();
                let desc = BodyDesc {
                    shape: shapes[rng.random_range(0..shapes.len())],
                    pose: old.pose,
                    motion: old.motion,
                    filter: old.filter,
                    margin: None,
                };
                assert_eq!(scene.add_body(&desc).unwrap(), id, "the slot is reused");
                replaced += 1;
            } else {
                let body = *scene.body(id).unwrap();
                scene
                    .update_body(
                        id,
                        body.motion,
                        body.filter,
                        Some(rng.random_range(0.0..0.2)),
                    )
                    .unwrap();
            }
            changed.insert(id.0);
        }
        let query = if rng.random_bool(0.05) {
            queries[rng.random_range(0..queries.len())]
        } else {
            last_query
        };
        let report = step(&scene, query, &mut kept, &mut got);
        let fresh = step(&scene, query, &mut PipelineWorkspace::default(), &mut want);
        assert_eq!(got.pairs, want.pairs, "frame {frame}");
        assert_eq!(got.contacts, want.contacts, "frame {frame}");
        // Reused: the candidates whose bodies did not change, under the same query, that
        // were candidates last frame too.
        assert_eq!(report.candidates, fresh.candidates, "frame {frame}");
        if query != last_query {
            assert_eq!(report.reused_pairs, 0, "frame {frame}: query changed");
        }
        assert!(report.reused_pairs <= report.candidates, "frame {frame}");
        let pairs: BTreeSet<(u32, u32)> = got.pairs.iter().map(|p| (p.a, p.b)).collect();
        if query == Query::DISTANCE && last_query == Query::DISTANCE && frame > 0 {
            // Every candidate is reported: the reused ones are exactly last frame's pairs
            // still candidates whose bodies did not change.
            let expected = pairs
                .intersection(&last_pairs)
                .filter(|(a, b)| !changed.contains(a) && !changed.contains(b))
                .count();
            assert_eq!(report.reused_pairs as usize, expected, "frame {frame}");
            exact_checks += 1;
        }
        if changed.is_empty() && query == last_query && frame > 0 {
            assert_eq!(
                report.reused_pairs, report.candidates,
                "frame {frame}: nothing changed"
            );
            assert_eq!(
                report.paths,
                PathCounts::default(),
                "frame {frame}: no query ran"
            );
            quiet_frames += 1;
        }
        reused_total += report.reused_pairs;
        fresh_total += report.candidates - report.reused_pairs;
        last_query = query;
        last_pairs = pairs;
        scene.end_frame();
    }
    assert!(exact_checks > 50, "{exact_checks}");
    assert!(quiet_frames > 20, "{quiet_frames}");
    assert!(replaced > 20, "{replaced} bodies replaced in place");
    assert!(
        reused_total > 1_000 && fresh_total > 1_000,
        "{reused_total} {fresh_total}"
    );
}
