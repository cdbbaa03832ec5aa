//! Capsule–cuboid: the segment–box distance minus the radius; when the core segment meets
//! the box, the separating-axis depth over the 3 box faces and the 3 segment × edge axes
//! plus the radius (exact: those are all face normals of the Minkowski difference).
//!
//! Through [`super::query`]; manifold: up to 2 points (segment clipped against a box face),
//! 1 for an edge or corner contact ([`super::clip`]).

use super::core::{AXIS_RELATIVE, Core};
use super::{clip, query};
use crate::geometry::{Capsule, Cuboid};
use crate::math::{DVec3, Isometry};
use crate::narrow::closest_points::closest_point_segment;
use crate::narrow::contact::{DistanceBound, Manifold, ShapeDistance};

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

/// Bounds on the signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's)
/// from the separating-axis test alone, A's frame, as [`DistanceBound`] states; the test
/// may stop once the lower bound exceeds `enough` metres (`f64::INFINITY`: never).
#[must_use]
pub fn distance_bound_capsule_cuboid(
    a: &Capsule,
    b: &Cuboid,
    pose_ab: &Isometry,
    enough: f64,
) -> DistanceBound {
    // PERF: in the box's frame, where each axis's separation is a few products: a quarter
    // of the shared engine's cost on placed cores (4,096 near pairs: 266–271 → 87 ns a call).
    let to_box = pose_ab.inverse();
    let seg = a.segment();
    let (p0, p1) = (to_box.transform_point(seg.a), to_box.transform_point(seg.b));
    let (c, e, h) = ((p0 + p1) * 0.5, (p1 - p0) * 0.5, b.half_extents);
    // The best axis from the box towards the segment, with its separation of the cores.
    let (mut away, mut separation) = (DVec3::X, f64::NEG_INFINITY);
    let mut offer = |u: DVec3, length: f64| {
        let s = (c.dot(u).abs() - e.dot(u).abs() - u.abs().dot(h)) / length;
        if s > separation {
            separation = s;
            away = if c.dot(u) >= 0.0 { u } else { -u } / length;
        }
        separation > enough + a.radius
    };
    let stopped = (0..3).any(|k| offer(DVec3::AXES[k], 1.0))
        || (0..3).any(|k| {
            let u = DVec3::AXES[k].cross(e);
            let length = u.length();
            length > AXIS_RELATIVE * e.length() && offer(u, length)
        });
    // Box faces and segment × box edges are every face normal of the cores' Minkowski
    // difference when the box is solid.
    let complete = !stopped && h.min_element() > 0.0;
    let scale = h
        .max_element()
        .max(p0.abs().max_element())
        .max(p1.abs().max_element());
    let slack = query::BOUND_ULPS * f64::EPSILON * (scale + a.radius);
    let lower = separation - a.radius - slack;
    let upper = if complete && separation <= 0.0 {
        // The skipped near-parallel cross axes may change the depth by as much.
        lower + 2.0 * slack + AXIS_RELATIVE * 2.0 * (e.length() + h.max_element())
    } else {
        // A step of alternating projection from the box point nearest the segment's middle.
        let on_box = c.clamp(-h, h);
        let on_segment = closest_point_segment(on_box, p0, p1);
        on_segment.distance(on_segment.clamp(-h, h)) - a.radius + slack
    };
    // A→B is from the segment towards the box; B's point farthest against it is the
    // corner on the segment's side.
    let normal = pose_ab.transform_vector(-away);
    let point_b = pose_ab.transform_point(away.signum() * h);
    DistanceBound::new(lower, upper, normal, point_b)
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
