//! Sorting a frame's candidate pairs into `(a, b)` order: a least-significant-digit radix
//! sort on the 64-bit key `a · 2³² + b`, one pass per byte, skipping the bytes every key
//! shares (the high bytes of both ids, in a scene of fewer than 2²⁴ bodies); on the 32-bit
//! key `a · 2¹⁶ + b` when every id is below 2¹⁶, which halves the counting pass
//! (`examples/broad_bench`, 1,000 uniform bodies all moving, about 490 pairs a frame,
//! alternating runs: 42.2–42.3 → 41.5–41.9 µs a frame; 10,000, within the noise).
//!
//! A comparison sort of `k` pairs makes about `k log₂ k` data-dependent compares; with
//! ids below 2¹⁶ (four bytes differ at most) this makes four passes of `k` counted moves,
//! plus one pass counting all eight bytes at once. Measured in [`SortAndSweep`] (10,000
//! bodies all moving, about 5,000 pairs a frame, three alternating runs, together with
//! its kept grid shape against neither: 1,500–1,637 → 1,373–1,395 µs a frame uniform,
//! 1,323–1,457 → 1,203–1,482 clustered; the kept shape alone had given 1,490–1,530 and
//! 1,271–1,398 in the same runs).
//!
//! [`SortAndSweep`]: super::SortAndSweep

use super::CandidatePair;
use super::radix::radix_sort;

/// Fewest pairs the radix sort is used for; fewer go to `sort_unstable`, whose compares
/// cost less than the radix passes' 256-entry tables then.
const RADIX_FROM: usize = 256;

/// The key the pairs sort by: `a` in the high half, `b` in the low.
#[inline]
fn key(pair: &CandidatePair) -> u64 {
    (u64::from(pair.a) << 32) | u64::from(pair.b)
}

/// Sorts `pairs` by `(a, b)`, using `scratch` (its contents are overwritten) as the other
/// buffer of the passes.
///
/// # Allocation
/// None once `scratch` has grown to the largest `pairs`.
pub(crate) fn sort_pairs(pairs: &mut Vec<CandidatePair>, scratch: &mut Vec<CandidatePair>) {
    if pairs.len() < RADIX_FROM {
        pairs.sort_unstable();
        return;
    }
    // Every id below 2¹⁶: a 32-bit key, half the counting.
    if pairs.iter().fold(0, |ids, p| ids | p.a | p.b) < 1 << 16 {
        radix_sort::<_, 4>(pairs, scratch, |p| (u64::from(p.a) << 16) | u64::from(p.b));
    } else {
        radix_sort::<_, 8>(pairs, scratch, key);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;

    #[test]
    fn sorts_like_sort_unstable_for_every_id_range_and_length() {
        let mut rng = rng(41);
        let mut scratch = Vec::new();
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
