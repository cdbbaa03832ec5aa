//! Closest points between simple features: point–triangle and segment–segment.
//!
//! Floating-point, branch-light helpers for [`super::triangle_triangle`]; both accept
//! degenerate input (zero-length segments, zero-area triangles) without producing NaN.
//!
//! Citation: C. Ericson, *Real-Time Collision Detection*, Morgan Kaufmann 2005, §5.1.5
//! (closest point on a triangle by Voronoi regions) and §5.1.9 (closest points of two
//! segments).

use crate::math::DVec3;

/// The point of the closed triangle `a, b, c` closest to `p` (same frame as the inputs).
///
/// Ericson's region method: the Voronoi regions of the three vertices and three edges are
/// tested with dot products only, then the face region by barycentric coordinates. A
/// zero-area triangle (to rounding) falls back to the closest of its three edges.
#[must_use]
#[inline]
pub(crate) fn closest_point_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * ratio(d1, d1 - d3);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * ratio(d2, d2 - d6);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 >= d3 && d5 >= d6 {
        return b + (c - b) * ratio(d4 - d3, (d4 - d3) + (d5 - d6));
    }
    let denom = va + vb + vc;
    if denom > 0.0 && va >= 0.0 && vb >= 0.0 && vc >= 0.0 {
        // NOTE: projecting along the normal, rather than summing barycentric terms, keeps
        // the in-plane position of `p` exact and the error along the normal proportional
        // to `p`'s own distance-scale terms: points just off the face keep a tiny distance.
        let n = ab.cross(ac);
        let n2 = n.length_squared();
        if n2 > 0.0 {
            return p - n * (n.dot(ap) / n2);
        }
    }
    // NOTE: only reachable for (nearly) zero-area triangles, where the region signs are
    // rounding noise; the closest edge point is then the answer to rounding.
    let candidates = [
        closest_point_segment(p, a, b),
        closest_point_segment(p, b, c),
        closest_point_segment(p, c, a),
    ];
    let mut best = candidates[0];
    for q in &candidates[1..] {
        if q.distance_squared(p) < best.distance_squared(p) {
            best = *q;
        }
    }
    best
}

/// The point of the closed segment `a, b` closest to `p`.
#[must_use]
#[inline]
pub(crate) fn closest_point_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    a + ab * ratio((p - a).dot(ab), ab.length_squared())
}

/// Closest points `(on_pq, on_rs)` of the closed segments `p, q` and `r, s`.
///
/// The parameter on `p q` of the closest pair of the two *lines* is the triple-product
/// ratio `((r - p) × d₂) · n / |n|²` with `n = d₁ × d₂` (Ericson's `(bf - ce) / (ae - b²)`
/// in a form that does not cancel: `ae - b² = |n|²`, but the cross product keeps its relative
/// accuracy near `eps / sin θ` for segments at angle `θ`, where the dot-product form loses
/// everything below `θ ≈ 1e-8`). Then, as in Ericson §5.1.9, the parameter is clamped and
/// the points are projected on each other's segment alternately (clamped), which handles
/// the end-point regions and, with `n = 0`, parallel and zero-length segments.
#[must_use]
#[inline]
pub(crate) fn closest_points_segment_segment(
    p: DVec3,
    q: DVec3,
    r: DVec3,
    s: DVec3,
) -> (DVec3, DVec3) {
    let d1 = q - p;
    let d2 = s - r;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let n = d1.cross(d2);
    let nn = n.length_squared();
    let t1 = if nn > 0.0 {
        ratio((r - p).cross(d2).dot(n), nn)
    } else {
        0.0
    };
    let on_pq = p + d1 * t1;
    let on_rs = r + d2 * ratio((on_pq - r).dot(d2), e);
    let on_pq = p + d1 * ratio((on_rs - p).dot(d1), a);
    (on_pq, r + d2 * ratio((on_pq - r).dot(d2), e))
}

/// `num / den` clamped to `[0, 1]`; `0` when `den <= 0` (a degenerate feature).
#[must_use]
#[inline]
fn ratio(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        (num / den).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn point_triangle_finds_each_voronoi_region() {
        let (a, b, c) = (v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0));
        let cases = [
            (v(-1.0, -1.0, 1.0), a),
            (v(3.0, -1.0, 0.0), b),
            (v(-1.0, 3.0, -2.0), c),
            (v(1.0, -1.0, 0.5), v(1.0, 0.0, 0.0)),
            (v(-1.0, 1.0, 0.0), v(0.0, 1.0, 0.0)),
            (v(2.0, 2.0, 1.0), v(1.0, 1.0, 0.0)),
            (v(0.5, 0.5, 3.0), v(0.5, 0.5, 0.0)),
        ];
        for (p, expected) in cases {
            let got = closest_point_triangle(p, a, b, c);
            assert!(
                got.distance(expected) < 1e-15,
                "{p} -> {got}, want {expected}"
            );
        }
    }

    #[test]
    fn point_triangle_handles_zero_area_triangles() {
        let (a, b, c) = (v(0.0, 0.0, 0.0), v(4.0, 0.0, 0.0), v(1.0, 0.0, 0.0));
        let got = closest_point_triangle(v(2.0, 3.0, 0.0), a, b, c);
        assert!(got.distance(v(2.0, 0.0, 0.0)) < 1e-15, "{got}");
        let point = v(1.0, 1.0, 1.0);
        let got = closest_point_triangle(v(5.0, 1.0, 1.0), point, point, point);
        assert_eq!(got, point);
    }

    #[test]
    fn segments_crossing_skew_have_the_perpendicular_closest_pair() {
        let (p, q) = closest_points_segment_segment(
            v(-1.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.5, -1.0, 2.0),
            v(0.5, 1.0, 2.0),
        );
        assert!(p.distance(v(0.5, 0.0, 0.0)) < 1e-15);
        assert!(q.distance(v(0.5, 0.0, 2.0)) < 1e-15);
    }

    #[test]
    fn parallel_and_point_segments_give_valid_closest_pairs() {
        let (p, q) = closest_points_segment_segment(
            v(0.0, 0.0, 0.0),
            v(2.0, 0.0, 0.0),
            v(1.0, 1.0, 0.0),
            v(5.0, 1.0, 0.0),
        );
        assert!((p.distance(q) - 1.0).abs() < 1e-15 && p.x >= 1.0 && p.x <= 2.0);
        let (p, q) = closest_points_segment_segment(
            v(3.0, 3.0, 3.0),
            v(3.0, 3.0, 3.0),
            v(0.0, 0.0, 0.0),
            v(0.0, 0.0, 6.0),
        );
        assert_eq!((p, q), (v(3.0, 3.0, 3.0), v(0.0, 0.0, 3.0)));
        let (p, q) = closest_points_segment_segment(
            v(1.0, 0.0, 0.0),
            v(1.0, 0.0, 0.0),
            v(0.0, 2.0, 0.0),
            v(0.0, 2.0, 0.0),
        );
        assert_eq!((p, q), (v(1.0, 0.0, 0.0), v(0.0, 2.0, 0.0)));
    }
}
