//! Contact manifolds of two placed cores, the engine behind every `manifold_*` function.
//!
//! # Algorithm
//! From the signed distance ([`super::query::distance`]), when it is `≤ 0` (shapes apart
//! along a separating axis skip it):
//! - **Face contact**: when a core has a face whose outward normal is within
//!   [`FACE_ALIGNMENT`] of the contact normal, the better aligned such face is the
//!   *reference*; the other core's *incident* feature (a box's face most opposed to it, the
//!   triangle, the segment or the point) is clipped against the reference face's side planes
//!   (Sutherland–Hodgman, Ericson §8.3.4); each clipped core point is moved onto the
//!   incident surface along the reference normal (for a ball or capsule, where that line
//!   leaves it: the point of the surface in that point's column), projected onto the
//!   reference face, and kept when it is not above it (Gregorius, *Robust Contact Creation
//!   for Physics Simulations*, GDC 2015). The manifold normal is the reference face's.
//! - **Parallel edges** (capsule–capsule, capsule along an edge; within [`EDGE_PARALLEL`]):
//!   B's segment is clipped to A's extent, and each end gives the two surface points on the
//!   line through it along the normal: up to 2 points.
//! - Otherwise (edge–edge, anything against a point): 1 point, the distance witnesses.
//!
//! More than [`MANIFOLD_POINTS`](crate::narrow::contact::MANIFOLD_POINTS) candidates are
//! reduced by [`Manifold::push_reduced`] (the deepest, the farthest from it, then the two
//! that span the largest area).

use super::placed_core::{Kind, PlacedCore, Polygon, line_interval};
use super::query::{FEATURE_RELATIVE, best_axis, distance_with_axis};
use crate::math::DVec3;
use crate::narrow::contact::{Manifold, ManifoldPoint, ShapeDistance};

/// Cosine between a face normal and the contact normal above which the face is a
/// reference face (about 0.8°).
pub(super) const FACE_ALIGNMENT: f64 = 0.9999;

/// Sine of the angle under which two edges (and an edge and the contact plane) count as
/// parallel for a two-point edge contact (about 0.6°).
pub(super) const EDGE_PARALLEL: f64 = 1e-2;

/// Candidate contact points before reduction.
#[derive(Debug, Clone, Copy)]
struct Candidates {
    pts: [ManifoldPoint; 8],
    len: usize,
}

/// Fills `out` with the contact manifold of two placed cores (module docs); empty when
/// they are apart.
pub(super) fn manifold(a: &PlacedCore, b: &PlacedCore, out: &mut Manifold) {
    let axis = best_axis(a, b);
    let slack = FEATURE_RELATIVE * a.scale().max(b.scale());
    if axis.separation - a.radius - b.radius > slack {
        // PERF: apart along an axis by more than rounding (so the distance is positive
        // too): no closest pair needed.
        out.reset(axis.normal);
        return;
    }
    if axis.separation <= 0.0 {
        // Overlapping cores: the distance's normal is the axis (query, step 3).
        manifold_along(a, b, axis.normal, || distance_with_axis(a, b, &axis), out);
    } else {
        manifold_from_distance(a, b, &distance_with_axis(a, b, &axis), out);
    }
}

/// [`manifold`] given the cores' signed distance `d` (from [`super::query`], or from a
/// pair's own faster path with the same contract).
pub(super) fn manifold_from_distance(
    a: &PlacedCore,
    b: &PlacedCore,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    out.reset(d.normal);
    if d.distance > 0.0 {
        return;
    }
    manifold_along(a, b, d.normal, || *d, out);
}

/// The manifold of cores touching or overlapping with contact normal `n` (A→B): the
/// signed distance `distance()` (whose normal is `n`) is computed only when no face or
/// parallel-edge contact gives points and its witnesses are the one point left.
pub(super) fn manifold_along(
    a: &PlacedCore,
    b: &PlacedCore,
    n: DVec3,
    distance: impl FnOnce() -> ShapeDistance,
    out: &mut Manifold,
) {
    let slack = FEATURE_RELATIVE * a.scale().max(b.scale());
    out.reset(n);
    let mut cands = Candidates {
        pts: [ManifoldPoint {
            point_a: DVec3::ZERO,
            point_b: DVec3::ZERO,
            distance: 0.0,
        }; 8],
        len: 0,
    };
    // The better aligned reference face; only that one is built.
    let aligned = |c: Option<f64>| c.filter(|&c| c >= FACE_ALIGNMENT);
    let use_a = match (
        aligned(a.best_face_alignment(n)),
        aligned(b.best_face_alignment(-n)),
    ) {
        (Some(ca), Some(cb)) => Some(ca >= cb),
        (Some(_), None) => Some(true),
        (None, Some(_)) => Some(false),
        (None, None) => None,
    };
    match use_a {
        Some(true) => {
            let (poly, f, _) = a.best_face(n).unwrap_or_default();
            out.normal = f;
            clip_face(&poly, f, a.radius, b, true, slack, &mut cands);
        }
        Some(false) => {
            let (poly, f, _) = b.best_face(-n).unwrap_or_default();
            out.normal = -f;
            clip_face(&poly, f, b.radius, a, false, slack, &mut cands);
        }
        None => parallel_edges(a, b, n, slack, &mut cands),
    }
    if cands.len == 0 {
        let d = distance();
        out.normal = n;
        out.push(ManifoldPoint {
            point_a: d.point_a,
            point_b: d.point_b,
            distance: d.distance,
        });
        return;
    }
    out.push_reduced(&cands.pts[..cands.len]);
}

/// The incident feature of `core` against a reference face of outward normal `f`.
fn incident(core: &PlacedCore, f: DVec3) -> Polygon {
    match core.kind {
        Kind::Box { .. } => match core.best_face(-f) {
            Some((poly, _, _)) => poly,
            None => core.support_feature(-f, 0.0),
        },
        _ => {
            let mut p = Polygon::default();
            for v in core.vertices() {
                p.push(*v);
            }
            p
        }
    }
}

/// Clips `other`'s incident feature against the reference face `poly` (outward normal `f`,
/// radius `r_ref`), adding the points at most the radii above it. `ref_is_a` says which side
/// the reference face is on.
fn clip_face(
    poly: &Polygon,
    f: DVec3,
    r_ref: f64,
    other: &PlacedCore,
    ref_is_a: bool,
    slack: f64,
    out: &mut Candidates,
) {
    // PERF: the incident polygon is clipped back and forth between two buffers; a new
    // polygon per edge (`clipped`) spent a seventh of the manifold's time copying them.
    let mut buffers = [incident(other, f), Polygon::new()];
    let mut current = 0;
    let ref_pts = poly.points();
    let centroid = ref_pts.iter().copied().sum::<DVec3>() / ref_pts.len() as f64;
    for i in 0..ref_pts.len() {
        let (p, q) = (ref_pts[i], ref_pts[(i + 1) % ref_pts.len()]);
        let mut side = (q - p).cross(f);
        if side.dot(centroid - p) > 0.0 {
            side = -side;
        }
        if side.length_squared() > 0.0 {
            let [first, second] = &mut buffers;
            let (from, to) = if current == 0 {
                (&*first, second)
            } else {
                (&*second, first)
            };
            from.clip_plane_into(side, side.dot(p), to);
            current = 1 - current;
        }
    }
    for q in buffers[current].points() {
        // The incident surface point in the column of `q`: for a rounded core, where the
        // line through `q` along `f` leaves it on the reference side.
        let on_inc = if other.radius > 0.0 {
            match line_interval(other, *q, -f) {
                Some((_, exit)) => *q - f * exit,
                None => continue,
            }
        } else {
            *q
        };
        let s = (on_inc - ref_pts[0]).dot(f) - r_ref;
        if s > slack {
            continue;
        }
        let on_ref = on_inc - f * s;
        let (point_a, point_b) = if ref_is_a {
            (on_ref, on_inc)
        } else {
            (on_inc, on_ref)
        };
        if out.len < out.pts.len() {
            out.pts[out.len] = ManifoldPoint {
                point_a,
                point_b,
                distance: s,
            };
            out.len += 1;
        }
    }
}

/// Two parallel edge features (both ⟂ the normal) give up to two points; else none.
fn parallel_edges(a: &PlacedCore, b: &PlacedCore, n: DVec3, slack: f64, out: &mut Candidates) {
    let fa = a.support_feature(n, EDGE_PARALLEL * a.extent());
    let fb = b.support_feature(-n, EDGE_PARALLEL * b.extent());
    if fa.len != 2 || fb.len != 2 {
        return;
    }
    let (da, db) = (fa.pts[1] - fa.pts[0], fb.pts[1] - fb.pts[0]);
    let (la, lb) = (da.length(), db.length());
    if la == 0.0
        || lb == 0.0
        || da.cross(db).length() > EDGE_PARALLEL * la * lb
        || da.dot(n).abs() > EDGE_PARALLEL * la
    {
        return;
    }
    let u = da / la;
    let (t0, t1) = (fa.pts[0].dot(u), fa.pts[1].dot(u));
    let mut seg = fb;
    seg = seg.clipped(u, t1);
    seg = seg.clipped(-u, -t0);
    for q in seg.points() {
        // Both surface points on the line through `q` along `n`: B's where the line leaves
        // B towards A, A's where it enters A from B's side.
        // A bare core's point may sit beside the column through `q`: the other point is
        // then taken in the column through it, so the pair lies along the normal.
        let pair = if is_bare(a) {
            column_point(a, *q, n, Column::Entering)
                .and_then(|pa| Some((pa, column_point(b, pa, n, Column::Leaving)?)))
        } else {
            column_point(b, *q, n, Column::Leaving)
                .and_then(|pb| Some((column_point(a, pb, n, Column::Entering)?, pb)))
        };
        let Some((point_a, point_b)) = pair else {
            continue;
        };
        let s = (point_b - point_a).dot(n);
        if s > slack || out.len == out.pts.len() {
            continue;
        }
        out.pts[out.len] = ManifoldPoint {
            point_a,
            point_b,
            distance: s,
        };
        out.len += 1;
    }
}

/// A point or segment core without radius: nothing for a line to cross.
fn is_bare(core: &PlacedCore) -> bool {
    core.radius == 0.0 && matches!(core.kind, Kind::Point | Kind::Segment)
}

/// Which end of a rounded core's chord a column point takes.
#[derive(Clone, Copy)]
enum Column {
    /// Where the line through `q` along `−n` enters the core (A's side, facing B).
    Entering,
    /// Where it leaves the core (B's side, facing A).
    Leaving,
}

/// The point of `core`'s surface in the column through `q` along the normal `n`.
///
/// A rounded core (radius > 0): where the line meets its surface ([`line_interval`]).
/// A bare point or segment (radius 0) has no width for a line to cross: a discriminant of
/// pure rounding would put the point `√ε·size` off it, or drop it. Its point nearest the
/// line is taken instead, which lies on it exactly.
fn column_point(core: &PlacedCore, q: DVec3, n: DVec3, end: Column) -> Option<DVec3> {
    if !is_bare(core) {
        let (enter, exit) = line_interval(core, q, -n)?;
        let s = match end {
            Column::Entering => enter,
            Column::Leaving => exit,
        };
        return Some(q - n * s);
    }
    let a = core.verts[0];
    let d = if matches!(core.kind, Kind::Segment) {
        core.verts[1] - a
    } else {
        DVec3::ZERO
    };
    // Components across the line; the closest segment point minimises their length.
    let (w, dp) = (a - q, d - n * d.dot(n));
    let wp = w - n * w.dot(n);
    let t = if dp.length_squared() > 0.0 {
        (-wp.dot(dp) / dp.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Some(a + d * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(x: f64, y: f64, depth: f64) -> ManifoldPoint {
        let p = DVec3::new(x, y, 0.0);
        ManifoldPoint {
            point_a: p,
            point_b: p,
            distance: depth,
        }
    }

    #[test]
    fn reduction_keeps_the_deepest_point_and_a_wide_quad() {
        let mut c = Candidates {
            pts: [point(0.0, 0.0, 0.0); 8],
            len: 0,
        };
        // An octagon, one vertex deeper than the rest.
        for i in 0..8u8 {
            let angle = f64::from(i) * std::f64::consts::FRAC_PI_4;
            c.pts[usize::from(i)] =
                point(angle.cos(), angle.sin(), if i == 3 { -0.2 } else { -0.1 });
        }
        c.len = 8;
        let mut m = Manifold::new();
        m.reset(DVec3::Z);
        m.push_reduced(&c.pts[..c.len]);
        let kept = m.points();
        assert_eq!(kept.len(), 4);
        assert_eq!(kept[0].distance, -0.2);
        // Opposite vertices, then the widest: the quad is the inscribed square.
        let area = |p: &[ManifoldPoint]| {
            let mut sum = 0.0;
            let mut q: Vec<DVec3> = p.iter().map(|m| m.point_a).collect();
            q.sort_by(|u, v| u.y.atan2(u.x).total_cmp(&v.y.atan2(v.x)));
            for i in 0..q.len() {
                sum += q[i].cross(q[(i + 1) % q.len()]).z;
            }
            0.5 * sum
        };
        assert!((area(kept) - 2.0).abs() < 1e-12, "{kept:?}");
    }

    #[test]
    fn clipping_keeps_a_segment_a_segment() {
        let mut seg = Polygon::default();
        seg.push(DVec3::new(-2.0, 0.0, 0.0));
        seg.push(DVec3::new(2.0, 0.0, 0.0));
        let out = seg.clipped(DVec3::X, 1.0);
        assert_eq!(
            out.points(),
            &[DVec3::new(-2.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)]
        );
        assert_eq!(seg.clipped(DVec3::X, -3.0).len, 0);
    }
}
