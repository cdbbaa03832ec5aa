//! Capsule: a segment along local Z, swept by a sphere.

use super::error::{ShapeError, check_size};
use super::{Segment, SupportMap};
use crate::math::DVec3;

/// The set of points within `radius` of the segment from `(0, 0, -half_height)` to
/// `(0, 0, +half_height)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// Half the length of the core segment, metres, ≥ 0.
    pub half_height: f64,
    /// Radius, metres, ≥ 0.
    pub radius: f64,
}

impl Capsule {
    /// From trusted sizes (≥ 0, finite).
    #[must_use]
    pub fn new(half_height: f64, radius: f64) -> Self {
        debug_assert!(check_size(half_height).is_ok() && check_size(radius).is_ok());
        Self {
            half_height,
            radius,
        }
    }

    /// From untrusted sizes.
    pub fn try_new(half_height: f64, radius: f64) -> Result<Self, ShapeError> {
        Ok(Self {
            half_height: check_size(half_height)?,
            radius: check_size(radius)?,
        })
    }

    /// The core segment, local frame.
    #[must_use]
    pub fn segment(&self) -> Segment {
        Segment::new(
            DVec3::new(0.0, 0.0, -self.half_height),
            DVec3::new(0.0, 0.0, self.half_height),
        )
    }
}

impl SupportMap for Capsule {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        let tip = DVec3::new(0.0, 0.0, self.half_height.copysign(direction.z));
        tip + direction.normalize_or_zero() * self.radius
    }
}
