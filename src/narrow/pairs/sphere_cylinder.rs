//! Sphere–cylinder: the centre clamped to the solid cylinder, minus the radius; inside it,
//! the nearest of the side and the two caps, plus the radius.
//!
//! Closed form, in B's frame (the cylinder's axis is its local Z, `|z| ≤ half_height`,
//! `x² + y² ≤ radius²`): the closest point of the solid cylinder to the centre clamps the
//! radial part to the radius and the axial part to the caps. Inside, the least translation
//! that moves the centre out is its distance to the boundary, `min(radius − ρ, half_height
//! − |z|)` (the cap on ties), so the depth is that plus the sphere's radius. A centre on
//! the axis leaves through the side along +X. Manifold: one point, the distance's
//! witnesses. Replaces GJK/EPA for this pair (`benches/pile.rs`: 0.25 µs a pair, half
//! parry's speed, before).

use super::sphere_solid::{sphere_inside, sphere_outside};
use crate::geometry::{Cylinder, Sphere};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_sphere_cylinder(a: &Sphere, b: &Cylinder, pose_ab: &Isometry) -> ShapeDistance {
    let (h, r) = (b.half_height, b.radius);
    // The sphere's centre (A's origin) in B's frame, and its closest point on the cylinder.
    let centre = pose_ab.inverse_transform_point(DVec3::ZERO);
    if let Some(d) = sphere_outside(a.radius, pose_ab, centre, b.closest_point(centre)) {
        return d;
    }
    // Inside (or on the surface): out through the nearer of a cap and the side.
    let radial = DVec3::new(centre.x, centre.y, 0.0);
    let rho = radial.length();
    let (room_cap, room_side) = (h - centre.z.abs(), r - rho);
    if room_cap <= room_side {
        let side = if centre.z < 0.0 { -1.0 } else { 1.0 };
        let exit = DVec3::new(centre.x, centre.y, side * h);
        sphere_inside(a.radius, pose_ab, exit, DVec3::Z * side, room_cap)
    } else {
        let outward = if rho > 0.0 { radial / rho } else { DVec3::X };
        let exit = outward * r + DVec3::Z * centre.z;
        sphere_inside(a.radius, pose_ab, exit, outward, room_side)
    }
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: one point on
/// both surfaces with the normal A→B, A's frame; empty when apart.
pub fn manifold_sphere_cylinder(a: &Sphere, b: &Cylinder, pose_ab: &Isometry, out: &mut Manifold) {
    out.set_from_distance(&distance_sphere_cylinder(a, b, pose_ab));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow::pairs::check;

    fn at(p: DVec3) -> Isometry {
        // B (the cylinder) placed so that the sphere centre is at `p` in B's frame.
        Isometry::from_translation(-p)
    }

    #[test]
    fn outside_inside_and_on_the_surface_give_exact_distances() {
        let (s, c) = (Sphere::new(0.5), Cylinder::new(2.0, 1.0));
        for (p, want) in [
            (DVec3::new(3.0, 0.0, 0.0), 1.5),
            (DVec3::new(0.0, 0.0, 4.0), 1.5),
            (DVec3::new(2.0, 0.0, 3.0), 2f64.sqrt() - 0.5),
            (DVec3::new(0.6, 0.8, 0.0), -0.5),
            (DVec3::new(0.5, 0.0, 0.0), -1.0),
            (DVec3::new(0.0, 0.0, 1.5), -1.0),
            (DVec3::ZERO, -1.5),
            (DVec3::new(0.0, 0.0, 2.0), -0.5),
        ] {
            let d = distance_sphere_cylinder(&s, &c, &at(p));
            assert!((d.distance - want).abs() < 1e-14, "{p}: {d:?}");
            check::contract(&d, 1e-14);
        }
    }

    #[test]
    fn a_zero_size_cylinder_is_a_point() {
        let d = distance_sphere_cylinder(
            &Sphere::new(1.0),
            &Cylinder::new(0.0, 0.0),
            &at(DVec3::ZERO),
        );
        assert_eq!(d.distance, -1.0);
        check::contract(&d, 1e-15);
    }
}
