//! Bounding sphere: exact minimum enclosing sphere (Welzl) or Ritter's fast approximation.
//!
//! [`BoundingSphere::fit_points`] runs Welzl's algorithm in its iterative move-to-front form
//! (Welzl 1991, "Smallest enclosing disks (balls and ellipsoids)"; Gärtner 1999, "Fast and
//! robust smallest enclosing balls"): four nested loops, one per support point, over the
//! points in a deterministic pseudo-random order, so the recursion depth is bounded by four
//! and the expected time is linear. Every point that falls outside the current ball is moved
//! to the front of its loop's range, which makes later passes find the hard points first.
//!
//! Edge cases:
//! - Work happens relative to the first point, so clouds 1e6 from the origin keep their
//!   relative precision.
//! - The ball through 3 (near-)collinear or 4 (near-)coplanar support points is undefined;
//!   it falls back to the ball of the farthest pair or the best circumcircle, never NaN.
//! - Whatever the loops produce, the final radius is recomputed as the largest distance
//!   from the final centre to any input point, then padded by
//!   [`conservative_slack`](crate::math::conservative_slack), so every input point passes
//!   [`BoundingVolume::contains_point`] whatever rounding did inside the loops.

use super::BoundingVolume;
use crate::geometry::Triangle;
use crate::math::{DVec3, Isometry, conservative_slack};

mod welzl;

/// A ball: every point within `radius` of `center` (local frame, metres).
///
/// # Invariants
/// `radius >= 0` and finite; `center` finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundingSphere {
    /// Centre, metres.
    pub center: DVec3,
    /// Radius, metres.
    pub radius: f64,
}

impl BoundingSphere {
    /// A sphere from trusted parts (`radius >= 0`, both finite).
    #[must_use]
    #[inline]
    pub fn new(center: DVec3, radius: f64) -> Self {
        debug_assert!(center.is_finite() && radius.is_finite() && radius >= 0.0);
        Self { center, radius }
    }

    /// Ritter's approximate enclosing sphere (Ritter 1990, Graphics Gems): the ball on the
    /// pair found by two farthest-point sweeps, grown over one more pass. At most about 20%
    /// larger than the minimum; two passes over the points, no allocation.
    ///
    /// `points` must be non-empty and finite. The radius is recomputed from the final centre
    /// and padded exactly as in [`fit_points`](BoundingVolume::fit_points).
    #[must_use]
    pub fn fit_points_ritter(points: &[DVec3]) -> Self {
        debug_assert!(!points.is_empty(), "fit of an empty point set");
        let origin = points[0];
        let farthest_from = |from: DVec3| {
            points
                .iter()
                .copied()
                .max_by(|p, q| {
                    p.distance_squared(from)
                        .total_cmp(&q.distance_squared(from))
                })
                .unwrap_or(from)
        };
        let y = farthest_from(origin) - origin;
        let z = farthest_from(y + origin) - origin;
        let mut center = (y + z) * 0.5;
        let mut radius = y.distance(z) * 0.5;
        for p in points {
            let local = *p - origin;
            let d = local.distance(center);
            if d > radius {
                // Grow to the ball just containing the old ball and `local`.
                let new_radius = (radius + d) * 0.5;
                center += (local - center) * ((new_radius - radius) / d);
                radius = new_radius;
            }
        }
        Self::padded_around(points, origin + center)
    }

    /// The ball centred at `center` that contains every point, padded by the slack.
    fn padded_around(points: &[DVec3], center: DVec3) -> Self {
        let mut max_d2 = 0.0_f64;
        let mut max_abs = center.abs().max_element();
        for p in points {
            max_d2 = max_d2.max(p.distance_squared(center));
            max_abs = max_abs.max(p.abs().max_element());
        }
        let radius = max_d2.sqrt();
        Self {
            center,
            radius: radius + conservative_slack(max_abs.max(radius)),
        }
    }

    /// Slack covering rounding in tests that involve this sphere's magnitudes.
    #[inline]
    fn magnitude(&self) -> f64 {
        self.center.abs().max_element() + self.radius
    }
}

impl BoundingVolume for BoundingSphere {
    const NAME: &'static str = "sphere";

    /// The minimum enclosing sphere (Welzl), padded. Allocates one copy of the points.
    fn fit_points(points: &[DVec3]) -> Self {
        debug_assert!(!points.is_empty(), "fit of an empty point set");
        let origin = points[0];
        let mut local: Vec<DVec3> = points.iter().map(|p| *p - origin).collect();
        shuffle(&mut local);
        let ball = welzl::min_ball(&mut local);
        Self::padded_around(points, origin + ball.center)
    }

    fn fit_triangles(triangles: &[Triangle]) -> Self {
        let vertices: Vec<DVec3> = triangles.iter().flat_map(Triangle::vertices).collect();
        Self::fit_points(&vertices)
    }

    /// The exact smallest sphere containing both, padded by the slack.
    fn merged(&self, other: &Self) -> Self {
        let offset = other.center - self.center;
        let d = offset.length();
        let (center, radius) = if d + other.radius <= self.radius {
            (self.center, self.radius)
        } else if d + self.radius <= other.radius {
            (other.center, other.radius)
        } else {
            // d > 0 here: with d == 0 one of the two branches above holds.
            let radius = (d + self.radius + other.radius) * 0.5;
            (self.center + offset * ((radius - self.radius) / d), radius)
        };
        let scale = self.magnitude() + other.magnitude();
        Self {
            center,
            radius: radius + conservative_slack(scale),
        }
    }

    /// The same ball moved by `pose`; the radius grows only by the slack that covers
    /// rounding of the moved centre.
    #[inline]
    fn transformed(&self, pose: &Isometry) -> Self {
        let scale = self.magnitude() + pose.translation.abs().max_element();
        Self {
            center: pose.transform_point(self.center),
            radius: self.radius + conservative_slack(scale),
        }
    }

    #[inline]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool {
        let other_center = pose_ab.transform_point(other.center);
        let scale = self.magnitude() + other.magnitude() + pose_ab.translation.abs().max_element();
        let reach = self.radius + other.radius + conservative_slack(scale);
        self.center.distance_squared(other_center) <= reach * reach
    }

    #[inline]
    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64 {
        let other_center = pose_ab.transform_point(other.center);
        let scale = self.magnitude() + other.magnitude() + pose_ab.translation.abs().max_element();
        let gap = self.center.distance(other_center)
            - self.radius
            - other.radius
            - conservative_slack(scale);
        gap.max(0.0)
    }

    #[inline]
    fn contains_point(&self, point: DVec3) -> bool {
        point.distance_squared(self.center) <= self.radius * self.radius
    }

    #[inline]
    fn center(&self) -> DVec3 {
        self.center
    }

    #[inline]
    fn volume(&self) -> f64 {
        4.0 / 3.0 * std::f64::consts::PI * self.radius.powi(3)
    }

    /// The diameter.
    #[inline]
    fn size(&self) -> f64 {
        2.0 * self.radius
    }

    /// The diameter: every point of the ball lies within `2r` of every other point of the
    /// ball, in particular of any point of the (non-empty) geometry inside it. No tighter
    /// bound holds without knowing the geometry (it may be a single point on the surface).
    #[inline]
    fn stand_off(&self) -> f64 {
        2.0 * self.radius
    }
}

/// Deterministic Fisher–Yates shuffle (splitmix64 with a fixed seed), so fits are
/// reproducible and adversarial input orders lose their power.
fn shuffle(points: &mut [DVec3]) {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut next = || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        crate::math::splitmix64(state)
    };
    for i in (1..points.len()).rev() {
        let j = (next() % (i as u64 + 1)) as usize;
        points.swap(i, j);
    }
}

#[cfg(test)]
mod tests;
