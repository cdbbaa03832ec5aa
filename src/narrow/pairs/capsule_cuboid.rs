//! Capsule–cuboid: the segment–box distance minus the radius; when the core segment meets
//! the box, the separating-axis depth over the 3 box faces and the 3 segment × edge axes
//! plus the radius (exact: those are all face normals of the Minkowski difference).
//!
//! Through [`super::query`]; manifold: up to 2 points (segment clipped against a box face),
//! 1 for an edge or corner contact ([`super::clip`]).

use super::core::Core;
use super::{clip, query};
use crate::geometry::{Capsule, Cuboid};
use crate::math::Isometry;
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_capsule_cuboid(a: &Capsule, b: &Cuboid, pose_ab: &Isometry) -> ShapeDistance {
    query::distance(
        &Core::capsule(a, &Isometry::IDENTITY),
        &Core::cuboid(b, pose_ab),
    )
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_capsule_cuboid(a: &Capsule, b: &Cuboid, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &Core::capsule(a, &Isometry::IDENTITY),
        &Core::cuboid(b, pose_ab),
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;

    #[test]
    fn a_capsule_lying_on_a_box_gives_two_points() {
        let c = Capsule::new(1.0, 0.5);
        let b = Cuboid::new(DVec3::new(2.0, 2.0, 1.0));
        // Box below the capsule, the capsule's core along the box's top face (X axis).
        let rot = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let pose = Isometry::new(rot, DVec3::new(0.0, 0.0, -1.4)).inverse();
        let d = distance_capsule_cuboid(&c, &b, &pose);
        assert!((d.distance + 0.1).abs() < 1e-14, "{d:?}");
        check::contract(&d, 1e-14);
        let mut m = Manifold::new();
        manifold_capsule_cuboid(&c, &b, &pose, &mut m);
        check::manifold(&m, 2, 1e-14);
    }

    #[test]
    fn a_core_through_the_box_uses_the_separating_axes() {
        let c = Capsule::new(3.0, 0.5);
        let b = Cuboid::new(DVec3::new(1.0, 2.0, 1.0));
        let pose = Isometry::from_translation(DVec3::new(0.25, 0.0, 0.0));
        let d = distance_capsule_cuboid(&c, &b, &pose);
        // Box spans x ∈ [-0.75, 1.25]: pushing it 0.75 along +X clears the core; plus the
        // radius.
        assert!((d.distance + 1.25).abs() < 1e-14, "{d:?}");
        assert!(d.normal.abs_diff_eq(DVec3::X, 1e-15));
        check::contract(&d, 1e-14);
    }
}
