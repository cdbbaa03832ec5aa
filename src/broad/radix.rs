//! The least-significant-digit radix sort shared by the broad phase's sorts (pairs in
//! `pair_sort.rs`, sweep orders in `key_sort.rs`): one counting pass over every byte of
//! the keys at once, then one stable pass of counted moves per byte, skipping the bytes
//! every key shares.

/// Sorts `records` ascending by the low `BYTES` bytes of `key(record)`, stably, using
/// `scratch` (its contents are overwritten) as the other buffer of the passes.
///
/// # Allocation
/// None once `scratch` has grown to the largest `records`.
pub(crate) fn radix_sort<R: Copy, const BYTES: usize>(
    records: &mut Vec<R>,
    scratch: &mut Vec<R>,
    key: impl Fn(&R) -> u64,
) {
    let mut counts = [[0u32; 256]; BYTES];
    for record in records.iter() {
        let k = key(record);
        for (byte, table) in counts.iter_mut().enumerate() {
            table[((k >> (8 * byte)) & 0xff) as usize] += 1;
        }
    }
    let Some(&first) = records.first() else {
        return;
    };
    scratch.clear();
    scratch.resize(records.len(), first);
    let n = records.len() as u32;
    for (byte, table) in counts.iter_mut().enumerate() {
        // Every key has the same byte here: the pass would move nothing.
        if table.contains(&n) {
            continue;
        }
        let mut start = 0;
        for count in table.iter_mut() {
            (start, *count) = (start + *count, start);
        }
        for record in records.iter() {
            let digit = ((key(record) >> (8 * byte)) & 0xff) as usize;
            scratch[table[digit] as usize] = *record;
            table[digit] += 1;
        }
        std::mem::swap(records, scratch);
    }
}
