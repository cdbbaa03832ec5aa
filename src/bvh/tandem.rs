//! Tandem traversal: descend two BVHs together under their relative pose.
//!
//! A pair of nodes is tested with a caller-given test on the two nodes (their volumes, and
//! for a leaf its triangles if the caller wants them); when it passes, the larger
//! node (by [`BvhNode::size`]; the internal one when the other is a leaf) is replaced by its
//! two children. Pairs of leaves that pass go to a visitor, which may stop the traversal.
//! This is the depth-first mid phase every exact mesh–mesh query uses; the budgeted
//! breadth-first variant of the frame pipeline is built on the same descent rule.
//!
//! Two drivers:
//! - [`for_each_leaf_pair`]: every leaf pair whose node pairs all pass a boolean test
//!   (overlap, or "within distance d"), in depth-first order;
//! - [`nearest_leaf_pairs`]: best-first branch and bound for a minimum, expanding the pair
//!   with the smallest lower bound first and stopping when no waiting pair can beat the best
//!   value found so far, or when its clock stops it (then with a lower bound of the
//!   minimum: the bound of the pair it would have expanded next).
//!
//! Both keep their stack or queue in caller-owned storage and allocate only while it grows
//! (the stack to the deepest descent, at most the sum of the two trees' depths plus one).

use super::{Bvh, BvhNode};
use crate::budget::WorkClock;
use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::ops::ControlFlow;

/// Which side of a node pair to descend: A's node when B's is a leaf or A's is at least as
/// large (both internal); B's otherwise.
#[must_use]
#[inline]
pub fn descend_a<B>(a: &BvhNode<B>, b: &BvhNode<B>) -> bool {
    b.is_leaf() || (!a.is_leaf() && a.size >= b.size)
}

/// Visits every pair of leaves `(leaf_a, leaf_b)` (node indices) reached through node pairs
/// that all pass `passes(node_a, node_b)`, depth first, until `visit` returns `Break`.
///
/// Returns `Break` when the visitor stopped the traversal.
pub fn for_each_leaf_pair<B, T, V>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    stack: &mut Vec<[u32; 2]>,
    passes: T,
    mut visit: V,
) -> ControlFlow<()>
where
    T: Fn(&BvhNode<B>, &BvhNode<B>) -> bool,
    V: FnMut(usize, usize) -> ControlFlow<()>,
{
    let (na, nb) = (a.nodes(), b.nodes());
    stack.clear();
    // PERF(examples/fcl_peer, collide_bool): a pair is tested when popped, not when pushed,
    // so a traversal the visitor stops early never tests the siblings it would not have
    // reached; a traversal run to the end tests the same pairs either way.
    stack.push([0, 0]);
    while let Some([ia, ib]) = stack.pop() {
        let (x, y) = (&na[ia as usize], &nb[ib as usize]);
        if !passes(x, y) {
            continue;
        }
        if x.is_leaf() && y.is_leaf() {
            visit(ia as usize, ib as usize)?;
        } else if descend_a(x, y) {
            // Push the second child first so the first is visited first.
            for c in x.children().into_iter().rev() {
                stack.push([c as u32, ib]);
            }
        } else {
            for c in y.children().into_iter().rev() {
                stack.push([ia, c as u32]);
            }
        }
    }
    ControlFlow::Continue(())
}

/// A node pair waiting in the branch-and-bound queue, with its lower bound. Ordered so that
/// a [`BinaryHeap`] pops the *smallest* bound first (ties by node indices, for
/// determinism).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RankedPair {
    /// Lower bound of the value over the pair's leaves (e.g. metres of distance).
    pub bound: f64,
    /// Node of A.
    pub a: u32,
    /// Node of B.
    pub b: u32,
}

impl Eq for RankedPair {}

impl Ord for RankedPair {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .bound
            .total_cmp(&self.bound)
            .then_with(|| (other.a, other.b).cmp(&(self.a, self.b)))
    }
}

impl PartialOrd for RankedPair {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Best-first branch and bound for the smallest leaf-pair value.
///
/// `bound(node_a, node_b, best)` must never exceed the value of any leaf pair beneath the two
/// nodes; once it reaches `best` (the best value so far) it may return any such bound that
/// is `≥ best` (a cheaper one: the pair is pruned either way). `visit(leaf_a, leaf_b)`
/// evaluates a leaf pair and returns its value. `prune(bound, best)` says whether a pair with
/// that lower bound can be skipped given the best value so far (for an exact answer:
/// `bound >= best`); it must be monotone in `bound`. Starts from `best` (a known upper
/// bound, or `f64::INFINITY`) and returns the best value found.
///
/// Pairs are expanded in increasing order of their bound, so the search stops as soon as
/// the smallest waiting bound is pruned, and expands no pair whose bound is above the final
/// answer (a depth-first search can, before its best value has come down).
///
/// `clock` is polled before each pair is expanded ([`WORK_PER_EXPANSION`] units). When it
/// stops the search, the minimum is at least [`Nearest::lower_bound`]: the largest bound
/// the search popped (every pair waiting had a bound at least that one's when it was
/// popped), capped at the best value; it never falls with more work.
pub fn nearest_leaf_pairs<B, L, P, V>(
    a: &Bvh<B>,
    b: &Bvh<B>,
    queue: &mut BinaryHeap<RankedPair>,
    mut best: f64,
    (bound, prune): (L, P),
    clock: &mut WorkClock,
    mut visit: V,
) -> Nearest
where
    L: Fn(&BvhNode<B>, &BvhNode<B>, f64) -> f64,
    P: Fn(f64, f64) -> bool,
    V: FnMut(usize, usize) -> f64,
{
    let (na, nb) = (a.nodes(), b.nodes());
    queue.clear();
    queue.push(RankedPair {
        bound: bound(&na[0], &nb[0], best),
        a: 0,
        b: 0,
    });
    // The largest lower bound seen: every pair waiting (and every leaf pair beneath) has a
    // bound at least the one popped (a heap), so each popped bound, or the best value when
    // smaller, is a lower bound of the minimum. Children need not bound higher than their
    // parent (volumes are fitted, not nested), hence the running maximum.
    let mut lower_bound = f64::NEG_INFINITY;
    while let Some(pair) = queue.pop() {
        if prune(pair.bound, best) {
            break;
        }
        lower_bound = lower_bound.max(pair.bound.min(best));
        if !clock.allows(WORK_PER_EXPANSION) {
            return Nearest { best, lower_bound };
        }
        let (x, y) = (&na[pair.a as usize], &nb[pair.b as usize]);
        if x.is_leaf() && y.is_leaf() {
            best = best.min(visit(pair.a as usize, pair.b as usize));
        } else if descend_a(x, y) {
            for c in x.children() {
                let child = RankedPair {
                    bound: bound(&na[c], y, best),
                    a: c as u32,
                    b: pair.b,
                };
                if !prune(child.bound, best) {
                    queue.push(child);
                }
            }
        } else {
            for c in y.children() {
                let child = RankedPair {
                    bound: bound(x, &nb[c], best),
                    a: pair.a,
                    b: c as u32,
                };
                if !prune(child.bound, best) {
                    queue.push(child);
                }
            }
        }
    }
    Nearest {
        best,
        lower_bound: best,
    }
}

/// Clock units one expansion of [`nearest_leaf_pairs`] counts: two volume bounds or a leaf
/// visit, each a few closed-form pairs' worth (about 0.2–0.5 µs).
pub const WORK_PER_EXPANSION: u64 = 8;

/// What [`nearest_leaf_pairs`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// The smallest leaf-pair value found.
    pub best: f64,
    /// A lower bound of the smallest value over all leaf pairs: `best` when the search
    /// finished (to its `prune` rule), less when its clock stopped it.
    pub lower_bound: f64,
}
