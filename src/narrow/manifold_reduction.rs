//! Contact manifold reduction: at most [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS) informative points out of a
//! pair's whole contact set.
//!
//! A mesh–mesh intersection can produce thousands of segment endpoints; a physics client
//! needs a few points that span the contact region. [`reduce_manifold`] keeps the extremes,
//! greedily:
//! 1. the farthest pair of points (exact for sets up to [`EXACT_DIAMETER_POINTS`] points;
//!    above that a double sweep — farthest point from the first point, then farthest point
//!    from that one — which is at least half the true diameter, in linear time);
//! 2. the point that maximises the area of the triangle with those two;
//! 3. the point that adds the most area outside that triangle (over its three edges, in the
//!    triangle's plane orientation), if any adds some.
//!
//! Over random small sets (tests) the kept points span at least half the area of the best
//! 4-point subset (worst seen about 0.65).
//!
//! Points are never invented: every output point is an input point, and no point is kept
//! twice. Degenerate sets shrink the output: all points equal → 1 point, all on one line → 2.

use crate::math::DVec3;
use crate::narrow::contact::{Manifold, ManifoldPoint};

/// Sets up to this many points get the exact farthest pair (quadratic); larger sets the
/// linear double sweep.
pub const EXACT_DIAMETER_POINTS: usize = 256;

/// The indices into `points` of at most [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS) distinct points spanning
/// the set, written to `out` (cleared first) in the order chosen: the farthest pair (exact
/// up to [`EXACT_DIAMETER_POINTS`] points, else a double sweep, at least half the diameter),
/// the point making the largest triangle with it, the point adding the most area beyond
/// that triangle. Equal points give one index, collinear ones two; empty input, none.
///
/// # Allocation
/// None once `out` holds [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS) indices.
pub fn reduce_manifold(points: &[DVec3], out: &mut Vec<usize>) {
    out.clear();
    if points.is_empty() {
        return;
    }
    let (i0, i1) = farthest_pair(points);
    out.push(i0);
    let (p0, p1) = (points[i0], points[i1]);
    if p0.distance_squared(p1) <= 0.0 {
        return;
    }
    out.push(i1);
    let edge = p1 - p0;
    let (i2, twice_area) = argmax(points, |q| edge.cross(q - p0).length());
    if twice_area <= 0.0 {
        return;
    }
    out.push(i2);
    let p2 = points[i2];
    let plane = edge.cross(p2 - p0);
    // Twice the area `q` adds beyond the triangle: the largest outward triangle it forms with
    // one of the edges (negative signed area relative to the triangle's orientation).
    let outside = |q: DVec3| {
        [(p0, p1), (p1, p2), (p2, p0)]
            .iter()
            .map(|&(s, e)| -(e - s).cross(q - s).dot(plane))
            .fold(0.0f64, f64::max)
    };
    let (i3, added) = argmax(points, outside);
    if added > 0.0 {
        out.push(i3);
    }
}

/// One manifold out of contact points that carry their own normals (the triangles of a
/// mesh, the part pairs of a compound), into `out`: the deepest point's normal becomes the
/// manifold's, [`reduce_manifold`] picks at most four points by their A positions, the
/// deepest always among them, and a point of another normal gets its depth along the
/// common one (its B point moved onto that normal through its A point). `normals[i]` is
/// point `i`'s; `positions` and `kept` are scratch. Returns `false`, leaving `out` as it
/// was, when there is no point.
pub(crate) fn reduce_under_deepest(
    points: &[ManifoldPoint],
    normals: &[DVec3],
    positions: &mut Vec<DVec3>,
    kept: &mut Vec<usize>,
    out: &mut Manifold,
) -> bool {
    let Some(deepest) =
        (0..points.len()).min_by(|&i, &j| points[i].distance.total_cmp(&points[j].distance))
    else {
        return false;
    };
    let normal = normals[deepest];
    out.reset(normal);
    positions.clear();
    positions.extend(points.iter().map(|p| p.point_a));
    reduce_manifold(positions, kept);
    if !kept.contains(&deepest) {
        kept.pop();
        kept.insert(0, deepest);
    }
    for &i in kept.iter() {
        let p = points[i];
        if normals[i] == normal {
            out.push(p);
        } else {
            let distance = (p.point_b - p.point_a).dot(normal).min(0.0);
            out.push(ManifoldPoint {
                point_a: p.point_a,
                point_b: p.point_a + distance * normal,
                distance,
            });
        }
    }
    true
}

/// The farthest pair's indices (exact up to [`EXACT_DIAMETER_POINTS`] points, else the
/// double sweep); `(0, 0)` for one point.
fn farthest_pair(points: &[DVec3]) -> (usize, usize) {
    if points.len() <= EXACT_DIAMETER_POINTS {
        let mut best = (0, 0, 0.0);
        for (i, &p) in points.iter().enumerate() {
            for (j, &q) in points.iter().enumerate().skip(i + 1) {
                let d = p.distance_squared(q);
                if d > best.2 {
                    best = (i, j, d);
                }
            }
        }
        (best.0, best.1)
    } else {
        let (a, _) = argmax(points, |q| q.distance_squared(points[0]));
        let (b, _) = argmax(points, |q| q.distance_squared(points[a]));
        (a, b)
    }
}

/// The first index with the largest `score` (NaN scores never win) and that score; `(0,
/// 0.0)` when no score is positive.
fn argmax(points: &[DVec3], score: impl Fn(DVec3) -> f64) -> (usize, f64) {
    let mut best = (0, 0.0);
    for (i, &q) in points.iter().enumerate() {
        let s = score(q);
        if s > best.1 {
            best = (i, s);
        }
    }
    best
}

#[cfg(test)]
#[path = "manifold_reduction_tests.rs"]
mod tests;
