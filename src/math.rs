//! Math types: glam re-exports, rigid poses, and the named tolerances every module shares.
//!
//! Two forms of a rigid motion live here:
//! - [`Pose`]: f64 position + unit quaternion. The public and wire-facing form; composes
//!   exactly, renormalises, and is what a body's placement is stored as.
//! - [`Isometry`]: rotation matrix + translation, the form hot paths take. Bounding-volume
//!   tests under a relative pose build one `Isometry` per pair, never per test.
//!
//! Convention for relative poses: `pose_ab` is the pose of frame B expressed in frame A, so
//! `pose_ab.transform_point(p_b)` gives the point's coordinates in A. With world poses
//! `pose_a` and `pose_b`, `pose_ab = pose_a.inverse() * pose_b` ([`Pose::relative`]).
//!
//! Units are SI throughout: metres and radians.

use std::fmt;
use std::ops::Mul;

pub use glam::{DMat3, DQuat, DVec3, Mat3, Quat, Vec3, Vec3A};

/// Named tolerances. Every comparison against a small number uses one of these.
pub mod tolerance {
    /// A quaternion whose length differs from 1 by more than this (relative) is rejected at
    /// the boundary instead of silently renormalised: it is a client bug, not rounding.
    pub const UNIT_QUATERNION: f64 = 1e-6;

    /// Relative tolerance (times the scale of the coordinates involved) under which two
    /// points are treated as coincident when building hulls and fitting volumes.
    pub const COINCIDENT_RELATIVE: f64 = 1e-12;

    /// Relative tolerance for orientation tests in hull construction: a point closer than
    /// `PLANE_RELATIVE * scale` to a face plane counts as on the plane.
    pub const PLANE_RELATIVE: f64 = 1e-10;

    /// Relative slack added to bounding-volume overlap tests so that rounding in the test
    /// itself can never turn an overlap into a miss (the tests stay conservative).
    pub const BV_RELATIVE: f64 = 1e-12;

    /// Added to every entry of |R| in separating-axis tests (Gottschalk's trick) so that
    /// near-parallel edges, whose cross product is nearly zero, never yield a false
    /// separating axis.
    pub const SAT_PARALLEL: f64 = 1e-9;

    /// Largest coordinate magnitude (metres) accepted from outside. Beyond this, squared
    /// lengths lose all precision that the predicates rely on.
    pub const MAX_COORDINATE: f64 = 1e9;
}

/// The smallest axis-aligned box `(min, max)` holding `points`, metres; `(+∞, −∞)` when
/// there are none.
#[must_use]
pub fn bounds_of(points: impl IntoIterator<Item = DVec3>) -> (DVec3, DVec3) {
    points
        .into_iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        })
}

/// Slack that keeps a floating-point comparison of quantities of magnitude `scale`
/// conservative: `BV_RELATIVE * scale`, plus a tiny absolute floor for `scale == 0`.
#[must_use]
#[inline]
pub fn conservative_slack(scale: f64) -> f64 {
    tolerance::BV_RELATIVE * scale + f64::MIN_POSITIVE
}

/// Why a [`Pose`] was rejected by [`Pose::try_new`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum PoseError {
    /// A position component is NaN or infinite.
    NonFinitePosition,
    /// A quaternion component is NaN or infinite.
    NonFiniteRotation,
    /// A position component exceeds [`tolerance::MAX_COORDINATE`].
    PositionTooLarge,
    /// The quaternion's length differs from 1 by more than [`tolerance::UNIT_QUATERNION`].
    NotUnitQuaternion,
}

impl fmt::Display for PoseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NonFinitePosition => "pose position has a NaN or infinite component",
            Self::NonFiniteRotation => "pose orientation has a NaN or infinite component",
            Self::PositionTooLarge => "pose position exceeds the largest accepted coordinate",
            Self::NotUnitQuaternion => "pose orientation is not a unit quaternion",
        })
    }
}

impl std::error::Error for PoseError {}

/// A rigid pose: f64 position (metres) and unit-quaternion orientation.
///
/// Maps points from the pose's local frame to its parent frame: `p_parent = R p_local + t`.
///
/// # Invariants
/// `rotation` is a unit quaternion (to rounding); `position` is finite. [`Pose::new`] checks
/// this with `debug_assert!`; [`Pose::try_new`] checks it always and is what the IPC
/// boundary calls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Origin of the local frame in the parent frame, metres.
    pub position: DVec3,
    /// Orientation of the local frame in the parent frame.
    pub rotation: DQuat,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Self = Self {
        position: DVec3::ZERO,
        rotation: DQuat::IDENTITY,
    };

    /// A pose from trusted parts. The quaternion must be unit length.
    #[must_use]
    #[inline]
    pub fn new(position: DVec3, rotation: DQuat) -> Self {
        debug_assert!(position.is_finite(), "non-finite position {position}");
        debug_assert!(rotation.is_normalized(), "non-unit rotation {rotation}");
        Self { position, rotation }
    }

    /// A pose from untrusted parts: rejects non-finite or huge positions and quaternions
    /// that are not unit within [`tolerance::UNIT_QUATERNION`]; renormalises the rest.
    pub fn try_new(position: DVec3, rotation: DQuat) -> Result<Self, PoseError> {
        if !position.is_finite() {
            return Err(PoseError::NonFinitePosition);
        }
        if !rotation.is_finite() {
            return Err(PoseError::NonFiniteRotation);
        }
        if position.abs().max_element() > tolerance::MAX_COORDINATE {
            return Err(PoseError::PositionTooLarge);
        }
        let length = rotation.length();
        if (length - 1.0).abs() > tolerance::UNIT_QUATERNION {
            return Err(PoseError::NotUnitQuaternion);
        }
        Ok(Self {
            position,
            rotation: rotation / length,
        })
    }

    /// A pure translation.
    #[must_use]
    #[inline]
    pub fn from_translation(position: DVec3) -> Self {
        Self {
            position,
            rotation: DQuat::IDENTITY,
        }
    }

    /// A pure rotation.
    #[must_use]
    #[inline]
    pub fn from_rotation(rotation: DQuat) -> Self {
        Self::new(DVec3::ZERO, rotation)
    }

    /// The inverse pose: maps parent coordinates back to local ones.
    #[must_use]
    #[inline]
    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.conjugate();
        Self {
            position: -(rotation * self.position),
            rotation,
        }
    }

    /// `self * other`: apply `other` first, then `self` (`other` is expressed in `self`'s
    /// local frame). The quaternion is renormalised so long chains do not drift.
    #[must_use]
    #[inline]
    pub fn compose(&self, other: &Self) -> Self {
        Self {
            position: self.position + self.rotation * other.position,
            rotation: (self.rotation * other.rotation).normalize(),
        }
    }

    /// The pose of `b` in the frame of `a`, from both world poses: `a⁻¹ · b`.
    #[must_use]
    #[inline]
    pub fn relative(a: &Self, b: &Self) -> Self {
        a.inverse().compose(b)
    }

    /// Maps a local point to the parent frame.
    #[must_use]
    #[inline]
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.position
    }

    /// Rotates a local vector into the parent frame.
    #[must_use]
    #[inline]
    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// Maps a parent-frame point to the local frame.
    #[must_use]
    #[inline]
    pub fn inverse_transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation.conjugate() * (p - self.position)
    }

    /// Rotates a parent-frame vector into the local frame.
    #[must_use]
    #[inline]
    pub fn inverse_transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation.conjugate() * v
    }

    /// The matrix form, for hot paths that apply the same pose many times.
    #[must_use]
    #[inline]
    pub fn to_isometry(&self) -> Isometry {
        Isometry {
            rotation: DMat3::from_quat(self.rotation),
            translation: self.position,
        }
    }

    /// True when both poses describe the same rigid motion; `q` and `-q` are the same
    /// rotation.
    #[must_use]
    pub fn same_motion(&self, other: &Self) -> bool {
        self.position == other.position
            && (self.rotation == other.rotation || self.rotation == -other.rotation)
    }
}

impl Mul for Pose {
    type Output = Pose;
    #[inline]
    fn mul(self, rhs: Pose) -> Pose {
        self.compose(&rhs)
    }
}

/// A rigid motion in matrix form: `p ↦ rotation · p + translation`.
///
/// The form bounding-volume tests and traversal take. Built from a [`Pose`] once per pair.
///
/// # Invariants
/// `rotation` is orthonormal with determinant +1 (to rounding).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Isometry {
    /// Rotation matrix; its columns are the local axes expressed in the parent frame.
    pub rotation: DMat3,
    /// Translation, metres.
    pub translation: DVec3,
}

impl Default for Isometry {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Isometry {
    /// The identity motion.
    pub const IDENTITY: Self = Self {
        rotation: DMat3::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// From a rotation matrix and a translation. The matrix must be a rotation.
    #[must_use]
    #[inline]
    pub fn new(rotation: DMat3, translation: DVec3) -> Self {
        debug_assert!(
            (rotation.transpose() * rotation).abs_diff_eq(DMat3::IDENTITY, 1e-9),
            "not a rotation: {rotation}"
        );
        Self {
            rotation,
            translation,
        }
    }

    /// A pure translation.
    #[must_use]
    #[inline]
    pub fn from_translation(translation: DVec3) -> Self {
        Self {
            rotation: DMat3::IDENTITY,
            translation,
        }
    }

    /// Maps a local point to the parent frame.
    #[must_use]
    #[inline]
    pub fn transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// Rotates a local vector into the parent frame.
    #[must_use]
    #[inline]
    pub fn transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// Maps a parent-frame point to the local frame.
    #[must_use]
    #[inline]
    pub fn inverse_transform_point(&self, p: DVec3) -> DVec3 {
        self.rotation.transpose() * (p - self.translation)
    }

    /// Rotates a parent-frame vector into the local frame.
    #[must_use]
    #[inline]
    pub fn inverse_transform_vector(&self, v: DVec3) -> DVec3 {
        self.rotation.transpose() * v
    }

    /// The inverse motion.
    #[must_use]
    #[inline]
    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.transpose();
        Self {
            rotation,
            translation: -(rotation * self.translation),
        }
    }

    /// `self * other`: apply `other` first, then `self`.
    #[must_use]
    #[inline]
    pub fn compose(&self, other: &Self) -> Self {
        Self {
            rotation: self.rotation * other.rotation,
            translation: self.transform_point(other.translation),
        }
    }

    /// Back to quaternion form (renormalised).
    #[must_use]
    pub fn to_pose(&self) -> Pose {
        Pose {
            position: self.translation,
            rotation: DQuat::from_mat3(&self.rotation).normalize(),
        }
    }

    /// The f32 form, for bounding-volume tests that run in single precision.
    #[must_use]
    #[inline]
    pub fn to_f32(&self) -> IsometryF32 {
        IsometryF32 {
            rotation: self.rotation.as_mat3(),
            translation: self.translation.as_vec3(),
        }
    }
}

impl Mul for Isometry {
    type Output = Isometry;
    #[inline]
    fn mul(self, rhs: Isometry) -> Isometry {
        self.compose(&rhs)
    }
}

impl From<Pose> for Isometry {
    #[inline]
    fn from(pose: Pose) -> Self {
        pose.to_isometry()
    }
}

/// An [`Isometry`] rounded to f32, for bounding-volume tests that run in single precision.
///
/// Rounding moves every entry by at most half an ulp; a test that uses this form must add
/// [`f32_rounding_slack`] of the magnitudes involved to stay conservative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IsometryF32 {
    /// Rotation matrix rounded to f32.
    pub rotation: Mat3,
    /// Translation rounded to f32, metres.
    pub translation: Vec3,
}

/// Slack (same unit as `magnitude`) that covers the rounding of an f32 evaluation of a
/// short dot-product chain (≤ 16 operations) over quantities of size `magnitude`: each
/// operation contributes at most one f32 ulp of the running magnitude.
#[must_use]
#[inline]
pub fn f32_rounding_slack(magnitude: f32) -> f32 {
    16.0 * f32::EPSILON * magnitude + f32::MIN_POSITIVE
}

/// An f32 at or below `x`, for lower interval ends: the nearest f32 (within half an ulp,
/// 2⁻²⁴ relative) lowered by a relative 2⁻²² and the smallest normal, so at most about
/// 3·2⁻²⁴ of `|x|` below it. Beyond f32's range, `±f32::MAX` or below.
///
/// Not the largest such f32: that needs a test of the nearest rounding's direction,
/// which is random and mispredicted half the time. Measured in the sort and sweep's
/// per-frame rounding of 10,000 boxes (`examples/broad_bench`, all moving): with the
/// test, 27 % of the frame; without, 4 %.
#[must_use]
#[inline]
pub fn f32_round_down(x: f64) -> f32 {
    let y = (x as f32).clamp(-f32::MAX, f32::MAX);
    y - (y.abs() * (2.0 * f32::EPSILON) + f32::MIN_POSITIVE)
}

/// An f32 at or above `x`, for upper interval ends and radii (as [`f32_round_down`]).
#[must_use]
#[inline]
pub fn f32_round_up(x: f64) -> f32 {
    -f32_round_down(-x)
}

/// An orthonormal basis `(u, v)` completing the unit vector `n` to a right-handed frame
/// `(u, v, n)`. Continuous except at one pole (Duff et al. 2017, "Building an Orthonormal
/// Basis, Revisited").
#[must_use]
#[inline]
pub fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    n.any_orthonormal_pair()
}

/// SplitMix64's finaliser (Steele, Lea, Flood 2014): a bijection of `u64` whose every
/// output bit depends on every input bit, for hashes and repeatable pseudo-random draws.
#[must_use]
#[inline]
pub(crate) fn splitmix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quat_from_seed(seed: u64) -> DQuat {
        // A cheap deterministic spread of rotations for tests in this file.
        let s = seed as f64;
        DQuat::from_euler(
            glam::EulerRot::ZYX,
            s * 0.731,
            s * 1.377 - 2.0,
            s * 2.113 + 0.5,
        )
    }

    #[test]
    fn inverse_composes_to_identity() {
        for seed in 0..1000 {
            let pose = Pose::new(DVec3::new(seed as f64, -3.0, 1e5), quat_from_seed(seed));
            let id = pose.compose(&pose.inverse());
            assert!(
                id.position.length() < 1e-9,
                "seed {seed}: {:?}",
                id.position
            );
            assert!(
                id.rotation.abs_diff_eq(DQuat::IDENTITY, 1e-12)
                    || id.rotation.abs_diff_eq(-DQuat::IDENTITY, 1e-12)
            );
        }
    }

    #[test]
    fn relative_pose_maps_b_local_into_a_local() {
        for seed in 0..1000 {
            let a = Pose::new(DVec3::new(1.0, 2.0, seed as f64), quat_from_seed(seed));
            let b = Pose::new(
                DVec3::new(-4.0, seed as f64 * 0.5, 3.0),
                quat_from_seed(seed + 17),
            );
            let pose_ab = Pose::relative(&a, &b);
            let p_b = DVec3::new(0.3, -0.7, 1.1);
            let via_world = a.inverse_transform_point(b.transform_point(p_b));
            assert!(
                pose_ab.transform_point(p_b).abs_diff_eq(via_world, 1e-9),
                "seed {seed}"
            );
            let iso = pose_ab.to_isometry();
            assert!(
                iso.transform_point(p_b).abs_diff_eq(via_world, 1e-9),
                "seed {seed}"
            );
            assert!(
                iso.inverse()
                    .transform_point(via_world)
                    .abs_diff_eq(p_b, 1e-9),
                "seed {seed}"
            );
            let back = iso.to_pose();
            assert!(
                back.transform_point(p_b).abs_diff_eq(via_world, 1e-9),
                "seed {seed}"
            );
        }
    }

    #[test]
    fn isometry_compose_matches_pose_compose() {
        for seed in 0..200 {
            let a = Pose::new(DVec3::new(seed as f64, 1.0, -2.0), quat_from_seed(seed));
            let b = Pose::new(DVec3::new(0.5, -1.5, 7.0), quat_from_seed(seed * 3 + 1));
            let p = DVec3::new(1.0, 2.0, 3.0);
            let via_pose = (a * b).transform_point(p);
            let via_iso = (a.to_isometry() * b.to_isometry()).transform_point(p);
            assert!(via_pose.abs_diff_eq(via_iso, 1e-9), "seed {seed}");
        }
    }

    #[test]
    fn try_new_rejects_bad_input_and_renormalises_rounding() {
        let q = DQuat::from_xyzw(0.0, 0.0, 0.0, 1.0);
        assert_eq!(
            Pose::try_new(DVec3::new(f64::NAN, 0.0, 0.0), q),
            Err(PoseError::NonFinitePosition)
        );
        assert_eq!(
            Pose::try_new(DVec3::ZERO, DQuat::from_xyzw(f64::INFINITY, 0.0, 0.0, 1.0)),
            Err(PoseError::NonFiniteRotation)
        );
        assert_eq!(
            Pose::try_new(DVec3::new(2e9, 0.0, 0.0), q),
            Err(PoseError::PositionTooLarge)
        );
        assert_eq!(
            Pose::try_new(DVec3::ZERO, DQuat::from_xyzw(0.0, 0.0, 0.0, 1.1)),
            Err(PoseError::NotUnitQuaternion)
        );
        assert_eq!(
            Pose::try_new(DVec3::ZERO, DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
            Err(PoseError::NotUnitQuaternion)
        );
        let nearly =
            Pose::try_new(DVec3::ZERO, DQuat::from_xyzw(0.0, 0.0, 0.0, 1.0 + 1e-8)).unwrap();
        assert!((nearly.rotation.length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn q_and_minus_q_are_the_same_motion() {
        let pose = Pose::new(DVec3::new(1.0, 2.0, 3.0), quat_from_seed(5));
        let flipped = Pose::new(pose.position, -pose.rotation);
        assert!(pose.same_motion(&flipped));
        let p = DVec3::new(-1.0, 0.5, 2.0);
        assert!(
            pose.transform_point(p)
                .abs_diff_eq(flipped.transform_point(p), 1e-12)
        );
    }

    /// The rounded ends bracket the value at every magnitude, within a few f32 ulps inside
    /// f32's normal range, over values that round to nearest in both directions.
    #[test]
    fn f32_rounding_brackets_the_value_at_any_magnitude() {
        use rand::Rng;
        let mut rng = crate::test_support::rng(41);
        let mut both = [0usize; 2];
        let special = [
            0.1,
            -0.1,
            1e-30,
            3.0,
            1e7 + 0.3,
            -123.456789,
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            1e-40,
            -1e-40,
            f64::from(f32::MAX),
            -f64::from(f32::MAX),
            1e39,
            -1e39,
            1e300,
            -1e300,
        ];
        let random = (0..20_000).map(|_| {
            let magnitude = 10f64.powf(rng.random_range(-12.0..12.0));
            magnitude * rng.random_range(-1.0..1.0)
        });
        for x in special.into_iter().chain(random) {
            let (below, above) = (f32_round_down(x), f32_round_up(x));
            assert!(
                f64::from(below) <= x && x <= f64::from(above),
                "{x}: {below} {above}"
            );
            if x.abs() > 1e-30 && x.abs() < 1e30 {
                assert!(f64::from(above) - f64::from(below) <= 1e-6 * x.abs(), "{x}");
            }
            // Which side of `x` the nearest f32 falls on: both must occur.
            both[usize::from(f64::from(x as f32) > x)] += 1;
        }
        assert!(both[0] > 1_000 && both[1] > 1_000, "{both:?}");
    }
}
