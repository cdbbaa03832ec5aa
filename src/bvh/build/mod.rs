//! BVH construction: split or cluster the triangles into a tree, then fit every node.
//!
//! Building is two steps. A *builder* decides the tree's shape only, as a `Topology`
//! (top-down splits in `top_down`, octree cells in `octree`, medial-axis cuts in
//! `medial_axis`, agglomerative clustering in `bottom_up`); then
//! `fit_topology` copies the triangles into leaf order and fits each node's volume to all
//! triangles of its subtree with [`BoundingVolume::fit_triangles`] (tighter than merging the
//! children's volumes, which is what refit does).
//!
//! Building is offline work (once per shape) and allocates freely.

mod bottom_up;
mod medial_axis;
mod octree;
mod top_down;

pub use medial_axis::MEDIAL_SPREAD;

use super::{Bvh, BvhNode};
use crate::bounding::BoundingVolume;
use crate::geometry::Triangle;
use crate::math::DVec3;

/// How the tree's shape is decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BuildStrategy {
    /// Top-down: split at the median centroid along the longest axis of the centroids' box.
    /// Balanced trees (depth ⌈log₂ n⌉), whatever the triangle distribution.
    Median,
    /// Top-down: split at the mean centroid along the direction of largest centroid variance
    /// (the principal axis; Gottschalk's OBBTree rule, FCL's default). Follows the shape's
    /// own orientation; falls back to the median when the mean leaves one side empty.
    MeanVariance,
    /// Top-down: binned surface-area heuristic over the triangles' boxes, the best of
    /// [`SAH_BINS`] planes on each of the three axes.
    BinnedSah,
    /// Bottom-up: agglomerative clustering (PLOC), repeatedly merging mutually nearest
    /// clusters, where "nearest" is the diagonal of the merged axis-aligned box, whatever
    /// volume type the tree is then fitted with (faster and tighter than clustering on
    /// OBB/RSS merges, measured in `bottom_up.rs`).
    Agglomerative,
    /// Top-down: the cells of a regular octree over the centroids (Hubbard's octree sphere
    /// tree, `octree.rs`), each cell written as three binary levels.
    Octree,
    /// Top-down: cuts across the surface's medial axis, approximated by one inscribed ball
    /// per triangle, then into surface patches where the balls bunch up (the medial-axis
    /// sphere tree, `medial_axis.rs`). Meant for closed surfaces; valid for any.
    MedialAxis,
}

/// Number of bins per axis of [`BuildStrategy::BinnedSah`].
pub const SAH_BINS: usize = 16;

/// Build parameters: strategy and leaf size, with presets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuildParams {
    /// How the tree's shape is decided.
    pub strategy: BuildStrategy,
    /// Largest number of triangles in a leaf (at least 1).
    pub leaf_size: u32,
}

impl BuildParams {
    /// Mean/variance split, one triangle per leaf: the general-purpose default.
    pub const MEAN_VARIANCE: Self = Self::new(BuildStrategy::MeanVariance, 1);
    /// Median split, one triangle per leaf.
    pub const MEDIAN: Self = Self::new(BuildStrategy::Median, 1);
    /// Binned SAH, one triangle per leaf.
    pub const BINNED_SAH: Self = Self::new(BuildStrategy::BinnedSah, 1);
    /// Agglomerative clustering, one triangle per leaf.
    pub const AGGLOMERATIVE: Self = Self::new(BuildStrategy::Agglomerative, 1);
    /// Octree cells, one triangle per leaf.
    pub const OCTREE: Self = Self::new(BuildStrategy::Octree, 1);
    /// Medial-axis cuts, one triangle per leaf.
    pub const MEDIAL_AXIS: Self = Self::new(BuildStrategy::MedialAxis, 1);

    /// Parameters from parts; a `leaf_size` of 0 is taken as 1.
    #[must_use]
    pub const fn new(strategy: BuildStrategy, leaf_size: u32) -> Self {
        Self {
            strategy,
            leaf_size: if leaf_size == 0 { 1 } else { leaf_size },
        }
    }

    /// The same strategy with another leaf size (0 is taken as 1).
    #[must_use]
    pub const fn with_leaf_size(self, leaf_size: u32) -> Self {
        Self::new(self.strategy, leaf_size)
    }
}

impl Default for BuildParams {
    fn default() -> Self {
        Self::MEAN_VARIANCE
    }
}

/// A tree's shape before volumes are fitted, in the final [`Bvh`] node layout.
///
/// # Invariants
/// `nodes[0]` is the root; an internal node's children are `first` and `first + 1`, both
/// after it; `span` is the subtree's range of positions in `order`, the two children's spans
/// split the parent's, and a leaf's `first .. first + count` equals its span. `order` is a
/// permutation of the triangle indices.
#[derive(Debug, Clone, Default)]
pub(crate) struct Topology {
    pub nodes: Vec<TopologyNode>,
    pub order: Vec<u32>,
}

/// One node of a [`Topology`]; `first`/`count` as in [`BvhNode`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct TopologyNode {
    pub first: u32,
    pub count: u32,
    pub span: [u32; 2],
}

/// The builder's view of one triangle: its centroid and its axis-aligned box.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BuildPrimitive {
    pub centroid: DVec3,
    pub min: DVec3,
    pub max: DVec3,
}

impl BuildPrimitive {
    fn of(t: &Triangle) -> Self {
        Self {
            centroid: t.centroid(),
            min: t.a.min(t.b).min(t.c),
            max: t.a.max(t.b).max(t.c),
        }
    }
}

/// Builds a [`Bvh`] over `triangles` with `params`.
pub(super) fn build<B: BoundingVolume>(triangles: &[Triangle], params: &BuildParams) -> Bvh<B> {
    assert!(!triangles.is_empty(), "a BVH needs at least one triangle");
    assert!(
        triangles.len() <= (u32::MAX / 2) as usize,
        "too many triangles for a BVH"
    );
    let primitives: Vec<BuildPrimitive> = triangles.iter().map(BuildPrimitive::of).collect();
    let leaf_size = params.leaf_size.max(1);
    let topology = match params.strategy {
        BuildStrategy::Median | BuildStrategy::MeanVariance | BuildStrategy::BinnedSah => {
            top_down::build(&primitives, params.strategy, leaf_size)
        }
        BuildStrategy::Agglomerative => bottom_up::build(triangles, &primitives, leaf_size),
        BuildStrategy::Octree => octree::build(&primitives, leaf_size),
        BuildStrategy::MedialAxis => medial_axis::build(triangles, &primitives, leaf_size),
    };
    fit_topology(&topology, triangles, leaf_size)
}

/// Copies `triangles` into the leaf order of `topology` and fits every node's volume to its
/// subtree's triangles.
pub(crate) fn fit_topology<B: BoundingVolume>(
    topology: &Topology,
    triangles: &[Triangle],
    leaf_size: u32,
) -> Bvh<B> {
    let ordered: Vec<Triangle> = topology
        .order
        .iter()
        .map(|&i| triangles[i as usize])
        .collect();
    let nodes = topology
        .nodes
        .iter()
        .map(|n| {
            let bv = B::fit_triangles(&ordered[n.span[0] as usize..n.span[1] as usize]);
            BvhNode {
                size: bv.size(),
                bv,
                first: n.first,
                count: n.count,
            }
        })
        .collect();
    Bvh {
        nodes,
        spans: topology.nodes.iter().map(|n| n.span).collect(),
        triangles: ordered,
        triangle_slots: inverse_permutation(&topology.order),
        triangle_ids: topology.order.clone(),
        leaf_size,
    }
}

/// The inverse of the permutation `order` of `0..order.len()` (slot → id gives id → slot).
fn inverse_permutation(order: &[u32]) -> Vec<u32> {
    let mut inverse = vec![0; order.len()];
    for (slot, &id) in order.iter().enumerate() {
        inverse[id as usize] = slot as u32;
    }
    inverse
}
