//! Exact separating-axis oracle for two triangles with integer coordinates: whether they
//! meet (decided in `i128`, no rounding) and their Euclidean distance (to a few ulps).
//!
//! The axis set is the complete one of `tests/triangle_triangle_oracle.rs` (whose oracle is
//! private to that file): both normals, every edge × edge, every vertex difference `v − w`
//! and `e × ((v − w) × e)` for every edge `e`. The closest pair `p, q` of two disjoint
//! triangles lies in the relative interiors of two faces (vertex, edge or triangle) and
//! `p − q` is orthogonal to both, so it is parallel to one of these axes (degenerate
//! triangles included). Hence the distance is exactly the largest separation over the set,
//! `max (gap along axis) / |axis|`, which is what [`exact_sat`] returns: the integer gap is
//! exact, only the division and the axis length round (relative error ≲ 4 ε).
//!
//! Magnitudes: with coordinates `|x| ≤ 2^24` the largest product is below `2^105`, well
//! inside `i128`; [`exact_sat`] debug-asserts that bound.
#![allow(dead_code)] // each including test file uses a different part of it

/// An integer point.
pub type I3 = [i128; 3];

/// Coordinates above this (absolute) may overflow the `i128` products.
pub const MAX_COORDINATE: i128 = 1 << 24;

/// `a − b`.
pub fn sub(a: I3, b: I3) -> I3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a × b`.
pub fn cross(a: I3, b: I3) -> I3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `a · b`.
pub fn dot(a: I3, b: I3) -> i128 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The exact answer for two closed triangles.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SatAnswer {
    /// Whether they share a point (touching counts).
    pub intersects: bool,
    /// Their distance, metres (0 when they meet), to a few ulps.
    pub distance: f64,
}

/// Exact SAT on integer triangles (module docs).
#[must_use]
pub fn exact_sat(a: &[I3; 3], b: &[I3; 3]) -> SatAnswer {
    debug_assert!(
        a.iter()
            .chain(b)
            .all(|p| p.iter().all(|x| x.abs() <= MAX_COORDINATE))
    );
    let edges = |t: &[I3; 3]| [sub(t[1], t[0]), sub(t[2], t[1]), sub(t[0], t[2])];
    let (ea, eb) = (edges(a), edges(b));
    let mut best_gap = 0i128;
    let mut distance = 0.0f64;
    let mut try_axis = |axis: I3| {
        if axis == [0; 3] {
            return;
        }
        let pa = a.map(|p| dot(axis, p));
        let pb = b.map(|p| dot(axis, p));
        let (amin, amax) = (*pa.iter().min().unwrap(), *pa.iter().max().unwrap());
        let (bmin, bmax) = (*pb.iter().min().unwrap(), *pb.iter().max().unwrap());
        let gap = (bmin - amax).max(amin - bmax);
        if gap > 0 {
            best_gap = best_gap.max(gap);
            let len = axis
                .iter()
                .map(|&x| (x as f64) * (x as f64))
                .sum::<f64>()
                .sqrt();
            distance = distance.max(gap as f64 / len);
        }
    };
    try_axis(cross(ea[0], ea[1]));
    try_axis(cross(eb[0], eb[1]));
    for e in ea {
        for f in eb {
            try_axis(cross(e, f));
        }
    }
    for v in a {
        for w in b {
            let d = sub(*v, *w);
            try_axis(d);
            for e in ea.iter().chain(eb.iter()) {
                try_axis(cross(*e, cross(d, *e)));
            }
        }
    }
    SatAnswer {
        intersects: best_gap == 0,
        distance,
    }
}
