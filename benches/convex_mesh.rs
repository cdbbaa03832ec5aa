//! A convex shape against a triangle mesh, Proxima against parry3d-f64 0.31 on the same
//! shapes and poses: the pairs that dominate `falling_bodies` (spheres, capsules and boxes
//! against its tori).
//!
//! # Inputs
//! - Meshes: the `falling_bodies` torus (major radius 0.3 m, minor 0.1 m, 16 × 8 quads, 256
//!   triangles) and a finer one (64 × 32 quads, 4,096 triangles).
//! - Shapes, `falling_bodies`' own: a sphere of radius 0.2 m, a capsule of radius 0.12 m and
//!   half height 0.2 m, a cube of half extent 0.18 m.
//! - [`POSES`] poses per shape and mesh, seeded ([`SEED`]): a uniform rotation, the centre
//!   at a uniform point within 0.4 m of a uniform point of the torus's centre circle, kept
//!   when Proxima's signed distance is within [-[`DEEPEST`], [`PREDICTION`]] (the pairs a
//!   pile touches or nearly touches, where the walk does its work), at least a third of
//!   them touching and a quarter apart.
//!
//! # What is measured (group `convex_mesh`)
//! - `proxima/<shape>-<mesh>`: `dispatch::distance` with the limit [`PREDICTION`] (the
//!   pipeline's query for a `CLOSE` pair with 2 cm margins): the signed distance, exact
//!   within the limit.
//! - `parry/<shape>-<mesh>`: `parry3d_f64::query::contact` with the same prediction.
//!
//! Before timing, both answer every pose and the agreement is printed: the poses each
//! reports within the prediction, and the largest distance difference where both report
//! one (both treat the mesh as a surface). Spheres and boxes agree to rounding (4e-16 m);
//! capsules differ by up to 2e-8 m: parry meets a capsule and a triangle by GJK, to its
//! tolerance, where Proxima has a closed form.
//!
//! `cargo bench --bench convex_mesh`

#[path = "common/cycle.rs"]
mod cycle;
#[path = "common/parry_convert.rs"]
mod parry_convert;
#[path = "../tests/support/mod.rs"]
mod support;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cycle::cycle_bench;
use parry_convert::{parry_mesh, parry_pose};
use parry3d_f64::math::Pose as ParryPose;
use parry3d_f64::shape::SharedShape;
use proxima::geometry::{Capsule, Cuboid, Sphere, TriMesh};
use proxima::math::{DVec3, Pose};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::{MeshShape, Shape};
use rand::Rng;
use std::f64::consts::TAU;
use std::sync::Arc;
use support::{TestRng, rotation};

/// Seed of the poses.
const SEED: u64 = 30;
/// Poses per shape and mesh.
const POSES: usize = 256;
/// The reporting limit of both engines, metres: two 2 cm margins.
const PREDICTION: f64 = 0.04;
/// The deepest penetration kept, metres.
const DEEPEST: f64 = 0.05;
/// Major and minor radius of the tori, metres.
const TORUS: (f64, f64) = (0.3, 0.1);

/// One shape in both engines' terms.
struct Convex {
    name: &'static str,
    shape: Shape,
    parry: SharedShape,
}

fn convex_shapes() -> Vec<Convex> {
    vec![
        Convex {
            name: "sphere",
            shape: Shape::Sphere(Sphere::new(0.2)),
            parry: SharedShape::ball(0.2),
        },
        Convex {
            name: "capsule",
            shape: Shape::Capsule(Capsule::new(0.2, 0.12)),
            parry: SharedShape::capsule_z(0.2, 0.12),
        },
        Convex {
            name: "box",
            shape: Shape::Cuboid(Cuboid::new(DVec3::splat(0.18))),
            parry: SharedShape::cuboid(0.18, 0.18, 0.18),
        },
    ]
}

/// A uniform point of the ball of radius `r` about the origin.
fn in_ball(rng: &mut TestRng, r: f64) -> DVec3 {
    loop {
        let p = DVec3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        if p.length_squared() <= 1.0 {
            return p * r;
        }
    }
}

/// [`POSES`] poses of `convex` (A) against `mesh` (B, at the origin), as the relative pose
/// `pose_ab` Proxima takes and parry's pair of poses; panics when the touching or the
/// apart ones are fewer than a quarter.
fn close_poses(
    convex: &Convex,
    mesh: &Shape,
    rng: &mut TestRng,
) -> Vec<(Pose, ParryPose, ParryPose)> {
    let mut scratch = NarrowScratch::default();
    let (mut poses, mut touching) = (Vec::new(), 0);
    while poses.len() < POSES {
        let angle = rng.random_range(0.0..TAU);
        let ring = DVec3::new(angle.cos(), angle.sin(), 0.0) * TORUS.0;
        let pose_a = Pose::new(ring + in_ball(rng, 0.4), rotation(rng));
        let pose_ab = Pose::relative(&pose_a, &Pose::IDENTITY);
        let d = dispatch::distance(&convex.shape, mesh, &pose_ab, PREDICTION, &mut scratch);
        if !(-DEEPEST..=PREDICTION).contains(&d.distance) {
            continue;
        }
        touching += usize::from(d.distance <= 0.0);
        poses.push((pose_ab, parry_pose(&pose_a), parry_pose(&Pose::IDENTITY)));
    }
    assert!(
        touching >= POSES / 4 && POSES - touching >= POSES / 4,
        "{}: {touching} of {POSES} touching",
        convex.name
    );
    poses
}

fn bench(c: &mut Criterion) {
    let mut rng = support::rng(SEED);
    let meshes = [("torus256", 16, 8), ("torus4096", 64, 32)].map(|(name, around, across)| {
        let mesh = TriMesh::torus(TORUS.0, TORUS.1, around, across);
        let parry = SharedShape::new(parry_mesh(&mesh));
        (name, Shape::Mesh(Arc::new(MeshShape::new(mesh))), parry)
    });
    let mut group = c.benchmark_group("convex_mesh");
    for convex in convex_shapes() {
        for (mesh_name, mesh, parry_mesh) in &meshes {
            let poses = close_poses(&convex, mesh, &mut rng);
            let mut scratch = NarrowScratch::default();
            let (mut ours, mut theirs, mut both, mut largest) = (0, 0, 0, 0.0_f64);
            for (pose_ab, pa, pb) in &poses {
                let d = dispatch::distance(&convex.shape, mesh, pose_ab, PREDICTION, &mut scratch);
                let p =
                    parry3d_f64::query::contact(pa, &*convex.parry, pb, &**parry_mesh, PREDICTION)
                        .expect("parry supports a convex shape against a mesh")
                        .map(|contact| contact.dist);
                ours += usize::from(d.distance <= PREDICTION);
                theirs += usize::from(p.is_some());
                if let Some(p) = p {
                    both += 1;
                    largest = largest.max((p - d.distance).abs());
                }
            }
            let name = format!("{}-{mesh_name}", convex.name);
            println!(
                "convex_mesh/{name}: within prediction: proxima {ours}, parry {theirs}, both {both}; largest |distance difference| {largest:.3e} m"
            );
            cycle_bench(
                &mut group,
                BenchmarkId::new("proxima", &name),
                &poses,
                |_, (pose_ab, _, _)| {
                    dispatch::distance(&convex.shape, mesh, pose_ab, PREDICTION, &mut scratch)
                        .distance
                },
            );
            cycle_bench(
                &mut group,
                BenchmarkId::new("parry", &name),
                &poses,
                |_, (_, pa, pb)| {
                    parry3d_f64::query::contact(pa, &*convex.parry, pb, &**parry_mesh, PREDICTION)
                        .ok()
                        .flatten()
                        .map_or(f64::INFINITY, |contact| contact.dist)
                },
            );
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
