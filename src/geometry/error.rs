//! Why a primitive shape's parameters were rejected.

use std::fmt;

/// Why [`try_new`](super::Sphere::try_new) rejected a primitive's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ShapeError {
    /// A parameter is NaN or infinite.
    NonFinite,
    /// A size parameter (radius, half-height, half-extent) is negative.
    Negative,
    /// A size exceeds [`tolerance::MAX_COORDINATE`](crate::math::tolerance::MAX_COORDINATE).
    TooLarge,
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NonFinite => "shape parameter is NaN or infinite",
            Self::Negative => "shape size parameter is negative",
            Self::TooLarge => "shape size parameter exceeds the largest accepted coordinate",
        })
    }
}

impl std::error::Error for ShapeError {}

/// Checks one size parameter: finite, non-negative, not huge.
pub(crate) fn check_size(x: f64) -> Result<f64, ShapeError> {
    if !x.is_finite() {
        Err(ShapeError::NonFinite)
    } else if x < 0.0 {
        Err(ShapeError::Negative)
    } else if x > crate::math::tolerance::MAX_COORDINATE {
        Err(ShapeError::TooLarge)
    } else {
        Ok(x)
    }
}

/// Checks one point: finite and not huge.
pub(crate) fn check_point(p: crate::math::DVec3) -> Result<crate::math::DVec3, ShapeError> {
    if !p.is_finite() {
        Err(ShapeError::NonFinite)
    } else if p.abs().max_element() > crate::math::tolerance::MAX_COORDINATE {
        Err(ShapeError::TooLarge)
    } else {
        Ok(p)
    }
}
