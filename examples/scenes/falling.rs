//! `falling_bodies`' scene: spheres, capsules, boxes and small tori, a quarter each,
//! dropped into an 8 m bin (a floor and four walls, static boxes) from a grid of layers,
//! and the point-mass integration that bounces them with the daemon's contacts.

use super::point_mass::{SolverParams, World};
use super::spec::{BodyPlan, SceneSpec, ShapeSpec};
use glam::{DQuat, DVec3};
use proxima::geometry::TriMesh;
use proxima_ipc::client::{Motion, Primitive};
use std::sync::Arc;

/// Bin: floor half extent and wall height, metres.
pub const BIN_HALF: f64 = 4.0;
const WALL_HEIGHT: f64 = 3.0;
/// Close-pair margin of every body, metres.
const MARGIN: f64 = 0.02;

/// Gravity 9.81 m/s², restitution 0.4; slow under 0.15 m/s (a body at rest on the floor
/// still gains g·dt ≈ 0.08 m/s each frame at 120 Hz before its contact stops it), asleep
/// after 60 slow frames, woken by hits over 0.3 m/s.
pub const FALLING_SOLVER: SolverParams = SolverParams {
    gravity: 9.81,
    restitution: 0.4,
    rest_speed: 0.15,
    sleep_frames: 60,
    wake_speed: 0.3,
    spin_decay: 0.995,
};

/// The bin and `count` falling bodies: the walls first (static), then the bodies.
#[must_use]
pub fn falling_scene(count: usize) -> SceneSpec {
    let mut spec = SceneSpec::default();
    let cuboid = |x, y, z| {
        ShapeSpec::Primitive(Primitive::Cuboid {
            half_extents: [x, y, z],
        })
    };
    let h = WALL_HEIGHT / 2.0;
    let floor = spec.add_shape(cuboid(BIN_HALF, BIN_HALF, 0.25));
    let wall_x = spec.add_shape(cuboid(0.25, BIN_HALF, h));
    let wall_y = spec.add_shape(cuboid(BIN_HALF, 0.25, h));
    for (shape, at) in [
        (floor, DVec3::new(0.0, 0.0, -0.25)),
        (wall_x, DVec3::new(-BIN_HALF - 0.25, 0.0, h)),
        (wall_x, DVec3::new(BIN_HALF + 0.25, 0.0, h)),
        (wall_y, DVec3::new(0.0, -BIN_HALF - 0.25, h)),
        (wall_y, DVec3::new(0.0, BIN_HALF + 0.25, h)),
    ] {
        spec.add_body(plan(shape, at, DQuat::IDENTITY, Motion::Static));
    }
    let shapes = [
        spec.add_shape(ShapeSpec::Primitive(Primitive::Sphere { radius: 0.2 })),
        spec.add_shape(ShapeSpec::Primitive(Primitive::Capsule {
            radius: 0.12,
            half_height: 0.2,
        })),
        spec.add_shape(cuboid(0.18, 0.18, 0.18)),
        spec.add_shape(ShapeSpec::Mesh(Arc::new(TriMesh::torus(0.3, 0.1, 16, 8)))),
    ];
    let side = (count as f64).sqrt().ceil() as usize;
    let spacing = (2.0 * BIN_HALF - 1.0) / side as f64;
    for i in 0..count {
        let (gx, gy) = (i % side, i / side % side);
        let layer = i / (side * side);
        let position = DVec3::new(
            -BIN_HALF + 0.5 + (gx as f64 + 0.5) * spacing,
            -BIN_HALF + 0.5 + (gy as f64 + 0.5) * spacing,
            2.0 + 1.0 * layer as f64 + 0.37 * ((i * 7) % 5) as f64,
        );
        let orientation =
            DQuat::from_euler(glam::EulerRot::XYZ, i as f64 * 0.7, i as f64 * 1.3, 0.0);
        spec.add_body(plan(
            shapes[i % shapes.len()],
            position,
            orientation,
            Motion::Dynamic,
        ));
    }
    spec
}

/// The simulation of `spec` (from [`falling_scene`]) whose bodies got daemon ids `ids`:
/// the static bodies as walls, the others falling, every third spinning one way, every
/// third the other, the rest not.
#[must_use]
pub fn falling_world(spec: &SceneSpec, ids: &[u32]) -> World {
    let mut world = World::new(FALLING_SOLVER);
    let mut falling = 0;
    for (body, &id) in spec.bodies.iter().zip(ids) {
        if body.motion == Motion::Static {
            world.add_static(id);
            continue;
        }
        let spin = DVec3::new(0.3, -0.2, 0.5) * ((falling % 3) as f64 - 1.0);
        world.add_moving(id, body.position, body.orientation, spin);
        falling += 1;
    }
    world
}

fn plan(shape: usize, position: DVec3, orientation: DQuat, motion: Motion) -> BodyPlan {
    BodyPlan {
        shape,
        position,
        orientation,
        motion,
        margin_m: MARGIN,
    }
}
