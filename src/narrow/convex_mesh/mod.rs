//! A convex shape against a triangle mesh: the walk of the mesh's BVH that finds the
//! triangles that can matter (`walk.rs`), pruned by the shape's lower bounds on its
//! distance to the tree's nodes (`node_bound.rs`), and the pair's signed distance and contact
//! manifold over those triangles, ghost normals removed (`contacts.rs`).
//!
//! Meshes are surfaces: two-sided triangles with no thickness. The signed distance is the
//! smallest over the triangles, negative when the shape reaches through one; a shape
//! entirely inside a closed mesh without touching its surface is apart from it.

mod contacts;
mod node_bound;
mod walk;

pub(crate) use contacts::{MeshContactScratch, shape_mesh_distance, shape_mesh_manifold};
pub use contacts::{shape_triangle_distance, shape_triangle_manifold};
pub use walk::{
    ConvexMeshWorkspace, TRIANGLE_WORK, Walk, for_each_overlapping_triangle, nearest_triangle,
    nearest_triangle_within, volume_bound,
};
