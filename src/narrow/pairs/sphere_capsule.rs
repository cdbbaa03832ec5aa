//! Sphere–capsule: the centre's distance to the capsule's core segment minus both radii.
//!
//! Closed form (Ericson §5.1.2 closest point on a segment), computed directly (the shared
//! core engine answers the same, measured 2.5× slower). Centre on the segment: the normal
//! is the first of `+X, +Y, +Z` (A's frame) crossed with the segment that is not parallel
//! to it, or `+X` for a zero-length segment; zero-length capsules are spheres. Manifold: one
//! point.

use crate::geometry::{Capsule, Sphere};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_sphere_capsule(a: &Sphere, b: &Capsule, pose_ab: &Isometry) -> ShapeDistance {
    // The capsule's segment in A's frame; the sphere's centre is A's origin.
    let axis = pose_ab.rotation.z_axis * b.half_height;
    let (p0, p1) = (pose_ab.translation - axis, pose_ab.translation + axis);
    let along = p1 - p0;
    let length_squared = along.length_squared();
    let t = if length_squared > 0.0 {
        (-p0.dot(along) / length_squared).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let closest = p0 + along * t;
    let gap = closest.length();
    let tiny = 1e-12 * (p0.abs().max_element() + p1.abs().max_element());
    let normal = if gap > tiny {
        closest / gap
    } else {
        // The centre on the segment: any direction across it separates soonest.
        [DVec3::X, DVec3::Y, DVec3::Z]
            .into_iter()
            .map(|fixed| fixed.cross(along))
            .find(|n| n.length_squared() > 1e-24 * length_squared)
            .map_or(DVec3::X, DVec3::normalize)
    };
    // Along the normal, the core segment's point `closest` is `gap·normal` (or within
    // rounding of the centre when the centre lies on it).
    let core_gap = if gap > tiny { gap } else { 0.0 };
    ShapeDistance {
        distance: core_gap - a.radius - b.radius,
        point_a: normal * a.radius,
        point_b: normal * (core_gap - b.radius),
        normal,
    }
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_sphere_capsule(a: &Sphere, b: &Capsule, pose_ab: &Isometry, out: &mut Manifold) {
    out.set_from_distance(&distance_sphere_capsule(a, b, pose_ab));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;

    #[test]
    fn a_sphere_beside_and_beyond_the_capsule_end_gives_exact_distances() {
        let (s, c) = (Sphere::new(0.5), Capsule::new(2.0, 1.0));
        // B's core runs along A's X.
        let rot = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        for (p, want) in [
            (DVec3::new(1.0, 0.0, 3.0), 1.5),
            (DVec3::new(-5.0, 0.0, 0.0), 1.5),
            (DVec3::new(0.0, 1.0, 0.0), -0.5),
        ] {
            let d = distance_sphere_capsule(&s, &c, &Isometry::new(rot, -p));
            assert!((d.distance - want).abs() < 1e-14, "{p}: {d:?}");
            check::contract(&d, 1e-14);
        }
    }

    #[test]
    fn a_centre_on_the_core_and_a_zero_length_capsule_never_give_nan() {
        let s = Sphere::new(0.5);
        for c in [Capsule::new(2.0, 1.0), Capsule::new(0.0, 1.0)] {
            let d = distance_sphere_capsule(&s, &c, &Isometry::IDENTITY);
            assert_eq!(d.distance, -1.5);
            check::contract(&d, 1e-15);
            let mut m = Manifold::new();
            manifold_sphere_capsule(&s, &c, &Isometry::IDENTITY, &mut m);
            check::manifold(&m, 1, 1e-15);
        }
    }
}
