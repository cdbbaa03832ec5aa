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
//!    product of the lengths are skipped (error bound in its docs). The test stops at the
//!    first axis the cores are apart on: apart, step 2 needs no more.
//! 2. **Disjoint cores**: the closest pair of two convex polytopes is realised by a vertex
//!    against the other polytope, or by interior points of two non-parallel edges; the
//!    segment between those is then perpendicular to both, so it lies along their cross
//!    product `u`, and the two edges are the support features of the cores along `±u`. The
//!    exact distance is therefore the minimum over every vertex against the other core
//!    (closest point in closed form) and, for every pair of edge directions, the support
//!    features along their cross product (when the cores are apart along it) — for two
//!    boxes 16 vertex clamps and at most 9 segment pairs instead of all 144 edge pairs.
//!    Against a triangle, vertices farther from its plane than the best pair are skipped.
//!    Rounded cores (a sphere's point, a capsule's segment) are mostly apart even when the
//!    shapes touch, so for them this step runs first, without step 1: its pair is kept
//!    when the cores are apart along the pair's own direction, which proves them disjoint.
//! 3. **Overlapping cores**: depth and normal from step 1; witnesses are the closest points
//!    of the two support features once B is moved out by the depth (they touch).
//! 4. **Radii**: the result is the core distance minus both radii, with the witnesses moved
//!    out along the normal; sweeping by a ball adds its radius to the penetration depth too,
//!    so every answer is exact (to rounding).

use super::placed_core::{AXIS_RELATIVE, Kind, PlacedCore, Polygon};
use crate::math::DVec3;
use crate::narrow::closest_points::closest_points_segment_segment;
#[cfg(doc)]
use crate::narrow::contact::DistanceBound;
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
pub(super) fn best_axis(a: &PlacedCore, b: &PlacedCore) -> Axis {
    best_axis_or_first_above(a, b, f64::INFINITY)
}

/// [`best_axis`], or the first axis found apart by more than `enough` metres (all that is
/// needed to know the cores are apart).
#[must_use]
pub(super) fn best_axis_or_first_above(a: &PlacedCore, b: &PlacedCore, enough: f64) -> Axis {
    let mut best = Axis {
        normal: DVec3::X,
        separation: f64::NEG_INFINITY,
    };
    // Offers axis `u`; true when the best is then apart by more than `enough`.
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
        best.separation > enough
    };
    for f in a.faces[..a.nf].iter().chain(&b.faces[..b.nf]) {
        if try_axis(*f) {
            return best;
        }
    }
    let crossed = |d: DVec3, e: DVec3| {
        let c = d.cross(e);
        (c.length() > AXIS_RELATIVE).then(|| c.normalize())
    };
    for d in &a.dirs[..a.nd] {
        for e in &b.dirs[..b.nd] {
            if let Some(u) = crossed(*d, *e)
                && try_axis(u)
            {
                return best;
            }
        }
    }
    let solid =
        |c: &PlacedCore| matches!(c.kind, Kind::Box { half, .. } if half.min_element() > 0.0);
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
            if try_axis(fixed) {
                return best;
            }
        }
        for m in &planes[..np] {
            for d in dirs.clone() {
                if let Some(u) = crossed(*m, *d)
                    && try_axis(u)
                {
                    return best;
                }
            }
        }
    }
    best
}

/// Rounding allowance of the separating-axis distance bounds ([`DistanceBound`]), in ulps
/// of the pair's coordinate scale (as the pipeline's error bound of exact answers).
pub(super) const BOUND_ULPS: f64 = 64.0;

/// The closest of the point pairs offered so far.
struct BestPair {
    distance_squared: f64,
    on_a: DVec3,
    on_b: DVec3,
}

impl Default for BestPair {
    fn default() -> Self {
        Self {
            distance_squared: f64::INFINITY,
            on_a: DVec3::ZERO,
            on_b: DVec3::ZERO,
        }
    }
}

impl BestPair {
    /// Keeps `(on_a, on_b)` when it is closer than the best so far.
    fn offer(&mut self, on_a: DVec3, on_b: DVec3) {
        let d = on_a.distance_squared(on_b);
        if d < self.distance_squared {
            *self = Self {
                distance_squared: d,
                on_a,
                on_b,
            };
        }
    }
}

/// The closest pair `(on_a, on_b)` of two convex polytopes: the best of every vertex
/// against the other polytope and every edge pair (module docs, step 2).
#[must_use]
pub(super) fn closest_pair(a: &Polygon, b: &Polygon) -> (DVec3, DVec3) {
    let mut best = BestPair::default();
    for v in a.points() {
        best.offer(*v, b.closest_point(*v));
    }
    for v in b.points() {
        best.offer(a.closest_point(*v), *v);
    }
    for (p, q) in a.edges() {
        let (mid_a, half_a) = ((p + q) * 0.5, 0.5 * p.distance(q));
        for (r, s) in b.edges() {
            // PERF: an edge pair whose bounding spheres are already farther apart than the
            // best pair so far cannot improve it (exact pruning; the vertex pairs above give
            // a tight bound first).
            let (mid_b, half_b) = ((r + s) * 0.5, 0.5 * r.distance(s));
            let bound = mid_a.distance(mid_b) - half_a - half_b;
            if bound > 0.0 && bound * bound > best.distance_squared {
                continue;
            }
            let (pa, pb) = closest_points_segment_segment(p, q, r, s);
            best.offer(pa, pb);
        }
    }
    (best.on_a, best.on_b)
}

/// The closest pair `(on_a, on_b)` of two disjoint cores (module docs, step 2); `tiny`
/// (metres) is the tolerance of the support features.
#[must_use]
fn closest_pair_disjoint(a: &PlacedCore, b: &PlacedCore, tiny: f64) -> (DVec3, DVec3) {
    let mut best = BestPair::default();
    offer_vertices(a, b, &mut best, false);
    offer_vertices(b, a, &mut best, true);
    for d in &a.dirs[..a.nd] {
        for e in &b.dirs[..b.nd] {
            let c = d.cross(*e);
            if c.length() <= AXIS_RELATIVE {
                // Parallel edges: a closest pair of them has a vertex, offered above.
                continue;
            }
            let u = c.normalize();
            let (lo_a, hi_a) = a.project(u);
            let (lo_b, hi_b) = b.project(u);
            // Oriented A → B; an edge pair realising the distance `δ > 0` is apart by `δ`
            // along it, and no pair of points is closer than the separation (exact pruning).
            let (u, separation) = if lo_b - hi_a >= lo_a - hi_b {
                (u, lo_b - hi_a)
            } else {
                (-u, lo_a - hi_b)
            };
            if separation <= 0.0 || separation * separation >= best.distance_squared {
                continue;
            }
            let (fa, fb) = (a.support_feature(u, tiny), b.support_feature(-u, tiny));
            if fa.len < 2 || fb.len < 2 {
                // A vertex is a support feature: its pair was offered above.
                continue;
            }
            let (pa, pb) = if fa.len == 2 && fb.len == 2 {
                closest_points_segment_segment(fa.pts[0], fa.pts[1], fb.pts[0], fb.pts[1])
            } else {
                closest_pair(&fa, &fb)
            };
            best.offer(pa, pb);
        }
    }
    (best.on_a, best.on_b)
}

/// Offers every vertex of `from` with its closest point on `to` (`swapped`: `from` is B).
/// A vertex farther from a triangle's plane than the best pair so far is skipped (its
/// distance to the triangle is at least that: exact pruning), nearest to the plane first.
fn offer_vertices(from: &PlacedCore, to: &PlacedCore, best: &mut BestPair, swapped: bool) {
    let offer = |best: &mut BestPair, v: DVec3| {
        let q = to.closest_point(v);
        if swapped {
            best.offer(q, v);
        } else {
            best.offer(v, q);
        }
    };
    let vertices = from.vertices();
    if !(matches!(to.kind, Kind::Triangle) && to.nf == 1 && vertices.len() > 2) {
        vertices.iter().for_each(|v| offer(best, *v));
        return;
    }
    // PERF: a box's far corners against a mesh triangle (the convex–mesh walk's hot case).
    let (n, origin) = (to.faces[0], to.verts[0]);
    let mut order = [(0.0, 0usize); 8];
    for (i, v) in vertices.iter().enumerate() {
        order[i] = (n.dot(*v - origin).abs(), i);
    }
    let order = &mut order[..vertices.len()];
    order.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    for &(plane_gap, i) in order.iter() {
        if plane_gap * plane_gap >= best.distance_squared {
            break;
        }
        offer(best, vertices[i]);
    }
}

/// The signed distance between two placed cores, A's frame (module docs).
#[must_use]
pub(super) fn distance(a: &PlacedCore, b: &PlacedCore) -> ShapeDistance {
    if a.radius + b.radius > 0.0
        && let Some(d) = apart_certified(a, b)
    {
        return d;
    }
    // Apart along any axis is enough for the closest pair; overlapping needs the best.
    distance_with_axis(a, b, &best_axis_or_first_above(a, b, 0.0))
}

/// The answer for cores proven apart without the separating-axis test: the closest pair
/// the cores would have if they were disjoint, kept when the separation along its own
/// direction is positive (which proves they are: overlapping cores have no separating
/// direction, and then the closest pair of [`closest_pair_disjoint`] is exact). `None`
/// when that proof fails. Rounded shapes in contact mostly have apart cores (they touch
/// through their radii), so this skips the test for them.
fn apart_certified(a: &PlacedCore, b: &PlacedCore) -> Option<ShapeDistance> {
    let tiny = FEATURE_RELATIVE * a.scale().max(b.scale());
    let (on_a, on_b) = closest_pair_disjoint(a, b, tiny);
    let gap = on_a.distance(on_b);
    if gap <= tiny {
        return None;
    }
    let n = (on_b - on_a) / gap;
    let separation = b.project(n).0 - a.project(n).1;
    (separation > 0.0).then(|| {
        let axis = Axis {
            normal: n,
            separation,
        };
        apart(a.radius, b.radius, on_a, on_b, &axis, tiny)
    })
}

/// [`distance`] given the cores' best separating axis (from [`best_axis`], or from a
/// pair's own faster test over the same axis set).
#[must_use]
pub(super) fn distance_with_axis(a: &PlacedCore, b: &PlacedCore, axis: &Axis) -> ShapeDistance {
    let tiny = FEATURE_RELATIVE * a.scale().max(b.scale());
    if axis.separation > 0.0 {
        let (on_a, on_b) = closest_pair_disjoint(a, b, tiny);
        apart(a.radius, b.radius, on_a, on_b, axis, tiny)
    } else {
        let depth = -axis.separation;
        let n = axis.normal;
        let shift = n * depth;
        let mut fb = b.support_feature(-n, tiny);
        for p in &mut fb.pts[..fb.len] {
            *p += shift;
        }
        let fa = a.support_feature(n, tiny);
        let (on_a, on_b) = if fa.len == 2 && fb.len == 2 {
            // PERF: edge against edge, the common overlapping case: one segment pair.
            closest_points_segment_segment(fa.pts[0], fa.pts[1], fb.pts[0], fb.pts[1])
        } else {
            closest_pair(&fa, &fb)
        };
        rounded(a.radius, b.radius, -depth, on_a, on_b - shift, n)
    }
}

/// The answer for cores apart, from their closest pair: the normal is the pair's direction,
/// or the separating axis when the gap is under `tiny` metres (rounding-sized: its direction
/// is noise).
#[must_use]
pub(super) fn apart(
    radius_a: f64,
    radius_b: f64,
    on_a: DVec3,
    on_b: DVec3,
    axis: &Axis,
    tiny: f64,
) -> ShapeDistance {
    let gap = on_a.distance(on_b);
    let normal = if gap > tiny {
        (on_b - on_a) / gap
    } else {
        axis.normal
    };
    rounded(radius_a, radius_b, gap, on_a, on_b, normal)
}

/// The cores' signed distance and witnesses turned into the shapes' (module docs, step 4).
fn rounded(
    radius_a: f64,
    radius_b: f64,
    core_distance: f64,
    on_a: DVec3,
    on_b: DVec3,
    normal: DVec3,
) -> ShapeDistance {
    ShapeDistance {
        distance: core_distance - radius_a - radius_b,
        point_a: on_a + normal * radius_a,
        point_b: on_b - normal * radius_b,
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
        let a = PlacedCore::sphere(
            &Sphere::new(0.0),
            &Isometry::from_translation(DVec3::new(2.0, 2.0, 0.0)),
        );
        let b = PlacedCore::triangle(&t, &Isometry::IDENTITY);
        assert!(best_axis(&a, &b).separation > 0.5);
        let d = distance(&a, &b);
        assert!((d.distance - 1.5 * 2f64.sqrt()).abs() < 1e-15, "{d:?}");
    }

    #[test]
    fn coplanar_disjoint_segments_are_apart() {
        let c = Capsule::new(1.0, 0.0);
        let a = PlacedCore::capsule(&c, &Isometry::IDENTITY);
        let pose = Isometry::new(
            crate::math::DMat3::from_rotation_y(1.0),
            DVec3::new(3.0, 0.0, 0.0),
        );
        let b = PlacedCore::capsule(&c, &pose);
        assert!(best_axis(&a, &b).separation > 0.0);
        assert!(distance(&a, &b).distance > 1.0);
    }
}
