//! Capsule–capsule: the distance between the core segments minus both radii.
//!
//! Closest points of two segments in the cross-product form (Ericson §5.1.9) through
//! [`super::query`]; crossing segments take `d₁ × d₂` as normal, parallel or zero-length
//! ones a fixed axis crossed with the direction. Manifold: 2 points for parallel
//! overlapping cores ([`super::clip`]), else 1.

use super::core::Core;
use super::{clip, query};
use crate::geometry::Capsule;
use crate::math::Isometry;
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_capsule_capsule(a: &Capsule, b: &Capsule, pose_ab: &Isometry) -> ShapeDistance {
    query::distance(
        &Core::capsule(a, &Isometry::IDENTITY),
        &Core::capsule(b, pose_ab),
    )
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_capsule_capsule(a: &Capsule, b: &Capsule, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &Core::capsule(a, &Isometry::IDENTITY),
        &Core::capsule(b, pose_ab),
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;

    #[test]
    fn crossing_cores_take_the_cross_product_normal() {
        let c = Capsule::new(1.0, 0.25);
        let pose = Isometry::new(
            DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2),
            DVec3::ZERO,
        );
        let d = distance_capsule_capsule(&c, &c, &pose);
        assert!((d.distance + 0.5).abs() < 1e-15, "{d:?}");
        assert!(d.normal.x.abs() > 1.0 - 1e-12);
        check::contract(&d, 1e-15);
        let mut m = Manifold::new();
        manifold_capsule_capsule(&c, &c, &pose, &mut m);
        check::manifold(&m, 1, 1e-15);
    }

    #[test]
    fn parallel_overlapping_capsules_give_two_points() {
        let c = Capsule::new(1.0, 0.25);
        let pose = Isometry::from_translation(DVec3::new(0.4, 0.0, 0.5));
        let d = distance_capsule_capsule(&c, &c, &pose);
        assert!((d.distance + 0.1).abs() < 1e-15 && d.normal.abs_diff_eq(DVec3::X, 1e-15));
        let mut m = Manifold::new();
        manifold_capsule_capsule(&c, &c, &pose, &mut m);
        check::manifold(&m, 2, 1e-14);
        let zs: Vec<f64> = m.points().iter().map(|p| p.point_a.z).collect();
        assert!((zs[0] - zs[1]).abs() > 1.4, "{m:?}");
    }

    #[test]
    fn collinear_and_zero_length_cores_never_give_nan() {
        let c = Capsule::new(1.0, 0.25);
        let dot = Capsule::new(0.0, 0.25);
        let pose = Isometry::from_translation(DVec3::new(0.0, 0.0, 0.5));
        for (a, b) in [(c, c), (c, dot), (dot, dot)] {
            let d = distance_capsule_capsule(&a, &b, &pose);
            check::contract(&d, 1e-15);
            assert!(
                (d.distance + 0.5).abs() < 1e-15 || a == dot && b == dot,
                "{d:?}"
            );
        }
    }
}
