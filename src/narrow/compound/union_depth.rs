//! The penetration depth of a shape into a compound as a whole: the shortest translation
//! that frees it from every part at once, not only from the deepest part.
//!
//! Part pair by part pair, a shape reaching across the cut between two parts gets the
//! deeper part's depth, whose direction may push it through the cut into the next part.
//! Any translation that frees it from every part is at least as long as the deepest part
//! pair's depth `δ`, so:
//! 1. **Certificate.** If moving B by `δ` along the deepest pair's normal frees it from
//!    every part, that is the union's depth, exactly (the usual case: one part touched, or
//!    a normal that leaves the others behind).
//! 2. **Search.** Otherwise each touching part pair's normal is a candidate direction, and
//!    so are the axes of A's frame and of B's (one of them carries B past A's extent, so
//!    the answer never exceeds [`freeing_bound`]); along each, B is moved out of every part it still overlaps (conservative advancement from
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
const MAX_STEPS: usize = 32;
/// Most times B is re-listed against the parts along one direction.
const MAX_ROUNDS: usize = 16;

/// A part pair counts as overlapping below this signed distance, metres, relative to the
/// scene's size (`scale`): EPA's depth and the moved pose carry rounding of about 1e-12 of it.
const OVERLAP_REL: f64 = 1e-9;

/// The union's depth for `deepest`, the smallest signed distance over the part pairs of `a`
/// and `b` (negative), under `scratch.clock` (see the [module docs](self)). Exact when the
/// certificate holds; else the shortest freeing translation found; [`Reached::Bounded`]
/// between the two when the clock stops the search.
pub(super) fn union_depth(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    deepest: ShapeDistance,
    scratch: &mut NarrowScratch,
    own: &mut CompoundScratch,
) -> Reached {
    if matches!(b, Shape::Mesh(_)) {
        return Reached::Exact(deepest);
    }
    let scale = a.local_bounds().half_extents().length()
        + b.local_bounds().half_extents().length()
        + pose_ab.position.length();
    let tolerance = OVERLAP_REL * scale;
    let depth = -deepest.distance;
    let first = escape_along(
        a,
        b,
        pose_ab,
        deepest.normal,
        depth,
        tolerance,
        scratch,
        own,
    );
    if first <= depth + tolerance {
        return Reached::Exact(deepest);
    }
    // The touching part pairs' normals, deepest first.
    list_candidates(a, b, pose_ab, 0.0, own);
    own.directions.clear();
    for k in 0..own.candidates.len() {
        let (part_a, part_b) = pair_of(a, b, &own.candidates[k]);
        let d = dispatch::distance(part_a, part_b, pose_ab, 0.0, scratch);
        if d.distance < -tolerance {
            own.directions.push((d.distance, d.normal));
        }
    }
    own.directions.sort_by(|x, y| x.0.total_cmp(&y.0));
    own.directions.truncate(MAX_DIRECTIONS);
    // The axes of both frames: the shortest move past A's extent along one frees B too,
    // so the answer is never more than that.
    own.directions
        .extend(axis_directions(pose_ab).map(|n| (0.0, n)));
    let mut best = (first, deepest.normal);
    for k in 0..own.directions.len() {
        let normal = own.directions[k].1;
        if !scratch.clock.allows(WORK_PER_CLOCK_READ) {
            let (length, normal) = best;
            let point_b = support_in(b, pose_ab, -normal);
            return Reached::Bounded(DistanceBound::new(-length, -depth, normal, point_b));
        }
        let length = escape_along(a, b, pose_ab, normal, depth, tolerance, scratch, own);
        if length < best.0 {
            best = (length, normal);
        }
    }
    let (length, normal) = best;
    // B's deepest point against the push, and A's surface where the push leaves it.
    let point_b = support_in(b, pose_ab, -normal);
    Reached::Exact(ShapeDistance {
        distance: -length,
        point_a: point_b + length * normal,
        point_b,
        normal,
    })
}

/// How far B (placed by `pose_ab`) must move along the unit `normal` (A's frame) to be free
/// of every part of `a`, at least `start` metres: an upper bound within about `tolerance`
/// of the exact length, and always a translation that frees it.
#[allow(clippy::too_many_arguments)]
fn escape_along(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    normal: DVec3,
    start: f64,
    tolerance: f64,
    scratch: &mut NarrowScratch,
    own: &mut CompoundScratch,
) -> f64 {
    let mut length = start;
    for _ in 0..MAX_ROUNDS {
        let moved = moved_by(pose_ab, normal * length);
        list_candidates(a, b, &moved, 0.0, own);
        let mut raised = false;
        for k in 0..own.candidates.len() {
            let c = own.candidates[k];
            let (part_a, part_b) = pair_of(a, b, &c);
            let d = dispatch::distance(part_a, part_b, &moved, 0.0, scratch);
            if d.distance < -tolerance {
                let exit = exit_along(part_a, part_b, pose_ab, normal, tolerance, scratch);
                length = length.max(exit);
                raised = true;
            }
        }
        if !raised {
            return length;
        }
    }
    length
}

/// The exit of B's part `part_b` (placed by `pose_ab`) from `part_a` along the unit
/// `normal`: the smallest translation along it beyond which they stay apart, from above
/// (conservative advancement from the separating plane of their projections on `normal`,
/// each step the pair's distance, which no motion of that length can close).
fn exit_along(
    part_a: &Shape,
    part_b: &Shape,
    pose_ab: &Pose,
    normal: DVec3,
    tolerance: f64,
    scratch: &mut NarrowScratch,
) -> f64 {
    let top_a = support_in(part_a, &Pose::IDENTITY, normal).dot(normal);
    let bottom_b = support_in(part_b, pose_ab, -normal).dot(normal);
    let mut length = (top_a - bottom_b).max(0.0);
    for _ in 0..MAX_STEPS {
        let moved = moved_by(pose_ab, normal * length);
        let gap = dispatch::distance(part_a, part_b, &moved, f64::INFINITY, scratch).distance;
        if gap <= tolerance {
            break;
        }
        length -= gap;
    }
    length
}

/// A translation length that frees B from the whole of `a` (B placed by `pose_ab`): the
/// shortest of the moves along the axis directions of A's frame and of B's that carry B
/// past A's extent (their supports), metres. No penetration depth of the two exceeds it.
/// Both frames' axes make it the same whichever shape is queried as A.
pub(super) fn freeing_bound(a: &CompoundShape, b: &Shape, pose_ab: &Pose) -> f64 {
    let whole_a = |n: DVec3| {
        a.parts()
            .iter()
            .map(|p| support_in(p, &Pose::IDENTITY, n).dot(n))
            .fold(f64::NEG_INFINITY, f64::max)
    };
    axis_directions(pose_ab)
        .map(|n| (whole_a(n) - support_in(b, pose_ab, -n).dot(n)).max(0.0))
        .fold(f64::INFINITY, f64::min)
}

/// The twelve axis directions of A's frame and of B's (placed by `pose_ab`), A's frame.
fn axis_directions(pose_ab: &Pose) -> impl Iterator<Item = DVec3> + '_ {
    [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .flat_map(|axis| [axis, pose_ab.transform_vector(axis)])
        .flat_map(|axis| [axis, -axis])
}

/// `pose_ab` with B moved by `offset`, A's frame.
fn moved_by(pose_ab: &Pose, offset: DVec3) -> Pose {
    Pose::new(pose_ab.position + offset, pose_ab.rotation)
}

/// The point of `shape`, placed by `pose` in A's frame, farthest along `direction` (A's
/// frame): a compound's over its parts. `shape` is convex or a compound.
fn support_in(shape: &Shape, pose: &Pose, direction: DVec3) -> DVec3 {
    if let Shape::Compound(c) = shape {
        return c
            .parts()
            .iter()
            .map(|p| support_in(p, pose, direction))
            .max_by(|x, y| x.dot(direction).total_cmp(&y.dot(direction)))
            .unwrap_or_else(|| unreachable!("a compound has parts"));
    }
    let Some((core, radius)) = core_of(shape) else {
        unreachable!("meshes keep the per-part answer");
    };
    let local = pose.inverse_transform_vector(direction);
    let unit = local.try_normalize().unwrap_or(DVec3::X);
    pose.transform_point(core.support(local) + radius * unit)
}
