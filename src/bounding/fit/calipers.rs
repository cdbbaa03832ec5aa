//! Minimum-area enclosing rectangle of a planar projection, for orientations PCA leaves open.
//!
//! When two eigenvalues of a covariance coincide (a square plate, a cube, a cylinder) PCA
//! fixes only the remaining axis; any rotation about it is an eigenbasis, and most of them
//! bound the set badly. [`frame_about`] resolves the freedom: it projects the points onto
//! the plane normal to the fixed axis and picks the in-plane directions of the
//! minimum-area enclosing rectangle, which has a side collinear with an edge of the
//! projection's convex hull (Freeman and Shapira 1975); every hull edge is tried.
//!
//! Citation: H. Freeman, R. Shapira, "Determining the minimum-area encasing rectangle for an
//! arbitrary closed curve", CACM 18(7), 1975; hull by Andrew's monotone chain (1979).

use crate::math::{DMat3, DVec3};
use glam::DVec2;

/// Hull edges tried at most; beyond this, edges are taken at an even stride (the result is
/// then near-minimal, which is all an orientation candidate needs).
const MAX_EDGES: usize = 256;

/// A right-handed orthonormal frame `(a, b, normal)` whose first two axes are the sides of
/// the minimum-area rectangle enclosing the projection of `points` onto the plane normal to
/// `normal` (unit). `reference` is any point near the set (subtracted for precision).
#[must_use]
pub fn frame_about(normal: DVec3, points: &[DVec3], reference: DVec3) -> DMat3 {
    let (u, v) = normal.any_orthonormal_pair();
    let projected: Vec<DVec2> = points
        .iter()
        .map(|&p| {
            let d = p - reference;
            DVec2::new(d.dot(u), d.dot(v))
        })
        .collect();
    let side = min_area_direction(projected);
    let a = u * side.x + v * side.y;
    super::orthonormalise(a, normal.cross(a))
}

/// A unit direction along one side of a minimum-area rectangle enclosing `points` (`X` when
/// the hull has no edge: a single point).
#[must_use]
pub fn min_area_direction(points: Vec<DVec2>) -> DVec2 {
    let hull = convex_hull(points);
    if hull.len() < 2 {
        return DVec2::X;
    }
    let stride = hull.len().div_ceil(MAX_EDGES).max(1);
    let (mut best, mut best_area) = (DVec2::X, f64::INFINITY);
    for i in (0..hull.len()).step_by(stride) {
        let Some(dir) = (hull[(i + 1) % hull.len()] - hull[i]).try_normalize() else {
            continue;
        };
        let perp = dir.perp();
        let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &p in &hull {
            let q = DVec2::new(p.dot(dir), p.dot(perp));
            lo = lo.min(q);
            hi = hi.max(q);
        }
        let area = (hi - lo).x * (hi - lo).y;
        if area < best_area {
            (best, best_area) = (dir, area);
        }
    }
    best
}

/// The convex hull of `points`, counter-clockwise, without collinear points (Andrew's
/// monotone chain).
fn convex_hull(mut points: Vec<DVec2>) -> Vec<DVec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let ordered: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in ordered {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;

    #[test]
    fn the_rectangle_of_a_rotated_rectangle_is_its_own_orientation() {
        let mut rng = rng(7);
        for case in 0..1000 {
            let angle: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let dir = DVec2::from_angle(angle);
            let half = DVec2::new(rng.random_range(0.1..2.0), rng.random_range(0.1..2.0));
            let mut points: Vec<DVec2> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .into_iter()
                .map(|(x, y)| dir * (x * half.x) + dir.perp() * (y * half.y))
                .collect();
            for _ in 0..30 {
                let (x, y) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                points.push(dir * (x * half.x) + dir.perp() * (y * half.y));
            }
            let found = min_area_direction(points);
            let alignment = found.dot(dir).abs().max(found.dot(dir.perp()).abs());
            assert!(alignment > 1.0 - 1e-9, "case {case}: {found} vs {dir}");
        }
    }

    #[test]
    fn degenerate_projections_still_give_a_frame() {
        for points in [
            vec![DVec3::ZERO],
            vec![DVec3::ONE; 4],
            vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0],
        ] {
            let f = frame_about(DVec3::Z, &points, DVec3::ZERO);
            assert!((f.transpose() * f).abs_diff_eq(DMat3::IDENTITY, 1e-12));
            assert!((f.determinant() - 1.0).abs() < 1e-12);
            assert!(f.z_axis.abs_diff_eq(DVec3::Z, 1e-12));
        }
    }

    #[test]
    fn collinear_points_have_a_two_point_hull() {
        let hull = convex_hull(
            (0..10)
                .map(|i| DVec2::new(i as f64, 2.0 * i as f64))
                .collect(),
        );
        assert_eq!(hull.len(), 2);
    }
}
