//! Narrow phase: exact queries between pairs of primitives.
//!
//! So far the triangle–triangle primitives that exact mesh–mesh queries are built on:
//! [`intersects_triangle_triangle`] (an exact boolean, decided by robust orientation
//! predicates), [`intersection_segment_triangle_triangle`] and
//! [`distance_triangle_triangle`] (distance with witness points). Both triangles are given in
//! the same frame; a mesh–mesh query transforms one mesh's triangles into the other's frame
//! first.
//!
//! [`mesh_mesh`] builds the exact mesh–mesh queries (collision, contacts, distance,
//! tolerance) on them by tandem traversal of two BVHs.
//!
//! [`gjk`] answers any two convex shapes given by support maps: GJK distance, EPA
//! penetration depth, and [`signed_distance_convex`] combining both under the
//! [`contact`] contract.
//!
//! Closed sets throughout: touching counts as intersecting, and zero-area triangles are the
//! segment or point they span.

mod closest_points;
pub mod contact;
pub mod gjk;
pub mod mesh_mesh;
mod triangle_overlap;
pub mod triangle_triangle;

pub use contact::{MANIFOLD_POINTS, Manifold, ManifoldPoint, ShapeDistance};
pub use gjk::{
    GjkCache, GjkOutcome, GjkParams, GjkResult, Rounded, gjk_distance, signed_distance_convex,
};
pub use triangle_triangle::{
    TriangleDistance, distance_triangle_triangle, intersection_segment_triangle_triangle,
    intersects_triangle_triangle,
};
