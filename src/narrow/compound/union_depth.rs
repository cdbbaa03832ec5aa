//! The penetration depth of a shape into a compound as a whole: the shortest translation
//! that frees it from every part at once, not only from the deepest part.
//!
//! Part pair by part pair, a shape reaching across the cut between two parts gets the
//! deeper part's depth, whose direction may push it through the cut into the next part.
//! Any translation that frees it from every part is at least as long as the deepest part
//! pair's depth `δ`, so:
//! 1. **Certificate.** If moving B by `δ` along the deepest pair's normal frees it from
//!    every part, that is the union's depth, exactly (the usual case: one part touched, or
//!    a normal that leaves the others behind). With one part touched and every other
//!    farther than `δ` (the distance search's bounds say so) it costs nothing more.
//! 2. **Search.** Otherwise each touching part pair's normal is a candidate direction; the
//!    move past A's extent along an axis of either frame (`freeing_bound`) frees B too
//!    and is the answer's ceiling. Along each direction, until it is no shorter than the
//!    best, B is moved out of every part it still overlaps (conservative advancement from
//!    the pair's separating plane inwards, which stops at the last exit), re-listing the
//!    parts it may hit on the way. The shortest such translation is the answer: an upper
//!    bound of the union's depth, at least `δ`, always one that frees B.
//!
//! A mesh B is a surface, not a solid: its pairs keep the per-part answer.

use super::CompoundShape;
use super::query::{CompoundScratch, list_candidates, pair_of};
use crate::budget::WORK_PER_CLOCK_READ;
use crate::geometry::SupportMap;
use crate::math::{DVec3, Pose};
use crate::narrow::Shape;
use crate::narrow::contact::{DistanceBound, Reached, ShapeDistance};
use crate::narrow::dispatch::{self, NarrowScratch};
use crate::narrow::shape::core_of;

/// Most candidate directions searched (the deepest touching pairs' normals).
const MAX_DIRECTIONS: usize = 8;
/// Most conservative-advancement steps per part pair and direction.
const MAX_STEPS: usize = 16;
/// Most times B is re-listed against the parts along one direction.
const MAX_ROUNDS: usize = 16;

/// A part pair counts as overlapping below this signed distance, metres, relative to the
/// scene's size (`scale`): EPA's depth and the moved pose carry rounding of about 1e-12 of it.
const OVERLAP_REL: f64 = 1e-9;

/// The union's depth for `deepest`, the smallest signed distance over the part pairs of `a`
/// and `b` (negative), under `scratch.clock` (see the [module docs](self)); the part pairs
/// not in `own.touching` are at least `others_apart_by` metres apart. Exact when the
/// certificate holds; else the shortest freeing translation found; [`Reached::Bounded`]
/// between the deepest pair's depth and the shortest freeing move known when the clock
/// stops the search (polled before each part pair's query).
pub(super) fn union_depth(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    deepest: ShapeDistance,
    others_apart_by: f64,
    scratch: &mut NarrowScratch,
    own: &mut CompoundScratch,
) -> Reached {
    if matches!(b, Shape::Mesh(_)) {
        return Reached::Exact(deepest);
    }
    let scale = a.local_bounds().half_extents().length()
        + b.local_bounds().half_extents().length()
        + pose_ab.position.length();
    let search = Search {
        a,
        b,
        pose_ab,
        tolerance: OVERLAP_REL * scale,
    };
    let depth = -deepest.distance;
    // The certificate for free: one part touched, and every other farther than the move.
    if own.touching.len() == 1 && others_apart_by > depth + search.tolerance {
        return Reached::Exact(deepest);
    }
    let answer = |length: f64, normal: DVec3, exact: bool| {
        // B's deepest point against the push, and A's surface where the push leaves it.
        let point_b = support_in(b, pose_ab, -normal);
        if exact {
            Reached::Exact(ShapeDistance {
                distance: -length,
                point_a: point_b + length * normal,
                point_b,
                normal,
            })
        } else {
            Reached::Bounded(DistanceBound::new(-length, -depth, normal, point_b))
        }
    };
    // The move past A's extent along an axis of either frame frees B: never answer more.
    let past_extent = freeing_move(a, b, pose_ab);
    let first = match search.escape_along(deepest.normal, depth, past_extent.0, scratch, own) {
        Some(length) if length <= depth + search.tolerance => return Reached::Exact(deepest),
        Some(length) => length,
        None if scratch.clock.stopped() => return answer(past_extent.0, past_extent.1, false),
        // No shorter than the move past A's extent.
        None => f64::INFINITY,
    };
    // The touching part pairs' normals (all found by the distance search), deepest first.
    own.directions.clear();
    own.directions.extend(
        own.touching
            .iter()
            .filter(|(_, d)| d.distance < -search.tolerance)
            .map(|(_, d)| (d.distance, d.normal)),
    );
    own.directions.sort_by(|x, y| x.0.total_cmp(&y.0));
    own.directions.truncate(MAX_DIRECTIONS);
    // That axis, refined: along it B may be free well before it clears A's extent.
    own.directions.push((0.0, past_extent.1));
    let mut best = if first < past_extent.0 {
        (first, deepest.normal)
    } else {
        past_extent
    };
    for k in 0..own.directions.len() {
        let normal = own.directions[k].1;
        // `None`: stopped by the clock, or no shorter than the best (then the loop goes on).
        match search.escape_along(normal, depth, best.0, scratch, own) {
            Some(length) => best = (length, normal),
            None if scratch.clock.stopped() => return answer(best.0, best.1, false),
            None => {}
        }
    }
    answer(best.0, best.1, true)
}

/// One search for the union's depth: B placed by `pose_ab` against compound `a`.
struct Search<'s> {
    a: &'s CompoundShape,
    b: &'s Shape,
    pose_ab: &'s Pose,
    /// A part pair counts as overlapping below minus this, metres.
    tolerance: f64,
}

impl Search<'_> {
    /// How far B must move along the unit `normal` (A's frame) to be free of every part of
    /// A, at least `start` metres: an upper bound within about the tolerance of the exact
    /// length, and always a translation that frees it. `None` once it is known to be at
    /// least `shorter_than`, or when `scratch.clock` stopped it (polled before each part
    /// pair's query).
    fn escape_along(
        &self,
        normal: DVec3,
        start: f64,
        shorter_than: f64,
        scratch: &mut NarrowScratch,
        own: &mut CompoundScratch,
    ) -> Option<f64> {
        let mut length = start;
        for _ in 0..MAX_ROUNDS {
            if length >= shorter_than {
                return None;
            }
            let moved = moved_by(self.pose_ab, normal * length);
            list_candidates(self.a, self.b, &moved, 0.0, own);
            let mut raised = false;
            for k in 0..own.candidates.len() {
                let (part_a, part_b) = pair_of(self.a, self.b, &own.candidates[k]);
                if !scratch.clock.allows(WORK_PER_CLOCK_READ) {
                    return None;
                }
                let d = dispatch::distance(part_a, part_b, &moved, 0.0, scratch);
                if d.distance < -self.tolerance {
                    length = length.max(self.exit_along(part_a, part_b, normal, scratch)?);
                    raised = true;
                }
            }
            if !raised {
                return Some(length);
            }
        }
        Some(length)
    }

    /// The exit of B's part `part_b` from `part_a` along the unit `normal`: the smallest
    /// translation along it beyond which they stay apart, from above (conservative
    /// advancement from the separating plane of their projections on `normal`, each step
    /// the pair's distance, which no motion of that length can close). `None` when
    /// `scratch.clock` stopped it (polled before each step).
    fn exit_along(
        &self,
        part_a: &Shape,
        part_b: &Shape,
        normal: DVec3,
        scratch: &mut NarrowScratch,
    ) -> Option<f64> {
        let top_a = support_in(part_a, &Pose::IDENTITY, normal).dot(normal);
        let bottom_b = support_in(part_b, self.pose_ab, -normal).dot(normal);
        let mut length = (top_a - bottom_b).max(0.0);
        for _ in 0..MAX_STEPS {
            if !scratch.clock.allows(WORK_PER_CLOCK_READ) {
                return None;
            }
            let moved = moved_by(self.pose_ab, normal * length);
            let gap = dispatch::distance(part_a, part_b, &moved, f64::INFINITY, scratch).distance;
            if gap <= self.tolerance {
                break;
            }
            length -= gap;
        }
        Some(length)
    }
}

/// A translation length that frees B from the whole of `a` (B placed by `pose_ab`): the
/// shortest of the moves along the axis directions of A's frame and of B's that carry B
/// past A's extent (their supports), metres. No penetration depth of the two exceeds it.
/// Both frames' axes make it the same whichever shape is queried as A.
pub(super) fn freeing_bound(a: &CompoundShape, b: &Shape, pose_ab: &Pose) -> f64 {
    freeing_move(a, b, pose_ab).0
}

/// [`freeing_bound`] and the direction of its move.
fn freeing_move(a: &CompoundShape, b: &Shape, pose_ab: &Pose) -> (f64, DVec3) {
    let top_a = |n: DVec3| compound_support(a, &Pose::IDENTITY, n).dot(n);
    axis_directions(pose_ab)
        .map(|n| ((top_a(n) - support_in(b, pose_ab, -n).dot(n)).max(0.0), n))
        .fold(
            (f64::INFINITY, DVec3::X),
            |x, y| if y.0 < x.0 { y } else { x },
        )
}

/// The twelve axis directions of A's frame and of B's (placed by `pose_ab`), A's frame.
fn axis_directions(pose_ab: &Pose) -> impl Iterator<Item = DVec3> + '_ {
    [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .flat_map(|axis| [axis, pose_ab.transform_vector(axis)])
        .flat_map(|axis| [axis, -axis])
}

/// [`support_in`] of a compound: the farthest of its parts'.
fn compound_support(compound: &CompoundShape, pose: &Pose, direction: DVec3) -> DVec3 {
    compound
        .parts()
        .iter()
        .map(|p| support_in(p, pose, direction))
        .max_by(|x, y| x.dot(direction).total_cmp(&y.dot(direction)))
        .unwrap_or_else(|| unreachable!("a compound has parts"))
}

/// `pose_ab` with B moved by `offset`, A's frame.
fn moved_by(pose_ab: &Pose, offset: DVec3) -> Pose {
    Pose::new(pose_ab.position + offset, pose_ab.rotation)
}

/// The point of `shape`, placed by `pose` in A's frame, farthest along `direction` (A's
/// frame): a compound's over its parts. `shape` is convex or a compound.
fn support_in(shape: &Shape, pose: &Pose, direction: DVec3) -> DVec3 {
    if let Shape::Compound(c) = shape {
        return compound_support(c, pose, direction);
    }
    let Some((core, radius)) = core_of(shape) else {
        unreachable!("meshes keep the per-part answer");
    };
    let local = pose.inverse_transform_vector(direction);
    let unit = local.try_normalize().unwrap_or(DVec3::X);
    pose.transform_point(core.support(local) + radius * unit)
}
