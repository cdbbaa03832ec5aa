//! A compound's distance and manifold against any shape, part pair by part pair through
//! the dispatcher.
//!
//! # Distance
//! The part tree lists the part pairs whose boxes may be within the limit, each with its
//! box bound; they are answered in order of that bound, each exact up to the best found so
//! far (or the limit), until the next bound is positive and no smaller than the best (boxes
//! that overlap may hold a deeper pair than any found, so all of them are answered). So:
//! - within the limit the answer is exact: apart, the smallest distance over the part
//!   pairs, with that pair's witnesses and normal; overlapping, the depth of the whole
//!   compound ([`union_depth`](super::union_depth)): the deepest part pair's when moving B
//!   out of it frees it from every part, else the shortest freeing translation found along
//!   the touching pairs' normals;
//! - beyond it, only a lower bound (`distance > limit` holds): the best part pair's, or the
//!   smallest box bound of the pairs left out when that is smaller;
//! - when the frame's clock stops it (polled before each part pair after the first, and
//!   inside each), [`Reached::Bounded`]: the best part pair found above, below the
//!   smallest bound of the pairs not answered: their boxes' gap, or where boxes overlap
//!   minus the length of a move that frees B from the whole compound (for a mesh B, minus
//!   the widest part's width).
//!
//! # Manifold
//! Every touching part pair's manifold (their distances kept from the distance just
//! asked of the same pair and pose, else answered again; the frame's clock polled before
//! each after the first, and when it stops them `manifold_cut_short` is raised in the
//! dispatcher's scratch); their points and the distance's own witnesses (the deepest, with the
//! compound's normal) are merged under that normal (`reduce_under_deepest`), the other
//! points' depths measured along it.

use super::CompoundShape;
use super::tree::Candidate;
use super::union_depth::{freeing_bound, union_depth};
use crate::bounding::Obb;
use crate::budget::WORK_PER_CLOCK_READ;
use crate::math::{DVec3, Pose};
use crate::narrow::Shape;
use crate::narrow::contact::{DistanceBound, Manifold, ManifoldPoint, Reached, ShapeDistance};
use crate::narrow::dispatch::{self, NarrowScratch};
use crate::narrow::manifold_reduction::reduce_under_deepest;
use crate::narrow::pair_key::PairKey;

/// Scratch of the compound queries for one thread (no allocation once grown).
#[derive(Debug, Default)]
pub(crate) struct CompoundScratch {
    stack: Vec<u32>,
    pair_stack: Vec<(u32, u32)>,
    pub(super) candidates: Vec<Candidate>,
    /// The touching part pairs' depths and normals, for the union's depth.
    pub(super) directions: Vec<(f64, DVec3)>,
    /// The part pairs the last finished distance found touching, with their exact
    /// distances, and which query that was: the manifold of the same pair and pose, asked
    /// next, takes them instead of answering the part pairs again.
    pub(super) touching: Vec<(Candidate, ShapeDistance)>,
    touching_of: Option<PairKey>,
    points: Vec<ManifoldPoint>,
    normals: Vec<DVec3>,
    positions: Vec<DVec3>,
    kept: Vec<usize>,
    part_manifold: Manifold,
}

/// The part pairs of `a` and `b` (B placed by `pose_ab`) whose boxes may be within
/// `cutoff`, into `scratch.candidates` sorted by their bound; returns the smallest bound of
/// the pairs left out.
pub(super) fn list_candidates(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    cutoff: f64,
    scratch: &mut CompoundScratch,
) -> f64 {
    let iso = pose_ab.to_isometry();
    let CompoundScratch {
        stack,
        pair_stack,
        candidates,
        ..
    } = scratch;
    let left_out = match b {
        Shape::Compound(b) => {
            a.tree()
                .candidate_pairs(b.tree(), &iso, cutoff, pair_stack, candidates)
        }
        Shape::Mesh(mesh) => {
            let root = &mesh.overlap_tree.nodes()[0].bv;
            a.tree()
                .candidates_against(root, &iso, cutoff, stack, candidates)
        }
        _ => {
            let bound = Obb::from_aabb(&b.local_bounds());
            a.tree()
                .candidates_against(&bound, &iso, cutoff, stack, candidates)
        }
    };
    candidates.sort_unstable_by(|x, y| x.lower.total_cmp(&y.lower));
    left_out
}

/// The two shapes of candidate `c`: a part of `a`, and a part of `b` or `b` itself.
pub(super) fn pair_of<'s>(
    a: &'s CompoundShape,
    b: &'s Shape,
    c: &Candidate,
) -> (&'s Shape, &'s Shape) {
    let part_a = &a.parts()[c.a as usize];
    match b {
        Shape::Compound(b) => (part_a, &b.parts()[c.b as usize]),
        _ => (part_a, b),
    }
}

/// The signed distance of compound `a` and any shape `b` placed by `pose_ab`, A's frame,
/// under `scratch.clock` (see the [module docs](self)).
pub(crate) fn distance_within(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> Reached {
    let mut own = std::mem::take(&mut scratch.compound);
    let left_out = list_candidates(a, b, pose_ab, limit, &mut own);
    own.touching.clear();
    own.touching_of = None;
    let mut best: Option<ShapeDistance> = None;
    let mut stopped: Option<DistanceBound> = None;
    // The widest gap rounding left in a part pair's answer (0: all exact).
    let mut resolution = 0.0_f64;
    // A lower bound of the distance of every part pair not touching.
    let mut others_apart_by = left_out;
    for (k, c) in own.candidates.iter().enumerate() {
        // Boxes apart by `lower` hold parts at least that far apart; overlapping boxes may
        // hold a deeper pair than any found.
        if c.lower > 0.0 && best.is_some_and(|d| c.lower >= d.distance) {
            others_apart_by = others_apart_by.min(c.lower);
            break;
        }
        if k > 0 && !scratch.clock.allows(WORK_PER_CLOCK_READ) {
            let left = lowest_left(a, b, pose_ab, &own.candidates[k..]);
            stopped = Some(bounds(left, best.as_ref()));
            break;
        }
        let (part_a, part_b) = pair_of(a, b, c);
        // Exact up to the best gap found, and every touching pair exact once one touches
        // (the whole compound's depth and the manifold want them all).
        let enough = best.map_or(limit, |d| d.distance.max(0.0).min(limit));
        let reached = dispatch::distance_within(part_a, part_b, pose_ab, enough, scratch);
        match reached {
            Reached::Exact(_) | Reached::Resolved(_) => {
                resolution = resolution.max(reached.width());
                let d = reached.at_lower();
                // Beyond `enough`, a convex pair's value is a lower bound.
                if d.distance > 0.0 {
                    others_apart_by = others_apart_by.min(d.distance);
                } else if limit >= 0.0 {
                    own.touching.push((*c, d));
                }
                if best.is_none_or(|b| d.distance < b.distance) {
                    best = Some(d);
                }
            }
            Reached::Bounded(bound) => {
                let lower = bound
                    .lower
                    .min(lowest_left(a, b, pose_ab, &own.candidates[k + 1..]));
                stopped = Some(match best {
                    Some(d) if d.distance <= bound.upper => bounds(lower, Some(&d)),
                    _ => DistanceBound::new(lower, bound.upper, bound.normal, bound.point_b),
                });
                break;
            }
        }
    }
    if stopped.is_none() && limit >= 0.0 {
        own.touching_of = Some(PairKey::new(a, b, pose_ab));
    }
    let answer = match (stopped, best) {
        (Some(bound), _) => Reached::Bounded(whole_compound_lower(a, b, pose_ab, bound)),
        // Overlapping: the depth of the whole compound, not only of the deepest part.
        (None, Some(d)) if d.distance < 0.0 => {
            union_depth(a, b, pose_ab, d, others_apart_by, scratch, &mut own)
        }
        (None, Some(d)) if d.distance <= limit || d.distance <= left_out => Reached::Exact(d),
        // Beyond the limit with pairs left out closer than the best: their bound.
        (None, Some(d)) => {
            Reached::Exact(DistanceBound::new(left_out, left_out, d.normal, d.point_b).at_lower())
        }
        (None, None) => Reached::Exact(beyond_every_box(a, b, pose_ab, left_out)),
    };
    scratch.compound = own;
    match answer {
        Reached::Exact(d) if resolution > 0.0 => Reached::Resolved(DistanceBound::new(
            d.distance,
            d.distance + resolution,
            d.normal,
            d.point_b,
        )),
        answer => answer,
    }
}

/// The smallest lower bound of the part pairs `left` (sorted by their box bound): the
/// first one's box bound when positive, else minus [`freeing_bound`], which no depth of the
/// whole compound exceeds.
fn lowest_left(a: &CompoundShape, b: &Shape, pose_ab: &Pose, left: &[Candidate]) -> f64 {
    match left.first() {
        None => f64::INFINITY,
        Some(c) if c.lower > 0.0 => c.lower,
        Some(_) if matches!(b, Shape::Mesh(_)) => {
            // A mesh is a surface: a part reaches through it by at most its own width.
            let width = |s: &Shape| (s.local_bounds().max - s.local_bounds().min).length();
            -a.parts().iter().map(width).fold(0.0, f64::max)
        }
        Some(_) => -freeing_bound(a, b, pose_ab),
    }
}

/// `bound`, from part pairs, as bounds of the whole compound's signed distance: where it
/// says they may overlap, the whole compound may be deeper than any part pair, down to
/// minus [`freeing_bound`] (a mesh B, a surface, keeps the part pairs' bound).
fn whole_compound_lower(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    bound: DistanceBound,
) -> DistanceBound {
    if bound.lower > 0.0 || matches!(b, Shape::Mesh(_)) {
        return bound;
    }
    let lower = bound.lower.min(-freeing_bound(a, b, pose_ab));
    DistanceBound::new(lower, bound.upper, bound.normal, bound.point_b)
}

/// Bounds from the best part pair found (the upper bound and its witnesses; `+∞` without
/// one) and the smallest `lower` bound of the pairs not answered.
fn bounds(lower: f64, best: Option<&ShapeDistance>) -> DistanceBound {
    match best {
        Some(d) => DistanceBound::new(lower.min(d.distance), d.distance, d.normal, d.point_b),
        None => DistanceBound::new(lower, f64::INFINITY, DVec3::X, DVec3::ZERO),
    }
}

/// The answer when every part pair's boxes are beyond the limit: their smallest bound,
/// along the line between the two shapes' box centres, B's witness its centre.
fn beyond_every_box(a: &CompoundShape, b: &Shape, pose_ab: &Pose, lower: f64) -> ShapeDistance {
    let centre_b = pose_ab.transform_point(b.local_bounds().center());
    let normal = (centre_b - a.local_bounds().center())
        .try_normalize()
        .unwrap_or(DVec3::X);
    DistanceBound::new(lower, lower, normal, centre_b).at_lower()
}

/// The contact manifold of compound `a` and any shape `b` placed by `pose_ab`, A's frame,
/// into `out` (emptied first; empty when `d`, their signed distance, says they are apart):
/// see the [module docs](self).
pub(crate) fn manifold(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    d: &ShapeDistance,
    scratch: &mut NarrowScratch,
    out: &mut Manifold,
) {
    out.reset(DVec3::ZERO);
    if d.distance > 0.0 {
        return;
    }
    let mut own = std::mem::take(&mut scratch.compound);
    if own.touching_of != Some(PairKey::new(a, b, pose_ab)) {
        // Not right after this pair's distance: answer the part pairs again.
        list_candidates(a, b, pose_ab, 0.0, &mut own);
        own.touching.clear();
        for (k, c) in own.candidates.iter().enumerate() {
            if k > 0 && !scratch.clock.allows(WORK_PER_CLOCK_READ) {
                scratch.manifold_cut_short = true;
                break;
            }
            let (part_a, part_b) = pair_of(a, b, c);
            let part_d = dispatch::distance(part_a, part_b, pose_ab, 0.0, scratch);
            if part_d.distance <= 0.0 {
                own.touching.push((*c, part_d));
            }
        }
    }
    own.points.clear();
    own.normals.clear();
    for (k, (c, part_d)) in own.touching.iter().enumerate() {
        if k > 0 && !scratch.clock.allows(WORK_PER_CLOCK_READ) {
            scratch.manifold_cut_short = true;
            break;
        }
        let (part_a, part_b) = pair_of(a, b, c);
        let m = &mut own.part_manifold;
        dispatch::manifold(part_a, part_b, pose_ab, part_d, scratch, m);
        own.points.extend_from_slice(m.points());
        own.normals.extend(std::iter::repeat_n(m.normal, m.len()));
    }
    // The compound's own depth and normal lead (the whole compound's, at least as deep as
    // any part pair's).
    own.points.push(ManifoldPoint {
        point_a: d.point_a,
        point_b: d.point_b,
        distance: d.distance,
    });
    own.normals.push(d.normal);
    let CompoundScratch {
        points,
        normals,
        positions,
        kept,
        ..
    } = &mut own;
    // Never empty: the distance's own point is in.
    reduce_under_deepest(points, normals, positions, kept, out);
    scratch.compound = own;
}
