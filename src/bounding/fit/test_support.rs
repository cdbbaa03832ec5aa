//! Seeded generators for the unit tests of the oriented volumes (a small in-crate mirror of
//! `tests/support`, which unit tests cannot include).
#![allow(dead_code)]

use crate::math::{DQuat, DVec3, Isometry, Pose};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

pub type TestRng = Pcg64Mcg;

pub fn rng(seed: u64) -> TestRng {
    TestRng::seed_from_u64(seed)
}

/// Uniform in `[-half, half]³`.
pub fn point_in_cube(rng: &mut TestRng, half: f64) -> DVec3 {
    DVec3::new(
        rng.random_range(-half..=half),
        rng.random_range(-half..=half),
        rng.random_range(-half..=half),
    )
}

/// A uniformly distributed rotation (Shoemake).
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

pub fn isometry(rng: &mut TestRng, half: f64) -> Isometry {
    Pose::new(point_in_cube(rng, half), rotation(rng)).to_isometry()
}

/// Centres up to 1e6 from the origin and sizes 1e-4..1e4, as in `tests/support`.
pub const CENTERS: [f64; 4] = [0.0, 1.0, 1e3, 1e6];
pub const SCALES: [f64; 5] = [1e-4, 1e-2, 1.0, 1e2, 1e4];

/// A cloud of `n` points of kind `kind % 7` (box, sphere, single, duplicates, collinear,
/// coplanar, needle) around `center`, of size `scale`, randomly rotated.
pub fn cloud(rng: &mut TestRng, kind: usize, n: usize, center: DVec3, scale: f64) -> Vec<DVec3> {
    let rot = rotation(rng);
    let half = DVec3::new(
        rng.random_range(0.1..1.0),
        rng.random_range(0.1..1.0),
        rng.random_range(0.1..1.0),
    );
    let distinct: Vec<DVec3> = (0..4).map(|_| point_in_cube(rng, 1.0)).collect();
    (0..n.max(1))
        .map(|i| {
            let p = match kind % 7 {
                0 => point_in_cube(rng, 1.0) * half,
                1 => point_in_cube(rng, 1.0).normalize_or(DVec3::X),
                2 => DVec3::ZERO,
                3 => distinct[i % 4],
                4 => DVec3::X * rng.random_range(-1.0..1.0),
                5 => DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                ),
                _ => DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1e-3..1e-3),
                    rng.random_range(-1e-3..1e-3),
                ),
            };
            center + rot * (p * scale)
        })
        .collect()
}

/// A point of the convex hull of `points`: a random convex combination of four of them.
pub fn point_in_hull(rng: &mut TestRng, points: &[DVec3]) -> DVec3 {
    let base = points[0];
    let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
    for _ in 0..4 {
        let w: f64 = rng.random::<f64>() + 1e-3;
        sum += (points[rng.random_range(0..points.len())] - base) * w;
        weight += w;
    }
    base + sum / weight
}
