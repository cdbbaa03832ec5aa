//! The memory budgets (the daemon's, and each client process's [quota](super::quota)) of
//! shapes and bodies: each convex or mesh registration is charged an estimate of what its
//! shape will take, from its header alone, before its payload is copied or anything is
//! built; each body is charged [`BODY_BYTES`]; a removed body and a dropped scene give their
//! charges back.
//!
//! The estimates are measured upper bounds (release build, resident memory, temporaries
//! included):
//! - a mesh took at most 1,264–1,416 bytes per triangle at the peak of its build, its
//!   vertices, trees, edges and hull included (grids of 20,000 and 200,000 triangles,
//!   UV spheres of 39,800 and 359,400; 2026-11-28, with the sphere trees, which add about
//!   250 bytes a triangle to the grids' peak and nothing to the spheres'), and a cloud of
//!   200,000 loose triangles, which keeps its sphere tree, 1,499 with its 600,000
//!   vertices; a convex hull 668–1,024 bytes per input point (4,096 to 65,536 points on a
//!   sphere, every one a hull vertex);
//! - a body took 2.1–3.3 KB once stepped (its record, broad phase, pair memory and the
//!   frame's workspace: 10,000 to 100,000 spheres in a grid, three `CLOSE` frames). Fewer
//!   bodies take more each (9.4 KB at 1,000) but less in all than the charge of 1,000.

use super::convert::GeometryRequest;

/// Bytes charged per mesh triangle (measured at most 1,416 with the vertices of a welded
/// mesh, which add about 32 of their own charge a triangle).
pub const MESH_BYTES_PER_TRIANGLE: u64 = 1_500;
/// Bytes charged per mesh vertex, besides its triangles'.
pub const MESH_BYTES_PER_VERTEX: u64 = 64;
/// Bytes charged per convex input point (measured at most 1,024).
pub const CONVEX_BYTES_PER_POINT: u64 = 1_100;
/// Bytes charged per body (measured at most 3.3 KB at 10,000 bodies and more).
pub const BODY_BYTES: u64 = 4_096;

/// `bytes` as a person reads it: KiB below a MiB, MiB above, rounded up.
#[must_use]
pub fn readable(bytes: u64) -> String {
    if bytes < 1 << 20 {
        format!("{} KiB", bytes.div_ceil(1 << 10))
    } else {
        format!("{} MiB", bytes.div_ceil(1 << 20))
    }
}

/// The bytes a convex or mesh registration is charged.
#[must_use]
pub fn geometry_estimate(geometry: &GeometryRequest) -> u64 {
    let (vertices, indices) = (
        u64::from(geometry.vertex_count),
        u64::from(geometry.index_count),
    );
    if geometry.kind.is_mesh() {
        (indices / 3) * MESH_BYTES_PER_TRIANGLE + vertices * MESH_BYTES_PER_VERTEX
    } else {
        vertices * CONVEX_BYTES_PER_POINT
    }
}
