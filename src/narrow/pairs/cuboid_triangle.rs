//! Cuboid–triangle: separating axes (3 box faces, the triangle normal, 9 edge × edge) for
//! the exact depth; apart, the best of box corners against the triangle, triangle corners
//! clamped to the box, and the edge–edge pairs (Akenine-Möller, *Fast 3D triangle-box
//! overlap testing*, 2001, for the axis set). A pair apart along a face axis takes its
//! closest pair straight from the features the triangle can be nearest to
//! ([`super::triangle_apart`]), a triangle sunk into one face of the box its depth from
//! that face ([`super::box_face_depth`]), any other [`super::query`]; manifold: face
//! clipping reduced to 4 points ([`super::clip`]).

use super::box_face_depth::face_depth_box_triangle;
use super::placed_core::PlacedCore;
use super::triangle_apart::apart_box_triangle;
use super::{clip, query};
use crate::geometry::{Cuboid, Triangle};
use crate::math::Isometry;
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_cuboid_triangle(a: &Cuboid, b: &Triangle, pose_ab: &Isometry) -> ShapeDistance {
    let placed = b.transformed(pose_ab);
    apart_box_triangle(a.half_extents, &placed)
        .or_else(|| face_depth_box_triangle(a.half_extents, &placed))
        .unwrap_or_else(|| {
            query::distance(
                &PlacedCore::cuboid(a, &Isometry::IDENTITY),
                &PlacedCore::triangle(b, pose_ab),
            )
        })
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_cuboid_triangle(a: &Cuboid, b: &Triangle, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &PlacedCore::cuboid(a, &Isometry::IDENTITY),
        &PlacedCore::triangle(b, pose_ab),
        out,
    );
}

/// [`manifold_cuboid_triangle`] from the pair's signed distance `d` (from
/// [`distance_cuboid_triangle`], A's frame): clipped along `d`'s normal without the
/// separating axes again. PERF: a cuboid against a mesh, whose distance walk records each
/// touching triangle's distance (`benches/falling.rs`).
pub fn manifold_cuboid_triangle_from(
    a: &Cuboid,
    b: &Triangle,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    clip::manifold_from_distance(
        &PlacedCore::cuboid(a, &Isometry::IDENTITY),
        &PlacedCore::triangle(b, pose_ab),
        d,
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use crate::narrow::pairs::check;

    #[test]
    fn a_box_sunk_into_a_big_triangle_gives_four_points() {
        let b = Cuboid::new(DVec3::splat(0.5));
        let t = Triangle::new(
            DVec3::new(-5.0, -5.0, 0.0),
            DVec3::new(5.0, -5.0, 0.0),
            DVec3::new(0.0, 5.0, 0.0),
        );
        let pose = Isometry::from_translation(DVec3::new(0.0, 0.0, -0.4));
        let d = distance_cuboid_triangle(&b, &t, &pose);
        assert!(
            (d.distance + 0.1).abs() < 1e-15 && d.normal == -DVec3::Z,
            "{d:?}"
        );
        check::contract(&d, 1e-15);
        let mut m = Manifold::new();
        manifold_cuboid_triangle(&b, &t, &pose, &mut m);
        check::manifold(&m, 4, 1e-15);
    }

    #[test]
    fn a_triangle_through_the_box_centre_has_full_half_depth() {
        let b = Cuboid::new(DVec3::new(1.0, 2.0, 3.0));
        let t = Triangle::new(
            DVec3::new(-0.1, -0.1, 0.0),
            DVec3::new(0.1, -0.1, 0.0),
            DVec3::new(0.0, 0.1, 0.0),
        );
        let d = distance_cuboid_triangle(&b, &t, &Isometry::IDENTITY);
        // Leaving through ±X: 1 + 0.1.
        assert!((d.distance + 1.1).abs() < 1e-14, "{d:?}");
        check::contract(&d, 1e-14);
        let degenerate = Triangle::new(DVec3::ZERO, DVec3::ZERO, DVec3::X);
        let d = distance_cuboid_triangle(&b, &degenerate, &Isometry::IDENTITY);
        check::contract(&d, 1e-14);
    }
}
