//! The least-significant-digit radix sort shared by the broad phase's sorts (pairs in
//! `pair_sort.rs`, sweep orders in `key_sort.rs`): one counting pass over every digit of
//! the keys at once, then one stable pass of counted moves per digit, skipping the digits
//! every key shares.
//!
//! The digits are as wide as the records are many, within 8 to 11 bits: a pass costs its
//! `2^digit` counts (cleared, summed, scanned) plus its `n` scattered moves, so a wider
//! digit saves a pass of moves for as long as its table is no longer than the records.
//! Callers give the key's width in bits, so a key of fewer bits takes fewer passes.

/// Narrowest digit, bits.
const MIN_DIGIT_BITS: u32 = 8;
/// Widest digit, bits: a 2,048-count table per pass stays in the first-level cache.
const MAX_DIGIT_BITS: u32 = 11;

/// The other buffer of [`radix_sort`]'s passes and its count tables, kept between sorts.
#[derive(Debug, Clone)]
pub(crate) struct RadixScratch<R> {
    other: Vec<R>,
    counts: Vec<u32>,
}

impl<R> Default for RadixScratch<R> {
    fn default() -> Self {
        Self {
            other: Vec::new(),
            counts: Vec::new(),
        }
    }
}

/// Sorts `records` ascending by `key(record)`, whose value is below `2^key_bits`
/// (`key_bits` at most 64), stably, using `scratch`.
///
/// # Allocation
/// None once `scratch` has grown to the largest `records`.
pub(crate) fn radix_sort<R: Copy>(
    records: &mut Vec<R>,
    scratch: &mut RadixScratch<R>,
    key_bits: u32,
    key: impl Fn(&R) -> u64,
) {
    let Some(&first) = records.first() else {
        return;
    };
    let n = records.len();
    let widest = n.ilog2().clamp(MIN_DIGIT_BITS, MAX_DIGIT_BITS);
    let passes = key_bits.div_ceil(widest).max(1) as usize;
    let digit = key_bits.div_ceil(passes as u32).max(1);
    let (size, mask) = (1usize << digit, (1u64 << digit) - 1);
    let counts = &mut scratch.counts;
    counts.clear();
    counts.resize(passes * size, 0);
    for record in records.iter() {
        let k = key(record);
        for (pass, table) in counts.chunks_exact_mut(size).enumerate() {
            table[((k >> (digit as usize * pass)) & mask) as usize] += 1;
        }
    }
    let other = &mut scratch.other;
    other.clear();
    other.resize(n, first);
    for (pass, table) in counts.chunks_exact_mut(size).enumerate() {
        // Every key has the same digit here: the pass would move nothing.
        if table.contains(&(n as u32)) {
            continue;
        }
        let mut start = 0;
        for count in table.iter_mut() {
            (start, *count) = (start + *count, start);
        }
        let shift = digit as usize * pass;
        for record in records.iter() {
            let d = ((key(record) >> shift) & mask) as usize;
            other[table[d] as usize] = *record;
            table[d] += 1;
        }
        std::mem::swap(records, other);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;

    /// Keys of every width from 1 to 64 bits over lengths either side of each digit width:
    /// the sort equals a stable sort by key, and records with equal keys keep their order.
    #[test]
    fn sorts_stably_like_sort_by_key_for_every_key_width_and_length() {
        let mut rng = rng(47);
        let mut scratch = RadixScratch::default();
        for key_bits in [1u32, 7, 8, 9, 16, 20, 28, 33, 34, 63, 64] {
            for len in [0usize, 1, 2, 255, 256, 300, 3_000, 5_000] {
                let mask = u64::MAX >> (64 - key_bits);
                let mut records: Vec<(u64, u32)> = (0..len as u32)
                    .map(|i| (rng.random::<u64>() & mask, i))
                    .collect();
                let mut expected = records.clone();
                expected.sort_by_key(|r| r.0);
                radix_sort(&mut records, &mut scratch, key_bits, |r| r.0);
                assert_eq!(records, expected, "{len} records of {key_bits}-bit keys");
            }
        }
    }
}
