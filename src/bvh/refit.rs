//! Refit after vertex motion: same tree, new volumes.
//!
//! A deformable mesh keeps its triangle connectivity and moves its vertices; rebuilding
//! would change the tree. Refit keeps the tree and recomputes the volumes bottom-up: leaves
//! are fitted to their triangles, internal nodes either merge their children's volumes
//! ([`RefitMode::Merge`], linear time) or are fitted to all of their subtree's triangles
//! ([`RefitMode::Fit`], as tight as a fresh build of the same tree, `O(n log n)`).

use super::{Bvh, BvhNode};
use crate::bounding::BoundingVolume;
use crate::geometry::Triangle;

/// How internal volumes are recomputed by [`Bvh::refit`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefitMode {
    /// Merge the two children's volumes: fast, looser after large motion.
    Merge,
    /// Fit each node to its subtree's triangles: slower, as tight as a build.
    Fit,
}

impl<B: BoundingVolume> Bvh<B> {
    /// Takes the moved `triangles` (input order, the same count and meaning as at build) and
    /// recomputes every volume. The tree's shape is unchanged.
    ///
    /// # Panics
    /// When `triangles.len()` differs from [`Bvh::triangle_count`].
    pub fn refit(&mut self, triangles: &[Triangle], mode: RefitMode) {
        assert_eq!(
            triangles.len(),
            self.triangles.len(),
            "refit needs the triangles the BVH was built over"
        );
        for (slot, &id) in self.triangle_ids.iter().enumerate() {
            self.triangles[slot] = triangles[id as usize];
        }
        // Children come after their parents: a reverse sweep sees children first.
        for index in (0..self.nodes.len()).rev() {
            let node = self.nodes[index];
            let bv = if node.is_leaf() || mode == RefitMode::Fit {
                let [start, end] = self.spans[index];
                B::fit_triangles(&self.triangles[start as usize..end as usize])
            } else {
                let [left, right] = node.children();
                self.nodes[left].bv.merged(&self.nodes[right].bv)
            };
            self.nodes[index] = BvhNode {
                size: bv.size(),
                bv,
                ..node
            };
        }
    }
}
