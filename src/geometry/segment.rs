//! Line segment between two points.

use super::SupportMap;
use super::error::{ShapeError, check_point};
use crate::math::DVec3;

/// The segment from `a` to `b` (local frame). `a == b` is allowed: a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// First end point, metres.
    pub a: DVec3,
    /// Second end point, metres.
    pub b: DVec3,
}

impl Segment {
    /// From trusted end points.
    #[must_use]
    pub fn new(a: DVec3, b: DVec3) -> Self {
        debug_assert!(a.is_finite() && b.is_finite());
        Self { a, b }
    }

    /// From untrusted end points.
    pub fn try_new(a: DVec3, b: DVec3) -> Result<Self, ShapeError> {
        Ok(Self {
            a: check_point(a)?,
            b: check_point(b)?,
        })
    }

    /// `b - a`.
    #[must_use]
    #[inline]
    pub fn direction(&self) -> DVec3 {
        self.b - self.a
    }

    /// Length, metres.
    #[must_use]
    #[inline]
    pub fn length(&self) -> f64 {
        self.direction().length()
    }

    /// The point `a + t (b - a)`.
    #[must_use]
    #[inline]
    pub fn point_at(&self, t: f64) -> DVec3 {
        self.a + (self.b - self.a) * t
    }
}

impl SupportMap for Segment {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        if self.b.dot(direction) > self.a.dot(direction) {
            self.b
        } else {
            self.a
        }
    }
}
