//! The all-pairs broad phase: `n²/2` box tests. Exact by construction, used as the oracle
//! of the faster broad phases and for small scenes.

use super::{CandidatePair, Proxy};
use crate::bounding::BoundingVolume;

/// Every pair of `proxies` whose grown boxes overlap (touching counts) and that may pair,
/// once each with `a < b`, in increasing `(a, b)` order; written to `out` (cleared first).
///
/// # Allocation
/// None once `out` has grown to the number of pairs.
pub fn pairs_brute_force(proxies: &[Proxy], out: &mut Vec<CandidatePair>) {
    out.clear();
    for (i, p) in proxies.iter().enumerate() {
        for q in &proxies[i + 1..] {
            if p.body != q.body && p.may_pair(q) && p.bounds.intersects(&q.bounds) {
                let (a, b) = if p.body < q.body {
                    (p.body, q.body)
                } else {
                    (q.body, p.body)
                };
                out.push(CandidatePair { a, b });
            }
        }
    }
    out.sort_unstable();
}

#[cfg(test)]
#[path = "brute_force_tests.rs"]
mod tests;
