//! Sphere–cuboid: the centre clamped to the box, minus the radius; inside the box, the
//! nearest face plus the radius.
//!
//! Closed form (Ericson §5.1.3), computed directly in B's frame (the shared core engine
//! answers the same, measured 3.5× slower): the centre clamped to the box; inside, the
//! nearest face (the first axis on ties), so a centre exactly on a face, edge or corner
//! gives depth = radius along a face normal. Manifold: one point, the distance's witnesses.

use super::sphere_solid::{sphere_inside, sphere_outside};
use crate::geometry::{Cuboid, Sphere};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_sphere_cuboid(a: &Sphere, b: &Cuboid, pose_ab: &Isometry) -> ShapeDistance {
    let h = b.half_extents;
    // The sphere's centre (A's origin) in B's frame, and its closest point on the box.
    let centre = pose_ab.inverse_transform_point(DVec3::ZERO);
    if let Some(d) = sphere_outside(a.radius, pose_ab, centre, centre.clamp(-h, h)) {
        return d;
    }
    // Inside (or on the surface): the nearest face; the first axis on ties. B separates by
    // moving so that this face passes the centre, then the radius.
    let room = h - centre.abs();
    let axis = if room.x <= room.y && room.x <= room.z {
        0
    } else if room.y <= room.z {
        1
    } else {
        2
    };
    let side = if centre[axis] < 0.0 { -1.0 } else { 1.0 };
    let mut face = centre;
    face[axis] = side * h[axis];
    let mut outward = DVec3::ZERO;
    outward[axis] = side;
    sphere_inside(a.radius, pose_ab, face, outward, room[axis])
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_sphere_cuboid(a: &Sphere, b: &Cuboid, pose_ab: &Isometry, out: &mut Manifold) {
    out.set_from_distance(&distance_sphere_cuboid(a, b, pose_ab));
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use crate::narrow::pairs::check;

    fn at(p: DVec3) -> Isometry {
        // B (the box) placed so that the sphere centre is at `p` in B's frame.
        Isometry::from_translation(-p)
    }

    #[test]
    fn outside_inside_and_on_the_surface_give_exact_distances() {
        let (s, b) = (Sphere::new(0.5), Cuboid::new(DVec3::new(1.0, 2.0, 3.0)));
        for (p, want) in [
            (DVec3::new(3.0, 0.0, 0.0), 1.5),
            (DVec3::new(2.0, 3.0, 3.0), 2f64.sqrt() - 0.5),
            (DVec3::new(0.5, 0.0, 0.0), -1.0),
            (DVec3::new(1.0, 2.0, 3.0), -0.5),
            (DVec3::new(1.0, 0.0, 0.0), -0.5),
            (DVec3::ZERO, -1.5),
        ] {
            let d = distance_sphere_cuboid(&s, &b, &at(p));
            assert!((d.distance - want).abs() < 1e-14, "{p}: {d:?}");
            check::contract(&d, 1e-14);
        }
    }

    #[test]
    fn a_zero_size_box_is_a_point() {
        let d = distance_sphere_cuboid(
            &Sphere::new(1.0),
            &Cuboid::new(DVec3::ZERO),
            &at(DVec3::ZERO),
        );
        assert_eq!(d.distance, -1.0);
        check::contract(&d, 1e-15);
        let mut m = Manifold::new();
        manifold_sphere_cuboid(
            &Sphere::new(1.0),
            &Cuboid::new(DVec3::ZERO),
            &at(DVec3::ZERO),
            &mut m,
        );
        check::manifold(&m, 1, 1e-15);
    }
}
