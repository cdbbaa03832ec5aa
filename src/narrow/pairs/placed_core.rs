//! The polytope "core" of a primitive, placed in the query frame (A's frame).
//!
//! Every primitive of this module is a convex polytope core swept by a ball: a sphere is a
//! point with a radius, a capsule a segment with a radius, a cuboid and a triangle have
//! radius 0. A [`PlacedCore`] holds what the pair queries need of the core: its vertices, its
//! edges, its face normals and edge directions (the separating-axis candidates), the closest
//! point to a query point, and its support features.

use crate::geometry::{Capsule, Cuboid, Sphere, Triangle};
use crate::math::{DMat3, DVec3, Isometry};
use crate::narrow::closest_points::{closest_point_segment, closest_point_triangle};

/// Cross products (and normals) shorter than this times the product of the lengths
/// involved count as zero: a skipped axis is within about `1e-12` rad of the degenerate one,
/// so skipping it can change a depth by at most `1e-12` times the shapes' extent.
pub(super) const AXIS_RELATIVE: f64 = 1e-12;

/// Which polytope the core is.
#[derive(Debug, Clone, Copy)]
pub(super) enum Kind {
    /// One point (sphere centre).
    Point,
    /// A segment (capsule axis); `verts[0]`, `verts[1]`.
    Segment,
    /// A box: centre, axes as columns, half extents.
    Box {
        center: DVec3,
        axes: DMat3,
        half: DVec3,
    },
    /// A triangle; `verts[0..3]`.
    Triangle,
}

/// A placed polytope core with a radius (see the module docs).
#[derive(Debug, Clone, Copy)]
pub(super) struct PlacedCore {
    pub kind: Kind,
    pub radius: f64,
    pub verts: [DVec3; 8],
    pub nv: usize,
    /// Unit face normals (one per opposite pair).
    pub faces: [DVec3; 3],
    pub nf: usize,
    /// Unit edge directions.
    pub dirs: [DVec3; 3],
    pub nd: usize,
}

/// The 12 edges of a box as pairs of indices into its binary-ordered corners.
const BOX_EDGES: [(usize, usize); 12] = [
    (0, 1),
    (2, 3),
    (4, 5),
    (6, 7),
    (0, 2),
    (1, 3),
    (4, 6),
    (5, 7),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

impl PlacedCore {
    fn empty(kind: Kind, radius: f64) -> Self {
        Self {
            kind,
            radius,
            verts: [DVec3::ZERO; 8],
            nv: 0,
            faces: [DVec3::ZERO; 3],
            nf: 0,
            dirs: [DVec3::ZERO; 3],
            nd: 0,
        }
    }

    /// A sphere placed by `pose`.
    pub fn sphere(s: &Sphere, pose: &Isometry) -> Self {
        let mut c = Self::empty(Kind::Point, s.radius);
        c.verts[0] = pose.translation;
        c.nv = 1;
        c
    }

    /// A capsule placed by `pose`.
    pub fn capsule(s: &Capsule, pose: &Isometry) -> Self {
        let mut c = Self::empty(Kind::Segment, s.radius);
        let seg = s.segment();
        c.verts[0] = pose.transform_point(seg.a);
        c.verts[1] = pose.transform_point(seg.b);
        c.nv = 2;
        c.dirs[0] = pose.rotation.z_axis;
        c.nd = 1;
        c
    }

    /// A cuboid placed by `pose`.
    pub fn cuboid(s: &Cuboid, pose: &Isometry) -> Self {
        let mut c = Self::empty(
            Kind::Box {
                center: pose.translation,
                axes: pose.rotation,
                half: s.half_extents,
            },
            0.0,
        );
        for (i, v) in s.corners().into_iter().enumerate() {
            c.verts[i] = pose.transform_point(v);
        }
        c.nv = 8;
        for i in 0..3 {
            c.faces[i] = pose.rotation.col(i);
            c.dirs[i] = pose.rotation.col(i);
        }
        c.nf = 3;
        c.nd = 3;
        c
    }

    /// A triangle placed by `pose`. Zero-area triangles keep no face normal, zero-length
    /// edges no direction.
    pub fn triangle(s: &Triangle, pose: &Isometry) -> Self {
        let mut c = Self::empty(Kind::Triangle, 0.0);
        let t = s.transformed(pose);
        c.verts[..3].copy_from_slice(&t.vertices());
        c.nv = 3;
        let (e0, e1) = (t.b - t.a, t.c - t.a);
        let n = e0.cross(e1);
        if n.length() > AXIS_RELATIVE * e0.length() * e1.length() {
            c.faces[0] = n.normalize();
            c.nf = 1;
        }
        for (p, q) in [(t.a, t.b), (t.b, t.c), (t.c, t.a)] {
            if let Some(d) = (q - p).try_normalize() {
                c.dirs[c.nd] = d;
                c.nd += 1;
            }
        }
        c
    }

    /// The vertices.
    pub fn vertices(&self) -> &[DVec3] {
        &self.verts[..self.nv]
    }

    /// The edges, as end-point pairs.
    pub fn edges(&self) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
        let list: &[(usize, usize)] = match self.kind {
            Kind::Point => &[],
            Kind::Segment => &[(0, 1)],
            Kind::Box { .. } => &BOX_EDGES,
            Kind::Triangle => &[(0, 1), (1, 2), (2, 0)],
        };
        list.iter().map(|&(i, j)| (self.verts[i], self.verts[j]))
    }

    /// The point of the core closest to `p`.
    #[must_use]
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        match self.kind {
            Kind::Point => self.verts[0],
            Kind::Segment => closest_point_segment(p, self.verts[0], self.verts[1]),
            Kind::Triangle => {
                closest_point_triangle(p, self.verts[0], self.verts[1], self.verts[2])
            }
            Kind::Box { center, axes, half } => {
                let local = axes.transpose() * (p - center);
                center + axes * local.clamp(-half, half)
            }
        }
    }

    /// Largest coordinate magnitude of the core, plus its radius: the scale rounding and
    /// tolerances are measured against.
    #[must_use]
    pub fn scale(&self) -> f64 {
        self.vertices()
            .iter()
            .fold(self.radius, |m, v| m.max(v.abs().max_element()))
    }

    /// The longest edge of the core (0 for a point): the size of its features.
    #[must_use]
    pub fn extent(&self) -> f64 {
        match self.kind {
            Kind::Box { half, .. } => 2.0 * half.max_element(),
            _ => self.edges().fold(0.0, |m, (p, q)| m.max(p.distance(q))),
        }
    }

    /// `(min, max)` of the vertices projected on `axis`.
    #[must_use]
    pub fn project(&self, axis: DVec3) -> (f64, f64) {
        if let Kind::Box { center, axes, half } = self.kind {
            // PERF: the centre's projection ± the half extents' reach, 3 dot products
            // instead of 8 (the separating-axis test projects on up to 15 axes).
            let c = center.dot(axis);
            let reach = (axes.transpose() * axis).abs().dot(half);
            return (c - reach, c + reach);
        }
        self.vertices()
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                let d = v.dot(axis);
                (lo.min(d), hi.max(d))
            })
    }

    /// The support feature along `n`: the vertices within `tol` of the maximum of `x · n`,
    /// as a convex polygon in cyclic order (1 to 4 points).
    #[must_use]
    pub fn support_feature(&self, n: DVec3, tol: f64) -> Polygon {
        let mut out = Polygon::default();
        match self.kind {
            Kind::Box { center, axes, half } => {
                // An axis is free (the feature spans it) when flipping its sign moves the
                // point by at most `tol` along n.
                // Zero-size axes change nothing: they stay fixed.
                let mut sign = [1.0; 3];
                let mut free = [0usize; 2];
                let mut nfree = 0;
                for i in 0..3 {
                    let d = axes.col(i).dot(n);
                    if half[i] > 0.0 && 2.0 * half[i] * d.abs() <= tol && nfree < 2 {
                        free[nfree] = i;
                        nfree += 1;
                    } else {
                        sign[i] = if d >= 0.0 { 1.0 } else { -1.0 };
                    }
                }
                let pattern: &[(f64, f64)] = match nfree {
                    0 => &[(0.0, 0.0)],
                    1 => &[(-1.0, 0.0), (1.0, 0.0)],
                    _ => &[(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)],
                };
                for &(s0, s1) in pattern {
                    let mut s = sign;
                    if nfree > 0 {
                        s[free[0]] = s0;
                    }
                    if nfree > 1 {
                        s[free[1]] = s1;
                    }
                    out.push(center + axes * (DVec3::from_array(s) * half));
                }
            }
            _ => {
                let max = self
                    .vertices()
                    .iter()
                    .fold(f64::NEG_INFINITY, |m, v| m.max(v.dot(n)));
                for v in self.vertices() {
                    if v.dot(n) >= max - tol {
                        out.push(*v);
                    }
                }
            }
        }
        out
    }

    /// The cosine between `n` (unit) and the outward normal of [`best_face`](Self::best_face),
    /// without building the face; `None` when it has none.
    #[must_use]
    pub fn best_face_alignment(&self, n: DVec3) -> Option<f64> {
        match self.kind {
            Kind::Box { axes, half, .. } => {
                let local = axes.transpose() * n;
                let i = local.abs().max_position();
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                (half[j] * half[k] > 0.0).then(|| local[i].abs())
            }
            Kind::Triangle if self.nf == 1 => Some(self.faces[0].dot(n).abs()),
            _ => None,
        }
    }

    /// The face of the core whose outward normal is closest to `n`, with that normal and
    /// its cosine to `n`; `None` for cores without faces of non-zero area.
    #[must_use]
    pub fn best_face(&self, n: DVec3) -> Option<(Polygon, DVec3, f64)> {
        match self.kind {
            Kind::Box { center, axes, half } => {
                let local = axes.transpose() * n;
                let i = local.abs().max_position();
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                if half[j] * half[k] <= 0.0 {
                    return None;
                }
                let s = if local[i] >= 0.0 { 1.0 } else { -1.0 };
                let mut out = Polygon::default();
                for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let mut c = DVec3::ZERO;
                    c[i] = s * half[i];
                    c[j] = a * half[j];
                    c[k] = b * half[k];
                    out.push(center + axes * c);
                }
                let normal = axes.col(i) * s;
                Some((out, normal, normal.dot(n)))
            }
            Kind::Triangle if self.nf == 1 => {
                let f = self.faces[0];
                let normal = if f.dot(n) >= 0.0 { f } else { -f };
                let mut out = Polygon::default();
                for v in &self.verts[..3] {
                    out.push(*v);
                }
                Some((out, normal, normal.dot(n)))
            }
            _ => None,
        }
    }
}

/// A convex polygon of at most 8 points (a point, a segment, a triangle, a quad, or a quad
/// clipped by a quad), cyclic order.
pub(super) type Polygon = crate::narrow::polygon::Polygon<8>;

/// The interval `[enter, exit]` of parameters `s` for which `o + v s` (unit `v`) lies in
/// the rounded core (`None` when the line misses it). Only for point and segment cores
/// (balls and capsules): the shapes whose surface a manifold point must be moved onto.
#[must_use]
pub(super) fn line_interval(core: &PlacedCore, o: DVec3, v: DVec3) -> Option<(f64, f64)> {
    let r = core.radius;
    let ball = |c: DVec3| {
        let w = o - c;
        let (bq, cq) = (w.dot(v), w.length_squared() - r * r);
        let disc = bq * bq - cq;
        (disc >= 0.0).then(|| (-bq - disc.sqrt(), -bq + disc.sqrt()))
    };
    let join = |x: Option<(f64, f64)>, y: Option<(f64, f64)>| match (x, y) {
        (Some(x), Some(y)) => Some((x.0.min(y.0), x.1.max(y.1))),
        (x, None) => x,
        (None, y) => y,
    };
    match core.kind {
        Kind::Point => ball(core.verts[0]),
        Kind::Segment => {
            let (a, b) = (core.verts[0], core.verts[1]);
            let mut out = join(ball(a), ball(b));
            let len = a.distance(b);
            if len > 0.0 {
                let u = (b - a) / len;
                let (w, vp) = (o - a, v - u * v.dot(u));
                let wp = w - u * w.dot(u);
                let (qa, qb, qc) = (vp.length_squared(), wp.dot(vp), wp.length_squared() - r * r);
                let disc = qb * qb - qa * qc;
                if qa > 0.0 && disc >= 0.0 {
                    let (s0, s1) = ((-qb - disc.sqrt()) / qa, (-qb + disc.sqrt()) / qa);
                    // Keep the part whose foot on the axis is within the segment.
                    let (t0, dt) = (w.dot(u), v.dot(u));
                    let (mut lo, mut hi) = (s0, s1);
                    if dt.abs() > 0.0 {
                        let (e0, e1) = ((0.0 - t0) / dt, (len - t0) / dt);
                        lo = lo.max(e0.min(e1));
                        hi = hi.min(e0.max(e1));
                    } else if !(0.0..=len).contains(&t0) {
                        hi = lo - 1.0;
                    }
                    if lo <= hi {
                        out = join(out, Some((lo, hi)));
                    }
                }
            }
            out
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_intervals_through_a_capsule_hit_the_cylinder_and_the_caps() {
        let c = PlacedCore::capsule(&Capsule::new(1.0, 0.5), &Isometry::IDENTITY);
        // Across the cylinder part.
        let (s0, s1) = line_interval(&c, DVec3::new(-2.0, 0.0, 0.3), DVec3::X).unwrap();
        assert!((s0 - 1.5).abs() < 1e-15 && (s1 - 2.5).abs() < 1e-15);
        // Along the axis: through both caps.
        let (s0, s1) = line_interval(&c, DVec3::new(0.0, 0.0, -3.0), DVec3::Z).unwrap();
        assert!((s0 - 1.5).abs() < 1e-15 && (s1 - 4.5).abs() < 1e-15);
        // Missing it.
        assert!(line_interval(&c, DVec3::new(0.0, 0.6, 0.0), DVec3::X).is_none());
    }

    #[test]
    fn support_features_of_zero_size_boxes_span_their_nonzero_axes() {
        let rod = PlacedCore::cuboid(&Cuboid::new(DVec3::new(0.0, 0.0, 1.0)), &Isometry::IDENTITY);
        assert_eq!(rod.support_feature(DVec3::X, 1e-12).len, 2);
        assert_eq!(rod.support_feature(DVec3::Z, 1e-12).len, 1);
        let cube = PlacedCore::cuboid(&Cuboid::new(DVec3::ONE), &Isometry::IDENTITY);
        assert_eq!(cube.support_feature(DVec3::X, 1e-12).len, 4);
        assert!(cube.best_face(DVec3::new(0.1, 0.0, -1.0)).unwrap().1 == -DVec3::Z);
    }
}
