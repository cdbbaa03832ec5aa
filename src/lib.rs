//! # Proxima
//!
//! A real-time collision co-processor. The `proximad` daemon owns every object's geometry,
//! bounding-volume hierarchy and broad-phase state; simulation processes publish poses to it
//! over iceoryx2 shared memory and get back, within each frame's deadline, close pairs,
//! signed distances and contacts, each with an error bound.
//!
//! This library is the engine, usable in-process without the daemon. Its modules follow the
//! data flow of one frame:
//!
//! ```text
//! poses in ─▶ math (Pose, Isometry) ─▶ geometry (shapes, meshes, hulls, predicates)
//!          ─▶ bounding (sphere, AABB, OBB, k-DOP, PSS/LSS/RSS) ─▶ BVH traversal
//!          ─▶ broad phase ─▶ narrow phase (triangle–triangle, …) ─▶ contacts out
//! ```
//!
//! A module uses only modules listed above it.

// So test support written against the public crate name compiles inside the crate's unit tests.
extern crate self as proxima;

// Stages in data-flow order (kept apart so rustfmt does not sort them).

// Poses, isometries, tolerances.
pub mod math;

// Budgets, deadlines and the completeness of answers cut short.
pub mod budget;

// Shapes, meshes, convex hulls, exact predicates.
pub mod geometry;

// Bounding volumes.
pub mod bounding;

// Bounding-volume hierarchies and their tandem traversal.
pub mod bvh;

// Broad phase: candidate pairs from margin-grown world boxes.
pub mod broad;

// Exact queries: triangle–triangle overlap, intersection and distance; mesh–mesh queries.
pub mod narrow;

#[cfg(test)]
#[path = "../tests/support/mod.rs"]
pub(crate) mod test_support;

// Scene state: registered shapes and placed bodies.
pub mod scene;

// One frame of collision work over a scene.
pub mod pipeline;

// The daemon's service loop and wire conversion (the only user of `proxima-ipc`).
pub mod daemon;

// Outside the data flow: a global allocator for binaries with large scenes.
pub mod huge_pages;
