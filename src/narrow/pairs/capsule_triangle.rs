//! Capsule–triangle: segment–triangle distance (endpoints against the triangle, edges
//! against the segment) minus the radius; a segment piercing the triangle takes the
//! separating-axis depth over the triangle normal and the segment × edge axes, plus the
//! radius. A segment apart from the triangle takes its closest pair straight from the
//! features ([`super::triangle_apart`]), any other [`super::query`]; manifold: up to 2
//! points (segment clipped against the triangle face), else 1 ([`super::clip`]).

use super::placed_core::PlacedCore;
use super::triangle_apart::apart_segment_triangle;
use super::{clip, query};
use crate::geometry::{Capsule, Triangle};
use crate::math::Isometry;
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_capsule_triangle(a: &Capsule, b: &Triangle, pose_ab: &Isometry) -> ShapeDistance {
    let axis = a.segment();
    apart_segment_triangle((axis.a, axis.b), a.radius, &b.transformed(pose_ab)).unwrap_or_else(
        || {
            query::distance(
                &PlacedCore::capsule(a, &Isometry::IDENTITY),
                &PlacedCore::triangle(b, pose_ab),
            )
        },
    )
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_capsule_triangle(
    a: &Capsule,
    b: &Triangle,
    pose_ab: &Isometry,
    out: &mut Manifold,
) {
    clip::manifold(
        &PlacedCore::capsule(a, &Isometry::IDENTITY),
        &PlacedCore::triangle(b, pose_ab),
        out,
    );
}

/// [`manifold_capsule_triangle`] from the pair's signed distance `d` (from
/// [`distance_capsule_triangle`], A's frame): clipped along `d`'s normal without the
/// separating axes again. PERF: a capsule against a mesh, whose distance walk records each
/// touching triangle's distance (`benches/falling.rs`).
pub fn manifold_capsule_triangle_from(
    a: &Capsule,
    b: &Triangle,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    clip::manifold_from_distance(
        &PlacedCore::capsule(a, &Isometry::IDENTITY),
        &PlacedCore::triangle(b, pose_ab),
        d,
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;

    fn tri() -> Triangle {
        Triangle::new(
            DVec3::new(-2.0, -2.0, 0.0),
            DVec3::new(2.0, -2.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        )
    }

    #[test]
    fn a_core_piercing_the_triangle_is_pushed_out_along_the_shorter_way() {
        let c = Capsule::new(1.0, 0.25);
        // PlacedCore along Z from -1 to 1 through the triangle at z = 0.3 (B frame: tri at -0.3).
        let pose = Isometry::from_translation(DVec3::new(0.0, 0.0, -0.3));
        let d = distance_capsule_triangle(&c, &tri(), &pose);
        assert!((d.distance + 0.95).abs() < 1e-14, "{d:?}");
        check::contract(&d, 1e-14);
    }

    #[test]
    fn a_capsule_lying_on_a_triangle_gives_two_points() {
        let c = Capsule::new(0.5, 0.25);
        let rot = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let pose = Isometry::new(rot, DVec3::new(0.0, 0.0, -0.2)).inverse();
        let d = distance_capsule_triangle(&c, &tri(), &pose);
        assert!((d.distance + 0.05).abs() < 1e-14, "{d:?}");
        let mut m = Manifold::new();
        manifold_capsule_triangle(&c, &tri(), &pose, &mut m);
        check::manifold(&m, 2, 1e-14);
    }
}
