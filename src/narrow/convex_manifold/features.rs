//! Contact features of the convex shapes: the face, line or point of a shape that faces a
//! direction, as a small fixed-capacity polygon in the shape's local frame.
//!
//! Curved faces are discretised: a cylinder's caps and a cone's base are regular polygons
//! of [`DISC_POINTS`] vertices *inscribed* in their circle, so every vertex and every point
//! of every edge lies on the real (flat) cap; the polygon misses the circle's segments
//! between vertices (about 2.5 % of the disc's area for 16 points). As an incident feature
//! the polygon is turned so that one vertex is the rim point farthest along the direction,
//! which is the shape's support point there: the deepest point of a tilted cap is then
//! always a vertex, and reported depths are exact rim depths, never the polygon's.

use crate::geometry::{Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, Sphere, SupportMap};
use crate::math::DVec3;

/// The most vertices of a face used as a contact feature; a hull face with more is not
/// used (its shape then contributes its support point only).
pub const FEATURE_POINTS: usize = 64;

/// Vertices of the regular polygon that stands for a cylinder's cap or a cone's base.
pub const DISC_POINTS: usize = 16;

/// Capacity of a [`Polygon`]: a convex polygon of `k` vertices clipped by the `m` side
/// planes of a convex face keeps at most `k + m` vertices.
const POLYGON_CAPACITY: usize = 2 * FEATURE_POINTS;

/// A point, segment or convex polygon of at most [`FEATURE_POINTS`] + [`FEATURE_POINTS`]
/// vertices (room for clipping), in order around its outline. Never allocates.
pub type Polygon = crate::narrow::polygon::Polygon<POLYGON_CAPACITY>;

/// What a convex shape shows another shape it touches: a core (its points, local frame)
/// swept by a ball of [`core_radius`](Self::core_radius).
///
/// # Contract
/// Directions are unit vectors in the shape's local frame. Every point written lies on the
/// core's surface (on the shape's surface when the radius is 0).
pub trait ContactFeatures {
    /// Radius swept around the core, metres (a sphere's or capsule's; 0 for the rest).
    #[must_use]
    fn core_radius(&self) -> f64 {
        0.0
    }

    /// The point of the shape's surface on the ray from `core_point` (a point of the
    /// core's feature) along unit `v` where the ray leaves the shape (local frame): the
    /// core point itself for radius 0, moved out by the radius for a sphere, the exact
    /// exit from a capsule whose segment is not ⟂ `v`.
    #[must_use]
    fn surface_along(&self, core_point: DVec3, v: DVec3) -> DVec3 {
        core_point + v * self.core_radius()
    }

    /// The largest `s` (metres) with `p + s·v` in the shape (`p` a point and `v` a unit
    /// vector, local frame): where the line through `p` along `v` leaves the shape, for
    /// the shapes whose contact feature can be a line (cylinder, capsule); `None` when the
    /// line misses the shape or the shape does not answer (the default).
    #[must_use]
    fn column_top(&self, _p: DVec3, _v: DVec3) -> Option<f64> {
        None
    }

    /// Whether [`column_top`](Self::column_top) answers (cylinders and capsules).
    #[must_use]
    fn has_columns(&self) -> bool {
        false
    }

    /// The flat face of the core whose outward unit normal is closest to `n`: its outline
    /// (counter-clockwise seen from outside) into `out` and its normal; `None` (and `out`
    /// empty) when the shape has no face of positive area with at most [`FEATURE_POINTS`]
    /// vertices (spheres, capsules, degenerate sizes).
    fn face_towards(&self, n: DVec3, out: &mut Polygon) -> Option<DVec3>;

    /// The feature of the core that `v` points out of, into `out`: the face, line or point
    /// whose outward normal is closest to `v` (for a polytope its best face; for a cylinder
    /// a cap or the side line through the support point; for a cone its base or the slant
    /// line through the support point; a capsule's segment; a sphere's centre). It always
    /// contains a support point of the core along `v`.
    fn feature_towards(&self, v: DVec3, out: &mut Polygon);
}

/// The unit radial direction of `v` about local Z, or `+X` when `v` is along the axis.
fn radial(v: DVec3) -> DVec3 {
    DVec3::new(v.x, v.y, 0.0)
        .try_normalize()
        .unwrap_or(DVec3::X)
}

/// How far past a cylinder's end (times its size and the point's coordinates) a column's
/// exit through the side still counts as on the side: rounding of the rim.
const RIM_RELATIVE: f64 = 1e-12;

/// An interval of line parameters; `(−∞, ∞)` for all of them.
type Interval = (f64, f64);

/// The parameters `s` with `p + s·v` within `radius` of the Z axis; `None` when none.
fn radial_interval(p: DVec3, v: DVec3, radius: f64) -> Option<Interval> {
    let a = v.x * v.x + v.y * v.y;
    let half_b = p.x * v.x + p.y * v.y;
    let c = p.x * p.x + p.y * p.y - radius * radius;
    if a == 0.0 {
        return (c <= 0.0).then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let disc = half_b * half_b - a * c;
    if disc < 0.0 {
        return None;
    }
    let root = disc.sqrt();
    Some(((-half_b - root) / a, (-half_b + root) / a))
}

/// The parameters `s` with `|z + s·vz| ≤ half_height`; empty (`lo > hi`) when none.
fn slab_interval(z: f64, vz: f64, half_height: f64) -> Interval {
    if vz == 0.0 {
        return if z.abs() <= half_height {
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            (1.0, -1.0)
        };
    }
    let (s0, s1) = ((-half_height - z) / vz, (half_height - z) / vz);
    (s0.min(s1), s0.max(s1))
}

/// The parameters `s` with `p + s·v` (`v` unit) in the ball of `radius` about the origin.
fn ball_interval(p: DVec3, v: DVec3, radius: f64) -> Option<Interval> {
    let half_b = p.dot(v);
    let disc = half_b * half_b - (p.length_squared() - radius * radius);
    (disc >= 0.0).then(|| (-half_b - disc.sqrt(), -half_b + disc.sqrt()))
}

/// The intersection of two intervals; `None` when empty.
fn meet(x: Interval, y: Interval) -> Option<Interval> {
    let (lo, hi) = (x.0.max(y.0), x.1.min(y.1));
    (lo <= hi).then_some((lo, hi))
}

/// The regular [`DISC_POINTS`]-gon inscribed in the circle of `radius` about `(0, 0, z)`,
/// starting at `radius · u` (`u` unit, ⟂ Z), counter-clockwise seen from `up` (`±Z`).
fn disc(z: f64, radius: f64, u: DVec3, up: f64, out: &mut Polygon) {
    out.clear();
    let w = DVec3::Z.cross(u) * up;
    for (cos, sin) in DISC_COS_SIN {
        let p = (u * cos + w * sin) * radius;
        out.push(DVec3::new(p.x, p.y, z));
    }
}

/// `(cos, sin)` of the [`DISC_POINTS`] angles `τ k / DISC_POINTS`, as `f64::cos` and
/// `f64::sin` round them (checked by a test).
// PERF: a table instead of 16 `sin_cos` calls per cap (`benches/pile.rs`, cylinder pairs).
// NOTE: the values are libm's roundings, which differ from `FRAC_1_SQRT_2` by an ulp in
// places; the test compares them with `cos` and `sin`.
#[allow(
    clippy::unreadable_literal,
    clippy::excessive_precision,
    clippy::approx_constant
)]
const DISC_COS_SIN: [(f64, f64); DISC_POINTS] = [
    (1.0, 0.0),
    (0.9238795325112867, 0.3826834323650898),
    (0.7071067811865476, 0.7071067811865475),
    (0.38268343236508984, 0.9238795325112867),
    (6.123233995736766e-17, 1.0),
    (-0.3826834323650897, 0.9238795325112867),
    (-0.7071067811865475, 0.7071067811865476),
    (-0.9238795325112867, 0.3826834323650899),
    (-1.0, 1.2246467991473532e-16),
    (-0.9238795325112868, -0.38268343236508967),
    (-0.7071067811865477, -0.7071067811865475),
    (-0.38268343236509034, -0.9238795325112865),
    (-1.8369701987210297e-16, -1.0),
    (0.38268343236509, -0.9238795325112866),
    (0.7071067811865474, -0.7071067811865477),
    (0.9238795325112865, -0.3826834323650904),
];

impl ContactFeatures for Sphere {
    fn core_radius(&self) -> f64 {
        self.radius
    }

    fn face_towards(&self, _n: DVec3, out: &mut Polygon) -> Option<DVec3> {
        out.clear();
        None
    }

    fn feature_towards(&self, _v: DVec3, out: &mut Polygon) {
        out.clear();
        out.push(DVec3::ZERO);
    }
}

impl ContactFeatures for Capsule {
    fn core_radius(&self) -> f64 {
        self.radius
    }

    fn face_towards(&self, _n: DVec3, out: &mut Polygon) -> Option<DVec3> {
        out.clear();
        None
    }

    fn surface_along(&self, core_point: DVec3, v: DVec3) -> DVec3 {
        // The ray c + s v leaves the ball of radius r about the axis point c − λ Z at
        // s(λ) = −λ k + √(r² − λ² g), with k = Z · v and g = 1 − k²; the capsule is the union
        // of those balls for λ in the segment's range, so the exit is the largest s(λ):
        // λ* = −k r / √g, clamped to the range.
        let (r, hh) = (self.radius, self.half_height);
        let k = v.z;
        let g = (1.0 - k * k).max(0.0);
        let (lo, hi) = (core_point.z - hh, core_point.z + hh);
        let lambda = if g > 0.0 {
            (-k * r / g.sqrt()).clamp(lo.min(hi), hi.max(lo))
        } else if -k * lo >= -k * hi {
            lo
        } else {
            hi
        };
        let s = -lambda * k + (r * r - lambda * lambda * g).max(0.0).sqrt();
        core_point + v * s
    }

    fn has_columns(&self) -> bool {
        true
    }

    fn column_top(&self, p: DVec3, v: DVec3) -> Option<f64> {
        // The union of the cylinder part and the two end balls (an interval: the capsule
        // is convex): the largest upper end.
        let (r, hh) = (self.radius, self.half_height);
        let tube = radial_interval(p, v, r).and_then(|t| meet(t, slab_interval(p.z, v.z, hh)));
        [
            ball_interval(p - DVec3::Z * hh, v, r),
            ball_interval(p + DVec3::Z * hh, v, r),
            tube,
        ]
        .into_iter()
        .flatten()
        .map(|(_, hi)| hi)
        .reduce(f64::max)
    }

    fn feature_towards(&self, _v: DVec3, out: &mut Polygon) {
        // The whole segment: an end that is not a support point is dropped by the
        // manifold's depth test.
        out.clear();
        let s = self.segment();
        out.push(s.a);
        out.push(s.b);
    }
}

impl ContactFeatures for Cuboid {
    fn face_towards(&self, n: DVec3, out: &mut Polygon) -> Option<DVec3> {
        out.clear();
        let h = self.half_extents;
        let a = n.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let sign = if n[axis] >= 0.0 { 1.0 } else { -1.0 };
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        if h[u] == 0.0 || h[v] == 0.0 {
            return None;
        }
        // Counter-clockwise about +e_axis is (u, v) = (+,+), (−,+), (−,−), (+,−); reversed
        // for the −e_axis face.
        for (su, sv) in [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            let mut p = DVec3::ZERO;
            p[axis] = sign * h[axis];
            p[u] = su * h[u];
            p[v] = sv * h[v] * sign;
            out.push(p);
        }
        let mut normal = DVec3::ZERO;
        normal[axis] = sign;
        Some(normal)
    }

    fn feature_towards(&self, v: DVec3, out: &mut Polygon) {
        if self.face_towards(v, out).is_none() {
            out.clear();
            // A flat box seen edge-on (or a segment, a point): its support corner, by the
            // sign pattern of `v`.
            let h = self.half_extents;
            let corner = DVec3::new(h.x.copysign(v.x), h.y.copysign(v.y), h.z.copysign(v.z));
            out.push(corner);
        }
    }
}

impl ContactFeatures for Cylinder {
    fn has_columns(&self) -> bool {
        true
    }

    fn column_top(&self, p: DVec3, v: DVec3) -> Option<f64> {
        let (h, r) = (self.half_height, self.radius);
        let tube = radial_interval(p, v, r)?;
        // NOTE: a column through the rim of a cap, nearly in the cap's plane (a line
        // contact's end on this cylinder's end), meets the side and the cap at the same
        // point to rounding: the side's exit is taken when within rounding of the slab, or
        // the slab's rounding would decide between the side and a zero-length chord.
        let rounding = RIM_RELATIVE * (h + r + p.abs().max_element());
        if (p.z + tube.1 * v.z).abs() <= h + rounding {
            return Some(tube.1);
        }
        meet(tube, slab_interval(p.z, v.z, h)).map(|(_, hi)| hi)
    }

    fn face_towards(&self, n: DVec3, out: &mut Polygon) -> Option<DVec3> {
        out.clear();
        if self.radius == 0.0 {
            return None;
        }
        let up = if n.z >= 0.0 { 1.0 } else { -1.0 };
        disc(up * self.half_height, self.radius, radial(n), up, out);
        Some(DVec3::Z * up)
    }

    fn feature_towards(&self, v: DVec3, out: &mut Polygon) {
        out.clear();
        let u = radial(v);
        let rho = DVec3::new(v.x, v.y, 0.0).length();
        let up = if v.z >= 0.0 { 1.0 } else { -1.0 };
        if v.z.abs() >= rho && self.radius > 0.0 {
            disc(up * self.half_height, self.radius, u, up, out);
        } else {
            let rim = u * self.radius;
            out.push(rim - DVec3::Z * self.half_height);
            out.push(rim + DVec3::Z * self.half_height);
        }
    }
}

impl ContactFeatures for Cone {
    fn face_towards(&self, _n: DVec3, out: &mut Polygon) -> Option<DVec3> {
        out.clear();
        if self.radius == 0.0 {
            return None;
        }
        disc(-self.half_height, self.radius, DVec3::X, -1.0, out);
        Some(-DVec3::Z)
    }

    fn feature_towards(&self, v: DVec3, out: &mut Polygon) {
        out.clear();
        let (h, r) = (self.half_height, self.radius);
        let u = radial(v);
        // The slant's outward normal in the half-plane of `u`: ⟂ to apex − rim.
        let slant = (u * (2.0 * h) + DVec3::Z * r).normalize_or_zero();
        if -v.z >= v.dot(slant) && r > 0.0 {
            disc(-h, r, u, -1.0, out);
        } else {
            out.push(DVec3::new(0.0, 0.0, h));
            out.push(u * r - DVec3::Z * h);
        }
    }
}

impl ContactFeatures for ConvexPolyhedron {
    fn face_towards(&self, n: DVec3, out: &mut Polygon) -> Option<DVec3> {
        out.clear();
        let face = self
            .faces()
            .iter()
            .max_by(|x, y| x.normal.dot(n).total_cmp(&y.normal.dot(n)))?;
        if face.vertices.len() > FEATURE_POINTS {
            return None;
        }
        for &i in &face.vertices {
            out.push(self.vertices()[i as usize]);
        }
        Some(face.normal)
    }

    fn feature_towards(&self, v: DVec3, out: &mut Polygon) {
        if self.face_towards(v, out).is_some() {
            return;
        }
        out.clear();
        if self.dimension() == 1 {
            // A segment hull: both ends (the depth test keeps the ones that touch).
            for &p in self.vertices().iter().take(2) {
                out.push(p);
            }
        } else {
            out.push(self.support(v));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_disc_table_holds_the_cosines_and_sines_of_its_angles() {
        for (k, &(cos, sin)) in DISC_COS_SIN.iter().enumerate() {
            let angle = std::f64::consts::TAU * k as f64 / DISC_POINTS as f64;
            assert!((cos - angle.cos()).abs() <= 1e-16, "{k}");
            assert!((sin - angle.sin()).abs() <= 1e-16, "{k}");
        }
    }

    #[test]
    fn a_tilted_cylinder_cap_starts_at_the_support_point() {
        let c = Cylinder::new(0.5, 2.0);
        let v = DVec3::new(0.3, -0.2, -1.0).normalize();
        let mut p = Polygon::new();
        c.feature_towards(v, &mut p);
        assert_eq!(p.len(), DISC_POINTS);
        assert!((p.points()[0] - c.support(v)).length() < 1e-12);
        for q in p.points() {
            assert!((DVec3::new(q.x, q.y, 0.0).length() - 2.0).abs() < 1e-12);
            assert_eq!(q.z, -0.5);
        }
    }

    #[test]
    fn a_cylinder_seen_from_the_side_is_its_support_line() {
        let c = Cylinder::new(0.5, 2.0);
        let v = DVec3::new(1.0, 1.0, 0.1).normalize();
        let mut p = Polygon::new();
        c.feature_towards(v, &mut p);
        assert_eq!(p.len(), 2);
        assert!((p.points()[1] - c.support(v)).length() < 1e-12);
    }

    #[test]
    fn a_cone_shows_its_base_downwards_and_its_slant_sideways() {
        let c = Cone::new(1.0, 1.0);
        let mut p = Polygon::new();
        c.feature_towards(-DVec3::Z, &mut p);
        assert_eq!(p.len(), DISC_POINTS);
        c.feature_towards(DVec3::new(1.0, 0.0, 0.2).normalize(), &mut p);
        assert_eq!(p.points(), &[DVec3::Z, DVec3::new(1.0, 0.0, -1.0)]);
    }

    #[test]
    fn columns_leave_cylinders_and_capsules_at_their_surfaces() {
        // The extreme along +X in the column through a point at x = 2: behind it.
        let c = Cylinder::new(1.0, 0.5);
        let s = c.column_top(DVec3::new(2.0, 0.0, 0.3), DVec3::X).unwrap();
        assert!((s + 1.5).abs() < 1e-15, "{s}");
        // Off the side line by 0.3: the circle at x = 0.4.
        let s = c.column_top(DVec3::new(2.0, 0.3, 0.0), DVec3::X).unwrap();
        assert!((s + 1.6).abs() < 1e-15, "{s}");
        assert!(c.column_top(DVec3::new(2.0, 0.6, 0.0), DVec3::X).is_none());
        assert!(c.column_top(DVec3::new(2.0, 0.0, 1.1), DVec3::X).is_none());
        let k = Capsule::new(1.0, 0.5);
        // Beyond the segment's end, the end ball answers.
        let s = k.column_top(DVec3::new(2.0, 0.0, 1.3), DVec3::X).unwrap();
        assert!((s + 1.6).abs() < 1e-15, "{s}");
        let s = k.column_top(DVec3::new(2.0, 0.0, 0.2), DVec3::X).unwrap();
        assert!((s + 1.5).abs() < 1e-15, "{s}");
        assert!(k.column_top(DVec3::new(2.0, 0.0, 1.6), DVec3::X).is_none());
    }

    #[test]
    fn box_faces_are_counter_clockwise_seen_from_outside() {
        let b = Cuboid::new(DVec3::new(1.0, 2.0, 3.0));
        let mut p = Polygon::new();
        for n in [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ] {
            let normal = b.face_towards(n, &mut p).unwrap();
            assert_eq!(normal, n);
            let q = p.points();
            let twice_area: DVec3 = (0..4).map(|i| q[i].cross(q[(i + 1) % 4])).sum();
            assert!(twice_area.dot(n) > 0.0, "{n}");
            assert!(q.iter().all(|x| x.dot(n) == b.half_extents.dot(n.abs())));
        }
    }
}
