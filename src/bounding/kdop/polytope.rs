//! The k-DOP as an explicit convex polyhedron, for its volume and an interior point. Not a
//! hot path: each face is a square in its plane clipped by every other half-space
//! (Sutherland–Hodgman), all in fixed-size arrays, so nothing allocates.

use super::Kdop;
use crate::math::DVec3;

/// Enough for the 26 half-spaces of a 26-DOP.
const MAX_PLANES: usize = 26;
/// A clipped face starts as 4 corners and gains at most one vertex per clip.
const MAX_POLYGON: usize = 4 + MAX_PLANES;

/// A convex polygon in a fixed array.
#[derive(Clone, Copy)]
struct Polygon {
    vertices: [DVec3; MAX_POLYGON],
    len: usize,
}

impl Polygon {
    fn push(&mut self, v: DVec3) {
        debug_assert!(self.len < MAX_POLYGON);
        self.vertices[self.len] = v;
        self.len += 1;
    }

    fn as_slice(&self) -> &[DVec3] {
        &self.vertices[..self.len]
    }

    /// Keeps the part with `n · x <= b + tolerance`.
    fn clipped(&self, n: DVec3, b: f64, tolerance: f64) -> Self {
        let mut out = Self {
            vertices: [DVec3::ZERO; MAX_POLYGON],
            len: 0,
        };
        let verts = self.as_slice();
        for (i, &p) in verts.iter().enumerate() {
            let q = verts[(i + 1) % verts.len()];
            let (sp, sq) = (n.dot(p) - b, n.dot(q) - b);
            let (p_in, q_in) = (sp <= tolerance, sq <= tolerance);
            if p_in {
                out.push(p);
            }
            if p_in != q_in {
                let t = sp / (sp - sq);
                out.push(p + (q - p) * t.clamp(0.0, 1.0));
            }
        }
        out
    }
}

/// Calls `visit(unit_normal, plane_distance, polygon)` for every face of `dop`, in
/// coordinates relative to `origin`: the face lies on `unit_normal · y = plane_distance`.
fn for_each_face<const N: usize>(
    dop: &Kdop<N>,
    origin: DVec3,
    mut visit: impl FnMut(DVec3, f64, &[DVec3]),
) {
    let dirs = Kdop::<N>::DIRECTIONS;
    let mut planes = [(DVec3::ZERO, 0.0); MAX_PLANES];
    for k in 0..N {
        let shift = dirs[k].dot(origin);
        planes[2 * k] = (dirs[k], dop.max[k] - shift);
        planes[2 * k + 1] = (-dirs[k], shift - dop.min[k]);
    }
    let planes = &planes[..2 * N];
    let half_diagonal = 0.5 * dop.aabb_diagonal();
    let scale = half_diagonal + origin.abs().max_element();
    let tolerance = 1e-12 * scale.max(f64::MIN_POSITIVE);
    let reach = 2.0 * half_diagonal + tolerance;
    for (i, &(n, b)) in planes.iter().enumerate() {
        let inv = 1.0 / n.length();
        let (unit, distance) = (n * inv, b * inv);
        let (u, v) = unit.any_orthonormal_pair();
        let foot = unit * distance;
        let mut polygon = Polygon {
            vertices: [DVec3::ZERO; MAX_POLYGON],
            len: 0,
        };
        for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            polygon.push(foot + (u * su + v * sv) * reach);
        }
        for (j, &(m, c)) in planes.iter().enumerate() {
            if j != i && polygon.len > 0 {
                polygon = polygon.clipped(m, c, tolerance * m.length());
            }
        }
        if polygon.len >= 3 {
            visit(unit, distance, polygon.as_slice());
        }
    }
}

/// Signed area of a planar polygon, seen from the side `unit_normal` points to.
fn area(unit_normal: DVec3, polygon: &[DVec3]) -> f64 {
    let p0 = polygon[0];
    let mut twice = DVec3::ZERO;
    for w in polygon[1..].windows(2) {
        twice += (w[0] - p0).cross(w[1] - p0);
    }
    0.5 * twice.dot(unit_normal)
}

/// The polytope's volume: `Σ area · distance / 3` over the faces (divergence theorem), with
/// distances from the AABB part's centre. Zero (to rounding) for flat DOPs.
pub(super) fn volume<const N: usize>(dop: &Kdop<N>) -> f64 {
    let origin = dop.aabb_center();
    let mut sum = 0.0;
    for_each_face(dop, origin, |unit, distance, polygon| {
        sum += area(unit, polygon) * distance;
    });
    (sum / 3.0).max(0.0)
}

/// The mean of the faces' polygon vertices: a point of the polytope (to rounding), or
/// `None` when no face survives (an empty DOP).
pub(super) fn vertex_mean<const N: usize>(dop: &Kdop<N>) -> Option<DVec3> {
    let origin = dop.aabb_center();
    let (mut sum, mut count) = (DVec3::ZERO, 0.0);
    for_each_face(dop, origin, |_, _, polygon| {
        for v in polygon {
            sum += *v;
            count += 1.0;
        }
    });
    (count > 0.0).then(|| origin + sum / count)
}

/// Every vertex of every face (with repeats), relative to nothing: absolute coordinates.
#[cfg(test)]
pub(super) fn vertices<const N: usize>(dop: &Kdop<N>) -> Vec<DVec3> {
    let origin = dop.aabb_center();
    let mut out = Vec::new();
    for_each_face(dop, origin, |_, _, polygon| {
        out.extend(polygon.iter().map(|v| origin + *v));
    });
    out
}
