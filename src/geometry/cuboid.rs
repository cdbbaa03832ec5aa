//! Box centred on the origin, aligned with the local axes.

use super::SupportMap;
use super::error::{ShapeError, check_size};
use crate::math::DVec3;

/// The box `[-h.x, h.x] × [-h.y, h.y] × [-h.z, h.z]` with `h = half_extents`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cuboid {
    /// Half side lengths, metres, each ≥ 0.
    pub half_extents: DVec3,
}

impl Cuboid {
    /// From trusted half extents (≥ 0, finite).
    #[must_use]
    pub fn new(half_extents: DVec3) -> Self {
        debug_assert!(half_extents.is_finite() && half_extents.min_element() >= 0.0);
        Self { half_extents }
    }

    /// From untrusted half extents.
    pub fn try_new(half_extents: DVec3) -> Result<Self, ShapeError> {
        for h in half_extents.to_array() {
            check_size(h)?;
        }
        Ok(Self { half_extents })
    }

    /// The 8 corners, local frame, in binary order (bit i set = +h along axis i).
    #[must_use]
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|i| {
            let s = DVec3::new(
                if i & 1 != 0 { 1.0 } else { -1.0 },
                if i & 2 != 0 { 1.0 } else { -1.0 },
                if i & 4 != 0 { 1.0 } else { -1.0 },
            );
            s * self.half_extents
        })
    }
}

impl SupportMap for Cuboid {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        // copysign keeps the +h corner for zero components, so the answer is a vertex.
        DVec3::new(
            self.half_extents.x.copysign(direction.x),
            self.half_extents.y.copysign(direction.y),
            self.half_extents.z.copysign(direction.z),
        )
    }
}
