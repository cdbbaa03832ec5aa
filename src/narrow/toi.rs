//! Time of impact over one frame's motion, by conservative advancement, and the swept
//! world box a broad phase needs to find the pairs worth asking.
//!
//! # Motion over a frame
//! A body moves from `start` to `end` over the frame's unit time `t ∈ [0, 1]`: its origin
//! along the straight segment, its orientation by slerp (a constant angular speed `θ`, the
//! angle between the two orientations, about a fixed axis). Every point of a shape within
//! `reach` of its origin then moves at most `|Δp| + θ · reach` per unit time.
//!
//! # Conservative advancement (Mirtich 1996; Zhang et al. 2006)
//! At time `t` the shapes are `d` apart along the unit normal `n` (A→B). Two convex shapes
//! stay apart by at least their separation along `n`, so their distance cannot shrink
//! faster than `μ = max(0, −Δp_rel · n) + θ_a · reach_a + θ_b · reach_b`; any other pair
//! (a mesh is not convex: another part of it may close in from the side) only by
//! `μ = |Δp_rel| + θ_a · reach_a + θ_b · reach_b`, the fastest a point of B moves relative
//! to a point of A. Advancing by `d / μ` never passes the first contact. Repeated, `t` converges to the time
//! of impact from below; the search stops when `d ≤ tolerance`, when `t` passes 1 (no
//! impact this frame) or after `max_iterations`. The distance comes from a caller-given
//! query (closed form, GJK, or mesh–mesh), so one driver serves every pair of shapes.
//!
//! Citation: B. Mirtich, *Impulse-based dynamic simulation of rigid body systems*, PhD
//! thesis, UC Berkeley 1996, §2.3; X. Zhang, S. Redon, M. Lee, Y. J. Kim, *Continuous
//! collision detection for articulated models using Taylor models and temporal culling*,
//! SIGGRAPH 2007 (the motion bound).

use super::contact::ShapeDistance;
use crate::bounding::{Aabb, BoundingVolume};
use crate::math::{DQuat, DVec3, Pose};

/// A body's motion over one frame: from `start` at `t = 0` to `end` at `t = 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameMotion {
    /// Pose at the start of the frame, world frame.
    pub start: Pose,
    /// Pose at the end of the frame, world frame.
    pub end: Pose,
}

impl FrameMotion {
    /// A body that does not move.
    #[must_use]
    pub fn at_rest(pose: Pose) -> Self {
        Self {
            start: pose,
            end: pose,
        }
    }

    /// The pose at `t ∈ [0, 1]`: position interpolated linearly, orientation by slerp
    /// along the shorter arc (`q` and `−q` give the same motion).
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Pose {
        let position = self.start.position.lerp(self.end.position, t);
        let rotation = self
            .start
            .rotation
            .slerp(shorter_arc(self.start.rotation, self.end.rotation), t)
            .normalize();
        Pose { position, rotation }
    }

    /// The rotation angle over the frame, radians, in `[0, π]`.
    #[must_use]
    pub fn angle(&self) -> f64 {
        let end = shorter_arc(self.start.rotation, self.end.rotation);
        let cos_half = self.start.rotation.dot(end).clamp(-1.0, 1.0);
        2.0 * cos_half.acos()
    }

    /// The origin's displacement over the frame, metres.
    #[must_use]
    pub fn displacement(&self) -> DVec3 {
        self.end.position - self.start.position
    }
}

/// `end`, or `−end` when that is the nearer of the two quaternions of the same rotation.
fn shorter_arc(start: DQuat, end: DQuat) -> DQuat {
    if start.dot(end) < 0.0 { -end } else { end }
}

/// The world box covering a shape over its whole motion: the boxes at both ends, merged,
/// grown by the largest distance a point strays from the straight path between its two
/// end positions (the sagitta `reach · (1 − cos(θ/2))` of its arc; `reach` for `θ > π`
/// cannot happen on the shorter arc). `local` is the shape's local box, `reach` the largest
/// distance of a shape point from the shape's origin, metres.
#[must_use]
pub fn swept_bounds(local: &Aabb, reach: f64, motion: &FrameMotion) -> Aabb {
    let start = local.transformed(&motion.start.to_isometry());
    let end = local.transformed(&motion.end.to_isometry());
    let sagitta = reach * (1.0 - (motion.angle() / 2.0).cos());
    Aabb::new(start.min.min(end.min), start.max.max(end.max)).grown(sagitta.max(0.0))
}

/// Settings of [`time_of_impact`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToiParams {
    /// The search stops once the shapes are at most this far apart, metres (`> 0`).
    pub tolerance: f64,
    /// Most distance queries.
    pub max_iterations: u32,
    /// Both shapes are convex, so the approach along the normal bounds how fast the
    /// distance shrinks (much faster convergence for grazing motions). `false` (the
    /// default) is sound for every pair, meshes included.
    pub convex: bool,
}

impl Default for ToiParams {
    fn default() -> Self {
        Self {
            tolerance: 1e-6,
            max_iterations: 64,
            convex: false,
        }
    }
}

/// What [`time_of_impact`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ToiOutcome {
    /// First contact at `t` (within the tolerance): the shapes are apart at every earlier
    /// time and at most `tolerance` apart at `t`; `contact` is the distance query there
    /// (world frame).
    Impact {
        /// Time of impact in `[0, 1]`.
        t: f64,
        /// The shapes' distance, witnesses and normal at `t`.
        contact: ShapeDistance,
    },
    /// Already touching or penetrating at `t = 0`.
    Initially {
        /// The distance query at `t = 0`.
        contact: ShapeDistance,
    },
    /// No contact during the frame.
    Miss,
    /// Still apart after `max_iterations` (a bound too loose for the motion), or stopped by
    /// the caller ([`time_of_impact_until`]); `t` is conservative: no contact happened
    /// before it.
    DidNotConverge {
        /// How far the search safely got.
        t: f64,
        /// The distance query at `t` (world frame): the pair is still apart there.
        contact: ShapeDistance,
    },
}

/// The first time in `[0, 1]` at which two shapes moving by `motion_a` and `motion_b`
/// come within `params.tolerance` of each other.
///
/// `reach_a`/`reach_b` bound the distance of each shape's points from its origin, metres;
/// `distance(pose_a, pose_b)` answers the signed distance of the shapes at two world poses
/// (world frame, normal A→B).
pub fn time_of_impact(
    motion_a: &FrameMotion,
    reach_a: f64,
    motion_b: &FrameMotion,
    reach_b: f64,
    params: &ToiParams,
    distance: impl FnMut(&Pose, &Pose) -> ShapeDistance,
) -> ToiOutcome {
    time_of_impact_until(
        motion_a,
        reach_a,
        motion_b,
        reach_b,
        params,
        distance,
        || true,
    )
}

/// [`time_of_impact`], asking `may_continue` before each distance query after the first:
/// once it says no (a frame's deadline), the search stops with
/// [`ToiOutcome::DidNotConverge`] at the time it safely reached.
pub fn time_of_impact_until(
    motion_a: &FrameMotion,
    reach_a: f64,
    motion_b: &FrameMotion,
    reach_b: f64,
    params: &ToiParams,
    mut distance: impl FnMut(&Pose, &Pose) -> ShapeDistance,
    mut may_continue: impl FnMut() -> bool,
) -> ToiOutcome {
    let first = distance(&motion_a.start, &motion_b.start);
    if first.distance <= params.tolerance {
        return ToiOutcome::Initially { contact: first };
    }
    let relative = motion_b.displacement() - motion_a.displacement();
    let turning = motion_a.angle() * reach_a + motion_b.angle() * reach_b;
    let (mut t, mut contact) = (0.0, first);
    for _ in 0..params.max_iterations {
        if !may_continue() {
            break;
        }
        // Fastest rate at which the distance can shrink: the approach (along the normal
        // for convex shapes) plus the rotations' sweep.
        let approach = if params.convex {
            (-relative.dot(contact.normal)).max(0.0)
        } else {
            relative.length()
        };
        let closing = approach + turning;
        if closing <= 0.0 {
            return ToiOutcome::Miss;
        }
        // Advance to just short of where the bound says contact could first happen.
        t += (contact.distance - 0.5 * params.tolerance).max(0.0) / closing;
        if t > 1.0 {
            return ToiOutcome::Miss;
        }
        contact = distance(&motion_a.pose_at(t), &motion_b.pose_at(t));
        if contact.distance <= params.tolerance {
            return ToiOutcome::Impact { t, contact };
        }
    }
    ToiOutcome::DidNotConverge { t, contact }
}

#[cfg(test)]
#[path = "toi_tests.rs"]
mod tests;
