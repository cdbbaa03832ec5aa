//! A sphere against a solid primitive B, from where its centre lies in B's frame: the two
//! ends every sphere closed form shares (sphere–cuboid, sphere–cylinder), each pair file
//! finding B's closest point, or the way out, for its own shape.

use crate::math::{DVec3, Isometry};
use crate::narrow::contact::ShapeDistance;

/// The sphere of `radius` (centred on A's origin) against B placed by `pose_ab`, when its
/// centre (`centre`, B's frame) is outside B and `closest` is B's closest point to it:
/// distance `gap − radius`, normal A→B from the centre to that point, witnesses on both
/// surfaces, all in A's frame. `None` when the centre is in B (`closest == centre`).
pub(super) fn sphere_outside(
    radius: f64,
    pose_ab: &Isometry,
    centre: DVec3,
    closest: DVec3,
) -> Option<ShapeDistance> {
    let outside = centre - closest;
    let gap = outside.length();
    if gap <= 0.0 {
        return None;
    }
    let normal = pose_ab.transform_vector(-outside / gap);
    Some(ShapeDistance {
        distance: gap - radius,
        point_a: normal * radius,
        point_b: pose_ab.transform_point(closest),
        normal,
    })
}

/// The sphere of `radius` against B placed by `pose_ab`, when its centre lies in B,
/// `room` from B's surface, which it leaves nearest at `exit` going along the unit
/// `outward` (both B's frame): depth `room + radius`, normal A→B `−outward`, in A's frame.
pub(super) fn sphere_inside(
    radius: f64,
    pose_ab: &Isometry,
    exit: DVec3,
    outward: DVec3,
    room: f64,
) -> ShapeDistance {
    let normal = pose_ab.transform_vector(-outward);
    ShapeDistance {
        distance: -(room + radius),
        // The sphere's point that B's surface must clear last: `point_b − depth·normal`.
        point_a: normal * radius,
        point_b: pose_ab.transform_point(exit),
        normal,
    }
}
