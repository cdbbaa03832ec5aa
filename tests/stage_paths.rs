//! The frame reports which narrow-phase paths it took ([`StepReport::paths`]), and a scene
//! of only spheres and capsules never enters BVH or EPA code (issue #7, "skip what the scene
//! does not need"), whatever it asks and however deep its bodies overlap.
//!
//! A control scene with cylinders, convex hulls and meshes shows that the counters do count
//! those paths, so the first test could fail.

#[path = "support/mod.rs"]
mod support;

use proxima::geometry::{Capsule, ConvexPolyhedron, Cylinder, Sphere};
use proxima::math::Pose;
use proxima::narrow::{MeshShape, Shape};
use proxima::pipeline::{FrameResults, PathCounts, PipelineWorkspace, Query, StepReport, step};
use proxima::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits};
use rand::Rng;
use std::sync::Arc;
use support::{TestRng, meshes, point_in_cube, rng, rotation};

/// Frames per scene.
const FRAMES: usize = 150;
/// Half-size of the cube the bodies live in, metres (crowded: many deep overlaps).
const HALF: f64 = 1.5;

/// Every flag at once: the most work a frame can ask for.
const EVERYTHING: Query = Query::CLOSE
    .union(Query::DISTANCE)
    .union(Query::CONTACTS)
    .union(Query::OVERLAP)
    .union(Query::TOI);

fn add(scene: &mut Scene, shape: Shape, rng: &mut TestRng) -> BodyId {
    let shape = scene.register_shape(shape).unwrap();
    scene
        .add_body(&BodyDesc {
            shape,
            pose: Pose::new(point_in_cube(rng, HALF), rotation(rng)),
            motion: Motion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: Some(0.05),
        })
        .unwrap()
}

/// Runs `FRAMES` frames of random motion; returns every frame's report and how many
/// penetrating and apart pair records the frames gave.
fn run(scene: &mut Scene, bodies: &[BodyId], rng: &mut TestRng) -> (Vec<StepReport>, [usize; 2]) {
    let (mut workspace, mut results) = (PipelineWorkspace::default(), FrameResults::default());
    let (mut reports, mut outcomes) = (Vec::new(), [0; 2]);
    for _ in 0..FRAMES {
        for &id in bodies {
            if rng.random_bool(0.5) {
                let pose = Pose::new(point_in_cube(rng, HALF), rotation(rng));
                scene.set_pose(id, pose).unwrap();
            }
        }
        let report = step(scene, EVERYTHING, &mut workspace, &mut results);
        for pair in &results.pairs {
            outcomes[usize::from(pair.distance > 0.0)] += 1;
        }
        reports.push(report);
        scene.end_frame();
    }
    (reports, outcomes)
}

fn total(reports: &[StepReport]) -> PathCounts {
    reports
        .iter()
        .fold(PathCounts::default(), |t, r| PathCounts {
            closed_form: t.closed_form + r.paths.closed_form,
            gjk: t.gjk + r.paths.gjk,
            separating_axes: t.separating_axes + r.paths.separating_axes,
            epa: t.epa + r.paths.epa,
            convex_mesh: t.convex_mesh + r.paths.convex_mesh,
            mesh_mesh: t.mesh_mesh + r.paths.mesh_mesh,
            compound: t.compound + r.paths.compound,
        })
}

#[test]
fn a_scene_of_spheres_and_capsules_never_enters_bvh_or_epa_code() {
    let mut rng = rng(0x5_7a6e);
    let mut scene = Scene::try_new(0.02, SceneLimits::STANDARD).unwrap();
    let bodies: Vec<BodyId> = (0..40)
        .map(|i| {
            let shape = if i % 2 == 0 {
                Shape::Sphere(Sphere::new(rng.random_range(0.1..0.5)))
            } else {
                Shape::Capsule(Capsule::new(
                    rng.random_range(0.0..0.6),
                    rng.random_range(0.05..0.4),
                ))
            };
            add(&mut scene, shape, &mut rng)
        })
        .collect();
    let (reports, [penetrating, apart]) = run(&mut scene, &bodies, &mut rng);
    for (frame, r) in reports.iter().enumerate() {
        assert_eq!(
            (r.paths.bvh(), r.paths.epa),
            (0, 0),
            "frame {frame}: {:?}",
            r.paths
        );
    }
    let t = total(&reports);
    assert!(t.closed_form > 10_000, "{t:?}");
    // Deep overlaps (which GJK would hand to EPA) and separated pairs both occurred.
    assert!(
        penetrating > 1_000 && apart > 1_000,
        "{penetrating} {apart}"
    );
}

#[test]
fn cylinders_hulls_and_meshes_are_counted_on_their_paths() {
    let mut rng = rng(0xc0_47e5);
    let mut scene = Scene::try_new(0.02, SceneLimits::STANDARD).unwrap();
    let torus = Arc::new(MeshShape::new(meshes::torus(0.5, 0.15, 16, 8)));
    let bodies: Vec<BodyId> = (0..24)
        .map(|i| {
            let shape = match i % 4 {
                0 => Shape::Cylinder(Cylinder::new(0.3, 0.25)),
                1 => Shape::Convex(Arc::new(
                    ConvexPolyhedron::try_from_points(
                        &(0..12)
                            .map(|_| point_in_cube(&mut rng, 0.3))
                            .collect::<Vec<_>>(),
                    )
                    .unwrap(),
                )),
                2 => Shape::Mesh(Arc::clone(&torus)),
                _ => Shape::Sphere(Sphere::new(0.3)),
            };
            add(&mut scene, shape, &mut rng)
        })
        .collect();
    let (reports, [penetrating, apart]) = run(&mut scene, &bodies, &mut rng);
    let t = total(&reports);
    assert!(
        t.epa > 0 && t.gjk > 0 && t.convex_mesh > 0 && t.mesh_mesh > 0 && t.closed_form > 0,
        "{t:?}"
    );
    assert!(penetrating > 0 && apart > 0, "{penetrating} {apart}");
}
