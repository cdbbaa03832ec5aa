//! A pair of registered meshes as the budgeted frontier sees them ([`PairTrees`]), refined
//! with the trees both meshes chose: listing a frame's pairs clones two `Arc`s per pair and
//! allocates nothing once the list has grown to the largest frame seen.

use super::{FrontierWitnesses, PairTrees, TreesAt};
use crate::math::Isometry;
use crate::narrow::{MeshShape, QueryVolume};
use std::sync::Arc;

/// One mesh pair of a budgeted frame, refined with the trees of its [`QueryVolume`].
#[derive(Debug, Clone)]
pub struct MeshPairTrees {
    /// Mesh of body A, mesh of body B (held while the frontier refers to their trees).
    pub meshes: [Arc<MeshShape>; 2],
    /// Which of the meshes' trees the pair is refined with ([`MeshShape::pair_volume`]):
    /// set once, so that every visit matches on it alone, and never spheres unless both
    /// meshes kept theirs.
    volume: QueryVolume,
    /// B's frame expressed in A's frame.
    pub pose_ab: Isometry,
    /// The pair's threshold, metres ([`crate::narrow::mesh_mesh::frontier::FrontierPair::threshold`]).
    pub threshold: f64,
    /// Triangles to try first ([`crate::narrow::mesh_mesh::frontier::FrontierPair::seed`]).
    pub seed: Option<[u32; 2]>,
}

impl MeshPairTrees {
    /// The pair of `a` (at the origin) and `b` placed by `pose_ab`, refined with the trees
    /// both meshes chose.
    #[must_use]
    pub fn new(
        a: &Arc<MeshShape>,
        b: &Arc<MeshShape>,
        pose_ab: Isometry,
        threshold: f64,
        seed: Option<[u32; 2]>,
    ) -> Self {
        Self {
            volume: a.pair_volume(b, None),
            meshes: [Arc::clone(a), Arc::clone(b)],
            pose_ab,
            threshold,
            seed,
        }
    }

    /// The same pair refined with `volume`'s trees instead of the ones its meshes chose
    /// (RSSs in place of spheres a mesh did not keep), for measurements and tests.
    #[must_use]
    pub fn with_volume(mut self, volume: QueryVolume) -> Self {
        let [a, b] = &self.meshes;
        self.volume = a.pair_volume(b, Some(volume));
        self
    }

    /// The volume type the pair is refined with.
    #[must_use]
    pub fn volume(&self) -> QueryVolume {
        self.volume
    }
}

/// Evaluates `$call` with `$trees` bound to the pair's [`TreesAt`] of its volume type.
macro_rules! on_trees {
    ($pair:ident, $trees:ident => $call:expr) => {{
        let [a, b] = &$pair.meshes;
        match $pair.volume {
            QueryVolume::Obb => {
                let $trees = TreesAt {
                    a: &a.overlap_tree,
                    b: &b.overlap_tree,
                    pose_ab: &$pair.pose_ab,
                };
                $call
            }
            QueryVolume::Rss => {
                let $trees = TreesAt {
                    a: &a.distance_tree,
                    b: &b.distance_tree,
                    pose_ab: &$pair.pose_ab,
                };
                $call
            }
            QueryVolume::Sphere => {
                let (a, b) = a.sphere_trees(b);
                let $trees = TreesAt {
                    a,
                    b,
                    pose_ab: &$pair.pose_ab,
                };
                $call
            }
        }
    }};
}

impl PairTrees for MeshPairTrees {
    fn threshold(&self) -> f64 {
        self.threshold
    }

    fn root_bounds(&self) -> (f64, f64) {
        on_trees!(self, t => t.root_bounds())
    }

    fn seed_distance(&self) -> Option<(f64, FrontierWitnesses)> {
        on_trees!(self, t => t.seed_distance(self.seed))
    }

    #[inline]
    fn bound(&self, nodes: [u32; 2], limit: f64) -> f64 {
        on_trees!(self, t => t.bound(nodes, limit))
    }

    fn upper_bound(&self, nodes: [u32; 2]) -> f64 {
        on_trees!(self, t => t.upper_bound(nodes))
    }

    #[inline]
    fn are_leaves(&self, nodes: [u32; 2]) -> bool {
        on_trees!(self, t => t.are_leaves(nodes))
    }

    #[inline]
    fn split(&self, nodes: [u32; 2], limit: f64) -> [([u32; 2], f64); 2] {
        on_trees!(self, t => t.split(nodes, limit))
    }

    fn test_leaves(
        &self,
        nodes: [u32; 2],
        best: &mut f64,
        witnesses: &mut Option<FrontierWitnesses>,
    ) -> u64 {
        on_trees!(self, t => t.test_leaves(nodes, best, witnesses))
    }
}
