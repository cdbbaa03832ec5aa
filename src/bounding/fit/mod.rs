//! Fitting helpers shared by the oriented volumes (OBB, LSS, RSS): moments, principal axes
//! (from [`crate::geometry::pca`], which convex decomposition shares) and the minimum-area
//! rectangle that settles orientations PCA leaves open.
//!
//! Fitting runs offline (BVH builds, merges), so these functions may allocate; the hot-path
//! overlap and distance tests never call them.

mod calipers;

pub use crate::geometry::pca::{
    Moments, orthonormalise, point_moments, principal_axes, principal_frame, triangle_moments,
};
pub use calipers::{frame_about, min_area_direction};
