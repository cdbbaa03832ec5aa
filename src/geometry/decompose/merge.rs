//! Merging neighbouring pieces back together, under two rules.
//!
//! - [`merge_within`] (the cut search's last step): the pair whose union is least concave,
//!   while that concavity stays within the limit, then down to the part count.
//! - [`merge_by_volume`] (the relaxation of the baseline): the smallest piece first, with the
//!   neighbour whose union fills the most of its hull, while the hull's empty fraction stays
//!   within a threshold, then down to the part count.
//!
//! Neighbours are pieces whose hull bounds touch ([`Fitted::may_touch`]): a superset of the
//! pieces that share a cut, which is all merging needs (a union of pieces apart is rejected
//! by its own concavity or empty volume).

use super::fitted::Fitted;
use super::parallel::map_in_order;
use std::collections::BTreeSet;

/// Live pieces and who may touch whom.
struct Pool {
    pieces: Vec<Option<Fitted>>,
    neighbours: Vec<BTreeSet<usize>>,
    slack: f64,
    /// Threads the pairs' unions are weighed on.
    threads: usize,
}

impl Pool {
    fn new(pieces: Vec<Fitted>, slack: f64, threads: usize) -> Self {
        let n = pieces.len();
        let mut neighbours = vec![BTreeSet::new(); n];
        for i in 0..n {
            for j in i + 1..n {
                if pieces[i].may_touch(&pieces[j], slack) {
                    neighbours[i].insert(j);
                    neighbours[j].insert(i);
                }
            }
        }
        Self {
            pieces: pieces.into_iter().map(Some).collect(),
            neighbours,
            slack,
            threads,
        }
    }

    fn live(&self) -> usize {
        self.pieces.iter().flatten().count()
    }

    fn get(&self, i: usize) -> &Fitted {
        self.pieces[i].as_ref().expect("only live pieces are named")
    }

    /// Replaces `i` and `j` by their union (already built); returns its index.
    fn replace(&mut self, i: usize, j: usize, union: Fitted) -> usize {
        let k = self.pieces.len();
        let mut around: BTreeSet<usize> = &self.neighbours[i] | &self.neighbours[j];
        around.remove(&i);
        around.remove(&j);
        around.retain(|&n| self.get(n).may_touch(&union, self.slack));
        for &n in &around {
            self.neighbours[n].remove(&i);
            self.neighbours[n].remove(&j);
            self.neighbours[n].insert(k);
        }
        self.pieces[i] = None;
        self.pieces[j] = None;
        self.neighbours[i].clear();
        self.neighbours[j].clear();
        self.pieces.push(Some(union));
        self.neighbours.push(around);
        k
    }

    fn into_pieces(self) -> Vec<Fitted> {
        self.pieces.into_iter().flatten().collect()
    }
}

/// Merges the least concave union of neighbours while its concavity is within `limit`
/// metres, then (if still above `max_parts`) the least concave unions regardless. Unions
/// are weighed on up to `threads` threads; the result is the same for any count.
pub(super) fn merge_within(
    pieces: Vec<Fitted>,
    limit: f64,
    max_parts: usize,
    slack: f64,
    threads: usize,
) -> Vec<Fitted> {
    let mut pool = Pool::new(pieces, slack, threads);
    merge_cheapest(
        &mut pool,
        |a, b, live| {
            // With no more than `max_parts` pieces left (and merging only lowers the
            // count), a union above the limit is never merged: it is enough to know
            // that it is above.
            let bar = if live <= max_parts {
                limit
            } else {
                f64::INFINITY
            };
            a.union_concavity(b, bar)
        },
        |concavity, live| concavity > limit && live <= max_parts,
    );
    pool.into_pieces()
}

/// Merges, over and over, the pair of neighbours with the lowest `cost(a, b, live
/// pieces)` (non-negative), until `done(lowest cost, live pieces)` or no pair is left.
fn merge_cheapest(
    pool: &mut Pool,
    cost: impl Fn(&Fitted, &Fitted, usize) -> f64 + Sync,
    done: impl Fn(f64, usize) -> bool,
) {
    // Non-negative floats order as their bits: (cost bits, i, j) sorts by cost.
    let mut costs: BTreeSet<(u64, usize, usize)> = BTreeSet::new();
    let price = |pool: &Pool, costs: &mut BTreeSet<_>, pairs: &[(usize, usize)]| {
        let live = pool.live();
        let prices = map_in_order(pairs, pool.threads, |&(i, j)| {
            cost(pool.get(i), pool.get(j), live)
        });
        for (&(i, j), c) in pairs.iter().zip(prices) {
            costs.insert((c.max(0.0).to_bits(), i.min(j), i.max(j)));
        }
    };
    let pairs: Vec<(usize, usize)> = (0..pool.pieces.len())
        .filter(|&i| pool.pieces[i].is_some())
        .flat_map(|i| pool.neighbours[i].range(i + 1..).map(move |&j| (i, j)))
        .collect();
    price(pool, &mut costs, &pairs);
    while let Some(&(bits, i, j)) = costs.first() {
        if done(f64::from_bits(bits), pool.live()) {
            break;
        }
        let union = pool.get(i).merged(pool.get(j));
        costs.retain(|&(_, a, b)| a != i && a != j && b != i && b != j);
        let k = pool.replace(i, j, union);
        let pairs: Vec<(usize, usize)> = pool.neighbours[k].iter().map(|&n| (n, k)).collect();
        price(pool, &mut costs, &pairs);
    }
}

/// The fraction of the hull of `a ∪ b` that the union leaves empty (0 for a convex union).
fn empty_fraction(a: &Fitted, b: &Fitted) -> f64 {
    let hull = a.merged_hull(b).volume();
    if hull > 0.0 {
        (1.0 - (a.volume + b.volume) / hull).max(0.0)
    } else {
        0.0
    }
}

/// The lecture's relaxation: the smallest piece merges with the neighbour whose union leaves
/// the least of its hull empty, while that fraction is within `max_empty`; a piece no
/// neighbour accepts is settled. Then, while above `max_parts`, the union leaving the least
/// empty is taken regardless.
pub(super) fn merge_by_volume(
    pieces: Vec<Fitted>,
    max_empty: f64,
    max_parts: usize,
    slack: f64,
    threads: usize,
) -> Vec<Fitted> {
    let mut pool = Pool::new(pieces, slack, threads);
    let mut settled = BTreeSet::new();
    loop {
        let smallest = (0..pool.pieces.len())
            .filter(|i| pool.pieces[*i].is_some() && !settled.contains(i))
            .min_by(|&a, &b| pool.get(a).volume.total_cmp(&pool.get(b).volume));
        let Some(i) = smallest else { break };
        match best_partner(&pool, i) {
            Some((j, empty)) if empty <= max_empty => {
                let union = pool.get(i).merged(pool.get(j));
                pool.replace(i, j, union);
            }
            _ => {
                settled.insert(i);
            }
        }
    }
    merge_cheapest(
        &mut pool,
        |a, b, _| empty_fraction(a, b),
        |_, live| live <= max_parts,
    );
    pool.into_pieces()
}

/// The neighbour of `i` whose union with it leaves the least of its hull empty, and that
/// fraction.
fn best_partner(pool: &Pool, i: usize) -> Option<(usize, f64)> {
    pool.neighbours[i]
        .iter()
        .map(|&j| (j, empty_fraction(pool.get(i), pool.get(j))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}
