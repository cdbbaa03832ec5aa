//! Cone along local Z: base disc at `z = -half_height`, apex at `z = +half_height`.

use super::SupportMap;
use super::error::{ShapeError, check_size};
use crate::math::DVec3;

/// The solid cone with base radius `radius` at `z = -half_height` and apex at
/// `(0, 0, half_height)`. Centred on the middle of its axis, not its centroid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// Half the height, metres, ≥ 0.
    pub half_height: f64,
    /// Radius of the base disc, metres, ≥ 0.
    pub radius: f64,
}

impl Cone {
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
}

impl SupportMap for Cone {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        // The farthest point is the apex or a point on the base rim: compare both.
        let apex = DVec3::new(0.0, 0.0, self.half_height);
        let rim = DVec3::new(direction.x, direction.y, 0.0).normalize_or_zero() * self.radius
            - DVec3::new(0.0, 0.0, self.half_height);
        if apex.dot(direction) >= rim.dot(direction) {
            apex
        } else {
            rim
        }
    }
}
