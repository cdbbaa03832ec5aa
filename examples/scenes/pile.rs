//! A settling pile: [`PILE_BODIES`] small bodies (spheres, capsules, boxes, cylinders and
//! convex hulls of 20–60 random points, a fifth each, every one 2–7 cm across at its
//! largest) dropped from a grid of layers into a 40 cm box (a floor and four walls, static
//! boxes), integrated at [`PILE_RATE_HZ`] by the point-mass solver ([`PILE_SOLVER`]) from
//! the contacts of `CLOSE | CONTACTS` frames until they come to rest.
//!
//! The same seed gives the same scene ([`pile_scene`]); its bodies are in layers of 16,
//! the lowest 10 cm above the floor, all falling at once.

use super::point_mass::{SolverParams, World};
use super::spec::{BodyPlan, SceneSpec, ShapeSpec};
use glam::{DQuat, DVec3};
use proxima_ipc::client::{Motion, Primitive};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Bodies in the pile.
pub const PILE_BODIES: usize = 100;
/// Frames per simulated second.
pub const PILE_RATE_HZ: f64 = 240.0;
/// Half the box's inner width, metres.
const BOX_HALF: f64 = 0.2;
/// Wall height above the floor, metres.
const WALL_HEIGHT: f64 = 0.5;
/// Half the thickness of the floor and walls, metres (thick, so that nothing falls through).
const WALL_HALF_THICKNESS: f64 = 0.05;
/// Smallest and largest body size (largest extent), metres.
const SIZE_M: (f64, f64) = (0.02, 0.07);
/// Close-pair margin of every body, metres.
const MARGIN_M: f64 = 0.005;
/// Bodies per layer (a 4 × 4 grid) and the layers' spacing, metres.
const LAYER_SIDE: usize = 4;
const LAYER_SPACING_M: f64 = 0.09;

/// Gravity 9.81 m/s², restitution 0.2; slow under 0.08 m/s (twice g·dt at 240 Hz), asleep
/// after a quarter of a second slow, woken by hits over 0.3 m/s; spin fades in about a
/// quarter of a second.
pub const PILE_SOLVER: SolverParams = SolverParams {
    gravity: 9.81,
    restitution: 0.2,
    rest_speed: 0.08,
    sleep_frames: 60,
    wake_speed: 0.3,
    spin_decay: 0.98,
};

/// The box (five static bodies first) and the [`PILE_BODIES`] bodies above it, each with a
/// shape of its own, at random orientations.
#[must_use]
pub fn pile_scene(seed: u64) -> SceneSpec {
    pile_of_kinds(seed, 5)
}

/// [`pile_scene`] with spheres, capsules and boxes only (a third each), the same sizes: the
/// primitive pile that #30's second target is set on.
#[must_use]
pub fn primitive_pile_scene(seed: u64) -> SceneSpec {
    pile_of_kinds(seed, 3)
}

/// The pile with body `i` of kind `i % kinds` ([`random_shape`]'s numbering).
fn pile_of_kinds(seed: u64, kinds: usize) -> SceneSpec {
    let mut rng = Pcg64Mcg::seed_from_u64(seed);
    let mut spec = SceneSpec::default();
    add_box(&mut spec);
    for i in 0..PILE_BODIES {
        let position = layer_position(i, &mut rng);
        let size = rng.random_range(SIZE_M.0..SIZE_M.1);
        let shape = spec.add_shape(random_shape(&mut rng, i % kinds, size));
        spec.add_body(BodyPlan {
            shape,
            position,
            orientation: random_orientation(&mut rng),
            motion: Motion::Dynamic,
            margin_m: MARGIN_M,
        });
    }
    spec
}

/// Where body `i` of a pile starts: the layers of 16, the lowest 10 cm above the floor,
/// each place jittered by up to a centimetre.
pub fn layer_position(i: usize, rng: &mut Pcg64Mcg) -> DVec3 {
    let spacing = 2.0 * BOX_HALF / LAYER_SIDE as f64;
    let (column, row, layer) = (
        i % LAYER_SIDE,
        i / LAYER_SIDE % LAYER_SIDE,
        i / (LAYER_SIDE * LAYER_SIDE),
    );
    let jitter = DVec3::new(
        rng.random_range(-0.01..0.01),
        rng.random_range(-0.01..0.01),
        0.0,
    );
    DVec3::new(
        -BOX_HALF + (column as f64 + 0.5) * spacing,
        -BOX_HALF + (row as f64 + 0.5) * spacing,
        0.1 + layer as f64 * LAYER_SPACING_M,
    ) + jitter
}

/// The simulation of `spec` (from [`pile_scene`]) whose bodies got daemon ids `ids`: the
/// static bodies as walls, the others falling, each with a small spin of its own (the
/// same for the same `seed`).
#[must_use]
pub fn pile_world(spec: &SceneSpec, ids: &[u32], seed: u64) -> World {
    let mut rng = Pcg64Mcg::seed_from_u64(seed.wrapping_add(1));
    let mut world = World::new(PILE_SOLVER);
    for (body, &id) in spec.bodies.iter().zip(ids) {
        if body.motion == Motion::Static {
            world.add_static(id);
        } else {
            let spin = random_unit(&mut rng) * rng.random_range(0.0..2.0);
            world.add_moving(id, body.position, body.orientation, spin);
        }
    }
    world
}

/// The floor and four walls around the box's inside, `[−BOX_HALF, BOX_HALF]²` from the
/// floor at `z = 0` up to [`WALL_HEIGHT`].
pub fn add_box(spec: &mut SceneSpec) {
    let (t, h) = (WALL_HALF_THICKNESS, WALL_HEIGHT / 2.0);
    let outer = BOX_HALF + 2.0 * t;
    let cuboid = |x, y, z| {
        ShapeSpec::Primitive(Primitive::Cuboid {
            half_extents: [x, y, z],
        })
    };
    let floor = spec.add_shape(cuboid(outer, outer, t));
    let wall_x = spec.add_shape(cuboid(t, BOX_HALF, h));
    let wall_y = spec.add_shape(cuboid(outer, t, h));
    for (shape, at) in [
        (floor, DVec3::new(0.0, 0.0, -t)),
        (wall_x, DVec3::new(-BOX_HALF - t, 0.0, h)),
        (wall_x, DVec3::new(BOX_HALF + t, 0.0, h)),
        (wall_y, DVec3::new(0.0, -BOX_HALF - t, h)),
        (wall_y, DVec3::new(0.0, BOX_HALF + t, h)),
    ] {
        spec.add_body(BodyPlan {
            shape,
            position: at,
            orientation: DQuat::IDENTITY,
            motion: Motion::Static,
            margin_m: MARGIN_M,
        });
    }
}

/// A shape of kind `kind` (0 sphere, 1 capsule, 2 box, 3 cylinder, 4 convex hull) whose
/// largest extent is `size`.
fn random_shape(rng: &mut Pcg64Mcg, kind: usize, size: f64) -> ShapeSpec {
    let half = size / 2.0;
    match kind {
        0 => ShapeSpec::Primitive(Primitive::Sphere { radius: half }),
        1 => {
            let radius = half * 0.7 * share(rng);
            ShapeSpec::Primitive(Primitive::Capsule {
                radius,
                half_height: half - radius,
            })
        }
        2 => ShapeSpec::Primitive(Primitive::Cuboid {
            half_extents: [half, half * share(rng), half * share(rng)],
        }),
        3 => {
            // Either the height or the diameter is the largest extent.
            let (a, b) = (share(rng), 1.0);
            let (radius, half_height) = if rng.random_bool(0.5) {
                (half * a, half * b)
            } else {
                (half * b, half * a)
            };
            ShapeSpec::Primitive(Primitive::Cylinder {
                radius,
                half_height,
            })
        }
        _ => {
            // Points in an ellipsoid with one semi-axis `half`, one on each end of it.
            let axes = DVec3::new(half, half * share(rng), half * share(rng));
            let count = rng.random_range(20..=60);
            let mut points = vec![DVec3::X * half, -DVec3::X * half];
            while points.len() < count {
                let p = random_unit(rng) * rng.random_range(0.5..1.0);
                points.push(p * axes);
            }
            ShapeSpec::Convex(points)
        }
    }
}

/// A share of the largest extent for a shorter one.
fn share(rng: &mut Pcg64Mcg) -> f64 {
    rng.random_range(0.4..1.0)
}

/// A unit vector, uniform over the sphere.
fn random_unit(rng: &mut Pcg64Mcg) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let length = v.length();
        if (1e-3..=1.0).contains(&length) {
            return v / length;
        }
    }
}

/// A rotation, uniform over all rotations.
pub fn random_orientation(rng: &mut Pcg64Mcg) -> DQuat {
    loop {
        let q = DQuat::from_xyzw(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let length = q.length();
        if (1e-3..=1.0).contains(&length) {
            return q / length;
        }
    }
}
