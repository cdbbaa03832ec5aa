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
use crate::math::{DVec3, Isometry, conservative_slack, tolerance};

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
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    for i in (1..points.len()).rev() {
        let j = (next() % (i as u64 + 1)) as usize;
        points.swap(i, j);
    }
}

/// Welzl's loops and the balls through 1 to 4 support points.
mod welzl {
    use super::{DVec3, tolerance};

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
            p.distance_squared(self.center)
                <= self.radius_squared * (1.0 + 1e-12) + self.floor_squared
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
}

/// Seeded point clouds for the bounding-volume unit tests (shared with the AABB and k-DOP
/// tests): the degenerate-input matrix of `tests/support`, restated here because unit tests
/// cannot reach the integration-test helpers.
#[cfg(test)]
pub(super) mod test_clouds {
    use crate::math::{DQuat, DVec3, Isometry, Pose};
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64Mcg;

    /// The PRNG of the unit tests.
    pub type TestRng = Pcg64Mcg;

    /// A PRNG from a seed.
    pub fn rng(seed: u64) -> TestRng {
        TestRng::seed_from_u64(seed)
    }

    /// Centres up to 1e6 from the origin.
    pub const CENTERS: [f64; 4] = [0.0, 1.0, 1e3, 1e6];
    /// Sizes from 1e-4 to 1e4.
    pub const SCALES: [f64; 5] = [1e-4, 1e-2, 1.0, 1e2, 1e4];

    /// The cloud kinds, degenerate ones included.
    #[derive(Debug, Clone, Copy, PartialEq, Eq)]
    pub enum Kind {
        Box,
        Sphere,
        Single,
        Duplicates,
        Collinear,
        Coplanar,
        Needle,
    }

    /// Every kind.
    pub const KINDS: [Kind; 7] = [
        Kind::Box,
        Kind::Sphere,
        Kind::Single,
        Kind::Duplicates,
        Kind::Collinear,
        Kind::Coplanar,
        Kind::Needle,
    ];

    /// A uniform point in `[-half, half]³`.
    pub fn point_in_cube(rng: &mut TestRng, half: f64) -> DVec3 {
        DVec3::new(
            rng.random_range(-half..=half),
            rng.random_range(-half..=half),
            rng.random_range(-half..=half),
        )
    }

    /// A uniform random rotation (Shoemake).
    pub fn rotation(rng: &mut TestRng) -> DQuat {
        let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
        let (s1, s2) = ((1.0 - u1).sqrt(), u1.sqrt());
        let tau = std::f64::consts::TAU;
        DQuat::from_xyzw(
            s1 * (tau * u2).sin(),
            s1 * (tau * u2).cos(),
            s2 * (tau * u3).sin(),
            s2 * (tau * u3).cos(),
        )
        .normalize()
    }

    /// A random isometry, translation in `[-half, half]³`.
    pub fn isometry(rng: &mut TestRng, half: f64) -> Isometry {
        Pose::new(point_in_cube(rng, half), rotation(rng)).to_isometry()
    }

    /// `n >= 1` points of `kind` around `center`, of size about `scale`, randomly rotated.
    pub fn cloud(rng: &mut TestRng, kind: Kind, n: usize, center: DVec3, scale: f64) -> Vec<DVec3> {
        let n = n.max(1);
        let rot = rotation(rng);
        let half = DVec3::new(
            rng.random_range(0.1..1.0),
            rng.random_range(0.1..1.0),
            rng.random_range(0.1..1.0),
        );
        let distinct: Vec<DVec3> = (0..4).map(|_| point_in_cube(rng, 1.0)).collect();
        let local: Vec<DVec3> = (0..n)
            .map(|i| match kind {
                Kind::Box => point_in_cube(rng, 1.0) * half,
                Kind::Sphere => point_in_cube(rng, 1.0).normalize_or(DVec3::X),
                Kind::Single => DVec3::ZERO,
                Kind::Duplicates => distinct[i % 4],
                Kind::Collinear => DVec3::X * rng.random_range(-1.0..1.0),
                Kind::Coplanar => DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                ),
                Kind::Needle => DVec3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1e-3..1e-3),
                    rng.random_range(-1e-3..1e-3),
                ),
            })
            .collect();
        local
            .into_iter()
            .map(|p| center + rot * (p * scale))
            .collect()
    }

    /// A cloud of random kind, size, offset (from [`CENTERS`]) and scale (from [`SCALES`]);
    /// returns the points and the scale.
    pub fn any_cloud(rng: &mut TestRng, max_n: usize) -> (Vec<DVec3>, f64) {
        let kind = KINDS[rng.random_range(0..KINDS.len())];
        let offset = CENTERS[rng.random_range(0..CENTERS.len())];
        let scale = SCALES[rng.random_range(0..SCALES.len())];
        let center = point_in_cube(rng, 1.0).normalize_or(DVec3::X) * offset;
        let n = rng.random_range(1..=max_n);
        (cloud(rng, kind, n, center, scale), scale)
    }

    /// The smallest distance between two point sets (brute force).
    pub fn min_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
        a.iter()
            .flat_map(|p| b.iter().map(move |q| p.distance(*q)))
            .fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::test_clouds::{self, Kind};
    use super::*;
    use rand::Rng;

    /// The exact minimum ball of a handful of points, by trying every ball through 2, 3 or 4
    /// of them (and the 1-point ball).
    fn brute_force_min_radius(points: &[DVec3]) -> f64 {
        let covers = |c: DVec3, r: f64| {
            points
                .iter()
                .all(|p| p.distance(c) <= r * (1.0 + 1e-9) + 1e-12)
        };
        let mut best = f64::INFINITY;
        let mut consider = |c: Option<DVec3>, support: &[DVec3]| {
            if let Some(c) = c {
                let r = support.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
                if r < best && covers(c, r) {
                    best = r;
                }
            }
        };
        let n = points.len();
        consider(Some(points[0]), &points[..1]);
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (points[i], points[j]);
                consider(Some((a + b) * 0.5), &[a, b]);
                for k in j + 1..n {
                    let c = points[k];
                    consider(welzl_circumcenter3(a, b, c), &[a, b, c]);
                    for &d in &points[k + 1..] {
                        consider(welzl_circumcenter4(a, b, c, d), &[a, b, c, d]);
                    }
                }
            }
        }
        best
    }

    // Independent circumcentres by solving the linear systems with glam's inverse.
    fn welzl_circumcenter3(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
        let (u, v) = (b - a, c - a);
        let n = u.cross(v);
        let m = crate::math::DMat3::from_cols(u, v, n).transpose();
        let rhs = DVec3::new(u.length_squared() / 2.0, v.length_squared() / 2.0, 0.0);
        (m.determinant().abs() > 1e-18).then(|| a + m.inverse() * rhs)
    }

    fn welzl_circumcenter4(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<DVec3> {
        let (u, v, w) = (b - a, c - a, d - a);
        let m = crate::math::DMat3::from_cols(u, v, w).transpose();
        let rhs = DVec3::new(u.length_squared(), v.length_squared(), w.length_squared()) / 2.0;
        (m.determinant().abs() > 1e-12).then(|| a + m.inverse() * rhs)
    }

    #[test]
    fn fitted_spheres_contain_every_point_across_the_degenerate_matrix() {
        let mut rng = test_clouds::rng(1);
        for case in 0..3000 {
            let (points, _) = test_clouds::any_cloud(&mut rng, 60);
            for sphere in [
                BoundingSphere::fit_points(&points),
                BoundingSphere::fit_points_ritter(&points),
            ] {
                assert!(sphere.radius.is_finite() && sphere.center.is_finite());
                for p in &points {
                    assert!(
                        sphere.contains_point(*p),
                        "case {case}: {p} not in {sphere:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn welzl_matches_the_brute_force_minimum_ball() {
        let mut rng = test_clouds::rng(2);
        for case in 0..2000 {
            let n = rng.random_range(1..=7);
            let points: Vec<DVec3> = (0..n)
                .map(|_| test_clouds::point_in_cube(&mut rng, 1.0))
                .collect();
            let welzl = BoundingSphere::fit_points(&points);
            let ritter = BoundingSphere::fit_points_ritter(&points);
            let exact = brute_force_min_radius(&points);
            assert!(
                (welzl.radius - exact).abs() <= 1e-9 * exact.max(1.0),
                "case {case}: welzl {} vs brute force {exact}",
                welzl.radius
            );
            assert!(welzl.radius <= ritter.radius + 1e-12, "case {case}");
        }
    }

    #[test]
    fn welzl_is_minimal_on_large_clouds_far_from_the_origin() {
        let mut rng = test_clouds::rng(3);
        for kind in [Kind::Sphere, Kind::Box, Kind::Collinear, Kind::Coplanar] {
            for &offset in &test_clouds::CENTERS {
                let center = DVec3::new(offset, -offset, 0.5 * offset);
                let points = test_clouds::cloud(&mut rng, kind, 2000, center, 1.0);
                let welzl = BoundingSphere::fit_points(&points);
                let ritter = BoundingSphere::fit_points_ritter(&points);
                assert!(
                    welzl.radius <= ritter.radius * (1.0 + 1e-9),
                    "{kind:?} {offset}"
                );
                // Minimality: the farthest-point distance is convex in the centre, so the
                // centre is its minimum when no small step in any direction lowers it.
                let farthest = |c: DVec3| points.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
                let at_center = farthest(welzl.center);
                for _ in 0..50 {
                    let step = test_clouds::point_in_cube(&mut rng, 1.0).normalize_or(DVec3::X);
                    let moved = farthest(welzl.center + step * 1e-4);
                    assert!(
                        moved >= at_center - 1e-9 * (1.0 + offset),
                        "{kind:?} {offset}"
                    );
                }
                if kind == Kind::Sphere {
                    // Points on the unit sphere: the minimum ball is about that sphere.
                    assert!((welzl.radius - 1.0).abs() < 1e-2, "radius {}", welzl.radius);
                }
            }
        }
    }

    #[test]
    fn fit_handles_a_hundred_thousand_points() {
        let mut rng = test_clouds::rng(4);
        let points = test_clouds::cloud(&mut rng, Kind::Sphere, 100_000, DVec3::splat(1e6), 3.0);
        let sphere = BoundingSphere::fit_points(&points);
        assert!(
            (sphere.radius - 3.0).abs() < 1e-3,
            "radius {}",
            sphere.radius
        );
        assert!(points.iter().all(|p| sphere.contains_point(*p)));
    }

    #[test]
    fn degenerate_inputs_give_finite_tight_spheres() {
        let p = DVec3::new(1e6, -2.0, 3.0);
        let single = BoundingSphere::fit_points(&[p]);
        assert!(single.contains_point(p) && single.radius < 1e-5);
        let duplicates = BoundingSphere::fit_points(&[p; 50]);
        assert!(duplicates.contains_point(p) && duplicates.radius < 1e-5);
        let line: Vec<DVec3> = (0..100).map(|i| DVec3::X * f64::from(i)).collect();
        let sphere = BoundingSphere::fit_points(&line);
        assert!(
            (sphere.radius - 49.5).abs() < 1e-9 && sphere.center.abs_diff_eq(DVec3::X * 49.5, 1e-9)
        );
        // A square: four concyclic coplanar points.
        let square = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y, DVec3::ZERO];
        let sphere = BoundingSphere::fit_points(&square);
        assert!((sphere.radius - 1.0).abs() < 1e-9 && sphere.center.length() < 1e-9);
        let tri = Triangle::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
        let sphere = BoundingSphere::fit_triangles(&[tri]);
        assert!((sphere.radius - 1.0).abs() < 1e-9);
    }

    #[test]
    fn merged_is_the_smallest_sphere_containing_both() {
        let mut rng = test_clouds::rng(5);
        for case in 0..3000 {
            let scale = test_clouds::SCALES[case % 5];
            let offset = test_clouds::CENTERS[case % 4];
            let a = BoundingSphere::new(
                test_clouds::point_in_cube(&mut rng, scale) + DVec3::splat(offset),
                rng.random_range(0.0..scale),
            );
            let b = BoundingSphere::new(
                test_clouds::point_in_cube(&mut rng, scale) + DVec3::splat(offset),
                rng.random_range(0.0..scale),
            );
            let m = a.merged(&b);
            for s in [a, b] {
                // Far points of each input sphere, in random directions and towards the other.
                for dir in [
                    test_clouds::point_in_cube(&mut rng, 1.0).normalize_or(DVec3::X),
                    (s.center - m.center).normalize_or(DVec3::X),
                ] {
                    assert!(m.contains_point(s.center + dir * s.radius), "case {case}");
                }
            }
            let expected = ((a.center.distance(b.center) + a.radius + b.radius) * 0.5)
                .max(a.radius)
                .max(b.radius);
            assert!(m.radius >= expected && m.radius <= expected + 1e-9 * (offset + scale));
        }
    }

    #[test]
    fn transformed_contains_the_moved_points() {
        let mut rng = test_clouds::rng(6);
        for case in 0..2000 {
            let (points, _) = test_clouds::any_cloud(&mut rng, 40);
            let pose = test_clouds::isometry(&mut rng, 1e3);
            let moved = BoundingSphere::fit_points(&points).transformed(&pose);
            for p in &points {
                assert!(
                    moved.contains_point(pose.transform_point(*p)),
                    "case {case}"
                );
            }
        }
    }

    #[test]
    fn overlap_and_distance_bound_are_conservative_against_brute_force() {
        let mut rng = test_clouds::rng(7);
        let (mut overlapping, mut apart) = (0, 0);
        for case in 0..3000 {
            let (a_points, scale) = test_clouds::any_cloud(&mut rng, 20);
            let (mut b_points, _) = test_clouds::any_cloud(&mut rng, 20);
            let pose_ab = test_clouds::isometry(&mut rng, 2.0 * scale);
            if case % 3 == 0 {
                // Force a shared point.
                b_points.push(pose_ab.inverse_transform_point(a_points[0]));
            }
            let a = BoundingSphere::fit_points(&a_points);
            let b = BoundingSphere::fit_points(&b_points);
            let b_in_a: Vec<DVec3> = b_points
                .iter()
                .map(|p| pose_ab.transform_point(*p))
                .collect();
            let truth = test_clouds::min_distance(&a_points, &b_in_a);
            let bound = a.distance_lower_bound(&b, &pose_ab);
            assert!(bound <= truth, "case {case}: bound {bound} > truth {truth}");
            let overlap = a.overlaps(&b, &pose_ab);
            if case % 3 == 0 {
                assert!(overlap && bound == 0.0, "case {case}: shared point missed");
            }
            if overlap {
                overlapping += 1;
                assert_eq!(bound, 0.0, "case {case}");
            } else {
                apart += 1;
                assert!(bound > 0.0, "case {case}");
            }
        }
        assert!(overlapping > 300 && apart > 300, "{overlapping} / {apart}");
    }

    #[test]
    fn transformed_then_identity_overlap_equals_overlap_under_the_pose() {
        let mut rng = test_clouds::rng(8);
        for case in 0..3000 {
            let a = BoundingSphere::new(test_clouds::point_in_cube(&mut rng, 3.0), rng.random());
            let b = BoundingSphere::new(test_clouds::point_in_cube(&mut rng, 3.0), rng.random());
            let pose = test_clouds::isometry(&mut rng, 3.0);
            let moved = b.transformed(&pose);
            let d_direct = a.distance_lower_bound(&b, &pose);
            let d_moved = a.distance_lower_bound(&moved, &Isometry::IDENTITY);
            assert!((d_direct - d_moved).abs() < 1e-9, "case {case}");
            if (a.center.distance(moved.center) - a.radius - b.radius).abs() > 1e-9 {
                assert_eq!(
                    a.overlaps(&b, &pose),
                    a.overlaps(&moved, &Isometry::IDENTITY),
                    "case {case}"
                );
            }
        }
    }

    #[test]
    fn measures_follow_the_radius() {
        let s = BoundingSphere::new(DVec3::new(1.0, 2.0, 3.0), 2.0);
        assert_eq!(s.size(), 4.0);
        assert_eq!(s.stand_off(), 4.0);
        assert!((s.volume() - 32.0 / 3.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(BoundingVolume::center(&s), s.center);
        assert_eq!(BoundingSphere::NAME, "sphere");
    }
}
