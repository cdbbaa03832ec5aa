//! Time of impact of one candidate pair over the frame's motion (the `TOI` flag).
//!
//! # Contract
//! Each body moves from the pose it had when the last frame was answered to its pose now
//! ([`Scene::frame_motion`]): `t ∈ [0, 1]` is the fraction of that motion, the position
//! interpolated linearly and the orientation by shortest-arc slerp, exactly
//! [`FrameMotion::pose_at`]. The pair *comes within contact* when its signed distance is at
//! most the sum of its margins (the `CLOSE` criterion; margins 0: touching). The search is
//! conservative advancement ([`time_of_impact`]) over the dispatcher's exact signed
//! distance, so every pair kind the dispatcher answers (primitives, convex shapes, a shape
//! and a mesh, two meshes) is covered. A pair is reported with the first `t` at which it
//! is within `margins + TOI_TOLERANCE`:
//! - never later than the true first contact (no time before `t` has the pair within its
//!   margins), error bound [`TOI_TOLERANCE`] in distance;
//! - `t = 0` when the pair is already within contact at the start of the motion;
//! - not at all when it stays farther apart than its margins over the whole motion.
//!
//! The record holds the signed distance, witnesses and unit normal (A→B) at the poses of
//! time `t`, world frame. When the search runs out of iterations (a long grazing motion
//! against a mesh) the pair is still reported, conservatively, at the time it safely
//! reached, with `reached = false`: no contact before it, contact after it possible.

use super::dispatch::{self, NarrowScratch};
use crate::broad::CandidatePair;
use crate::math::{DVec3, Pose};
use crate::narrow::contact::ShapeDistance;
use crate::narrow::toi::{FrameMotion, ToiOutcome, ToiParams, time_of_impact};
use crate::scene::{Body, Scene, Shape};

/// Distance tolerance of the time-of-impact search, metres: at the reported time the pair
/// is at most its margins plus this far apart.
pub const TOI_TOLERANCE: f64 = 1e-6;

/// Most distance queries per pair and frame before the search reports how far it got.
const MAX_ITERATIONS: u32 = 256;

/// The time of impact of one pair over the frame's motion, world frame.
///
/// `time ∈ [0, 1]` is the fraction of the motion from each body's pose when the last frame
/// was answered to its pose now (position linear, orientation shortest-arc slerp). The
/// pair comes within contact when its signed distance is at most the sum of its margins.
/// Conservative: no time before `time` has the pair within contact, and (when `reached`)
/// at `time` it is within its margins plus [`TOI_TOLERANCE`]; `time = 0` when it already
/// is at the start. Pairs that stay farther apart than their margins report nothing. See
/// the [pipeline docs](super#time-of-impact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairToi {
    /// The smaller body id.
    pub a: u32,
    /// The larger body id.
    pub b: u32,
    /// Fraction of the frame's motion at first contact, in `[0, 1]`.
    pub time: f64,
    /// Signed distance at `time`, metres (exact to the narrow phase's rounding).
    pub distance: f64,
    /// [`TOI_TOLERANCE`]: at `time` (when `reached`) the distance is at most the margins
    /// plus this, metres.
    pub error_bound: f64,
    /// Witness on A at `time`, world frame.
    pub point_a: DVec3,
    /// Witness on B at `time`, world frame.
    pub point_b: DVec3,
    /// Unit normal from A to B at `time`, world frame.
    pub normal: DVec3,
    /// Whether the pair is within contact at `time`; `false`: the search stopped at its
    /// iteration limit, no contact before `time`.
    pub reached: bool,
}

/// The time of impact of candidate `pair` over the current frame's motion, `None` when it
/// never comes within its margins.
pub(super) fn pair_toi(
    scene: &Scene,
    pair: &CandidatePair,
    (a, sa): (&Body, &Shape),
    (b, sb): (&Body, &Shape),
    scratch: &mut NarrowScratch,
) -> Option<PairToi> {
    let (motion_a, motion_b) = (scene.frame_motion(a), scene.frame_motion(b));
    let margins = a.margin + b.margin;
    let params = ToiParams {
        tolerance: TOI_TOLERANCE,
        max_iterations: MAX_ITERATIONS,
        convex: !matches!(sa, Shape::Mesh(_)) && !matches!(sb, Shape::Mesh(_)),
    };
    // The gap to contact (distance minus margins) at two world poses, world frame. The
    // limit is infinite: an upper bound of the distance would not be a safe step.
    let mut gap = |pose_a: &Pose, pose_b: &Pose| {
        let d = dispatch::distance(
            sa,
            sb,
            &Pose::relative(pose_a, pose_b),
            f64::INFINITY,
            scratch,
        );
        ShapeDistance {
            distance: d.distance - margins,
            point_a: pose_a.transform_point(d.point_a),
            point_b: pose_a.transform_point(d.point_b),
            normal: pose_a.transform_vector(d.normal),
        }
    };
    let (time, contact, reached) = match time_of_impact(
        &motion_a,
        scene.reach(a),
        &motion_b,
        scene.reach(b),
        &params,
        &mut gap,
    ) {
        ToiOutcome::Miss => return None,
        ToiOutcome::Initially { contact } => (0.0, contact, true),
        ToiOutcome::Impact { t, contact } => (t, contact, true),
        ToiOutcome::DidNotConverge { t } => (t, at(&motion_a, &motion_b, t, &mut gap), false),
    };
    Some(PairToi {
        a: pair.a,
        b: pair.b,
        time,
        distance: contact.distance + margins,
        error_bound: TOI_TOLERANCE,
        point_a: contact.point_a,
        point_b: contact.point_b,
        normal: contact.normal,
        reached,
    })
}

/// The query `gap` at time `t` of both motions.
fn at(
    motion_a: &FrameMotion,
    motion_b: &FrameMotion,
    t: f64,
    gap: &mut impl FnMut(&Pose, &Pose) -> ShapeDistance,
) -> ShapeDistance {
    gap(&motion_a.pose_at(t), &motion_b.pose_at(t))
}
