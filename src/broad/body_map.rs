//! Body id maps: [`SlotTable`], id → slot, a plain array while the ids are small;
//! [`BodyMap`], a hash map with a hash fit for `u32` ids; [`PairMap`], the same for pairs
//! of ids (the pipeline's per-pair state).
//!
//! The standard library's SipHash guards against adversarial keys and costs about 20 ns a
//! look-up; body ids are chosen by the scene, not by an adversary, and every moved body is
//! looked up once per frame (every candidate pair several times). One multiply by the
//! golden-ratio constant per id spreads it over the high bits, and folding the high half
//! down reaches the low bits the table indexes by.

use std::collections::HashMap;

use super::{CandidatePair, Proxy};
use std::hash::{BuildHasherDefault, Hasher};

/// Body id → a value (by default its slot).
pub(crate) type BodyMap<V = u32> = HashMap<u32, V, BuildHasherDefault<IdHasher>>;

/// Candidate pair → a value.
pub(crate) type PairMap<V> = HashMap<CandidatePair, V, BuildHasherDefault<IdHasher>>;

/// Multiplicative hash of `u32` ids (one, or the two of a pair, each folded in turn).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct IdHasher {
    state: u64,
}

impl Hasher for IdHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }

    #[inline]
    fn write_u32(&mut self, id: u32) {
        self.write_u64(u64::from(id));
    }

    #[inline]
    fn write_u64(&mut self, word: u64) {
        self.state = (self.state ^ word).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.state ^ (self.state >> 32)
    }
}

/// Body id → slot, as a plain array while the ids are small (every id below four times the
/// count plus [`DENSE_SLACK`], so the array is at most about four cells per body plus
/// 256 KiB: one read of a 4-byte cell where a hash map probes a table three times the
/// size), and as a [`BodyMap`] from the first id beyond that (`examples/broad_bench`,
/// 100,000 bodies).
#[derive(Debug, Clone)]
pub(crate) enum SlotTable {
    /// `slots[id]` is the slot of body `id`, or [`ABSENT`]; `count` ids are present.
    Dense {
        slots: Vec<u32>,
        count: usize,
    },
    Sparse(BodyMap),
}

/// Ids a dense table allows beyond four times its count.
const DENSE_SLACK: usize = 1 << 16;
/// A free cell of a dense table.
const ABSENT: u32 = u32::MAX;

impl Default for SlotTable {
    fn default() -> Self {
        Self::Dense {
            slots: Vec::new(),
            count: 0,
        }
    }
}

impl SlotTable {
    #[inline]
    pub(crate) fn get(&self, id: u32) -> Option<u32> {
        match self {
            Self::Dense { slots, .. } => slots.get(id as usize).copied().filter(|&s| s != ABSENT),
            Self::Sparse(map) => map.get(&id).copied(),
        }
    }

    pub(crate) fn contains(&self, id: u32) -> bool {
        self.get(id).is_some()
    }

    pub(crate) fn len(&self) -> usize {
        match self {
            Self::Dense { count, .. } => *count,
            Self::Sparse(map) => map.len(),
        }
    }

    /// Sets `id`'s slot (present or not), returning the slot it had.
    pub(crate) fn insert(&mut self, id: u32, slot: u32) -> Option<u32> {
        if let Self::Dense { slots, count } = self {
            let i = id as usize;
            if i < slots.len() || i < 4 * (*count + 1) + DENSE_SLACK {
                if i >= slots.len() {
                    slots.resize(i + 1, ABSENT);
                }
                let previous = std::mem::replace(&mut slots[i], slot);
                *count += usize::from(previous == ABSENT);
                return (previous != ABSENT).then_some(previous);
            }
            let map: BodyMap = slots
                .iter()
                .enumerate()
                .filter(|&(_, &s)| s != ABSENT)
                .map(|(i, &s)| (i as u32, s))
                .collect();
            *self = Self::Sparse(map);
        }
        match self {
            Self::Sparse(map) => map.insert(id, slot),
            Self::Dense { .. } => unreachable!("converted above"),
        }
    }

    /// Removes `id`, returning its slot if it was present.
    pub(crate) fn remove(&mut self, id: u32) -> Option<u32> {
        match self {
            Self::Dense { slots, count } => {
                let cell = slots.get_mut(id as usize)?;
                let slot = std::mem::replace(cell, ABSENT);
                (slot != ABSENT).then(|| {
                    *count -= 1;
                    slot
                })
            }
            Self::Sparse(map) => map.remove(&id),
        }
    }
}

/// The bodies of a stateful broad phase: their proxies densely by slot, and each id's slot.
/// Slots are dense: removing a body moves the last one into its slot.
#[derive(Debug, Clone, Default)]
pub(crate) struct Bodies {
    /// The proxies by slot. Only their boxes may be changed in place; bodies come and go
    /// through [`push`](Self::push), [`unmap`](Self::unmap) and
    /// [`swap_remove`](Self::swap_remove).
    pub(crate) proxies: Vec<Proxy>,
    slot_of: SlotTable,
}

impl Bodies {
    pub(crate) fn len(&self) -> usize {
        self.proxies.len()
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.proxies.is_empty()
    }

    pub(crate) fn contains(&self, body: u32) -> bool {
        self.slot_of.contains(body)
    }

    /// The slot of `body`, if present.
    #[inline]
    pub(crate) fn slot(&self, body: u32) -> Option<usize> {
        self.slot_of.get(body).map(|s| s as usize)
    }

    /// Adds `proxy` (its id not present) at the next slot, returned.
    pub(crate) fn push(&mut self, proxy: Proxy) -> usize {
        let slot = self.proxies.len();
        let previous = self.slot_of.insert(proxy.body, slot as u32);
        debug_assert!(previous.is_none(), "body {} given twice", proxy.body);
        self.proxies.push(proxy);
        slot
    }

    /// Unmaps `body` and returns its slot, which keeps the body's proxy until
    /// [`swap_remove`](Self::swap_remove).
    pub(crate) fn unmap(&mut self, body: u32) -> Option<usize> {
        self.slot_of.remove(body).map(|s| s as usize)
    }

    /// Empties slot `slot` (already unmapped): the last slot's body moves into it and is
    /// remapped. The caller moves its own per-slot records alike (`Vec::swap_remove`), and
    /// renames the last slot's listings to `slot` first.
    pub(crate) fn swap_remove(&mut self, slot: usize) {
        let last = self.proxies.len() - 1;
        if slot != last {
            self.slot_of.insert(self.proxies[last].body, slot as u32);
        }
        self.proxies.swap_remove(slot);
    }

    /// Checks that the id table and the proxies agree: one id per slot, mapped to it.
    pub(crate) fn check(&self) -> Result<(), String> {
        if self.slot_of.len() != self.proxies.len() {
            return Err(format!(
                "{} proxies, {} ids mapped",
                self.proxies.len(),
                self.slot_of.len()
            ));
        }
        for (slot, p) in self.proxies.iter().enumerate() {
            if self.slot(p.body) != Some(slot) {
                return Err(format!("body {} at slot {slot} not mapped to it", p.body));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;
    use std::collections::HashMap;

    /// Random inserts, replacements and removals agree with a `HashMap`, on small ids (the
    /// table stays dense) and with a few huge ones mixed in (it turns sparse, keeping
    /// every entry).
    #[test]
    fn a_slot_table_agrees_with_a_hash_map_dense_and_after_turning_sparse() {
        let mut rng = rng(41);
        for huge_ids in [false, true] {
            let (mut table, mut truth) = (SlotTable::default(), HashMap::new());
            for step in 0..20_000u32 {
                let id = if huge_ids && rng.random_range(0..500) == 0 {
                    rng.random_range(1_000_000..u32::MAX)
                } else {
                    rng.random_range(0..3_000)
                };
                if rng.random_range(0..3) == 0 {
                    assert_eq!(table.remove(id), truth.remove(&id), "step {step}");
                } else {
                    assert_eq!(
                        table.insert(id, step),
                        truth.insert(id, step),
                        "step {step}"
                    );
                }
                assert_eq!(table.len(), truth.len());
                let probe = rng.random_range(0..3_000);
                assert_eq!(table.get(probe), truth.get(&probe).copied());
                assert_eq!(table.contains(probe), truth.contains_key(&probe));
            }
            assert_eq!(matches!(table, SlotTable::Sparse(_)), huge_ids);
        }
    }
}
