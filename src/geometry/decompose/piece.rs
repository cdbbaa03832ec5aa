//! A piece of a closed solid, and the plane cut that makes two pieces of one.
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
//!
//! A cut is Sutherland–Hodgman clipping of every loop against each side of the plane, with
//! one point per crossed edge shared by the loops on both sides of that edge, then the
//! cap: the new edges on the plane chained into loops. A cap can be concave, and a cut can
//! leave several stretches of it on one side: those are joined along the cut line where the
//! cap lies on it ([`Clipper::clip_stretches`]), never across a gap, so every corner of a
//! piece lies in the solid. A point's side is decided once per cut
//! from its signed distance (`≤ 0` below), so both pieces and all loops agree on it.

use super::cap_outline::CapOutline;
use crate::math::DVec3;
use std::collections::{HashMap, HashSet};

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

    /// The two pieces on either side of `plane`: `(below, above)`. `None` when every corner
    /// is on one side (the cut would change nothing).
    pub fn cut(&self, plane: &Plane) -> Option<(Piece, Piece)> {
        let side: Vec<f64> = self
            .points
            .iter()
            .map(|&p| plane.signed_distance(p))
            .collect();
        let below = |i: u32| side[i as usize] <= 0.0;
        let any_below = self.corners.iter().any(|&c| below(c));
        let any_above = self.corners.iter().any(|&c| !below(c));
        if !(any_below && any_above) {
            return None;
        }
        let mut crossings = Crossings::new(self.points.len());
        let mut lower = Clipper::new(self.points.len());
        let mut upper = Clipper::new(self.points.len());
        for &l in &self.loops {
            let corners = self.loop_corners(l);
            lower.clip(self, corners, l, &below, &side, &mut crossings);
            upper.clip(self, corners, l, &|i| !below(i), &side, &mut crossings);
        }
        let new_cut = self.cuts.len() as u32;
        let (mut below, mut above) = (
            lower.finish(self, &crossings, self.forced_caps, new_cut),
            upper.finish(self, &crossings, self.forced_caps, new_cut),
        );
        below.cuts = self.cuts.clone();
        below.cuts.push(*plane);
        above.cuts = self.cuts.clone();
        above.cuts.push(Plane {
            normal: -plane.normal,
            offset: -plane.offset,
        });
        Some((below, above))
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

/// The points made where edges cross the plane: one per edge, shared by both sides.
struct Crossings {
    /// Edge `(low, high)` → index into `points`, numbered after the piece's own points.
    by_edge: HashMap<(u32, u32), u32>,
    points: Vec<DVec3>,
    first_id: u32,
}

impl Crossings {
    fn new(first_id: usize) -> Self {
        Self {
            by_edge: HashMap::new(),
            points: Vec::new(),
            first_id: first_id as u32,
        }
    }

    /// The crossing on edge `a–b` (their signed distances differ in side), made once.
    fn on_edge(&mut self, piece: &Piece, side: &[f64], a: u32, b: u32) -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&id) = self.by_edge.get(&key) {
            return id;
        }
        // Interpolated from the low index so both loops of the edge get the same point.
        let (lo, hi) = key;
        let (s_lo, s_hi) = (side[lo as usize], side[hi as usize]);
        let t = s_lo / (s_lo - s_hi);
        let (p, q) = (piece.points[lo as usize], piece.points[hi as usize]);
        let id = self.first_id + self.points.len() as u32;
        self.points.push(p + (q - p) * t.clamp(0.0, 1.0));
        self.by_edge.insert(key, id);
        id
    }

    fn point(&self, piece: &Piece, id: u32) -> DVec3 {
        if id < self.first_id {
            piece.points[id as usize]
        } else {
            self.points[(id - self.first_id) as usize]
        }
    }
}

/// Builds one side's piece: clipped loops, their corners renumbered, the cap's edges.
struct Clipper {
    piece: Piece,
    /// Parent (or crossing) id → this piece's point index, `u32::MAX` until used.
    renumber: Vec<u32>,
    /// Cap edges `[from, to]` in parent/crossing ids, oriented as the cap's outline.
    cap_edges: Vec<[u32; 2]>,
    scratch: Vec<u32>,
}

impl Clipper {
    fn new(parent_points: usize) -> Self {
        Self {
            piece: Piece::default(),
            renumber: vec![u32::MAX; parent_points],
            cap_edges: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Clips one loop to the side where `inside` holds (Sutherland–Hodgman) and records the
    /// cap edge that closes each gap it leaves: the clipped loop runs `exit → entry` along
    /// the plane, so the cap runs `entry → exit`.
    fn clip(
        &mut self,
        parent: &Piece,
        corners: &[u32],
        kind: Loop,
        inside: &dyn Fn(u32) -> bool,
        side: &[f64],
        crossings: &mut Crossings,
    ) {
        // More than one stretch inside: only a cap can be concave enough for that (surface
        // loops are convex).
        if !kind.surface {
            let n = corners.len();
            let crossed = (0..n)
                .filter(|&k| inside(corners[k]) != inside(corners[(k + 1) % n]))
                .count();
            if crossed > 2 && self.clip_stretches(parent, corners, kind, inside, side, crossings) {
                return;
            }
        }
        self.scratch.clear();
        let (mut first_entry, mut open_exit) = (None, None);
        for (k, &a) in corners.iter().enumerate() {
            let b = corners[(k + 1) % corners.len()];
            if inside(a) {
                self.scratch.push(a);
            }
            if inside(a) != inside(b) {
                let x = crossings.on_edge(parent, side, a, b);
                self.scratch.push(x);
                if inside(a) {
                    open_exit = Some(x);
                } else if let Some(exit) = open_exit.take() {
                    self.cap_edges.push([x, exit]);
                } else {
                    first_entry = Some(x);
                }
            }
        }
        if let (Some(exit), Some(entry)) = (open_exit, first_entry) {
            self.cap_edges.push([entry, exit]);
        }
        if self.scratch.len() >= 3 {
            let ids = std::mem::take(&mut self.scratch);
            self.push_loop(parent, crossings, &ids, kind.surface, kind.cut);
            self.scratch = ids;
        }
    }

    /// Clips a loop that enters and leaves the kept side more than once (a concave cap):
    /// each stretch inside runs from an entry to an exit, and the stretches are joined
    /// along the cut line the way the loop's own region lies on it. Sorted along the line,
    /// the crossings bound, pair by pair, the line's segments inside the loop; each pair
    /// joins an exit to an entry. (Sutherland–Hodgman would join the stretches in walk
    /// order instead, by bridges across the gaps between them: outside the solid, and a
    /// later cut through a bridge would put a corner there.) Returns `false` when the
    /// sorted crossings do not pair up so (ties of near-coincident crossings), having added
    /// nothing to the piece: the caller then clips it the plain way.
    fn clip_stretches(
        &mut self,
        parent: &Piece,
        corners: &[u32],
        kind: Loop,
        inside: &dyn Fn(u32) -> bool,
        side: &[f64],
        crossings: &mut Crossings,
    ) -> bool {
        let n = corners.len();
        // Walk from just after an exit so that every stretch is whole.
        let Some(start) = (0..n).find(|&k| !inside(corners[k]) && inside(corners[(k + 1) % n]))
        else {
            return false;
        };
        let mut stretches: Vec<Vec<u32>> = Vec::new();
        for step in 0..n {
            let k = (start + step) % n;
            let (a, b) = (corners[k], corners[(k + 1) % n]);
            if inside(a) != inside(b) {
                let x = crossings.on_edge(parent, side, a, b);
                if inside(a) {
                    stretches.last_mut().expect("an entry came first").push(x);
                } else {
                    stretches.push(vec![x]);
                }
            }
            if inside(b) {
                stretches.last_mut().expect("an entry came first").push(b);
            }
        }
        // Crossings along the line, each with its stretch and whether it ends it (exit).
        let at = |id: u32| crossings.point(parent, id);
        let origin = at(stretches[0][0]);
        let far = stretches
            .iter()
            .flat_map(|s| [s[0], s[s.len() - 1]])
            .map(at)
            .max_by(|p, q| {
                (*p - origin)
                    .length_squared()
                    .total_cmp(&(*q - origin).length_squared())
            })
            .expect("stretches");
        let along = (far - origin).normalize_or_zero();
        let mut ends: Vec<(f64, usize, bool)> = Vec::with_capacity(2 * stretches.len());
        for (i, s) in stretches.iter().enumerate() {
            ends.push(((at(s[0]) - origin).dot(along), i, false));
            ends.push(((at(s[s.len() - 1]) - origin).dot(along), i, true));
        }
        ends.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Pair by pair: a segment of the line inside the loop, from one stretch's exit to
        // the entry of the stretch that follows it.
        let joins: Option<Vec<(usize, usize)>> = ends
            .chunks_exact(2)
            .map(|pair| match (pair[0], pair[1]) {
                ((_, exit, true), (_, entry, false)) | ((_, entry, false), (_, exit, true)) => {
                    Some((exit, entry))
                }
                _ => None,
            })
            .collect();
        let Some(joins) = joins else {
            return false;
        };
        let mut next = vec![usize::MAX; stretches.len()];
        for (exit, entry) in joins {
            next[exit] = entry;
            // The new cap runs along the segment the other way: entry → exit.
            let exit_id = *stretches[exit].last().expect("a stretch ends at its exit");
            self.cap_edges.push([stretches[entry][0], exit_id]);
        }
        let mut done = vec![false; stretches.len()];
        for first in 0..stretches.len() {
            let mut ids = Vec::new();
            let mut s = first;
            while !done[s] {
                done[s] = true;
                ids.extend_from_slice(&stretches[s]);
                s = next[s];
            }
            if ids.len() >= 3 {
                self.push_loop(parent, crossings, &ids, kind.surface, kind.cut);
            }
        }
        true
    }

    fn push_loop(
        &mut self,
        parent: &Piece,
        crossings: &Crossings,
        ids: &[u32],
        surface: bool,
        cut: u32,
    ) {
        let start = self.piece.corners.len() as u32;
        for &id in ids {
            let local = self.local(parent, crossings, id);
            self.piece.corners.push(local);
        }
        self.piece.loops.push(Loop {
            start,
            len: ids.len() as u32,
            surface,
            cut,
        });
    }

    fn local(&mut self, parent: &Piece, crossings: &Crossings, id: u32) -> u32 {
        let id = id as usize;
        if id >= self.renumber.len() {
            self.renumber.resize(id + 1, u32::MAX);
        }
        if self.renumber[id] == u32::MAX {
            self.renumber[id] = self.piece.points.len() as u32;
            self.piece.points.push(crossings.point(parent, id as u32));
        }
        self.renumber[id]
    }

    /// Chains the cap edges into outlines and adds them as cap loops.
    fn finish(mut self, parent: &Piece, crossings: &Crossings, forced: usize, cut: u32) -> Piece {
        let edges = std::mem::take(&mut self.cap_edges);
        let (outlines, forced_now) = chain_outlines(&edges);
        for outline in outlines {
            if outline.len() >= 3 {
                self.push_loop(parent, crossings, &outline, false, cut);
            }
        }
        self.piece.forced_caps = forced + forced_now;
        self.piece
    }
}

/// Chains directed edges into closed outlines, following each edge by one that starts where
/// it ends. An edge with no follower closes its outline straight back to the start: returns
/// how many outlines that forced (0 on a closed input).
pub(super) fn chain_outlines(edges: &[[u32; 2]]) -> (Vec<Vec<u32>>, usize) {
    let mut starting: HashMap<u32, Vec<usize>> = HashMap::with_capacity(edges.len());
    for (i, e) in edges.iter().enumerate() {
        starting.entry(e[0]).or_default().push(i);
    }
    let mut used = vec![false; edges.len()];
    let (mut outlines, mut forced) = (Vec::new(), 0);
    for first in 0..edges.len() {
        if used[first] {
            continue;
        }
        used[first] = true;
        let origin = edges[first][0];
        let mut outline = vec![origin];
        let mut at = edges[first][1];
        while at != origin {
            outline.push(at);
            let next = starting.get_mut(&at).and_then(|list| {
                list.iter()
                    .position(|&e| !used[e])
                    .map(|k| list.swap_remove(k))
            });
            match next {
                Some(e) => {
                    used[e] = true;
                    at = edges[e][1];
                }
                None => {
                    forced += 1;
                    break;
                }
            }
        }
        outlines.push(outline);
    }
    (outlines, forced)
}
