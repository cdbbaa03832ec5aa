//! Welzl's loops and the balls through 1 to 4 support points (see the parent module doc).

use crate::math::{DVec3, tolerance};

/// A ball as the loops keep it: centre and squared radius, plus the containment
/// tolerance (squared) of the point set.
#[derive(Debug, Clone, Copy)]
pub(super) struct Ball {
    pub(super) center: DVec3,
    radius_squared: f64,
    floor_squared: f64,
}

impl Ball {
    fn contains(&self, p: DVec3) -> bool {
        p.distance_squared(self.center) <= self.radius_squared * (1.0 + 1e-12) + self.floor_squared
    }

    fn with_center(center: DVec3, support: &[DVec3], floor_squared: f64) -> Self {
        let radius_squared = support
            .iter()
            .map(|p| p.distance_squared(center))
            .fold(0.0, f64::max);
        Self {
            center,
            radius_squared,
            floor_squared,
        }
    }

    fn one(a: DVec3, floor_squared: f64) -> Self {
        Self::with_center(a, &[a], floor_squared)
    }

    fn two(a: DVec3, b: DVec3, floor_squared: f64) -> Self {
        Self::with_center((a + b) * 0.5, &[a, b], floor_squared)
    }

    /// The smallest ball with `a, b, c` on its boundary: the circumcircle's ball, or the
    /// ball of the farthest pair when the three are (near) collinear.
    fn three(a: DVec3, b: DVec3, c: DVec3, floor_squared: f64) -> Self {
        match circumcenter3(a, b, c) {
            Some(center) => Self::with_center(center, &[a, b, c], floor_squared),
            None => farthest_pair_ball([a, b, c], floor_squared),
        }
    }

    /// The ball with `a, b, c, d` on its boundary, or when they are (near) coplanar the
    /// smallest ball through a pair or triple of them that holds all four.
    fn four(a: DVec3, b: DVec3, c: DVec3, d: DVec3, floor_squared: f64) -> Self {
        let all = [a, b, c, d];
        if let Some(center) = circumcenter4(a, b, c, d) {
            return Self::with_center(center, &all, floor_squared);
        }
        let mut best = farthest_pair_ball(all, floor_squared);
        for skip in 0..4 {
            let mut tri = [DVec3::ZERO; 3];
            let mut n = 0;
            for (i, p) in all.iter().enumerate() {
                if i != skip {
                    tri[n] = *p;
                    n += 1;
                }
            }
            let candidate = Self::three(tri[0], tri[1], tri[2], floor_squared);
            let candidate = Self::with_center(candidate.center, &all, floor_squared);
            if candidate.radius_squared < best.radius_squared {
                best = candidate;
            }
        }
        best
    }
}

fn farthest_pair_ball<const K: usize>(points: [DVec3; K], floor_squared: f64) -> Ball {
    let (mut a, mut b, mut best) = (points[0], points[0], -1.0);
    for i in 0..K {
        for j in i + 1..K {
            let d2 = points[i].distance_squared(points[j]);
            if d2 > best {
                (a, b, best) = (points[i], points[j], d2);
            }
        }
    }
    Ball::with_center((a + b) * 0.5, &points, floor_squared)
}

/// Circumcentre of a triangle, or `None` when it is (near) degenerate: the sine of its
/// angle at `a` below 1e-10 (or an edge of zero length).
fn circumcenter3(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    let (u, v) = (b - a, c - a);
    let w = u.cross(v);
    let w2 = w.length_squared();
    if w2 <= 1e-20 * u.length_squared() * v.length_squared() {
        return None;
    }
    let offset = (v * u.length_squared() - u * v.length_squared()).cross(w) / (2.0 * w2);
    offset.is_finite().then_some(a + offset)
}

/// Circumcentre of a tetrahedron, or `None` when it is (near) flat: its volume below 1e-10
/// of the product of its edge lengths at `a`.
fn circumcenter4(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<DVec3> {
    let (u, v, w) = (b - a, c - a, d - a);
    let det = u.dot(v.cross(w));
    let bound = u.length() * v.length() * w.length();
    if det.abs() <= 1e-10 * bound {
        return None;
    }
    let offset = (v.cross(w) * u.length_squared()
        + w.cross(u) * v.length_squared()
        + u.cross(v) * w.length_squared())
        / (2.0 * det);
    offset.is_finite().then_some(a + offset)
}

/// The minimum ball of `points` (non-empty, shuffled, near the origin). Reorders them
/// (move-to-front).
pub(super) fn min_ball(points: &mut [DVec3]) -> Ball {
    let scale = points
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    let floor = tolerance::COINCIDENT_RELATIVE * scale;
    let floor_squared = floor * floor;
    let mut ball = Ball::one(points[0], floor_squared);
    for i in 1..points.len() {
        if ball.contains(points[i]) {
            continue;
        }
        let pi = points[i];
        ball = Ball::one(pi, floor_squared);
        for j in 0..i {
            if ball.contains(points[j]) {
                continue;
            }
            let pj = points[j];
            ball = Ball::two(pi, pj, floor_squared);
            for k in 0..j {
                if ball.contains(points[k]) {
                    continue;
                }
                let pk = points[k];
                ball = Ball::three(pi, pj, pk, floor_squared);
                for l in 0..k {
                    if !ball.contains(points[l]) {
                        ball = Ball::four(pi, pj, pk, points[l], floor_squared);
                        points[..=l].rotate_right(1);
                    }
                }
                points[..=k].rotate_right(1);
            }
            points[..=j].rotate_right(1);
        }
        points[..=i].rotate_right(1);
    }
    ball
}
