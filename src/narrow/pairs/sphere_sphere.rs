//! Sphere–sphere: the centre distance minus both radii.
//!
//! Closed form (Ericson, *Real-Time Collision Detection*, §4.3.1), computed directly (the
//! shared core engine answers the same, measured 3× slower). Coincident centres: normal
//! `+X` of A's frame, depth `r_a + r_b`. Manifold: one point.

use crate::geometry::Sphere;
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_sphere_sphere(a: &Sphere, b: &Sphere, pose_ab: &Isometry) -> ShapeDistance {
    let centre_b = pose_ab.translation;
    let gap = centre_b.length();
    let normal = if gap > 0.0 { centre_b / gap } else { DVec3::X };
    ShapeDistance {
        distance: gap - a.radius - b.radius,
        point_a: normal * a.radius,
        point_b: centre_b - normal * b.radius,
        normal,
    }
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_sphere_sphere(a: &Sphere, b: &Sphere, pose_ab: &Isometry, out: &mut Manifold) {
    out.set_from_distance(&distance_sphere_sphere(a, b, pose_ab));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use crate::narrow::pairs::check;

    #[test]
    fn apart_touching_and_overlapping_spheres_give_exact_distances() {
        let (a, b) = (Sphere::new(1.0), Sphere::new(0.5));
        for (x, want) in [(3.0, 1.5), (1.5, 0.0), (1.0, -0.5)] {
            let pose = Isometry::from_translation(DVec3::new(0.0, x, 0.0));
            let d = distance_sphere_sphere(&a, &b, &pose);
            assert!((d.distance - want).abs() < 1e-15, "{d:?}");
            assert!(d.normal.abs_diff_eq(DVec3::Y, 1e-15));
            check::contract(&d, 1e-15);
        }
    }

    #[test]
    fn coincident_centres_take_plus_x_and_full_depth() {
        let d = distance_sphere_sphere(&Sphere::new(1.0), &Sphere::new(2.0), &Isometry::IDENTITY);
        assert_eq!(d.normal, DVec3::X);
        assert_eq!(d.distance, -3.0);
        check::contract(&d, 1e-15);
        let mut m = Manifold::new();
        manifold_sphere_sphere(
            &Sphere::new(1.0),
            &Sphere::new(2.0),
            &Isometry::IDENTITY,
            &mut m,
        );
        check::manifold(&m, 1, 1e-15);
    }

    #[test]
    fn separated_spheres_have_an_empty_manifold() {
        let mut m = Manifold::new();
        let pose = Isometry::from_translation(DVec3::new(5.0, 0.0, 0.0));
        manifold_sphere_sphere(&Sphere::new(1.0), &Sphere::new(2.0), &pose, &mut m);
        assert!(m.is_empty());
    }
}
