//! Which pair a query just answered, so that the manifold asked right after it, of the
//! same pair, reuses that query's work instead of doing it again.

use crate::math::Pose;

/// A pair of shapes by address (both live in the scene for the whole frame) and their
/// relative pose, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PairKey {
    a: usize,
    b: usize,
    pose_ab: Pose,
}

impl PairKey {
    /// The key of `a` and `b` placed by `pose_ab`.
    pub(crate) fn new<A, B>(a: &A, b: &B, pose_ab: &Pose) -> Self {
        Self {
            a: std::ptr::from_ref(a) as usize,
            b: std::ptr::from_ref(b) as usize,
            pose_ab: *pose_ab,
        }
    }
}
