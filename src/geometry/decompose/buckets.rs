//! Item indices filed by bucket in one flat array (a counting sort): the sample grid's
//! cells and a cap outline's bands both read a bucket's items as one slice.

use std::ops::RangeInclusive;

/// Bucket `b` holds `items[starts[b] .. starts[b + 1]]`, in increasing item order.
#[derive(Debug, Clone)]
pub(super) struct Buckets {
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl Buckets {
    /// `count` buckets holding items `0..items`, item `i` in every bucket of
    /// `buckets_of(i)` (each below `count`). Counts, prefix sums, then a fill.
    pub fn new(
        count: usize,
        items: usize,
        buckets_of: impl Fn(usize) -> RangeInclusive<usize>,
    ) -> Self {
        let mut starts = vec![0u32; count + 1];
        for i in 0..items {
            for b in buckets_of(i) {
                starts[b + 1] += 1;
            }
        }
        for b in 0..count {
            starts[b + 1] += starts[b];
        }
        let mut next = starts.clone();
        let mut filed = vec![0u32; starts[count] as usize];
        for i in 0..items {
            for b in buckets_of(i) {
                filed[next[b] as usize] = i as u32;
                next[b] += 1;
            }
        }
        Self {
            starts,
            items: filed,
        }
    }

    /// The items of bucket `b`.
    pub fn get(&self, b: usize) -> &[u32] {
        &self.items[self.starts[b] as usize..self.starts[b + 1] as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::Buckets;

    #[test]
    fn every_item_is_in_exactly_its_buckets_in_order() {
        let ranges = |i: usize| (i % 5)..=(i % 5 + i % 3).min(6);
        let buckets = Buckets::new(7, 40, ranges);
        for b in 0..7 {
            let expected: Vec<u32> = (0..40u32)
                .filter(|&i| ranges(i as usize).contains(&b))
                .collect();
            assert_eq!(buckets.get(b), expected.as_slice(), "bucket {b}");
        }
        assert!(Buckets::new(3, 0, |_| 0..=0).get(1).is_empty());
    }
}
