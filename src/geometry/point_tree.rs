//! The nearest of many points to a query point anywhere in space: a k-d tree.
//!
//! Built once over a point cloud (median splits along the widest axis of each node's box,
//! buckets of at most [`BUCKET`] points), queried best-first: a query descends to the bucket
//! holding its point, then visits the other sides only while their box can still hold a
//! closer point. Unlike a uniform grid, the cost does not grow with the query's distance
//! from the cloud (the medial-ball search of [`crate::geometry::mesh::medial_balls`] asks from
//! deep inside a solid, far from every surface sample).

use crate::math::DVec3;

/// Most points in a leaf.
const BUCKET: usize = 8;

/// A k-d tree over points (local frame, finite).
///
/// # Invariants
/// `order` is a permutation of the point indices; node `i`'s points are
/// `order[span.0 .. span.1]`, and an internal node's children split that range at `mid`:
/// every point left of `mid` has `coordinate(axis) <= split`, every point right of it
/// `>= split`.
#[derive(Debug, Clone)]
pub struct PointTree {
    points: Vec<DVec3>,
    order: Vec<u32>,
    nodes: Vec<Node>,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    span: (u32, u32),
    /// The box of the node's points.
    lo: DVec3,
    hi: DVec3,
    /// `usize::MAX` for a leaf; else the split axis (0, 1, 2).
    axis: usize,
    split: f64,
    /// Children, internal nodes only.
    children: [u32; 2],
}

impl PointTree {
    /// The tree over `points`, which it copies.
    #[must_use]
    pub fn new(points: &[DVec3]) -> Self {
        let mut tree = Self {
            points: points.to_vec(),
            order: (0..points.len() as u32).collect(),
            nodes: Vec::with_capacity(2 * points.len() / BUCKET + 1),
        };
        if !points.is_empty() {
            tree.build(0, points.len());
        }
        tree
    }

    /// Builds the node over `order[start..end]`, returning its index.
    fn build(&mut self, start: usize, end: usize) -> u32 {
        let index = self.nodes.len() as u32;
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &i in &self.order[start..end] {
            let p = self.points[i as usize];
            lo = lo.min(p);
            hi = hi.max(p);
        }
        self.nodes.push(Node {
            span: (start as u32, end as u32),
            lo,
            hi,
            axis: usize::MAX,
            split: 0.0,
            children: [0; 2],
        });
        if end - start <= BUCKET {
            return index;
        }
        let extent = hi - lo;
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = (end - start) / 2;
        let points = &self.points;
        self.order[start..end].select_nth_unstable_by(mid, |&a, &b| {
            points[a as usize][axis].total_cmp(&points[b as usize][axis])
        });
        let split = self.points[self.order[start + mid] as usize][axis];
        let left = self.build(start, start + mid);
        let right = self.build(start + mid, end);
        let node = &mut self.nodes[index as usize];
        node.axis = axis;
        node.split = split;
        node.children = [left, right];
        index
    }

    /// The point nearest `query` among those `accept` takes (by index into the input), and
    /// its squared distance; `None` when no point is accepted.
    pub fn nearest(&self, query: DVec3, accept: impl Fn(usize) -> bool) -> Option<(usize, f64)> {
        self.nearest_within(query, f64::INFINITY, accept)
    }

    /// [`nearest`](Self::nearest) among the points closer than `sqrt(limit_squared)`: `None`
    /// when there is none. Subtrees beyond the limit are never opened, so asking whether a
    /// ball is empty costs what the ball's neighbourhood holds, not the whole cloud.
    pub fn nearest_within(
        &self,
        query: DVec3,
        limit_squared: f64,
        accept: impl Fn(usize) -> bool,
    ) -> Option<(usize, f64)> {
        if self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<(usize, f64)> = None;
        let bound = |best: Option<(usize, f64)>| best.map_or(limit_squared, |(_, d)| d);
        // (node, squared distance from the query to the node's side of its parent's plane).
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        stack.push((0, 0.0));
        while let Some((index, floor)) = stack.pop() {
            if floor >= bound(best) {
                continue;
            }
            let node = self.nodes[index as usize];
            if node.axis == usize::MAX {
                for &i in &self.order[node.span.0 as usize..node.span.1 as usize] {
                    let i = i as usize;
                    let d = self.points[i].distance_squared(query);
                    if d < bound(best) && accept(i) {
                        best = Some((i, d));
                    }
                }
                continue;
            }
            let offset = query[node.axis] - node.split;
            let (near, far) = if offset <= 0.0 {
                (node.children[0], node.children[1])
            } else {
                (node.children[1], node.children[0])
            };
            // The far side is at least the plane's distance away (and at least as far as
            // this node's own floor); the near side is pushed last, so visited first.
            stack.push((far, floor.max(offset * offset)));
            stack.push((near, floor));
        }
        best
    }
}

impl PointTree {
    /// The point with the largest `direction · p` and that value, computed as
    /// `direction.dot(p)` exactly as a linear scan would (ties: any of them); `None` for no
    /// points. Branch and bound over the nodes' boxes: about `log n` leaves for a point
    /// cloud spread in space, so checking every plane of a polytope against every point
    /// costs `O(F log V)` rather than `O(F V)`.
    #[must_use]
    pub fn max_dot(&self, direction: DVec3) -> Option<(usize, f64)> {
        if self.nodes.is_empty() {
            return None;
        }
        // A box's largest `direction · x`, padded for the rounding of the dot products it
        // stands for (each within a few ulps of `Σ |d_k| |x_k|`).
        let reach = |node: &Node| {
            let (a, b) = (direction * node.lo, direction * node.hi);
            let top = a.max(b);
            let scale = (direction.abs() * node.lo.abs().max(node.hi.abs())).element_sum();
            top.element_sum() + 8.0 * f64::EPSILON * scale
        };
        let mut best: Option<(usize, f64)> = None;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        stack.push(0);
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            if best.is_some_and(|(_, b)| reach(node) < b) {
                continue;
            }
            if node.axis == usize::MAX {
                for &i in &self.order[node.span.0 as usize..node.span.1 as usize] {
                    let value = direction.dot(self.points[i as usize]);
                    if best.is_none_or(|(_, b)| value > b) {
                        best = Some((i as usize, value));
                    }
                }
                continue;
            }
            // The child reaching further is visited first.
            let [left, right] = node.children;
            let (near, far) =
                if reach(&self.nodes[left as usize]) >= reach(&self.nodes[right as usize]) {
                    (left, right)
                } else {
                    (right, left)
                };
            stack.push(far);
            stack.push(near);
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::splitmix64;

    fn cloud(seed: u64, n: usize) -> Vec<DVec3> {
        let mut state = seed;
        let mut unit = || {
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            (splitmix64(state) >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| DVec3::new(unit(), unit() * 0.1, unit() * 3.0))
            .collect()
    }

    /// Against a linear scan, from queries inside, near and far from the cloud, with and
    /// without a filter.
    #[test]
    fn nearest_equals_a_linear_scan() {
        for (seed, n) in [(1, 1), (2, 7), (3, 100), (4, 2_000)] {
            let points = cloud(seed, n);
            let tree = PointTree::new(&points);
            let queries = cloud(seed + 100, 300);
            for (k, q) in queries.iter().enumerate() {
                let q = *q * (1.0 + (k % 5) as f64 * 3.0) - DVec3::splat(k as f64 % 2.0);
                let odd = |i: usize| i % 2 == 1;
                for filter in [false, true] {
                    let accept = |i: usize| !filter || odd(i);
                    let scan = points
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| accept(*i))
                        .map(|(i, p)| (i, p.distance_squared(q)))
                        .min_by(|a, b| a.1.total_cmp(&b.1));
                    let found = tree.nearest(q, accept);
                    assert_eq!(
                        found.map(|f| f.1),
                        scan.map(|s| s.1),
                        "seed {seed} query {k}"
                    );
                    // Within a limit: the same point when it is closer, else none.
                    let limit = 0.3 * (k % 4) as f64;
                    let within = tree.nearest_within(q, limit * limit, accept);
                    let expected = scan.filter(|s| s.1 < limit * limit);
                    assert_eq!(within.map(|f| f.1), expected.map(|s| s.1));
                }
            }
        }
        assert!(PointTree::new(&[]).nearest(DVec3::ZERO, |_| true).is_none());
    }

    /// The largest dot product equals a linear scan's, bit for bit, in every direction.
    #[test]
    fn max_dot_equals_a_linear_scan() {
        for (seed, n) in [(5, 1), (6, 9), (7, 500), (8, 5_000)] {
            let points = cloud(seed, n);
            let tree = PointTree::new(&points);
            for (k, d) in cloud(seed + 50, 200).iter().enumerate() {
                let direction = (*d - DVec3::new(0.5, 0.05, 1.5)) * (k as f64 + 1.0);
                let scan = points
                    .iter()
                    .map(|p| direction.dot(*p))
                    .fold(f64::NEG_INFINITY, f64::max);
                let (i, found) = tree.max_dot(direction).expect("points");
                assert_eq!(found, scan, "seed {seed} direction {k}");
                assert_eq!(direction.dot(points[i]), scan);
            }
        }
        assert!(PointTree::new(&[]).max_dot(DVec3::X).is_none());
    }
}
