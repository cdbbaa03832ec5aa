//! Triangle given by three points.

use super::SupportMap;
use super::error::{ShapeError, check_point};
use crate::math::{DVec3, Isometry};

/// The triangle `a, b, c` (local frame); counter-clockwise seen from the side its
/// [`normal`](Self::normal) points to. Zero-area triangles are allowed and handled by every
/// query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Triangle {
    /// First vertex, metres.
    pub a: DVec3,
    /// Second vertex, metres.
    pub b: DVec3,
    /// Third vertex, metres.
    pub c: DVec3,
}

impl Triangle {
    /// From trusted vertices.
    #[must_use]
    pub fn new(a: DVec3, b: DVec3, c: DVec3) -> Self {
        debug_assert!(a.is_finite() && b.is_finite() && c.is_finite());
        Self { a, b, c }
    }

    /// From untrusted vertices.
    pub fn try_new(a: DVec3, b: DVec3, c: DVec3) -> Result<Self, ShapeError> {
        Ok(Self {
            a: check_point(a)?,
            b: check_point(b)?,
            c: check_point(c)?,
        })
    }

    /// The vertices as an array.
    #[must_use]
    #[inline]
    pub fn vertices(&self) -> [DVec3; 3] {
        [self.a, self.b, self.c]
    }

    /// `(b - a) × (c - a)`: normal direction with length twice the area.
    #[must_use]
    #[inline]
    pub fn scaled_normal(&self) -> DVec3 {
        (self.b - self.a).cross(self.c - self.a)
    }

    /// Unit normal, or `None` when the triangle has zero area (to rounding).
    #[must_use]
    #[inline]
    pub fn normal(&self) -> Option<DVec3> {
        self.scaled_normal().try_normalize()
    }

    /// Area, square metres.
    #[must_use]
    #[inline]
    pub fn area(&self) -> f64 {
        0.5 * self.scaled_normal().length()
    }

    /// The triangle moved by `pose` (each vertex through [`Isometry::transform_point`]).
    ///
    /// Mesh–mesh queries map B's triangles into A's frame with exactly this function, so an
    /// oracle that does the same sees bit-identical triangles.
    #[must_use]
    #[inline]
    pub fn transformed(&self, pose: &Isometry) -> Self {
        Self {
            a: pose.transform_point(self.a),
            b: pose.transform_point(self.b),
            c: pose.transform_point(self.c),
        }
    }

    /// Centroid.
    #[must_use]
    #[inline]
    pub fn centroid(&self) -> DVec3 {
        (self.a + self.b + self.c) / 3.0
    }
}

impl SupportMap for Triangle {
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        let (da, db, dc) = (
            self.a.dot(direction),
            self.b.dot(direction),
            self.c.dot(direction),
        );
        if da >= db && da >= dc {
            self.a
        } else if db >= dc {
            self.b
        } else {
            self.c
        }
    }
}
