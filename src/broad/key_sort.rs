//! Sorting items by an `f32` key, for orders kept from frame to frame: insertion sort while
//! the items moved little since the last sort, a radix sort on the keys when they moved
//! more (the sort and sweep's order of its proxies along the sweep axis).
//!
//! Insertion sort is linear in the items plus their shifts, and shifts grow with the
//! density of the boxes along the axis as well as with their speed: at 10,000 uniform
//! bodies all moving (`examples/broad_bench`) about 2 a proxy, at 100,000 about 8 or more,
//! where each shift moves a whole item. The radix sort costs the same whatever moved:
//! three or four counted passes over 8-byte `(key, position)` records, then one gather of
//! the items in the new order, which for a kept order is close to the old one
//! (near-sequential reads).
//!
//! The switch between them is a count of shifts per item: below it insertion is cheaper,
//! above it the radix sort (`examples/broad_bench`, sort and sweep, measures both sides).

use super::radix::{RadixScratch, radix_sort};

/// A key's bits mapped to a `u32` whose unsigned order is [`f32::total_cmp`]'s.
#[inline]
fn ordered_bits(key: f32) -> u32 {
    let bits = key.to_bits();
    if bits >> 31 == 1 {
        !bits
    } else {
        bits | 1 << 31
    }
}

/// Shifts an item beyond which insertion gives way to the radix sort, for this sort and
/// the next ones; the next sort tries insertion again once a radix sort finds that
/// insertion would have taken fewer (see [`KeySort::sort`]).
const RADIX_ABOVE_SHIFTS_PER_ITEM: f64 = 0.75;

/// Scratch of [`KeySort::sort`], and the method its last sort settled on.
#[derive(Debug, Clone)]
pub(crate) struct KeySort<T> {
    /// `(ordered key bits, position)` records and the other buffer of their passes.
    records: Vec<(u32, u32)>,
    other: RadixScratch<(u32, u32)>,
    /// The items in their new order, before the swap.
    gathered: Vec<T>,
    /// Whether the next sort goes straight to the radix sort.
    radix: bool,
}

impl<T> Default for KeySort<T> {
    fn default() -> Self {
        Self {
            records: Vec::new(),
            other: RadixScratch::default(),
            gathered: Vec::new(),
            radix: false,
        }
    }
}

impl<T: Copy> KeySort<T> {
    /// Sorts `items` ascending by `key` (ties in any order). By insertion while the items
    /// keep close to their last order: a sort that would take more than
    /// [`RADIX_ABOVE_SHIFTS_PER_ITEM`] shifts an item is finished by the radix sort, and so
    /// are the next ones until one finds the items displaced by fewer places than that in
    /// all.
    ///
    /// # Allocation
    /// None once the scratch has grown to the largest `items`.
    pub(crate) fn sort(&mut self, items: &mut Vec<T>, key: impl Fn(&T) -> f32 + Copy) {
        let n = items.len() as f64;
        if !self.radix && insertion_sort(items, key, (RADIX_ABOVE_SHIFTS_PER_ITEM * n) as usize) {
            return;
        }
        let displacement = self.radix_sort(items, key);
        // Insertion's shifts (the inversions) are at most the total displacement
        // (Diaconis and Graham 1977), so insertion would have stayed within the cap.
        self.radix = displacement as f64 >= RADIX_ABOVE_SHIFTS_PER_ITEM * n;
    }

    /// The radix sort; returns the items' total displacement, the sum over the items of
    /// how many places each moved.
    fn radix_sort(&mut self, items: &mut Vec<T>, key: impl Fn(&T) -> f32) -> usize {
        self.records.clear();
        self.records.extend(
            items
                .iter()
                .enumerate()
                .map(|(i, item)| (ordered_bits(key(item)), i as u32)),
        );
        radix_sort(&mut self.records, &mut self.other, 32, |r| u64::from(r.0));
        self.gathered.clear();
        self.gathered
            .extend(self.records.iter().map(|&(_, i)| items[i as usize]));
        std::mem::swap(items, &mut self.gathered);
        self.records
            .iter()
            .enumerate()
            .map(|(to, &(_, from))| to.abs_diff(from as usize))
            .sum()
    }
}

/// Sorts by insertion, giving up (`false`, `items` then partly sorted) once more than
/// `max_shifts` items have been shifted.
fn insertion_sort<T: Copy>(items: &mut [T], key: impl Fn(&T) -> f32, max_shifts: usize) -> bool {
    let mut shifts = 0;
    for i in 1..items.len() {
        let item = items[i];
        let k = key(&item);
        let mut j = i;
        while j > 0 && key(&items[j - 1]).total_cmp(&k).is_gt() {
            items[j] = items[j - 1];
            j -= 1;
        }
        items[j] = item;
        shifts += i - j;
        if shifts > max_shifts {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;

    /// Frames of nudged keys (insertion), shuffled keys (radix) and the way back: every sort
    /// equals `sort_by(total_cmp)` on the keys, and both methods run.
    #[test]
    fn sorts_like_total_cmp_through_nudges_shuffles_and_back() {
        let mut rng = rng(43);
        let mut sort = KeySort::default();
        let (mut insertion_sorts, mut radix_sorts) = (0, 0);
        for len in [0usize, 1, 2, 37, 1_000, 5_000] {
            // (key, id): the id tells items with equal keys apart.
            let mut items: Vec<(f32, u32)> = (0..len as u32)
                .map(|i| (rng.random_range(-1e3f32..1e3), i))
                .collect();
            for frame in 0..12 {
                // A shuffle, a frame with ends of the range and signed zeros, then nudges.
                let (shuffle, special) = (frame % 6 == 0, frame % 6 == 1);
                for item in &mut items {
                    item.0 = match rng.random_range(0..400) {
                        _ if shuffle => rng.random_range(-1e3f32..1e3),
                        0 if special => 0.0,
                        1 if special => -0.0,
                        2 if special => f32::MAX,
                        3 if special => -f32::MIN_POSITIVE,
                        _ => item.0 + rng.random_range(-0.01f32..0.01),
                    };
                }
                let mut expected = items.clone();
                expected.sort_by(|a, b| a.0.total_cmp(&b.0));
                let radix_before = sort.radix;
                sort.sort(&mut items, |item| item.0);
                let keys = |v: &[(f32, u32)]| v.iter().map(|i| i.0.to_bits()).collect::<Vec<_>>();
                assert_eq!(keys(&items), keys(&expected), "{len} items, frame {frame}");
                let mut ids: Vec<u32> = items.iter().map(|i| i.1).collect();
                ids.sort_unstable();
                assert!(
                    ids.iter().copied().eq(0..len as u32),
                    "items lost or doubled"
                );
                if len > 100 {
                    if radix_before || sort.radix {
                        radix_sorts += 1;
                    } else {
                        insertion_sorts += 1;
                    }
                }
            }
        }
        assert!(
            insertion_sorts > 5 && radix_sorts > 5,
            "insertion sorts {insertion_sorts}, radix sorts {radix_sorts}"
        );
    }

    #[test]
    fn ordered_bits_follow_total_cmp() {
        let keys = [
            f32::NEG_INFINITY,
            -f32::MAX,
            -1.0,
            -f32::MIN_POSITIVE,
            -0.0,
            0.0,
            1e-45,
            1.0,
            f32::MAX,
            f32::INFINITY,
        ];
        for w in keys.windows(2) {
            assert!(ordered_bits(w[0]) < ordered_bits(w[1]), "{} {}", w[0], w[1]);
        }
    }
}
