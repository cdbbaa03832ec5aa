//! Bounding-volume hierarchies over triangles, and the tandem traversal of two of them.
//!
//! A [`Bvh<B>`] is a binary tree of bounding volumes of one type `B` (any
//! [`BoundingVolume`]) over the triangles of one shape, stored flat:
//!
//! - `nodes[0]` is the root; the two children of an internal node are adjacent
//!   (`first`, `first + 1`) and always come after their parent, so a reverse sweep over the
//!   array visits children before parents (that is how [`Bvh::refit`] works);
//! - the triangles are copied into *leaf order*: a leaf owns the contiguous slots
//!   `first .. first + count`, and [`Bvh::triangle_id`] maps a slot back to the mesh's own
//!   triangle index. Traversal therefore never chases an index to reach a triangle.
//!
//! Trees are made by the builders in [`build`] (top-down median, mean and binned-SAH splits,
//! bottom-up agglomerative clustering), chosen through [`BuildParams`] presets. The tandem
//! traversal of two trees under a relative pose lives in [`tandem`]; exact mesh–mesh queries
//! built on it are in [`crate::narrow::mesh_mesh`]. The budgeted breadth-first traversal of
//! many mesh pairs at once (the time-critical frame) is [`crate::narrow::mesh_mesh::frontier`].
//!
//! # Invariants
//! Checked by [`Bvh::validate`], which tests call after every build and refit:
//! 1. every node's volume contains every vertex of every triangle in its subtree (this, not
//!    "child volume inside parent volume", is what traversal relies on: a fitted child OBB
//!    may poke out of its parent's box while both enclose the same triangles);
//! 2. every triangle slot belongs to exactly one leaf, `triangle_ids` is a permutation and
//!    `triangle_slots` its inverse;
//! 3. children come after their parent, in range, adjacent; every node but the root has
//!    exactly one parent; leaves hold `1 ..= leaf_size` triangles.

pub mod build;
mod refit;
pub mod tandem;
#[cfg(test)]
mod test_support;
mod validate;

pub use build::{BuildParams, BuildStrategy};
pub use refit::RefitMode;
pub use validate::BvhError;

use crate::bounding::BoundingVolume;
use crate::geometry::{TriMesh, Triangle};

/// One node of a [`Bvh`]: its volume and either two children or a run of triangle slots.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhNode<B> {
    /// The volume, in the shape's local frame.
    pub bv: B,
    /// [`BoundingVolume::size`] of `bv`, metres, cached for the descent rule.
    pub size: f64,
    /// Internal node: index of the first child (the second is `first + 1`). Leaf: first
    /// triangle slot.
    first: u32,
    /// `0` for an internal node, otherwise the number of triangle slots of the leaf.
    count: u32,
}

impl<B> BvhNode<B> {
    /// Whether this node is a leaf.
    #[must_use]
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count != 0
    }

    /// The two children of an internal node (meaningless for a leaf).
    #[must_use]
    #[inline]
    pub fn children(&self) -> [usize; 2] {
        [self.first as usize, self.first as usize + 1]
    }

    /// The triangle slots of a leaf (empty for an internal node).
    #[must_use]
    #[inline]
    pub fn slots(&self) -> std::ops::Range<usize> {
        if self.is_leaf() {
            self.first as usize..(self.first + self.count) as usize
        } else {
            0..0
        }
    }
}

/// A bounding-volume hierarchy of volume type `B` over the triangles of one shape.
///
/// See the [module docs](self) for the layout and the invariants.
#[derive(Debug, Clone)]
pub struct Bvh<B> {
    nodes: Vec<BvhNode<B>>,
    /// For each node, its subtree's triangle slots `[start, end)` (used by refit and validate).
    spans: Vec<[u32; 2]>,
    /// Triangles in leaf order, local frame.
    triangles: Vec<Triangle>,
    /// Leaf slot → index of the triangle in the input.
    triangle_ids: Vec<u32>,
    /// Index of the triangle in the input → leaf slot: the inverse of `triangle_ids`.
    triangle_slots: Vec<u32>,
    leaf_size: u32,
}

impl<B: BoundingVolume> Bvh<B> {
    /// Builds the hierarchy over the triangles of `mesh`.
    ///
    /// # Panics
    /// When the mesh has no triangles ([`crate::geometry::TriMesh`] construction rejects
    /// that already).
    #[must_use]
    pub fn from_mesh(mesh: &TriMesh, params: &BuildParams) -> Self {
        let triangles: Vec<Triangle> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle(i))
            .collect();
        Self::from_triangles(&triangles, params)
    }

    /// Builds the hierarchy over `triangles` (local frame, finite); `triangle_id` reports
    /// indices into this slice.
    ///
    /// # Panics
    /// When `triangles` is empty or holds more than `u32::MAX / 2` triangles.
    #[must_use]
    pub fn from_triangles(triangles: &[Triangle], params: &BuildParams) -> Self {
        build::build(triangles, params)
    }
}

impl<B> Bvh<B> {
    /// All nodes; `nodes()[0]` is the root.
    #[must_use]
    #[inline]
    pub fn nodes(&self) -> &[BvhNode<B>] {
        &self.nodes
    }

    /// The root's volume.
    #[must_use]
    #[inline]
    pub fn root_bv(&self) -> &B {
        &self.nodes[0].bv
    }

    /// Triangles in leaf order (local frame).
    #[must_use]
    #[inline]
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The input index of the triangle in leaf slot `slot`.
    #[must_use]
    #[inline]
    pub fn triangle_id(&self, slot: usize) -> u32 {
        self.triangle_ids[slot]
    }

    /// The leaf slot of input triangle `id`, if the mesh has one (`O(1)`: the frontier
    /// looks up its seed triangles this way every frame).
    #[must_use]
    #[inline]
    pub fn slot_of(&self, id: u32) -> Option<usize> {
        self.triangle_slots
            .get(id as usize)
            .map(|&slot| slot as usize)
    }

    /// Number of triangles.
    #[must_use]
    #[inline]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The largest number of triangles a leaf may hold.
    #[must_use]
    #[inline]
    pub fn leaf_size(&self) -> usize {
        self.leaf_size as usize
    }

    /// Length of the longest root-to-leaf path, in edges.
    #[must_use]
    pub fn depth(&self) -> usize {
        let mut depth = vec![0usize; self.nodes.len()];
        let mut deepest = 0;
        for (i, node) in self.nodes.iter().enumerate() {
            if !node.is_leaf() {
                for c in node.children() {
                    depth[c] = depth[i] + 1;
                    deepest = deepest.max(depth[c]);
                }
            }
        }
        deepest
    }
}
