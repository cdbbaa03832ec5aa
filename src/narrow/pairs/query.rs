//! Signed distance between two placed cores (see [`super::core`]), the engine behind every
//! `distance_*` function of this module.
//!
//! # Algorithm
//! 1. **Separating axes** on the polytope cores: the face normals of both, the cross
//!    products of their edge directions, and — for pairs without a box, whose Minkowski
//!    difference may be flat (no box of non-zero volume) — the fixed axes and every plane candidate (triangle normal,
//!    edge cross product, fixed axis) crossed with every edge direction. For two
//!    convex polytopes (degenerate ones included) every face normal of their Minkowski
//!    difference is in this set, so the largest separation over it is positive iff the
//!    cores are disjoint, and when they overlap minus it is their exact penetration depth
//!    (Gottschalk, Lin, Manocha, *OBBTree*, SIGGRAPH 1996; Ericson, *Real-Time Collision
//!    Detection*, §4.4 and §5.2.1). Cross products shorter than [`AXIS_RELATIVE`] times the
//!    product of the lengths are skipped (error bound in its docs).
//! 2. **Disjoint cores**: the exact distance is the minimum over vertex–closest-point and
//!    edge–edge pairs (the closest pair of two convex polytopes is realised by a vertex
//!    against the other polytope or by two edges), every one in closed form.
//! 3. **Overlapping cores**: depth and normal from step 1; witnesses are the closest points
//!    of the two support features once B is moved out by the depth (they touch).
//! 4. **Radii**: the result is the core distance minus both radii, with the witnesses moved
//!    out along the normal; sweeping by a ball adds its radius to the penetration depth too,
//!    so every answer is exact (to rounding).

use super::core::{AXIS_RELATIVE, Core, Kind, Polygon};
use crate::math::DVec3;
use crate::narrow::closest_points::closest_points_segment_segment;
use crate::narrow::contact::ShapeDistance;

/// Relative size (times the coordinate scale) under which a core gap is treated as zero
/// for choosing a normal, and within which vertices count as one support feature.
pub(super) const FEATURE_RELATIVE: f64 = 1e-10;

/// The best separating axis: oriented from A to B, with its separation (negative: overlap).
#[derive(Debug, Clone, Copy)]
pub(super) struct Axis {
    pub normal: DVec3,
    pub separation: f64,
}

/// The separating-axis test over the complete candidate set (module docs, step 1).
#[must_use]
pub(super) fn best_axis(a: &Core, b: &Core) -> Axis {
    let mut best = Axis {
        normal: DVec3::X,
        separation: f64::NEG_INFINITY,
    };
    let mut try_axis = |u: DVec3| {
        let (lo_a, hi_a) = a.project(u);
        let (lo_b, hi_b) = b.project(u);
        let (plus, minus) = (lo_b - hi_a, lo_a - hi_b);
        let (normal, separation) = if plus >= minus {
            (u, plus)
        } else {
            (-u, minus)
        };
        if separation > best.separation {
            best = Axis { normal, separation };
        }
    };
    for f in a.faces[..a.nf].iter().chain(&b.faces[..b.nf]) {
        try_axis(*f);
    }
    let crossed = |d: DVec3, e: DVec3| {
        let c = d.cross(e);
        (c.length() > AXIS_RELATIVE).then(|| c.normalize())
    };
    for d in &a.dirs[..a.nd] {
        for e in &b.dirs[..b.nd] {
            if let Some(u) = crossed(*d, *e) {
                try_axis(u);
            }
        }
    }
    let solid = |c: &Core| matches!(c.kind, Kind::Box { half, .. } if half.min_element() > 0.0);
    if !solid(a) && !solid(b) {
        // Without a solid box, the Minkowski difference can be flat (a triangle with a point or a
        // coplanar segment, two segments): its sides then have the normals `m × d` for its
        // plane normal `m` (a triangle normal or an edge cross product) and an edge
        // direction `d`. With no plane candidate at all (points, collinear segments) the
        // fixed axes stand in for `m`.
        let dirs = a.dirs[..a.nd].iter().chain(&b.dirs[..b.nd]);
        let mut planes = [DVec3::ZERO; 24];
        let mut np = 0;
        for f in a.faces[..a.nf].iter().chain(&b.faces[..b.nf]) {
            planes[np] = *f;
            np += 1;
        }
        for d in &a.dirs[..a.nd] {
            for e in &b.dirs[..b.nd] {
                if let Some(u) = crossed(*d, *e) {
                    planes[np] = u;
                    np += 1;
                }
            }
        }
        for fixed in [DVec3::X, DVec3::Y, DVec3::Z] {
            planes[np] = fixed;
            np += 1;
            try_axis(fixed);
        }
        for m in &planes[..np] {
            for d in dirs.clone() {
                if let Some(u) = crossed(*m, *d) {
                    try_axis(u);
                }
            }
        }
    }
    best
}

/// What [`closest_pair`] needs of a convex polytope: vertices, edges, closest point.
pub(super) trait Features {
    fn feature_vertices(&self) -> &[DVec3];
    fn feature_edges(&self) -> impl Iterator<Item = (DVec3, DVec3)>;
    fn feature_closest(&self, p: DVec3) -> DVec3;
}

impl Features for Core {
    fn feature_vertices(&self) -> &[DVec3] {
        self.vertices()
    }
    fn feature_edges(&self) -> impl Iterator<Item = (DVec3, DVec3)> {
        self.edges()
    }
    fn feature_closest(&self, p: DVec3) -> DVec3 {
        self.closest_point(p)
    }
}

impl Features for Polygon {
    fn feature_vertices(&self) -> &[DVec3] {
        self.points()
    }
    fn feature_edges(&self) -> impl Iterator<Item = (DVec3, DVec3)> {
        self.edges()
    }
    fn feature_closest(&self, p: DVec3) -> DVec3 {
        self.closest_point(p)
    }
}

/// The closest pair `(on_a, on_b)` of two convex polytopes: the best of every vertex
/// against the other polytope and every edge pair (module docs, step 2).
#[must_use]
pub(super) fn closest_pair(a: &impl Features, b: &impl Features) -> (DVec3, DVec3) {
    let mut best = (f64::INFINITY, DVec3::ZERO, DVec3::ZERO);
    let offer = |best: &mut (f64, DVec3, DVec3), pa: DVec3, pb: DVec3| {
        let d = pa.distance_squared(pb);
        if d < best.0 {
            *best = (d, pa, pb);
        }
    };
    for v in a.feature_vertices() {
        offer(&mut best, *v, b.feature_closest(*v));
    }
    for v in b.feature_vertices() {
        offer(&mut best, a.feature_closest(*v), *v);
    }
    for (p, q) in a.feature_edges() {
        let (mid_a, half_a) = ((p + q) * 0.5, 0.5 * p.distance(q));
        for (r, s) in b.feature_edges() {
            // PERF: an edge pair whose bounding spheres are already farther apart than the
            // best pair so far cannot improve it (exact pruning; the vertex pairs above give
            // a tight bound first).
            let (mid_b, half_b) = ((r + s) * 0.5, 0.5 * r.distance(s));
            let bound = mid_a.distance(mid_b) - half_a - half_b;
            if bound > 0.0 && bound * bound > best.0 {
                continue;
            }
            let (pa, pb) = closest_points_segment_segment(p, q, r, s);
            offer(&mut best, pa, pb);
        }
    }
    (best.1, best.2)
}

/// The signed distance between two placed cores, A's frame (module docs).
#[must_use]
pub(super) fn distance(a: &Core, b: &Core) -> ShapeDistance {
    let scale = a.scale().max(b.scale());
    let tiny = FEATURE_RELATIVE * scale;
    let axis = best_axis(a, b);
    let (core_distance, on_a, on_b, normal) = if axis.separation > 0.0 {
        let (on_a, on_b) = closest_pair(a, b);
        let gap = on_a.distance(on_b);
        let normal = if gap > tiny {
            (on_b - on_a) / gap
        } else {
            axis.normal
        };
        (gap, on_a, on_b, normal)
    } else {
        let depth = -axis.separation;
        let n = axis.normal;
        let shift = n * depth;
        let mut fb = b.support_feature(-n, tiny);
        for p in &mut fb.pts[..fb.len] {
            *p += shift;
        }
        let (on_a, on_b) = closest_pair(&a.support_feature(n, tiny), &fb);
        (-depth, on_a, on_b - shift, n)
    };
    ShapeDistance {
        distance: core_distance - a.radius - b.radius,
        point_a: on_a + normal * a.radius,
        point_b: on_b - normal * b.radius,
        normal,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Capsule, Sphere, Triangle};
    use crate::math::Isometry;

    #[test]
    fn a_point_beside_a_coplanar_triangle_is_separated_by_an_in_plane_axis() {
        // The Minkowski difference is flat here: the triangle normal alone shows overlap 0.
        let t = Triangle::new(DVec3::ZERO, DVec3::X, DVec3::Y);
        let a = Core::sphere(
            &Sphere::new(0.0),
            &Isometry::from_translation(DVec3::new(2.0, 2.0, 0.0)),
        );
        let b = Core::triangle(&t, &Isometry::IDENTITY);
        assert!(best_axis(&a, &b).separation > 0.5);
        let d = distance(&a, &b);
        assert!((d.distance - 1.5 * 2f64.sqrt()).abs() < 1e-15, "{d:?}");
    }

    #[test]
    fn coplanar_disjoint_segments_are_apart() {
        let c = Capsule::new(1.0, 0.0);
        let a = Core::capsule(&c, &Isometry::IDENTITY);
        let pose = Isometry::new(
            crate::math::DMat3::from_rotation_y(1.0),
            DVec3::new(3.0, 0.0, 0.0),
        );
        let b = Core::capsule(&c, &pose);
        assert!(best_axis(&a, &b).separation > 0.0);
        assert!(distance(&a, &b).distance > 1.0);
    }
}
