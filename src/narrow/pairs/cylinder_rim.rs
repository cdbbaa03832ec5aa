//! A cylinder apart from a box or another cylinder, nearest at a rim: the distance from
//! the rim circle, found by a search along the circle, certified by the support planes
//! through the two witnesses, without GJK.
//!
//! # Why
//! A rim is curved, so GJK converges on it only linearly: on the settling pile a cylinder
//! near a box edge or another cylinder's rim took 25–40 GJK steps, 2–7 µs a pair, where the
//! caps' and side's certificates (`cylinder_certificate`) do not apply. Along the rim the
//! distance is a function of one angle, whose slope is known without differencing.
//!
//! # Search
//! Let `c(θ) = (r cos θ, r sin θ, ±h)` be a point of the rim (computed without
//! trigonometry, from `tan(θ/2)` relative to the start) and `q(θ)` B's point nearest
//! to it (closed form for a box or a cylinder). The distance `f(θ) = |c(θ) − q(θ)|` has
//! slope `f′(θ) = u(θ) · c′(θ)` with `u` the unit vector from `q` to `c` (the gradient of
//! the distance to a convex set at a point outside it is that unit vector). From the angle
//! of B's point nearest the cap's centre, moved twice to the angle of B's point nearest the
//! rim point there, doubling steps (up to about 105° either way) along the descent
//! direction bracket a sign change of the slope, and regula falsi (the Illinois variant,
//! with bisection as the fallback) closes the bracket to rounding. The cap is the one on
//! the side of A's mid-plane where B's origin lies.
//!
//! # Certificate
//! `|c − q|` is a real distance between points of the two shapes: an upper bound. With
//! `n = (q − c) / |q − c|`, the gap between A's support plane along `n` and B's along `−n`
//! is a lower bound (any two points of A and B are at least that far apart along `n`).
//! When the two meet to `rel_tol` (relative) plus rounding, the answer is exact to the
//! dispatcher's tolerance, with real witnesses. They meet only when the pair's nearest
//! points are the rim point and its nearest point of B; any other pair (the closest point
//! of A on a cap face or the side, the shapes touching or overlapping, the search stopped
//! on a local minimum) gives no answer, and the caller runs GJK/EPA. The search never
//! decides correctness; the certificate does.

use crate::geometry::{Cuboid, Cylinder, SupportMap};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::ShapeDistance;
use crate::narrow::gjk::ROUNDING_ULPS;

/// Steps from the cap's centre towards B before the search (module docs).
const START_STEPS: usize = 2;
/// The first step that brackets the slope's sign change, in `tan(θ/2)` of the angle from
/// the start (about 0.04 rad); each further step doubles.
const BRACKET_STEP: f64 = 0.02;
/// Most bracketing steps: up to `t = ±1.3` (about 105°) from the start.
const MAX_BRACKET_STEPS: usize = 6;
/// Most steps of the regula falsi.
const MAX_REFINE_STEPS: usize = 32;
/// The refinement ends once the slope (the cosine between the rim's tangent and the
/// direction to B's nearest point) is this small: the angle is then within about this
/// much of the minimum's relative to the curvature, far inside what the certificate needs
/// (the support planes' gap grows with the square of the normal's error).
const SLOPE_TOL: f64 = 1e-12;

/// A convex shape whose nearest point to any point has a closed form.
pub trait NearestPoint: SupportMap {
    /// The point of the solid nearest to `p` (its own frame): `p` itself when inside.
    fn nearest_point(&self, p: DVec3) -> DVec3;
}

impl NearestPoint for Cylinder {
    #[inline]
    fn nearest_point(&self, p: DVec3) -> DVec3 {
        self.closest_point(p)
    }
}

impl NearestPoint for Cuboid {
    #[inline]
    fn nearest_point(&self, p: DVec3) -> DVec3 {
        p.clamp(-self.half_extents, self.half_extents)
    }
}

/// The distance from cylinder `a` to `b` (placed by `pose_ab`, A's frame) when the pair is
/// apart and nearest at one of A's rims, certified to `rel_tol` (relative) plus rounding
/// (module docs); else `None`. About 10–20 nearest-point calls of `b`, and two support
/// calls. Never NaN: non-finite input gives `None`.
#[must_use]
pub fn certified_rim_distance<B: NearestPoint + ?Sized>(
    a: &Cylinder,
    b: &B,
    pose_ab: &Isometry,
    rel_tol: f64,
) -> Option<ShapeDistance> {
    let (r, h) = (a.radius, a.half_height);
    if r <= 0.0 {
        return None;
    }
    let cap_z = h.copysign(pose_ab.translation.z);
    let nearest_b =
        |p: DVec3| pose_ab.transform_point(b.nearest_point(pose_ab.inverse_transform_point(p)));
    // The start: the direction of B's point nearest the cap's centre, then of B's point
    // nearest the rim point there, twice (one step lands on the minimum when B's nearest
    // feature is flat).
    let radial = |p: DVec3| DVec3::new(p.x, p.y, 0.0).try_normalize();
    let mut base = radial(nearest_b(DVec3::new(0.0, 0.0, cap_z)))?;
    for _ in 0..START_STEPS {
        base = radial(nearest_b(base * r + DVec3::Z * cap_z))?;
    }
    // The rim point at angle 2·atan(t) from `base`, and the tangent there: rational in `t`,
    // no trigonometry.
    let rim = |t: f64| {
        let (w, two_t) = (1.0 / (1.0 + t * t), 2.0 * t);
        let (cos, sin) = ((1.0 - t * t) * w, two_t * w);
        let along = DVec3::new(
            base.x * cos - base.y * sin,
            base.x * sin + base.y * cos,
            0.0,
        );
        (
            along * r + DVec3::Z * cap_z,
            DVec3::new(-along.y, along.x, 0.0),
        )
    };
    // The slope of the distance along the rim (up to a positive factor): u · tangent.
    let slope = |t: f64| {
        let (c, tangent) = rim(t);
        let u = c - nearest_b(c);
        u.dot(tangent) / u.length()
    };
    let t = bracket_and_refine(&slope)?;
    let (point_a, _) = rim(t);
    let point_b = nearest_b(point_a);
    certify(a, b, pose_ab, (point_a, point_b), rel_tol)
}

/// The parameter where `slope` changes sign from negative to positive (a minimum of the
/// distance), searched from 0 (the start); `None` when no sign change is found within the
/// bracketing steps or the slope is not finite.
fn bracket_and_refine(slope: &impl Fn(f64) -> f64) -> Option<f64> {
    let start = 0.0;
    let s0 = slope(start);
    if !s0.is_finite() {
        return None;
    }
    if s0.abs() <= SLOPE_TOL {
        return Some(start);
    }
    // Descend: against the slope's sign, until it flips.
    let mut step = -BRACKET_STEP.copysign(s0);
    let (mut lo, mut s_lo) = (start, s0);
    let mut hi = start;
    let mut s_hi = s0;
    for _ in 0..MAX_BRACKET_STEPS {
        hi = lo + step;
        s_hi = slope(hi);
        if !s_hi.is_finite() {
            return None;
        }
        if s_hi.signum() != s0.signum() {
            break;
        }
        (lo, s_lo) = (hi, s_hi);
        step *= 2.0;
    }
    if s_hi.signum() == s0.signum() {
        return None;
    }
    // Illinois regula falsi on [lo, hi] (either order), the slope of opposite signs at the
    // ends; the end kept twice in a row has its value halved.
    let mut kept_side = 0i8;
    for _ in 0..MAX_REFINE_STEPS {
        let denominator = s_hi - s_lo;
        let mut mid = hi - s_hi * (hi - lo) / denominator;
        let (min, max) = (lo.min(hi), lo.max(hi));
        if !(mid > min && mid < max) {
            mid = 0.5 * (lo + hi);
        }
        if mid <= min || mid >= max {
            // The bracket is one ulp wide.
            break;
        }
        let s_mid = slope(mid);
        if !s_mid.is_finite() {
            return None;
        }
        if s_mid.abs() <= SLOPE_TOL {
            return Some(mid);
        }
        if s_mid.signum() == s_hi.signum() {
            (hi, s_hi) = (mid, s_mid);
            if kept_side == -1 {
                s_lo *= 0.5;
            }
            kept_side = -1;
        } else {
            (lo, s_lo) = (mid, s_mid);
            if kept_side == 1 {
                s_hi *= 0.5;
            }
            kept_side = 1;
        }
    }
    // Either end is as good to rounding; the one of the smaller slope is nearer the root.
    Some(if s_lo.abs() <= s_hi.abs() { lo } else { hi })
}

/// The exact answer when the support planes through witnesses `point_a` (on A) and
/// `point_b` (on B) along their direction meet the witnesses' distance to tolerance.
fn certify<B: SupportMap + ?Sized>(
    a: &Cylinder,
    b: &B,
    pose_ab: &Isometry,
    (point_a, point_b): (DVec3, DVec3),
    rel_tol: f64,
) -> Option<ShapeDistance> {
    let gap = point_b - point_a;
    let distance = gap.length();
    if !(distance.is_finite() && distance > 0.0) {
        return None;
    }
    let normal = gap / distance;
    let support_a = a.support(normal);
    let support_b = pose_ab.transform_point(b.support(pose_ab.inverse_transform_vector(-normal)));
    let lower = normal.dot(support_b - support_a);
    let scale = support_a
        .abs()
        .max_element()
        .max(support_b.abs().max_element())
        .max(point_b.abs().max_element());
    let slack = rel_tol * distance + ROUNDING_ULPS * f64::EPSILON * scale;
    (distance - lower <= slack).then_some(ShapeDistance {
        distance,
        point_a,
        point_b,
        normal,
    })
}

#[cfg(test)]
#[path = "cylinder_rim_tests.rs"]
mod tests;
