//! Sphere centred on the origin.

use super::SupportMap;
use super::error::{ShapeError, check_size};
use crate::math::DVec3;

/// A sphere of `radius` metres centred on the local origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Radius, metres, ≥ 0.
    pub radius: f64,
}

impl Sphere {
    /// From a trusted radius (≥ 0, finite).
    #[must_use]
    pub fn new(radius: f64) -> Self {
        debug_assert!(check_size(radius).is_ok(), "bad sphere radius {radius}");
        Self { radius }
    }

    /// From an untrusted radius.
    pub fn try_new(radius: f64) -> Result<Self, ShapeError> {
        Ok(Self {
            radius: check_size(radius)?,
        })
    }
}

impl SupportMap for Sphere {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        direction.normalize_or_zero() * self.radius
    }
}
