//! The linear support search of a small hull: its vertices stored in blocks of
//! [`LANES`] coordinates per axis (structure of arrays), so one block's scores are computed
//! together and the running maximum is kept per lane without a data-dependent branch.
//!
//! PERF: on 8 random vertices the branchy scan over `DVec3`s mispredicted about one
//! comparison in four; with lanes the comparisons become selects.

use crate::math::DVec3;

/// Vertices per block.
const LANES: usize = 4;

/// One block: the coordinates of [`LANES`] vertices, axis by axis.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(32))]
struct Block {
    x: [f64; LANES],
    y: [f64; LANES],
    z: [f64; LANES],
}

/// The vertices of a small hull (centred), for a linear support search.
///
/// # Invariant
/// Lane `l` of block `k` holds vertex `k · LANES + l`; the slots past the
/// last vertex hold copies of vertex 0, which never win a tie against it (ties go to the
/// lowest index).
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct VertexLanes {
    blocks: Vec<Block>,
}

impl VertexLanes {
    /// The lanes of `centred` (at least one point).
    pub(super) fn new(centred: &[DVec3]) -> Self {
        let blocks = centred
            .chunks(LANES)
            .map(|chunk| {
                let at = |l: usize| chunk.get(l).copied().unwrap_or(centred[0]);
                Block {
                    x: std::array::from_fn(|l| at(l).x),
                    y: std::array::from_fn(|l| at(l).y),
                    z: std::array::from_fn(|l| at(l).z),
                }
            })
            .collect();
        Self { blocks }
    }

    /// The index of the vertex with the largest `p · direction`, the lowest index on ties;
    /// 0 for a NaN direction.
    #[inline(always)]
    pub(super) fn argmax(&self, direction: DVec3) -> usize {
        let mut best = [f64::NEG_INFINITY; LANES];
        let mut index = [0_usize; LANES];
        for (k, block) in self.blocks.iter().enumerate() {
            for l in 0..LANES {
                let s =
                    block.x[l] * direction.x + block.y[l] * direction.y + block.z[l] * direction.z;
                let better = s > best[l];
                best[l] = if better { s } else { best[l] };
                index[l] = if better { k * LANES + l } else { index[l] };
            }
        }
        // PERF: bitwise `&`/`|` and value selects, so the reduction compiles without
        // data-dependent branches (with `||` it mispredicted about once per call).
        let pick = |(s0, i0): (f64, usize), (s1, i1): (f64, usize)| {
            let take = (s1 > s0) | ((s1 == s0) & (i1 < i0));
            (if take { s1 } else { s0 }, if take { i1 } else { i0 })
        };
        let low = pick((best[0], index[0]), (best[1], index[1]));
        let high = pick((best[2], index[2]), (best[3], index[3]));
        pick(low, high).1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first-wins linear scan the lanes replace.
    fn first_max(points: &[DVec3], d: DVec3) -> usize {
        let mut best = (points[0].dot(d), 0);
        for (i, p) in points.iter().enumerate().skip(1) {
            if p.dot(d) > best.0 {
                best = (p.dot(d), i);
            }
        }
        best.1
    }

    #[test]
    fn lanes_pick_the_first_maximum_as_a_linear_scan_does() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            // Coarse values, so ties happen.
            f64::from((state % 7) as u32) - 3.0
        };
        let mut ties = 0;
        for n in 1..=13 {
            for _ in 0..400 {
                let points: Vec<DVec3> =
                    (0..n).map(|_| DVec3::new(next(), next(), next())).collect();
                let d = DVec3::new(next(), next(), next());
                let lanes = VertexLanes::new(&points);
                let want = first_max(&points, d);
                assert_eq!(lanes.argmax(d), want, "{points:?} along {d}");
                let top = points[want].dot(d);
                ties += usize::from(points.iter().filter(|p| p.dot(d) == top).count() > 1);
            }
        }
        assert!(ties > 100, "the draws must exercise ties ({ties})");
        let points = [DVec3::X, DVec3::Y];
        assert_eq!(VertexLanes::new(&points).argmax(DVec3::NAN), 0);
    }
}
