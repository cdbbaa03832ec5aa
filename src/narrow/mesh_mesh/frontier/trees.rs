//! The trees of one frontier pair, seen through [`PairTrees`]: the few operations the
//! frontier needs (node bounds, splits, leaf tests), so that one frontier can hold pairs of
//! different volume types, each pair's chosen by measured tightness (the pipeline's
//! [`MeshPairTrees`](crate::narrow::mesh_mesh::frontier::MeshPairTrees)).

use super::super::leaf_triangle::LeafTriangles;
use super::FrontierWitnesses;
use crate::bounding::BoundingVolume;
use crate::bvh::Bvh;
use crate::bvh::tandem::descend_a;
use crate::math::{Isometry, conservative_slack};
use crate::narrow::distance_triangle_triangle;
use crate::narrow::mesh_mesh::{precedes_in_ties, rounding_bound};

/// One mesh pair of the frame.
#[derive(Debug, Clone, Copy)]
pub struct FrontierPair<'a, B> {
    /// Tree of mesh A (A's frame).
    pub a: &'a Bvh<B>,
    /// Tree of mesh B (B's frame).
    pub b: &'a Bvh<B>,
    /// B's frame expressed in A's frame.
    pub pose_ab: Isometry,
    /// The distance that counts as close (the pair's margin sum), metres, `≥ 0`; `+∞`
    /// asks for the exact distance of every pair (nothing is dropped for exceeding it,
    /// only for not beating the pair's best distance so far).
    pub threshold: f64,
    /// A triangle pair to try first (ids into each mesh's own triangle list, as
    /// [`FrontierWitnesses::triangles`]): typically the pair that proved it within the
    /// threshold last frame. Tested when the root is first processed (one visit), its
    /// exact distance starts the pair's best distance, so entries that cannot beat it are
    /// dropped, as the warm start of the depth-first queries does; a seed still within the
    /// threshold proves the pair close at once. A pair with a seed is *expected close*: it
    /// waits while undecided pairs are settled even when its seed no longer holds (module
    /// docs, "Decide first"). `None`, or ids out of range, start from nothing. Exact
    /// distances do not depend on it (the witnesses of tied pairs may); a truncated answer
    /// stays conservative, and is usually tighter.
    pub seed: Option<[u32; 2]>,
}

/// What the frontier needs of a pair's two trees. Nodes are named `[node of A, node of B]`
/// (indices into each tree's nodes; `[0, 0]` is the root pair). Implemented by
/// [`FrontierPair`] for every volume type and by the pipeline's
/// [`MeshPairTrees`](crate::narrow::mesh_mesh::frontier::MeshPairTrees), whose type is chosen per pair.
pub trait PairTrees {
    /// The pair's threshold ([`FrontierPair::threshold`]).
    fn threshold(&self) -> f64;

    /// The roots' upper bound of the distance ([`FrontierPair`]'s centres plus stand-offs)
    /// and the rounding of a triangle distance at the pair's scale, metres.
    fn root_bounds(&self) -> (f64, f64);

    /// The seed triangle pair's distance and witnesses (one triangle test), when the pair
    /// has a seed naming triangles of both meshes.
    fn seed_distance(&self) -> Option<(f64, FrontierWitnesses)>;

    /// A lower bound of the distance between the two nodes' triangles, metres
    /// ([`BoundingVolume::distance_lower_bound_within`] with `limit`, raised for a large
    /// triangle's leaf against a small node as the exact queries raise it).
    fn bound(&self, nodes: [u32; 2], limit: f64) -> f64;

    /// An upper bound of the distance between the two nodes' triangles (centres plus
    /// stand-offs, padded for rounding), metres.
    fn upper_bound(&self, nodes: [u32; 2]) -> f64;

    /// Whether both nodes are leaves.
    fn are_leaves(&self, nodes: [u32; 2]) -> bool;

    /// The two child node pairs, splitting the side [`descend_a`] chooses, each with its
    /// [`bound`](Self::bound) within `limit` (the node kept is placed once for both).
    fn split(&self, nodes: [u32; 2], limit: f64) -> [([u32; 2], f64); 2];

    /// Tests every triangle pair of the leaf pair `nodes`, lowering `best` (metres) and
    /// replacing `witnesses` on each strictly closer pair; returns the number of tests.
    fn test_leaves(
        &self,
        nodes: [u32; 2],
        best: &mut f64,
        witnesses: &mut Option<FrontierWitnesses>,
    ) -> u64;
}

/// Two trees and B's pose in A's frame, borrowed: the operations of [`PairTrees`] on them,
/// shared by every implementation.
#[derive(Debug, Clone, Copy)]
pub struct TreesAt<'a, B> {
    /// Tree of mesh A (A's frame).
    pub a: &'a Bvh<B>,
    /// Tree of mesh B (B's frame).
    pub b: &'a Bvh<B>,
    /// B's frame expressed in A's frame.
    pub pose_ab: &'a Isometry,
}

impl<B: BoundingVolume> TreesAt<'_, B> {
    /// See [`PairTrees::root_bounds`].
    #[must_use]
    pub fn root_bounds(&self) -> (f64, f64) {
        let (ra, rb) = (self.a.root_bv(), self.b.root_bv());
        (
            centre_upper_bound(ra, rb, self.pose_ab),
            rounding_bound(self.a, self.b, self.pose_ab),
        )
    }

    /// See [`PairTrees::seed_distance`]; `seed` names a triangle of each mesh.
    #[must_use]
    pub fn seed_distance(&self, seed: Option<[u32; 2]>) -> Option<(f64, FrontierWitnesses)> {
        let [ia, ib] = seed?;
        let (sa, sb) = (self.a.slot_of(ia)?, self.b.slot_of(ib)?);
        let tri_b = self.b.triangles()[sb].transformed(self.pose_ab);
        let d = distance_triangle_triangle(&self.a.triangles()[sa], &tri_b);
        Some((
            d.distance,
            FrontierWitnesses {
                point_a: d.point_a,
                point_b: d.point_b,
                triangles: [ia, ib],
            },
        ))
    }

    /// See [`PairTrees::bound`].
    #[inline]
    #[must_use]
    pub fn bound(&self, [a, b]: [u32; 2], limit: f64) -> f64 {
        let (x, y) = (&self.a.nodes()[a as usize], &self.b.nodes()[b as usize]);
        self.leaf_triangles()
            .distance_lower_bound_within(x, y, limit)
    }

    /// The two trees at their pose, for the large-triangle test (`leaf_triangle.rs`).
    #[inline]
    fn leaf_triangles(&self) -> LeafTriangles<'_, B> {
        LeafTriangles {
            a: self.a,
            b: self.b,
            iso: self.pose_ab,
        }
    }

    /// See [`PairTrees::upper_bound`].
    #[must_use]
    pub fn upper_bound(&self, [a, b]: [u32; 2]) -> f64 {
        let (x, y) = (
            &self.a.nodes()[a as usize].bv,
            &self.b.nodes()[b as usize].bv,
        );
        centre_upper_bound(x, y, self.pose_ab)
    }

    /// See [`PairTrees::are_leaves`].
    #[inline]
    #[must_use]
    pub fn are_leaves(&self, [a, b]: [u32; 2]) -> bool {
        self.a.nodes()[a as usize].is_leaf() && self.b.nodes()[b as usize].is_leaf()
    }

    /// See [`PairTrees::split`]. A split of B's node bounds its children against A's node
    /// in B's frame (through the inverse pose): a bound of the same distance, and for OBBs
    /// the same 15 separating axes, so the same bound up to rounding.
    #[inline]
    #[must_use]
    pub fn split(&self, [a, b]: [u32; 2], limit: f64) -> [([u32; 2], f64); 2] {
        let (x, y) = (&self.a.nodes()[a as usize], &self.b.nodes()[b as usize]);
        let split_a = descend_a(x, y);
        let inverse;
        let (tree, kept, children, pose) = if split_a {
            (self.a, &y.bv, x.children(), self.pose_ab)
        } else {
            inverse = self.pose_ab.inverse();
            (self.b, &x.bv, y.children(), &inverse)
        };
        let bounds = B::distance_lower_bounds_within(
            children.map(|c| &tree.nodes()[c].bv),
            kept,
            pose,
            limit,
        );
        let leaf = self.leaf_triangles();
        [0, 1].map(|k| {
            let child = &tree.nodes()[children[k]];
            let c = children[k] as u32;
            if split_a {
                ([c, b], leaf.raise(bounds[k], child, y, limit))
            } else {
                ([a, c], leaf.raise(bounds[k], x, child, limit))
            }
        })
    }

    /// See [`PairTrees::test_leaves`].
    pub fn test_leaves(
        &self,
        [a, b]: [u32; 2],
        best: &mut f64,
        witnesses: &mut Option<FrontierWitnesses>,
    ) -> u64 {
        let (x, y) = (&self.a.nodes()[a as usize], &self.b.nodes()[b as usize]);
        let (ta, tb) = (self.a.triangles(), self.b.triangles());
        let mut tests = 0;
        for sb in y.slots() {
            let tri_b = tb[sb].transformed(self.pose_ab);
            for sa in x.slots() {
                let d = distance_triangle_triangle(&ta[sa], &tri_b);
                tests += 1;
                let ids = || [self.a.triangle_id(sa), self.b.triangle_id(sb)];
                if replaces_closest(d.distance, ids, *best, witnesses.as_ref()) {
                    *best = d.distance;
                    *witnesses = Some(FrontierWitnesses {
                        point_a: d.point_a,
                        point_b: d.point_b,
                        triangles: ids(),
                    });
                }
            }
        }
        tests
    }
}

impl<'a, B> FrontierPair<'a, B> {
    /// Its trees and pose, borrowed.
    #[inline]
    #[must_use]
    pub fn trees(&self) -> TreesAt<'_, B> {
        TreesAt {
            a: self.a,
            b: self.b,
            pose_ab: &self.pose_ab,
        }
    }
}

impl<B: BoundingVolume> PairTrees for FrontierPair<'_, B> {
    #[inline]
    fn threshold(&self) -> f64 {
        self.threshold
    }

    fn root_bounds(&self) -> (f64, f64) {
        self.trees().root_bounds()
    }

    fn seed_distance(&self) -> Option<(f64, FrontierWitnesses)> {
        self.trees().seed_distance(self.seed)
    }

    #[inline]
    fn bound(&self, nodes: [u32; 2], limit: f64) -> f64 {
        self.trees().bound(nodes, limit)
    }

    fn upper_bound(&self, nodes: [u32; 2]) -> f64 {
        self.trees().upper_bound(nodes)
    }

    #[inline]
    fn are_leaves(&self, nodes: [u32; 2]) -> bool {
        self.trees().are_leaves(nodes)
    }

    #[inline]
    fn split(&self, nodes: [u32; 2], limit: f64) -> [([u32; 2], f64); 2] {
        self.trees().split(nodes, limit)
    }

    fn test_leaves(
        &self,
        nodes: [u32; 2],
        best: &mut f64,
        witnesses: &mut Option<FrontierWitnesses>,
    ) -> u64 {
        self.trees().test_leaves(nodes, best, witnesses)
    }
}

/// Whether a triangle pair at `distance` (its ids from `ids`) replaces the closest found so
/// far (`best`, named by `witnesses`): closer, or as close and first in
/// [`precedes_in_ties`]'s order, as in every exact distance query.
#[inline]
pub(super) fn replaces_closest(
    distance: f64,
    ids: impl Fn() -> [u32; 2],
    best: f64,
    witnesses: Option<&FrontierWitnesses>,
) -> bool {
    distance < best
        || (distance == best && witnesses.is_some_and(|w| precedes_in_ties(ids(), w.triangles)))
}

/// An upper bound of the distance between the geometry bounded by `x` (frame A) and by `y`
/// (frame B): each volume's centre lies inside it, hence within its stand-off of its
/// geometry. Padded for the rounding of the centre's transform.
#[must_use]
fn centre_upper_bound<B: BoundingVolume>(x: &B, y: &B, pose_ab: &Isometry) -> f64 {
    let (cx, cy) = (x.center(), pose_ab.transform_point(y.center()));
    let slack =
        conservative_slack(cx.abs().max_element() + cy.abs().max_element() + x.size() + y.size());
    cx.distance(cy) + x.stand_off() + y.stand_off() + slack
}
