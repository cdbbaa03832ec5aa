//! Sorting a frame's candidate pairs into `(a, b)` order: a least-significant-digit radix
//! sort (`radix.rs`) on the key `a · 2^w + b`, `w` the width of the largest id, so a scene
//! of 1,000 bodies sorts 20-bit keys and one of 100,000 34-bit keys, in as few passes as
//! the digit width allows.
//!
//! A comparison sort of `k` pairs makes about `k log₂ k` data-dependent compares; the
//! radix sort a few passes of `k` counted moves, plus one pass counting every digit at
//! once. `examples/broad_bench` (sort and sweep) measures it.

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
