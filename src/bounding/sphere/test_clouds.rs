//! Seeded point clouds for the bounding-volume unit tests (shared with the AABB and k-DOP
//! tests): the degenerate-input matrix of `tests/support`, restated here because unit tests
//! cannot reach the integration-test helpers.

use crate::math::{DQuat, DVec3, Isometry, Pose};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// The PRNG of the unit tests.
pub type TestRng = Pcg64Mcg;

/// A PRNG from a seed.
pub fn rng(seed: u64) -> TestRng {
    TestRng::seed_from_u64(seed)
}

/// Centres up to 1e6 from the origin.
pub const CENTERS: [f64; 4] = [0.0, 1.0, 1e3, 1e6];
/// Sizes from 1e-4 to 1e4.
pub const SCALES: [f64; 5] = [1e-4, 1e-2, 1.0, 1e2, 1e4];

/// The cloud kinds, degenerate ones included.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Box,
    Sphere,
    Single,
    Duplicates,
    Collinear,
    Coplanar,
    Needle,
}

/// Every kind.
pub const KINDS: [Kind; 7] = [
    Kind::Box,
    Kind::Sphere,
    Kind::Single,
    Kind::Duplicates,
    Kind::Collinear,
    Kind::Coplanar,
    Kind::Needle,
];

/// A uniform point in `[-half, half]³`.
pub fn point_in_cube(rng: &mut TestRng, half: f64) -> DVec3 {
    DVec3::new(
        rng.random_range(-half..=half),
        rng.random_range(-half..=half),
        rng.random_range(-half..=half),
    )
}

/// A uniform random rotation (Shoemake).
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

/// A random isometry, translation in `[-half, half]³`.
pub fn isometry(rng: &mut TestRng, half: f64) -> Isometry {
    Pose::new(point_in_cube(rng, half), rotation(rng)).to_isometry()
}

/// `n >= 1` points of `kind` around `center`, of size about `scale`, randomly rotated.
pub fn cloud(rng: &mut TestRng, kind: Kind, n: usize, center: DVec3, scale: f64) -> Vec<DVec3> {
    let n = n.max(1);
    let rot = rotation(rng);
    let half = DVec3::new(
        rng.random_range(0.1..1.0),
        rng.random_range(0.1..1.0),
        rng.random_range(0.1..1.0),
    );
    let distinct: Vec<DVec3> = (0..4).map(|_| point_in_cube(rng, 1.0)).collect();
    let local: Vec<DVec3> = (0..n)
        .map(|i| match kind {
            Kind::Box => point_in_cube(rng, 1.0) * half,
            Kind::Sphere => point_in_cube(rng, 1.0).normalize_or(DVec3::X),
            Kind::Single => DVec3::ZERO,
            Kind::Duplicates => distinct[i % 4],
            Kind::Collinear => DVec3::X * rng.random_range(-1.0..1.0),
            Kind::Coplanar => DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                0.0,
            ),
            Kind::Needle => DVec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1e-3..1e-3),
                rng.random_range(-1e-3..1e-3),
            ),
        })
        .collect();
    local
        .into_iter()
        .map(|p| center + rot * (p * scale))
        .collect()
}

/// A cloud of random kind, size, offset (from [`CENTERS`]) and scale (from [`SCALES`]);
/// returns the points and the scale.
pub fn any_cloud(rng: &mut TestRng, max_n: usize) -> (Vec<DVec3>, f64) {
    let kind = KINDS[rng.random_range(0..KINDS.len())];
    let offset = CENTERS[rng.random_range(0..CENTERS.len())];
    let scale = SCALES[rng.random_range(0..SCALES.len())];
    let center = point_in_cube(rng, 1.0).normalize_or(DVec3::X) * offset;
    let n = rng.random_range(1..=max_n);
    (cloud(rng, kind, n, center, scale), scale)
}

/// The smallest distance between two point sets (brute force).
pub fn min_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
    a.iter()
        .flat_map(|p| b.iter().map(move |q| p.distance(*q)))
        .fold(f64::INFINITY, f64::min)
}
