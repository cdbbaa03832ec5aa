//! The tree of a compound's part boxes: which part pairs may be closer than a cutoff.
//!
//! A binary tree of OBBs, one part per leaf, split top-down at the median part centre
//! along the axis the centres spread most on. Compounds hold tens of parts, so the tree is
//! small; its job is to skip the part pairs that are far apart, the bulk of them once two
//! compounds are near each other at one place only.

use crate::bounding::{BoundingVolume, Obb};
use crate::math::{DVec3, Isometry, bounds_of};

/// One node of a [`PartTree`]: its box and either two children or one part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartNode {
    /// Contains every point of the parts below, the compound's frame.
    pub bv: Obb,
    /// Leaf: the part's index. Internal: the first child's index (the second follows it).
    first: u32,
    /// Whether the node is a leaf.
    leaf: bool,
}

impl PartNode {
    /// The part of a leaf, `None` for an internal node.
    #[must_use]
    pub fn part(&self) -> Option<usize> {
        self.leaf.then_some(self.first as usize)
    }

    /// The two children of an internal node, `None` for a leaf.
    #[must_use]
    pub fn children(&self) -> Option<[usize; 2]> {
        (!self.leaf).then_some([self.first as usize, self.first as usize + 1])
    }
}

/// A part pair (or a part against a whole other shape, `b` 0) that may be within the
/// cutoff, with the lower bound of its distance from the boxes, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Lower bound of the pair's distance (0 where the boxes overlap).
    pub lower: f64,
    /// Part of the first compound.
    pub a: u32,
    /// Part of the second compound (0 against a single shape).
    pub b: u32,
}

/// The tree of a compound's part boxes.
///
/// # Invariants
/// `nodes[0]` is the root; an internal node's children are adjacent and after it; every
/// part is the leaf of exactly one node; a node's box contains every point its parts were
/// fitted from (their hulls' vertices, or their local boxes' corners).
#[derive(Debug, Clone)]
pub struct PartTree {
    nodes: Vec<PartNode>,
}

impl PartTree {
    /// The tree over parts given by points whose hull contains each (non-empty lists).
    pub(super) fn new(parts: &[Vec<DVec3>]) -> Self {
        let centres: Vec<DVec3> = parts
            .iter()
            .map(|p| p.iter().sum::<DVec3>() / p.len() as f64)
            .collect();
        let mut order: Vec<u32> = (0..parts.len() as u32).collect();
        let mut tree = Self { nodes: Vec::new() };
        tree.nodes.push(tree.fit(parts, &order));
        tree.split(0, &mut order, parts, &centres);
        tree
    }

    /// The nodes, root first.
    #[must_use]
    pub fn nodes(&self) -> &[PartNode] {
        &self.nodes
    }

    /// A node over `parts[ids]`: a leaf for one part.
    fn fit(&self, parts: &[Vec<DVec3>], ids: &[u32]) -> PartNode {
        let points: Vec<DVec3> = ids
            .iter()
            .flat_map(|&i| parts[i as usize].iter().copied())
            .collect();
        PartNode {
            bv: Obb::fit_points(&points),
            first: ids[0],
            leaf: ids.len() == 1,
        }
    }

    /// Splits node `index`, over `ids`, into two children and recurses.
    fn split(&mut self, index: usize, ids: &mut [u32], parts: &[Vec<DVec3>], centres: &[DVec3]) {
        if ids.len() < 2 {
            return;
        }
        let (lo, hi) = bounds_of(ids.iter().map(|&i| centres[i as usize]));
        let axis = (hi - lo).max_position();
        ids.sort_unstable_by(|&i, &j| {
            centres[i as usize][axis].total_cmp(&centres[j as usize][axis])
        });
        let (left, right) = ids.split_at_mut(ids.len() / 2);
        let first = self.nodes.len();
        self.nodes[index].first = first as u32;
        let (l, r) = (self.fit(parts, left), self.fit(parts, right));
        self.nodes.extend([l, r]);
        self.split(first, left, parts, centres);
        self.split(first + 1, right, parts, centres);
    }

    /// Into `out` (emptied first), every part whose box may be within `cutoff` metres of
    /// `other` (its own frame, placed by `pose_ab`), with that bound; returns the smallest
    /// bound of what was left out (`+∞` when nothing was).
    pub fn candidates_against(
        &self,
        other: &Obb,
        pose_ab: &Isometry,
        cutoff: f64,
        stack: &mut Vec<u32>,
        out: &mut Vec<Candidate>,
    ) -> f64 {
        out.clear();
        stack.clear();
        stack.push(0);
        let mut left_out = f64::INFINITY;
        while let Some(i) = stack.pop() {
            let node = &self.nodes[i as usize];
            let lower = node.bv.distance_lower_bound_within(other, pose_ab, cutoff);
            if lower > cutoff {
                left_out = left_out.min(lower);
                continue;
            }
            match node.children() {
                Some([l, r]) => stack.extend([l as u32, r as u32]),
                None => out.push(Candidate {
                    lower,
                    a: node.first,
                    b: 0,
                }),
            }
        }
        left_out
    }

    /// Into `out` (emptied first), every pair of a part of this tree and one of `other`
    /// (placed by `pose_ab`) whose boxes may be within `cutoff` metres, with that bound;
    /// returns the smallest bound of what was left out (`+∞` when nothing was). Descends the
    /// larger box of a pair first, both trees' leaves last.
    pub fn candidate_pairs(
        &self,
        other: &Self,
        pose_ab: &Isometry,
        cutoff: f64,
        stack: &mut Vec<(u32, u32)>,
        out: &mut Vec<Candidate>,
    ) -> f64 {
        out.clear();
        stack.clear();
        stack.push((0, 0));
        let mut left_out = f64::INFINITY;
        while let Some((i, j)) = stack.pop() {
            let (a, b) = (&self.nodes[i as usize], &other.nodes[j as usize]);
            let lower = a.bv.distance_lower_bound_within(&b.bv, pose_ab, cutoff);
            if lower > cutoff {
                left_out = left_out.min(lower);
                continue;
            }
            match (a.children(), b.children()) {
                (None, None) => out.push(Candidate {
                    lower,
                    a: a.first,
                    b: b.first,
                }),
                (Some([l, r]), None) => stack.extend([(l as u32, j), (r as u32, j)]),
                (None, Some([l, r])) => stack.extend([(i, l as u32), (i, r as u32)]),
                (Some([al, ar]), Some([bl, br])) => {
                    if a.bv.size() >= b.bv.size() {
                        stack.extend([(al as u32, j), (ar as u32, j)]);
                    } else {
                        stack.extend([(i, bl as u32), (i, br as u32)]);
                    }
                }
            }
        }
        left_out
    }
}
