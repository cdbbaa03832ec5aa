//! The answers every pair query of the narrow phase gives: a signed distance with witness
//! points, and a contact manifold.
//!
//! # Contract (DESIGN §4), for every pair of shapes A and B
//! - Frame: everything is in the query frame, A's local frame; B is placed by `pose_ab`
//!   (B's frame expressed in A's).
//! - [`ShapeDistance::distance`] is signed: `> 0` the gap, `< 0` minus the penetration depth
//!   (the length of the shortest translation of B that separates them), `0` touching.
//! - [`ShapeDistance::normal`] is a unit vector from A to B: along `point_b − point_a` when
//!   apart; the direction that shortest translation moves B when penetrating. Never NaN:
//!   when no direction is defined (coincident centres) a fixed, documented choice is made.
//! - `point_a` lies on A's surface, `point_b` on B's (to rounding), and
//!   `point_b − point_a = distance · normal` (to rounding).
//! - Symmetry: swapping A and B (with the inverse pose) gives the same distance, swapped
//!   points and the opposite normal.
//! - A [`Manifold`] holds at most [`MANIFOLD_POINTS`] points sharing one normal (A→B), each
//!   with the points on both surfaces and its signed distance (`≤ 0` for touching or
//!   penetrating points).

use crate::math::DVec3;

/// The most points a contact manifold holds.
pub const MANIFOLD_POINTS: usize = 4;

/// The signed distance between two shapes, with witnesses (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeDistance {
    /// Signed distance, metres (negative: penetration depth).
    pub distance: f64,
    /// Witness on A's surface, A's frame.
    pub point_a: DVec3,
    /// Witness on B's surface, A's frame.
    pub point_b: DVec3,
    /// Unit normal from A to B, A's frame.
    pub normal: DVec3,
}

impl ShapeDistance {
    /// The same answer seen from B: points swapped, normal reversed, mapped by `pose_ba`
    /// (A's frame expressed in B's) into B's frame.
    #[must_use]
    pub fn flipped(&self, pose_ba: &crate::math::Isometry) -> Self {
        Self {
            distance: self.distance,
            point_a: pose_ba.transform_point(self.point_b),
            point_b: pose_ba.transform_point(self.point_a),
            normal: pose_ba.transform_vector(-self.normal),
        }
    }
}

/// Bounds on the signed distance between two shapes from a test cheaper than the exact
/// query (the separating axes; closest features only where they cost no more), A's frame:
/// what a pair gets when there is no time for its exact answer, or all a query needs to
/// know it is beyond its limit.
///
/// - `lower ≤ exact signed distance ≤ upper`, rounding included.
/// - `normal` is the unit axis A→B that gave `lower`: the shapes' projections on it are
///   `lower` apart (overlapping by `−lower` when negative).
/// - `point_a` and `point_b` lie on the two shapes' supporting planes across that axis,
///   `point_b − point_a = lower · normal` as in a [`ShapeDistance`], and at least one of
///   them lies on its shape's surface (the query takes B's point farthest along `−normal`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DistanceBound {
    /// Lower bound on the signed distance, metres.
    pub lower: f64,
    /// Upper bound on the signed distance, metres.
    pub upper: f64,
    /// Unit axis from A to B, A's frame.
    pub normal: DVec3,
    /// On A's supporting plane, A's frame.
    pub point_a: DVec3,
    /// On B's supporting plane, A's frame.
    pub point_b: DVec3,
}

impl DistanceBound {
    /// The bounds `lower` and `upper` (raised to `lower` when below it) along the unit axis
    /// `normal`, with B's witness `point_b` and A's across the axis from it.
    #[must_use]
    pub fn new(lower: f64, upper: f64, normal: DVec3, point_b: DVec3) -> Self {
        Self {
            lower,
            upper: upper.max(lower),
            normal,
            point_a: point_b - normal * lower,
            point_b,
        }
    }

    /// An exact answer `d` as bounds, `slack` metres (its rounding) either side.
    #[must_use]
    pub fn exact(d: &ShapeDistance, slack: f64) -> Self {
        Self::new(d.distance - slack, d.distance + slack, d.normal, d.point_b)
    }

    /// The same bounds seen from B (see [`ShapeDistance::flipped`]).
    #[must_use]
    pub fn flipped(&self, pose_ba: &crate::math::Isometry) -> Self {
        Self {
            lower: self.lower,
            upper: self.upper,
            normal: pose_ba.transform_vector(-self.normal),
            point_a: pose_ba.transform_point(self.point_b),
            point_b: pose_ba.transform_point(self.point_a),
        }
    }

    /// The bounds as a [`ShapeDistance`] at the lower bound (its witnesses and normal).
    #[must_use]
    pub fn at_lower(&self) -> ShapeDistance {
        ShapeDistance {
            distance: self.lower,
            point_a: self.point_a,
            point_b: self.point_b,
            normal: self.normal,
        }
    }
}

/// A pair's signed distance as far as the frame's clock let its query go
/// ([`dispatch::distance_within`](super::dispatch::distance_within)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reached {
    /// The query finished: its exact answer.
    Exact(ShapeDistance),
    /// The clock stopped it: bounds on the signed distance (`upper` may be `+∞` when it
    /// found no candidate yet), with the axis and witness of the best answer found.
    Bounded(DistanceBound),
    /// The query finished, but rounding stopped it short of its tolerance (EPA's polytope
    /// broken near the answer, [`gjk::epa`](super::gjk::epa)): the signed distance lies
    /// between the bounds, a gap at f64's resolution on the shapes, and the answer is
    /// [`DistanceBound::at_lower`]. Work left undone would not narrow it.
    Resolved(DistanceBound),
}

impl Reached {
    /// The same answer seen from B (see [`ShapeDistance::flipped`]).
    #[must_use]
    pub fn flipped(&self, pose_ba: &crate::math::Isometry) -> Self {
        match self {
            Self::Exact(d) => Self::Exact(d.flipped(pose_ba)),
            Self::Bounded(b) => Self::Bounded(b.flipped(pose_ba)),
            Self::Resolved(b) => Self::Resolved(b.flipped(pose_ba)),
        }
    }

    /// How far, metres, the true signed distance may lie above [`at_lower`](Self::at_lower):
    /// 0 when exact, the bounds' width otherwise (for [`Resolved`](Self::Resolved), the gap
    /// rounding left).
    #[must_use]
    pub fn width(&self) -> f64 {
        match self {
            Self::Exact(_) => 0.0,
            Self::Bounded(b) | Self::Resolved(b) => b.upper - b.lower,
        }
    }

    /// The answer at the lower end: exact, or the bounds' [`DistanceBound::at_lower`].
    #[must_use]
    pub fn at_lower(&self) -> ShapeDistance {
        match self {
            Self::Exact(d) => *d,
            Self::Bounded(b) | Self::Resolved(b) => b.at_lower(),
        }
    }
}

/// One point of a contact manifold, A's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ManifoldPoint {
    /// Point on A's surface.
    pub point_a: DVec3,
    /// Point on B's surface.
    pub point_b: DVec3,
    /// Signed distance along the manifold normal, metres (`≤ 0` touching or penetrating).
    pub distance: f64,
}

/// Up to [`MANIFOLD_POINTS`] contact points with one normal (A→B), A's frame. Filled in
/// place, so building one never allocates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Manifold {
    /// Unit normal from A to B.
    pub normal: DVec3,
    points: [ManifoldPoint; MANIFOLD_POINTS],
    len: usize,
}

impl Default for Manifold {
    fn default() -> Self {
        Self::new()
    }
}

impl Manifold {
    const NO_POINT: ManifoldPoint = ManifoldPoint {
        point_a: DVec3::ZERO,
        point_b: DVec3::ZERO,
        distance: 0.0,
    };

    /// An empty manifold.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            normal: DVec3::ZERO,
            points: [Self::NO_POINT; MANIFOLD_POINTS],
            len: 0,
        }
    }

    /// The same manifold seen from B, in place: each point's witnesses swapped, the normal
    /// reversed, all mapped by `pose_ba` (A's frame expressed in B's) into B's frame, as
    /// [`ShapeDistance::flipped`].
    pub fn flip(&mut self, pose_ba: &crate::math::Isometry) {
        let mut flipped = Self::new();
        flipped.reset(pose_ba.transform_vector(-self.normal));
        for p in self.points() {
            flipped.push(ManifoldPoint {
                point_a: pose_ba.transform_point(p.point_b),
                point_b: pose_ba.transform_point(p.point_a),
                distance: p.distance,
            });
        }
        *self = flipped;
    }

    /// The one-point manifold of a signed distance: its witnesses under its normal when the
    /// shapes touch or overlap (`distance ≤ 0`), else empty with that normal. Pairs whose
    /// manifold is one point build it so, and then it always agrees with the distance.
    pub fn set_from_distance(&mut self, d: &ShapeDistance) {
        self.reset(d.normal);
        if d.distance <= 0.0 {
            self.push(ManifoldPoint {
                point_a: d.point_a,
                point_b: d.point_b,
                distance: d.distance,
            });
        }
    }

    /// Adds the most informative [`MANIFOLD_POINTS`] of `pts` (all of them when they are
    /// few): the deepest, the farthest from it, the one spanning the largest triangle with
    /// those, then the one farthest outside that triangle — positions on A's surface, areas
    /// about the manifold's normal. Points on one line give its two ends; a fourth inside the
    /// triangle is left out.
    pub fn push_reduced(&mut self, pts: &[ManifoldPoint]) {
        let (normal, out) = (self.normal, self);
        if pts.len() <= MANIFOLD_POINTS {
            for p in pts {
                out.push(*p);
            }
            return;
        }
        let pos = |i: usize| pts[i].point_a;
        let mut chosen = [usize::MAX; MANIFOLD_POINTS];
        let best = |score: &dyn Fn(usize) -> f64, chosen: &[usize]| {
            (0..pts.len())
                .filter(|i| !chosen.contains(i))
                .max_by(|&i, &j| score(i).total_cmp(&score(j)))
                .unwrap_or(0)
        };
        chosen[0] = best(&|i| -pts[i].distance, &chosen);
        let p0 = pos(chosen[0]);
        chosen[1] = best(&|i| pos(i).distance_squared(p0), &chosen);
        let p1 = pos(chosen[1]);
        let area = |x: DVec3, y: DVec3, z: DVec3| (y - x).cross(z - x).dot(normal);
        let third = best(&|i| area(p0, p1, pos(i)).abs(), &chosen);
        if area(p0, p1, pos(third)) == 0.0 {
            // All on one line: its two ends.
            out.push(pts[chosen[0]]);
            out.push(pts[chosen[1]]);
            return;
        }
        chosen[2] = third;
        let p2 = pos(chosen[2]);
        // Counter-clockwise about the normal; the fourth point is the farthest outside an edge.
        let (p1, p2) = if area(p0, p1, p2) >= 0.0 {
            (p1, p2)
        } else {
            (p2, p1)
        };
        let outside = |i: usize| {
            let q = pos(i);
            (-area(p0, p1, q))
                .max(-area(p1, p2, q))
                .max(-area(p2, p0, q))
        };
        let fourth = best(&outside, &chosen);
        if outside(fourth) > 0.0 {
            chosen[3] = fourth;
        }
        for i in chosen.into_iter().filter(|&i| i != usize::MAX) {
            out.push(pts[i]);
        }
    }

    /// Empties the manifold and sets its normal.
    pub fn reset(&mut self, normal: DVec3) {
        self.normal = normal;
        self.len = 0;
    }

    /// Adds a point; returns `false` (and drops it) when the manifold is full.
    pub fn push(&mut self, point: ManifoldPoint) -> bool {
        if self.len == MANIFOLD_POINTS {
            return false;
        }
        self.points[self.len] = point;
        self.len += 1;
        true
    }

    /// The points.
    #[must_use]
    pub fn points(&self) -> &[ManifoldPoint] {
        &self.points[..self.len]
    }

    /// Number of points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds no point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_manifold_keeps_at_most_four_points_and_resets() {
        let mut m = Manifold::new();
        for i in 0..6 {
            let p = ManifoldPoint {
                point_a: DVec3::splat(f64::from(i)),
                point_b: DVec3::splat(f64::from(i)),
                distance: -f64::from(i),
            };
            assert_eq!(m.push(p), i < 4);
        }
        assert_eq!(m.len(), 4);
        assert_eq!(m.points()[3].distance, -3.0);
        m.reset(DVec3::Z);
        assert!(m.is_empty() && m.normal == DVec3::Z);
    }
}
