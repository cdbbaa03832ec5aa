//! Bottom-up builder: agglomerative clustering by locally-ordered nearest neighbours.
//!
//! Citation: D. Meister and J. Bittner, "Parallel Locally-Ordered Clustering for Bounding
//! Volume Hierarchy Construction", IEEE TVCG 24(3), 2018 (PLOC), after B. Walter et al.,
//! "Fast Agglomerative Clustering for Rendering", IEEE RT 2008.
//!
//! Exact agglomerative clustering (always merge the globally nearest pair) is quadratic.
//! PLOC approximates it in `O(n · R)` distance evaluations per round:
//! 1. sort the triangles along a Morton curve of their centroids, normalised to the cube
//!    around the centroids' box (all centroids equal: every code is 0, and the input order
//!    decides);
//! 2. each cluster looks for its nearest neighbour among the `R` clusters before and after
//!    it in that order ([`SEARCH_RADIUS`]); the distance of two clusters is the size of
//!    their merged bounding volume, [`Aabb::size`] (the diagonal) of the merged boxes;
//! 3. mutual nearest neighbours merge; the merged cluster takes the place of the first of
//!    the two, so the list stays in curve order; repeat until one cluster is left.
//!
//! # Why boxes, whatever the tree's volume type
//! The clustering core is generic over any [`BoundingVolume`], but [`build`] runs it on
//! [`Aabb`]s for every tree type `B`, as Walter et al. and PLOC do. Measured on the Stanford
//! bunny (69,451 triangles, debug build): clustering on `B`'s own `merged` took 10.5 s for
//! [`Obb`](crate::bounding::Obb) and 28 s for [`Rss`](crate::bounding::Rss) (their merges
//! fit a new frame by PCA, 2–6 µs each, about 4.5 million of them) against 0.09 s on boxes,
//! *and* gave looser trees: merged OBBs and RSSs grow with every merge, so their sizes rank
//! candidates worse than boxes do. The OBB tree clustered on boxes has a 2 % smaller sum of
//! node sizes and needs 6 % fewer volume tests in a bunny–bunny overlap traversal than the
//! one clustered on OBBs; switching to `B` for the top 256–4096 clusters did not help
//! either. The volumes of the final tree are `B`s fitted by [`super::fit_topology`].
//!
//! Ties are broken by the pair's positions ([`pair_rank`]), which makes the order over pairs
//! total: the least pair of every round is mutual, so each round merges at least once, and
//! equal candidates (identical triangles, a regular grid) pair up side by side into a
//! balanced tree. Nothing depends on hash order, so the tree is a function of the input
//! alone.
//!
//! The binary cluster tree is then laid out as a [`Topology`] depth first from the root,
//! each internal node's two children allocated side by side; a cluster of at most
//! `leaf_size` triangles becomes one leaf holding them all.

use super::{BuildPrimitive, Topology, TopologyNode};
use crate::bounding::{Aabb, BoundingVolume};
use crate::geometry::Triangle;
use crate::math::{DVec3, bounds_of};

/// How many clusters before and after its own position in curve order a cluster searches
/// for its nearest neighbour (PLOC's `r`; the paper finds 8–16 about as good as exact).
pub(super) const SEARCH_RADIUS: usize = 16;

/// Bits per axis of a Morton code (three interleaved in a `u64`).
const MORTON_BITS: u32 = 21;

/// Builds the topology by agglomerative clustering of `triangles` (`primitives` are their
/// centroids and boxes, index for index). The shape does not depend on the volume type the
/// tree will be fitted with (see the [module docs](self)).
pub(super) fn build(
    triangles: &[Triangle],
    primitives: &[BuildPrimitive],
    leaf_size: u32,
) -> Topology {
    debug_assert_eq!(triangles.len(), primitives.len());
    let curve = morton_order(primitives);
    let tree = cluster::<Aabb>(triangles, &curve);
    lay_out(&tree, leaf_size)
}

/// Triangle indices sorted by the Morton code of their centroid (ties by index).
fn morton_order(primitives: &[BuildPrimitive]) -> Vec<u32> {
    let (lo, hi) = bounds_of(primitives.iter().map(|p| p.centroid));
    let side = (hi - lo).max_element();
    let cells = f64::from((1u32 << MORTON_BITS) - 1);
    let scale = if side > 0.0 { cells / side } else { 0.0 };
    let mut keyed: Vec<(u64, u32)> = primitives
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let cell = ((p.centroid - lo) * scale).clamp(DVec3::ZERO, DVec3::splat(cells));
            (
                morton_code(cell.x as u32, cell.y as u32, cell.z as u32),
                i as u32,
            )
        })
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

/// Interleaves the low [`MORTON_BITS`] bits of `x`, `y`, `z` (x lowest).
#[must_use]
fn morton_code(x: u32, y: u32, z: u32) -> u64 {
    spread_bits(x) | (spread_bits(y) << 1) | (spread_bits(z) << 2)
}

/// The low 21 bits of `v` moved to every third bit position (bit `k` to bit `3k`).
#[must_use]
fn spread_bits(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// The binary tree made by clustering. Cluster ids below `leaves` are the triangles
/// themselves; id `leaves + k` is `merges[k]`. The last merge is the root (or triangle 0
/// when there is only one).
#[derive(Debug, Clone)]
struct ClusterTree {
    leaves: u32,
    merges: Vec<Merge>,
}

/// An internal cluster: its two parts and how many triangles it holds.
#[derive(Debug, Clone, Copy)]
struct Merge {
    parts: [u32; 2],
    count: u32,
}

impl ClusterTree {
    fn root(&self) -> u32 {
        match self.merges.len() {
            0 => 0,
            merges => self.leaves + merges as u32 - 1,
        }
    }

    /// The two parts of an internal cluster, `None` for a triangle.
    fn parts(&self, id: u32) -> Option<[u32; 2]> {
        id.checked_sub(self.leaves)
            .map(|k| self.merges[k as usize].parts)
    }

    fn count(&self, id: u32) -> u32 {
        id.checked_sub(self.leaves)
            .map_or(1, |k| self.merges[k as usize].count)
    }
}

/// A cluster's nearest neighbour so far, by merged size, then by [`pair_rank`].
#[derive(Debug, Clone, Copy)]
struct Nearest {
    distance: f64,
    position: u32,
}

impl Nearest {
    const NONE: Self = Self {
        distance: f64::INFINITY,
        position: u32::MAX,
    };

    /// Keeps the cluster at `other` when its merge with the one at `me` is smaller, or as
    /// small and the pair ranks first.
    #[inline]
    fn offer(&mut self, me: u32, distance: f64, other: u32) {
        if distance
            .total_cmp(&self.distance)
            .then_with(|| pair_rank(me, other).cmp(&pair_rank(me, self.position)))
            .is_lt()
        {
            *self = Self {
                distance,
                position: other,
            };
        }
    }
}

/// Tie-break between pairs of equal merged size: closer in curve order first, then pairs
/// starting at an even position, then the lower position. Distinct pairs rank differently,
/// so the order over pairs is total and each round's least pair is mutual. Preferring even
/// starts makes a run of equal candidates pair up as (0, 1), (2, 3), … — with "lowest
/// position wins" alone, every cluster would pick its left neighbour, only the first pair
/// would be mutual, and identical triangles would cluster into a chain in `n` rounds.
#[must_use]
#[inline]
fn pair_rank(i: u32, j: u32) -> (u32, u32, u32) {
    let (lo, hi) = (i.min(j), i.max(j));
    (hi - lo, lo & 1, lo)
}

/// PLOC over the triangles in `curve` order with volumes of type `V`; see the
/// [module docs](self).
fn cluster<V: BoundingVolume>(triangles: &[Triangle], curve: &[u32]) -> ClusterTree {
    let leaves = triangles.len() as u32;
    let mut tree = ClusterTree {
        leaves,
        merges: Vec::with_capacity(triangles.len().saturating_sub(1)),
    };
    // The live clusters in curve order: their ids and volumes.
    let mut ids: Vec<u32> = curve.to_vec();
    let mut volumes: Vec<V> = curve
        .iter()
        .map(|&i| V::fit_triangles(std::slice::from_ref(&triangles[i as usize])))
        .collect();
    let mut nearest = Vec::with_capacity(ids.len());
    let (mut next_ids, mut next_volumes) = (Vec::new(), Vec::new());
    while ids.len() > 1 {
        let live = ids.len();
        nearest.clear();
        nearest.resize(live, Nearest::NONE);
        // Each pair within the window once, offered to both ends.
        for i in 0..live {
            for j in i + 1..live.min(i + 1 + SEARCH_RADIUS) {
                let distance = volumes[i].merged(&volumes[j]).size();
                let (me, other) = (i as u32, j as u32);
                nearest[i].offer(me, distance, other);
                nearest[j].offer(other, distance, me);
            }
        }
        next_ids.clear();
        next_volumes.clear();
        for i in 0..live {
            let j = nearest[i].position as usize;
            let mutual = nearest[j].position as usize == i;
            if !mutual {
                next_ids.push(ids[i]);
                next_volumes.push(volumes[i]);
            } else if i < j {
                let parts = [ids[i], ids[j]];
                let count = tree.count(parts[0]) + tree.count(parts[1]);
                next_ids.push(leaves + tree.merges.len() as u32);
                tree.merges.push(Merge { parts, count });
                next_volumes.push(volumes[i].merged(&volumes[j]));
            }
        }
        debug_assert!(
            next_ids.len() < live,
            "a round must merge at least one pair"
        );
        std::mem::swap(&mut ids, &mut next_ids);
        std::mem::swap(&mut volumes, &mut next_volumes);
    }
    tree
}

/// Lays the cluster tree out as a [`Topology`]: depth first, children side by side after
/// their parent, every cluster of at most `leaf_size` triangles one leaf.
fn lay_out(tree: &ClusterTree, leaf_size: u32) -> Topology {
    let n = tree.leaves;
    let mut topology = Topology {
        nodes: vec![TopologyNode {
            first: 0,
            count: 0,
            span: [0, n],
        }],
        order: vec![0; n as usize],
    };
    // The cluster each topology node stands for, index for index.
    let mut clusters = vec![tree.root()];
    let mut pending = vec![0usize];
    let mut walk = Vec::new();
    while let Some(index) = pending.pop() {
        let cluster = clusters[index];
        let [start, end] = topology.nodes[index].span;
        debug_assert_eq!(end - start, tree.count(cluster));
        let parts = tree.parts(cluster).filter(|_| end - start > leaf_size);
        let Some([left, right]) = parts else {
            topology.nodes[index].first = start;
            topology.nodes[index].count = end - start;
            collect_triangles(
                tree,
                cluster,
                &mut walk,
                &mut topology.order[start as usize..],
            );
            continue;
        };
        let first = topology.nodes.len();
        topology.nodes[index].first = first as u32;
        let mid = start + tree.count(left);
        for (cluster, span) in [(left, [start, mid]), (right, [mid, end])] {
            topology.nodes.push(TopologyNode {
                first: 0,
                count: 0,
                span,
            });
            clusters.push(cluster);
        }
        pending.push(first + 1);
        pending.push(first);
    }
    topology
}

/// Writes the triangles of `cluster`, left part first, to the front of `out`.
fn collect_triangles(tree: &ClusterTree, cluster: u32, stack: &mut Vec<u32>, out: &mut [u32]) {
    stack.clear();
    stack.push(cluster);
    let mut written = 0;
    while let Some(id) = stack.pop() {
        match tree.parts(id) {
            Some([left, right]) => {
                stack.push(right);
                stack.push(left);
            }
            None => {
                out[written] = id;
                written += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BuildParams, BuildStrategy, fit_topology};
    use super::*;
    use crate::bounding::Obb;
    use crate::bvh::Bvh;
    use crate::bvh::test_support::{for_each_volume, soup};
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    fn primitives(triangles: &[Triangle]) -> Vec<BuildPrimitive> {
        triangles.iter().map(BuildPrimitive::of).collect()
    }

    fn topology(triangles: &[Triangle], leaf_size: u32) -> Topology {
        build(triangles, &primitives(triangles), leaf_size)
    }

    /// Asserts the [`Topology`] contract, independently of [`Bvh::validate`].
    fn assert_topology(t: &Topology, n: usize, leaf_size: u32) {
        let mut sorted = t.order.clone();
        sorted.sort_unstable();
        assert!(
            sorted.iter().copied().eq(0..n as u32),
            "order is a permutation"
        );
        assert_eq!(t.nodes[0].span, [0, n as u32], "root spans everything");
        let mut parents = vec![0usize; t.nodes.len()];
        for (index, node) in t.nodes.iter().enumerate() {
            let [start, end] = node.span;
            assert!(start < end, "node {index} is empty");
            if node.count > 0 {
                assert!(node.count <= leaf_size, "leaf {index} too large");
                assert_eq!([node.first, node.first + node.count], node.span);
            } else {
                let first = node.first as usize;
                assert!(
                    first > index && first + 1 < t.nodes.len(),
                    "children after parent"
                );
                assert!(end - start > leaf_size, "a small subtree must be one leaf");
                let (left, right) = (t.nodes[first].span, t.nodes[first + 1].span);
                assert_eq!([left[0], left[1], right[1]], [start, right[0], end]);
                parents[first] += 1;
                parents[first + 1] += 1;
            }
        }
        assert_eq!(parents[0], 0);
        assert!(
            parents[1..].iter().all(|&p| p == 1),
            "every node has one parent"
        );
    }

    #[test]
    fn morton_codes_interleave_the_bits_with_x_lowest() {
        assert_eq!(morton_code(1, 0, 0), 0b001);
        assert_eq!(morton_code(0, 1, 0), 0b010);
        assert_eq!(morton_code(0, 0, 1), 0b100);
        assert_eq!(morton_code(3, 0, 1), 0b001_101);
        let max = (1 << MORTON_BITS) - 1;
        assert_eq!(morton_code(max, max, max), (1u64 << 63) - 1);
        assert_eq!(morton_code(max, 0, 0), 0x1249_2492_4924_9249);
        // Bits above the 21st are ignored rather than bleeding into other axes.
        assert_eq!(morton_code(1 << MORTON_BITS, 0, 0), 0);
    }

    #[test]
    fn curve_order_sorts_by_cell_and_keeps_input_order_for_equal_centroids() {
        let at = |x: f64| {
            let p = DVec3::new(x, 0.0, 0.0);
            Triangle::new(p, p, p)
        };
        let line = [at(3.0), at(1.0), at(2.0), at(0.0)];
        assert_eq!(morton_order(&primitives(&line)), [3, 1, 2, 0]);
        let same = [at(5.0); 6];
        assert_eq!(morton_order(&primitives(&same)), [0, 1, 2, 3, 4, 5]);
    }

    #[test]
    fn two_distant_groups_become_the_two_children_of_the_root() {
        let mut rng = rng(301);
        for case in 0..200 {
            let n = rng.random_range(4..60);
            let offset = DVec3::new(100.0, 0.0, 0.0);
            let mut triangles = soup(&mut rng, n, 1.0, 0.1);
            // Every other triangle moves to the far group.
            for t in triangles.iter_mut().skip(1).step_by(2) {
                *t = Triangle::new(t.a + offset, t.b + offset, t.c + offset);
            }
            let t = topology(&triangles, 1);
            assert_topology(&t, n, 1);
            let root = t.nodes[0];
            let [left, right] = [
                t.nodes[root.first as usize],
                t.nodes[root.first as usize + 1],
            ];
            for span in [left.span, right.span] {
                let far: Vec<bool> = t.order[span[0] as usize..span[1] as usize]
                    .iter()
                    .map(|&i| i % 2 == 1)
                    .collect();
                assert!(
                    far.iter().all(|&f| f == far[0]),
                    "case {case}: a root child mixes the two groups"
                );
            }
            // Each group is a whole child (the spans tile the root's, so one test suffices).
            let far_on_left = t.order[left.span[0] as usize] % 2 == 1;
            let far_on_right = t.order[right.span[0] as usize] % 2 == 1;
            assert_ne!(far_on_left, far_on_right, "case {case}");
        }
    }

    #[test]
    fn clustering_pairs_the_nearest_triangles_first() {
        // Four tiny triangles at x = 0, 1, 10, 11: the pairs {0, 1} and {10, 11} merge first.
        let at = |x: f64| {
            let p = DVec3::new(x, 0.0, 0.0);
            Triangle::new(p, p + DVec3::Y * 0.01, p + DVec3::Z * 0.01)
        };
        let triangles = [at(10.0), at(0.0), at(11.0), at(1.0)];
        let t = topology(&triangles, 1);
        assert_topology(&t, 4, 1);
        assert_eq!(t.nodes.len(), 7);
        let mut halves = [t.order[..2].to_vec(), t.order[2..].to_vec()];
        for half in &mut halves {
            half.sort_unstable();
        }
        halves.sort();
        assert_eq!(halves, [vec![0, 2], vec![1, 3]]);
        // With leaf size 2 each pair is one leaf under the root.
        let t = topology(&triangles, 2);
        assert_topology(&t, 4, 2);
        assert_eq!(t.nodes.len(), 3);
    }

    #[test]
    fn random_soups_give_valid_topologies_for_every_leaf_size() {
        let mut rng = rng(302);
        for case in 0..400 {
            let n = rng.random_range(1..300);
            let leaf_size = rng.random_range(1..9);
            let size = [1e-6, 0.01, 0.3, 3.0][case % 4];
            let triangles = soup(&mut rng, n, 1.0, size);
            let t = topology(&triangles, leaf_size);
            assert_topology(&t, n, leaf_size);
            assert_eq!(t.nodes.len() == 1, n as u32 <= leaf_size, "case {case}");
        }
    }

    #[test]
    fn identical_and_zero_area_triangles_still_merge_every_round() {
        let mut rng = rng(303);
        let p = point_in_cube(&mut rng, 1e5);
        for n in [1, 2, 3, 17, 100, 1000] {
            let same = vec![Triangle::new(p, p + DVec3::X, p + DVec3::Y); n];
            let points = vec![Triangle::new(p, p, p); n];
            for (triangles, leaf_size) in [(&same, 1), (&points, 1), (&same, 4), (&points, 3)] {
                let t = topology(triangles, leaf_size);
                assert_topology(&t, n, leaf_size);
                // Ties pair neighbours side by side: as balanced as a median split.
                let bvh: Bvh<Aabb> = fit_topology(&t, triangles, leaf_size);
                let ceil_log2 = |k: usize| k.next_power_of_two().ilog2() as usize;
                let least = ceil_log2(n.div_ceil(leaf_size as usize));
                let depth = bvh.depth();
                assert!(
                    least <= depth && depth <= ceil_log2(n),
                    "n {n} leaf {leaf_size}"
                );
                if leaf_size == 1 {
                    assert_eq!(depth, ceil_log2(n), "n {n}");
                }
            }
        }
    }

    #[test]
    fn clustering_is_a_function_of_the_input() {
        let mut rng = rng(304);
        for _ in 0..50 {
            let n = rng.random_range(1..500);
            let triangles = soup(&mut rng, n, 1.0, 0.2);
            let (a, b) = (topology(&triangles, 2), topology(&triangles, 2));
            assert_eq!(a.nodes, b.nodes);
            assert_eq!(a.order, b.order);
        }
    }

    fn cluster_with<V: BoundingVolume>(triangles: &[Triangle]) {
        let curve = morton_order(&primitives(triangles));
        let tree = cluster::<V>(triangles, &curve);
        assert_eq!(tree.merges.len(), triangles.len() - 1, "{}", V::NAME);
        assert_eq!(tree.count(tree.root()), triangles.len() as u32);
        assert_topology(&lay_out(&tree, 1), triangles.len(), 1);
    }

    #[test]
    fn the_clustering_core_works_with_every_volume_type() {
        let mut rng = rng(305);
        for n in [1, 2, 5, 40, 150] {
            let triangles = soup(&mut rng, n, 1.0, 0.1);
            for_each_volume!(cluster_with(&triangles));
        }
    }

    #[test]
    fn layout_of_a_built_topology_fits_and_validates_for_agglomerative_presets() {
        let mut rng = rng(308);
        for case in 0..100 {
            let n = rng.random_range(1..200);
            let triangles = soup(&mut rng, n, 1.0, 0.05);
            let leaf_size = rng.random_range(1..6);
            let params = BuildParams::new(BuildStrategy::Agglomerative, leaf_size);
            let bvh = Bvh::<Obb>::from_triangles(&triangles, &params);
            assert_eq!(bvh.validate(), Ok(()), "case {case}");
            assert_eq!(bvh.leaf_size(), leaf_size as usize);
        }
    }
}
