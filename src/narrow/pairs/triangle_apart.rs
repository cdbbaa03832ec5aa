//! The closest pair of a sphere's, a capsule's or a box's core and a triangle whose cores are
//! apart, straight from the features, without the separating-axis test of
//! [`super::query`]: the hot case of a convex shape walking a mesh, where most triangles
//! the walk reaches are near the shape but not touching its core.
//!
//! # Why the candidates are complete
//! The closest pair of two disjoint convex polytopes lies on a pair of features. A vertex
//! of either against the other polytope is one closest-point query (a clamp onto the box,
//! the point of a segment, the point of the triangle); two edges are one segment pair. A
//! pair with a face interior on one side and an edge or face interior on the other is
//! parallel there, so the closest set reaches a vertex or an edge pair at its end. The
//! minimum over vertices both ways and every edge pair is therefore the distance (Ericson,
//! *Real-Time Collision Detection*, §5.1.9 and §5.2.9). A candidate whose features' boxes
//! are already farther apart than the best pair so far cannot improve it and is skipped
//! (exact pruning).
//!
//! # Why the answer is exact
//! The minimum is the distance only for disjoint cores. It is kept when the cores are apart
//! along the pair's own direction `n`: an overlapping pair has no separating direction, so
//! a positive separation along `n` proves them disjoint (as
//! [`super::query`]'s `apart_certified`). A pair that fails (touching or overlapping cores,
//! or a gap under the feature tolerance, whose direction is rounding noise) returns `None`
//! and is left to the separating-axis test.

use super::query::FEATURE_RELATIVE;
use crate::geometry::Triangle;
use crate::math::DVec3;
use crate::narrow::closest_points::{
    HingeFrame, closest_point_segment, closest_points_segment_segment,
};
use crate::narrow::contact::ShapeDistance;

/// The closest of the point pairs offered so far, with the triangle's features.
struct Closest<'t> {
    triangle: &'t Triangle,
    /// Built on the first core vertex that may improve the pair.
    hinge: Option<HingeFrame>,
    /// The triangle's box, A's frame.
    low: DVec3,
    high: DVec3,
    distance_squared: f64,
    on_core: DVec3,
    on_triangle: DVec3,
}

impl<'t> Closest<'t> {
    fn new(triangle: &'t Triangle) -> Self {
        let (a, b, c) = (triangle.a, triangle.b, triangle.c);
        Self {
            triangle,
            hinge: None,
            low: a.min(b).min(c),
            high: a.max(b).max(c),
            distance_squared: f64::INFINITY,
            on_core: DVec3::ZERO,
            on_triangle: DVec3::ZERO,
        }
    }

    fn offer(&mut self, on_core: DVec3, on_triangle: DVec3) {
        let d = on_core.distance_squared(on_triangle);
        if d < self.distance_squared {
            (self.distance_squared, self.on_core, self.on_triangle) = (d, on_core, on_triangle);
        }
    }

    /// Whether the segment `p, q` (a point when equal) may come nearer the triangle than
    /// the best pair: the gap between its box and the triangle's does not rule it out.
    fn may_improve(&self, p: DVec3, q: DVec3) -> bool {
        let gap = (self.low - p.max(q))
            .max(p.min(q) - self.high)
            .max(DVec3::ZERO);
        gap.length_squared() < self.distance_squared
    }

    /// A core point against the triangle.
    fn offer_core_vertex(&mut self, v: DVec3) {
        if self.may_improve(v, v) {
            let t = self.triangle;
            let hinge = self
                .hinge
                .get_or_insert_with(|| HingeFrame::new(t.a, t.b, t.c));
            let q = hinge.closest_point(v);
            self.offer(v, q);
        }
    }

    /// The segment `p, q` of the core against the triangle's three edges.
    fn offer_core_edge(&mut self, p: DVec3, q: DVec3) {
        if !self.may_improve(p, q) {
            return;
        }
        let (low, high) = (p.min(q), p.max(q));
        let t = self.triangle;
        for (r, s) in [(t.a, t.b), (t.b, t.c), (t.c, t.a)] {
            let gap = (low - r.max(s)).max(r.min(s) - high).max(DVec3::ZERO);
            if gap.length_squared() < self.distance_squared {
                let (on_core, on_triangle) = closest_points_segment_segment(p, q, r, s);
                self.offer(on_core, on_triangle);
            }
        }
    }

    /// The answer for a core of radius `radius` whose largest extent along a unit axis `n`
    /// is `reach(n)`, and whose coordinates are at most `scale` in magnitude: `None` unless
    /// the best pair is certified (module docs).
    fn certified(
        &self,
        radius: f64,
        scale: f64,
        reach: impl Fn(DVec3) -> f64,
    ) -> Option<ShapeDistance> {
        let t = self.triangle;
        let tiny =
            FEATURE_RELATIVE * scale.max(t.a.abs().max(t.b.abs()).max(t.c.abs()).max_element());
        let gap = self.distance_squared.sqrt();
        if gap.is_nan() || gap <= tiny {
            return None;
        }
        let n = (self.on_triangle - self.on_core) / gap;
        let nearest = t.a.dot(n).min(t.b.dot(n)).min(t.c.dot(n));
        (nearest - reach(n) > 0.0).then(|| ShapeDistance {
            distance: gap - radius,
            point_a: self.on_core + n * radius,
            point_b: self.on_triangle,
            normal: n,
        })
    }
}

/// A ball of `radius` centred at `center` (A's frame) against `triangle` (A's frame):
/// the exact signed distance when the centre is off the triangle by more than the feature
/// tolerance (module docs), else `None`.
#[must_use]
pub(super) fn apart_point_triangle(
    center: DVec3,
    radius: f64,
    triangle: &Triangle,
) -> Option<ShapeDistance> {
    let mut closest = Closest::new(triangle);
    let hinge = HingeFrame::new(triangle.a, triangle.b, triangle.c);
    closest.offer(center, hinge.closest_point(center));
    let scale = radius.max(center.abs().max_element());
    closest.certified(radius, scale, |n| center.dot(n))
}

/// A capsule of `radius` around the segment `p, q` (A's frame) against `triangle`: the
/// exact signed distance when the segment and the triangle are apart (module docs), else
/// `None`.
#[must_use]
pub(super) fn apart_segment_triangle(
    (p, q): (DVec3, DVec3),
    radius: f64,
    triangle: &Triangle,
) -> Option<ShapeDistance> {
    let mut closest = Closest::new(triangle);
    closest.offer_core_vertex(p);
    closest.offer_core_vertex(q);
    for v in triangle.vertices() {
        closest.offer(closest_point_segment(v, p, q), v);
    }
    closest.offer_core_edge(p, q);
    let scale = radius.max(p.abs().max(q.abs()).max_element());
    closest.certified(radius, scale, |n| p.dot(n).max(q.dot(n)))
}

/// The box `[-half, half]` (A's frame, axis-aligned at A's origin) against `triangle`: the
/// exact signed distance when they are apart along one of the four face axes (the box's
/// three, the triangle's normal) and the pair is certified (module docs), else `None` (a
/// pair apart only along an edge cross product, touching or overlapping).
///
/// Only the box's corners and edges the triangle can be nearest to are tried: a point's
/// nearest point of the box is its clamp, which lies on the `+` side of axis `i` only for
/// points beyond `half[i]` and on the `−` side only for points below `−half[i]`; the
/// triangle's box says which sides any of its points reach.
#[must_use]
pub(super) fn apart_box_triangle(half: DVec3, triangle: &Triangle) -> Option<ShapeDistance> {
    let (a, b, c) = (triangle.a, triangle.b, triangle.c);
    let mut closest = Closest::new(triangle);
    let (low, high) = (closest.low, closest.high);
    let face_apart = (low - half).max(-half - high).max_element() > 0.0
        || triangle.normal().is_some_and(|n| {
            let (da, db, dc) = (a.dot(n), b.dot(n), c.dot(n));
            let reach = half.dot(n.abs());
            da.min(db).min(dc) > reach || da.max(db).max(dc) < -reach
        });
    if !face_apart {
        return None;
    }
    for v in [a, b, c] {
        closest.offer(v.clamp(-half, half), v);
    }
    // Per axis, the sides (bit 0: −, bit 1: +) the triangle reaches beyond.
    let sides: [u8; 3] =
        std::array::from_fn(|i| u8::from(low[i] <= -half[i]) | (u8::from(high[i] >= half[i]) << 1));
    let reaches = |i: usize, plus: bool| sides[i] & (1 << u8::from(plus)) != 0;
    let corner = |signs: [bool; 3]| {
        DVec3::new(
            if signs[0] { half.x } else { -half.x },
            if signs[1] { half.y } else { -half.y },
            if signs[2] { half.z } else { -half.z },
        )
    };
    for i in 0..8 {
        let signs = [i & 1 != 0, i & 2 != 0, i & 4 != 0];
        if (0..3).all(|k| reaches(k, signs[k])) {
            closest.offer_core_vertex(corner(signs));
        }
    }
    // An edge along axis `k` lies on the sides `(sj, sl)` of the other two axes: tried when
    // the triangle reaches beyond both, and not wholly past either end of the edge along
    // `k` (there the nearest box points are on that end's face, whose corners and edges
    // the other passes try).
    for k in 0..3 {
        if low[k] >= half[k] || high[k] <= -half[k] {
            continue;
        }
        let (j, l) = ((k + 1) % 3, (k + 2) % 3);
        for (sj, sl) in [(false, false), (true, false), (false, true), (true, true)] {
            if !(reaches(j, sj) && reaches(l, sl)) {
                continue;
            }
            let mut signs = [false; 3];
            (signs[j], signs[l]) = (sj, sl);
            let from = corner(signs);
            let mut to = from;
            to[k] = half[k];
            closest.offer_core_edge(from, to);
        }
    }
    closest.certified(0.0, half.max_element(), |n| half.dot(n.abs()))
}

#[cfg(test)]
mod tests {
    use super::super::placed_core::PlacedCore;
    use super::super::query;
    use super::*;
    use crate::geometry::{Capsule, Cuboid, Sphere};
    use crate::math::Isometry;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    /// A random triangle near the origin: ordinary, thin, a segment or a point, at a
    /// random distance from a unit-sized shape.
    fn triangle(rng: &mut TestRng) -> Triangle {
        let centre = point_in_cube(rng, 2.5);
        let size = [0.05, 0.5, 3.0][rng.random_range(0..3)];
        let a = centre + point_in_cube(rng, size);
        let (b, c) = match rng.random_range(0..10) {
            0 => (a, a),
            1 => (a + point_in_cube(rng, size), a),
            2 => {
                let b = a + point_in_cube(rng, size);
                (b, a + (b - a) * 0.3 + point_in_cube(rng, 1e-12))
            }
            _ => (
                centre + point_in_cube(rng, size),
                centre + point_in_cube(rng, size),
            ),
        };
        Triangle::new(a, b, c)
    }

    /// Half extents of a box, degenerate (flat, a rod, a point) now and then.
    fn half_extents(rng: &mut TestRng) -> DVec3 {
        let mut half = DVec3::new(
            rng.random_range(0.05..1.0),
            rng.random_range(0.05..1.0),
            rng.random_range(0.05..1.0),
        );
        for k in 0..3 {
            if rng.random_range(0..12) == 0 {
                half[k] = 0.0;
            }
        }
        half
    }

    /// Checks a fast answer against the separating-axis path's on the same cores: the same
    /// distance to rounding, and witnesses that realise it along the normal.
    fn check_against_axes(fast: &ShapeDistance, axes: &ShapeDistance, case: usize) {
        let scale = 1.0 + fast.point_a.abs().max(fast.point_b.abs()).max_element();
        assert!(
            (fast.distance - axes.distance).abs() <= 1e-12 * scale,
            "case {case}: {fast:?} against {axes:?}"
        );
        assert!((fast.normal.length() - 1.0).abs() < 1e-12, "case {case}");
        let gap = fast.point_b - fast.point_a;
        assert!(
            (gap - fast.normal * fast.distance).length() <= 1e-12 * scale,
            "case {case}: {fast:?}"
        );
        // Where the closest pair is unique (a non-parallel pair), so are its points.
        if axes.normal.dot(fast.normal) > 1.0 - 1e-9 {
            assert!(
                fast.point_b.distance(axes.point_b) <= 1e-6 * scale
                    || (fast.distance - axes.distance).abs() <= 1e-12 * scale,
                "case {case}"
            );
        }
    }

    /// Spheres, capsules and boxes against triangles: every answer of the fast path equals
    /// the separating-axis path's; pairs it declines (touching or overlapping cores, a box
    /// apart only along an edge cross product) occur too, and are what the caller
    /// answers by that path.
    #[test]
    fn the_fast_closest_pair_equals_the_separating_axis_answer() {
        let mut rng = rng(4711);
        let identity = Isometry::IDENTITY;
        let mut taken = [0usize; 3];
        let mut declined = [0usize; 3];
        for case in 0..30_000 {
            let mut t = triangle(&mut rng);
            if rng.random_range(0..5) == 0 {
                // Centred on the origin: through the ball's centre, the capsule's segment
                // and the box, whose cores it then touches or cuts.
                let centroid = (t.a + t.b + t.c) / 3.0;
                t = Triangle::new(t.a - centroid, t.b - centroid, t.c - centroid);
            }
            let kind = case % 3;
            let (fast, axes) = match kind {
                0 => {
                    let radius = rng.random_range(0.0..1.0);
                    let sphere = Sphere::new(radius);
                    (
                        apart_point_triangle(DVec3::ZERO, radius, &t),
                        query::distance(
                            &PlacedCore::sphere(&sphere, &identity),
                            &PlacedCore::triangle(&t, &identity),
                        ),
                    )
                }
                1 => {
                    let capsule =
                        Capsule::new(rng.random_range(0.0..1.0), rng.random_range(0.0..1.0));
                    let axis = capsule.segment();
                    (
                        apart_segment_triangle((axis.a, axis.b), capsule.radius, &t),
                        query::distance(
                            &PlacedCore::capsule(&capsule, &identity),
                            &PlacedCore::triangle(&t, &identity),
                        ),
                    )
                }
                _ => {
                    let cuboid = Cuboid::new(half_extents(&mut rng));
                    (
                        apart_box_triangle(cuboid.half_extents, &t),
                        query::distance(
                            &PlacedCore::cuboid(&cuboid, &identity),
                            &PlacedCore::triangle(&t, &identity),
                        ),
                    )
                }
            };
            match fast {
                Some(fast) => {
                    taken[kind] += 1;
                    check_against_axes(&fast, &axes, case);
                }
                None => declined[kind] += 1,
            }
        }
        for kind in 0..3 {
            assert!(
                taken[kind] > 3_000 && declined[kind] > 300,
                "kind {kind}: {taken:?} taken, {declined:?} declined"
            );
        }
    }
}
