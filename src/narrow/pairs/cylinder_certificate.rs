//! A cylinder against any convex shape given by its support map: the signed distance
//! certified from three support calls or a few more, without GJK or EPA, or nothing.
//!
//! # Bounds
//! For a unit direction `n`, let `p` be B's deepest point along `−n` (its support point)
//! and `δ(n) = h_A(n) − n·p` the overlap of the two along `n` (`h_A` the cylinder's support
//! value). Every `n` bounds the answer from one side, every point of B from the other:
//! - overlapping: moving B by `δ(n)·n` separates the two, so the depth is at most `δ(n)`;
//!   a point `p` of B inside A leaves A only under a translation of at least its distance
//!   to A's boundary, `room(p) = min(half_height − |z|, radius − ρ)`, so the depth is at
//!   least `room(p)` (van den Bergen, *Collision Detection in Interactive 3D
//!   Environments*, §4.3.4, penetration depth as a minimum over directions);
//! - apart: B lies beyond the plane `x·n = h_A(n)` by `−δ(n)`, a lower bound of the
//!   distance, and any point `p` of B is a real point at `dist(p, A)` (the closed form of
//!   `sphere_cylinder`), an upper bound.
//!
//! When the two bounds meet (to the dispatcher's relative tolerance, the one GJK and EPA
//! stop at, plus rounding), the answer is exact and its witnesses are real points. Tried in
//! turn, each proof ending the search:
//! - the cap of least overlap, with B's deepest point under it (a box, hull or cylinder
//!   standing on the cap, or the cap resting on it): two support calls;
//! - the side, along the radial direction from the axis to the point of B's *shadow* (B
//!   projected along the axis onto the cross-section plane) nearest the axis, found by GJK
//!   in that plane; the point of B over it gives the lower bound. A polytope's shadow is a
//!   polygon, so this takes a few support calls when B rests on the side by a vertex, an
//!   edge or a face (a box, hull, capsule or parallel cylinder against a cylinder lying
//!   down).
//!
//! Contacts at a rim, and crossings whose deepest point is not over a cap or the side, give
//! bounds that do not meet: the caller runs GJK/EPA. Measured on the settling pile
//! (`benches/pile.rs`, frame `k`'s 138 pairs with a cylinder, alternating in one run): the
//! distance queries took 116 µs against 149 µs by GJK/EPA alone.
//!
//! # Rounding
//! Each bound is evaluated from the same rounded `p`: a cap's overlap and its room are
//! one subtraction, so they agree exactly; the side's differ by the shadow GJK's remaining
//! gap, which it ends at rounding level. `p` itself carries the rounding of B's support map
//! and pose, as every method's witnesses do.

use super::face_certificate::FaceCertificate;
use crate::geometry::{Cylinder, SupportMap};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::ShapeDistance;
use crate::narrow::gjk::ROUNDING_ULPS;
use std::cell::Cell;

/// Most GJK steps towards B's shadow (each one support call of B).
const SHADOW_STEPS: usize = 16;
/// The shadow's GJK stops when `|v|² − v·w` is at most this share of `|v|²`.
const SHADOW_REL_TOL: f64 = 1e-15;

/// One direction tried: the outward normal `n` of A, B's deepest point `p` along `−n`
/// (A's frame), and the overlap `δ(n)` (negative: a gap).
#[derive(Debug, Clone, Copy)]
struct Probe {
    n: DVec3,
    p: DVec3,
    overlap: f64,
}

/// The signed distance from cylinder `a` to the convex shape `b` (its support map in B's
/// frame) placed by `pose_ab`, A's frame, when the bounds of the module docs meet to
/// `rel_tol` (relative) plus rounding; a lower bound when B is apart beyond a plane of A by
/// more than `limit` metres; else [`FaceCertificate::Unknown`]. Two support calls of `b`
/// for the caps, and up to `SHADOW_STEPS` + 2 more when the side is tried; never NaN
/// (non-finite input gives `Unknown`).
#[must_use]
pub fn certified_distance_cylinder_convex<S: SupportMap + ?Sized>(
    a: &Cylinder,
    b: &S,
    pose_ab: &Isometry,
    rel_tol: f64,
    limit: f64,
) -> FaceCertificate {
    let (h, r) = (a.half_height, a.radius);
    let to_b = pose_ab.rotation.transpose();
    let hint = Cell::new(0);
    let probe = |n: DVec3| {
        let mut at = hint.get();
        let p = pose_ab.transform_point(b.support_from(to_b * -n, &mut at));
        hint.set(at);
        let reach = if n.z == 0.0 { r } else { h };
        Probe {
            n,
            p,
            overlap: reach - n.dot(p),
        }
    };
    let [up, down] = [probe(DVec3::Z), probe(DVec3::NEG_Z)];
    let cap = if up.overlap <= down.overlap { up } else { down };
    if let Some(d) = settled(a, &cap, &[cap.p], rel_tol) {
        return FaceCertificate::Exact(d);
    }
    let mut least = cap;
    if let Some((side, over_side)) = side_probe(&probe, pose_ab.translation) {
        least = if side.overlap < cap.overlap {
            side
        } else {
            cap
        };
        if let Some(d) = settled(a, &least, &[cap.p, side.p, over_side], rel_tol) {
            return FaceCertificate::Exact(d);
        }
    }
    let gap = -least.overlap;
    if gap > limit && least.p.is_finite() {
        return FaceCertificate::Beyond(ShapeDistance {
            distance: gap,
            point_a: a.closest_point(least.p),
            point_b: least.p,
            normal: least.n,
        });
    }
    FaceCertificate::Unknown
}

/// The exact answer when the bounds of the module docs meet: `least` is the probe of least
/// overlap (its `δ(n)` the upper bound of the depth, or minus it the lower bound of the
/// distance), `points` are points of B (A's frame) whose room (overlapping) or distance to
/// A (apart) bounds the answer from the other side.
fn settled(a: &Cylinder, least: &Probe, points: &[DVec3], rel_tol: f64) -> Option<ShapeDistance> {
    if !(least.overlap.is_finite() && least.p.is_finite()) {
        return None;
    }
    let scale = least.p.abs().max_element().max(a.half_height).max(a.radius);
    let slack = |value: f64| rel_tol * value + ROUNDING_ULPS * f64::EPSILON * scale;
    if least.overlap > 0.0 {
        let depth = least.overlap;
        let lower = points
            .iter()
            .map(|&p| room(a, p))
            .fold(f64::NEG_INFINITY, f64::max);
        return (depth - lower <= slack(depth)).then_some(ShapeDistance {
            distance: -depth,
            point_a: least.p + least.n * depth,
            point_b: least.p,
            normal: least.n,
        });
    }
    let gap = -least.overlap;
    let (p, on_a) = points
        .iter()
        .map(|&p| (p, a.closest_point(p)))
        .min_by(|x, y| {
            (x.0 - x.1)
                .length_squared()
                .total_cmp(&(y.0 - y.1).length_squared())
        })?;
    let distance = (p - on_a).length();
    (distance - gap <= slack(distance)).then(|| ShapeDistance {
        distance,
        point_a: on_a,
        point_b: p,
        normal: if distance > 0.0 {
            (p - on_a) / distance
        } else {
            least.n
        },
    })
}

/// The side's probe: `n` the radial direction from A's axis to the point of B's shadow
/// (B projected along Z onto A's cross-section plane) nearest the axis, and `q`, B's point
/// over that nearest point (the same convex combination of B's support points), whose room
/// is the side's lower bound. Found by GJK in the plane from the origin, starting towards
/// B's centre `centre` (A's frame). `None` when the origin lies in the shadow (to
/// rounding; the side is then not the way out) or the input is not finite.
fn side_probe(probe: &impl Fn(DVec3) -> Probe, centre: DVec3) -> Option<(Probe, DVec3)> {
    let flat = |p: DVec3| DVec3::new(p.x, p.y, 0.0);
    let mut q = probe(flat(centre).try_normalize().unwrap_or(DVec3::X)).p;
    // The simplex: up to two points of B whose shadows bound the nearest point.
    let mut simplex: [DVec3; 2] = [q, q];
    let mut count = 1;
    for _ in 0..SHADOW_STEPS {
        // The nearest point so far; B's support point along it is the side's probe.
        let v = flat(q);
        let vv = v.length_squared();
        if !vv.is_finite() || vv <= f64::MIN_POSITIVE {
            return None;
        }
        let along = probe(v / vv.sqrt());
        let w = along.p;
        if !w.is_finite() {
            return None;
        }
        // Converged: no support point is nearer the origin along `v` than `v` itself.
        if vv - v.dot(flat(w)) <= SHADOW_REL_TOL * vv {
            return Some((along, q));
        }
        // The nearest point of the segments from `w` to the simplex's points (2D); the
        // origin inside the triangle they span means the shadow covers the axis.
        let mut best = (flat(w).length_squared(), w, w, 1.0);
        for &s in &simplex[..count] {
            let (a, b) = (flat(w), flat(s));
            let e = b - a;
            let ee = e.length_squared();
            if ee > 0.0 {
                let t = (-a.dot(e) / ee).clamp(0.0, 1.0);
                let d2 = (a + e * t).length_squared();
                if d2 < best.0 {
                    best = (d2, w, s, 1.0 - t);
                }
            }
        }
        if count == 2 && in_triangle(flat(w), flat(simplex[0]), flat(simplex[1])) {
            return None;
        }
        let (d2, a, b, t) = best;
        if d2 >= vv {
            // No progress: rounding.
            return Some((along, q));
        }
        q = a * t + b * (1.0 - t);
        (simplex, count) = if t < 1.0 { ([a, b], 2) } else { ([a, a], 1) };
    }
    Some((probe(flat(q).try_normalize()?), q))
}

/// Whether the origin lies in the triangle `a b c` of the XY plane (inclusive).
fn in_triangle(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let cross = |p: DVec3, q: DVec3| p.x * q.y - p.y * q.x;
    let (s1, s2, s3) = (cross(a, b), cross(b, c), cross(c, a));
    (s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) || (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0)
}

/// The distance of `p` (A's frame) to the cylinder's boundary when inside, else ≤ 0.
fn room(a: &Cylinder, p: DVec3) -> f64 {
    let rho = DVec3::new(p.x, p.y, 0.0).length();
    (a.half_height - p.z.abs()).min(a.radius - rho)
}
