//! Sphere–triangle: the centre's closest point on the triangle (Voronoi regions, Ericson
//! §5.1.5) minus the radius; a centre on the (two-sided, flat) triangle gives depth = radius
//! along the triangle normal. Zero-area triangles are their segment or point. A centre off
//! the triangle takes its closest point straight ([`super::triangle_apart`]), one on it
//! [`super::query`]; manifold: one point.

use super::placed_core::PlacedCore;
use super::triangle_apart::apart_point_triangle;
use super::{clip, query};
use crate::geometry::{Sphere, Triangle};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_sphere_triangle(a: &Sphere, b: &Triangle, pose_ab: &Isometry) -> ShapeDistance {
    apart_point_triangle(DVec3::ZERO, a.radius, &b.transformed(pose_ab)).unwrap_or_else(|| {
        query::distance(
            &PlacedCore::sphere(a, &Isometry::IDENTITY),
            &PlacedCore::triangle(b, pose_ab),
        )
    })
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_sphere_triangle(a: &Sphere, b: &Triangle, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &PlacedCore::sphere(a, &Isometry::IDENTITY),
        &PlacedCore::triangle(b, pose_ab),
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use crate::narrow::pairs::check;

    fn tri() -> Triangle {
        Triangle::new(
            DVec3::ZERO,
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 2.0, 0.0),
        )
    }

    #[test]
    fn face_edge_vertex_and_on_plane_centres_give_exact_distances() {
        let s = Sphere::new(0.5);
        for (p, want) in [
            (DVec3::new(0.5, 0.5, 2.0), 1.5),
            (DVec3::new(0.5, 0.5, -0.25), -0.25),
            (DVec3::new(-3.0, -4.0, 0.0), 4.5),
            (DVec3::new(0.5, 0.5, 0.0), -0.5),
            (DVec3::new(1.0, 0.0, 0.0), -0.5),
        ] {
            let d = distance_sphere_triangle(&s, &tri(), &Isometry::from_translation(-p));
            assert!((d.distance - want).abs() < 1e-14, "{p}: {d:?}");
            check::contract(&d, 1e-14);
        }
    }

    #[test]
    fn zero_area_triangles_are_segments_or_points() {
        let s = Sphere::new(0.5);
        let seg = Triangle::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        let d = distance_sphere_triangle(
            &s,
            &seg,
            &Isometry::from_translation(DVec3::new(-1.0, -1.0, 0.0)),
        );
        assert!((d.distance - 0.5).abs() < 1e-15);
        let dot = Triangle::new(DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
        let d = distance_sphere_triangle(&s, &dot, &Isometry::IDENTITY);
        assert_eq!(d.distance, -0.5);
        check::contract(&d, 1e-15);
    }
}
