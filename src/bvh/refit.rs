//! Refit after vertex motion: same tree, new volumes.
//!
//! A deformable mesh keeps its triangle connectivity and moves its vertices; rebuilding
//! would change the tree. Refit keeps the tree and recomputes the volumes bottom-up: leaves
//! and internal nodes are re-enclosed in their own old orientation — around their
//! children's volumes ([`RefitMode::Merge`], linear time) or around all their subtree's
//! triangles ([`RefitMode::KeepFrames`], as tight as the build while the contents have not
//! turned; see [`BoundingVolume::fit_triangles_in_frame`] and
//! [`BoundingVolume::merged_in_frame`]) — or fitted afresh to all of their subtree's triangles
//! ([`RefitMode::Fit`], as tight as a fresh build of the same tree, `O(n log n)`).

use super::{Bvh, BvhNode};
use crate::bounding::BoundingVolume;
use crate::geometry::Triangle;

/// How internal volumes are recomputed by [`Bvh::refit`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RefitMode {
    /// Re-enclose each node (leaf: its triangles; internal: its children's volumes) in its
    /// old orientation: linear time, but parents enclose boxes rather than triangles, so
    /// queries run about 2× slower than on a fresh build (measured on bunny×fandisk).
    Merge,
    /// Re-enclose every node's subtree triangles in its old orientation: `O(n log n)`
    /// projections, no fitting; as tight as the build until the contents turn.
    KeepFrames,
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
            let [start, end] = self.spans[index];
            let triangles = &self.triangles[start as usize..end as usize];
            let bv = if mode == RefitMode::Fit {
                B::fit_triangles(triangles)
            } else if node.is_leaf() || mode == RefitMode::KeepFrames {
                node.bv.fit_triangles_in_frame(triangles)
            } else {
                let [left, right] = node.children();
                node.bv
                    .merged_in_frame(&self.nodes[left].bv, &self.nodes[right].bv)
            };
            self.nodes[index] = BvhNode {
                size: bv.size(),
                bv,
                ..node
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::test_support::{PRESETS, for_each_volume, soup};
    use crate::math::DVec3;
    use crate::test_support::{point_in_cube, rng};

    /// Builds with every preset and leaf sizes 1 and 4, then checks refit in both modes.
    fn refit_contracts<B: BoundingVolume + PartialEq>(seed: u64) {
        let mut rng = rng(seed);
        for case in 0..6 {
            let n = [1, 2, 7, 60, 150, 150][case];
            let (half, size) = [(1.0, 0.1), (1e3, 20.0), (1e-3, 1e-4)][case % 3];
            let offset = if case == 5 {
                DVec3::splat(1e5)
            } else {
                DVec3::ZERO
            };
            let triangles: Vec<Triangle> = soup(&mut rng, n, half, size)
                .into_iter()
                .map(|t| Triangle::new(t.a + offset, t.b + offset, t.c + offset))
                .collect();
            for params in PRESETS {
                for leaf_size in [1, 4] {
                    let params = params.with_leaf_size(leaf_size);
                    let built = Bvh::<B>::from_triangles(&triangles, &params);
                    let what = format!("{} {params:?} case {case}", B::NAME);
                    assert_eq!(built.validate(), Ok(()), "{what}");
                    let mut same = built.clone();
                    same.refit(&triangles, RefitMode::Fit);
                    assert_eq!(
                        same.nodes, built.nodes,
                        "{what}: fit refit of unmoved triangles"
                    );
                    let moved: Vec<Triangle> = triangles
                        .iter()
                        .map(|t| {
                            let mut jiggle = || point_in_cube(&mut rng, 2.0 * half);
                            Triangle::new(t.a + jiggle(), t.b + jiggle(), t.c + jiggle())
                        })
                        .collect();
                    for mode in [RefitMode::Merge, RefitMode::KeepFrames, RefitMode::Fit] {
                        let mut refitted = built.clone();
                        refitted.refit(&moved, mode);
                        assert_eq!(refitted.validate(), Ok(()), "{what} {mode:?}");
                        // The tree's shape and slot map are unchanged.
                        assert_eq!(refitted.spans, built.spans);
                        assert_eq!(refitted.triangle_ids, built.triangle_ids);
                    }
                }
            }
        }
    }

    #[test]
    fn refit_keeps_every_tree_valid_and_fit_refit_of_unmoved_triangles_is_the_build() {
        for_each_volume!(refit_contracts(306));
    }
}
