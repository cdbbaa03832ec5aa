//! Swept-sphere volumes: a core shape (point, segment, rectangle) grown by a radius.
//!
//! - [`Pss`]: the point-swept sphere, which is the [`BoundingSphere`](super::BoundingSphere).
//! - [`Lss`]: a segment core (a capsule).
//! - [`Rss`]: a rectangle core (a rounded slab).
//!
//! **Fit.** PCA of the points (or area-weighted triangles) gives the core's frame. Each fit
//! works on *balls* (centre, radius) so that the same routine fits points (radius 0) and
//! merges volumes (the corner balls of both inputs: a swept volume is the hull of its core's
//! corner balls, so containing those contains the volume). The radius comes from the spread
//! across the core (LSS: around the axis; RSS: along the least axis), then the core is
//! shrunk so that its rounded ends and corners still contain every ball: a ball that sticks
//! out past a rectangle corner pushes the cheaper of the two sides out. Results are padded
//! by the conservative slack.
//!
//! **Distance.** Exact distance between the cores minus both radii. Segment–segment is
//! closed form. Rectangle–rectangle enumerates the candidate closest features (edge
//! pairs; a vertex over the other's face, where only each rectangle's support vertex along
//! the other's normal can be closest) and then *certifies* the answer: the returned core
//! distance is the separation of the two rectangles along the direction between the closest
//! pair found, computed from their support functions. That separation never exceeds the
//! true distance whatever the enumeration found, and equals it when the pair is the closest
//! one. The certificate also ends the search early: the four pairs of edges that face the
//! other rectangle's centre are tried first, and the other twelve only when the certified
//! separation falls short of the best pair's distance (about 5% of random pairs). A point
//! against a rectangle (a sphere's volume) is a clamp, certified the same way.
//!
//! Citation: E. Larsen, S. Gottschalk, M. C. Lin, D. Manocha, "Fast Proximity Queries with
//! Swept Sphere Volumes", UNC TR99-018 (1999), the fit idea of PQP's RSS; Ericson,
//! *Real-Time Collision Detection* §5.1.9 for segment–segment.

use super::BoundingVolume;
use super::fit::{
    Moments, frame_about, orthonormalise, point_moments, principal_frame, triangle_moments,
};
use crate::geometry::{Segment, Triangle};
use crate::math::{DMat3, DVec3, Isometry, conservative_slack};
use std::f64::consts::PI;

/// The point-swept sphere: the zero-dimensional swept-sphere volume, a
/// [`BoundingSphere`](super::BoundingSphere). It is fitted exactly (minimum enclosing
/// sphere, Welzl), a tighter fit than PCA could give, so it has no PCA fit of its own here.
pub type Pss = super::BoundingSphere;

/// A line-swept sphere (capsule): every point within `radius` of the segment `core`.
///
/// # Invariants
/// `radius ≥ 0`; the core's end points are finite (they may coincide).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lss {
    /// The core segment, metres.
    pub core: Segment,
    /// Radius, metres.
    pub radius: f64,
}

/// A rectangle-swept sphere: every point within `radius` of the rectangle
/// `center + axes.x_axis · u + axes.y_axis · v`, `|u| ≤ half_lengths[0]`,
/// `|v| ≤ half_lengths[1]`.
///
/// # Invariants
/// `axes` is a rotation (its third column is the rectangle's normal); `half_lengths ≥ 0`;
/// `radius ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rss {
    /// Centre of the rectangle, metres.
    pub center: DVec3,
    /// Rectangle frame as columns: two in-plane axes, then the normal.
    pub axes: DMat3,
    /// Half side lengths of the rectangle along `axes.x_axis` and `axes.y_axis`, metres.
    pub half_lengths: [f64; 2],
    /// Radius, metres.
    pub radius: f64,
}

/// A ball to contain: centre and radius (0 for a point).
type Ball = (DVec3, f64);

/// Adjacent eigenvalues closer than this fraction of the largest leave the in-plane
/// orientation open; the minimum-area rectangle then settles it.
const AMBIGUOUS_EIGENVALUES: f64 = 0.05;

/// Rotation steps (radians) of the local search that polishes a fitted frame: PCA of a
/// sampled surface can tilt a long or flat set's axis by a few hundredths of a radian, which
/// costs the radius (and the volume) more than it costs an OBB.
const POLISH_STEPS: [f64; 3] = [0.04, 0.01, 0.0025];

/// The least-`cost` frame among `candidates`, then improved greedily by small rotations
/// about each of its axes. `candidates` must be non-empty and orthonormal.
fn polish_frame(candidates: impl Iterator<Item = DMat3>, cost: impl Fn(DMat3) -> f64) -> DMat3 {
    let mut best = (DMat3::IDENTITY, f64::INFINITY);
    for frame in candidates {
        let c = cost(frame);
        if c < best.1 {
            best = (frame, c);
        }
    }
    for step in POLISH_STEPS {
        for k in 0..3 {
            for angle in [step, -step] {
                let frame = DMat3::from_axis_angle(best.0.col(k), angle) * best.0;
                let c = cost(frame);
                if c < best.1 {
                    best = (frame, c);
                }
            }
        }
    }
    best.0
}

/// A right-handed frame whose first axis is `direction` (any completion; `X` when zero).
fn frame_along(direction: DVec3) -> DMat3 {
    orthonormalise(direction, direction.any_orthogonal_vector())
}

/// The triangles' vertices as balls of radius 0.
fn vertex_balls(triangles: &[Triangle]) -> Vec<Ball> {
    triangles
        .iter()
        .flat_map(Triangle::vertices)
        .map(|p| (p, 0.0))
        .collect()
}

/// The largest coordinate magnitude among the balls (with their radii): the scale of the
/// fit's slack.
fn ball_scale(balls: &[Ball]) -> f64 {
    balls
        .iter()
        .fold(0.0f64, |s, (c, r)| s.max(c.abs().max_element() + r))
}

/// How far a coordinate may move towards the core while the ball, `offset` off the core
/// across it, stays within `reach` of the core: `sqrt(reach² − offset²)`, 0 when negative.
#[inline]
fn shrink(reach: f64, offset_squared: f64) -> f64 {
    (reach * reach - offset_squared).max(0.0).sqrt()
}

/// The interval `[lo, hi]` of core positions along one axis that keeps every ball inside;
/// collapsed to its midpoint when the balls allow an empty one.
fn core_interval(values: impl Iterator<Item = (f64, f64)>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (x, slack) in values {
        hi = hi.max(x - slack);
        lo = lo.min(x + slack);
    }
    if lo > hi {
        let mid = 0.5 * (lo + hi);
        (mid, mid)
    } else {
        (lo, hi)
    }
}

impl Lss {
    /// From trusted parts.
    #[must_use]
    pub fn new(core: Segment, radius: f64) -> Self {
        debug_assert!(radius >= 0.0 && core.a.is_finite() && core.b.is_finite());
        Self { core, radius }
    }

    /// The capsule with axis `axes.x_axis` containing every ball, padded by `pad`.
    fn from_balls(balls: &[Ball], axes: DMat3, reference: DVec3, pad: f64) -> Self {
        let to_local = axes.transpose();
        let local: Vec<(DVec3, f64)> = balls
            .iter()
            .map(|(c, r)| (to_local * (*c - reference), *r))
            .collect();
        // Cross-section centre: the middle of the balls' extent across the axis.
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for (q, r) in &local {
            lo = lo.min(*q - DVec3::splat(*r));
            hi = hi.max(*q + DVec3::splat(*r));
        }
        let (cy, cz) = (0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z));
        let across = |q: DVec3| (q.y - cy) * (q.y - cy) + (q.z - cz) * (q.z - cz);
        let radius = local
            .iter()
            .fold(0.0f64, |m, (q, r)| m.max(across(*q).sqrt() + r));
        let (x0, x1) = core_interval(
            local
                .iter()
                .map(|(q, r)| (q.x, shrink(radius - r, across(*q)))),
        );
        let at = |x: f64| reference + axes * DVec3::new(x, cy, cz);
        Self {
            core: Segment::new(at(x0), at(x1)),
            radius: radius + pad,
        }
    }

    /// The least-volume capsule over candidate axes `directions`, polished by
    /// [`polish_frame`].
    fn fit_balls(balls: &[Ball], directions: &[DVec3]) -> Self {
        let reference = balls[0].0;
        let cost = |axes: DMat3| Self::from_balls(balls, axes, reference, 0.0).volume();
        let axes = polish_frame(directions.iter().map(|&d| frame_along(d)), cost);
        Self::enclosing_balls(balls, axes)
    }

    /// The capsule with axis `axes.x_axis` containing every ball, padded for rounding.
    fn enclosing_balls(balls: &[Ball], axes: DMat3) -> Self {
        Self::from_balls(
            balls,
            axes,
            balls[0].0,
            conservative_slack(ball_scale(balls)),
        )
    }

    /// The end balls of two capsules.
    fn end_balls(a: &Self, b: &Self) -> [Ball; 4] {
        [
            (a.core.a, a.radius),
            (a.core.b, a.radius),
            (b.core.a, b.radius),
            (b.core.b, b.radius),
        ]
    }

    /// PCA axis, and the axis through the centroids of the two end thirds of the points
    /// along it (far less sensitive to sampling noise across a long set); the least volume
    /// wins.
    fn fit(points: &[DVec3], moments: &Moments) -> Self {
        let (axes, _) = principal_frame(&moments.covariance);
        let balls: Vec<Ball> = points.iter().map(|p| (*p, 0.0)).collect();
        let ends = end_centroids(points, axes.x_axis, moments.mean);
        Self::fit_balls(&balls, &[axes.x_axis, ends])
    }

    /// The core in the frame of `pose` applied to it.
    #[inline]
    fn moved_core(&self, pose: &Isometry) -> Segment {
        Segment::new(
            pose.transform_point(self.core.a),
            pose.transform_point(self.core.b),
        )
    }

    /// Distance between the cores of `self` and `other` (`pose_ab` = B in A), and the slack
    /// for the magnitudes involved.
    #[inline]
    fn core_distance(&self, other: &Self, pose_ab: &Isometry) -> (f64, f64) {
        let b = other.moved_core(pose_ab);
        let (_, _, p, q) = self.core.closest_points(&b);
        let scale = self.core.a.abs().max_element()
            + self.core.b.abs().max_element()
            + b.a.abs().max_element()
            + b.b.abs().max_element()
            + self.radius
            + other.radius;
        (p.distance(q), conservative_slack(scale))
    }
}

/// The direction from the centroid of the lowest third of `points` along `axis` to that of
/// the highest third (`axis` itself when either is empty or they coincide).
fn end_centroids(points: &[DVec3], axis: DVec3, reference: DVec3) -> DVec3 {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let x = axis.dot(*p - reference);
            (lo.min(x), hi.max(x))
        });
    let (cut_lo, cut_hi) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
    let (mut sum_lo, mut n_lo, mut sum_hi, mut n_hi) = (DVec3::ZERO, 0.0, DVec3::ZERO, 0.0);
    for p in points {
        let d = *p - reference;
        let x = axis.dot(d);
        if x <= cut_lo {
            (sum_lo, n_lo) = (sum_lo + d, n_lo + 1.0);
        }
        if x >= cut_hi {
            (sum_hi, n_hi) = (sum_hi + d, n_hi + 1.0);
        }
    }
    if n_lo == 0.0 || n_hi == 0.0 {
        return axis;
    }
    (sum_hi / n_hi - sum_lo / n_lo)
        .try_normalize()
        .unwrap_or(axis)
}

impl BoundingVolume for Lss {
    const NAME: &'static str = "lss";

    fn fit_points(points: &[DVec3]) -> Self {
        debug_assert!(!points.is_empty());
        Self::fit(points, &point_moments(points))
    }

    fn fit_triangles(triangles: &[Triangle]) -> Self {
        debug_assert!(!triangles.is_empty());
        let vertices: Vec<DVec3> = triangles.iter().flat_map(|t| t.vertices()).collect();
        let moments = triangle_moments(triangles).unwrap_or_else(|| point_moments(&vertices));
        Self::fit(&vertices, &moments)
    }

    fn fit_triangles_in_frame(&self, triangles: &[Triangle]) -> Self {
        Self::enclosing_balls(&vertex_balls(triangles), frame_along(self.core.direction()))
    }

    fn merged_in_frame(&self, a: &Self, b: &Self) -> Self {
        Self::enclosing_balls(&Self::end_balls(a, b), frame_along(self.core.direction()))
    }

    /// Contains the four end balls of both inputs; the axis is the best of both inputs'
    /// axes and the PCA axis of the four end points.
    fn merged(&self, other: &Self) -> Self {
        let balls = Self::end_balls(self, other);
        let ends = balls.map(|(c, _)| c);
        let (pca, _) = principal_frame(&point_moments(&ends).covariance);
        Self::fit_balls(
            &balls,
            &[self.core.direction(), other.core.direction(), pca.x_axis],
        )
    }

    #[inline]
    fn transformed(&self, pose: &Isometry) -> Self {
        let pad = super::transform_slack(self.center(), pose, self.size());
        Self {
            core: self.moved_core(pose),
            radius: self.radius + pad,
        }
    }

    #[inline]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool {
        let (d, slack) = self.core_distance(other, pose_ab);
        d <= self.radius + other.radius + slack
    }

    #[inline]
    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64 {
        let (d, slack) = self.core_distance(other, pose_ab);
        (d - self.radius - other.radius - slack).max(0.0)
    }

    #[inline]
    fn contains_point(&self, point: DVec3) -> bool {
        let (a, d) = (self.core.a, self.core.direction());
        let length_squared = d.length_squared();
        let t = if length_squared > 0.0 {
            ((point - a).dot(d) / length_squared).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (point - a - d * t).length_squared() <= self.radius * self.radius
    }

    #[inline]
    fn center(&self) -> DVec3 {
        self.core.point_at(0.5)
    }

    #[inline]
    fn volume(&self) -> f64 {
        let r = self.radius;
        PI * r * r * (self.core.length() + 4.0 / 3.0 * r)
    }

    #[inline]
    fn size(&self) -> f64 {
        self.core.length() + 2.0 * self.radius
    }

    #[inline]
    fn stand_off(&self) -> f64 {
        self.size()
    }
}

impl Rss {
    /// From trusted parts.
    #[must_use]
    pub fn new(center: DVec3, axes: DMat3, half_lengths: [f64; 2], radius: f64) -> Self {
        debug_assert!(
            (axes.transpose() * axes).abs_diff_eq(DMat3::IDENTITY, 1e-9),
            "axes not orthonormal: {axes}"
        );
        debug_assert!(half_lengths[0] >= 0.0 && half_lengths[1] >= 0.0 && radius >= 0.0);
        Self {
            center,
            axes,
            half_lengths,
            radius,
        }
    }

    /// The rectangle's four corners.
    #[must_use]
    pub fn corners(&self) -> [DVec3; 4] {
        let (u, v) = (
            self.axes.x_axis * self.half_lengths[0],
            self.axes.y_axis * self.half_lengths[1],
        );
        [
            self.center - u - v,
            self.center + u - v,
            self.center + u + v,
            self.center - u + v,
        ]
    }

    /// The RSS with rectangle frame `axes` containing every ball, padded by `pad`.
    fn from_balls(balls: &[Ball], axes: DMat3, reference: DVec3, pad: f64) -> Self {
        let to_local = axes.transpose();
        let local: Vec<(DVec3, f64)> = balls
            .iter()
            .map(|(c, r)| (to_local * (*c - reference), *r))
            .collect();
        let (zlo, zhi) = local
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (q, r)| {
                (lo.min(q.z - r), hi.max(q.z + r))
            });
        let (cz, radius) = (0.5 * (zlo + zhi), 0.5 * (zhi - zlo));
        // Per ball: how far it may be from the rectangle in-plane, squared.
        let reach2 = |q: DVec3, r: f64| {
            let reach = radius - r;
            (reach * reach - (q.z - cz) * (q.z - cz)).max(0.0)
        };
        let (mut x0, mut x1) =
            core_interval(local.iter().map(|(q, r)| (q.x, reach2(*q, *r).sqrt())));
        let (mut y0, mut y1) =
            core_interval(local.iter().map(|(q, r)| (q.y, reach2(*q, *r).sqrt())));
        // Corner regions: a ball past both an x and a y side pushes the cheaper side out.
        // Sides only grow, so balls already handled stay inside.
        for (q, r) in &local {
            let ex = (q.x - x1).max(x0 - q.x).max(0.0);
            let ey = (q.y - y1).max(y0 - q.y).max(0.0);
            let room = reach2(*q, *r);
            if ex > 0.0 && ey > 0.0 && ex * ex + ey * ey > room {
                let push_x = ex - shrink(room.sqrt(), ey * ey);
                let push_y = ey - shrink(room.sqrt(), ex * ex);
                if push_x <= push_y {
                    if q.x > x1 { x1 += push_x } else { x0 -= push_x }
                } else if q.y > y1 {
                    y1 += push_y;
                } else {
                    y0 -= push_y;
                }
            }
        }
        Self {
            center: reference + axes * DVec3::new(0.5 * (x0 + x1), 0.5 * (y0 + y1), cz),
            axes,
            half_lengths: [0.5 * (x1 - x0), 0.5 * (y1 - y0)],
            radius: radius + pad,
        }
    }

    /// The least-volume RSS over candidate frames, polished by [`polish_frame`].
    fn fit_balls(balls: &[Ball], frames: &[DMat3]) -> Self {
        let reference = balls[0].0;
        let cost = |axes: DMat3| Self::from_balls(balls, axes, reference, 0.0).volume();
        let axes = polish_frame(frames.iter().copied(), cost);
        Self::enclosing_balls(balls, axes)
    }

    /// The RSS with rectangle frame `axes` containing every ball, padded for rounding.
    fn enclosing_balls(balls: &[Ball], axes: DMat3) -> Self {
        Self::from_balls(
            balls,
            axes,
            balls[0].0,
            conservative_slack(ball_scale(balls)),
        )
    }

    /// The corner balls of two RSSs (four rectangle corners each, with its radius).
    fn corner_balls(a: &Self, b: &Self) -> [Ball; 8] {
        let (ca, cb) = (a.corners(), b.corners());
        std::array::from_fn(|k| {
            if k < 4 {
                (ca[k], a.radius)
            } else {
                (cb[k - 4], b.radius)
            }
        })
    }

    /// PCA frame (normal = least axis), plus the minimum-area rectangle frame when the two
    /// in-plane eigenvalues nearly coincide.
    fn fit(points: &[DVec3], moments: &Moments) -> Self {
        let (axes, values) = principal_frame(&moments.covariance);
        let mut frames = vec![axes];
        if values.x - values.y <= AMBIGUOUS_EIGENVALUES * values.x {
            frames.push(frame_about(axes.z_axis, points, moments.mean));
        }
        let balls: Vec<Ball> = points.iter().map(|p| (*p, 0.0)).collect();
        Self::fit_balls(&balls, &frames)
    }

    /// B's rectangle in A's rectangle frame (`c`, `u`, `v`) and the slack for the
    /// magnitudes involved.
    #[inline]
    fn relative(&self, other: &Self, pose_ab: &Isometry) -> (DVec3, DVec3, DVec3, f64) {
        let to_a = self.axes.transpose();
        let r = to_a * (pose_ab.rotation * other.axes);
        let c = to_a * (pose_ab.rotation * other.center + pose_ab.translation - self.center);
        let scale = self.center.abs().max_element()
            + other.center.abs().max_element()
            + pose_ab.translation.abs().max_element()
            + self.half_lengths[0]
            + self.half_lengths[1]
            + other.half_lengths[0]
            + other.half_lengths[1]
            + self.radius
            + other.radius;
        (c, r.x_axis, r.y_axis, conservative_slack(scale))
    }
}

/// A lower bound, exact to rounding, on the distance between rectangle A
/// (`|x| ≤ a[0], |y| ≤ a[1], z = 0`) and rectangle B (`c + s·u + t·v`, `|s| ≤ b[0]`,
/// `|t| ≤ b[1]`, `u, v` orthonormal), all in A's frame. 0 when they touch or cross.
///
/// The closest pair of two rectangles lies on an edge pair or is a vertex over the other's
/// face (16 edge pairs, 2 support vertices; facing edges first, see the module doc). The
/// direction between the best pair is then
/// snapped to the exact normal of the features it lies on (the cross product of two edges
/// met in their interiors, a face normal, or the direction with an edge's component
/// removed) and certified by the support functions (see the module doc).
#[must_use]
#[inline]
pub fn rectangle_distance(a: [f64; 2], c: DVec3, u: DVec3, v: DVec3, b: [f64; 2]) -> f64 {
    // A point (a sphere's core) against a rectangle: its closest point by a clamp, certified
    // like the general case. The pair's direction must be orthogonal to the rectangle's
    // axes along which the closest point is inside it, as the general path snaps its normal
    // ([`Closest::normal`]): on a large rectangle a direction off by rounding loses the
    // half-lengths times that rounding. In A's frame the clamp leaves those components
    // exactly zero; along B's axes they are removed.
    // PERF: a ball's volume against an RSS tree (`convex_mesh::volume_bound` of a ball);
    // the pipeline's walk has its own inline copy (`convex_mesh/node_bound.rs`).
    if b == [0.0, 0.0] {
        let closest = DVec3::new(clamp_symmetric(c.x, a[0]), clamp_symmetric(c.y, a[1]), 0.0);
        return certified_gap(c - closest, a, c, [u, v], b);
    }
    if a == [0.0, 0.0] {
        let (s, t) = (u.dot(c), v.dot(c));
        let (s_in, t_in) = (clamp_symmetric(s, b[0]), clamp_symmetric(t, b[1]));
        let mut delta = c - u * s_in - v * t_in;
        if s_in == s {
            delta -= u * u.dot(delta);
        }
        if t_in == t {
            delta -= v * v.dot(delta);
        }
        return certified_gap(delta, a, c, [u, v], b);
    }
    let pair = RectanglePair::new(a, c, u, v, b);
    let mut best = Closest {
        distance_squared: f64::INFINITY,
        delta: DVec3::ZERO,
        free: [DVec3::ZERO; 2],
    };
    pair.vertices_over_faces(&mut best);
    // Phase 1: the two edges of each rectangle that face the other's centre. When the
    // certificate matches the pair found, no other pair can be closer: stop.
    let sign = |x: f64| if x >= 0.0 { 1.0 } else { -1.0 };
    let facing_a = [sign(c.y), sign(c.x)];
    let facing_b = [-sign(pair.g_dot_c[0]), -sign(pair.g_dot_c[1])];
    pair.edge_pair::<0, 0>(facing_a[0], facing_b[0], &mut best);
    pair.edge_pair::<0, 1>(facing_a[0], facing_b[1], &mut best);
    pair.edge_pair::<1, 0>(facing_a[1], facing_b[0], &mut best);
    pair.edge_pair::<1, 1>(facing_a[1], facing_b[1], &mut best);
    let Some(gap) = pair.certify(&best) else {
        return 0.0;
    };
    if gap >= (1.0 - EARLY_EXIT_RELATIVE) * best.distance_squared.sqrt() {
        return gap.max(0.0);
    }
    // Phase 2: the other twelve edge pairs.
    pair.other_edge_pairs::<0, 0>(facing_a[0], facing_b[0], &mut best);
    pair.other_edge_pairs::<0, 1>(facing_a[0], facing_b[1], &mut best);
    pair.other_edge_pairs::<1, 0>(facing_a[1], facing_b[0], &mut best);
    pair.other_edge_pairs::<1, 1>(facing_a[1], facing_b[1], &mut best);
    pair.certify(&best).map_or(0.0, |gap| gap.max(0.0))
}

/// A certificate within this fraction of the best pair's distance ends the search early
/// (the answer is then within this fraction of the exact distance).
const EARLY_EXIT_RELATIVE: f64 = 1e-12;

/// Rectangle A (`|x| ≤ a[0], |y| ≤ a[1], z = 0`) and rectangle B (`c + s·u + t·v`) in A's
/// frame, with the terms every edge pair shares.
struct RectanglePair {
    a: [f64; 2],
    b: [f64; 2],
    c: DVec3,
    /// B's edge directions `[u, v]`.
    dirs: [DVec3; 2],
    /// `dirs[j]·c`.
    f_dot_c: [f64; 2],
    /// `g·c` for the offset direction `g = dirs[1 - j]` of B's edges along `dirs[j]`.
    g_dot_c: [f64; 2],
    /// `1 / (1 − k²)` with `k = e_i·dirs[j]`, or 0 when the edges are parallel (any `s` is
    /// then optimal for the lines: take the middle, then clamp).
    inverse: [[f64; 2]; 2],
}

impl RectanglePair {
    #[inline]
    fn new(a: [f64; 2], c: DVec3, u: DVec3, v: DVec3, b: [f64; 2]) -> Self {
        let inverse = |k: f64| {
            let denominator = 1.0 - k * k;
            if denominator > PARALLEL_SIN_SQUARED {
                1.0 / denominator
            } else {
                0.0
            }
        };
        let (uc, vc) = (u.dot(c), v.dot(c));
        Self {
            a,
            b,
            c,
            dirs: [u, v],
            f_dot_c: [uc, vc],
            g_dot_c: [vc, uc],
            inverse: [[inverse(u.x), inverse(v.x)], [inverse(u.y), inverse(v.y)]],
        }
    }

    /// A's edge along axis `i` at `sign_a · a[1 − i]` across, against B's edge along
    /// `f = dirs[j]` at `sign_b · b[1 − j]` along `g = dirs[1 − j]`: the line solution
    /// clamped, `t` from `s`, and `s` again from `t` when `t` was clamped (Ericson §5.1.9,
    /// in centred form; `f·g = 0` makes `f·w` independent of B's offset).
    // PERF: const indices make every component access static; with `inline(always)` the
    // whole search is one straight-line function (see the rss distance bench).
    #[inline(always)]
    fn edge_pair<const I: usize, const J: usize>(
        &self,
        sign_a: f64,
        sign_b: f64,
        best: &mut Closest,
    ) {
        let (a, b, c) = (self.a, self.b, self.c);
        let across = 1 - I;
        let (f, g) = (self.dirs[J], self.dirs[1 - J]);
        let (ha, hb) = (a[I], b[J]);
        let mut pa = DVec3::ZERO;
        pa[across] = sign_a * a[across];
        let w = pa - (c + g * (sign_b * b[1 - J]));
        let (k, pe, pf) = (f[I], w[I], f[across] * pa[across] - self.f_dot_c[J]);
        let mut s = clamp_symmetric((k * pf - pe) * self.inverse[I][J], ha);
        let t_free = pf + s * k;
        let t = clamp_symmetric(t_free, hb);
        if t != t_free {
            s = clamp_symmetric(t * k - pe, ha);
        }
        let e = if I == 0 { DVec3::X } else { DVec3::Y };
        let free_a = if s.abs() < ha { e } else { DVec3::ZERO };
        let free_b = if t.abs() < hb { f } else { DVec3::ZERO };
        best.consider(-(w + e * s - f * t), [free_a, free_b]);
    }

    /// The three edge pairs of directions `I`, `J` other than the facing one.
    #[inline(always)]
    fn other_edge_pairs<const I: usize, const J: usize>(
        &self,
        facing_a: f64,
        facing_b: f64,
        best: &mut Closest,
    ) {
        self.edge_pair::<I, J>(-facing_a, facing_b, best);
        self.edge_pair::<I, J>(facing_a, -facing_b, best);
        self.edge_pair::<I, J>(-facing_a, -facing_b, best);
    }

    /// The vertex–face candidates. When a vertex of A over B's face is the closest pair,
    /// the direction between them is B's normal `n` oriented from A to B (the sign of
    /// `n·c`), and the vertex is A's support point along `n`: only that vertex is tried.
    /// Likewise for B's vertex over A's face with A's normal.
    #[inline]
    fn vertices_over_faces(&self, best: &mut Closest) {
        let (a, b, c, [u, v]) = (self.a, self.b, self.c, self.dirs);
        let sign = |x: f64| if x >= 0.0 { 1.0 } else { -1.0 };
        let normal_b = u.cross(v);
        let n = normal_b * sign(normal_b.dot(c));
        let p = DVec3::new(sign(n.x) * a[0], sign(n.y) * a[1], 0.0);
        let d = p - c;
        let (s, t) = (d.dot(u), d.dot(v));
        if s.abs() <= b[0] && t.abs() <= b[1] {
            best.consider(c + u * s + v * t - p, [u, v]);
        }
        let up = sign(c.z);
        let q = c - u * (sign(up * u.z) * b[0]) - v * (sign(up * v.z) * b[1]);
        if q.x.abs() <= a[0] && q.y.abs() <= a[1] {
            best.consider(DVec3::new(0.0, 0.0, q.z), [DVec3::X, DVec3::Y]);
        }
    }

    /// The separation of the rectangles along the best pair's direction (min over B of
    /// `n·y` minus max over A of `n·x`): never above the true distance. `None` when the
    /// pair coincides (the rectangles touch).
    #[inline]
    fn certify(&self, best: &Closest) -> Option<f64> {
        let n = best.normal()?;
        Some(separation_along(n, self.a, self.c, self.dirs, self.b))
    }
}

/// The separation of rectangles A and B (as in [`rectangle_distance`]) along unit `n`: min
/// over B of `n·y` minus max over A of `n·x`, from their support functions. Never above
/// their distance.
#[inline(always)]
fn separation_along(n: DVec3, a: [f64; 2], c: DVec3, [u, v]: [DVec3; 2], b: [f64; 2]) -> f64 {
    n.dot(c) - b[0] * n.dot(u).abs() - b[1] * n.dot(v).abs() - a[0] * n.x.abs() - a[1] * n.y.abs()
}

/// [`rectangle_distance`] when one rectangle is a point: the separation along `delta`, the
/// closest pair's direction from A to B, or 0 when it is zero (they touch).
#[inline(always)]
fn certified_gap(delta: DVec3, a: [f64; 2], c: DVec3, dirs: [DVec3; 2], b: [f64; 2]) -> f64 {
    delta
        .try_normalize()
        .map_or(0.0, |n| separation_along(n, a, c, dirs, b).max(0.0))
}

/// The best candidate pair so far: `delta = q − p` (from A to B) and the unit directions
/// along which the pair is free to slide (an edge met in its interior, a face's axes), to
/// which the exact separating direction is orthogonal. Unused slots are zero.
struct Closest {
    distance_squared: f64,
    delta: DVec3,
    free: [DVec3; 2],
}

impl Closest {
    #[inline]
    fn consider(&mut self, delta: DVec3, free: [DVec3; 2]) {
        let distance_squared = delta.length_squared();
        if distance_squared < self.distance_squared {
            *self = Self {
                distance_squared,
                delta,
                free,
            };
        }
    }

    /// The unit direction from A to B, orthogonal to the free directions; `None` when the
    /// pair coincides (the rectangles touch).
    #[inline]
    fn normal(&self) -> Option<DVec3> {
        let w = self.delta;
        let [f0, f1] = self.free;
        let cross = f0.cross(f1);
        let n = if cross.length_squared() > PARALLEL_SIN_SQUARED {
            cross
        } else {
            // At most one independent free direction (the other is zero or parallel).
            let f = if f0 == DVec3::ZERO { f1 } else { f0 };
            w - f * f.dot(w)
        };
        let n = n.try_normalize().or_else(|| w.try_normalize())?;
        Some(if n.dot(w) < 0.0 { -n } else { n })
    }
}

/// `x` clamped to `[-h, h]` (`h ≥ 0`, `x` finite).
// PERF: plain comparisons compile to minsd/maxsd; `f64::clamp` and `f64::max` add NaN
// handling and an assertion (rss distance bench).
#[inline(always)]
fn clamp_symmetric(x: f64, h: f64) -> f64 {
    let y = if x > h { h } else { x };
    if y < -h { -h } else { y }
}

/// Below this `sin²` of their angle, two directions count as parallel.
const PARALLEL_SIN_SQUARED: f64 = 1e-12;

impl BoundingVolume for Rss {
    const NAME: &'static str = "rss";

    fn fit_points(points: &[DVec3]) -> Self {
        debug_assert!(!points.is_empty());
        Self::fit(points, &point_moments(points))
    }

    fn fit_triangles(triangles: &[Triangle]) -> Self {
        debug_assert!(!triangles.is_empty());
        let vertices: Vec<DVec3> = triangles.iter().flat_map(|t| t.vertices()).collect();
        let moments = triangle_moments(triangles).unwrap_or_else(|| point_moments(&vertices));
        Self::fit(&vertices, &moments)
    }

    fn fit_triangles_in_frame(&self, triangles: &[Triangle]) -> Self {
        Self::enclosing_balls(&vertex_balls(triangles), self.axes)
    }

    fn merged_in_frame(&self, a: &Self, b: &Self) -> Self {
        Self::enclosing_balls(&Self::corner_balls(a, b), self.axes)
    }

    /// Contains the eight corner balls of both inputs; the frame is the best of both inputs'
    /// frames and the PCA frame of the eight corners.
    fn merged(&self, other: &Self) -> Self {
        let balls = Self::corner_balls(self, other);
        let (pca, _) = principal_frame(&point_moments(&balls.map(|(c, _)| c)).covariance);
        Self::fit_balls(&balls, &[self.axes, other.axes, pca])
    }

    #[inline]
    fn transformed(&self, pose: &Isometry) -> Self {
        let pad = super::transform_slack(self.center, pose, self.size());
        Self {
            center: pose.transform_point(self.center),
            axes: pose.rotation * self.axes,
            half_lengths: self.half_lengths,
            radius: self.radius + pad,
        }
    }

    /// Quick accept when the rectangle centres are within reach (they are core points),
    /// quick reject on a gap along either normal, else the exact rectangle distance.
    #[inline]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool {
        let (c, u, v, slack) = self.relative(other, pose_ab);
        let (a, b) = (self.half_lengths, other.half_lengths);
        let reach = self.radius + other.radius + slack;
        if c.length_squared() <= reach * reach {
            return true;
        }
        if c.z.abs() - b[0] * u.z.abs() - b[1] * v.z.abs() > reach {
            return false;
        }
        let n = u.cross(v);
        if n.dot(c).abs() - a[0] * n.x.abs() - a[1] * n.y.abs() > reach {
            return false;
        }
        rectangle_distance(a, c, u, v, b) <= reach
    }

    #[inline]
    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64 {
        let (c, u, v, slack) = self.relative(other, pose_ab);
        let d = rectangle_distance(self.half_lengths, c, u, v, other.half_lengths);
        (d - self.radius - other.radius - slack).max(0.0)
    }

    /// Cheap bounds first, each returned as soon as it reaches `limit`: the enclosing balls
    /// (no relative rotation needed), then the gaps along either rectangle's normal, then
    /// the exact rectangle distance.
    #[inline]
    fn distance_lower_bound_within(&self, other: &Self, pose_ab: &Isometry, limit: f64) -> f64 {
        let ball = |r: &Self| 0.5 * r.size();
        let centres = self.center.distance(pose_ab.transform_point(other.center));
        let slack = super::transform_slack(other.center, pose_ab, other.size())
            + conservative_slack(self.center.abs().max_element() + self.size());
        let by_balls = centres - ball(self) - ball(other) - slack;
        if by_balls >= limit {
            return by_balls;
        }
        let (c, u, v, slack) = self.relative(other, pose_ab);
        let (a, b) = (self.half_lengths, other.half_lengths);
        let reach = self.radius + other.radius + slack;
        let n = u.cross(v);
        let by_normals = (c.z.abs() - b[0] * u.z.abs() - b[1] * v.z.abs())
            .max(n.dot(c).abs() - a[0] * n.x.abs() - a[1] * n.y.abs())
            - reach;
        if by_normals >= limit {
            return by_normals;
        }
        (rectangle_distance(a, c, u, v, b) - self.radius - other.radius - slack).max(0.0)
    }

    #[inline]
    fn contains_point(&self, point: DVec3) -> bool {
        let q = self.axes.transpose() * (point - self.center);
        let dx = (q.x.abs() - self.half_lengths[0]).max(0.0);
        let dy = (q.y.abs() - self.half_lengths[1]).max(0.0);
        dx * dx + dy * dy + q.z * q.z <= self.radius * self.radius
    }

    #[inline]
    fn center(&self) -> DVec3 {
        self.center
    }

    /// `2·L0·L1·r + π(L0 + L1)·r² + 4/3·π·r³` with full side lengths `L = 2·half`
    /// (Steiner's formula for a flat rectangle swept by a ball).
    #[inline]
    fn volume(&self) -> f64 {
        let (l0, l1, r) = (
            2.0 * self.half_lengths[0],
            2.0 * self.half_lengths[1],
            self.radius,
        );
        2.0 * l0 * l1 * r + PI * (l0 + l1) * r * r + 4.0 / 3.0 * PI * r * r * r
    }

    #[inline]
    fn size(&self) -> f64 {
        // PERF: libm's `hypot` showed up at 5% of the distance query (mesh_pair bench); the
        // plain form cannot overflow below `MAX_COORDINATE`.
        let [x, y] = self.half_lengths;
        2.0 * (x * x + y * y).sqrt() + 2.0 * self.radius
    }

    #[inline]
    fn stand_off(&self) -> f64 {
        self.size()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::*;
    use rand::Rng;

    /// A point of the swept volume: `core_point` plus a random offset within `radius`
    /// (often on the surface).
    fn swept(rng: &mut TestRng, core_point: DVec3, radius: f64) -> DVec3 {
        let dir = point_in_cube(rng, 1.0).normalize_or(DVec3::Z);
        let t: f64 = if rng.random::<bool>() {
            1.0
        } else {
            rng.random()
        };
        core_point + dir * (radius * t)
    }

    fn in_lss(rng: &mut TestRng, l: &Lss) -> DVec3 {
        let t: f64 = rng.random();
        swept(rng, l.core.point_at(t), l.radius)
    }

    fn in_rss(rng: &mut TestRng, r: &Rss) -> DVec3 {
        let (s, t) = (rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0));
        let core = r.center
            + r.axes.x_axis * (s * r.half_lengths[0])
            + r.axes.y_axis * (t * r.half_lengths[1]);
        swept(rng, core, r.radius)
    }

    fn random_lss(rng: &mut TestRng, center: f64, scale: f64) -> Lss {
        let c = DVec3::splat(center);
        let a = c + point_in_cube(rng, scale);
        let b = if rng.random_range(0..8) == 0 {
            a
        } else {
            c + point_in_cube(rng, scale)
        };
        Lss::new(Segment::new(a, b), rng.random_range(0.0..0.5) * scale)
    }

    fn random_rss(rng: &mut TestRng, center: f64, scale: f64) -> Rss {
        let mut half = [
            rng.random_range(0.0..1.0) * scale,
            rng.random_range(0.0..1.0) * scale,
        ];
        match rng.random_range(0..8) {
            0 => half = [0.0, 0.0],
            1 => half[1] = 0.0,
            _ => {}
        }
        Rss::new(
            DVec3::splat(center) + point_in_cube(rng, scale),
            DMat3::from_quat(rotation(rng)),
            half,
            rng.random_range(0.0..0.5) * scale,
        )
    }

    #[test]
    fn fits_contain_every_point_and_vertex() {
        let mut rng = rng(31);
        for case in 0..4000 {
            let center = DVec3::splat(CENTERS[case % 4]);
            let scale = SCALES[(case / 4) % 5];
            let kind = CloudKind::ALL[(case / 20) % CloudKind::ALL.len()];
            let points = cloud(&mut rng, kind, 1 + case % 37, center, scale);
            let lss = Lss::fit_points(&points);
            let rss = Rss::fit_points(&points);
            for p in &points {
                assert!(lss.contains_point(*p), "case {case}: {p} outside {lss:?}");
                assert!(rss.contains_point(*p), "case {case}: {p} outside {rss:?}");
            }
            assert!(lss.volume().is_finite() && rss.volume().is_finite());
            let tris: Vec<Triangle> = points
                .chunks(3)
                .map(|c| Triangle::new(c[0], c[c.len() / 2], c[c.len() - 1]))
                .collect();
            let (lss, rss) = (Lss::fit_triangles(&tris), Rss::fit_triangles(&tris));
            for v in tris.iter().flat_map(|t| t.vertices()) {
                assert!(lss.contains_point(v), "case {case}: {v} outside {lss:?}");
                assert!(rss.contains_point(v), "case {case}: {v} outside {rss:?}");
            }
        }
    }

    /// PCA of 400 surface samples tilts the axis by up to ~0.05 rad in the worst of these
    /// cases (sampling noise); the polishing search must recover most of it.
    #[test]
    fn fits_of_a_capsule_and_a_slab_are_tight() {
        let mut rng = rng(32);
        for case in 0..500 {
            let rot = DMat3::from_quat(rotation(&mut rng));
            let center = DVec3::splat(CENTERS[case % 4]);
            // Points on a capsule of length 4 and radius 0.5 along the rotated x axis.
            let lss = Lss::new(
                Segment::new(center - rot.x_axis * 2.0, center + rot.x_axis * 2.0),
                0.5,
            );
            let points: Vec<DVec3> = (0..400)
                .map(|_| {
                    let t: f64 = rng.random();
                    lss.core.point_at(t) + point_in_cube(&mut rng, 1.0).normalize_or(DVec3::Y) * 0.5
                })
                .collect();
            let fitted = Lss::fit_points(&points);
            assert!(
                fitted.volume() <= lss.volume() * 1.1,
                "case {case}: {fitted:?}"
            );
            // A 4 × 2 rectangle swept by 0.1.
            let rss = Rss::new(center, rot, [2.0, 1.0], 0.1);
            let points: Vec<DVec3> = (0..400).map(|_| in_rss(&mut rng, &rss)).collect();
            let fitted = Rss::fit_points(&points);
            assert!(
                fitted.volume() <= rss.volume() * 1.1,
                "case {case}: {fitted:?}"
            );
        }
    }

    #[test]
    fn merged_volumes_contain_both_inputs() {
        let mut rng = rng(33);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let (la, lb) = (
                random_lss(&mut rng, center, scale),
                random_lss(&mut rng, center, scale),
            );
            let (ra, rb) = (
                random_rss(&mut rng, center, scale),
                random_rss(&mut rng, center, scale),
            );
            let (lm, rm) = (la.merged(&lb), ra.merged(&rb));
            for _ in 0..30 {
                let which = if rng.random::<bool>() { &la } else { &lb };
                let p = in_lss(&mut rng, which);
                assert!(
                    lm.contains_point(p),
                    "case {case}: {p} outside {lm:?} ({la:?}, {lb:?})"
                );
                let which = if rng.random::<bool>() { &ra } else { &rb };
                let p = in_rss(&mut rng, which);
                assert!(
                    rm.contains_point(p),
                    "case {case}: {p} outside {rm:?} ({ra:?}, {rb:?})"
                );
            }
        }
    }

    /// Exact distance from segment `p0 p1` to the rectangle `c + s·u + t·v` (oracle): zero
    /// when it crosses the face, else the least of the end points over the face and the four
    /// edge distances.
    fn segment_rectangle(p0: DVec3, p1: DVec3, c: DVec3, u: DVec3, v: DVec3, h: [f64; 2]) -> f64 {
        let n = u.cross(v);
        let inside = |x: DVec3| {
            let d = x - c;
            d.dot(u).abs() <= h[0] && d.dot(v).abs() <= h[1]
        };
        let (d0, d1) = ((p0 - c).dot(n), (p1 - c).dot(n));
        if d0 * d1 <= 0.0 && d0 != d1 && inside(p0 + (p1 - p0) * (d0 / (d0 - d1))) {
            return 0.0;
        }
        let mut best = f64::INFINITY;
        for (x, d) in [(p0, d0), (p1, d1)] {
            if inside(x) {
                best = best.min(d.abs());
            }
        }
        let corners = [
            c - u * h[0] - v * h[1],
            c + u * h[0] - v * h[1],
            c + u * h[0] + v * h[1],
            c - u * h[0] + v * h[1],
        ];
        for k in 0..4 {
            let (_, _, a, b) = Segment::new(p0, p1)
                .closest_points(&Segment::new(corners[k], corners[(k + 1) % 4]));
            best = best.min(a.distance(b));
        }
        best
    }

    /// Exact rectangle–rectangle distance (oracle): the least segment–rectangle distance
    /// over the eight edges.
    fn rectangle_oracle(a: [f64; 2], c: DVec3, u: DVec3, v: DVec3, b: [f64; 2]) -> f64 {
        let a_corners = [
            DVec3::new(-a[0], -a[1], 0.0),
            DVec3::new(a[0], -a[1], 0.0),
            DVec3::new(a[0], a[1], 0.0),
            DVec3::new(-a[0], a[1], 0.0),
        ];
        let b_corners = [
            c - u * b[0] - v * b[1],
            c + u * b[0] - v * b[1],
            c + u * b[0] + v * b[1],
            c - u * b[0] + v * b[1],
        ];
        let mut best = f64::INFINITY;
        for k in 0..4 {
            let (p0, p1) = (a_corners[k], a_corners[(k + 1) % 4]);
            best = best.min(segment_rectangle(p0, p1, c, u, v, b));
            let (q0, q1) = (b_corners[k], b_corners[(k + 1) % 4]);
            best = best.min(segment_rectangle(
                q0,
                q1,
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                a,
            ));
        }
        best
    }

    /// Random rectangle pairs in A's frame: general, parallel planes, coplanar, crossing,
    /// edge-parallel, degenerate (zero half-lengths) and a point on either side.
    fn random_rectangle_pair(
        rng: &mut TestRng,
        case: usize,
    ) -> ([f64; 2], DVec3, DVec3, DVec3, [f64; 2]) {
        let mut half = || [rng.random_range(0.0..2.0), rng.random_range(0.0..2.0)];
        let (mut a, mut b) = (half(), half());
        let mut rot = DMat3::from_quat(rotation(rng));
        let mut c = point_in_cube(rng, 3.0);
        match case % 8 {
            0 => rot = DMat3::from_rotation_z(rng.random_range(0.0..6.3)),
            1 => {
                rot = DMat3::from_rotation_z(rng.random_range(0.0..6.3));
                c.z = 0.0;
            }
            2 => c = point_in_cube(rng, 0.5),
            3 => rot = DMat3::from_rotation_x(rng.random_range(0.0..6.3)),
            4 => {
                a[rng.random_range(0..2)] = 0.0;
                b[rng.random_range(0..2)] = 0.0;
            }
            5 => rot = DMat3::from_rotation_z(1e-9) * DMat3::from_rotation_x(1e-9),
            // A point (a sphere's core) on either side.
            6 => b = [0.0, 0.0],
            7 => a = [0.0, 0.0],
            _ => {}
        }
        (a, c, rot.x_axis, rot.y_axis, b)
    }

    #[test]
    fn rectangle_distance_matches_the_exact_oracle() {
        let mut rng = rng(34);
        let (mut touching, mut apart, mut worst) = (0, 0, 0.0f64);
        for case in 0..20000 {
            let (a, c, u, v, b) = random_rectangle_pair(&mut rng, case);
            let found = rectangle_distance(a, c, u, v, b);
            let exact = rectangle_oracle(a, c, u, v, b);
            assert!(found <= exact + 1e-12, "case {case}: {found} > {exact}");
            // Relative to the distance, with an absolute floor for the oracle's own rounding
            // (sizes here are a few metres).
            let error = (exact - found) / exact.max(1e-5);
            worst = worst.max(error);
            assert!(
                error <= 1e-9,
                "case {case}: {found} vs {exact}: {a:?} {c} {u} {v} {b:?}"
            );
            if exact == 0.0 {
                touching += 1;
            } else {
                apart += 1;
            }
        }
        assert!(touching > 1000 && apart > 1000, "{touching} / {apart}");
        eprintln!("worst relative error {worst:e}");
    }

    #[test]
    fn overlap_and_distance_are_conservative_against_sampled_points() {
        let mut rng = rng(35);
        let (mut overlapping, mut apart) = ([0; 2], [0; 2]);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let mut pose = isometry(&mut rng, 0.5 * scale);
            pose.translation += DVec3::splat(center);
            let (la, lb) = (
                random_lss(&mut rng, center, scale),
                random_lss(&mut rng, 0.0, scale),
            );
            let (ra, rb) = (
                random_rss(&mut rng, center, scale),
                random_rss(&mut rng, 0.0, scale),
            );
            // LSS: the bound is the exact capsule distance, never above the sampled one.
            let (o, d) = (la.overlaps(&lb, &pose), la.distance_lower_bound(&lb, &pose));
            let pa: Vec<DVec3> = (0..200).map(|_| in_lss(&mut rng, &la)).collect();
            let pb: Vec<DVec3> = (0..200)
                .map(|_| pose.transform_point(in_lss(&mut rng, &lb)))
                .collect();
            check(case, o, d, &pa, &pb, |p| la.contains_point(p));
            if o {
                overlapping[0] += 1
            } else {
                apart[0] += 1
            }
            // RSS: also against the exact oracle.
            let (o, d) = (ra.overlaps(&rb, &pose), ra.distance_lower_bound(&rb, &pose));
            let pa: Vec<DVec3> = (0..200).map(|_| in_rss(&mut rng, &ra)).collect();
            let pb: Vec<DVec3> = (0..200)
                .map(|_| pose.transform_point(in_rss(&mut rng, &rb)))
                .collect();
            check(case, o, d, &pa, &pb, |p| ra.contains_point(p));
            let to_a = ra.axes.transpose();
            let r = to_a * (pose.rotation * rb.axes);
            let c = to_a * (pose.transform_point(rb.center) - ra.center);
            let exact = (rectangle_oracle(ra.half_lengths, c, r.x_axis, r.y_axis, rb.half_lengths)
                - ra.radius
                - rb.radius)
                .max(0.0);
            let tolerance = 1e-9 * exact + 1e-11 * (center + scale);
            assert!(d <= exact + 1e-12 * scale, "case {case}: {d} > {exact}");
            assert!(d >= exact - tolerance, "case {case}: {d} < {exact}");
            if o {
                overlapping[1] += 1
            } else {
                apart[1] += 1
            }
        }
        for k in 0..2 {
            assert!(
                overlapping[k] > 300 && apart[k] > 300,
                "{overlapping:?} / {apart:?}"
            );
        }
    }

    /// Overlap is reported when a sampled point of B lies in A; the bound never exceeds
    /// the sampled distance, and is positive whenever overlap is denied.
    fn check(
        case: usize,
        overlaps: bool,
        bound: f64,
        pa: &[DVec3],
        pb: &[DVec3],
        in_a: impl Fn(DVec3) -> bool,
    ) {
        assert!(bound >= 0.0);
        if pb.iter().any(|p| in_a(*p)) {
            assert!(overlaps, "case {case}: false negative");
            assert_eq!(bound, 0.0, "case {case}");
        }
        assert_eq!(
            overlaps,
            bound == 0.0,
            "case {case}: overlap {overlaps}, bound {bound}"
        );
        let sampled = pa
            .iter()
            .flat_map(|p| pb.iter().map(move |q| p.distance(*q)))
            .fold(f64::INFINITY, f64::min);
        assert!(bound <= sampled, "case {case}: {bound} > {sampled}");
    }

    #[test]
    fn transformed_volumes_move_their_points_and_keep_overlap() {
        let mut rng = rng(36);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let mut pose = isometry(&mut rng, scale);
            pose.translation += DVec3::splat(center);
            let (la, lb) = (
                random_lss(&mut rng, 0.0, scale),
                random_lss(&mut rng, 0.0, scale),
            );
            let (ra, rb) = (
                random_rss(&mut rng, 0.0, scale),
                random_rss(&mut rng, 0.0, scale),
            );
            let (lm, rm) = (lb.transformed(&pose), rb.transformed(&pose));
            let id = Isometry::IDENTITY;
            // Moved volumes are padded for the rounding of the move (transform_slack): the
            // two distances may differ by that padding on top of the rounding itself.
            let tolerance = 1e-9 * scale + 1e-12 * center;
            let (d1, d2) = (
                la.distance_lower_bound(&lb, &pose),
                la.distance_lower_bound(&lm, &id),
            );
            let lss_pad = lm.radius - lb.radius;
            assert!(
                (d1 - d2).abs() <= tolerance + lss_pad,
                "case {case}: {d1} vs {d2}"
            );
            let (d1, d2) = (
                ra.distance_lower_bound(&rb, &pose),
                ra.distance_lower_bound(&rm, &id),
            );
            let rss_pad = rm.radius - rb.radius;
            assert!(
                (d1 - d2).abs() <= tolerance + rss_pad,
                "case {case}: {d1} vs {d2}"
            );
            assert_eq!(
                la.overlaps(&lb, &pose),
                la.overlaps(&lm, &id),
                "case {case}"
            );
            assert_eq!(
                ra.overlaps(&rb, &pose),
                ra.overlaps(&rm, &id),
                "case {case}"
            );
            // Points at least this deep inside survive the rounding of the move.
            let depth = 1e-10 * (center + scale);
            let (shrunk_r, shrunk_l) = (
                Rss {
                    radius: rb.radius - depth,
                    ..rb
                },
                Lss {
                    radius: lb.radius - depth,
                    ..lb
                },
            );
            for _ in 0..10 {
                let p = in_rss(&mut rng, &rb);
                if shrunk_r.radius > 0.0 && shrunk_r.contains_point(p) {
                    assert!(rm.contains_point(pose.transform_point(p)), "case {case}");
                }
                let p = in_lss(&mut rng, &lb);
                if shrunk_l.radius > 0.0 && shrunk_l.contains_point(p) {
                    assert!(lm.contains_point(pose.transform_point(p)), "case {case}");
                }
            }
        }
    }

    #[test]
    fn touching_volumes_overlap_with_zero_distance() {
        let mut rng = rng(37);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let ra = random_rss(&mut rng, center, scale);
            let rb = random_rss(&mut rng, 0.0, scale);
            // A point on A's surface, and B's corner ball placed to touch it from outside.
            let dir = point_in_cube(&mut rng, 1.0).normalize_or(DVec3::Z);
            let (s, t) = (rng.random_range(-1.0..=1.0), rng.random_range(-1.0..=1.0));
            let core_a = ra.center
                + ra.axes.x_axis * (s * ra.half_lengths[0])
                + ra.axes.y_axis * (t * ra.half_lengths[1]);
            let (dir, core_a) = if dir.dot(ra.axes.z_axis).abs() > 0.0 {
                (ra.axes.z_axis * dir.dot(ra.axes.z_axis).signum(), core_a)
            } else {
                (dir, core_a)
            };
            let target = core_a + dir * (ra.radius + rb.radius);
            let rot = DMat3::from_quat(rotation(&mut rng));
            let corner = rb.corners()[case % 4];
            let pose = Isometry::new(rot, target - rot * corner);
            assert!(ra.overlaps(&rb, &pose), "case {case}");
            assert_eq!(ra.distance_lower_bound(&rb, &pose), 0.0, "case {case}");
            let la = Lss::new(Segment::new(ra.corners()[0], ra.corners()[2]), ra.radius);
            let lb = Lss::new(Segment::new(rb.corners()[0], rb.corners()[2]), rb.radius);
            let on_a = la.core.point_at(rng.random()) + dir * (la.radius + lb.radius);
            let pose = Isometry::new(rot, on_a - rot * lb.core.b);
            assert!(la.overlaps(&lb, &pose), "case {case}");
            assert_eq!(la.distance_lower_bound(&lb, &pose), 0.0, "case {case}");
        }
    }

    #[test]
    fn volumes_match_monte_carlo_estimates() {
        let mut rng = rng(38);
        for case in 0..6 {
            let rss = random_rss(&mut rng, 0.0, 1.0);
            let lss = random_lss(&mut rng, 0.0, 1.0);
            for (volume, center, reach, inside) in [
                (
                    rss.volume(),
                    rss.center,
                    rss.size(),
                    &(|p| rss.contains_point(p)) as &dyn Fn(DVec3) -> bool,
                ),
                (lss.volume(), lss.center(), lss.size(), &|p| {
                    lss.contains_point(p)
                }),
            ] {
                let n = 200_000;
                let hits = (0..n)
                    .filter(|_| inside(center + point_in_cube(&mut rng, 0.5 * reach)))
                    .count();
                let estimate = hits as f64 / n as f64 * reach.powi(3);
                let sigma = reach.powi(3) * (hits as f64).sqrt() / n as f64;
                assert!(
                    (estimate - volume).abs() <= 4.0 * sigma + 1e-12,
                    "case {case}: {estimate} vs {volume}"
                );
            }
        }
    }

    #[test]
    fn degenerate_inputs_give_small_valid_volumes() {
        for center in CENTERS {
            let p = DVec3::new(center, -center, 0.3 * center);
            for points in [vec![p], vec![p; 7], vec![p, p + DVec3::X * 1e-4]] {
                let (lss, rss) = (Lss::fit_points(&points), Rss::fit_points(&points));
                for q in &points {
                    assert!(lss.contains_point(*q) && rss.contains_point(*q));
                }
                assert!(lss.size() <= 1e-4 + 1e-9 * (1.0 + center), "{lss:?}");
                assert!(rss.size() <= 2e-4 + 1e-9 * (1.0 + center), "{rss:?}");
                assert!(lss.stand_off() == lss.size() && rss.stand_off() == rss.size());
            }
        }
        // A zero-radius RSS of a flat set has zero volume.
        let flat = Rss::new(DVec3::ZERO, DMat3::IDENTITY, [1.0, 2.0], 0.0);
        assert_eq!(flat.volume(), 0.0);
    }
}
