//! Narrow-phase pair queries, Proxima against parry3d-f64 0.31, on the same shapes and the
//! same relative poses: mean time per query.
//!
//! # Inputs
//! Everything is generated before timing from a fixed seed. For each pair of shapes, poses
//! `pose_ab` (a uniform rotation, a translation of uniform direction and uniform length up
//! to a reach that straddles contact) are drawn and sorted by Proxima's signed distance into
//! two cases of [`POSES`] poses each: `separated` (distance > 1 µm) and `penetrating`
//! (distance < −1 µm); grazing poses are dropped. parry gets the same quaternion and
//! translation as `pos12` (`pos1 = identity`, `pos2 = pose_ab`). Each timed iteration takes
//! the next pose of the case in order ([`cycle::cycle_bench`]).
//!
//! # What is compared
//! | query | Proxima (`proxima`, and for the convex hulls `proxima-accelerated`, `proxima-warm`) | parry (`parry`) |
//! |---|---|---|
//! | `sphere_sphere`, `sphere_capsule`, `capsule_capsule`, `sphere_cuboid`, `capsule_cuboid`, `cuboid_cuboid`, and against one triangle of a mesh's size `sphere_triangle`, `capsule_triangle`, `cuboid_triangle` | the closed-form `proxima::narrow::distance_X_Y`: signed distance, witnesses and normal under the contact contract, for both cases | `separated`: `query::distance`; `penetrating`: `query::contact` with prediction 0 (depth, points, normal), each parry's dedicated pair routine where it has one, GJK/EPA otherwise |
//! | `capsule_capsule`, `capsule_cuboid`, `cuboid_cuboid` (`proxima-bound`) | `distance_bound_X_Y` (no limit): the bounds the pipeline answers with past a frame's deadline, on the same poses; checked to hold the exact distance before timing | — (parry has no bound query; its exact query is the comparison) |
//! | `cuboid_cuboid_manifold` | [`manifold_cuboid_cuboid`]: up to 4 points, clipped faces (empty when apart) | `PersistentQueryDispatcher::contact_manifold_convex_convex` with prediction 0 into one reused `ContactManifold` (no contact reuse between unrelated poses: each is a fresh manifold computation, as `contact_manifolds` would do on a new pair) |
//! | `convex_distance/hullN` (separated poses) | [`gjk_distance`] on [`ConvexPolyhedron`] hulls of `N` = 8, 64, 512, 4,096 random points on the unit sphere: `proxima` plain GJK, `proxima-accelerated` with `GjkParams { accelerated: true, .. }`, `proxima-warm` plain with a [`GjkCache`] per pose kept across laps (the best case of frame-to-frame coherence); other runs use a fresh cache | `query::distance` on `ConvexPolyhedron::from_convex_hull` of the same points (GJK) |
//! | `convex_depth/hullN` (penetrating poses) | [`signed_distance_convex`] (GJK, then EPA on penetration), same three variants, one [`EpaWorkspace`] per bench | `query::contact` with prediction 0 (GJK, then EPA) |
//! | `curved_depth/cylinder_cylinder`, `curved_depth/cylinder_hull` (penetrating poses) | [`signed_distance_convex`] on a cylinder of radius 2 cm and height 6 cm against one of 1.5 cm and 4 cm, or against a hull of 40 random points in a 2.5 cm ball: EPA on a curved difference, the pile's slowest pairs; plain only | `query::contact` with prediction 0 (parry's cylinder stands on Y: turned onto Z by a fixed rotation in `pos12`) |
//!
//! Support maps differ: Proxima's hull climbs its vertex adjacency (a linear scan below
//! `HILL_CLIMB_MIN_VERTICES` vertices), parry's `ConvexPolyhedron` scans every vertex, so
//! the large hulls mostly measure that.
//!
//! Before timing, every query is run once per pose by both engines and the largest
//! disagreement is printed (distances for separated poses, depths for penetrating ones,
//! point counts and deepest point for the manifolds).
//!
//! `cargo bench --bench narrow_phase`; names are `narrow_phase/<query>/<engine>/<case>`.

#[path = "../tests/support/mod.rs"]
mod support;

#[path = "common/cycle.rs"]
mod cycle;

#[path = "common/parry_convert.rs"]
mod parry_convert;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cycle::cycle_bench;
use parry_convert::{parry_cylinder_offset, parry_pose, parry_vector};
use parry3d_f64::math::Pose as ParryPose;
use parry3d_f64::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use parry3d_f64::shape::{
    Ball as ParryBall, Capsule as ParryCapsule, ConvexPolyhedron as ParryHull,
    Cuboid as ParryCuboid, Cylinder as ParryCylinder, Shape as ParryShape,
    Triangle as ParryTriangle,
};
use proxima::geometry::{
    Capsule, ConvexPolyhedron, Cuboid, Cylinder, Sphere, SupportMap, Triangle,
};
use proxima::math::{DVec3, Isometry, Pose};
use proxima::narrow::gjk::EpaWorkspace;
use proxima::narrow::{
    DistanceBound, GjkCache, GjkParams, Manifold, Rounded, ShapeDistance,
    distance_bound_capsule_capsule, distance_bound_capsule_cuboid, distance_bound_cuboid_cuboid,
    distance_capsule_capsule, distance_capsule_cuboid, distance_capsule_triangle,
    distance_cuboid_cuboid, distance_cuboid_triangle, distance_sphere_capsule,
    distance_sphere_cuboid, distance_sphere_sphere, distance_sphere_triangle, gjk_distance,
    manifold_cuboid_cuboid, signed_distance_convex,
};
use rand::Rng;
use std::hint::black_box;
use support::TestRng;

const SEED: u64 = 0x5EED_7A11;
/// Poses per case (separated, penetrating).
const POSES: usize = 64;
/// Hull sizes of the GJK benches.
const HULL_POINTS: [usize; 4] = [8, 64, 512, 4096];
/// Signed distances within this of zero (metres) are grazing and dropped from both cases.
const GRAZING: f64 = 1e-6;

/// One case's poses, in both engines' types.
struct Poses {
    name: &'static str,
    proxima: Vec<Isometry>,
    parry: Vec<ParryPose>,
}

impl Poses {
    fn new(name: &'static str, poses: &[Pose]) -> Self {
        Self {
            name,
            proxima: poses.iter().map(Pose::to_isometry).collect(),
            parry: poses.iter().map(parry_pose).collect(),
        }
    }
}

/// [`POSES`] separated and [`POSES`] penetrating poses, by Proxima's `signed` distance:
/// uniform rotations, translations of uniform direction and length in `[0, reach]`.
///
/// # Panics
/// When 200,000 draws do not fill both cases (a reach that misses contact).
fn sorted_poses(
    rng: &mut TestRng,
    reach: f64,
    mut signed: impl FnMut(&Isometry) -> f64,
) -> [Poses; 2] {
    let (mut separated, mut penetrating) = (Vec::new(), Vec::new());
    for _ in 0..200_000 {
        if separated.len() == POSES && penetrating.len() == POSES {
            break;
        }
        let direction = support::rotation(rng) * DVec3::X;
        let length = reach * rng.random::<f64>();
        let pose = Pose::new(direction * length, support::rotation(rng));
        let d = signed(&pose.to_isometry());
        if d > GRAZING && separated.len() < POSES {
            separated.push(pose);
        } else if d < -GRAZING && penetrating.len() < POSES {
            penetrating.push(pose);
        }
    }
    assert!(
        separated.len() == POSES && penetrating.len() == POSES,
        "reach {reach}: {} separated, {} penetrating poses",
        separated.len(),
        penetrating.len()
    );
    [
        Poses::new("separated", &separated),
        Poses::new("penetrating", &penetrating),
    ]
}

/// parry's signed distance: `query::distance` when apart, `query::contact` (negative
/// `dist`) when penetrating.
fn parry_signed(a: &dyn ParryShape, b: &dyn ParryShape, pos12: &ParryPose, apart: bool) -> f64 {
    if apart {
        parry3d_f64::query::distance(&ParryPose::IDENTITY, a, pos12, b)
            .expect("parry supports the pair")
            .distance
    } else {
        parry3d_f64::query::contact(&ParryPose::IDENTITY, a, pos12, b, 0.0)
            .expect("parry supports the pair")
            .map_or(f64::INFINITY, |c| c.dist)
    }
}

/// Times one closed-form pair query of Proxima against parry on both cases, after printing
/// their largest disagreement.
fn bench_pair(
    c: &mut Criterion,
    rng: &mut TestRng,
    query: &str,
    reach: f64,
    proxima: impl Fn(&Isometry) -> ShapeDistance,
    bound: Option<&dyn Fn(&Isometry) -> DistanceBound>,
    (parry_a, parry_b): (&dyn ParryShape, &dyn ParryShape),
) {
    let cases = sorted_poses(rng, reach, |pose| proxima(pose).distance);
    let mut group = c.benchmark_group(format!("narrow_phase/{query}"));
    for case in &cases {
        let apart = case.name == "separated";
        if let Some(bound) = bound {
            check_bounds(query, case, &proxima, bound);
            cycle_bench(
                &mut group,
                BenchmarkId::new("proxima-bound", case.name),
                &case.proxima,
                |_, pose| bound(pose).lower,
            );
        }
        let worst = case
            .proxima
            .iter()
            .zip(&case.parry)
            .map(|(p, q)| (proxima(p).distance - parry_signed(parry_a, parry_b, q, apart)).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "narrow_phase/{query}/{}: largest |proxima − parry| signed distance: {worst:e} m",
            case.name
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("proxima", case.name),
            &case.proxima,
            |_, pose| proxima(pose).distance,
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("parry", case.name),
            &case.parry,
            |_, pos12| parry_signed(black_box(parry_a), black_box(parry_b), pos12, apart),
        );
    }
    group.finish();
}

/// Checks that `bound` holds `proxima`'s exact distance between its bounds on every pose of
/// `case` (to 1 nm), and prints the widest gap between them.
///
/// # Panics
/// When a bound misses the exact distance.
fn check_bounds(
    query: &str,
    case: &Poses,
    proxima: &impl Fn(&Isometry) -> ShapeDistance,
    bound: &dyn Fn(&Isometry) -> DistanceBound,
) {
    let mut widest = 0.0f64;
    for pose in &case.proxima {
        let (exact, b) = (proxima(pose).distance, bound(pose));
        assert!(
            b.lower <= exact + 1e-9 && exact <= b.upper + 1e-9,
            "{query}/{}: {b:?} misses {exact}",
            case.name
        );
        widest = widest.max(b.upper - b.lower);
    }
    eprintln!(
        "narrow_phase/{query}/{}: bounds hold the exact distance, widest gap {widest:e} m",
        case.name
    );
}

fn closed_form_pairs(c: &mut Criterion, rng: &mut TestRng) {
    let sphere = Sphere::new(0.5);
    let capsule = Capsule::new(0.6, 0.3);
    let (box_a, box_b) = (
        Cuboid::new(DVec3::new(0.6, 0.4, 0.3)),
        Cuboid::new(DVec3::new(0.5, 0.5, 0.2)),
    );
    let p_sphere = ParryBall::new(sphere.radius);
    let p_capsule = ParryCapsule::new_z(capsule.half_height, capsule.radius);
    let (p_box_a, p_box_b) = (
        ParryCuboid::new(parry_vector(box_a.half_extents)),
        ParryCuboid::new(parry_vector(box_b.half_extents)),
    );
    bench_pair(
        c,
        rng,
        "sphere_sphere",
        2.0,
        |p| distance_sphere_sphere(black_box(&sphere), black_box(&sphere), p),
        None,
        (&p_sphere, &p_sphere),
    );
    bench_pair(
        c,
        rng,
        "sphere_capsule",
        2.5,
        |p| distance_sphere_capsule(black_box(&sphere), black_box(&capsule), p),
        None,
        (&p_sphere, &p_capsule),
    );
    bench_pair(
        c,
        rng,
        "capsule_capsule",
        3.0,
        |p| distance_capsule_capsule(black_box(&capsule), black_box(&capsule), p),
        Some(&|p: &Isometry| {
            distance_bound_capsule_capsule(black_box(&capsule), black_box(&capsule), p)
        }),
        (&p_capsule, &p_capsule),
    );
    bench_pair(
        c,
        rng,
        "sphere_cuboid",
        2.5,
        |p| distance_sphere_cuboid(black_box(&sphere), black_box(&box_a), p),
        None,
        (&p_sphere, &p_box_a),
    );
    bench_pair(
        c,
        rng,
        "capsule_cuboid",
        3.0,
        |p| distance_capsule_cuboid(black_box(&capsule), black_box(&box_a), p),
        Some(&|p: &Isometry| {
            distance_bound_capsule_cuboid(black_box(&capsule), black_box(&box_a), p)
        }),
        (&p_capsule, &p_box_a),
    );
    bench_pair(
        c,
        rng,
        "cuboid_cuboid",
        2.5,
        |p| distance_cuboid_cuboid(black_box(&box_a), black_box(&box_b), p),
        Some(&|p: &Isometry| {
            distance_bound_cuboid_cuboid(black_box(&box_a), black_box(&box_b), p, f64::INFINITY)
        }),
        (&p_box_a, &p_box_b),
    );
    cuboid_manifolds(c, rng, (&box_a, &box_b), (&p_box_a, &p_box_b));
    triangle_pairs(
        c,
        rng,
        (&sphere, &capsule, &box_a),
        (&p_sphere, &p_capsule, &p_box_a),
    );
}

/// The ball, the capsule and the box against one triangle of a mesh's size: the
/// per-triangle queries of a convex shape's walk of a mesh.
fn triangle_pairs(
    c: &mut Criterion,
    rng: &mut TestRng,
    (sphere, capsule, cuboid): (&Sphere, &Capsule, &Cuboid),
    (p_sphere, p_capsule, p_cuboid): (&ParryBall, &ParryCapsule, &ParryCuboid),
) {
    let triangle = Triangle::new(
        DVec3::new(-0.4, -0.3, 0.0),
        DVec3::new(0.5, -0.2, 0.0),
        DVec3::new(0.0, 0.45, 0.0),
    );
    let p_triangle = ParryTriangle::new(
        parry_vector(triangle.a),
        parry_vector(triangle.b),
        parry_vector(triangle.c),
    );
    bench_pair(
        c,
        rng,
        "sphere_triangle",
        1.5,
        |p| distance_sphere_triangle(black_box(sphere), black_box(&triangle), p),
        None,
        (p_sphere, &p_triangle),
    );
    bench_pair(
        c,
        rng,
        "capsule_triangle",
        2.0,
        |p| distance_capsule_triangle(black_box(capsule), black_box(&triangle), p),
        None,
        (p_capsule, &p_triangle),
    );
    bench_pair(
        c,
        rng,
        "cuboid_triangle",
        2.0,
        |p| distance_cuboid_triangle(black_box(cuboid), black_box(&triangle), p),
        None,
        (p_cuboid, &p_triangle),
    );
}

/// parry's manifold of two cuboids into `manifold`; returns its point count.
fn parry_manifold(
    a: &ParryCuboid,
    b: &ParryCuboid,
    pos12: &ParryPose,
    manifold: &mut ContactManifold<(), ()>,
) -> usize {
    DefaultQueryDispatcher
        .contact_manifold_convex_convex(pos12, a, b, None, None, 0.0, manifold)
        .expect("parry supports cuboid–cuboid manifolds");
    manifold.points.len()
}

fn cuboid_manifolds(
    c: &mut Criterion,
    rng: &mut TestRng,
    (a, b): (&Cuboid, &Cuboid),
    (pa, pb): (&ParryCuboid, &ParryCuboid),
) {
    let cases = sorted_poses(rng, 2.5, |pose| distance_cuboid_cuboid(a, b, pose).distance);
    let (mut ours, mut theirs) = (Manifold::new(), ContactManifold::<(), ()>::new());
    let mut group = c.benchmark_group("narrow_phase/cuboid_cuboid_manifold");
    for case in &cases {
        let (mut count, mut parry_count, mut worst_depth) = (0, 0, 0.0f64);
        for (p, q) in case.proxima.iter().zip(&case.parry) {
            manifold_cuboid_cuboid(a, b, p, &mut ours);
            parry_manifold(pa, pb, q, &mut theirs);
            count += ours.len();
            parry_count += theirs.points.len();
            let deepest = ours.points().iter().map(|m| m.distance).fold(0.0, f64::min);
            let parry_deepest = theirs.points.iter().map(|m| m.dist).fold(0.0, f64::min);
            worst_depth = worst_depth.max((deepest - parry_deepest).abs());
        }
        eprintln!(
            "narrow_phase/cuboid_cuboid_manifold/{}: points over all poses: proxima {count}, \
             parry {parry_count}; largest |deepest point − parry deepest|: {worst_depth:e} m",
            case.name
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("proxima", case.name),
            &case.proxima,
            |_, pose| {
                manifold_cuboid_cuboid(black_box(a), black_box(b), pose, &mut ours);
                ours.len() as f64
            },
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("parry", case.name),
            &case.parry,
            |_, pos12| parry_manifold(black_box(pa), black_box(pb), pos12, &mut theirs) as f64,
        );
    }
    group.finish();
}

/// `n` uniform random points on the unit sphere.
fn sphere_points(rng: &mut TestRng, n: usize) -> Vec<DVec3> {
    (0..n).map(|_| support::rotation(rng) * DVec3::Z).collect()
}

/// The Proxima variants of the convex benches: name, parameters, warm start.
const VARIANTS: [(&str, bool, bool); 3] = [
    ("proxima", false, false),
    ("proxima-accelerated", true, false),
    ("proxima-warm", false, true),
];

fn convex_hulls(c: &mut Criterion, rng: &mut TestRng) {
    let mut distance = c.benchmark_group("narrow_phase/convex_distance");
    let mut hulls = Vec::new();
    for n in HULL_POINTS {
        let (pts_a, pts_b) = (sphere_points(rng, n), sphere_points(rng, n));
        let a = ConvexPolyhedron::try_from_points(&pts_a).expect("points on a sphere");
        let b = ConvexPolyhedron::try_from_points(&pts_b).expect("points on a sphere");
        let pa = ParryHull::from_convex_hull(
            &pts_a.iter().map(|&p| parry_vector(p)).collect::<Vec<_>>(),
        )
        .expect("parry builds the hull");
        let pb = ParryHull::from_convex_hull(
            &pts_b.iter().map(|&p| parry_vector(p)).collect::<Vec<_>>(),
        )
        .expect("parry builds the hull");
        let mut workspace = EpaWorkspace::default();
        let cases = sorted_poses(rng, 2.5, |pose| {
            signed(
                &a,
                &b,
                pose,
                &GjkParams::default(),
                &mut GjkCache::default(),
                &mut workspace,
            )
        });
        hulls.push((format!("hull{n}"), a, b, pa, pb, cases));
    }
    for (name, a, b, pa, pb, [separated, _]) in &hulls {
        let worst = |accelerated: bool| {
            let params = GjkParams {
                accelerated,
                ..GjkParams::default()
            };
            separated
                .proxima
                .iter()
                .zip(&separated.parry)
                .map(|(p, q)| {
                    let ours = gjk_distance(a, b, p, &params, &mut GjkCache::default()).distance;
                    (ours - parry_signed(pa, pb, q, true)).abs()
                })
                .fold(0.0, f64::max)
        };
        let mean_iterations = |accelerated: bool| {
            let params = GjkParams {
                accelerated,
                ..GjkParams::default()
            };
            let total: u32 = separated
                .proxima
                .iter()
                .map(|p| gjk_distance(a, b, p, &params, &mut GjkCache::default()).iterations)
                .sum();
            f64::from(total) / separated.proxima.len() as f64
        };
        eprintln!(
            "narrow_phase/convex_distance/{name}: largest |proxima − parry| distance: plain \
             {:e} m, accelerated {:e} m; mean GJK iterations: plain {:.2}, accelerated {:.2}",
            worst(false),
            worst(true),
            mean_iterations(false),
            mean_iterations(true)
        );
        for (engine, accelerated, warm) in VARIANTS {
            let params = GjkParams {
                accelerated,
                ..GjkParams::default()
            };
            let mut caches = vec![GjkCache::default(); separated.proxima.len()];
            cycle_bench(
                &mut distance,
                BenchmarkId::new(engine, name),
                &separated.proxima,
                |i, pose| {
                    let mut fresh = GjkCache::default();
                    let cache = if warm { &mut caches[i] } else { &mut fresh };
                    gjk_distance(black_box(a), black_box(b), pose, &params, cache).distance
                },
            );
        }
        cycle_bench(
            &mut distance,
            BenchmarkId::new("parry", name),
            &separated.parry,
            |_, pos12| parry_signed(black_box(pa), black_box(pb), pos12, true),
        );
    }
    distance.finish();
    let mut depth = c.benchmark_group("narrow_phase/convex_depth");
    for (name, a, b, pa, pb, [_, penetrating]) in &hulls {
        let mut workspace = EpaWorkspace::default();
        let worst = |accelerated: bool, workspace: &mut EpaWorkspace| {
            let params = GjkParams {
                accelerated,
                ..GjkParams::default()
            };
            penetrating
                .proxima
                .iter()
                .zip(&penetrating.parry)
                .map(|(p, q)| {
                    let ours = signed(a, b, p, &params, &mut GjkCache::default(), workspace);
                    (ours - parry_signed(pa, pb, q, false)).abs()
                })
                .fold(0.0, f64::max)
        };
        let (plain, fast) = (worst(false, &mut workspace), worst(true, &mut workspace));
        eprintln!(
            "narrow_phase/convex_depth/{name}: largest |proxima − parry| signed distance: \
             plain {plain:e} m, accelerated {fast:e} m"
        );
        for (engine, accelerated, warm) in VARIANTS {
            let params = GjkParams {
                accelerated,
                ..GjkParams::default()
            };
            let mut caches = vec![GjkCache::default(); penetrating.proxima.len()];
            cycle_bench(
                &mut depth,
                BenchmarkId::new(engine, name),
                &penetrating.proxima,
                |i, pose| {
                    let mut fresh = GjkCache::default();
                    let cache = if warm { &mut caches[i] } else { &mut fresh };
                    signed(
                        black_box(a),
                        black_box(b),
                        pose,
                        &params,
                        cache,
                        &mut workspace,
                    )
                },
            );
        }
        cycle_bench(
            &mut depth,
            BenchmarkId::new("parry", name),
            &penetrating.parry,
            |_, pos12| parry_signed(black_box(pa), black_box(pb), pos12, false),
        );
    }
    depth.finish();
}

/// Penetration of curved pairs (module docs' `curved_depth`): GJK then EPA, where EPA's
/// polytope must follow a cylinder's rim or side to the tolerance.
fn curved_pairs(c: &mut Criterion, rng: &mut TestRng) {
    let (big, small) = (Cylinder::new(0.03, 0.02), Cylinder::new(0.02, 0.015));
    let points: Vec<DVec3> = (0..40)
        .map(|_| support::rotation(rng) * DVec3::Z * (0.025 * rng.random::<f64>().cbrt()))
        .collect();
    let hull = ConvexPolyhedron::try_from_points(&points).expect("points in a ball");
    let parry_big = ParryCylinder::new(big.half_height, big.radius);
    let parry_small = ParryCylinder::new(small.half_height, small.radius);
    let parry_hull =
        ParryHull::from_convex_hull(&points.iter().map(|&p| parry_vector(p)).collect::<Vec<_>>())
            .expect("parry builds the hull");
    let cylinder_offset = parry_cylinder_offset();
    let mut group = c.benchmark_group("narrow_phase/curved_depth");
    let mut workspace = EpaWorkspace::default();
    let pairs: [(&str, &dyn SupportMap, &dyn ParryShape, bool); 2] = [
        ("cylinder_cylinder", &small, &parry_small, true),
        ("cylinder_hull", &hull, &parry_hull, false),
    ];
    for (name, b, parry_b, b_is_cylinder) in pairs {
        let [_, penetrating] = sorted_poses(rng, 0.06, |pose| {
            signed(
                &big,
                b,
                pose,
                &GjkParams::default(),
                &mut GjkCache::default(),
                &mut workspace,
            )
        });
        let pos12: Vec<ParryPose> = penetrating
            .proxima
            .iter()
            .map(|iso| {
                let pose = iso.to_pose();
                let b_frame = if b_is_cylinder {
                    cylinder_offset
                } else {
                    Pose::IDENTITY
                };
                parry_pose(&cylinder_offset.inverse().compose(&pose).compose(&b_frame))
            })
            .collect();
        let worst = penetrating
            .proxima
            .iter()
            .zip(&pos12)
            .map(|(p, q)| {
                let ours = signed(
                    &big,
                    b,
                    p,
                    &GjkParams::default(),
                    &mut GjkCache::default(),
                    &mut workspace,
                );
                (ours - parry_signed(&parry_big, parry_b, q, false)).abs()
            })
            .fold(0.0, f64::max);
        eprintln!(
            "narrow_phase/curved_depth/{name}: largest |proxima − parry| signed distance {worst:e} m"
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("proxima", name),
            &penetrating.proxima,
            |_, pose| {
                signed(
                    black_box(&big),
                    black_box(b),
                    pose,
                    &GjkParams::default(),
                    &mut GjkCache::default(),
                    &mut workspace,
                )
            },
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("parry", name),
            &pos12,
            |_, pos12| parry_signed(black_box(&parry_big), black_box(parry_b), pos12, false),
        );
    }
    group.finish();
}

/// Proxima's signed distance of two convex shapes (GJK, EPA on penetration).
fn signed<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    params: &GjkParams,
    cache: &mut GjkCache,
    workspace: &mut EpaWorkspace,
) -> f64 {
    let (a, b) = (Rounded::plain(a), Rounded::plain(b));
    signed_distance_convex(&a, &b, pose_ab, params, cache, workspace)
        .0
        .distance
}

fn narrow_phase(c: &mut Criterion) {
    let mut rng = support::rng(SEED);
    closed_form_pairs(c, &mut rng);
    convex_hulls(c, &mut rng);
    curved_pairs(c, &mut rng);
}

criterion_group!(benches, narrow_phase);
criterion_main!(benches);
