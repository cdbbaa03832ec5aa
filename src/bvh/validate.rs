//! The invariant check of [`Bvh`], run by tests after every build and refit.

use super::Bvh;
use crate::bounding::BoundingVolume;
use std::fmt;

/// An invariant of a [`Bvh`] that does not hold (see the [module docs](super)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum BvhError {
    /// The tree has no nodes or no triangles.
    Empty,
    /// Node `node` names a child at `child`, out of range or not after its parent.
    BadChild { node: usize, child: usize },
    /// Node `node` is reached from the root more than once, or never.
    NotATree { node: usize },
    /// Leaf `node` holds `count` triangles: zero, more than the leaf size, or out of range.
    BadLeaf { node: usize, count: usize },
    /// Triangle slot `slot` is owned by no leaf or by several.
    SlotCoverage { slot: usize },
    /// The slot → triangle map is not a permutation (triangle `id` is missing or repeated),
    /// or the triangle → slot map is not its inverse at `id`.
    NotAPermutation { id: usize },
    /// A node's recorded span disagrees with the slots of the leaves beneath it.
    BadSpan { node: usize },
    /// Node `node`'s volume misses a vertex of triangle slot `slot` of its subtree.
    Escapes { node: usize, slot: usize },
    /// Node `node`'s cached size differs from its volume's.
    StaleSize { node: usize },
}

impl fmt::Display for BvhError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Empty => write!(f, "BVH has no nodes or no triangles"),
            Self::BadChild { node, child } => write!(f, "node {node} has bad child index {child}"),
            Self::NotATree { node } => {
                write!(f, "node {node} is not reached exactly once from the root")
            }
            Self::BadLeaf { node, count } => write!(f, "leaf {node} holds {count} triangles"),
            Self::SlotCoverage { slot } => {
                write!(f, "triangle slot {slot} is not in exactly one leaf")
            }
            Self::NotAPermutation { id } => {
                write!(
                    f,
                    "triangle {id} is missing, repeated or mapped to another slot"
                )
            }
            Self::BadSpan { node } => {
                write!(f, "node {node} has a span that disagrees with its leaves")
            }
            Self::Escapes { node, slot } => {
                write!(
                    f,
                    "node {node}'s volume misses a vertex of triangle slot {slot}"
                )
            }
            Self::StaleSize { node } => write!(f, "node {node} caches a stale size"),
        }
    }
}

impl std::error::Error for BvhError {}

impl<B: BoundingVolume> Bvh<B> {
    /// Checks every invariant listed in the [module docs](super); `O(n · depth)`.
    ///
    /// # Errors
    /// The first broken invariant found.
    pub fn validate(&self) -> Result<(), BvhError> {
        let n_nodes = self.nodes.len();
        let n_slots = self.triangles.len();
        if n_nodes == 0
            || n_slots == 0
            || self.spans.len() != n_nodes
            || self.triangle_ids.len() != n_slots
            || self.triangle_slots.len() != n_slots
        {
            return Err(BvhError::Empty);
        }
        let mut seen = vec![false; self.triangle_ids.len()];
        for &id in &self.triangle_ids {
            let id = id as usize;
            if id >= n_slots || std::mem::replace(&mut seen[id], true) {
                return Err(BvhError::NotAPermutation { id });
            }
        }
        for (slot, &id) in self.triangle_ids.iter().enumerate() {
            if self.triangle_slots[id as usize] as usize != slot {
                return Err(BvhError::NotAPermutation { id: id as usize });
            }
        }
        let mut reached = vec![0u32; n_nodes];
        reached[0] = 1;
        let mut owner = vec![0u32; n_slots];
        for (index, node) in self.nodes.iter().enumerate() {
            if node.size != node.bv.size() {
                return Err(BvhError::StaleSize { node: index });
            }
            if node.is_leaf() {
                let slots = node.slots();
                if node.count > self.leaf_size || slots.end > n_slots {
                    return Err(BvhError::BadLeaf {
                        node: index,
                        count: node.count as usize,
                    });
                }
                if self.spans[index] != [slots.start as u32, slots.end as u32] {
                    return Err(BvhError::BadSpan { node: index });
                }
                for slot in slots {
                    owner[slot] += 1;
                }
            } else {
                for child in node.children() {
                    if child <= index || child >= n_nodes {
                        return Err(BvhError::BadChild { node: index, child });
                    }
                    reached[child] += 1;
                }
                let [left, right] = node.children();
                let [start, end] = self.spans[index];
                if self.spans[left][0] != start
                    || self.spans[left][1] != self.spans[right][0]
                    || self.spans[right][1] != end
                {
                    return Err(BvhError::BadSpan { node: index });
                }
            }
        }
        if let Some(node) = reached.iter().position(|&r| r != 1) {
            return Err(BvhError::NotATree { node });
        }
        if let Some(slot) = owner.iter().position(|&o| o != 1) {
            return Err(BvhError::SlotCoverage { slot });
        }
        for (index, node) in self.nodes.iter().enumerate() {
            let [start, end] = self.spans[index];
            for slot in start as usize..end as usize {
                if !self.triangles[slot]
                    .vertices()
                    .iter()
                    .all(|&v| node.bv.contains_point(v))
                {
                    return Err(BvhError::Escapes { node: index, slot });
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::Aabb;
    use crate::bvh::test_support::soup;
    use crate::bvh::{BuildParams, BvhNode};
    use crate::geometry::Triangle;
    use crate::math::DVec3;
    use crate::test_support::rng;

    /// An 8-triangle median tree with one triangle per leaf, and one of its leaves.
    fn small_tree() -> (Bvh<Aabb>, usize) {
        let triangles = soup(&mut rng(307), 8, 1.0, 0.1);
        let bvh = Bvh::<Aabb>::from_triangles(&triangles, &BuildParams::MEDIAN);
        assert_eq!(bvh.validate(), Ok(()));
        let leaf = bvh.nodes.iter().rposition(BvhNode::is_leaf).unwrap();
        (bvh, leaf)
    }

    #[test]
    fn validate_catches_each_kind_of_corruption() {
        let (bvh, leaf) = small_tree();
        let (mut bad, far) = (bvh.clone(), DVec3::splat(50.0));
        bad.nodes[leaf].bv = Aabb::fit_points(&[far]);
        bad.nodes[leaf].size = bad.nodes[leaf].bv.size();
        assert!(matches!(bad.validate(), Err(BvhError::Escapes { node, .. }) if node == leaf));

        let mut bad = bvh.clone();
        let slot = bad.nodes[leaf].slots().start;
        bad.triangles[slot] = Triangle::new(far, far, far);
        assert!(matches!(bad.validate(), Err(BvhError::Escapes { slot: s, .. }) if s == slot));

        let mut bad = bvh.clone();
        bad.nodes[3].size *= 2.0;
        assert_eq!(bad.validate(), Err(BvhError::StaleSize { node: 3 }));

        let mut bad = bvh.clone();
        bad.triangle_ids[1] = bad.triangle_ids[0];
        let id = bad.triangle_ids[0] as usize;
        assert_eq!(bad.validate(), Err(BvhError::NotAPermutation { id }));

        let mut bad = bvh.clone();
        bad.triangle_slots.swap(0, 1);
        assert!(matches!(
            bad.validate(),
            Err(BvhError::NotAPermutation { id: 0 | 1 })
        ));
        assert_eq!(bvh.slot_of(bvh.triangle_ids[2]), Some(2));

        let mut bad = bvh.clone();
        bad.nodes[0].first = 0;
        assert_eq!(
            bad.validate(),
            Err(BvhError::BadChild { node: 0, child: 0 })
        );

        let mut bad = bvh.clone();
        bad.nodes[leaf].count = 2;
        assert!(
            matches!(bad.validate(), Err(BvhError::BadLeaf { node, count: 2 }) if node == leaf)
        );

        let mut bad = bvh.clone();
        bad.spans[leaf][1] += 1;
        // Found at the leaf's parent, which is checked first.
        assert!(matches!(bad.validate(), Err(BvhError::BadSpan { .. })));

        let mut bad = bvh.clone();
        bad.spans.pop();
        assert_eq!(bad.validate(), Err(BvhError::Empty));

        // And the uncorrupted tree passes.
        assert_eq!(bvh.validate(), Ok(()));
    }
}
