//! The daemon-wide memory budget of convex and mesh shapes: each registration is charged
//! an estimate of what its shape will take, from its header alone, before its payload is
//! copied or anything is built; a scene gives its charges back when it goes.
//!
//! The estimates are measured upper bounds (release build, resident memory around one
//! build, temporaries included): a mesh took 884–1,082 bytes per triangle (grids of 20,000
//! to 980,000 triangles, its two BVHs, edges and hull included), a convex hull 668–1,024
//! bytes per input point (4,096 to 65,536 points on a sphere, every one a hull vertex).

use super::convert::GeometryRequest;

/// Bytes charged per mesh triangle (measured at most 1,082).
pub const MESH_BYTES_PER_TRIANGLE: u64 = 1_200;
/// Bytes charged per mesh vertex, besides its triangles'.
pub const MESH_BYTES_PER_VERTEX: u64 = 64;
/// Bytes charged per convex input point (measured at most 1,024).
pub const CONVEX_BYTES_PER_POINT: u64 = 1_100;

/// The bytes a convex or mesh registration is charged.
#[must_use]
pub fn geometry_estimate(geometry: &GeometryRequest) -> u64 {
    let (vertices, indices) = (
        u64::from(geometry.vertex_count),
        u64::from(geometry.index_count),
    );
    if geometry.mesh {
        (indices / 3) * MESH_BYTES_PER_TRIANGLE + vertices * MESH_BYTES_PER_VERTEX
    } else {
        vertices * CONVEX_BYTES_PER_POINT
    }
}
