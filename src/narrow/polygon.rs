//! A fixed-capacity polygon for contact features (a point, a segment or a convex polygon,
//! vertices in order around the outline) and Sutherland–Hodgman clipping (Ericson §8.3.4),
//! shared by the closed-form pairs' manifolds ([`super::pairs`], 8 vertices) and the
//! general convex manifold ([`super::convex_manifold`], room for 64-gons clipped by 64-gons).

use super::closest_points::{closest_point_segment, closest_point_triangle};
use crate::math::DVec3;

/// At most `N` vertices, in order around the outline. Never allocates.
#[derive(Debug, Clone, Copy)]
pub struct Polygon<const N: usize> {
    pub(crate) pts: [DVec3; N],
    pub(crate) len: usize,
}

impl<const N: usize> Default for Polygon<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Polygon<N> {
    /// An empty polygon.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            pts: [DVec3::ZERO; N],
            len: 0,
        }
    }

    /// Empties it.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Adds a vertex; returns `false` (and drops it) when full.
    pub fn push(&mut self, p: DVec3) -> bool {
        if self.len == N {
            return false;
        }
        self.pts[self.len] = p;
        self.len += 1;
        true
    }

    /// The vertices.
    #[must_use]
    pub fn points(&self) -> &[DVec3] {
        &self.pts[..self.len]
    }

    /// The vertices, mutable (to move the polygon into another frame).
    pub fn points_mut(&mut self) -> &mut [DVec3] {
        &mut self.pts[..self.len]
    }

    /// Number of vertices.
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it has no vertex.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The point of the (closed, convex, planar) polygon closest to `p`.
    #[must_use]
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        let v = self.points();
        match v.len() {
            1 => v[0],
            2 => closest_point_segment(p, v[0], v[1]),
            _ => {
                let mut best = closest_point_triangle(p, v[0], v[1], v[2]);
                for i in 3..v.len() {
                    let q = closest_point_triangle(p, v[0], v[i - 1], v[i]);
                    if q.distance_squared(p) < best.distance_squared(p) {
                        best = q;
                    }
                }
                best
            }
        }
    }

    /// The edges (none for a point, one for a segment).
    pub fn edges(&self) -> impl Iterator<Item = (DVec3, DVec3)> + '_ {
        let n = self.len;
        let count = match n {
            0 | 1 => 0,
            2 => 1,
            _ => n,
        };
        (0..count).map(move |i| (self.pts[i], self.pts[(i + 1) % n]))
    }

    /// Sutherland–Hodgman: the part of the polygon with `side · x ≤ offset`, into `out`.
    /// A point stays a point and a segment a segment; vertices past `out`'s capacity are
    /// dropped.
    pub fn clip_plane_into<const M: usize>(&self, side: DVec3, offset: f64, out: &mut Polygon<M>) {
        out.clear();
        let pts = self.points();
        let inside = |p: DVec3| side.dot(p) - offset;
        match pts.len() {
            0 => {}
            1 => {
                if inside(pts[0]) <= 0.0 {
                    out.push(pts[0]);
                }
            }
            2 => {
                let (p, q) = (pts[0], pts[1]);
                let (dp, dq) = (inside(p), inside(q));
                let cut = || p + (q - p) * (dp / (dp - dq));
                match (dp <= 0.0, dq <= 0.0) {
                    (true, true) => {
                        out.push(p);
                        out.push(q);
                    }
                    (true, false) => {
                        out.push(p);
                        out.push(cut());
                    }
                    (false, true) => {
                        out.push(cut());
                        out.push(q);
                    }
                    (false, false) => {}
                }
            }
            len => {
                for i in 0..len {
                    let (p, q) = (pts[i], pts[(i + 1) % len]);
                    let (dp, dq) = (inside(p), inside(q));
                    if dp <= 0.0 {
                        out.push(p);
                    }
                    if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
                        out.push(p + (q - p) * (dp / (dp - dq)));
                    }
                }
            }
        }
    }

    /// [`clip_plane_into`](Self::clip_plane_into) returning the clipped polygon.
    #[must_use]
    pub fn clipped(&self, side: DVec3, offset: f64) -> Self {
        let mut out = Self::new();
        self.clip_plane_into(side, offset, &mut out);
        out
    }
}
