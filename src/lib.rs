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
//! poses in ─▶ scene (bodies, change log) ─▶ pipeline: broad phase ─▶ plan
//!          ─▶ mid phase (hull proofs, budgeted BVH frontier) ─▶ narrow phase ─▶ contacts out
//! ```
//!
//! built on layers, lowest first: math and budget, geometry (shapes in their local frames),
//! bounding volumes, BVHs and broad phases, narrow (every pair query, one dispatcher),
//! scene, pipeline (one frame), daemon. A module uses only its own layer and those below.

// So test support written against the public crate name compiles inside the crate's unit tests.
extern crate self as proxima;

// Stages in data-flow order (kept apart so rustfmt does not sort them).

// Poses, isometries, tolerances.
pub mod math;

// Budgets, deadlines and the completeness of answers cut short.
pub mod budget;

// Shapes, meshes, convex hulls, exact predicates.
pub mod geometry;

// Approximate convex decomposition of closed meshes (part of the geometry layer).
pub use geometry::decompose;

// Bounding volumes.
pub mod bounding;

// Bounding-volume hierarchies and their tandem traversal.
pub mod bvh;

// Broad phase: candidate pairs from margin-grown world boxes.
pub mod broad;

// Every pair query: the shape set, the one dispatcher, closed forms, GJK/EPA,
// convex–mesh, mesh–mesh (exact and budgeted).
pub mod narrow;

#[cfg(test)]
#[path = "../tests/support/mod.rs"]
pub(crate) mod test_support;

// Scene state: bodies, their change log, limits.
pub mod scene;

// One frame of collision work over a scene.
pub mod pipeline;

// The daemon's service loop and wire conversion (the only user of `proxima-ipc`).
pub mod daemon;

// Outside the data flow: a global allocator for binaries with large scenes.
pub mod huge_pages;
