//! Shared generators for integration tests: a seeded PRNG, random rotations and poses, and
//! point sets that include the degenerate cases every geometric test must survive.
//!
//! Include with `mod support;` from a test file. Items unused by one test file are allowed.
#![allow(dead_code)]

use proxima::math::{DQuat, DVec3, Isometry, Pose};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

pub mod meshes;

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

// ---- Procedural triangle meshes (BVH tests) ----

use proxima::geometry::Triangle;

/// A UV sphere of `radius` about the origin: `rings ≥ 2` bands from pole to pole, `segments
/// ≥ 3` around; the pole bands are fans, so there are `2 · segments · (rings - 1)`
/// triangles and none has zero area.
pub fn uv_sphere(rings: usize, segments: usize, radius: f64) -> Vec<Triangle> {
    let (rings, segments) = (rings.max(2), segments.max(3));
    let point = |ring: usize, seg: usize| {
        let theta = std::f64::consts::PI * ring as f64 / rings as f64;
        let phi = std::f64::consts::TAU * (seg % segments) as f64 / segments as f64;
        DVec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        ) * radius
    };
    let mut triangles = Vec::new();
    for ring in 0..rings {
        for seg in 0..segments {
            let (a, b) = (point(ring, seg), point(ring, seg + 1));
            let (c, d) = (point(ring + 1, seg), point(ring + 1, seg + 1));
            if ring != 0 {
                triangles.push(Triangle::new(a, c, b));
            }
            if ring != rings - 1 {
                triangles.push(Triangle::new(b, c, d));
            }
        }
    }
    triangles
}

/// A torus about the z axis: tube of radius `minor` around a circle of radius `major`,
/// `2 · around · across` triangles.
pub fn torus(around: usize, across: usize, major: f64, minor: f64) -> Vec<Triangle> {
    let (around, across) = (around.max(3), across.max(3));
    let point = |i: usize, j: usize| {
        let u = std::f64::consts::TAU * (i % around) as f64 / around as f64;
        let v = std::f64::consts::TAU * (j % across) as f64 / across as f64;
        let r = major + minor * v.cos();
        DVec3::new(r * u.cos(), r * u.sin(), minor * v.sin())
    };
    let mut triangles = Vec::with_capacity(2 * around * across);
    for i in 0..around {
        for j in 0..across {
            let (a, b) = (point(i, j), point(i + 1, j));
            let (c, d) = (point(i, j + 1), point(i + 1, j + 1));
            triangles.push(Triangle::new(a, b, d));
            triangles.push(Triangle::new(a, d, c));
        }
    }
    triangles
}

/// `n` independent random triangles: centres uniform in `[-half, half]³`, vertices within
/// `size` of their centre (an unwelded soup with overlaps and slivers).
pub fn triangle_soup(rng: &mut TestRng, n: usize, half: f64, size: f64) -> Vec<Triangle> {
    (0..n)
        .map(|_| {
            let c = point_in_cube(rng, half);
            Triangle::new(
                c + point_in_cube(rng, size),
                c + point_in_cube(rng, size),
                c + point_in_cube(rng, size),
            )
        })
        .collect()
}

/// A flat `nx × ny` grid of unit cells in the plane `z = 0`, two triangles per cell: every
/// triangle coplanar, many merged volumes of exactly equal size.
pub fn flat_grid(nx: usize, ny: usize) -> Vec<Triangle> {
    let p = |x: usize, y: usize| DVec3::new(x as f64, y as f64, 0.0);
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for x in 0..nx {
        for y in 0..ny {
            triangles.push(Triangle::new(p(x, y), p(x + 1, y), p(x + 1, y + 1)));
            triangles.push(Triangle::new(p(x, y), p(x + 1, y + 1), p(x, y + 1)));
        }
    }
    triangles
}

/// `n` zero-area triangles in the cube `[-half, half]³`: alternately all three vertices at
/// one point, and three collinear points (one repeated every third time).
pub fn zero_area_triangles(rng: &mut TestRng, n: usize, half: f64) -> Vec<Triangle> {
    (0..n)
        .map(|i| {
            let p = point_in_cube(rng, half);
            let d = point_in_cube(rng, half * 0.1);
            match i % 3 {
                0 => Triangle::new(p, p, p),
                1 => Triangle::new(p, p + d, p + 2.5 * d),
                _ => Triangle::new(p, p + d, p),
            }
        })
        .collect()
}

/// `triangles` scaled by `scale` about the origin, then moved by `offset`.
pub fn scaled_and_moved(triangles: &[Triangle], scale: f64, offset: DVec3) -> Vec<Triangle> {
    let f = |p: DVec3| p * scale + offset;
    triangles
        .iter()
        .map(|t| Triangle::new(f(t.a), f(t.b), f(t.c)))
        .collect()
}
