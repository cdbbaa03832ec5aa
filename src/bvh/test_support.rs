//! Shared pieces of the BVH unit tests: a seeded triangle soup, the build presets and a
//! macro that runs a check for every volume type.

use super::BuildParams;
use crate::geometry::Triangle;
use crate::test_support::{TestRng, point_in_cube};

/// Runs `$check::<B>($args)` for every volume type a BVH is built with in tests.
macro_rules! for_each_volume {
    ($check:ident($($arg:expr),*)) => {
        $check::<$crate::bounding::Aabb>($($arg),*);
        $check::<$crate::bounding::Obb>($($arg),*);
        $check::<$crate::bounding::BoundingSphere>($($arg),*);
        $check::<$crate::bounding::Kdop18>($($arg),*);
        $check::<$crate::bounding::Lss>($($arg),*);
        $check::<$crate::bounding::Rss>($($arg),*);
    };
}

pub(crate) const PRESETS: [BuildParams; 4] = [
    BuildParams::MEDIAN,
    BuildParams::MEAN_VARIANCE,
    BuildParams::BINNED_SAH,
    BuildParams::AGGLOMERATIVE,
];

pub(crate) use for_each_volume;

/// `n` random triangles of size about `size` in a cube of half side `half`.
pub(crate) fn soup(rng: &mut TestRng, n: usize, half: f64, size: f64) -> Vec<Triangle> {
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
