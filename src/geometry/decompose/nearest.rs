//! The nearest of many sample points to a query, through a uniform grid.

use crate::math::DVec3;

/// Sample points bucketed in a uniform grid of about [`PER_CELL`] points a cell.
pub(super) struct SampleGrid<'a> {
    points: &'a [DVec3],
    lo: DVec3,
    /// Cell edge, metres.
    cell: f64,
    dims: [usize; 3],
    /// Cell `c` holds `items[starts[c] .. starts[c + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
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
        let mut grid = Self {
            points,
            lo,
            cell,
            dims,
            starts: vec![0; dims[0] * dims[1] * dims[2] + 1],
            items: vec![0; points.len()],
        };
        let cells: Vec<usize> = points.iter().map(|&p| grid.flat(grid.cell_of(p))).collect();
        for &c in &cells {
            grid.starts[c + 1] += 1;
        }
        for c in 1..grid.starts.len() {
            grid.starts[c] += grid.starts[c - 1];
        }
        let mut fill = grid.starts.clone();
        for (i, &c) in cells.iter().enumerate() {
            grid.items[fill[c] as usize] = i as u32;
            fill[c] += 1;
        }
        grid
    }

    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let q = ((p - self.lo) / self.cell).to_array();
        [0, 1, 2].map(|k| (q[k].max(0.0) as usize).min(self.dims[k] - 1))
    }

    fn flat(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
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
        let centre = self.cell_of(p);
        let floor_squared = floor * floor;
        let mut best = f64::INFINITY;
        let rings = self.dims.into_iter().max().unwrap_or(1);
        for ring in 0..rings {
            self.visit_ring(centre, ring, |i| {
                if accept(i) {
                    best = best.min((self.points[i] - p).length_squared());
                }
            });
            if best <= floor_squared {
                return None;
            }
            // Every cell of the next ring is at least `ring` cells away from `p`'s cell.
            if best.sqrt() <= ring as f64 * self.cell {
                break;
            }
        }
        Some(best.sqrt())
    }

    /// Calls `f` with every point in the cells at Chebyshev distance `ring` from `c`.
    fn visit_ring(&self, c: [usize; 3], ring: usize, mut f: impl FnMut(usize)) {
        let range = |k: usize| c[k].saturating_sub(ring)..=(c[k] + ring).min(self.dims[k] - 1);
        let mut visit_cell = |x: usize, y: usize, z: usize| {
            let cell = self.flat([x, y, z]);
            for &i in &self.items[self.starts[cell] as usize..self.starts[cell + 1] as usize] {
                f(i as usize);
            }
        };
        for z in range(2) {
            for y in range(1) {
                let on_shell = z.abs_diff(c[2]) == ring || y.abs_diff(c[1]) == ring;
                if on_shell {
                    for x in range(0) {
                        visit_cell(x, y, z);
                    }
                } else {
                    // Inside the shell in y and z: only the two x ends are on the ring.
                    if c[0] >= ring {
                        visit_cell(c[0] - ring, y, z);
                    }
                    if ring > 0 && c[0] + ring < self.dims[0] {
                        visit_cell(c[0] + ring, y, z);
                    }
                }
            }
        }
    }
}
