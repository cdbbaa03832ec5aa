//! A piece of a closed solid: its loops, and what is measured on them.
//!
//! A piece is its closed boundary: polygon *loops* over a pool of points. Loops come in two
//! kinds: **surface** loops are pieces of the input mesh's triangles (each a convex polygon,
//! a triangle cut by half-spaces), **cap** loops lie on a cutting plane and close the piece
//! where a cut went through the solid.
//!
//! # Invariants
//! - The loops form a closed oriented chain: every directed edge `a → b` of one loop has its
//!   reverse `b → a` in another (up to the repairs the solid needed, see `solid.rs`). That is
//!   what makes [`Piece::volume`] exact and the cap of the next cut closable.
//! - The piece lies in every half-space that cut it, and each of its caps on that
//!   half-space's plane. Caps are therefore on the boundary of the piece's convex hull and
//!   never hold concavity: [`Piece::concavity`] samples surface loops only.
//! - The hull of a piece is the hull of its points: every point on its boundary is in the
//!   convex hull of its loops' corners (surface loops are convex; a cap's hull is the hull of
//!   its outline).
//! - A cap covers only where its plane crosses the solid, and a mesh face along a cutting
//!   plane stays with its solid: no piece holds a zero-volume fin (a face and a cap over it,
//!   back to back) whose corners would stretch its hull.
//!
//! The cut that makes two pieces of one is in [`cut`](self::cut): each side's loops, clipped,
//! and a cap that closes it exactly where the plane crosses solid.

mod cut;

use super::cap_outline::CapOutline;
use crate::math::DVec3;
pub(super) use cut::chain_outlines;
use std::collections::HashSet;

/// An oriented plane, `normal · x = offset` (metres); "below" is `normal · x ≤ offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Plane {
    /// Unit normal.
    pub normal: DVec3,
    /// Offset along `normal`, metres.
    pub offset: f64,
}

impl Plane {
    /// Signed distance of `p` above the plane, metres.
    #[inline]
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// One loop: `corners[start .. start + len]`, counter-clockwise seen from outside the piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Loop {
    start: u32,
    len: u32,
    /// A piece of the input surface (not a cap).
    surface: bool,
    /// For a cap, the index of its plane in [`Piece::cuts`].
    cut: u32,
}

/// A piece of a closed solid, bounded by polygon loops (see the module docs).
#[derive(Debug, Clone, Default)]
pub(super) struct Piece {
    points: Vec<DVec3>,
    corners: Vec<u32>,
    loops: Vec<Loop>,
    /// The planes that cut this piece off, outward (the piece is below each).
    pub cuts: Vec<Plane>,
    /// Cap outlines that did not close when this piece was cut off (an input the repairs could
    /// not make closed); each was closed by a straight edge.
    pub forced_caps: usize,
}

impl Piece {
    /// A piece bounded by `triangles` over `points`, all surface loops.
    pub fn from_triangles(points: Vec<DVec3>, triangles: &[[u32; 3]]) -> Self {
        let mut corners = Vec::with_capacity(triangles.len() * 3);
        let mut loops = Vec::with_capacity(triangles.len());
        for t in triangles {
            loops.push(Loop {
                start: corners.len() as u32,
                len: 3,
                surface: true,
                cut: u32::MAX,
            });
            corners.extend_from_slice(t);
        }
        Self {
            points,
            corners,
            loops,
            cuts: Vec::new(),
            forced_caps: 0,
        }
    }

    /// Every point some loop uses, once each: the hull's input. (The root's pool can hold
    /// points no triangle uses, which are no part of the solid.)
    pub fn used_points(&self) -> Vec<DVec3> {
        let mut used = vec![false; self.points.len()];
        for &c in &self.corners {
            used[c as usize] = true;
        }
        self.points
            .iter()
            .zip(used)
            .filter_map(|(&p, used)| used.then_some(p))
            .collect()
    }

    fn loop_corners(&self, l: Loop) -> &[u32] {
        &self.corners[l.start as usize..(l.start + l.len) as usize]
    }

    /// The points where concavity is measured: every surface loop's corners and, on each
    /// triangle of its fan, a lattice at most `spacing` metres apart (at most
    /// [`MAX_SURFACE_DIVISIONS`] per edge; the centroid alone for a small triangle); and the
    /// caps' outlines, as points along their edges as far apart. Surface loops are convex, so
    /// every sample is on the piece's boundary. (Cap samples lie on the hull's boundary and
    /// never count as deep, see the module docs; they hold hull points near a cap's edge to
    /// the piece.)
    pub fn surface_samples(&self, spacing: f64) -> Vec<DVec3> {
        let mut used = vec![false; self.points.len()];
        let mut samples = Vec::new();
        for l in &self.loops {
            let corners = self.loop_corners(*l);
            for &c in corners {
                if !std::mem::replace(&mut used[c as usize], true) {
                    samples.push(self.points[c as usize]);
                }
            }
            if l.surface {
                let a = self.points[corners[0] as usize];
                for w in corners[1..].windows(2) {
                    let (b, c) = (self.points[w[0] as usize], self.points[w[1] as usize]);
                    lattice_samples(a, b, c, spacing, MAX_SURFACE_DIVISIONS, &mut samples);
                }
            } else {
                for (k, &a) in corners.iter().enumerate() {
                    let b = corners[(k + 1) % corners.len()];
                    let (a, b) = (self.points[a as usize], self.points[b as usize]);
                    let steps = ((a - b).length() / spacing)
                        .ceil()
                        .min(MAX_SURFACE_DIVISIONS as f64);
                    for i in 1..steps as usize {
                        samples.push(a + (b - a) * (i as f64 / steps));
                    }
                }
            }
        }
        samples
    }

    /// The edges of the surface loops, each once (as `(low, high)` point indices), with the
    /// points they join: what a candidate cut crosses.
    pub fn surface_edges(&self) -> Vec<[DVec3; 2]> {
        let mut seen: HashSet<(u32, u32)> = HashSet::new();
        let mut edges = Vec::new();
        for l in self.loops.iter().filter(|l| l.surface) {
            let corners = self.loop_corners(*l);
            for (k, &a) in corners.iter().enumerate() {
                let b = corners[(k + 1) % corners.len()];
                if seen.insert((a.min(b), a.max(b))) {
                    edges.push([self.points[a as usize], self.points[b as usize]]);
                }
            }
        }
        edges
    }

    /// Enclosed volume, m³, by the divergence theorem over the loops (fans about a point
    /// near the piece, for precision far from the origin).
    pub fn volume(&self) -> f64 {
        let Some(&first) = self.corners.first() else {
            return 0.0;
        };
        let o = self.points[first as usize];
        let mut six_volume = 0.0;
        for l in &self.loops {
            let corners = self.loop_corners(*l);
            let a = self.points[corners[0] as usize] - o;
            for w in corners[1..].windows(2) {
                let b = self.points[w[0] as usize] - o;
                let c = self.points[w[1] as usize] - o;
                six_volume += a.dot(b.cross(c));
            }
        }
        six_volume / 6.0
    }

    /// The outlines of the caps of the cuts `cuts` (one plane, named once or more by a
    /// merged piece), to test points against ([`CapOutline::contains`]).
    pub fn cap_outline(&self, cuts: &[usize]) -> CapOutline {
        let mut edges = Vec::new();
        for l in self
            .loops
            .iter()
            .filter(|l| !l.surface && cuts.contains(&(l.cut as usize)))
        {
            let corners = self.loop_corners(*l);
            for (k, &a) in corners.iter().enumerate() {
                let b = corners[(k + 1) % corners.len()];
                edges.push([self.points[a as usize], self.points[b as usize]]);
            }
        }
        CapOutline::new(self.cuts[cuts[0]].normal, &edges)
    }

    /// The union of two pieces that touch along a cut: their loops together (the shared caps
    /// face each other and cancel in the volume; they are not surface, so they hold no
    /// concavity).
    pub fn merged(&self, other: &Piece) -> Piece {
        let offset = self.points.len() as u32;
        let mut merged = self.clone();
        merged.points.extend_from_slice(&other.points);
        let corner_offset = merged.corners.len() as u32;
        merged
            .corners
            .extend(other.corners.iter().map(|&c| c + offset));
        let cut_offset = self.cuts.len() as u32;
        merged.loops.extend(other.loops.iter().map(|l| Loop {
            start: l.start + corner_offset,
            cut: if l.surface { l.cut } else { l.cut + cut_offset },
            ..*l
        }));
        merged.forced_caps += other.forced_caps;
        merged.cuts.extend_from_slice(&other.cuts);
        merged
    }
}

/// Most divisions of a surface triangle's edge when sampling it for concavity: enough that
/// the distance from a hull point to the nearest sample stays near the spacing on triangles
/// up to this many spacings long.
const MAX_SURFACE_DIVISIONS: usize = 128;

/// Points of triangle `a b c` on a lattice about `spacing` apart (at most `most` divisions
/// per edge), corners excluded; the centroid when the triangle is smaller than `spacing`.
pub(super) fn lattice_samples(
    a: DVec3,
    b: DVec3,
    c: DVec3,
    spacing: f64,
    most: usize,
    out: &mut Vec<DVec3>,
) {
    let longest = (b - a).length().max((c - b).length()).max((a - c).length());
    let divisions = (longest / spacing).ceil();
    if divisions.is_nan() || divisions < 2.0 {
        out.push((a + b + c) / 3.0);
        return;
    }
    let k = (divisions as usize).min(most);
    let (u, v) = ((b - a) / k as f64, (c - a) / k as f64);
    for i in 0..=k {
        for j in 0..=k - i {
            let corner = (i == 0 && j == 0) || i == k || j == k;
            if !corner {
                out.push(a + u * i as f64 + v * j as f64);
            }
        }
    }
}
