//! Narrow phase: exact queries between pairs of primitives.
//!
//! The triangle–triangle primitives that exact mesh–mesh queries are built on:
//! [`intersects_triangle_triangle`] (an exact boolean, decided by robust orientation
//! predicates), [`intersection_segment_triangle_triangle`] and
//! [`distance_triangle_triangle`] (distance with witness points). Both triangles are given in
//! the same frame; a mesh–mesh query transforms one mesh's triangles into the other's frame
//! first.
//!
//! [`mesh_mesh`] builds the exact mesh–mesh queries (collision, contacts, distance,
//! tolerance) on them by tandem traversal of two BVHs.
//!
//! [`pairs`] holds the closed-form distance and manifold queries between the primitives
//! sphere, capsule, cuboid and triangle.
//!
//! [`gjk`] answers any two convex shapes given by support maps: GJK distance, EPA
//! penetration depth, and [`signed_distance_convex`] combining both under the
//! [`contact`] contract.
//!
//! [`convex_manifold`] builds multi-point manifolds for the GJK pairs from their signed
//! distance (reference-face clipping over each shape's contact features).
//!
//! [`compound`] answers solids made of convex parts (a convex decomposition's hulls),
//! part pair by part pair.
//!
//! [`convex_mesh`] walks a mesh's BVH for a convex shape; [`toi`] finds the time of impact
//! over a frame's motion by conservative advancement, on any of these distance queries.
//!
//! Closed sets throughout: touching counts as intersecting, and zero-area triangles are the
//! segment or point they span.

mod closest_points;
pub mod compound;
pub mod contact;
pub mod convex_manifold;
pub mod convex_mesh;
pub mod dispatch;
pub mod gjk;
pub mod manifold_reduction;
pub mod mesh_hull;
pub mod mesh_mesh;
mod pair_key;
pub mod pairs;
pub mod polygon;
pub mod shape;
pub mod toi;
mod triangle_overlap;
pub mod triangle_triangle;

pub use compound::{CompoundError, CompoundShape};
pub use contact::{
    DistanceBound, MANIFOLD_POINTS, Manifold, ManifoldPoint, Reached, ShapeDistance,
};
pub use convex_manifold::{
    ContactFeatures, ManifoldScratch, manifold_convex_convex, manifold_convex_convex_in,
};
pub use gjk::{
    GjkCache, GjkOutcome, GjkParams, GjkResult, Rounded, gjk_distance, signed_distance_convex,
};
pub use manifold_reduction::{EXACT_DIAMETER_POINTS, reduce_manifold};
pub use pairs::{
    distance_bound_capsule_capsule, distance_bound_capsule_cuboid, distance_bound_cuboid_cuboid,
    distance_capsule_capsule, distance_capsule_cuboid, distance_capsule_triangle,
    distance_cuboid_cuboid, distance_cuboid_triangle, distance_sphere_capsule,
    distance_sphere_cuboid, distance_sphere_sphere, distance_sphere_triangle,
    manifold_capsule_capsule, manifold_capsule_cuboid, manifold_capsule_triangle,
    manifold_cuboid_cuboid, manifold_cuboid_triangle, manifold_sphere_capsule,
    manifold_sphere_cuboid, manifold_sphere_sphere, manifold_sphere_triangle,
};
pub use shape::{MESH_TREE_PARAMS, MeshShape, QueryVolume, Shape};
pub use triangle_triangle::{
    TriangleDistance, distance_triangle_triangle, intersection_segment_triangle_triangle,
    intersects_triangle_triangle,
};
