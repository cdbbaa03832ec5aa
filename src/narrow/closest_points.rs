//! Closest points between simple features: point–triangle and segment–segment.
//!
//! Floating-point, branch-light helpers for [`super::triangle_triangle`], the primitive
//! pairs and the mesh queries; all accept degenerate input (zero-length segments,
//! zero-area triangles) without producing NaN.
//!
//! Citation: C. Ericson, *Real-Time Collision Detection*, Morgan Kaufmann 2005, §5.1.5
//! (closest point on a triangle) and §5.1.9 (closest points of two segments).

use crate::math::DVec3;

/// The point of the closed triangle `a, b, c` closest to `p` (same frame as the inputs).
///
/// Accurate to a few ulps of the coordinates for every triangle, thin and zero-area ones
/// included (a zero-area triangle is the segment or point it spans).
///
/// Method: the triangle is described in the frame of its longest edge `o → e` (the
/// hinge): `u` along it, `v` the unit component of the third vertex `w` across it (`t`
/// its length, the triangle's thickness), so the triangle is the 2-D triangle `(0, 0),
/// (|e − o|, 0), ((w − o)·u, t)` of the plane spanned by `u, v`. If `p`'s coordinates in
/// that frame fall inside it the answer is `p` projected on the plane, else it lies on an
/// edge whose inner side `p` is not on, and the closest point of those edges (in 3-D) is
/// the answer.
///
/// NOTE: Ericson's Voronoi-region method with the normal `(b − a) × (c − a)` is not used:
/// for a thin triangle that normal carries a relative error `eps / sin θ` (smallest angle
/// `θ`) and the region signs cancel, so the projected face point lands off the triangle —
/// by about its thickness when thin and arbitrarily far when the normal is rounding noise
/// (e.g. `a, b, a + 0.3 (b − a)` after a rotation). In the hinge frame the tilt error of
/// `v`, `eps / t` of the size, multiplies only a coordinate across the hinge, which is at
/// most `t` for points of the triangle: the frame describes a copy of the triangle moved by
/// a few ulps, and the answer is exact for that copy to rounding.
#[must_use]
#[inline]
pub(crate) fn closest_point_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    HingeFrame::new(a, b, c).closest_point(p)
}

/// A triangle described in the frame of its longest edge, as
/// [`closest_point_triangle`] describes it: built once, then queried for many points
/// (triangle–triangle distance asks for three), each answer the same as
/// [`closest_point_triangle`]'s.
#[derive(Debug, Clone, Copy)]
pub(crate) enum HingeFrame {
    /// All three vertices coincide.
    Point(DVec3),
    /// Thinner than rounding: the triangle is within that of its longest edge `o → e`,
    /// which spans it.
    Edge(DVec3, DVec3),
    /// The 2-D triangle `(0, 0), (len, 0), (xw, t)` of the plane through `o` spanned by
    /// the unit vectors `u` (along the hinge `o → e`) and `v` (across it, towards `w`).
    Face {
        o: DVec3,
        e: DVec3,
        w: DVec3,
        u: DVec3,
        v: DVec3,
        len: f64,
        xw: f64,
        t: f64,
    },
}

impl HingeFrame {
    /// The frame of the closed triangle `a, b, c`.
    #[must_use]
    #[inline]
    pub(crate) fn new(a: DVec3, b: DVec3, c: DVec3) -> Self {
        debug_assert!(a.is_finite() && b.is_finite() && c.is_finite());
        let (ab, bc, ca) = (
            (b - a).length_squared(),
            (c - b).length_squared(),
            (a - c).length_squared(),
        );
        let (o, e, w) = if ab >= bc && ab >= ca {
            (a, b, c)
        } else if bc >= ca {
            (b, c, a)
        } else {
            (c, a, b)
        };
        let len2 = ab.max(bc).max(ca);
        if len2 == 0.0 {
            return Self::Point(a);
        }
        let len = len2.sqrt();
        let u = (e - o) / len;
        let ow = w - o;
        let xw = ow.dot(u);
        // NOTE: the second Gram–Schmidt pass is needed: the first leaves a component along
        // `u` of `eps |w − o|`, which is large relative to a small `t` (a needle or a
        // sliver) and would skew the frame, adding `x (u · v)` to every `y`.
        let across = ow - u * xw;
        let across = across - u * across.dot(u);
        let t = across.length();
        // NOTE: the first pass errs by about `4 eps |w − o|`; a smaller `t` is rounding
        // (possibly along `u`, for exactly collinear input) and gives no direction. The
        // triangle is then within that of its longest edge, which spans it.
        if t <= 8.0 * f64::EPSILON * ow.length() {
            return Self::Edge(o, e);
        }
        Self::Face {
            o,
            e,
            w,
            u,
            v: across / t,
            len,
            xw,
            t,
        }
    }

    /// The point of the triangle closest to `p` (same frame as the triangle).
    #[must_use]
    #[inline(always)]
    pub(crate) fn closest_point(&self, p: DVec3) -> DVec3 {
        debug_assert!(p.is_finite());
        match *self {
            Self::Point(a) => a,
            Self::Edge(o, e) => closest_point_segment(p, o, e),
            Self::Face {
                o,
                e,
                w,
                u,
                v,
                len,
                xw,
                t,
            } => {
                let d = p - o;
                let (x, y) = (d.dot(u), d.dot(v));
                // Inner sides of the 2-D triangle (0, 0) → (len, 0) → (xw, t),
                // counter-clockwise.
                let inner_oe = y >= 0.0;
                let inner_ew = (xw - len) * y - t * (x - len) >= 0.0;
                let inner_wo = t * (x - xw) - xw * (y - t) >= 0.0;
                if inner_oe && inner_ew && inner_wo {
                    let m = u.cross(v);
                    return p - m * d.dot(m);
                }
                let mut best = None::<DVec3>;
                for (inner, x0, x1) in [(inner_oe, o, e), (inner_ew, e, w), (inner_wo, w, o)] {
                    if !inner {
                        let q = closest_point_segment(p, x0, x1);
                        if best.is_none_or(|b| q.distance_squared(p) < b.distance_squared(p)) {
                            best = Some(q);
                        }
                    }
                }
                best.unwrap_or(p)
            }
        }
    }
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
#[inline(always)]
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
#[path = "closest_points_tests.rs"]
mod tests;
