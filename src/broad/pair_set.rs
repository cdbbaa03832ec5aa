//! The overlapping-pair set the stateful broad phases keep between frames: a sorted list
//! plus a log of the edits since it was last brought up to date.
//!
//! A balanced tree would pay a cache-missing `O(log k)` search per edit; a broad phase edits
//! its set many times per frame but reads it once. Here an edit is a push onto the log, and
//! [`PairSet::commit`] folds the log into the sorted list in one pass: the log sorted by pair
//! (then by place in the log, so the edits of one pair keep their order and the last one wins), then merged
//! with the list. `O(k + e log e)` per frame for `k` pairs and `e` edits, against
//! `O(e log k)` tree edits plus an `O(k)` tree walk to list the pairs.
//!
//! # Contract
//! An edit states the pair's new membership ([`insert`](PairSet::insert): present,
//! [`remove`](PairSet::remove): absent) and is idempotent: inserting a present pair or
//! removing an absent one changes nothing. The broad phases still log only real changes, to
//! keep the log short.

use std::collections::BTreeSet;

use super::{CandidatePair, Proxy, pairs_brute_force};

/// Sorted pair list plus pending edits.
#[derive(Debug, Clone, Default)]
pub(crate) struct PairSet {
    /// The pairs as of the last commit, strictly increasing.
    sorted: Vec<CandidatePair>,
    /// Edits since: the pair, the edit's place in the log, and whether the pair is now
    /// present.
    log: Vec<(CandidatePair, u32, bool)>,
    /// Merge target, swapped with `sorted` by each commit (no allocation once grown).
    spare: Vec<CandidatePair>,
}

impl PairSet {
    /// Records that `pair` is now in the set.
    #[inline]
    pub(crate) fn insert(&mut self, pair: CandidatePair) {
        self.log.push((pair, self.log.len() as u32, true));
    }

    /// Records that `pair` is no longer in the set.
    #[inline]
    pub(crate) fn remove(&mut self, pair: CandidatePair) {
        self.log.push((pair, self.log.len() as u32, false));
    }

    /// Folds the pending edits into the sorted list and returns it, strictly increasing.
    ///
    /// # Allocation
    /// None once the list, the log and the merge buffer have grown to their peak sizes.
    pub(crate) fn commit(&mut self) -> &[CandidatePair] {
        if self.log.is_empty() {
            return &self.sorted;
        }
        // By pair, then by place in the log, so the last edit of each run wins. Unstable
        // with the place as tie-break: the same order as a stable sort, without the
        // scratch buffer a stable sort allocates every call.
        self.log.sort_unstable_by_key(|&(pair, at, _)| (pair, at));
        self.spare.clear();
        let mut old = self.sorted.iter().copied().peekable();
        let mut edits = self.log.iter().copied().peekable();
        while let Some((pair, _, mut present)) = edits.next() {
            while let Some(&(next, _, state)) = edits.peek()
                && next == pair
            {
                present = state;
                edits.next();
            }
            while let Some(&kept) = old.peek()
                && kept < pair
            {
                self.spare.push(kept);
                old.next();
            }
            if old.peek() == Some(&pair) {
                old.next();
            }
            if present {
                self.spare.push(pair);
            }
        }
        self.spare.extend(old);
        self.log.clear();
        std::mem::swap(&mut self.sorted, &mut self.spare);
        &self.sorted
    }

    /// Writes the pairs, the pending edits folded in ([`commit`](Self::commit)), to `out`
    /// (cleared first).
    #[inline]
    pub(crate) fn list(&mut self, out: &mut Vec<CandidatePair>) {
        out.clear();
        out.extend_from_slice(self.commit());
    }

    /// Moves the edits logged since the last commit or take to `out` (each pair and
    /// whether it is now present, in the order they were made), as a caller that keeps the
    /// set itself wants them; the sorted list is left as it was.
    pub(crate) fn take_edits(&mut self, out: &mut Vec<(CandidatePair, bool)>) {
        out.extend(self.log.iter().map(|&(pair, _, present)| (pair, present)));
        self.log.clear();
    }

    /// Number of pairs, committed first.
    #[cfg(test)]
    pub(crate) fn len(&mut self) -> usize {
        self.commit().len()
    }

    /// Whether `pair` is in the set, committed first.
    #[cfg(test)]
    pub(crate) fn contains(&mut self, pair: &CandidatePair) -> bool {
        self.commit().binary_search(pair).is_ok()
    }

    /// `Ok` when the set as of now (pending edits applied) is exactly
    /// [`pairs_brute_force`] over `proxies`; else the extra and the missing pairs (for the
    /// broad phases' `validate`). `O(n²)`.
    pub(crate) fn check_against_brute_force(&self, proxies: &[Proxy]) -> Result<(), String> {
        let mut expected = Vec::new();
        pairs_brute_force(proxies, &mut expected);
        let have = self.snapshot();
        if have == expected {
            return Ok(());
        }
        let (have, want): (BTreeSet<_>, BTreeSet<_>) =
            (have.into_iter().collect(), expected.into_iter().collect());
        Err(format!(
            "pair set differs from brute force: extra {:?}, missing {:?}",
            have.difference(&want).collect::<Vec<_>>(),
            want.difference(&have).collect::<Vec<_>>()
        ))
    }

    /// The set as of now, pending edits applied, without committing (for `validate`).
    pub(crate) fn snapshot(&self) -> Vec<CandidatePair> {
        let mut copy = self.clone();
        copy.commit().to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::rng;
    use rand::Rng;
    use std::collections::BTreeSet;

    fn pair(a: u32, b: u32) -> CandidatePair {
        CandidatePair { a, b }
    }

    #[test]
    fn random_edit_sequences_with_commits_at_random_points_match_a_tree_set() {
        let mut rng = rng(0x9a1);
        let (mut redundant, mut commits) = (0, 0);
        for _ in 0..200 {
            let mut set = PairSet::default();
            let mut tree = BTreeSet::new();
            for _ in 0..rng.random_range(0..400) {
                let p = pair(rng.random_range(0..12), rng.random_range(12..24));
                let present = rng.random_bool(0.5);
                redundant += usize::from(tree.contains(&p) == present);
                if present {
                    set.insert(p);
                    tree.insert(p);
                } else {
                    set.remove(p);
                    tree.remove(&p);
                }
                if rng.random_bool(0.05) {
                    commits += 1;
                    assert!(set.commit().iter().eq(tree.iter()));
                }
            }
            assert!(set.snapshot().iter().eq(tree.iter()));
            assert!(set.commit().iter().eq(tree.iter()));
            assert!(set.log.is_empty(), "commit empties the log");
        }
        assert!(redundant > 1000 && commits > 500, "{redundant} {commits}");
    }

    #[test]
    fn the_last_edit_of_a_pair_within_one_commit_wins() {
        let mut set = PairSet::default();
        set.insert(pair(1, 2));
        set.remove(pair(1, 2));
        set.insert(pair(0, 5));
        assert_eq!(set.commit(), &[pair(0, 5)]);
        set.remove(pair(0, 5));
        set.insert(pair(0, 5));
        set.insert(pair(1, 2));
        assert_eq!(set.commit(), &[pair(0, 5), pair(1, 2)]);
    }
}
