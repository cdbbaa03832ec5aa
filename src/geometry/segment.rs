//! Line segment between two points.

use super::SupportMap;
use super::error::{ShapeError, check_point};
use crate::math::DVec3;

/// The segment from `a` to `b` (local frame). `a == b` is allowed: a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// First end point, metres.
    pub a: DVec3,
    /// Second end point, metres.
    pub b: DVec3,
}

impl Segment {
    /// From trusted end points.
    #[must_use]
    pub fn new(a: DVec3, b: DVec3) -> Self {
        debug_assert!(a.is_finite() && b.is_finite());
        Self { a, b }
    }

    /// From untrusted end points.
    pub fn try_new(a: DVec3, b: DVec3) -> Result<Self, ShapeError> {
        Ok(Self {
            a: check_point(a)?,
            b: check_point(b)?,
        })
    }

    /// `b - a`.
    #[must_use]
    #[inline]
    pub fn direction(&self) -> DVec3 {
        self.b - self.a
    }

    /// Length, metres.
    #[must_use]
    #[inline]
    pub fn length(&self) -> f64 {
        self.direction().length()
    }

    /// The point `a + t (b - a)`.
    #[must_use]
    #[inline]
    pub fn point_at(&self, t: f64) -> DVec3 {
        self.a + (self.b - self.a) * t
    }

    /// The closest points between `self` and `other`: `(s, t, on_self, on_other)` with
    /// `on_self = self.point_at(s)`, `on_other = other.point_at(t)`, `s, t ∈ [0, 1]`.
    /// Robust for zero-length and parallel segments (Ericson, *Real-Time Collision
    /// Detection*, §5.1.9). The free function `closest_points_segment_segment` in this
    /// module is the same query.
    #[must_use]
    #[inline]
    pub fn closest_points(&self, other: &Segment) -> (f64, f64, DVec3, DVec3) {
        closest_points_segment_segment(self, other)
    }
}

/// Closest points between segments `p` and `q` (same frame): returns `(s, t, on_p, on_q)`
/// with `on_p = p.point_at(s)`, `on_q = q.point_at(t)` and `s, t ∈ [0, 1]`, minimising
/// `|on_p - on_q|`.
///
/// Robust for zero-length segments (points) and parallel segments (then one of the
/// equally close pairs is returned). Solves the 2×2 normal equations and clamps, clamping
/// the other parameter again when one leaves `[0, 1]` (Ericson, *Real-Time Collision
/// Detection*, §5.1.9).
#[must_use]
#[inline]
pub fn closest_points_segment_segment(p: &Segment, q: &Segment) -> (f64, f64, DVec3, DVec3) {
    let (d1, d2, r) = (p.b - p.a, q.b - q.a, p.a - q.a);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    // A squared length this far below the other magnitudes carries no direction.
    let tiny = f64::EPSILON * f64::EPSILON * (a + e + r.length_squared());
    let (s, t) = if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            // Parallel (to rounding): any s is optimal for the lines; take 0, then clamp.
            let s = if denom > PARALLEL_RELATIVE * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let t = (b * s + f) / e;
            if t < 0.0 {
                ((-c / a).clamp(0.0, 1.0), 0.0)
            } else if t > 1.0 {
                (((b - c) / a).clamp(0.0, 1.0), 1.0)
            } else {
                (s, t)
            }
        }
    };
    (s, t, p.a + d1 * s, q.a + d2 * t)
}

/// `sin²` of the angle under which two segments count as parallel.
const PARALLEL_RELATIVE: f64 = 1e-14;

impl SupportMap for Segment {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        if self.b.dot(direction) > self.a.dot(direction) {
            self.b
        } else {
            self.a
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// Brute force: the minimum over a parameter grid, refined by nested ternary search
    /// (the distance is convex in `(s, t)`).
    fn brute_distance(p: &Segment, q: &Segment) -> f64 {
        let along_q = |x: DVec3| {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..100 {
                let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
                if x.distance(q.point_at(m1)) < x.distance(q.point_at(m2)) {
                    hi = m2;
                } else {
                    lo = m1;
                }
            }
            x.distance(q.point_at(0.5 * (lo + hi)))
        };
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..100 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            if along_q(p.point_at(m1)) < along_q(p.point_at(m2)) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        along_q(p.point_at(0.5 * (lo + hi)))
    }

    fn random_segment(rng: &mut Pcg64Mcg, center: DVec3, scale: f64) -> Segment {
        let mut p = || {
            center
                + DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                ) * scale
        };
        Segment::new(p(), p())
    }

    #[test]
    fn closest_points_match_a_brute_force_search() {
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        for case in 0..3000 {
            let center = DVec3::splat([0.0, 1.0, 1e3, 1e6][case % 4]);
            let scale = [1e-4, 1e-2, 1.0, 1e2, 1e4][case % 5];
            let p = random_segment(&mut rng, center, scale);
            let mut q = random_segment(&mut rng, center, scale);
            match case % 6 {
                // Parallel, overlapping in projection or not.
                0 => q = Segment::new(q.a, q.a + p.direction() * rng.random_range(-2.0..2.0)),
                // Zero length.
                1 => q = Segment::new(q.a, q.a),
                2 => q = Segment::new(p.a, p.a),
                _ => {}
            }
            let (s, t, on_p, on_q) = closest_points_segment_segment(&p, &q);
            assert!(
                (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t),
                "case {case}"
            );
            assert!(on_p.distance(p.point_at(s)) <= 1e-12 * (center.x + scale));
            assert!(on_q.distance(q.point_at(t)) <= 1e-12 * (center.x + scale));
            let found = on_p.distance(on_q);
            let brute = brute_distance(&p, &q);
            let tolerance = 1e-9 * scale + 1e-12 * center.x;
            assert!(found <= brute + tolerance, "case {case}: {found} > {brute}");
            assert!(
                found >= brute - tolerance - 1e-6 * scale,
                "case {case}: {found} < {brute}"
            );
        }
    }

    #[test]
    fn crossing_segments_meet_at_their_intersection() {
        let p = Segment::new(DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        let q = Segment::new(DVec3::new(0.5, -1.0, 0.0), DVec3::new(0.5, 3.0, 0.0));
        let (s, t, on_p, on_q) = p.closest_points(&q);
        assert!((s - 0.75).abs() < 1e-15 && (t - 0.25).abs() < 1e-15);
        assert!(on_p.distance(on_q) < 1e-15);
    }

    #[test]
    fn parallel_and_point_segments_give_exact_distances() {
        let p = Segment::new(DVec3::ZERO, DVec3::X * 2.0);
        let q = Segment::new(DVec3::new(3.0, 1.0, 0.0), DVec3::new(5.0, 1.0, 0.0));
        let (_, _, a, b) = p.closest_points(&q);
        assert!((a.distance(b) - 2f64.sqrt()).abs() < 1e-15);
        let q = Segment::new(DVec3::new(0.5, 1.0, 0.0), DVec3::new(5.0, 1.0, 0.0));
        let (_, _, a, b) = p.closest_points(&q);
        assert!((a.distance(b) - 1.0).abs() < 1e-15);
        let point = Segment::new(DVec3::new(1.0, 0.0, 2.0), DVec3::new(1.0, 0.0, 2.0));
        let (s, t, a, b) = p.closest_points(&point);
        assert_eq!((s, t), (0.5, 0.0));
        assert!((a.distance(b) - 2.0).abs() < 1e-15);
        let (_, _, a, b) = point.closest_points(&point);
        assert_eq!(a, b);
    }
}
