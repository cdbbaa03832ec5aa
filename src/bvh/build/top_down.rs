//! Top-down builders: split the triangle set in two, recursively, until leaves are small.
//!
//! Three rules decide a split (see [`BuildStrategy`]): median along the longest centroid
//! axis, mean along the principal axis of the centroids (Gottschalk et al., "OBBTree",
//! SIGGRAPH 1996, §3), and the binned surface-area heuristic (Wald, "On fast Construction of
//! SAH-based Bounding Volume Hierarchies", IEEE RT 2007). Every rule returns a split with
//! both sides non-empty; when a rule cannot separate the triangles (all centroids equal
//! along its axis) it falls back to the median by index, which always can.

use super::{BuildPrimitive, BuildStrategy, SAH_BINS, Topology, TopologyNode};
use crate::bounding::fit::{point_moments, principal_axes};
use crate::math::{DVec3, bounds_of};

/// Builds the topology by recursive splitting with `strategy` (not `Agglomerative`).
pub(super) fn build(
    primitives: &[BuildPrimitive],
    strategy: BuildStrategy,
    leaf_size: u32,
) -> Topology {
    let mut scratch = Vec::new();
    split_recursively(primitives.len(), leaf_size, (), |order, ()| {
        let mid = match strategy {
            BuildStrategy::Median => split_median(primitives, order),
            BuildStrategy::MeanVariance => split_mean(primitives, order, &mut scratch),
            BuildStrategy::BinnedSah => split_sah(primitives, order),
            BuildStrategy::Agglomerative | BuildStrategy::Octree | BuildStrategy::MedialAxis => {
                unreachable!("not a split rule of this builder")
            }
        };
        (mid, [(), ()])
    })
}

/// The topology made by splitting `0..n` recursively until parts hold at most `leaf_size`:
/// `split` reorders a node's indices and returns where to cut them (`0 < mid < len`), and
/// the state each side carries into its own split (a cell, for the octree); `root` is the
/// root's state.
pub(super) fn split_recursively<S>(
    n: usize,
    leaf_size: u32,
    root: S,
    mut split: impl FnMut(&mut [u32], &S) -> (usize, [S; 2]),
) -> Topology {
    let n = n as u32;
    let mut topology = Topology {
        nodes: vec![TopologyNode {
            first: 0,
            count: 0,
            span: [0, n],
        }],
        order: (0..n).collect(),
    };
    let mut pending = vec![(0usize, root)];
    while let Some((index, state)) = pending.pop() {
        let [start, end] = topology.nodes[index].span;
        let len = end - start;
        if len <= leaf_size {
            topology.nodes[index].first = start;
            topology.nodes[index].count = len;
            continue;
        }
        let order = &mut topology.order[start as usize..end as usize];
        let (mid, [left, right]) = split(order, &state);
        let mid = mid as u32;
        debug_assert!(mid > 0 && mid < len);
        let first = topology.nodes.len();
        topology.nodes[index].first = first as u32;
        topology.nodes.push(TopologyNode {
            first: 0,
            count: 0,
            span: [start, start + mid],
        });
        topology.nodes.push(TopologyNode {
            first: 0,
            count: 0,
            span: [start + mid, end],
        });
        pending.push((first + 1, right));
        pending.push((first, left));
    }
    topology
}

/// Centroid bounds of the triangles in `order`.
fn centroid_bounds(primitives: &[BuildPrimitive], order: &[u32]) -> (DVec3, DVec3) {
    bounds_of(order.iter().map(|&i| primitives[i as usize].centroid))
}

/// Median of the centroids along the longest axis of their box; returns `order.len() / 2`.
fn split_median(primitives: &[BuildPrimitive], order: &mut [u32]) -> usize {
    let (lo, hi) = centroid_bounds(primitives, order);
    let axis = (hi - lo).max_position();
    split_at_median_by(order, |i| primitives[i as usize].centroid[axis])
}

/// Reorders `order` so its first half has the smaller `key`s (of the indices); returns the
/// split index.
pub(super) fn split_at_median_by(order: &mut [u32], key: impl Fn(u32) -> f64) -> usize {
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |&i, &j| key(i).total_cmp(&key(j)));
    mid
}

/// Mean of the centroids along their principal axis; the median along it when the mean
/// leaves a side empty.
fn split_mean(primitives: &[BuildPrimitive], order: &mut [u32], scratch: &mut Vec<DVec3>) -> usize {
    scratch.clear();
    scratch.extend(order.iter().map(|&i| primitives[i as usize].centroid));
    let moments = point_moments(scratch);
    let axis = principal_axes(&moments.covariance).x_axis;
    let mean = axis.dot(moments.mean);
    let below = partition(order, |i| axis.dot(primitives[i as usize].centroid) < mean);
    if below == 0 || below == order.len() {
        split_at_median_by(order, |i| axis.dot(primitives[i as usize].centroid))
    } else {
        below
    }
}

/// Moves the indices satisfying `goes_left` to the front; returns how many there are.
pub(super) fn partition(order: &mut [u32], goes_left: impl Fn(u32) -> bool) -> usize {
    let mut left = 0;
    for k in 0..order.len() {
        if goes_left(order[k]) {
            order.swap(left, k);
            left += 1;
        }
    }
    left
}

/// Box accumulated over a bin's triangles.
#[derive(Debug, Clone, Copy)]
struct Bin {
    min: DVec3,
    max: DVec3,
    count: usize,
}

impl Bin {
    const EMPTY: Self = Self {
        min: DVec3::INFINITY,
        max: DVec3::NEG_INFINITY,
        count: 0,
    };

    fn add(&mut self, p: &BuildPrimitive) {
        self.min = self.min.min(p.min);
        self.max = self.max.max(p.max);
        self.count += 1;
    }

    fn merged(&self, other: &Self) -> Self {
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
            count: self.count + other.count,
        }
    }

    /// Half the surface area of the box (0 when empty).
    fn half_area(&self) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let d = self.max - self.min;
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// Binned SAH: the plane between bins, on any axis, minimising `area(L)·|L| + area(R)·|R|`.
fn split_sah(primitives: &[BuildPrimitive], order: &mut [u32]) -> usize {
    let (lo, hi) = centroid_bounds(primitives, order);
    let extent = hi - lo;
    let mut best: Option<(f64, usize, usize)> = None; // (cost, axis, planes below)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = SAH_BINS as f64 / extent[axis];
        let bin_of = |c: DVec3| (((c[axis] - lo[axis]) * scale) as usize).min(SAH_BINS - 1);
        let mut bins = [Bin::EMPTY; SAH_BINS];
        for &i in order.iter() {
            let p = &primitives[i as usize];
            bins[bin_of(p.centroid)].add(p);
        }
        // Sweep from the right to know every suffix's cost, then from the left.
        let mut right_cost = [0.0; SAH_BINS];
        let mut acc = Bin::EMPTY;
        for b in (1..SAH_BINS).rev() {
            acc = acc.merged(&bins[b]);
            right_cost[b] = acc.half_area() * acc.count as f64;
        }
        let mut left = Bin::EMPTY;
        for planes in 1..SAH_BINS {
            left = left.merged(&bins[planes - 1]);
            if left.count == 0 || left.count == order.len() {
                continue;
            }
            let cost = left.half_area() * left.count as f64 + right_cost[planes];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, planes));
            }
        }
    }
    let Some((_, axis, planes)) = best else {
        return split_at_median_by(order, |i| primitives[i as usize].centroid.x);
    };
    let scale = SAH_BINS as f64 / extent[axis];
    partition(order, |i| {
        let c = primitives[i as usize].centroid;
        ((((c[axis] - lo[axis]) * scale) as usize).min(SAH_BINS - 1)) < planes
    })
}
