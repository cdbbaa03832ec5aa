//! A compound's distance and manifold against any shape, part pair by part pair through
//! the dispatcher.
//!
//! # Distance
//! The part tree lists the part pairs whose boxes may be within the limit, each with its
//! box bound; they are answered in order of that bound, each exact up to the best found so
//! far (or the limit), until the next bound is positive and no smaller than the best (boxes
//! that overlap may hold a deeper pair than any found, so all of them are answered). So:
//! - within the limit the answer is exact: the smallest signed distance over the part
//!   pairs, with that pair's witnesses and normal;
//! - beyond it, only a lower bound (`distance > limit` holds): the best part pair's, or the
//!   smallest box bound of the pairs left out when that is smaller;
//! - when the frame's clock stops it (polled before each part pair after the first, and
//!   inside each), [`Reached::Bounded`]: the best part pair found above, below the
//!   smallest bound of the pairs not answered: their boxes' gap, or where the boxes overlap
//!   minus the smaller part's box diagonal.
//!
//! # Manifold
//! Every part pair whose boxes overlap is answered (distance, then its manifold when it
//! touches); their points are merged under the deepest one's normal
//! ([`reduce_under_deepest`]).

use super::CompoundShape;
use super::tree::Candidate;
use crate::bounding::Obb;
use crate::budget::WORK_PER_CLOCK_READ;
use crate::math::{DMat3, DVec3, Pose};
use crate::narrow::Shape;
use crate::narrow::contact::{DistanceBound, Manifold, ManifoldPoint, Reached, ShapeDistance};
use crate::narrow::dispatch::{self, NarrowScratch};
use crate::narrow::manifold_reduction::reduce_under_deepest;

/// Scratch of the compound queries for one thread (no allocation once grown).
#[derive(Debug, Default)]
pub(crate) struct CompoundScratch {
    stack: Vec<u32>,
    pair_stack: Vec<(u32, u32)>,
    candidates: Vec<Candidate>,
    points: Vec<ManifoldPoint>,
    normals: Vec<DVec3>,
    positions: Vec<DVec3>,
    kept: Vec<usize>,
    part_manifold: Manifold,
}

/// The part pairs of `a` and `b` (B placed by `pose_ab`) whose boxes may be within
/// `cutoff`, into `scratch.candidates` sorted by their bound; returns the smallest bound of
/// the pairs left out.
fn list_candidates(
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
            let local = b.local_bounds();
            let bound = Obb::new(local.center(), DMat3::IDENTITY, local.half_extents());
            a.tree()
                .candidates_against(&bound, &iso, cutoff, stack, candidates)
        }
    };
    candidates.sort_unstable_by(|x, y| x.lower.total_cmp(&y.lower));
    left_out
}

/// The two shapes of candidate `c`: a part of `a`, and a part of `b` or `b` itself.
fn pair_of<'s>(a: &'s CompoundShape, b: &'s Shape, c: &Candidate) -> (&'s Shape, &'s Shape) {
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
    let mut best: Option<ShapeDistance> = None;
    let mut stopped: Option<DistanceBound> = None;
    for (k, c) in own.candidates.iter().enumerate() {
        // Boxes apart by `lower` hold parts at least that far apart; overlapping boxes may
        // hold a deeper pair than any found.
        if c.lower > 0.0 && best.is_some_and(|d| c.lower >= d.distance) {
            break;
        }
        if k > 0 && !scratch.clock.allows(WORK_PER_CLOCK_READ) {
            let left = lowest_left(a, b, &own.candidates[k..]);
            stopped = Some(bounds(left, best.as_ref()));
            break;
        }
        let (part_a, part_b) = pair_of(a, b, c);
        let enough = best.map_or(limit, |d| d.distance.min(limit));
        match dispatch::distance_within(part_a, part_b, pose_ab, enough, scratch) {
            Reached::Exact(d) => {
                if best.is_none_or(|b| d.distance < b.distance) {
                    best = Some(d);
                }
            }
            Reached::Bounded(bound) => {
                let lower = bound.lower.min(lowest_left(a, b, &own.candidates[k + 1..]));
                stopped = Some(match best {
                    Some(d) if d.distance <= bound.upper => bounds(lower, Some(&d)),
                    _ => DistanceBound::new(lower, bound.upper, bound.normal, bound.point_b),
                });
                break;
            }
        }
    }
    scratch.compound = own;
    if let Some(bound) = stopped {
        return Reached::Bounded(bound);
    }
    Reached::Exact(match best {
        Some(d) if d.distance <= limit || d.distance <= left_out => d,
        // Beyond the limit with pairs left out closer than the best: their bound.
        Some(d) => DistanceBound::new(left_out, left_out, d.normal, d.point_b).at_lower(),
        None => beyond_every_box(a, b, pose_ab, left_out),
    })
}

/// The smallest lower bound of the part pairs `left`: their box bound, or where the boxes
/// overlap minus the smaller part's box diagonal, which no penetration depth exceeds (the
/// smaller part pushed by its whole width along any direction is clear of the other).
fn lowest_left(a: &CompoundShape, b: &Shape, left: &[Candidate]) -> f64 {
    let width = |s: &Shape| (s.local_bounds().max - s.local_bounds().min).length();
    left.iter()
        .map(|c| {
            if c.lower > 0.0 {
                return c.lower;
            }
            let (part_a, part_b) = pair_of(a, b, c);
            -width(part_a).min(width(part_b))
        })
        .fold(f64::INFINITY, f64::min)
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
    list_candidates(a, b, pose_ab, 0.0, &mut own);
    own.points.clear();
    own.normals.clear();
    for c in &own.candidates {
        let (part_a, part_b) = pair_of(a, b, c);
        let part_d = dispatch::distance(part_a, part_b, pose_ab, 0.0, scratch);
        if part_d.distance > 0.0 {
            continue;
        }
        let m = &mut own.part_manifold;
        dispatch::manifold(part_a, part_b, pose_ab, &part_d, scratch, m);
        own.points.extend_from_slice(m.points());
        own.normals.extend(std::iter::repeat_n(m.normal, m.len()));
    }
    let CompoundScratch {
        points,
        normals,
        positions,
        kept,
        ..
    } = &mut own;
    if !reduce_under_deepest(points, normals, positions, kept, out) {
        // Touching at rounding level with no part pair's point: the distance's own.
        out.set_from_distance(d);
    }
    scratch.compound = own;
}
