//! Fitting helpers shared by the oriented volumes (OBB, LSS, RSS): moments, principal axes
//! and the minimum-area rectangle that settles orientations PCA leaves open.
//!
//! This is the only module that uses faer (for the self-adjoint eigen-decomposition). Fitting
//! runs offline (BVH builds, merges), so these functions may allocate; the hot-path
//! overlap and distance tests never call them.

mod calipers;
mod pca;

pub use calipers::{frame_about, min_area_direction};
pub use pca::{
    Moments, orthonormalise, point_moments, principal_axes, principal_frame, triangle_moments,
};
