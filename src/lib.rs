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
//! poses in ─▶ math (Pose, Isometry) ─▶ geometry (shapes, meshes, hulls)
//!          ─▶ bounding (sphere, AABB, OBB, k-DOP, PSS/LSS/RSS) ─▶ BVH traversal
//!          ─▶ broad phase ─▶ narrow phase ─▶ contacts out
//! ```
//!
//! A module uses only modules listed above it.

pub mod bounding;
pub mod geometry;
pub mod math;
pub mod narrow;
