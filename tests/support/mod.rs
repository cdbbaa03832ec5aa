//! Shared generators for integration tests: a seeded PRNG, random rotations and poses, and
//! point sets that include the degenerate cases every geometric test must survive.
//! Procedural triangle meshes live in [`meshes`].
//!
//! Include with `mod support;` from a test file; the crate's unit tests reach the same module
//! as `crate::test_support` (see `src/lib.rs`). Items unused by one test file are allowed.
#![allow(dead_code)]

use proxima::geometry::{Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, Sphere, SupportMap};
use proxima::math::{DQuat, DVec3, Isometry, Pose};
use proxima::narrow::Shape;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::sync::Arc;

pub mod data;
pub mod meshes;
pub mod pair_queries;
pub mod triangle_pairs;

/// The minimum of a convex function on `[0, 1]` by golden-section search (120 steps, to
/// rounding), the ends included: the brute-force oracle of a distance along a segment to a
/// convex set, which needs only the set's point closest-point function.
pub fn convex_minimum_on_unit_interval(f: impl Fn(f64) -> f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..120 {
        let (m1, m2) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        if f(m1) <= f(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    f(0.0).min(f(1.0)).min(f((lo + hi) / 2.0))
}

/// The PRNG every test uses, always seeded explicitly.
pub type TestRng = Pcg64Mcg;

/// A PRNG from a seed.
pub fn rng(seed: u64) -> TestRng {
    TestRng::seed_from_u64(seed)
}

/// A uniform point in the cube `[-half, half]³`.
pub fn point_in_cube(rng: &mut TestRng, half: f64) -> DVec3 {
    DVec3::new(
        rng.random_range(-half..=half),
        rng.random_range(-half..=half),
        rng.random_range(-half..=half),
    )
}

/// A uniformly distributed rotation (Shoemake's method).
pub fn rotation(rng: &mut TestRng) -> DQuat {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (s1, s2) = ((1.0 - u1).sqrt(), u1.sqrt());
    let tau = std::f64::consts::TAU;
    DQuat::from_xyzw(
        s1 * (tau * u2).sin(),
        s1 * (tau * u2).cos(),
        s2 * (tau * u3).sin(),
        s2 * (tau * u3).cos(),
    )
    .normalize()
}

/// A random pose with its translation in `[-half, half]³`.
pub fn pose(rng: &mut TestRng, half: f64) -> Pose {
    Pose::new(point_in_cube(rng, half), rotation(rng))
}

/// A random isometry with its translation in `[-half, half]³`.
pub fn isometry(rng: &mut TestRng, half: f64) -> Isometry {
    pose(rng, half).to_isometry()
}

/// The gap between A's support plane along the unit `n` (A's frame, pointing A→B) and B's
/// along `−n`, B placed by `pose_ab`: a lower bound of the distance for every `n`, equal to
/// it along the pair's true normal.
pub fn support_gap<A, B>(a: &A, b: &B, pose_ab: &Isometry, n: DVec3) -> f64
where
    A: SupportMap + ?Sized,
    B: SupportMap + ?Sized,
{
    n.dot(pose_ab.transform_point(b.support(pose_ab.inverse_transform_vector(-n))) - a.support(n))
}

/// A random cylinder of the pile's sizes (radius 3–30 mm, half-height 5–30 mm).
pub fn random_cylinder(r: &mut TestRng) -> Cylinder {
    Cylinder::new(r.random_range(0.003..0.03), r.random_range(0.005..0.03))
}

/// A random pose of B around cylinder A: B's centre at a random point of A's rim (either
/// cap), pushed out along a random direction of the rim's normal cone by B's size `b_size`
/// (metres) times 0.5–1.3, so that B is near the rim, apart or overlapping, with a random
/// rotation.
pub fn around_the_rim(r: &mut TestRng, a: &Cylinder, b_size: f64) -> Isometry {
    let theta = r.random_range(0.0..std::f64::consts::TAU);
    let cap = if r.random_bool(0.5) { 1.0 } else { -1.0 };
    let radial = DVec3::new(theta.cos(), theta.sin(), 0.0);
    let rim = radial * a.radius + DVec3::Z * (cap * a.half_height);
    let phi = r.random_range(0.0..std::f64::consts::FRAC_PI_2);
    let out = radial * phi.cos() + DVec3::Z * (cap * phi.sin());
    let reach = b_size * r.random_range(0.5..1.3);
    Isometry::new(
        proxima::math::DMat3::from_quat(rotation(r)),
        rim + out * reach,
    )
}

/// The shapes of point cloud every fit and hull test runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CloudKind {
    /// Uniform in a box with random proportions.
    Box,
    /// On a sphere's surface.
    Sphere,
    /// One point.
    Single,
    /// A few distinct points, each repeated many times.
    Duplicates,
    /// All on one line.
    Collinear,
    /// All on one plane.
    Coplanar,
    /// A needle: long along one axis, thin across.
    Needle,
}

impl CloudKind {
    /// Every kind.
    pub const ALL: [CloudKind; 7] = [
        CloudKind::Box,
        CloudKind::Sphere,
        CloudKind::Single,
        CloudKind::Duplicates,
        CloudKind::Collinear,
        CloudKind::Coplanar,
        CloudKind::Needle,
    ];
}

/// `n ≥ 1` points of the given kind, around `center`, of size about `scale`, randomly
/// rotated.
pub fn cloud(
    rng: &mut TestRng,
    kind: CloudKind,
    n: usize,
    center: DVec3,
    scale: f64,
) -> Vec<DVec3> {
    let n = n.max(1);
    let rot = rotation(rng);
    let local: Vec<DVec3> = match kind {
        CloudKind::Box => {
            let half = DVec3::new(
                rng.random_range(0.1..1.0),
                rng.random_range(0.1..1.0),
                rng.random_range(0.1..1.0),
            );
            (0..n).map(|_| point_in_cube(rng, 1.0) * half).collect()
        }
        CloudKind::Sphere => (0..n)
            .map(|_| point_in_cube(rng, 1.0).normalize_or(DVec3::X))
            .collect(),
        CloudKind::Single => vec![DVec3::ZERO; 1],
        CloudKind::Duplicates => {
            let distinct: Vec<DVec3> = (0..4).map(|_| point_in_cube(rng, 1.0)).collect();
            (0..n).map(|i| distinct[i % distinct.len()]).collect()
        }
        CloudKind::Collinear => (0..n)
            .map(|_| DVec3::X * rng.random_range(-1.0..1.0))
            .collect(),
        CloudKind::Coplanar => (0..n)
            .map(|_| {
                DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                )
            })
            .collect(),
        CloudKind::Needle => (0..n)
            .map(|_| {
                DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1e-3..1e-3),
                    rng.random_range(-1e-3..1e-3),
                )
            })
            .collect(),
    };
    local
        .into_iter()
        .map(|p| center + rot * (p * scale))
        .collect()
}

/// The offsets and scales of the degenerate-input matrix: centres up to 1e6 from the origin,
/// sizes from 1e-4 to 1e4.
pub const CENTERS: [f64; 4] = [0.0, 1.0, 1e3, 1e6];
/// See [`CENTERS`].
pub const SCALES: [f64; 5] = [1e-4, 1e-2, 1.0, 1e2, 1e4];

/// One random cloud from the degenerate-input matrix: a random [`CloudKind`], centre at a
/// random direction times one of [`CENTERS`], size one of [`SCALES`], `1..=max_n` points.
/// Returns the points and the scale (metres).
pub fn random_cloud(rng: &mut TestRng, max_n: usize) -> (Vec<DVec3>, f64) {
    let kind = CloudKind::ALL[rng.random_range(0..CloudKind::ALL.len())];
    let center = rotation(rng) * DVec3::X * CENTERS[rng.random_range(0..CENTERS.len())];
    let scale = SCALES[rng.random_range(0..SCALES.len())];
    let n = rng.random_range(1..=max_n.max(1));
    (cloud(rng, kind, n, center, scale), scale)
}

/// `n` unit directions spread evenly over the sphere (a Fibonacci lattice).
pub fn sphere_directions(n: usize) -> Vec<DVec3> {
    let golden = std::f64::consts::PI * (3.0 - 5.0_f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let ring = (1.0 - z * z).sqrt();
            let angle = golden * i as f64;
            DVec3::new(ring * angle.cos(), ring * angle.sin(), z)
        })
        .collect()
}

/// The smallest distance between two point sets (brute force over all pairs); infinite if
/// either is empty.
pub fn min_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .flat_map(|p| b.iter().map(move |q| p.distance(*q)))
        .fold(f64::INFINITY, f64::min)
}

/// One of the first `kinds` convex kinds (box, ball, capsule, cylinder, cone, hull of 12
/// points), each size a uniform fraction 0.2–1 of `scale`.
pub fn random_convex(rng: &mut TestRng, scale: f64, kinds: usize) -> Shape {
    let mut size = || rng.random_range(0.2..1.0) * scale;
    let (p, q, r) = (size(), size(), size());
    match rng.random_range(0..kinds) {
        0 => Shape::Cuboid(Cuboid::new(DVec3::new(p, q, r))),
        1 => Shape::Sphere(Sphere::new(p)),
        2 => Shape::Capsule(Capsule::new(p, q * 0.5)),
        3 => Shape::Cylinder(Cylinder::new(p, q)),
        4 => Shape::Cone(Cone::new(p, q)),
        _ => {
            let points: Vec<DVec3> = (0..12).map(|_| point_in_cube(rng, scale)).collect();
            Shape::Convex(Arc::new(
                ConvexPolyhedron::try_from_points(&points).unwrap(),
            ))
        }
    }
}
