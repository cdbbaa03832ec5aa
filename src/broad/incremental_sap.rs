//! Incremental sweep and prune on three axes (I-COLLIDE: Cohen, Lin, Manocha, Ponamgi 1995;
//! Ericson, *Real-Time Collision Detection*, §7.5.2): a stateful broad phase that keeps, per
//! axis, the sorted list of every body's box endpoints and the set of overlapping pairs
//! between frames, so that a frame costs only the endpoint swaps its motion causes.
//!
//! # Invariants
//! - Each axis holds `2n` endpoints (a min and a max per body) sorted by coordinate, every
//!   min before every max at equal coordinates (`Endpoint::after`). On one axis, the
//!   intervals of bodies `a` and `b` overlap exactly when `a`'s min lies before `b`'s max
//!   and `b`'s min before `a`'s max; so `a.min == b.max` counts as overlapping, as in
//!   [`Aabb::intersects`] (closed boxes: touching boxes pair, zero-size boxes are points).
//! - The pair set holds exactly the pairs whose stored boxes overlap on all three axes and
//!   that may pair, never the `O(n²)` pairs that overlap on one axis (what a per-axis
//!   overlap count would store for "dice on a table", all sharing one z range).
//!
//! # A move
//! [`IncrementalSap::update`] moves a body's endpoints one at a time to their new
//! coordinates by insertion sort (adjacent swaps); a min passing a max of another body (or
//! back) is the only swap that changes an overlap, and:
//! - when it may *start* one, the pair's full boxes are tested (all three axes, from the
//!   stored bounds, which the endpoint lists agree with) and the pair enters the set if they
//!   overlap and may pair;
//! - when it *ends* one, the pair leaves the set.
//!
//! This is exact: during one endpoint's move, each other endpoint is passed at most once,
//! and every pair whose relation changed ends with an event that leaves it in the set
//! exactly when the boxes now overlap. A teleport takes the same path, one swap per
//! endpoint passed: remove plus insert would be `O(n)` too.
//!
//! # Costs (`n` bodies, `k` pairs in the set)
//! - [`update`](IncrementalSap::update): `O(1 + s)` for `s` swaps, linear in how far the
//!   body moved through the lists (up to `O(n)` per axis for a jump). A body that is not
//!   updated costs nothing.
//! - [`insert`](IncrementalSap::insert) and [`remove`](IncrementalSap::remove): `O(n)`.
//! - [`pairs`](IncrementalSap::pairs): `O(k + e log e)` for `e` pair changes (`pair_set.rs`).
//!
//! Bounds are trusted: finite with `min <= max` (the [`Aabb`] invariant; the daemon
//! validates poses before they reach the broad phase; a NaN would break the sort order),
//! checked by `debug_assert!`. The automatic choice ([`choose`](super::choose)) never takes
//! it: on every measured class another kind is faster.

use super::body_map::Bodies;
use super::pair_set::PairSet;
use super::stateful::{StatefulBroadPhase, stateful_api};
use super::{CandidatePair, Proxy, SortAndSweep, debug_assert_valid_bounds};
use crate::bounding::{Aabb, BoundingVolume};

/// Index of a body's min endpoint in [`IncrementalSap::positions`].
const MIN: usize = 0;
/// Index of a body's max endpoint in [`IncrementalSap::positions`].
const MAX: usize = 1;

/// One end of one body's interval on one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Endpoint {
    /// The coordinate, metres.
    value: f64,
    /// `slot << 1 | kind`, where `kind` is [`MIN`] or [`MAX`].
    tag: u32,
}

impl Endpoint {
    #[inline]
    fn new(value: f64, slot: usize, kind: usize) -> Self {
        debug_assert!(slot < (1 << 31), "too many bodies");
        Self {
            value,
            tag: (slot as u32) << 1 | kind as u32,
        }
    }

    #[inline]
    fn slot(self) -> usize {
        (self.tag >> 1) as usize
    }

    #[inline]
    fn kind(self) -> usize {
        (self.tag & 1) as usize
    }

    #[inline]
    fn is_max(self) -> bool {
        self.kind() == MAX
    }

    /// Whether `self` sorts strictly after `other`: a larger coordinate, or the same
    /// coordinate with `self` a max and `other` a min (mins first, so touching overlaps).
    /// Coordinates are compared with `>` and `==`, not `total_cmp`, so `-0.0` and `0.0` tie
    /// as they do in [`Aabb::intersects`]. Equal endpoints of the same kind keep their
    /// relative order; their order changes no overlap.
    #[inline]
    fn after(self, other: Self) -> bool {
        self.value > other.value || (self.value == other.value && self.kind() > other.kind())
    }
}

/// Incremental three-axis sweep and prune over bodies identified by `u32` ids; see the
/// module docs for the algorithm, the tie rule and the costs.
#[derive(Debug, Clone, Default)]
pub struct IncrementalSap {
    /// The bodies, densely by slot; `bodies.proxies[s].bounds` is what the endpoint lists
    /// hold.
    bodies: Bodies,
    /// `positions[s][axis][MIN | MAX]`: where slot `s`'s endpoints are in `axes[axis]`.
    positions: Vec<[[u32; 2]; 3]>,
    /// Per axis, all endpoints sorted by [`Endpoint::after`].
    axes: [Vec<Endpoint>; 3],
    /// The pairs whose boxes overlap and that may pair, `a < b`.
    pairs: PairSet,
}

impl IncrementalSap {
    /// An empty broad phase.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// A broad phase holding `proxies` (distinct ids), built in `O(n log n + k log k)`: each
    /// axis's endpoints sorted once and the pairs found by one [`SortAndSweep`] pass,
    /// instead of `n` insertions at `O(n)` each (300 ms for 10,000 bodies, 44 s for
    /// 100,000). The same state as inserting them one by one, up to the order of equal
    /// endpoints of the same kind (which changes no overlap).
    #[must_use]
    pub fn from_proxies(proxies: &[Proxy]) -> Self {
        let mut sap = Self::new();
        for p in proxies {
            debug_assert_valid_bounds(&p.bounds);
            sap.bodies.push(*p);
            sap.positions.push([[0; 2]; 3]);
        }
        for axis in 0..3 {
            let endpoints = &mut sap.axes[axis];
            endpoints.extend(proxies.iter().enumerate().flat_map(|(slot, p)| {
                [
                    Endpoint::new(p.bounds.min[axis], slot, MIN),
                    Endpoint::new(p.bounds.max[axis], slot, MAX),
                ]
            }));
            // The order of `after`: coordinate (`-0.0 == 0.0`, no NaN), mins first at ties.
            endpoints.sort_by(|x, y| {
                x.value
                    .partial_cmp(&y.value)
                    .unwrap_or(std::cmp::Ordering::Equal)
                    .then(x.kind().cmp(&y.kind()))
            });
            sap.renumber_from(axis, 0);
        }
        let mut found = Vec::new();
        SortAndSweep::new().pairs(proxies, &mut found);
        for pair in found {
            sap.pairs.insert(pair);
        }
        sap
    }

    /// Hands `edit` each pair of slot `slot`'s body: every body overlapping it has its min
    /// before its max on every axis, so one scan of the axis where the fewest endpoints
    /// precede that max finds them.
    fn edit_pairs_of(&mut self, slot: usize, edit: fn(&mut PairSet, CandidatePair)) {
        let axis = self.axis_with_fewest_before_max(slot);
        let end = self.positions[slot][axis][MAX] as usize;
        let p = &self.bodies.proxies[slot];
        for e in &self.axes[axis][..end] {
            if e.is_max() || e.slot() == slot {
                continue;
            }
            let q = &self.bodies.proxies[e.slot()];
            if p.may_pair(q) && p.bounds.intersects(&q.bounds) {
                edit(&mut self.pairs, CandidatePair::of(p.body, q.body));
            }
        }
    }

    /// Sets one coordinate of slot `slot`'s box and moves that endpoint to its sorted place
    /// by adjacent swaps, updating the pair set at each min/max swap with another body.
    fn move_endpoint(&mut self, slot: usize, axis: usize, kind: usize, value: f64) {
        let bounds = &mut self.bodies.proxies[slot].bounds;
        if kind == MIN {
            bounds.min[axis] = value;
        } else {
            bounds.max[axis] = value;
        }
        let endpoints = &mut self.axes[axis];
        let mut i = self.positions[slot][axis][kind] as usize;
        let moving = Endpoint::new(value, slot, kind);
        // Down: a min passing a max may start an overlap; a max passing a min ends one.
        while i > 0 && endpoints[i - 1].after(moving) {
            let other = endpoints[i - 1];
            endpoints[i] = other;
            self.positions[other.slot()][axis][other.kind()] = i as u32;
            if other.kind() != kind {
                crossed(
                    &self.bodies.proxies,
                    &mut self.pairs,
                    (slot, other.slot()),
                    axis,
                    kind == MIN,
                );
            }
            i -= 1;
        }
        // Up: a max passing a min may start an overlap; a min passing a max ends one.
        while i + 1 < endpoints.len() && moving.after(endpoints[i + 1]) {
            let other = endpoints[i + 1];
            endpoints[i] = other;
            self.positions[other.slot()][axis][other.kind()] = i as u32;
            if other.kind() != kind {
                crossed(
                    &self.bodies.proxies,
                    &mut self.pairs,
                    (slot, other.slot()),
                    axis,
                    kind == MAX,
                );
            }
            i += 1;
        }
        endpoints[i] = moving;
        self.positions[slot][axis][kind] = i as u32;
    }

    /// Records the positions of `axes[axis][from..]` (after an insert or remove shifted them).
    fn renumber_from(&mut self, axis: usize, from: usize) {
        for (i, e) in self.axes[axis].iter().enumerate().skip(from) {
            self.positions[e.slot()][axis][e.kind()] = i as u32;
        }
    }

    /// The axis on which the fewest endpoints precede slot `slot`'s max.
    fn axis_with_fewest_before_max(&self, slot: usize) -> usize {
        let at = self.positions[slot];
        (0..3).min_by_key(|&axis| at[axis][MAX]).unwrap_or(0)
    }
}

stateful_api!(IncrementalSap);

impl StatefulBroadPhase for IncrementalSap {
    fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    fn bodies_mut(&mut self) -> &mut Bodies {
        &mut self.bodies
    }

    /// Its endpoints inserted at their sorted places and its pairs found directly, without
    /// re-sorting the other bodies: `O(n)`, a binary search of the endpoint positions, a
    /// `Vec` insert (memmove) and renumbering of the shifted endpoints on each axis, and
    /// one scan for the pairs ([`edit_pairs_of`](IncrementalSap::edit_pairs_of)).
    fn file(&mut self, slot: usize) {
        let proxy = self.bodies.proxies[slot];
        let bounds = proxy.bounds;
        self.positions.push([[0; 2]; 3]);
        for axis in 0..3 {
            let endpoints = &mut self.axes[axis];
            // After every endpoint that does not sort after it (stable among ties); the max
            // sorts strictly after the min, so it lands after it.
            let min = Endpoint::new(bounds.min[axis], slot, MIN);
            let min_at = endpoints.partition_point(|x| !x.after(min));
            endpoints.insert(min_at, min);
            let max = Endpoint::new(bounds.max[axis], slot, MAX);
            let max_at = endpoints.partition_point(|x| !x.after(max));
            endpoints.insert(max_at, max);
            self.renumber_from(axis, min_at);
        }
        self.edit_pairs_of(slot, PairSet::insert);
    }

    /// Its pairs dropped by one scan, then its endpoints removed (memmove) and the shifted
    /// ones renumbered on each axis: `O(n)`.
    fn unfile(&mut self, slot: usize) {
        self.edit_pairs_of(slot, PairSet::remove);
        for axis in 0..3 {
            let [min_at, max_at] = self.positions[slot][axis];
            self.axes[axis].remove(max_at as usize);
            self.axes[axis].remove(min_at as usize);
            self.renumber_from(axis, min_at as usize);
        }
    }

    fn swap_remove_slot(&mut self, slot: usize) {
        let last = self.bodies.len() - 1;
        self.positions.swap_remove(slot);
        if slot != last {
            for axis in 0..3 {
                for kind in [MIN, MAX] {
                    let at = self.positions[slot][axis][kind] as usize;
                    self.axes[axis][at] = Endpoint::new(self.axes[axis][at].value, slot, kind);
                }
            }
        }
    }

    /// Each endpoint moved by insertion sort, the pair set updated by the swaps the move
    /// causes. On each axis the min is moved before the max when it decreases, after it
    /// otherwise, so a stored box is never inverted, not even between the two moves.
    #[inline]
    fn relocate(&mut self, slot: usize, bounds: Aabb) {
        for axis in 0..3 {
            let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
            // Order the two moves so the stored interval is never inverted.
            if lo < self.bodies.proxies[slot].bounds.min[axis] {
                self.move_endpoint(slot, axis, MIN, lo);
                self.move_endpoint(slot, axis, MAX, hi);
            } else {
                self.move_endpoint(slot, axis, MAX, hi);
                self.move_endpoint(slot, axis, MIN, lo);
            }
        }
    }

    fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        self.pairs.list(out);
    }

    /// Checks every invariant: the slot table and id map agree; each axis holds exactly the
    /// two endpoints of every body, at the positions recorded, with the body's stored
    /// coordinates, sorted (mins first at ties); stored boxes are finite and not inverted;
    /// and the pair set equals [`pairs_brute_force`](super::pairs_brute_force) over the
    /// stored boxes.
    fn validate(&self) -> Result<(), String> {
        self.bodies.check()?;
        let n = self.bodies.len();
        if self.positions.len() != n {
            return Err(format!(
                "{n} proxies, {} position rows",
                self.positions.len()
            ));
        }
        for p in &self.bodies.proxies {
            let b = &p.bounds;
            if !(b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all()) {
                return Err(format!("body {} has invalid bounds {b:?}", p.body));
            }
        }
        for (axis, endpoints) in self.axes.iter().enumerate() {
            if endpoints.len() != 2 * n {
                return Err(format!(
                    "axis {axis}: {} endpoints, {n} bodies",
                    endpoints.len()
                ));
            }
            for (i, e) in endpoints.iter().enumerate() {
                let slot = e.slot();
                if slot >= n || self.positions[slot][axis][e.kind()] as usize != i {
                    return Err(format!(
                        "axis {axis}: endpoint {i} ({e:?}) not where recorded"
                    ));
                }
                let b = &self.bodies.proxies[slot].bounds;
                let stored = if e.is_max() { b.max[axis] } else { b.min[axis] };
                if stored.to_bits() != e.value.to_bits() {
                    return Err(format!(
                        "axis {axis}: endpoint {i} {} != stored {stored}",
                        e.value
                    ));
                }
                if i > 0 && endpoints[i - 1].after(*e) {
                    return Err(format!(
                        "axis {axis}: endpoints {} and {i} out of order",
                        i - 1
                    ));
                }
            }
        }
        self.pairs.check_against_brute_force(&self.bodies.proxies)
    }
}

/// The pair set's response to slot `s`'s endpoint passing one of slot `t`'s of the other
/// kind on `axis`: when the swap may start an overlap, test the boxes (all axes) and the
/// filters; when it ends one, drop the pair if it was in the set, that is when the two
/// intervals were overlapping on the other two axes too (they were on `axis` until this
/// swap) and the bodies may pair. Only real changes are logged.
#[inline]
fn crossed(
    proxies: &[Proxy],
    pairs: &mut PairSet,
    (s, t): (usize, usize),
    axis: usize,
    starts: bool,
) {
    debug_assert_ne!(s, t, "a body's min and max never swap");
    let (p, q) = (&proxies[s], &proxies[t]);
    if !p.may_pair(q) {
        return;
    }
    if starts {
        if p.bounds.intersects(&q.bounds) {
            pairs.insert(CandidatePair::of(p.body, q.body));
        }
    } else {
        let (a, b) = (&p.bounds, &q.bounds);
        let overlaps_on = |k: usize| a.min[k] <= b.max[k] && b.min[k] <= a.max[k];
        if overlaps_on((axis + 1) % 3) && overlaps_on((axis + 2) % 3) {
            pairs.remove(CandidatePair::of(p.body, q.body));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad::{CollisionFilter, pairs_brute_force};
    use crate::math::DVec3;
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    use crate::broad::conformance::{self, pairs_of, unit_at};

    /// A body on a quarter-metre grid (ties everywhere), sometimes a point, sometimes huge,
    /// sometimes static, some with filters; `-0.0` coordinates included.
    fn grid_proxy(rng: &mut crate::test_support::TestRng, body: u32) -> Proxy {
        let q = |rng: &mut crate::test_support::TestRng, n: i32| {
            let v = f64::from(rng.random_range(-n..=n)) * 0.25;
            if v == 0.0 && rng.random_bool(0.5) {
                -0.0
            } else {
                v
            }
        };
        let lo = DVec3::new(q(rng, 12), q(rng, 12), q(rng, 4));
        let size = match rng.random_range(0..20) {
            0 => DVec3::ZERO,
            1 => DVec3::splat(8.0),
            _ => DVec3::new(q(rng, 4).abs(), q(rng, 4).abs(), q(rng, 4).abs()),
        };
        Proxy {
            body,
            bounds: Aabb::new(lo, lo + size),
            is_static: rng.random_bool(0.15),
            filter: if rng.random_bool(0.2) {
                CollisionFilter { group: 1, mask: 2 }
            } else {
                CollisionFilter::ALL
            },
        }
    }

    #[test]
    fn built_at_once_it_equals_one_by_one_insertion_and_keeps_working() {
        let mut rng = rng(0xb01c);
        let mut nonempty = 0;
        for scene in 0..40 {
            let proxies: Vec<Proxy> = (0..rng.random_range(0..120))
                .map(|i| grid_proxy(&mut rng, 3 * i + scene))
                .collect();
            let mut built = IncrementalSap::from_proxies(&proxies);
            let mut inserted = IncrementalSap::new();
            for p in &proxies {
                inserted.insert(p.body, p.bounds, p.is_static, p.filter);
            }
            built
                .validate()
                .unwrap_or_else(|e| panic!("scene {scene}: {e}"));
            assert_eq!(
                pairs_of(&mut built),
                pairs_of(&mut inserted),
                "scene {scene}"
            );
            nonempty += usize::from(!pairs_of(&mut built).is_empty());
            // Both keep answering alike through moves, removals and insertions.
            for frame in 0..30 {
                let body = match proxies.get(rng.random_range(0..proxies.len().max(1))) {
                    Some(p) => p.body,
                    None => break,
                };
                if !built.contains(body) {
                    continue;
                }
                match rng.random_range(0..10) {
                    0 => {
                        built.remove(body);
                        inserted.remove(body);
                    }
                    _ => {
                        let p = grid_proxy(&mut rng, body);
                        built.update(body, p.bounds);
                        inserted.update(body, p.bounds);
                    }
                }
                built
                    .validate()
                    .unwrap_or_else(|e| panic!("scene {scene} frame {frame}: {e}"));
                assert_eq!(pairs_of(&mut built), pairs_of(&mut inserted));
            }
        }
        assert!(nonempty > 30, "{nonempty}");
    }

    #[test]
    fn boxes_touching_at_a_face_edge_or_corner_pair_and_a_gap_of_one_ulp_does_not() {
        let mut sap = IncrementalSap::new();
        sap.insert(0, unit_at(0.0, 0.0, 0.0), false, CollisionFilter::ALL);
        sap.insert(1, unit_at(1.0, 0.0, 0.0), false, CollisionFilter::ALL); // face
        sap.insert(2, unit_at(1.0, 1.0, 0.0), false, CollisionFilter::ALL); // edge with 0
        sap.insert(3, unit_at(-1.0, -1.0, -1.0), false, CollisionFilter::ALL); // corner with 0
        let gap = f64::from_bits(1.0f64.to_bits() + 1);
        // Face with 0 and 3, edge with 1, corner with 2.
        sap.insert(4, unit_at(0.0, 0.0, -1.0), false, CollisionFilter::ALL);
        let all = [
            (0, 1),
            (0, 2),
            (0, 3),
            (0, 4),
            (1, 2),
            (1, 4),
            (2, 4),
            (3, 4),
        ];
        assert_eq!(pairs_of(&mut sap), all);
        // One ulp apart: 1 no longer touches 0 and 4; back: touching again (both by swaps).
        sap.update(1, unit_at(gap, 0.0, 0.0));
        assert_eq!(
            pairs_of(&mut sap),
            [(0, 2), (0, 3), (0, 4), (1, 2), (2, 4), (3, 4)]
        );
        sap.update(1, unit_at(1.0, 0.0, 0.0));
        assert_eq!(pairs_of(&mut sap), all);
    }

    #[test]
    fn zero_size_boxes_pair_when_they_coincide_or_lie_on_a_face() {
        let mut sap = IncrementalSap::new();
        let point = |x: f64| Aabb::new(DVec3::splat(x), DVec3::splat(x));
        sap.insert(7, point(0.5), false, CollisionFilter::ALL);
        sap.insert(8, point(0.5), false, CollisionFilter::ALL);
        sap.insert(9, point(1.0), false, CollisionFilter::ALL); // corner of the unit box
        sap.insert(10, point(1.5), false, CollisionFilter::ALL);
        sap.insert(3, unit_at(0.0, 0.0, 0.0), false, CollisionFilter::ALL);
        assert_eq!(pairs_of(&mut sap), [(3, 7), (3, 8), (3, 9), (7, 8)]);
        // Points walking across each other and the box's faces, in exact steps.
        for step in 0..=12 {
            let x = f64::from(step) * 0.125;
            sap.update(10, point(1.5 - x));
            sap.update(7, point(x));
            let mut expected = Vec::new();
            pairs_brute_force(sap.proxies(), &mut expected);
            let mut found = Vec::new();
            sap.pairs(&mut found);
            assert_eq!(found, expected, "step {step}");
            sap.validate().unwrap();
        }
    }

    #[test]
    fn negative_zero_and_zero_tie_as_in_aabb_intersects() {
        let mut sap = IncrementalSap::new();
        let a = Aabb::new(DVec3::splat(-1.0), DVec3::splat(-0.0));
        let b = Aabb::new(DVec3::splat(0.0), DVec3::splat(1.0));
        assert!(a.intersects(&b));
        sap.insert(0, a, false, CollisionFilter::ALL);
        sap.insert(1, b, false, CollisionFilter::ALL);
        assert_eq!(pairs_of(&mut sap), [(0, 1)]);
        // Arriving at the tie by motion rather than by insertion.
        sap.update(1, Aabb::new(DVec3::splat(3.0), DVec3::splat(4.0)));
        assert_eq!(pairs_of(&mut sap), []);
        sap.update(1, b);
        assert_eq!(pairs_of(&mut sap), [(0, 1)]);
    }

    #[test]
    fn a_removed_id_can_be_reinserted_with_new_bounds_kind_and_filter() {
        let mut sap = IncrementalSap::new();
        conformance::removed_ids_come_back_with_new_bounds_kind_and_filter(
            &mut sap,
            unit_at(-9.0, 0.0, 0.0),
        );
        conformance::removing_every_body_empties_it(&mut sap);
    }

    #[test]
    fn static_bodies_never_pair_with_each_other_however_they_overlap() {
        let boxed = |rng: &mut crate::test_support::TestRng| {
            let c = point_in_cube(rng, 1.0);
            Aabb::new(c - DVec3::splat(1.0), c + DVec3::splat(1.0))
        };
        let mut sap = IncrementalSap::new();
        conformance::static_bodies_never_pair_with_each_other(
            &mut sap,
            &mut rng(606),
            40,
            boxed,
            1_000,
        );
    }

    /// Random boxes on an exact grid of 1/4 m (many equal coordinates), moved, teleported,
    /// removed and inserted one at a time; the invariants hold after every operation.
    #[test]
    fn validate_holds_after_every_single_operation_on_a_tie_heavy_grid() {
        let mut rng = rng(707);
        let mut sap = IncrementalSap::new();
        let grid_box = |rng: &mut crate::test_support::TestRng| {
            let lo = DVec3::new(
                f64::from(rng.random_range(-8..8)),
                f64::from(rng.random_range(-8..8)),
                f64::from(rng.random_range(-8..8)),
            ) * 0.25;
            let size = DVec3::new(
                f64::from(rng.random_range(0..5)),
                f64::from(rng.random_range(0..5)),
                f64::from(rng.random_range(0..5)),
            ) * 0.25;
            Aabb::new(lo, lo + size)
        };
        let mut present: Vec<u32> = Vec::new();
        let mut total_pairs = 0;
        for op in 0..3_000 {
            let filter = CollisionFilter {
                group: 1 << rng.random_range(0..2),
                mask: rng.random_range(1..4),
            };
            match rng.random_range(0..10) {
                0 | 1 if present.len() < 40 => {
                    let id = rng.random_range(0..60);
                    let is_static = rng.random_range(0..3) == 0;
                    sap.insert(id, grid_box(&mut rng), is_static, filter);
                    if !present.contains(&id) {
                        present.push(id);
                    }
                }
                2 if !present.is_empty() => {
                    let i = rng.random_range(0..present.len());
                    assert!(sap.remove(present.swap_remove(i)));
                }
                _ if !present.is_empty() => {
                    let id = present[rng.random_range(0..present.len())];
                    sap.update(id, grid_box(&mut rng));
                }
                _ => {}
            }
            sap.validate().unwrap_or_else(|e| panic!("op {op}: {e}"));
            total_pairs += sap.pairs.len();
        }
        assert!(total_pairs > 5_000, "{total_pairs}");
    }
}
