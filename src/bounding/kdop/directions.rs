//! The fixed slab directions of the 14-, 18- and 26-DOP, and the cone decompositions the
//! rotated refit bounds support values with.
//!
//! Directions are integer and unnormalised, so a slab value `d · x` is a signed sum of
//! coordinates and fit and containment round identically. The full table holds the 3 axes,
//! the 4 corner diagonals and the 6 edge diagonals; a k-DOP stores the families it uses in
//! table order: 14-DOP = axes + corners, 18-DOP = axes + edges, 26-DOP = all 13.

use crate::math::DVec3;

/// The 13 directions: axes (0..3), corners (3..7), edges (7..13).
const TABLE: [[f64; 3]; 13] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 1.0],
    [1.0, 1.0, -1.0],
    [1.0, -1.0, 1.0],
    [-1.0, 1.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
];

/// `1 / |d|` for axes, corners and edges.
const INV_NORM: [f64; 3] = [
    1.0,
    0.577_350_269_189_625_8,
    std::f64::consts::FRAC_1_SQRT_2,
];

/// The direction families a k-DOP with `n` slabs uses, and where each family starts in its
/// slab arrays. Panics (at compile time, when evaluated in a const) for any `n` other than
/// 7, 9 or 13.
#[derive(Debug, Clone, Copy)]
pub(super) struct Layout {
    /// First slot of the corner directions, if the DOP has them.
    pub(super) corners: Option<usize>,
    /// First slot of the edge directions, if the DOP has them.
    pub(super) edges: Option<usize>,
}

impl Layout {
    pub(super) const fn of(n: usize) -> Self {
        match n {
            7 => Self {
                corners: Some(3),
                edges: None,
            },
            9 => Self {
                corners: None,
                edges: Some(3),
            },
            13 => Self {
                corners: Some(3),
                edges: Some(7),
            },
            _ => panic!("a k-DOP has 7 (14-DOP), 9 (18-DOP) or 13 (26-DOP) slab directions"),
        }
    }
}

/// The `n` directions of the DOP, in slot order. Panics for an invalid `n` (see [`Layout`]).
pub(super) const fn directions<const N: usize>() -> [DVec3; N] {
    let layout = Layout::of(N);
    let mut out = [DVec3::ZERO; N];
    let mut slot = 0;
    let mut i = 0;
    while i < TABLE.len() {
        let family_used = match i {
            0..3 => true,
            3..7 => layout.corners.is_some(),
            _ => layout.edges.is_some(),
        };
        if family_used {
            out[slot] = DVec3::new(TABLE[i][0], TABLE[i][1], TABLE[i][2]);
            slot += 1;
        }
        i += 1;
    }
    out
}

/// `1 / |d|` for each slot, in slot order.
pub(super) const fn inverse_norms<const N: usize>() -> [f64; N] {
    let dirs = directions::<N>();
    let mut out = [0.0; N];
    let mut k = 0;
    while k < N {
        let d = dirs[k];
        let nonzero = (d.x != 0.0) as usize + (d.y != 0.0) as usize + (d.z != 0.0) as usize;
        out[k] = match nonzero {
            1 => INV_NORM[0],
            3 => INV_NORM[1],
            _ => INV_NORM[2],
        };
        k += 1;
    }
    out
}

/// A slab direction with a sign: the direction `sign · d[slot]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Signed {
    /// Slot in the DOP's arrays.
    pub(super) slot: usize,
    /// Whether the direction is `-d[slot]`.
    pub(super) negated: bool,
}

/// The signs of a vector's components (`true` = negative; zero counts as positive).
pub(super) type Signs = [bool; 3];

/// The signed axis `±e_a`.
#[inline]
pub(super) fn axis(a: usize, signs: Signs) -> Signed {
    Signed {
        slot: a,
        negated: signs[a],
    }
}

/// The signed corner `(±1, ±1, ±1)` with the given signs, for a layout with corners from
/// slot `first`. The table holds the four corners with at most one negative component; the
/// others are their negations.
#[inline]
pub(super) fn corner(first: usize, signs: Signs) -> Signed {
    let negatives = usize::from(signs[0]) + usize::from(signs[1]) + usize::from(signs[2]);
    let negated = negatives >= 2;
    // The canonical representative's negative component (if any), after flipping.
    let canonical = if negated {
        [!signs[0], !signs[1], !signs[2]]
    } else {
        signs
    };
    let index = if canonical[2] {
        1
    } else if canonical[1] {
        2
    } else if canonical[0] {
        3
    } else {
        0
    };
    Signed {
        slot: first + index,
        negated,
    }
}

/// The signed edge `±e_a ± e_b` (`a != b`) with the given signs, for a layout with edges
/// from slot `first`. The table holds each with a positive first (lower-index) component.
#[inline]
pub(super) fn edge(first: usize, a: usize, b: usize, signs: Signs) -> Signed {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    let pair = lo + hi - 1; // (0,1) -> 0, (0,2) -> 1, (1,2) -> 2
    let opposite = signs[lo] != signs[hi];
    Signed {
        slot: first + pair + if opposite { 3 } else { 0 },
        negated: signs[lo],
    }
}

/// Up to three signed directions with non-negative weights whose weighted sum is `u`.
pub(super) type Combination = [(f64, Signed); 3];

/// `u`'s components sorted by magnitude: indices `(a, b, c)` with `|u_a| >= |u_b| >= |u_c|`
/// and the magnitudes `(A, B, C)`.
#[inline]
pub(super) fn sorted(u: DVec3) -> ([usize; 3], [f64; 3]) {
    let m = u.abs().to_array();
    let mut idx = [0, 1, 2];
    if m[idx[0]] < m[idx[1]] {
        idx.swap(0, 1);
    }
    if m[idx[1]] < m[idx[2]] {
        idx.swap(1, 2);
    }
    if m[idx[0]] < m[idx[1]] {
        idx.swap(0, 1);
    }
    (idx, [m[idx[0]], m[idx[1]], m[idx[2]]])
}

/// The octant-cone decomposition of `u` over the DOP's own directions (see the module doc
/// of `kdop`): 26-DOP over axis, edge and corner; 14-DOP over corner and two axes; 18-DOP
/// over an axis and two edges, or three edges.
#[inline]
pub(super) fn cone_combination(layout: Layout, u: DVec3) -> Combination {
    let signs = [u.x < 0.0, u.y < 0.0, u.z < 0.0];
    let ([a, b, c], [big, mid, small]) = sorted(u);
    match (layout.corners, layout.edges) {
        (Some(corners), Some(edges)) => [
            (big - mid, axis(a, signs)),
            (mid - small, edge(edges, a, b, signs)),
            (small, corner(corners, signs)),
        ],
        (Some(corners), None) => [
            (small, corner(corners, signs)),
            (big - small, axis(a, signs)),
            (mid - small, axis(b, signs)),
        ],
        (None, Some(edges)) => {
            if big >= mid + small {
                [
                    (big - mid - small, axis(a, signs)),
                    (mid, edge(edges, a, b, signs)),
                    (small, edge(edges, a, c, signs)),
                ]
            } else {
                [
                    ((big + mid - small) * 0.5, edge(edges, a, b, signs)),
                    ((big + small - mid) * 0.5, edge(edges, a, c, signs)),
                    ((mid + small - big) * 0.5, edge(edges, b, c, signs)),
                ]
            }
        }
        (None, None) => unreachable!("every layout has corners or edges"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support as support;

    fn check_combinations<const N: usize>() {
        let dirs = directions::<N>();
        let layout = Layout::of(N);
        let mut rng = support::rng(N as u64);
        for case in 0..5000 {
            let mut u = support::point_in_cube(&mut rng, 1.0);
            // Ties and zeros: snap some components.
            if case % 5 == 0 {
                u.y = u.x.abs() * u.y.signum();
            }
            if case % 7 == 0 {
                u.z = 0.0;
            }
            let combination = cone_combination(layout, u);
            let mut sum = DVec3::ZERO;
            for (weight, s) in combination {
                assert!(weight >= 0.0, "N {N} case {case}: weight {weight}");
                let d = if s.negated {
                    -dirs[s.slot]
                } else {
                    dirs[s.slot]
                };
                sum += d * weight;
            }
            assert!(sum.abs_diff_eq(u, 1e-14), "N {N} case {case}: {sum} vs {u}");
        }
    }

    #[test]
    fn cone_combinations_are_non_negative_and_sum_to_the_vector() {
        check_combinations::<7>();
        check_combinations::<9>();
        check_combinations::<13>();
    }

    #[test]
    fn every_signed_corner_and_edge_maps_to_its_direction() {
        let dirs = directions::<13>();
        for bits in 0..8u8 {
            let signs = [bits & 1 != 0, bits & 2 != 0, bits & 4 != 0];
            let v = DVec3::new(
                if signs[0] { -1.0 } else { 1.0 },
                if signs[1] { -1.0 } else { 1.0 },
                if signs[2] { -1.0 } else { 1.0 },
            );
            let s = corner(3, signs);
            assert_eq!(
                if s.negated {
                    -dirs[s.slot]
                } else {
                    dirs[s.slot]
                },
                v
            );
            for (a, b) in [(0, 1), (0, 2), (1, 2), (2, 0)] {
                let mut expected = DVec3::ZERO;
                expected[a] = v[a];
                expected[b] = v[b];
                let s = edge(7, a, b, signs);
                assert_eq!(
                    if s.negated {
                        -dirs[s.slot]
                    } else {
                        dirs[s.slot]
                    },
                    expected
                );
            }
        }
    }

    #[test]
    fn layouts_hold_the_documented_direction_sets() {
        assert_eq!(directions::<7>()[6], DVec3::new(-1.0, 1.0, 1.0));
        assert_eq!(directions::<9>()[3], DVec3::new(1.0, 1.0, 0.0));
        assert_eq!(directions::<9>()[8], DVec3::new(0.0, 1.0, -1.0));
        for (d, inv) in directions::<13>().iter().zip(inverse_norms::<13>()) {
            assert!((d.length() * inv - 1.0).abs() < 1e-15);
        }
    }
}
