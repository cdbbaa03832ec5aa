//! Shapes, in their own local frames. No poses here: a shape is placed by a body's pose.
//!
//! Axis conventions (shared with FCL and Coal): capsule, cylinder and cone are aligned with
//! the local **Z** axis and centred on the origin (the cone's apex at `+half_height`).
//! Every convex shape implements [`SupportMap`], which is all GJK needs.
//!
//! Constructors come in two doors (STYLE.md §3): `new` for trusted input, checked with
//! `debug_assert!`, and `try_new`, which returns [`ShapeError`] and is what the IPC boundary
//! calls.

mod capsule;
mod cone;
pub mod convex;
mod cuboid;
mod cylinder;
pub mod decompose;
mod error;
pub mod mesh;
pub mod pca;
mod point_tree;
pub mod predicates;
mod segment;
mod sphere;
mod triangle;

pub use capsule::Capsule;
pub use cone::Cone;
pub use convex::{ConvexHullError, ConvexPolyhedron, HullTriangle};
pub use cuboid::Cuboid;
pub use cylinder::Cylinder;
pub use error::ShapeError;
pub use mesh::{MeshError, MeshLimits, MeshReport, TriMesh};
pub use point_tree::PointTree;
pub use segment::{Segment, closest_points_segment_segment};
pub use sphere::Sphere;
pub use triangle::Triangle;

use crate::math::DVec3;

/// The kinds of shape, in canonical pair order: a narrow-phase pair function is written only
/// for `(a, b)` with `a <= b` in this order; the dispatcher flips the rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ShapeKind {
    /// [`Sphere`].
    Sphere,
    /// [`Capsule`].
    Capsule,
    /// [`Cuboid`].
    Cuboid,
    /// [`Cylinder`].
    Cylinder,
    /// [`Cone`].
    Cone,
    /// [`Segment`].
    Segment,
    /// [`Triangle`].
    Triangle,
    /// [`ConvexPolyhedron`].
    Convex,
    /// [`TriMesh`].
    Mesh,
}

/// The support mapping of a convex shape: the point of the shape farthest along a direction.
///
/// # Contract
/// `support(d)` returns a point `p` of the shape with `p · d = max over the shape of x · d`,
/// in the shape's local frame. `d` need not be unit length; for `d = 0` any point of the
/// shape is returned. Never NaN for finite `d`.
pub trait SupportMap {
    /// The farthest point of the shape along `direction` (local frame).
    #[must_use]
    fn support(&self, direction: DVec3) -> DVec3;

    /// [`support`](Self::support) with a search hint kept by the caller between calls
    /// along nearby directions (GJK's iterations, one pair across frames): shapes that
    /// search (a convex hull climbing its vertex graph) start from `*hint` and store where
    /// they ended. Any `hint` value is valid; the answer meets the same contract.
    #[must_use]
    #[inline]
    fn support_from(&self, direction: DVec3, hint: &mut u32) -> DVec3 {
        let _ = hint;
        self.support(direction)
    }
}
