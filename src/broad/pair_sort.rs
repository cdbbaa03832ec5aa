//! Sorting a frame's candidate pairs into `(a, b)` order: a least-significant-digit radix
//! sort (`radix.rs`) on the key `a · 2^w + b`, `w` the width of the largest id, so a scene
//! of 1,000 bodies sorts 20-bit keys and one of 100,000 34-bit keys, in as few passes as
//! the digit width allows. Measured (`examples/broad_bench`, sort and sweep, three
//! alternating runs, means a frame) against a 32-bit key `a · 2¹⁶ + b` (64-bit past 2¹⁶
//! ids) sorted one byte a pass: 10,000 uniform bodies all moving (about 5,000 pairs a
//! frame: three passes of 10 bits, not four of 8) 459–463 → 450–454 µs; 1,000 (about 490
//! pairs) within the noise, 41.6–42.3 against 41.8–42.4. The 32-bit key had itself
//! measured 42.2–42.3 → 41.5–41.9 µs against the 64-bit one at 1,000 bodies.
//!
//! A comparison sort of `k` pairs makes about `k log₂ k` data-dependent compares; the
//! radix sort a few passes of `k` counted moves, plus one pass counting every digit at
//! once. Measured (one pass a byte then) in [`SortAndSweep`] (10,000
//! bodies all moving, about 5,000 pairs a frame, three alternating runs, together with
//! its kept grid shape against neither: 1,500–1,637 → 1,373–1,395 µs a frame uniform,
//! 1,323–1,457 → 1,203–1,482 clustered; the kept shape alone had given 1,490–1,530 and
//! 1,271–1,398 in the same runs).
//!
//! [`SortAndSweep`]: super::SortAndSweep

use super::CandidatePair;
use super::radix::{RadixScratch, radix_sort};

/// Fewest pairs the radix sort is used for; fewer go to `sort_unstable`, whose compares
/// cost less than the radix passes' count tables then.
const RADIX_FROM: usize = 256;

/// Sorts `pairs` by `(a, b)`, using `scratch`.
///
/// # Allocation
/// None once `scratch` has grown to the largest `pairs`.
pub(crate) fn sort_pairs(
    pairs: &mut Vec<CandidatePair>,
    scratch: &mut RadixScratch<CandidatePair>,
) {
    if pairs.len() < RADIX_FROM {
        pairs.sort_unstable();
        return;
    }
    // The key `a · 2^bits + b`, with `bits` the width of the largest id.
    let ids = pairs.iter().fold(0, |ids, p| ids | p.a | p.b);
    let bits = u32::BITS - ids.leading_zeros();
    radix_sort(pairs, scratch, 2 * bits, |p| {
        (u64::from(p.a) << bits) | u64::from(p.b)
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;

    #[test]
    fn sorts_like_sort_unstable_for_every_id_range_and_length() {
        let mut rng = rng(41);
        let mut scratch = RadixScratch::default();
        let mut lengths_seen = 0;
        for &(len, bits) in &[
            (0, 8),
            (1, 8),
            (255, 16),
            (256, 8),
            (300, 1),
            (5_000, 14),
            (5_000, 32),
            (20_000, 24),
        ] {
            for _ in 0..3 {
                let ids = |rng: &mut crate::test_support::TestRng| {
                    (rng.random::<u64>() & ((1u64 << bits) - 1)) as u32
                };
                let mut pairs: Vec<CandidatePair> = (0..len)
                    .map(|_| CandidatePair {
                        a: ids(&mut rng),
                        b: ids(&mut rng),
                    })
                    .collect();
                let mut expected = pairs.clone();
                expected.sort_unstable();
                sort_pairs(&mut pairs, &mut scratch);
                assert_eq!(pairs, expected, "{len} pairs of {bits}-bit ids");
                lengths_seen += usize::from(len >= RADIX_FROM);
            }
        }
        assert!(lengths_seen >= 12, "the radix path ran");
    }
}
