//! Hulls of lower dimension: the convex polygon of a flat cloud (Andrew's monotone chain,
//! A. M. Andrew 1979, "Another efficient algorithm for convex hulls in two dimensions").
//!
//! Points within `eps` of the line through their neighbours are dropped, so collinear and
//! duplicate points never become polygon vertices.

use crate::math::{DVec3, orthonormal_basis};

/// The convex polygon of `pts` (all within `eps` of the plane with unit normal `normal`), as
/// indices into `pts`, counter-clockwise seen from the side `normal` points to.
pub(super) fn polygon(pts: &[DVec3], normal: DVec3, eps: f64) -> Vec<usize> {
    let (u, v) = orthonormal_basis(normal);
    let mut order: Vec<(f64, f64, usize)> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| (p.dot(u), p.dot(v), i))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    // `b` is dropped when it is not more than `eps` to the left of the line `a → c`.
    let keeps_left_turn = |a: (f64, f64, usize), b: (f64, f64, usize), c: (f64, f64, usize)| {
        let cross = (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0);
        let base = ((c.0 - a.0).powi(2) + (c.1 - a.1).powi(2)).sqrt();
        cross > eps * base
    };
    let mut chain: Vec<(f64, f64, usize)> = Vec::with_capacity(order.len() + 1);
    for pass in 0..2 {
        let floor = chain.len();
        let points: Box<dyn Iterator<Item = &(f64, f64, usize)>> = if pass == 0 {
            Box::new(order.iter())
        } else {
            Box::new(order.iter().rev())
        };
        for &p in points {
            while chain.len() >= floor + 2
                && !keeps_left_turn(chain[chain.len() - 2], chain[chain.len() - 1], p)
            {
                chain.pop();
            }
            chain.push(p);
        }
        chain.pop(); // the last point starts the other chain
    }
    let mut ids: Vec<usize> = chain.into_iter().map(|p| p.2).collect();
    // Drop repeats within `eps` (a cloud whose 2D extent is below the tolerance).
    ids.dedup_by(|a, b| (pts[*a] - pts[*b]).length() <= eps);
    while ids.len() > 1 && (pts[ids[0]] - pts[*ids.last().unwrap()]).length() <= eps {
        ids.pop();
    }
    ids
}
