//! Expanding polytope algorithm: the penetration depth of two overlapping convex sets.
//!
//! Starts from GJK's final simplex (which holds the origin), blows a point, segment or
//! triangle up to a tetrahedron with support points along directions that leave its span,
//! then repeatedly pushes out the face of the polytope nearest to the origin by the support
//! point along its normal, until the support point is no farther than the face (to
//! tolerance). The nearest face's plane then is the boundary of `A − B` nearest the origin:
//! depth = its distance, normal A→B = its outward normal (van den Bergen, "Proximity queries
//! and penetration depth computation on 3D game objects", GDC 2001).
//!
//! # Fallback
//! When `A − B` has no volume (flat or needle shapes), when the polytope runs out of
//! capacity or iterations, or when rounding breaks its convexity, the answer is
//! [`EpaOutcome::Fallback`] ([`EpaOutcome::RoundingLimited`] for the last): the direction
//! `n` with the smallest support value `h(n)` among the polytope's face normals evaluated so
//! far (or, without a tetrahedron, among the normals of the span's complement), depth
//! `max(h(n), 0)`. Translating B by that depth along `n`
//! always separates the shapes, so the fallback over-estimates the depth, never under.
//! Its witnesses keep `point_a − point_b = depth · normal` exactly: `point_a` is a point of A
//! (the origin's projection on the face of that normal, or GJK's common point of A and B
//! when no tetrahedron could be built) and `point_b = point_a − depth · normal`, which may
//! lie off B's surface by the depth's uncertainty. Without a tetrahedron `A − B` is flat
//! through the origin and the depth is 0 (to rounding), so both witnesses are GJK's common
//! point.
//!
//! The polytope's vertices are points of `A − B` and it holds the origin, so its nearest
//! face's distance is a lower bound on the depth: a fallback states it as
//! [`EpaResult::depth_lower`] (0 without a tetrahedron), raised to the depth when the two
//! are within the convergence tolerance (the answer is then as good as a converged one).
//!
//! Buffers live in an [`EpaWorkspace`] of fixed capacity, so a query allocates nothing.

use super::simplex::{Simplex, SupportPoint};
use super::{GjkParams, floor, support};
use crate::budget::WorkClock;
use crate::geometry::SupportMap;
use crate::math::{DVec3, Isometry, orthonormal_basis};

/// Units of [`WorkClock`] work one expansion counts for (a support query and a scan of up
/// to 512 faces).
pub const EXPANSION_WORK: u64 = 16;

/// Most polytope vertices.
const MAX_VERTICES: usize = 256;
/// Most polytope faces (a closed triangulation of `V` vertices has `2V − 4`).
const MAX_FACES: usize = 2 * MAX_VERTICES;

/// How EPA ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EpaOutcome {
    /// The nearest face was confirmed to tolerance.
    Converged,
    /// Its clock stopped it first: the answer is the fallback's (an over-estimated depth
    /// along a valid direction), and [`EpaResult::depth_lower`] the polytope's nearest face
    /// distance, an under-estimate.
    Stopped,
    /// See the [module docs](self): an upper bound on the depth along a valid direction,
    /// and [`EpaResult::depth_lower`] the polytope's lower bound.
    Fallback,
    /// The fallback's answer when rounding broke the polytope (a new face had the origin
    /// outside): on curved differences this happens near the answer, with a gap a few
    /// times the tolerance, which further expansions could not close.
    RoundingLimited,
}

/// The answer of [`penetration`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpaResult {
    /// How it ended.
    pub outcome: EpaOutcome,
    /// Penetration depth, metres (≥ 0 up to rounding).
    pub depth: f64,
    /// Unit normal A→B: translating B by `depth · normal` makes the shapes touch.
    pub normal: DVec3,
    /// Deepest point of A (A's frame).
    pub point_a: DVec3,
    /// Deepest point of B (A's frame); `point_a − point_b = depth · normal`.
    pub point_b: DVec3,
    /// Polytope expansions.
    pub iterations: u32,
    /// A lower bound on the depth, metres: `depth` when converged; otherwise the polytope's
    /// nearest face distance (the polytope lies inside `A − B`), 0 without a polytope, and
    /// `depth` when the gap is within the convergence tolerance. `depth_lower < depth`
    /// means the depth is known only between the two.
    pub depth_lower: f64,
}

#[derive(Debug, Clone, Copy)]
struct Face {
    v: [u32; 3],
    normal: DVec3,
    dist: f64,
}

impl Face {
    /// A removed face's slot: like a degenerate face (zero normal, infinite distance), it
    /// is never nearest while a live face is finite and never sees a point, so every pass
    /// over the faces skips it without a test of its own.
    const DEAD: Self = Self {
        v: [u32::MAX; 3],
        normal: DVec3::ZERO,
        dist: f64::INFINITY,
    };
}

/// Reused buffers of [`penetration`]; allocate once per thread.
#[derive(Debug, Clone)]
pub struct EpaWorkspace {
    vertices: Vec<SupportPoint>,
    /// Live faces and dead ones ([`Face::DEAD`]), whose slots `free` lists for reuse.
    faces: Vec<Face>,
    free: Vec<u32>,
    edges: Vec<(u32, u32)>,
}

impl Default for EpaWorkspace {
    fn default() -> Self {
        Self::new()
    }
}

impl EpaWorkspace {
    /// Buffers at full capacity.
    #[must_use]
    pub fn new() -> Self {
        Self {
            vertices: Vec::with_capacity(MAX_VERTICES),
            faces: Vec::with_capacity(MAX_FACES),
            free: Vec::with_capacity(MAX_FACES),
            edges: Vec::with_capacity(3 * MAX_FACES),
        }
    }
}

/// Tracks the best upper bound `h(n)` seen: the fallback answer.
struct Fallback {
    h: f64,
    normal: DVec3,
    a: DVec3,
}

impl Fallback {
    fn new() -> Self {
        Self {
            h: f64::INFINITY,
            normal: DVec3::Z,
            a: DVec3::ZERO,
        }
    }

    /// Offers direction `n` with its support point `p`; `a` is a point of A that the
    /// witnesses start from if `n` wins.
    fn offer(&mut self, n: DVec3, p: &SupportPoint, a: DVec3) {
        self.offer_with(n, p, || a);
    }

    /// [`offer`](Self::offer) computing the witness start only when `n` wins.
    // PERF: a face's witness costs a barycentric solve; most offers lose
    // (`benches/pile.rs`, cylinder pairs' EPA).
    #[inline]
    fn offer_with(&mut self, n: DVec3, p: &SupportPoint, a: impl FnOnce() -> DVec3) {
        let h = p.w.dot(n);
        if h < self.h {
            *self = Self {
                h,
                normal: n,
                a: a(),
            };
        }
    }

    /// The fallback's answer, ended by `outcome` after `iterations` expansions with the
    /// polytope's nearest face at `face_distance` from the origin (0 without a polytope):
    /// its depth is known down to that face, or to itself when the gap is at most
    /// `tolerance` (the convergence criterion's, [`EpaOutcome::Stopped`] excepted).
    fn result(
        &self,
        outcome: EpaOutcome,
        iterations: u32,
        face_distance: f64,
        tolerance: f64,
    ) -> EpaResult {
        let depth = self.h.max(0.0);
        let lower = face_distance.max(0.0).min(depth);
        let converged = outcome != EpaOutcome::Stopped && depth - lower <= tolerance;
        EpaResult {
            outcome,
            depth,
            normal: self.normal,
            point_a: self.a,
            point_b: self.a - self.normal * depth,
            iterations,
            depth_lower: if converged { depth } else { lower },
        }
    }
}

#[inline]
fn face(vs: &[SupportPoint], v: [u32; 3]) -> Face {
    let [a, b, c] = v.map(|i| vs[i as usize].w);
    let n = (b - a).cross(c - a);
    let len = n.length();
    if len > 0.0 && len.is_finite() {
        let normal = n / len;
        // Average of the three offsets: less biased than any one vertex.
        let dist = (normal.dot(a) + normal.dot(b) + normal.dot(c)) / 3.0;
        Face { v, normal, dist }
    } else {
        Face {
            v,
            normal: DVec3::ZERO,
            dist: f64::INFINITY,
        }
    }
}

/// The penetration depth of `a` and `b` (placed by `pose_ab`) from GJK's final `simplex`,
/// whose convex hull holds the origin (GJK outcome `Penetrating` or `Touching`).
///
/// Never NaN for finite input; see the module docs for the fallback.
///
/// `clock` is polled before each expansion ([`EXPANSION_WORK`] units); stopped, the answer
/// is [`EpaOutcome::Stopped`].
#[must_use]
pub fn penetration<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    simplex: &Simplex,
    params: &GjkParams,
    ws: &mut EpaWorkspace,
    clock: &mut WorkClock,
) -> EpaResult {
    let mut hints = [0; 2];
    let mut sup = |d: DVec3| support(a, b, pose_ab, d, &mut hints);
    let mut fallback = Fallback::new();
    ws.vertices.clear();
    ws.faces.clear();
    ws.free.clear();
    ws.vertices.extend_from_slice(simplex.points());
    let common = simplex.closest().a;
    let mut scale = ws
        .vertices
        .iter()
        .map(|p| p.a.abs().max_element().max(p.b.abs().max_element()))
        .fold(0.0, f64::max);
    // The convergence criterion's allowed gap above a face at distance `d`.
    let gap = |d: f64, scale: f64| params.epa_rel_tol * d.abs() + floor(params, scale);
    if !blow_up_to_tetrahedron(&mut sup, params, ws, &mut fallback, common, &mut scale) {
        return fallback.result(EpaOutcome::Fallback, 0, 0.0, gap(0.0, scale));
    }
    start_faces(ws);

    let mut iterations = 0;
    // The polytope's nearest face distance: a lower bound on the depth.
    let mut lower = 0.0;
    while iterations < params.max_iterations {
        iterations += 1;
        let Some(best_i) = nearest_face(&ws.faces) else {
            break;
        };
        let best = ws.faces[best_i];
        if !best.dist.is_finite() {
            break;
        }
        lower = best.dist;
        let p = sup(best.normal);
        if !clock.allows(EXPANSION_WORK) {
            // The nearest face's direction is always offered, so the answer is finite.
            if p.w.is_finite() {
                fallback.offer_with(best.normal, &p, || face_point_a(&ws.vertices, &best));
            }
            return fallback.result(EpaOutcome::Stopped, iterations - 1, best.dist, 0.0);
        }
        if !p.w.is_finite() {
            break;
        }
        fallback.offer_with(best.normal, &p, || face_point_a(&ws.vertices, &best));
        scale = scale.max(p.a.abs().max_element().max(p.b.abs().max_element()));
        let tol = floor(params, scale);
        let h = p.w.dot(best.normal);
        if h - best.dist <= gap(best.dist, scale) {
            // Coplanar faces tie on distance; the witnesses need the one whose triangle holds
            // the origin's projection. Only faces in the confirmed plane qualify: a face
            // through the origin at another angle has distance 0 too but no certificate.
            let near = best.dist + (tol + 1e-9 * scale).max(h - best.dist);
            let f = ws
                .faces
                .iter()
                .filter(|f| f.dist <= near && f.normal.dot(best.normal) >= 1.0 - 1e-9)
                .map(|f| (inside(&ws.vertices, f), f))
                .max_by(|x, y| x.0.total_cmp(&y.0))
                .map_or(best, |(_, f)| *f);
            return converged(&ws.vertices, &f, iterations);
        }
        if ws.vertices.len() == MAX_VERTICES {
            break;
        }
        match expand(ws, p, best_i, tol) {
            Expansion::Grown => {}
            Expansion::Full => break,
            // The origin fell outside a new face: rounding broke the polytope (the one
            // before this expansion still bounds the depth from below).
            Expansion::Broken => {
                let tolerance = gap(lower.max(0.0), scale);
                return fallback.result(EpaOutcome::RoundingLimited, iterations, lower, tolerance);
            }
        }
    }
    fallback.result(
        EpaOutcome::Fallback,
        iterations,
        lower,
        gap(lower.max(0.0), scale),
    )
}

/// The index of the first face of least distance; `None` when there is no face. Distances
/// are never NaN: a degenerate face ([`face`]) and a dead one ([`Face::DEAD`]) are infinitely
/// far.
// PERF: compares the distances in place; `min_by` over copied faces moved every 48-byte
// face through the stack (a fifth of EPA's time, `benches/pile.rs` cylinder pairs). A plain
// `<` in place of `total_cmp`'s bit twiddling took a fifth of what was left (`curved_depth`).
#[inline]
fn nearest_face(faces: &[Face]) -> Option<usize> {
    let first = faces.first()?;
    let (mut best_i, mut best_dist) = (0, first.dist);
    for (i, f) in faces.iter().enumerate().skip(1) {
        if f.dist < best_dist {
            (best_i, best_dist) = (i, f.dist);
        }
    }
    Some(best_i)
}

/// Grows `ws.vertices` (GJK's 1 to 4 points) to a tetrahedron by support points farthest
/// from their span, offering each to `fallback`; `false` when no direction leaves the span
/// (the Minkowski difference is flat there: the fallback answers).
#[inline]
fn blow_up_to_tetrahedron(
    sup: &mut impl FnMut(DVec3) -> SupportPoint,
    params: &GjkParams,
    ws: &mut EpaWorkspace,
    fallback: &mut Fallback,
    common: DVec3,
    scale: &mut f64,
) -> bool {
    while ws.vertices.len() < 4 {
        let vs = &ws.vertices;
        let tol = floor(params, *scale);
        let (dirs, n_dirs): ([DVec3; 6], usize) = match vs.len() {
            1 => (
                // +X first: when A − B is a single point, every direction ties and the
                // first wins, which is the documented normal of coincident shapes (the
                // closed forms' choice too).
                [
                    DVec3::X,
                    DVec3::NEG_X,
                    DVec3::Y,
                    DVec3::NEG_Y,
                    DVec3::Z,
                    DVec3::NEG_Z,
                ],
                6,
            ),
            2 => {
                let e = vs[1].w - vs[0].w;
                let (u, v) = orthonormal_basis(e.normalize_or(DVec3::Z));
                let h = 0.5 * 3f64.sqrt();
                (
                    [
                        u,
                        u * -0.5 + v * h,
                        u * -0.5 - v * h,
                        -u,
                        u * 0.5 - v * h,
                        u * 0.5 + v * h,
                    ],
                    6,
                )
            }
            _ => {
                let n = (vs[1].w - vs[0].w)
                    .cross(vs[2].w - vs[0].w)
                    .normalize_or(DVec3::Z);
                ([n, -n, n, n, n, n], 2)
            }
        };
        // The candidate farthest from the current span.
        let mut best: Option<(f64, SupportPoint)> = None;
        for &d in &dirs[..n_dirs] {
            let p = sup(d);
            if !p.w.is_finite() {
                continue;
            }
            fallback.offer(d, &p, common);
            let off = off_span(vs, p.w);
            if best.is_none_or(|(o, _)| off > o) {
                best = Some((off, p));
            }
        }
        match best {
            Some((off, p)) if off > tol.max(1e-12 * span_size(vs)) => {
                *scale = scale.max(p.a.abs().max_element().max(p.b.abs().max_element()));
                ws.vertices.push(p);
            }
            _ => return false,
        }
    }
    true
}

/// The tetrahedron's four faces, each turned outward (away from its centre).
#[inline]
fn start_faces(ws: &mut EpaWorkspace) {
    let centre = ws.vertices.iter().map(|p| p.w).sum::<DVec3>() / 4.0;
    for f in [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]] {
        let mut fc = face(&ws.vertices, f);
        if fc.normal.dot(centre - ws.vertices[f[0] as usize].w) > 0.0 {
            fc = face(&ws.vertices, [f[0], f[2], f[1]]);
        }
        ws.faces.push(fc);
    }
}

/// What adding a support point did to the polytope.
enum Expansion {
    /// The point joined: the faces that saw it were replaced by its cone over their horizon.
    Grown,
    /// No room for the new faces, or a degenerate horizon: stop with the best so far.
    Full,
    /// A new face has the origin outside: rounding broke the polytope.
    Broken,
}

/// Adds `p` to the polytope: removes the faces that see it (face `best_i` always), keeps
/// their horizon (edges not shared by two of them) and closes it with faces through `p`.
#[inline]
fn expand(ws: &mut EpaWorkspace, p: SupportPoint, best_i: usize, tol: f64) -> Expansion {
    let new = ws.vertices.len() as u32;
    ws.vertices.push(p);
    ws.edges.clear();
    // The faces that see `p` die in place; their slots take the new faces.
    // PERF: no compaction (every kept 48-byte face was moved down each expansion). With the
    // visibility test below, `curved_depth/cylinder_cylinder` went 8.7 → 7.2 µs
    // (`benches/narrow_phase.rs`).
    for i in 0..ws.faces.len() {
        let f = ws.faces[i];
        // The face's plane offset `dist` stands for its vertices' (their mean): no vertex
        // load per face.
        let sees = i == best_i || (f.normal != DVec3::ZERO && f.normal.dot(p.w) - f.dist > tol);
        if sees {
            for k in 0..3 {
                let e = (f.v[k], f.v[(k + 1) % 3]);
                if let Some(j) = ws.edges.iter().position(|&x| x == (e.1, e.0)) {
                    ws.edges.swap_remove(j);
                } else {
                    ws.edges.push(e);
                }
            }
            ws.faces[i] = Face::DEAD;
            ws.free.push(i as u32);
        }
    }
    let live = ws.faces.len() - ws.free.len();
    if ws.edges.len() < 3 || live + ws.edges.len() > MAX_FACES {
        return Expansion::Full;
    }
    for k in 0..ws.edges.len() {
        let (i, j) = ws.edges[k];
        let f = face(&ws.vertices, [i, j, new]);
        if f.dist < -tol {
            return Expansion::Broken;
        }
        match ws.free.pop() {
            Some(slot) => ws.faces[slot as usize] = f,
            None => ws.faces.push(f),
        }
    }
    Expansion::Grown
}

/// Distance of `w` from the affine span of `vs` (1 to 3 points).
fn off_span(vs: &[SupportPoint], w: DVec3) -> f64 {
    let d = w - vs[0].w;
    match vs.len() {
        1 => d.length(),
        2 => {
            let e = (vs[1].w - vs[0].w).normalize_or_zero();
            (d - e * d.dot(e)).length()
        }
        _ => {
            let n = (vs[1].w - vs[0].w)
                .cross(vs[2].w - vs[0].w)
                .normalize_or_zero();
            d.dot(n).abs()
        }
    }
}

/// Largest distance between the first point and the others.
fn span_size(vs: &[SupportPoint]) -> f64 {
    vs.iter()
        .map(|p| (p.w - vs[0].w).length())
        .fold(0.0, f64::max)
}

/// The smallest barycentric coordinate of the origin's projection on face `f` (≥ 0: inside).
fn inside(vs: &[SupportPoint], f: &Face) -> f64 {
    let l = barycentric(vs, f);
    if l.iter().all(|x| x.is_finite()) {
        l[0].min(l[1]).min(l[2])
    } else {
        f64::NEG_INFINITY
    }
}

fn barycentric(vs: &[SupportPoint], f: &Face) -> [f64; 3] {
    let [p0, p1, p2] = f.v.map(|i| vs[i as usize].w);
    let n = f.normal;
    let q = n * f.dist;
    let area = |x: DVec3, y: DVec3, z: DVec3| (y - x).cross(z - x).dot(n);
    let total = area(p0, p1, p2);
    [
        area(q, p1, p2) / total,
        area(p0, q, p2) / total,
        area(p0, p1, q) / total,
    ]
}

/// A's witness for face `f`: the origin's projection on it, in barycentric coordinates
/// (clamped), applied to A's support points.
fn face_point_a(vs: &[SupportPoint], f: &Face) -> DVec3 {
    converged(vs, f, 0).point_a
}

/// The answer from the confirmed nearest face: the origin's projection on it, in
/// barycentric coordinates, gives the witnesses.
fn converged(vs: &[SupportPoint], f: &Face, iterations: u32) -> EpaResult {
    let [p0, p1, p2] = f.v.map(|i| vs[i as usize]);
    let n = f.normal;
    let mut l = barycentric(vs, f);
    if !l.iter().all(|x| x.is_finite()) {
        l = [1.0 / 3.0; 3];
    }
    // Rounding can put the projection a hair outside the face: clamp and renormalise.
    let l = l.map(|x| x.max(0.0));
    let s: f64 = l.iter().sum();
    let l = if s > 0.0 {
        l.map(|x| x / s)
    } else {
        [1.0 / 3.0; 3]
    };
    let point_a = p0.a * l[0] + p1.a * l[1] + p2.a * l[2];
    let point_b = p0.b * l[0] + p1.b * l[1] + p2.b * l[2];
    EpaResult {
        outcome: EpaOutcome::Converged,
        depth: f.dist.max(0.0),
        normal: n,
        point_a,
        point_b,
        iterations,
        depth_lower: f.dist.max(0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cuboid, Segment};
    use crate::narrow::gjk::{GjkCache, GjkOutcome, gjk_distance};

    fn run<A: SupportMap, B: SupportMap>(a: &A, b: &B, pose: &Isometry) -> EpaResult {
        let params = GjkParams::default();
        let g = gjk_distance(a, b, pose, &params, &mut GjkCache::default());
        assert_eq!(g.outcome, GjkOutcome::Penetrating);
        penetration(
            a,
            b,
            pose,
            &g.simplex,
            &params,
            &mut EpaWorkspace::new(),
            &mut WorkClock::default(),
        )
    }

    #[test]
    fn concentric_boxes_are_blown_up_from_one_point_and_separate_along_the_thin_axis() {
        let a = Cuboid::new(DVec3::new(1.0, 0.25, 2.0));
        let e = run(&a, &a, &Isometry::IDENTITY);
        assert_eq!(e.outcome, EpaOutcome::Converged);
        assert!((e.depth - 0.5).abs() < 1e-15, "{e:?}");
        assert!(e.normal.abs().abs_diff_eq(DVec3::Y, 1e-15), "{e:?}");
        assert!((e.point_a - e.point_b - e.normal * e.depth).length() < 1e-15);
    }

    #[test]
    fn crossing_segments_have_a_flat_difference_and_fall_back_to_zero_depth() {
        let a = Segment::new(DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        let b = Segment::new(DVec3::new(0.0, -1.0, 0.0), DVec3::new(0.0, 1.0, 0.0));
        let pose = Isometry::from_translation(DVec3::new(0.25, 0.5, 0.0));
        let e = run(&a, &b, &pose);
        assert_eq!(e.outcome, EpaOutcome::Fallback);
        assert_eq!(e.depth, 0.0);
        assert!(e.normal.abs().abs_diff_eq(DVec3::Z, 1e-15), "{e:?}");
        // Both witnesses at the crossing point.
        assert!(
            (e.point_a - DVec3::new(0.25, 0.0, 0.0)).length() < 1e-15,
            "{e:?}"
        );
        assert_eq!(e.point_a, e.point_b);
    }

    #[test]
    fn a_reused_workspace_gives_the_same_answers_as_a_fresh_one() {
        let a = Cuboid::new(DVec3::new(1.0, 0.5, 0.3));
        let b = Cuboid::new(DVec3::new(0.4, 0.6, 0.2));
        let params = GjkParams::default();
        let mut ws = EpaWorkspace::new();
        for k in 0..50 {
            let t = f64::from(k) * 0.02;
            let rot = crate::math::DMat3::from_rotation_z(t)
                * crate::math::DMat3::from_rotation_x(2.0 * t);
            let pose = Isometry::new(rot, DVec3::new(t, 0.3 - t, 0.1));
            let g = gjk_distance(&a, &b, &pose, &params, &mut GjkCache::default());
            if g.outcome != GjkOutcome::Penetrating {
                continue;
            }
            let reused = penetration(
                &a,
                &b,
                &pose,
                &g.simplex,
                &params,
                &mut ws,
                &mut WorkClock::default(),
            );
            let fresh = penetration(
                &a,
                &b,
                &pose,
                &g.simplex,
                &params,
                &mut EpaWorkspace::new(),
                &mut WorkClock::default(),
            );
            assert_eq!(reused, fresh);
        }
    }
}
