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
//! against a mesh) or the frame's deadline stops it, the pair is still reported,
//! conservatively, at the time it safely reached, with `reached = false`: no contact
//! before it, contact after it possible.
//!
//! # Under a deadline
//! A frame with a deadline ([`step_within`](super::step_within)) searches its candidates
//! in order while time is left before its tail (the conservative answers of the
//! candidates left and the publishing of every record, measured on the scene:
//! [`FrameCosts::tail_ns`](super::FrameCosts::tail_ns)): a search that meets that point
//! stops where it is, and each candidate after it gets the
//! conservative answer of [`unsearched`]: reported at `t = 0`, `reached = false`, `exact =
//! false`, with the distance between the two shapes' boxes at the start of the motion (a
//! lower bound) and those boxes' witnesses and normal. No pair that comes within contact
//! is ever left out, and none is reported later than its first contact.

use super::plan::FramePlan;
use super::{FrameResults, PipelineWorkspace, Query, body, shape};
use crate::broad::CandidatePair;
use crate::math::{DVec3, Pose};
use crate::narrow::Shape;
use crate::narrow::contact::ShapeDistance;
use crate::narrow::dispatch::{self, NarrowScratch};
use crate::narrow::toi::{ToiOutcome, ToiParams, time_of_impact_until};
use crate::scene::{Body, Scene};

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
    /// Whether the pair is within contact at `time`; `false`: the search stopped (at its
    /// iteration limit, or the frame's deadline), no contact before `time`.
    pub reached: bool,
    /// Whether `distance`, the witnesses and the normal are the exact ones at `time`.
    /// `false` when the frame's deadline came before the pair's search (a frame with a
    /// deadline searches its candidates in order while time is left): `time` 0, and the
    /// record the two shapes' boxes at the start of the motion give, `distance` a lower
    /// bound of the distance then, within `error_bound` of it.
    pub exact: bool,
}

/// The time of impact of candidate `pair` over the current frame's motion, `None` when it
/// never comes within its margins; the search asks `may_continue` before each distance
/// query after the first (see [`time_of_impact_until`]).
pub(super) fn pair_toi(
    scene: &Scene,
    pair: &CandidatePair,
    (a, sa): (&Body, &Shape),
    (b, sb): (&Body, &Shape),
    scratch: &mut NarrowScratch,
    may_continue: impl FnMut() -> bool,
) -> Option<PairToi> {
    let (motion_a, motion_b) = (scene.frame_motion(a), scene.frame_motion(b));
    let margins = a.margin + b.margin;
    let params = ToiParams {
        tolerance: TOI_TOLERANCE,
        max_iterations: MAX_ITERATIONS,
        convex: !matches!(sa, Shape::Mesh(_) | Shape::Compound(_))
            && !matches!(sb, Shape::Mesh(_) | Shape::Compound(_)),
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
    let (time, contact, reached) = match time_of_impact_until(
        &motion_a,
        scene.reach(a),
        &motion_b,
        scene.reach(b),
        &params,
        &mut gap,
        may_continue,
    ) {
        ToiOutcome::Miss => return None,
        ToiOutcome::Initially { contact } => (0.0, contact, true),
        ToiOutcome::Impact { t, contact } => (t, contact, true),
        ToiOutcome::DidNotConverge { t, contact } => (t, contact, false),
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
        exact: true,
    })
}

/// The conservative time of impact of a candidate the frame's deadline left no time to
/// search (module docs): `t = 0`, not reached, the two shapes' boxes at the start of the
/// motion as the record (their distance, a lower bound of the shapes', with the boxes'
/// diagonals and overlap as error bound, their witnesses and normal).
pub(super) fn unsearched(scene: &Scene, pair: &CandidatePair, a: &Body, b: &Body) -> PairToi {
    let start = |body: &Body| scene.bounds_at(body, &scene.frame_motion(body).start);
    let boxes =
        super::answer::boxes(pair, &start(a), &start(b), Query::NONE, &mut Vec::new()).result;
    PairToi {
        a: pair.a,
        b: pair.b,
        time: 0.0,
        distance: boxes.distance,
        error_bound: boxes.error_bound,
        point_a: boxes.point_a,
        point_b: boxes.point_b,
        normal: boxes.normal,
        reached: false,
        exact: false,
    }
}
/// What the time-of-impact stage did under the frame's deadline.
pub(super) struct ToiTally {
    /// Candidates left unsearched ([`unsearched`]).
    pub(super) truncated: u32,
    /// The deadline came: some candidate went unsearched or a search stopped at it.
    pub(super) expired: bool,
}

/// The time of impact of every swept-box candidate of the frame, into `results.tois`,
/// keeping to the frame's clock (`workspace.narrow.clock`, "Under a deadline", module
/// docs).
pub(super) fn answer_tois(
    scene: &Scene,
    plan: &FramePlan,
    workspace: &mut PipelineWorkspace,
    results: &mut FrameResults,
) -> ToiTally {
    let PipelineWorkspace {
        toi_candidates,
        narrow,
        costs,
        ..
    } = workspace;
    // Out of the scratch while the searches borrow it; put back below.
    let mut toi_clock = std::mem::take(&mut narrow.clock);
    let mut truncated = 0;
    for (slot, pair) in toi_candidates.iter().enumerate() {
        let left = toi_candidates.len() - slot;
        plan.pace(&mut toi_clock, costs, left, results.record_count());
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        if !toi_clock.allows(1) {
            truncated += 1;
            results.tois.push(unsearched(scene, pair, a, b));
            continue;
        }
        let shapes = (shape(scene, a), shape(scene, b));
        let searched = pair_toi(scene, pair, (a, shapes.0), (b, shapes.1), narrow, || {
            toi_clock.allows(1)
        });
        if let Some(toi) = searched {
            results.tois.push(toi);
        }
    }
    // Set once a candidate went unsearched or a search stopped at the deadline.
    let expired = toi_clock.stopped();
    narrow.clock = toi_clock;
    ToiTally { truncated, expired }
}
