//! Octree builder: the triangles grouped by the cells of a regular octree over their
//! centroids, the first of the two sphere-tree constructions of Hubbard ("Approximating
//! polyhedra with spheres for time-critical collision detection", ACM TOG 15(3), 1996).
//!
//! The root cell is the cube around the centroids' box. An octree cell's eight children are
//! written as three binary levels: the cell is halved at its middle along x, each half along
//! y, each quarter along z, each side holding the triangles whose centroid falls in it. A
//! halving that leaves one side empty is skipped (the cell shrinks to the occupied half and
//! the next axis is tried), so every node holds triangles. Triangles whose centroids
//! coincide cannot be told apart by any cell: after [`MAX_EMPTY_HALVINGS`] fruitless halvings
//! they are split by index.
//!
//! Hubbard bounds an occupied cell by the sphere of half its diagonal. Here every node's
//! sphere is fitted to its triangles ([`super::fit_topology`]): never larger than the cell's
//! sphere grown to take in the triangles' parts outside the cell.

use super::top_down::{partition, split_recursively};
use super::{BuildPrimitive, Topology};
use crate::math::{DVec3, bounds_of};

/// Halvings in a row that may leave a side empty before a node is split by index.
const MAX_EMPTY_HALVINGS: u32 = 3 * 64;

/// The cell of a node: a box and the axis its next halving cuts.
#[derive(Debug, Clone, Copy)]
struct Cell {
    lo: DVec3,
    hi: DVec3,
    axis: usize,
}

impl Cell {
    /// The cell's two halves along its axis, each to be cut next along the following axis.
    fn halves(&self) -> [Self; 2] {
        let (axis, next) = (self.axis, (self.axis + 1) % 3);
        let middle = 0.5 * (self.lo[axis] + self.hi[axis]);
        let (mut low_hi, mut high_lo) = (self.hi, self.lo);
        low_hi[axis] = middle;
        high_lo[axis] = middle;
        [
            Self {
                lo: self.lo,
                hi: low_hi,
                axis: next,
            },
            Self {
                lo: high_lo,
                hi: self.hi,
                axis: next,
            },
        ]
    }
}

/// Builds the topology by octree subdivision of the centroids (see the [module docs](self)).
pub(super) fn build(primitives: &[BuildPrimitive], leaf_size: u32) -> Topology {
    let (lo, hi) = bounds_of(primitives.iter().map(|p| p.centroid));
    let side = (hi - lo).max_element();
    let root = Cell {
        lo,
        hi: lo + DVec3::splat(side),
        axis: 0,
    };
    split_recursively(primitives.len(), leaf_size, root, |order, cell| {
        let mut cell = *cell;
        for _ in 0..MAX_EMPTY_HALVINGS {
            let [low, high] = cell.halves();
            let axis = cell.axis;
            let below = partition(order, |i| {
                primitives[i as usize].centroid[axis] < low.hi[axis]
            });
            match below {
                0 => cell = high,
                n if n == order.len() => cell = low,
                n => return (n, [low, high]),
            }
        }
        (order.len() / 2, [cell, cell])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Triangle;

    /// Tiny triangles centred at `centres`.
    fn primitives(centres: &[DVec3]) -> Vec<BuildPrimitive> {
        centres
            .iter()
            .map(|&c| {
                BuildPrimitive::of(&Triangle::new(c, c + DVec3::X * 1e-3, c + DVec3::Y * 1e-3))
            })
            .collect()
    }

    /// The sorted triangle indices of node `i`.
    fn members(topology: &Topology, i: usize) -> Vec<u32> {
        let [start, end] = topology.nodes[i].span;
        let mut m = topology.order[start as usize..end as usize].to_vec();
        m.sort_unstable();
        m
    }

    /// Cells, not medians: the root's cube (side 100 m) is cut at its middle, so the four
    /// centroids near the origin go one way and the far one the other (a median would cut
    /// 2 | 3); the near four are cut where their shrunken cell's middle falls, 1.5625 m.
    #[test]
    fn splits_fall_at_cell_middles_not_medians() {
        let centres = [0.0, 1.0, 2.0, 3.0, 100.0].map(|x| DVec3::new(x, 0.0, 0.0));
        let topology = build(&primitives(&centres), 1);
        let root = topology.nodes[0];
        let [near, far] = [root.first as usize, root.first as usize + 1];
        assert_eq!(members(&topology, near), [0, 1, 2, 3]);
        assert_eq!(members(&topology, far), [4]);
        let first = topology.nodes[near].first as usize;
        assert_eq!(members(&topology, first), [0, 1]);
        assert_eq!(members(&topology, first + 1), [2, 3]);
    }

    /// Coincident centroids cannot be told apart by any cell: they are split by index, and
    /// every leaf holds one triangle.
    #[test]
    fn coincident_centroids_end_in_single_leaves() {
        let topology = build(&primitives(&[DVec3::splat(0.5); 5]), 1);
        let leaves = topology.nodes.iter().filter(|n| n.count > 0).count();
        assert_eq!(leaves, 5);
        assert!(topology.nodes.iter().all(|n| n.count <= 1));
    }
}
