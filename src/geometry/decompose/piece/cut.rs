//! The plane cut that makes two pieces of one.
//!
//! Each point's side is decided once per cut, so both pieces and all loops agree on it:
//! below, above, or **on** the plane (within [`ON_PLANE`] of it, relative to the piece's
//! coordinates). A point on the plane belongs to both sides.
//!
//! 1. **Loops that cross the plane** are clipped to each side (Sutherland–Hodgman), with one
//!    point per edge that goes from strictly below to strictly above, shared by the loops on
//!    both sides of that edge. A clipped loop with no corner strictly on its side has no
//!    area there and is dropped.
//! 2. **Loops that lie on the plane** (every corner on it: a mesh face along a cut) go whole
//!    to the side their solid is on, opposite their outward normal. Splitting them by the
//!    sign of a rounding error would give the other side a face whose solid is not there,
//!    closed by a cap over it: a zero-volume fin whose corners stretch that side's hull.
//! 3. **The cap** of each side closes what the first two leave open: the edges on the plane
//!    whose reverse no loop of that side holds (the clipped loops' closing edges, and edges
//!    along the plane whose other face went to the other side), reversed and chained into
//!    outlines. It therefore covers exactly where the plane crosses solid.
//!
//! A cap can be concave, and a cut can leave several stretches of it on one side: those are
//! joined along the cut line where the cap lies on it ([`Clipper::clip_stretches`]), never
//! across a gap, so every corner of a piece lies in the solid.

use super::{Loop, Piece, Plane};
use crate::math::DVec3;
use std::collections::HashMap;

/// A point within this fraction of the cut's scale lies on the plane (the scale: the largest
/// of the piece's coordinate magnitudes, its points' distances from the plane and the
/// plane's offset): a few hundred times the rounding of a signed distance, so a plane
/// through a mesh face finds all of its corners.
const ON_PLANE: f64 = 1e-12;

impl Piece {
    /// The two pieces on either side of `plane`: `(below, above)`. `None` unless some corner
    /// is strictly below and some strictly above (the cut would change nothing).
    pub fn cut(&self, plane: &Plane) -> Option<(Piece, Piece)> {
        let mut cutting = Cutting::new(self, plane)?;
        let mut lower = Clipper::new(self.points.len(), Side::Below);
        let mut upper = Clipper::new(self.points.len(), Side::Above);
        for &l in &self.loops {
            let corners = self.loop_corners(l);
            if corners.iter().all(|&c| cutting.side(c) == Side::On) {
                // Counter-clockwise from outside: the area vector points out of the solid.
                if self.area_vector(corners).dot(plane.normal) >= 0.0 {
                    lower.push_loop(&cutting, corners, l);
                } else {
                    upper.push_loop(&cutting, corners, l);
                }
                continue;
            }
            lower.clip(&mut cutting, corners, l);
            upper.clip(&mut cutting, corners, l);
        }
        let new_cut = self.cuts.len() as u32;
        let (mut below, mut above) = (
            lower.finish(&cutting, self.forced_caps, new_cut),
            upper.finish(&cutting, self.forced_caps, new_cut),
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

    /// Twice the loop's area times its unit normal (the sum of its fan's cross products), m².
    fn area_vector(&self, corners: &[u32]) -> DVec3 {
        let o = self.points[corners[0] as usize];
        corners[1..].windows(2).fold(DVec3::ZERO, |sum, w| {
            let (b, c) = (self.points[w[0] as usize], self.points[w[1] as usize]);
            sum + (b - o).cross(c - o)
        })
    }
}

/// Where a point lies against the cut's plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Below,
    On,
    Above,
}

/// One cut in progress: the parent piece, each of its points' side, and the crossing points
/// both sides share.
struct Cutting<'a> {
    parent: &'a Piece,
    /// The plane's unit normal.
    normal: DVec3,
    /// Signed distance of each parent point above the plane, metres.
    distance: Vec<f64>,
    side: Vec<Side>,
    crossings: Crossings,
}

impl<'a> Cutting<'a> {
    /// `None` unless some corner is strictly below and some strictly above.
    fn new(parent: &'a Piece, plane: &Plane) -> Option<Self> {
        let distance: Vec<f64> = parent
            .points
            .iter()
            .map(|&p| plane.signed_distance(p))
            .collect();
        let scale = parent
            .points
            .iter()
            .zip(&distance)
            .fold(plane.offset.abs(), |m, (p, d)| {
                m.max(p.abs().max_element()).max(d.abs())
            });
        let tolerance = ON_PLANE * scale;
        let side: Vec<Side> = distance
            .iter()
            .map(|&d| {
                if d < -tolerance {
                    Side::Below
                } else if d > tolerance {
                    Side::Above
                } else {
                    Side::On
                }
            })
            .collect();
        let has = |s: Side| parent.corners.iter().any(|&c| side[c as usize] == s);
        if !(has(Side::Below) && has(Side::Above)) {
            return None;
        }
        Some(Self {
            parent,
            normal: plane.normal,
            distance,
            side,
            crossings: Crossings::new(parent.points.len()),
        })
    }

    /// The side of parent point `id`.
    fn side(&self, id: u32) -> Side {
        self.side[id as usize]
    }

    /// Whether the edge `a–b` goes from strictly one side to strictly the other.
    fn crosses(&self, a: u32, b: u32) -> bool {
        matches!(
            (self.side(a), self.side(b)),
            (Side::Below, Side::Above) | (Side::Above, Side::Below)
        )
    }

    /// The crossing on edge `a–b` (see [`Self::crosses`]), made once.
    fn crossing(&mut self, a: u32, b: u32) -> u32 {
        self.crossings.on_edge(self.parent, &self.distance, a, b)
    }

    /// Whether point `id` (parent or crossing) lies on the plane.
    fn on_plane(&self, id: u32) -> bool {
        id >= self.crossings.first_id || self.side(id) == Side::On
    }

    fn point(&self, id: u32) -> DVec3 {
        self.crossings.point(self.parent, id)
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

    /// The crossing on edge `a–b` (their signed distances strictly differ in sign), made once.
    fn on_edge(&mut self, piece: &Piece, distance: &[f64], a: u32, b: u32) -> u32 {
        let key = (a.min(b), a.max(b));
        if let Some(&id) = self.by_edge.get(&key) {
            return id;
        }
        // Interpolated from the low index so both loops of the edge get the same point.
        let (lo, hi) = key;
        let (s_lo, s_hi) = (distance[lo as usize], distance[hi as usize]);
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

/// Builds one side's piece: its loops, their corners renumbered, and its edges on the plane.
struct Clipper {
    /// The side kept (besides the points on the plane).
    keeps: Side,
    piece: Piece,
    /// Parent (or crossing) id → this piece's point index, `u32::MAX` until used.
    renumber: Vec<u32>,
    /// Directed edges of this side's loops with both ends on the plane, in parent/crossing
    /// ids: the cap is made of those left unmatched.
    plane_edges: Vec<[u32; 2]>,
    scratch: Vec<u32>,
}

impl Clipper {
    fn new(parent_points: usize, keeps: Side) -> Self {
        Self {
            keeps,
            piece: Piece::default(),
            renumber: vec![u32::MAX; parent_points],
            plane_edges: Vec::new(),
            scratch: Vec::new(),
        }
    }

    /// Whether parent point `id` belongs to this side.
    fn keeps(&self, cutting: &Cutting, id: u32) -> bool {
        let side = cutting.side(id);
        side == Side::On || side == self.keeps
    }

    /// Whether `ids` holds a point strictly on this side: a loop without one lies on the
    /// plane and has no area here.
    fn has_area(&self, cutting: &Cutting, ids: &[u32]) -> bool {
        ids.iter()
            .any(|&id| id < cutting.crossings.first_id && cutting.side(id) == self.keeps)
    }

    /// Clips one loop that crosses the plane to this side (Sutherland–Hodgman); its closing
    /// edges along the plane become cap edges in [`Self::finish`].
    fn clip(&mut self, cutting: &mut Cutting, corners: &[u32], kind: Loop) {
        // Only a cap can be concave enough to leave several stretches on one side (surface
        // loops are convex).
        if !kind.surface && self.clip_stretches(cutting, corners, kind) {
            return;
        }
        let n = corners.len();
        let mut kept = std::mem::take(&mut self.scratch);
        kept.clear();
        for (k, &a) in corners.iter().enumerate() {
            let b = corners[(k + 1) % n];
            if self.keeps(cutting, a) {
                kept.push(a);
            }
            if cutting.crosses(a, b) {
                kept.push(cutting.crossing(a, b));
            }
        }
        if kept.len() >= 3 && self.has_area(cutting, &kept) {
            self.push_loop(cutting, &kept, kind);
        }
        self.scratch = kept;
    }

    /// Clips a loop that may enter and leave this side more than once (a concave cap): each
    /// stretch kept runs from an entry to an exit on the plane, and the stretches are joined
    /// along the cut line the way the loop's own region lies on it. Sorted along the line,
    /// the stretches' ends bound, pair by pair, the line's segments inside the loop; each
    /// pair joins an exit to an entry. (Sutherland–Hodgman would join the stretches in walk
    /// order instead, by bridges across the gaps between them: outside the solid, and a
    /// later cut through a bridge would put a corner there.)
    ///
    /// An edge along the plane whose region lies on the other side ends a stretch too: the
    /// loop only touches this side there. A stretch of points on the plane alone has no
    /// area but is joined like the others, so the joins pass through its corners, as the
    /// loops beside them do.
    ///
    /// Returns `false` when the loop never leaves this side, or when the sorted ends do not
    /// pair up so (ties of near-coincident points), having added nothing to the piece: the
    /// caller then clips it the plain way.
    fn clip_stretches(&mut self, cutting: &mut Cutting, corners: &[u32], kind: Loop) -> bool {
        let Some(stretches) = self.stretches(cutting, corners) else {
            return false;
        };
        let Some(next) = joins_along_line(cutting, &stretches) else {
            return false;
        };
        let mut done = vec![false; stretches.len()];
        for first in 0..stretches.len() {
            let mut ids = Vec::new();
            let mut s = first;
            while !done[s] {
                done[s] = true;
                ids.extend_from_slice(&stretches[s]);
                s = next[s];
            }
            if ids.len() >= 3 && self.has_area(cutting, &ids) {
                self.push_loop(cutting, &ids, kind);
            }
        }
        true
    }

    /// The stretches of `corners` this side keeps, in walk order, each from its entry to its
    /// exit (crossings included); `None` when the loop never leaves this side.
    fn stretches(&self, cutting: &mut Cutting, corners: &[u32]) -> Option<Vec<Vec<u32>>> {
        let n = corners.len();
        let area = cutting.parent.area_vector(corners);
        let toward_kept = if self.keeps == Side::Below {
            -cutting.normal
        } else {
            cutting.normal
        };
        // A step from `a` to `b` that enters this side: from outside, or past an edge along
        // the plane whose region is on the other side (left of the edge, seen from outside).
        let enters = |a: u32, b: u32| {
            let (keeps_a, keeps_b) = (self.keeps(cutting, a), self.keeps(cutting, b));
            (!keeps_a && keeps_b)
                || (cutting.side(a) == Side::On
                    && cutting.side(b) == Side::On
                    && area
                        .cross(cutting.point(b) - cutting.point(a))
                        .dot(toward_kept)
                        < 0.0)
        };
        // Walk from an entry so that every stretch is whole.
        let start = (0..n).find(|&k| enters(corners[k], corners[(k + 1) % n]))?;
        let steps: Vec<(u32, u32, bool)> = (0..n)
            .map(|step| {
                let k = start + step;
                let (a, b) = (corners[k % n], corners[(k + 1) % n]);
                (a, b, enters(a, b))
            })
            .collect();
        let mut stretches: Vec<Vec<u32>> = Vec::new();
        for (a, b, entry) in steps {
            if entry {
                stretches.push(Vec::new());
            }
            let stretch = stretches.last_mut().expect("the walk starts at an entry");
            if cutting.crosses(a, b) {
                stretch.push(cutting.crossing(a, b));
            }
            if self.keeps(cutting, b) {
                stretch.push(b);
            }
        }
        Some(stretches)
    }

    /// Adds a loop over parent/crossing `ids`, noting its edges on the plane.
    fn push_loop(&mut self, cutting: &Cutting, ids: &[u32], kind: Loop) {
        for (k, &a) in ids.iter().enumerate() {
            let b = ids[(k + 1) % ids.len()];
            if a != b && cutting.on_plane(a) && cutting.on_plane(b) {
                self.plane_edges.push([a, b]);
            }
        }
        let start = self.piece.corners.len() as u32;
        for &id in ids {
            let local = self.local(cutting, id);
            self.piece.corners.push(local);
        }
        self.piece.loops.push(Loop {
            start,
            len: ids.len() as u32,
            ..kind
        });
    }

    fn local(&mut self, cutting: &Cutting, id: u32) -> u32 {
        let id = id as usize;
        if id >= self.renumber.len() {
            self.renumber.resize(id + 1, u32::MAX);
        }
        if self.renumber[id] == u32::MAX {
            self.renumber[id] = self.piece.points.len() as u32;
            self.piece.points.push(cutting.point(id as u32));
        }
        self.renumber[id]
    }

    /// Closes the side with its cap: the edges on the plane left unmatched, reversed and
    /// chained into outlines.
    fn finish(mut self, cutting: &Cutting, forced: usize, cut: u32) -> Piece {
        let cap_edges = unmatched_reversed(&self.plane_edges);
        let (outlines, forced_now) = chain_outlines(&cap_edges);
        let cap = Loop {
            start: 0,
            len: 0,
            surface: false,
            cut,
        };
        for outline in outlines {
            if outline.len() >= 3 {
                self.push_loop(cutting, &outline, cap);
            }
        }
        self.piece.forced_caps = forced + forced_now;
        self.piece
    }
}

/// For each stretch (every one non-empty, from its entry to its exit on the line), the
/// stretch its exit joins along the line: sorted along the line, the ends bound pair by pair
/// the line's segments inside the loop, each from an exit to the entry that follows it.
/// `None` when the sorted ends do not pair up so.
fn joins_along_line(cutting: &Cutting, stretches: &[Vec<u32>]) -> Option<Vec<usize>> {
    let first = |s: &Vec<u32>| s[0];
    let last = |s: &Vec<u32>| s[s.len() - 1];
    let origin = cutting.point(first(&stretches[0]));
    let far = stretches
        .iter()
        .flat_map(|s| [first(s), last(s)])
        .map(|id| cutting.point(id))
        .max_by(|p, q| {
            (*p - origin)
                .length_squared()
                .total_cmp(&(*q - origin).length_squared())
        })?;
    let along = (far - origin).normalize_or_zero();
    // Each end: its place along the line, its stretch, and whether it is the exit.
    let mut ends: Vec<(f64, usize, bool)> = Vec::with_capacity(2 * stretches.len());
    for (i, s) in stretches.iter().enumerate() {
        ends.push(((cutting.point(first(s)) - origin).dot(along), i, false));
        ends.push(((cutting.point(last(s)) - origin).dot(along), i, true));
    }
    ends.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut next = vec![usize::MAX; stretches.len()];
    for pair in ends.chunks_exact(2) {
        match (pair[0], pair[1]) {
            ((_, exit, true), (_, entry, false)) | ((_, entry, false), (_, exit, true)) => {
                next[exit] = entry;
            }
            _ => return None,
        }
    }
    Some(next)
}

/// The directed edges that no reverse edge cancels, each reversed (what closes them), in an
/// order fixed by the edges alone.
fn unmatched_reversed(edges: &[[u32; 2]]) -> Vec<[u32; 2]> {
    // Each edge as its (low, high) key and +1 forward (low → high) or −1 backward.
    let mut keyed: Vec<((u32, u32), i32)> = edges
        .iter()
        .map(|&[a, b]| if a < b { ((a, b), 1) } else { ((b, a), -1) })
        .collect();
    keyed.sort_unstable();
    let mut reversed = Vec::new();
    for group in keyed.chunk_by(|x, y| x.0 == y.0) {
        let (lo, hi) = group[0].0;
        let net: i32 = group.iter().map(|&(_, s)| s).sum();
        let closing = if net > 0 { [hi, lo] } else { [lo, hi] };
        reversed.extend(std::iter::repeat_n(closing, net.unsigned_abs() as usize));
    }
    reversed
}

/// Chains directed edges into closed outlines, following each edge by one that starts where
/// it ends. An edge with no follower closes its outline straight back to the start: returns
/// how many outlines that forced (0 on a closed input).
pub(in crate::geometry::decompose) fn chain_outlines(edges: &[[u32; 2]]) -> (Vec<Vec<u32>>, usize) {
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
