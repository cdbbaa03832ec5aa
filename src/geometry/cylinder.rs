//! Cylinder along local Z, centred on the origin.

use super::SupportMap;
use super::error::{ShapeError, check_size};
use crate::math::DVec3;

/// The solid cylinder `x² + y² ≤ radius²`, `|z| ≤ half_height`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    /// Half the height, metres, ≥ 0.
    pub half_height: f64,
    /// Radius, metres, ≥ 0.
    pub radius: f64,
}

impl Cylinder {
    /// From trusted sizes (≥ 0, finite).
    #[must_use]
    pub fn new(half_height: f64, radius: f64) -> Self {
        debug_assert!(check_size(half_height).is_ok() && check_size(radius).is_ok());
        Self {
            half_height,
            radius,
        }
    }

    /// The point of the solid cylinder nearest to `p` (local frame): `p` itself when inside,
    /// else `p` with its radial part pulled in to the radius and its height clamped to the
    /// caps.
    #[must_use]
    #[inline]
    pub fn closest_point(&self, p: DVec3) -> DVec3 {
        let rho = DVec3::new(p.x, p.y, 0.0).length();
        let pulled_in = if rho > self.radius {
            self.radius / rho
        } else {
            1.0
        };
        DVec3::new(
            p.x * pulled_in,
            p.y * pulled_in,
            p.z.clamp(-self.half_height, self.half_height),
        )
    }

    /// From untrusted sizes.
    pub fn try_new(half_height: f64, radius: f64) -> Result<Self, ShapeError> {
        Ok(Self {
            half_height: check_size(half_height)?,
            radius: check_size(radius)?,
        })
    }
}

impl SupportMap for Cylinder {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        let radial = DVec3::new(direction.x, direction.y, 0.0).normalize_or_zero() * self.radius;
        radial + DVec3::new(0.0, 0.0, self.half_height.copysign(direction.z))
    }
}
