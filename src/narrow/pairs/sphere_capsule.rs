//! Sphere–capsule: the centre's distance to the capsule's core segment minus both radii.
//!
//! Closed form (Ericson §5.1.2 closest point on a segment) through [`super::query`]. Centre
//! on the segment: the normal is a fixed axis crossed with the segment (module docs of
//! [`super`]); zero-length capsules are spheres. Manifold: one point.

use super::core::Core;
use super::{clip, query};
use crate::geometry::{Capsule, Sphere};
use crate::math::Isometry;
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_sphere_capsule(a: &Sphere, b: &Capsule, pose_ab: &Isometry) -> ShapeDistance {
    query::distance(
        &Core::sphere(a, &Isometry::IDENTITY),
        &Core::capsule(b, pose_ab),
    )
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_sphere_capsule(a: &Sphere, b: &Capsule, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &Core::sphere(a, &Isometry::IDENTITY),
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
