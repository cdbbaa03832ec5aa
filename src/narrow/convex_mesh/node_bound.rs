//! The convex shape of a convex–mesh walk, placed once in the mesh's frame, and its lower
//! bound on the distance to each node of the mesh's RSS tree.
//!
//! # Why not the shape's own RSS
//! Measured against a node as one RSS against another, a node cost a relative placement and
//! a rectangle–rectangle search (16 edge pairs), and a box became a rectangle swept by its
//! smallest half extent: past each edge it reaches out by that much (a cube's RSS is about
//! three times its volume). The node bounds were then the largest share of a falling-bodies
//! frame (`examples/falling_bodies.rs`).
//!
//! # The bound
//! A ball is its centre, a capsule its segment, a box the box itself, each placed in the
//! mesh's frame once per walk. For a node (rectangle `c + R·(x, y, 0)`, `|x| ≤ l₀`,
//! `|y| ≤ l₁`, swept by `r`) and any unit axis `u`, the gap between their projections,
//!
//! `|u·(p − c)| − w_shape(u) − (l₀|u·R₀| + l₁|u·R₁| + r)`,
//!
//! with `p` the shape's centre and `w_shape(u)` its half width along `u` (both centrally
//! symmetric), is a lower bound on their distance for *every* `u`: the bound stays valid
//! however the axis was chosen, and only its tightness depends on the choice. The axes
//! tried:
//! - the direction between a closest pair of the node's rectangle and the shape's core
//!   found by alternating projections (a clamp onto each in turn, twice). For a ball the
//!   clamp is exact and so is the bound;
//! - the rectangle's normal, and for a box the rectangle's in-plane axes and the box's
//!   three axes (the face axes of a separating-axis test).
//!
//! The largest gap, less a rounding slack for the magnitudes involved, clamped at 0, is the
//! bound. Other convex shapes keep their fitted RSS, placed once.

use crate::bounding::{BoundingVolume, Rss};
use crate::math::{DMat3, DVec3, Isometry, conservative_slack};
use crate::narrow::Shape;

/// A convex shape placed in the mesh's frame for the walk's node bounds.
#[derive(Debug, Clone, Copy)]
pub(crate) enum PlacedShape {
    /// A ball: centre and radius, metres.
    Ball { center: DVec3, radius: f64 },
    /// A capsule: the centre and half vector of its segment, and its radius, metres.
    Capsule {
        center: DVec3,
        half: DVec3,
        radius: f64,
    },
    /// A box: centre, axes (columns) and half extents along them, metres.
    Box {
        center: DVec3,
        axes: DMat3,
        half_extents: DVec3,
    },
    /// Any other convex shape: the RSS fitted to the corners of its local box, in the mesh's
    /// frame.
    Fitted(Rss),
}

impl PlacedShape {
    /// `shape` (centred on its own frame A) placed in the mesh's frame B by `iso_ba`.
    pub(crate) fn new(shape: &Shape, iso_ba: &Isometry) -> Self {
        let center = iso_ba.translation;
        match shape {
            Shape::Sphere(s) => Self::Ball {
                center,
                radius: s.radius,
            },
            Shape::Capsule(c) => Self::Capsule {
                center,
                half: iso_ba.rotation.z_axis * c.half_height,
                radius: c.radius,
            },
            Shape::Cuboid(b) => Self::Box {
                center,
                axes: iso_ba.rotation,
                half_extents: b.half_extents,
            },
            Shape::Cylinder(_)
            | Shape::Cone(_)
            | Shape::Convex(_)
            | Shape::Mesh(_)
            | Shape::Compound(_) => {
                Self::Fitted(Rss::fit_points(&shape.local_bounds().corners()).transformed(iso_ba))
            }
        }
    }

    /// A lower bound on the distance between the shape and anything inside `node` (the
    /// mesh's frame), metres; 0 when they may touch.
    #[inline]
    pub(crate) fn lower_bound(&self, node: &Rss) -> f64 {
        match *self {
            Self::Ball { center, radius } => {
                // PERF: the same clamp and certificate as the point case of
                // `ssv::rectangle_distance`, inline here: calling that took sphere–torus256
                // (`benches/convex_mesh.rs`) from 3.44 to 4.11–4.16 µs (alternating runs).
                let q = to_node(node, center);
                let gap = node_gap(node, q - rectangle_point(node, q), q, radius);
                (gap - slack(node, center, radius)).max(0.0)
            }
            Self::Capsule {
                center,
                half,
                radius,
            } => {
                let q = to_node(node, center);
                let h = node.axes.transpose() * half;
                let width = |u: DVec3| u.dot(h).abs() + radius;
                let on_segment = |target: DVec3| {
                    let length_squared = h.length_squared();
                    let t = if length_squared > 0.0 {
                        ((target - q).dot(h) / length_squared).clamp(-1.0, 1.0)
                    } else {
                        0.0
                    };
                    q + h * t
                };
                let mut x = on_segment(DVec3::ZERO);
                let mut y = rectangle_point(node, x);
                x = on_segment(y);
                y = rectangle_point(node, x);
                let gap = node_gap_with(node, x - y, q, width).max(normal_gap(node, q, width));
                (gap - slack(node, center, half.length() + radius)).max(0.0)
            }
            Self::Box {
                center,
                axes,
                half_extents: e,
            } => {
                let q = to_node(node, center);
                // The box's axes in the node's frame.
                let m = node.axes.transpose() * axes;
                let width = |u: DVec3| {
                    e.x * u.dot(m.x_axis).abs()
                        + e.y * u.dot(m.y_axis).abs()
                        + e.z * u.dot(m.z_axis).abs()
                };
                let on_box = |target: DVec3| {
                    let local = m.transpose() * (target - q);
                    q + m * local.clamp(-e, e)
                };
                let mut x = on_box(DVec3::ZERO);
                let mut y = rectangle_point(node, x);
                x = on_box(y);
                y = rectangle_point(node, x);
                // The face axes are unit vectors (the box's to rounding, which the slack
                // covers): their gaps need no normalising. The box's half widths along the
                // node's axes, and the rectangle's along the box's.
                let [l0, l1] = node.half_lengths;
                let abs = [m.x_axis.abs(), m.y_axis.abs(), m.z_axis.abs()];
                let box_width = abs[0] * e.x + abs[1] * e.y + abs[2] * e.z;
                let by_node_axes = (q.x.abs() - l0 - box_width.x)
                    .max(q.y.abs() - l1 - box_width.y)
                    .max(q.z.abs() - box_width.z);
                let by_box_axes = (q.dot(m.x_axis).abs() - e.x - l0 * abs[0].x - l1 * abs[0].y)
                    .max(q.dot(m.y_axis).abs() - e.y - l0 * abs[1].x - l1 * abs[1].y)
                    .max(q.dot(m.z_axis).abs() - e.z - l0 * abs[2].x - l1 * abs[2].y);
                let gap = node_gap_with(node, x - y, q, width)
                    .max(by_node_axes.max(by_box_axes) - node.radius);
                (gap - slack(node, center, e.element_sum())).max(0.0)
            }
            Self::Fitted(ref rss) => node.distance_lower_bound(rss, &Isometry::IDENTITY),
        }
    }
}

/// `point` (the mesh's frame) in the node's rectangle frame.
#[inline(always)]
fn to_node(node: &Rss, point: DVec3) -> DVec3 {
    node.axes.transpose() * (point - node.center)
}

/// The point of the node's rectangle nearest `q` (the rectangle's frame).
#[inline(always)]
fn rectangle_point(node: &Rss, q: DVec3) -> DVec3 {
    let [l0, l1] = node.half_lengths;
    DVec3::new(q.x.clamp(-l0, l0), q.y.clamp(-l1, l1), 0.0)
}

/// The gap along `direction` (the rectangle's frame, any length; 0 when zero) between the
/// node and a ball of `radius` at `q`.
#[inline(always)]
fn node_gap(node: &Rss, direction: DVec3, q: DVec3, radius: f64) -> f64 {
    node_gap_with(node, direction, q, |_| radius)
}

/// The gap along `direction` (the rectangle's frame, any length) between the node and a
/// centrally symmetric shape centred at `q` whose half width along a unit axis is
/// `width(axis)`; 0 when the direction is zero (the shape and the rectangle meet).
#[inline(always)]
fn node_gap_with(node: &Rss, direction: DVec3, q: DVec3, width: impl Fn(DVec3) -> f64) -> f64 {
    let Some(u) = direction.try_normalize() else {
        return 0.0;
    };
    let [l0, l1] = node.half_lengths;
    u.dot(q).abs() - l0 * u.x.abs() - l1 * u.y.abs() - node.radius - width(u)
}

/// The gap along the rectangle's normal.
#[inline(always)]
fn normal_gap(node: &Rss, q: DVec3, width: impl Fn(DVec3) -> f64) -> f64 {
    q.z.abs() - node.radius - width(DVec3::Z)
}

/// Rounding slack for a node and a shape centred at `center` reaching `reach` from it.
#[inline(always)]
fn slack(node: &Rss, center: DVec3, reach: f64) -> f64 {
    let [l0, l1] = node.half_lengths;
    conservative_slack(
        node.center.abs().max_element()
            + center.abs().max_element()
            + l0
            + l1
            + node.radius
            + reach,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Triangle;
    use crate::math::Pose;
    use crate::narrow::convex_mesh::shape_triangle_distance;
    use crate::narrow::gjk::EpaWorkspace;
    use crate::test_support::{TestRng, point_in_cube, random_convex, rng, rotation};
    use rand::Rng;

    /// A node as the tree builds one: an RSS fitted around one to four random triangles,
    /// flat, long or fat.
    fn random_node(rng: &mut TestRng) -> (Rss, Vec<Triangle>) {
        let center = point_in_cube(rng, 1.0);
        let spread = DVec3::new(
            rng.random_range(0.0..0.6),
            rng.random_range(0.0..0.6),
            rng.random_range(0.0..0.6) * rng.random_range(0.0..1.0),
        );
        let turn = rotation(rng);
        let count = rng.random_range(1..5);
        let mut corner = || center + turn * (point_in_cube(rng, 1.0) * spread);
        let triangles: Vec<Triangle> = (0..count)
            .map(|_| Triangle::new(corner(), corner(), corner()))
            .collect();
        (Rss::fit_triangles(&triangles), triangles)
    }

    /// Over random shapes (every convex kind), poses and nodes, the bound never exceeds the
    /// shape's distance to any triangle inside the node (the per-triangle closed forms or
    /// GJK/EPA, clamped at 0 like the bound). Both pruning (a positive bound) and touching
    /// nodes occur, and for balls the bound is the fitted RSS's exact distance.
    #[test]
    fn the_bound_never_exceeds_the_distance_to_the_nodes_triangles() {
        let mut rng = rng(4242);
        let mut epa = EpaWorkspace::default();
        let (mut pruning, mut touching) = (0, 0);
        for case in 0..20_000 {
            let shape = random_convex(&mut rng, 0.4, 6);
            let (node, triangles) = random_node(&mut rng);
            // The shape's frame A placed in the mesh's frame B, near the node.
            let at = node.center + point_in_cube(&mut rng, 0.6);
            let pose_ba = Pose::new(at, rotation(&mut rng));
            let iso_ba = pose_ba.to_isometry();
            let placed = PlacedShape::new(&shape, &iso_ba);
            let bound = placed.lower_bound(&node);
            let iso_ab = iso_ba.inverse();
            let nearest = triangles
                .iter()
                .map(|t| shape_triangle_distance(&shape, &t.transformed(&iso_ab), &mut epa))
                .map(|d| d.distance.max(0.0))
                .fold(f64::INFINITY, f64::min);
            assert!(
                bound <= nearest + 1e-12,
                "case {case}: {shape:?} bound {bound} above the nearest triangle's {nearest}"
            );
            if let Shape::Sphere(s) = shape {
                let ball = Rss::new(DVec3::ZERO, DMat3::IDENTITY, [0.0, 0.0], s.radius);
                let exact = node.distance_lower_bound(&ball, &iso_ba);
                assert!(
                    (bound - exact).abs() <= 1e-9,
                    "case {case}: {bound} vs {exact}"
                );
            }
            if bound > 0.0 {
                pruning += 1;
            } else if nearest == 0.0 {
                touching += 1;
            }
        }
        assert!(
            pruning > 5_000 && touching > 1_000,
            "{pruning} / {touching}"
        );
    }
}
