//! The exact triangle–triangle overlap decision, with a common point as witness.
//!
//! Every branch is decided by the signs of [`orient3d`] and [`orient2d_projected`], which
//! are exact, so the answer is the exact answer for the floating-point input. Only the
//! witness point is computed in rounded arithmetic.
//!
//! Each triangle is first reduced, exactly, to the convex hull of its vertices: a proper
//! [`Hull::Triangle`], a [`Hull::Segment`] (collinear vertices; end points by lexicographic
//! order, which is exact along a line) or a [`Hull::Point`]. Pairs of hulls are then decided
//! by these facts about closed convex sets:
//! - two triangles meet iff an edge of one meets the other (their intersection is convex, so
//!   an extreme point of it lies on the boundary of one of them);
//! - a segment crossing a triangle's plane meets it iff the line through it passes through
//!   the triangle: the three `orient3d(p, q, edge)` signs do not disagree (Plücker test);
//! - coplanar sets are decided in a coordinate projection that is one-to-one on their plane
//!   (the one where the reference triangle keeps a non-zero area); a segment's plane is not
//!   known, so coplanar segments must meet in all three coordinate projections: disjoint
//!   convex sets of one plane stay disjoint in every one-to-one projection of it.

use super::closest_points::closest_points_segment_segment;
use crate::geometry::Triangle;
use crate::geometry::predicates::{orient2d_projected, orient3d, project};
use crate::math::DVec3;

/// A proper triangle with the projection that keeps its area.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProperTriangle {
    /// The vertices.
    pub v: [DVec3; 3],
    /// The coordinate axis dropped by the one-to-one projection of its plane.
    pub drop_axis: usize,
    /// `±1`: the sign of the projected orientation.
    pub winding: f64,
}

/// The exact convex hull of a triangle's three vertices.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Hull {
    Point(DVec3),
    Segment(DVec3, DVec3),
    Triangle(ProperTriangle),
}

impl Hull {
    /// Reduces `t` exactly: collinear vertices give a segment, coincident ones a point.
    #[must_use]
    #[inline]
    pub(crate) fn of(t: &Triangle) -> Self {
        let n = t.scaled_normal().abs();
        let order = if n.x >= n.y && n.x >= n.z {
            [0, 1, 2]
        } else if n.y >= n.z {
            [1, 2, 0]
        } else {
            [2, 0, 1]
        };
        for drop_axis in order {
            let o = orient2d_projected(drop_axis, t.a, t.b, t.c);
            if o != 0.0 {
                return Hull::Triangle(ProperTriangle {
                    v: [t.a, t.b, t.c],
                    drop_axis,
                    winding: o.signum(),
                });
            }
        }
        let (mut lo, mut hi) = (t.a, t.a);
        for p in [t.b, t.c] {
            if lex_less(p, lo) {
                lo = p;
            }
            if lex_less(hi, p) {
                hi = p;
            }
        }
        if lo == hi {
            Hull::Point(lo)
        } else {
            Hull::Segment(lo, hi)
        }
    }
}

/// A point common to both hulls (to rounding), or `None` when they are exactly disjoint.
#[must_use]
pub(crate) fn common_point(a: &Hull, b: &Hull) -> Option<DVec3> {
    match (*a, *b) {
        (Hull::Triangle(ta), Hull::Triangle(tb)) => triangle_triangle(&ta, &tb),
        (Hull::Triangle(t), Hull::Segment(p, q)) | (Hull::Segment(p, q), Hull::Triangle(t)) => {
            let [a, b, c] = t.v;
            segment_triangle(
                p,
                q,
                sign(orient3d(a, b, c, p)),
                sign(orient3d(a, b, c, q)),
                &t,
            )
        }
        (Hull::Triangle(t), Hull::Point(p)) | (Hull::Point(p), Hull::Triangle(t)) => {
            let [a, b, c] = t.v;
            (orient3d(a, b, c, p) == 0.0 && point_in_triangle(p, &t)).then_some(p)
        }
        (Hull::Segment(p, q), Hull::Segment(r, s)) => segment_segment(p, q, r, s),
        (Hull::Segment(p, q), Hull::Point(r)) | (Hull::Point(r), Hull::Segment(p, q)) => {
            segment_segment(p, q, r, r)
        }
        (Hull::Point(p), Hull::Point(q)) => (p == q).then_some(p),
    }
}

/// Exact signs of `t`'s vertices relative to the plane of `plane`, with the approximate
/// determinants (proportional to signed distances).
#[must_use]
#[inline]
fn plane_sides(plane: &ProperTriangle, t: &ProperTriangle) -> Sides {
    let [a, b, c] = plane.v;
    // PERF(benches/mesh_pair.rs, collide_all): a floating-point filter with the plane's
    // normal computed once; only vertices too close to the plane to be sure of go to the
    // exact predicate. `orient3d(a, b, c, p) = ((b − a) × (c − a))·(p − a)` (our convention:
    // positive above a counter-clockwise triangle).
    let (u, v) = (b - a, c - a);
    let normal = u.cross(v);
    // The computed `normal·w` is off from the exact determinant by at most ~5ε times the
    // sum of the absolute values of its six triple products (Shewchuk's `o3derrboundA`
    // is 7ε for the same expansion); 16ε times a larger sum is a safe margin.
    let products = (u.y * v.z).abs()
        + (u.z * v.y).abs()
        + (u.z * v.x).abs()
        + (u.x * v.z).abs()
        + (u.x * v.y).abs()
        + (u.y * v.x).abs();
    let d = t.v.map(|p| {
        let w = p - a;
        let approximate = normal.dot(w);
        let permanent = products * w.abs().max_element();
        // Below `FILTER_UNDERFLOW` the products may have lost precision to underflow.
        if permanent > FILTER_UNDERFLOW && approximate.abs() > 16.0 * f64::EPSILON * permanent {
            approximate
        } else {
            orient3d(a, b, c, p)
        }
    });
    (d.map(sign), d)
}

/// Magnitude below which the floating-point filter of [`plane_sides`] defers to the exact
/// predicate (far above the subnormal range, where products lose relative precision).
const FILTER_UNDERFLOW: f64 = 1e-250;

/// `true` when all three signs are strictly positive or all strictly negative.
#[must_use]
#[inline]
pub(crate) fn strictly_one_side(s: [i8; 3]) -> bool {
    (s[0] > 0 && s[1] > 0 && s[2] > 0) || (s[0] < 0 && s[1] < 0 && s[2] < 0)
}

fn triangle_triangle(ta: &ProperTriangle, tb: &ProperTriangle) -> Option<DVec3> {
    match planes(ta, tb) {
        Planes::Apart => None,
        Planes::Coplanar => coplanar_triangle_triangle(ta, tb),
        Planes::Crossing { a, b } => crossing_common_point(ta, tb, a.0, b.0),
    }
}

/// Each proper triangle's vertices against the other's plane: exact signs, with the
/// approximate determinants of [`plane_sides`].
pub(crate) type Sides = ([i8; 3], [f64; 3]);

/// What the two planes of a pair of proper triangles decide.
pub(crate) enum Planes {
    /// One triangle lies strictly on one side of the other's plane: no common point.
    Apart,
    /// Both lie in one plane.
    Coplanar,
    /// Each touches or crosses the other's plane: `a`'s vertices against `b`'s plane and
    /// `b`'s against `a`'s.
    Crossing { a: Sides, b: Sides },
}

/// The plane-side rejection of a pair of proper triangles (Möller; Devillers–Guigue).
#[must_use]
#[inline]
pub(crate) fn planes(ta: &ProperTriangle, tb: &ProperTriangle) -> Planes {
    let b = plane_sides(ta, tb);
    if strictly_one_side(b.0) {
        return Planes::Apart;
    }
    if b.0 == [0, 0, 0] {
        return Planes::Coplanar;
    }
    let a = plane_sides(tb, ta);
    if strictly_one_side(a.0) {
        return Planes::Apart;
    }
    Planes::Crossing { a, b }
}

/// A common point of two proper triangles that each touch or cross the other's plane
/// (`sa`: `ta`'s vertices against `tb`'s plane, `sb` the converse), or `None` when they are
/// exactly disjoint: an edge of one meets the other.
#[must_use]
pub(crate) fn crossing_common_point(
    ta: &ProperTriangle,
    tb: &ProperTriangle,
    sa: [i8; 3],
    sb: [i8; 3],
) -> Option<DVec3> {
    for (i, j) in EDGES {
        if sa[i] * sa[j] <= 0
            && let Some(p) = segment_triangle(ta.v[i], ta.v[j], sa[i], sa[j], tb)
        {
            return Some(p);
        }
    }
    for (i, j) in EDGES {
        if sb[i] * sb[j] <= 0
            && let Some(p) = segment_triangle(tb.v[i], tb.v[j], sb[i], sb[j], ta)
        {
            return Some(p);
        }
    }
    None
}

/// The closed segment `p q` against a proper triangle, given the exact plane sides of `p`
/// and `q`.
fn segment_triangle(p: DVec3, q: DVec3, sp: i8, sq: i8, t: &ProperTriangle) -> Option<DVec3> {
    if sp == 0 && sq == 0 {
        return coplanar_segment_triangle(p, q, t);
    }
    if sp * sq > 0 {
        return None;
    }
    // The line misses the triangle as soon as two of its edges' signs disagree: most
    // segments a collision query tests are settled by the first two predicates.
    let mut seen = 0_i8;
    for (i, j) in EDGES {
        let s = sign(orient3d(p, q, t.v[i], t.v[j]));
        if s * seen < 0 {
            return None;
        }
        if s != 0 {
            seen = s;
        }
    }
    if sp == 0 {
        return Some(p);
    }
    if sq == 0 {
        return Some(q);
    }
    Some(crossing_point(p, q, t))
}

/// Where the segment `p q`, known to cross the proper triangle `t` with `p` and `q` strictly
/// on opposite sides of its plane, meets it (rounded).
///
/// The plane crossing `p + (q - p) dp / (dp - dq)` is ill-conditioned when `p q` is nearly
/// parallel to the plane, so the parameter is clamped to the part of `p q` inside the prism
/// over `t` (the three edge half-spaces that contain the normal): the result is then on
/// `p q`, over `t`, and as close to its plane as the segment gets.
fn crossing_point(p: DVec3, q: DVec3, t: &ProperTriangle) -> DVec3 {
    let [a, b, c] = t.v;
    let n = (b - a).cross(c - a);
    let (dp, dq) = (n.dot(p - a), n.dot(q - a));
    let along = if dp != dq {
        (dp / (dp - dq)).clamp(0.0, 1.0)
    } else {
        0.5
    };
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for (i, j) in EDGES {
        let inward = n.cross(t.v[j] - t.v[i]);
        let (fp, fq) = (inward.dot(p - t.v[i]), inward.dot(q - t.v[i]));
        if fp < 0.0 && fq > fp {
            lo = lo.max(fp / (fp - fq));
        } else if fq < 0.0 && fp > fq {
            hi = hi.min(fp / (fp - fq));
        }
    }
    let along = if lo <= hi { along.clamp(lo, hi) } else { along };
    p + (q - p) * along
}

/// A common point of two proper triangles of one plane, or `None` when they are exactly
/// disjoint.
pub(crate) fn coplanar_triangle_triangle(
    ta: &ProperTriangle,
    tb: &ProperTriangle,
) -> Option<DVec3> {
    if let Some(&p) = tb.v.iter().find(|&&p| point_in_triangle(p, ta)) {
        return Some(p);
    }
    if let Some(&p) = ta.v.iter().find(|&&p| point_in_triangle(p, tb)) {
        return Some(p);
    }
    for (i, j) in EDGES {
        for (k, l) in EDGES {
            let (p, q, r, s) = (ta.v[i], ta.v[j], tb.v[k], tb.v[l]);
            if segments_meet_projected(ta.drop_axis, p, q, r, s) {
                return Some(segment_witness(p, q, r, s));
            }
        }
    }
    None
}

fn coplanar_segment_triangle(p: DVec3, q: DVec3, t: &ProperTriangle) -> Option<DVec3> {
    if point_in_triangle(p, t) {
        return Some(p);
    }
    if point_in_triangle(q, t) {
        return Some(q);
    }
    for (i, j) in EDGES {
        let (r, s) = (t.v[i], t.v[j]);
        if segments_meet_projected(t.drop_axis, p, q, r, s) {
            return Some(segment_witness(p, q, r, s));
        }
    }
    None
}

/// Two closed segments (either may be a point) in 3D.
fn segment_segment(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> Option<DVec3> {
    if orient3d(p, q, r, s) != 0.0 {
        return None;
    }
    (0..3)
        .all(|axis| segments_meet_projected(axis, p, q, r, s))
        .then(|| segment_witness(p, q, r, s))
}

/// `p` in the closed proper triangle `t`, for `p` in `t`'s plane.
#[inline]
fn point_in_triangle(p: DVec3, t: &ProperTriangle) -> bool {
    let [a, b, c] = t.v;
    let axis = t.drop_axis;
    orient2d_projected(axis, a, b, p) * t.winding >= 0.0
        && orient2d_projected(axis, b, c, p) * t.winding >= 0.0
        && orient2d_projected(axis, c, a, p) * t.winding >= 0.0
}

/// Whether the projections of the closed segments `p q` and `r s` (either may be a point)
/// meet, exactly.
fn segments_meet_projected(axis: usize, p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> bool {
    let o1 = sign(orient2d_projected(axis, p, q, r));
    let o2 = sign(orient2d_projected(axis, p, q, s));
    let o3 = sign(orient2d_projected(axis, r, s, p));
    let o4 = sign(orient2d_projected(axis, r, s, q));
    if o1 * o2 < 0 && o3 * o4 < 0 {
        return true;
    }
    let within = |a: DVec3, b: DVec3, x: DVec3| {
        let (a, b, x) = (project(axis, a), project(axis, b), project(axis, x));
        a.min(b).cmple(x).all() && x.cmple(a.max(b)).all()
    };
    (o1 == 0 && within(p, q, r))
        || (o2 == 0 && within(p, q, s))
        || (o3 == 0 && within(r, s, p))
        || (o4 == 0 && within(r, s, q))
}

/// A common point of two segments known to meet: the midpoint of their closest pair.
#[inline]
fn segment_witness(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> DVec3 {
    let (x, y) = closest_points_segment_segment(p, q, r, s);
    (x + y) * 0.5
}

const EDGES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

#[inline]
fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

#[inline]
fn lex_less(a: DVec3, b: DVec3) -> bool {
    (a.x, a.y, a.z) < (b.x, b.y, b.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tiny seeded generator (this module has no access to the test support crate).
    fn next(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn filtered_plane_sides_match_the_exact_predicate_on_and_near_the_plane() {
        let mut state = 7u64;
        let (mut on, mut off) = (0, 0);
        for case in 0..20_000 {
            let scale = [1e-3, 1.0, 1e3, 1e6][case % 4];
            let point = |state: &mut u64| DVec3::new(next(state), next(state), next(state)) * scale;
            let (a, b, c) = (point(&mut state), point(&mut state), point(&mut state));
            let plane = ProperTriangle {
                v: [a, b, c],
                drop_axis: 2,
                winding: 1.0,
            };
            // Dyadic combinations of integer-valued corners lie exactly on the plane; a
            // nudge by one ulp moves them off it.
            let (ai, bi, ci) = (a.round(), b.round(), c.round());
            let exact_plane = ProperTriangle {
                v: [ai, bi, ci],
                drop_axis: 2,
                winding: 1.0,
            };
            let (s, t) = (
                (next(&mut state) * 8.0).floor() / 8.0,
                (next(&mut state) * 8.0).floor() / 8.0,
            );
            let on_plane = ai + (bi - ai) * s + (ci - ai) * t;
            let nudged = DVec3::new(
                on_plane.x,
                on_plane.y,
                f64::from_bits(on_plane.z.to_bits() + 1),
            );
            let other = ProperTriangle {
                v: [on_plane, nudged, point(&mut state)],
                drop_axis: 2,
                winding: 1.0,
            };
            for (p, t) in [(&plane, &other), (&exact_plane, &other)] {
                let (signs, _) = plane_sides(p, t);
                let [x, y, z] = p.v;
                let exact = t.v.map(|q| sign(orient3d(x, y, z, q)));
                assert_eq!(signs, exact, "case {case}");
                on += exact.iter().filter(|&&e| e == 0).count();
                off += exact.iter().filter(|&&e| e != 0).count();
            }
        }
        assert!(on > 1_000 && off > 1_000, "on the plane {on}, off {off}");
    }
}
