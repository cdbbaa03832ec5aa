//! Sort and sweep on one axis: proxies sorted by the low end of their box on the axis where
//! the box centres spread most; each proxy is tested only against the proxies whose low end
//! lies within its own interval on that axis. `O(n log n + k)` for `k` interval overlaps,
//! against brute force's `n²/2`.
//!
//! The order is kept between frames and re-sorted by insertion sort, which is linear when
//! bodies move coherently (the order barely changes); proxies added or removed since the
//! last frame are appended or dropped before it, so insertions and removals do not force a
//! full sort either. The axis is chosen again every frame from the centres' variance;
//! changing it costs one full re-sort. Testing the other two axes only for the pairs that
//! overlap on the sweep axis keeps it robust to "dice on a table" (all boxes sharing one
//! z range), where every small vertical motion of the three-axis
//! [`IncrementalSap`](super::IncrementalSap) swaps endpoints among all the boxes on the shared
//! axis; the widest-spread axis is not the shared one in that layout.
//!
//! TODO(#6): the automatic choice between this, [`super::IncrementalSap`] and [`super::HashGrid`].

use super::{CandidatePair, Proxy};
use crate::bounding::BoundingVolume;

/// Scratch and frame-to-frame order of the sweep.
#[derive(Debug, Clone, Default)]
pub struct SortAndSweep {
    /// `(low end on the axis, index into the proxies)`, ascending after [`Self::pairs`].
    order: Vec<(f64, u32)>,
    /// The axis `order` was sorted on last frame.
    axis: usize,
}

impl SortAndSweep {
    /// An empty sweep.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Every pair of `proxies` whose grown boxes overlap (touching counts) and that may pair,
    /// once each with `a < b`, in increasing `(a, b)` order, written to `out` (cleared
    /// first): exactly the pairs of [`pairs_brute_force`](super::pairs_brute_force).
    ///
    /// # Allocation
    /// None once the scratch and `out` have grown to the proxy and pair counts.
    pub fn pairs(&mut self, proxies: &[Proxy], out: &mut Vec<CandidatePair>) {
        out.clear();
        let axis = widest_spread_axis(proxies);
        self.refresh_order(proxies, axis);
        let order = &self.order;
        for (i, &(_, pi)) in order.iter().enumerate() {
            let p = &proxies[pi as usize];
            let high = p.bounds.max[axis];
            for &(low, qi) in &order[i + 1..] {
                if low > high {
                    break;
                }
                let q = &proxies[qi as usize];
                if p.body != q.body && p.may_pair(q) && p.bounds.intersects(&q.bounds) {
                    out.push(CandidatePair {
                        a: p.body.min(q.body),
                        b: p.body.max(q.body),
                    });
                }
            }
        }
        out.sort_unstable();
    }

    /// Brings `order` up to date with `proxies` on `axis`: rebuilt and fully sorted when the
    /// axis changed; otherwise entries past the new proxy count are dropped, new indices
    /// appended, every entry's key refreshed (entries are indices, so a proxy that changed
    /// place, e.g. by a caller's `swap_remove`, is simply re-keyed) and the order
    /// insertion-sorted, which is linear when the bodies moved coherently and few changed
    /// place.
    fn refresh_order(&mut self, proxies: &[Proxy], axis: usize) {
        if axis != self.axis || self.order.is_empty() {
            self.order.clear();
            self.order.extend(
                proxies
                    .iter()
                    .enumerate()
                    .map(|(i, p)| (p.bounds.min[axis], i as u32)),
            );
            self.order.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            self.axis = axis;
            return;
        }
        let (old, n) = (self.order.len(), proxies.len());
        if n < old {
            self.order.retain(|&(_, i)| (i as usize) < n);
        }
        for entry in &mut self.order {
            entry.0 = proxies[entry.1 as usize].bounds.min[axis];
        }
        self.order.extend(
            proxies
                .iter()
                .enumerate()
                .skip(old)
                .map(|(i, p)| (p.bounds.min[axis], i as u32)),
        );
        insertion_sort(&mut self.order);
    }

    /// Checks the kept order against `proxies`, which must be the slice of the last
    /// [`Self::pairs`] call: one entry per proxy, each holding that proxy's low end on the
    /// sweep axis, ascending. The pairs themselves are checked by comparing with
    /// [`pairs_brute_force`](super::pairs_brute_force).
    ///
    /// # Errors
    /// A description of the first violated invariant.
    pub fn validate(&self, proxies: &[Proxy]) -> Result<(), String> {
        if self.order.len() != proxies.len() {
            return Err(format!(
                "{} entries for {} proxies",
                self.order.len(),
                proxies.len()
            ));
        }
        let mut seen = vec![false; proxies.len()];
        for (k, &(low, i)) in self.order.iter().enumerate() {
            let i = i as usize;
            if i >= proxies.len() || std::mem::replace(&mut seen[i], true) {
                return Err(format!(
                    "entry {k}: proxy index {i} out of range or repeated"
                ));
            }
            if low.to_bits() != proxies[i].bounds.min[self.axis].to_bits() {
                return Err(format!("entry {k}: stale low end {low} for proxy {i}"));
            }
            if k > 0 && self.order[k - 1].0.total_cmp(&low).is_gt() {
                return Err(format!("entries {} and {k} out of order", k - 1));
            }
        }
        Ok(())
    }
}

/// Sorts by the first field; linear on nearly sorted input.
fn insertion_sort(entries: &mut [(f64, u32)]) {
    for i in 1..entries.len() {
        let entry = entries[i];
        let mut j = i;
        while j > 0 && entries[j - 1].0.total_cmp(&entry.0).is_gt() {
            entries[j] = entries[j - 1];
            j -= 1;
        }
        entries[j] = entry;
    }
}

/// The axis (0, 1, 2) along which the proxies' box centres have the largest variance.
fn widest_spread_axis(proxies: &[Proxy]) -> usize {
    if proxies.is_empty() {
        return 0;
    }
    let n = proxies.len() as f64;
    let mean = proxies
        .iter()
        .fold(crate::math::DVec3::ZERO, |s, p| s + p.bounds.center())
        / n;
    let variance = proxies.iter().fold(crate::math::DVec3::ZERO, |s, p| {
        let d = p.bounds.center() - mean;
        s + d * d
    });
    if variance.x >= variance.y && variance.x >= variance.z {
        0
    } else if variance.y >= variance.z {
        1
    } else {
        2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounding::Aabb;
    use crate::broad::{CollisionFilter, pairs_brute_force};
    use crate::math::DVec3;
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    fn random_proxy(rng: &mut crate::test_support::TestRng, body: u32, spread: f64) -> Proxy {
        let c = point_in_cube(rng, spread);
        // Zero-size, ordinary and huge boxes.
        let h = match rng.random_range(0..10) {
            0 => DVec3::ZERO,
            1 => DVec3::splat(rng.random_range(2.0..20.0)),
            _ => DVec3::new(
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
                rng.random_range(0.0..1.0),
            ),
        };
        Proxy {
            body,
            bounds: Aabb::new(c - h, c + h),
            is_static: rng.random_range(0..5) == 0,
            filter: CollisionFilter {
                group: 1 << rng.random_range(0..3),
                mask: rng.random_range(1..8),
            },
        }
    }

    /// Coherent motion with occasional teleports, insertions and removals: the sweep's pairs
    /// equal brute force's every frame.
    #[test]
    fn sweep_pairs_equal_brute_force_over_coherent_frames() {
        let mut rng = rng(91);
        let mut sweep = SortAndSweep::new();
        let (mut expected, mut found) = (Vec::new(), Vec::new());
        let (mut total_pairs, mut empty_frames) = (0usize, 0usize);
        for scene in 0..20 {
            let spread = [2.0, 10.0, 40.0][scene % 3];
            let mut proxies: Vec<Proxy> = (0..rng.random_range(0..150))
                .map(|i| random_proxy(&mut rng, i * 2 + 1, spread))
                .collect();
            let mut next_id = 1000;
            for frame in 0..100 {
                for p in &mut proxies {
                    let step = if rng.random_range(0..50) == 0 {
                        point_in_cube(&mut rng, spread) - p.bounds.center() // teleport
                    } else {
                        point_in_cube(&mut rng, 0.05)
                    };
                    p.bounds = Aabb::new(p.bounds.min + step, p.bounds.max + step);
                }
                if rng.random_range(0..10) == 0 && !proxies.is_empty() {
                    let i = rng.random_range(0..proxies.len());
                    proxies.swap_remove(i);
                }
                if rng.random_range(0..10) == 0 {
                    proxies.push(random_proxy(&mut rng, next_id, spread));
                    next_id += 1;
                }
                pairs_brute_force(&proxies, &mut expected);
                sweep.pairs(&proxies, &mut found);
                assert_eq!(found, expected, "scene {scene} frame {frame}");
                total_pairs += expected.len();
                empty_frames += usize::from(expected.is_empty());
            }
        }
        assert!(
            total_pairs > 10_000 && empty_frames > 10,
            "pairs {total_pairs}, empty frames {empty_frames}"
        );
    }

    #[test]
    fn boxes_touching_at_one_point_or_stacked_on_one_coordinate_pair() {
        let unit = |x: f64, y: f64| Proxy {
            body: 0,
            bounds: Aabb::new(DVec3::new(x, y, 0.0), DVec3::new(x + 1.0, y + 1.0, 1.0)),
            is_static: false,
            filter: CollisionFilter::ALL,
        };
        // Corner to corner, and ten boxes sharing the same low end on every axis.
        let mut proxies = vec![unit(0.0, 0.0), unit(1.0, 1.0)];
        proxies.extend((0..10).map(|_| unit(5.0, 5.0)));
        for (i, p) in proxies.iter_mut().enumerate() {
            p.body = i as u32;
        }
        let (mut expected, mut found) = (Vec::new(), Vec::new());
        pairs_brute_force(&proxies, &mut expected);
        SortAndSweep::new().pairs(&proxies, &mut found);
        assert_eq!(found, expected);
        assert_eq!(found.len(), 1 + 45);
    }
}
