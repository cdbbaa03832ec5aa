//! The nearest of many sample points to a query, through a uniform grid.

use super::buckets::Buckets;
use crate::math::DVec3;
use std::ops::ControlFlow;

/// Sample points bucketed in a uniform grid of about [`PER_CELL`] points a cell.
pub(super) struct SampleGrid<'a> {
    points: &'a [DVec3],
    lo: DVec3,
    /// Cell edge, metres.
    cell: f64,
    dims: [usize; 3],
    /// The points of each cell (by [`Self::flat`] index).
    cells: Buckets,
}

/// The cell of a grid (least corner `lo`, cells `cell` metres wide, `dims` along the axes)
/// that holds `p`, or the nearest cell to it.
fn cell_index(lo: DVec3, cell: f64, dims: [usize; 3], p: DVec3) -> [usize; 3] {
    let q = ((p - lo) / cell).to_array();
    [0, 1, 2].map(|k| (q[k].max(0.0) as usize).min(dims[k] - 1))
}

/// The index of cell `c` among the `dims` cells, x fastest.
fn flat_index(dims: [usize; 3], c: [usize; 3]) -> usize {
    (c[2] * dims[1] + c[1]) * dims[0] + c[0]
}

/// Points per cell the grid aims for.
const PER_CELL: f64 = 4.0;
/// Most cells along one axis.
const MAX_DIM: usize = 32;

impl<'a> SampleGrid<'a> {
    /// Buckets `points` (finite).
    pub fn new(points: &'a [DVec3]) -> Self {
        let (lo, hi) = crate::math::bounds_of(points.iter().copied());
        let extent = (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
        let volume = extent.x * extent.y * extent.z;
        let by_count = (volume * PER_CELL / points.len().max(1) as f64).cbrt();
        // Flat clouds have no volume: then the grid is sized by its largest extent.
        let cell = by_count.max(extent.max_element() / MAX_DIM as f64);
        let dims = (extent / cell)
            .to_array()
            .map(|d| (d.ceil() as usize).clamp(1, MAX_DIM));
        let cells: Vec<usize> = points
            .iter()
            .map(|&p| flat_index(dims, cell_index(lo, cell, dims, p)))
            .collect();
        Self {
            points,
            lo,
            cell,
            dims,
            cells: Buckets::new(dims.iter().product(), points.len(), |i| cells[i]..=cells[i]),
        }
    }

    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        cell_index(self.lo, self.cell, self.dims, p)
    }

    fn flat(&self, c: [usize; 3]) -> usize {
        flat_index(self.dims, c)
    }

    /// Whether an accepted point lies within `floor` of `p`, found cheaply: the point
    /// `hint`, then the eight cells nearest to `p` (which hold every point within half a
    /// cell of a `p` inside the grid). `false` says nothing: such a point may lie farther
    /// out. A point found
    /// becomes the `hint` (any value is valid): neighbouring queries are mostly answered by
    /// the same point, in one test.
    pub fn near_within(
        &self,
        p: DVec3,
        floor: f64,
        accept: impl Fn(usize) -> bool,
        hint: &mut usize,
    ) -> bool {
        let floor_squared = floor * floor;
        let within = |i: usize| accept(i) && (self.points[i] - p).length_squared() <= floor_squared;
        if *hint < self.points.len() && within(*hint) {
            return true;
        }
        let found = self.visit_block(p, self.cell_of(p), |i| {
            if within(i) {
                ControlFlow::Break(i)
            } else {
                ControlFlow::Continue(())
            }
        });
        match found {
            ControlFlow::Break(i) => {
                *hint = i;
                true
            }
            ControlFlow::Continue(()) => false,
        }
    }

    /// Distance from `p` to the nearest point whose index `accept`s, metres, when it is
    /// above `floor`; `None` as soon as an accepted point within `floor` is found (the
    /// caller wants the largest nearest distance, which such a query cannot raise), and
    /// infinite when no point is accepted.
    pub fn nearest_above(
        &self,
        p: DVec3,
        floor: f64,
        accept: impl Fn(usize) -> bool,
    ) -> Option<f64> {
        let floor_squared = floor * floor;
        let centre = self.cell_of(p);
        let mut best = f64::INFINITY;
        let rings = self.dims.into_iter().max().unwrap_or(1);
        for ring in 0..rings {
            let found = self.visit_ring(centre, ring, |i| {
                if !accept(i) {
                    return ControlFlow::Continue(());
                }
                let d = (self.points[i] - p).length_squared();
                if d <= floor_squared {
                    return ControlFlow::Break(());
                }
                best = best.min(d);
                ControlFlow::Continue(())
            });
            if found.is_break() {
                return None;
            }
            // Every cell of the next ring is at least `ring` cells away from `p`'s cell.
            if best.sqrt() <= ring as f64 * self.cell {
                break;
            }
        }
        Some(best.sqrt())
    }

    /// Calls `f` with every point of the (up to) eight cells that share the corner of cell
    /// `c` (holding `p`) nearest to `p`, until it breaks.
    fn visit_block<B>(
        &self,
        p: DVec3,
        c: [usize; 3],
        mut f: impl FnMut(usize) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        let q = ((p - self.lo) / self.cell).to_array();
        // Along each axis: this cell, and its neighbour on the side `p` is nearer to.
        let sides = [0, 1, 2].map(|k| {
            let upper = q[k] - c[k] as f64 >= 0.5;
            let other = if upper {
                c[k] + 1
            } else {
                c[k].wrapping_sub(1)
            };
            [Some(c[k]), (other < self.dims[k]).then_some(other)]
        });
        for z in sides[2].into_iter().flatten() {
            for y in sides[1].into_iter().flatten() {
                for x in sides[0].into_iter().flatten() {
                    self.visit_cell([x, y, z], &mut f)?;
                }
            }
        }
        ControlFlow::Continue(())
    }

    /// Calls `f` with every point of cell `c`, until it breaks.
    fn visit_cell<B>(
        &self,
        c: [usize; 3],
        f: &mut impl FnMut(usize) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        self.cells
            .get(self.flat(c))
            .iter()
            .try_for_each(|&i| f(i as usize))
    }

    /// Calls `f` with every point in the cells at Chebyshev distance `ring` from `c`, until
    /// it breaks.
    fn visit_ring<B>(
        &self,
        c: [usize; 3],
        ring: usize,
        mut f: impl FnMut(usize) -> ControlFlow<B>,
    ) -> ControlFlow<B> {
        let range = |k: usize| c[k].saturating_sub(ring)..=(c[k] + ring).min(self.dims[k] - 1);
        let mut visit_cell = |x: usize, y: usize, z: usize| self.visit_cell([x, y, z], &mut f);
        for z in range(2) {
            for y in range(1) {
                let on_shell = z.abs_diff(c[2]) == ring || y.abs_diff(c[1]) == ring;
                if on_shell {
                    for x in range(0) {
                        visit_cell(x, y, z)?;
                    }
                } else {
                    // Inside the shell in y and z: only the two x ends are on the ring.
                    if c[0] >= ring {
                        visit_cell(c[0] - ring, y, z)?;
                    }
                    if ring > 0 && c[0] + ring < self.dims[0] {
                        visit_cell(c[0] + ring, y, z)?;
                    }
                }
            }
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use super::SampleGrid;
    use crate::math::DVec3;
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    /// Both searches against brute force over clouds on a sphere (a surface, as the
    /// decomposition's samples are) and in a slab, with queries on, inside and outside
    /// them, some points refused, floors below and above the true distance.
    #[test]
    fn both_searches_agree_with_brute_force_whatever_the_hint() {
        let mut r = rng(4401);
        let (mut dismissed, mut measured, mut near_found) = (0, 0, 0);
        for cloud in 0..40 {
            let n = r.random_range(1..600);
            let points: Vec<DVec3> = (0..n)
                .map(|_| {
                    let p = point_in_cube(&mut r, 1.0);
                    if cloud % 2 == 0 {
                        p.normalize_or(DVec3::X)
                    } else {
                        p * DVec3::new(1.0, 1.0, 0.02)
                    }
                })
                .collect();
            let grid = SampleGrid::new(&points);
            let refused = r.random_range(0..4);
            let accept = |i: usize| i % 4 != refused || refused == 3;
            let mut hint = r.random_range(0..2 * n);
            for _ in 0..200 {
                let p = point_in_cube(&mut r, 1.6);
                let nearest = (0..n)
                    .filter(|&i| accept(i))
                    .map(|i| (points[i] - p).length())
                    .fold(f64::INFINITY, f64::min);
                let floor = nearest * r.random_range(0.0..2.0);
                // `near_within` may miss a point, but never claims one that is not there.
                if grid.near_within(p, floor, accept, &mut hint) {
                    assert!(
                        nearest <= floor,
                        "{p}: claimed a point within {floor}, nearest {nearest}"
                    );
                    assert!(accept(hint) && (points[hint] - p).length() <= floor);
                    near_found += 1;
                }
                match grid.nearest_above(p, floor, accept) {
                    None => {
                        assert!(
                            nearest <= floor,
                            "{p}: dismissed at floor {floor}, nearest {nearest}"
                        );
                        dismissed += 1;
                    }
                    Some(d) => {
                        assert!(nearest > floor || nearest.is_infinite());
                        assert_eq!(d, nearest, "{p}: nearest {nearest}, found {d}");
                        measured += 1;
                    }
                }
            }
        }
        assert!(
            dismissed > 1000 && measured > 1000 && near_found > 500,
            "{dismissed} {measured} {near_found}"
        );
    }
}
