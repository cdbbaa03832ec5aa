//! One stateful broad phase of any kind behind one API ([`BroadPhase`]).
//!
//! [`BroadPhase`] holds one of the five broad phases ([`BroadPhaseKind`]) and gives them the
//! same body-level API: [`insert`](BroadPhase::insert), [`update`](BroadPhase::update),
//! [`remove`](BroadPhase::remove), [`pairs`](BroadPhase::pairs). Every kind sits behind
//! the crate's `StatefulBroadPhase` trait (`stateful.rs`), over the one body table they
//! share: the stateful [`IncrementalSap`], [`HashGrid`], [`ColumnGrid`] and [`SkinGrid`] as
//! they are; the stateless [`SortAndSweep`] through a wrapper that keeps the body table and
//! sweeps its proxy list in [`pairs`](BroadPhase::pairs). One match dispatches each call
//! statically. Every kind reports exactly the pairs of [`pairs_brute_force`] over its
//! bodies, in `(a, b)` order.
//!
//! Beside the kind, it keeps each body's static flag and filter (so [`set`](BroadPhase::set)
//! tells a move from a replacement) and measures the moves ([`MoveCounts`]) the choice of
//! kind reads.

use super::body_map::{Bodies, BodyMap};
use super::select::MoveCounts;
use super::stateful::StatefulBroadPhase;
#[cfg(doc)]
use super::{BroadPhaseStats, choose};
use super::{
    CandidatePair, CollisionFilter, ColumnGrid, HashGrid, IncrementalSap, Proxy, SkinGrid,
    SortAndSweep, pairs_brute_force,
};
use crate::bounding::Aabb;

/// Bodies up to which the [`SortAndSweep`] kind tests every pair instead of sweeping: the
/// sweep's fixed cost (the axis, the column grid, listing the columns) exceeds `n²/2` box
/// tests there.
pub const ALL_PAIRS_MAX: usize = 32;

/// Which broad-phase algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BroadPhaseKind {
    /// One-axis sort and sweep over the whole proxy list each frame ([`SortAndSweep`]).
    SortAndSweep,
    /// Incremental three-axis sweep and prune ([`IncrementalSap`]).
    IncrementalSap,
    /// Hierarchical hash grid ([`HashGrid`]).
    HashGrid,
    /// Hierarchical grid of sorted columns ([`ColumnGrid`]).
    ColumnGrid,
    /// The column grid over skin-grown boxes, with each body's neighbours listed
    /// ([`SkinGrid`]).
    SkinGrid,
}

impl BroadPhaseKind {
    /// Every kind.
    pub const ALL: [Self; 5] = [
        Self::SortAndSweep,
        Self::IncrementalSap,
        Self::HashGrid,
        Self::ColumnGrid,
        Self::SkinGrid,
    ];
}

/// Which broad phase a scene runs: chosen from measured statistics, or fixed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum BroadPhaseChoice {
    /// [`choose`] from [`BroadPhaseStats`] measured on the scene.
    #[default]
    Auto,
    /// Always this one.
    Fixed(BroadPhaseKind),
}

/// Per-body record of [`BroadPhase`]: what `update` must not change, and the box its moves
/// are measured from.
#[derive(Debug, Clone, Copy)]
struct Entry {
    is_static: bool,
    filter: CollisionFilter,
    /// Its box, to measure its moves ([`BroadPhase::take_move_counts`]).
    bounds: Aabb,
}

impl Entry {
    /// Keeps the body's new box, its move counted in `counts`
    /// ([`BroadPhase::take_move_counts`]).
    fn note_move(&mut self, bounds: Aabb, counts: &mut MoveCounts) {
        counts.add(&self.bounds, &bounds);
        self.bounds = bounds;
    }
}

/// The stateless [`SortAndSweep`] over the shared body table, handed the whole proxy list
/// in `pairs` (up to [`ALL_PAIRS_MAX`] bodies, every pair tested instead).
#[derive(Debug, Clone, Default)]
struct Sweep {
    bodies: Bodies,
    sweep: SortAndSweep,
    /// Whether `sweep`'s kept order matches the proxies (no change since the last `pairs`).
    swept: bool,
}

impl StatefulBroadPhase for Sweep {
    fn bodies(&self) -> &Bodies {
        &self.bodies
    }

    fn bodies_mut(&mut self) -> &mut Bodies {
        &mut self.bodies
    }

    fn file(&mut self, _slot: usize) {
        self.swept = false;
    }

    fn unfile(&mut self, _slot: usize) {
        self.swept = false;
    }

    /// Nothing to rename: the sweep's kept order is re-keyed by its next pass.
    fn swap_remove_slot(&mut self, _slot: usize) {}

    fn relocate(&mut self, slot: usize, bounds: Aabb) {
        self.bodies.proxies[slot].bounds = bounds;
        self.swept = false;
    }

    fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        if self.bodies.len() <= ALL_PAIRS_MAX {
            pairs_brute_force(&self.bodies.proxies, out);
            self.swept = false;
        } else {
            self.sweep.pairs(&self.bodies.proxies, out);
            self.swept = true;
        }
    }

    /// The body table, and the sweep's kept order when no body changed since the last
    /// `pairs`.
    fn validate(&self) -> Result<(), String> {
        self.bodies.check()?;
        if self.swept {
            self.sweep.validate(&self.bodies.proxies)
        } else {
            Ok(())
        }
    }
}

/// The kind a [`BroadPhase`] holds; every variant is a [`StatefulBroadPhase`].
#[derive(Debug, Clone)]
enum Inner {
    /// Boxed, as `Skin`: its scratch is a dozen vectors.
    Sweep(Box<Sweep>),
    Sap(IncrementalSap),
    Grid(HashGrid),
    Columns(ColumnGrid),
    /// Boxed: it holds a column grid and its own tables besides.
    Skin(Box<SkinGrid>),
}

/// Evaluates `$body` with `$k` bound to the kind `$inner` holds: the one match over the
/// kinds, each arm statically dispatched through [`StatefulBroadPhase`].
macro_rules! with_kind {
    ($inner:expr, $k:ident => $body:expr) => {
        match $inner {
            Inner::Sweep($k) => $body,
            Inner::Sap($k) => $body,
            Inner::Grid($k) => $body,
            Inner::Columns($k) => $body,
            Inner::Skin($k) => $body,
        }
    };
}

/// One broad phase of any [`BroadPhaseKind`] behind one stateful API over bodies identified
/// by `u32` ids (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct BroadPhase {
    inner: Inner,
    entries: BodyMap<Entry>,
    /// Updates since the last [`take_move_counts`](Self::take_move_counts).
    counts: MoveCounts,
    /// [`set_all`](Self::set_all)'s batch of plain moves.
    batch: Vec<(u32, Aabb)>,
}

impl BroadPhase {
    /// An empty broad phase of kind `kind`.
    #[must_use]
    pub fn new(kind: BroadPhaseKind) -> Self {
        let inner = match kind {
            BroadPhaseKind::SortAndSweep => Inner::Sweep(Box::default()),
            BroadPhaseKind::IncrementalSap => Inner::Sap(IncrementalSap::new()),
            BroadPhaseKind::HashGrid => Inner::Grid(HashGrid::new()),
            BroadPhaseKind::ColumnGrid => Inner::Columns(ColumnGrid::new()),
            BroadPhaseKind::SkinGrid => Inner::Skin(Box::new(SkinGrid::new())),
        };
        Self {
            inner,
            entries: BodyMap::default(),
            counts: MoveCounts::default(),
            batch: Vec::new(),
        }
    }

    /// A broad phase of kind `kind` holding `proxies` (distinct ids). The incremental sweep
    /// and prune is built at once ([`IncrementalSap::from_proxies`]: endpoints sorted once)
    /// rather than by `n` insertions of `O(n)` each, and so are the column grid
    /// ([`ColumnGrid::from_proxies`]: its levels chosen once, from every body) and the skin
    /// grid over it; the others insert one by one.
    #[must_use]
    pub fn from_proxies(kind: BroadPhaseKind, proxies: &[Proxy]) -> Self {
        let mut broad = Self::new(kind);
        broad.inner = match kind {
            BroadPhaseKind::IncrementalSap => Inner::Sap(IncrementalSap::from_proxies(proxies)),
            BroadPhaseKind::ColumnGrid => Inner::Columns(ColumnGrid::from_proxies(proxies)),
            BroadPhaseKind::SkinGrid => Inner::Skin(Box::new(SkinGrid::from_proxies(proxies))),
            BroadPhaseKind::SortAndSweep | BroadPhaseKind::HashGrid => {
                for p in proxies {
                    broad.insert(p.body, p.bounds, p.is_static, p.filter);
                }
                return broad;
            }
        };
        broad.entries.extend(proxies.iter().map(|p| {
            (
                p.body,
                Entry {
                    is_static: p.is_static,
                    filter: p.filter,
                    bounds: p.bounds,
                },
            )
        }));
        broad
    }

    /// Its algorithm.
    #[must_use]
    pub fn kind(&self) -> BroadPhaseKind {
        match self.inner {
            Inner::Sweep(_) => BroadPhaseKind::SortAndSweep,
            Inner::Sap(_) => BroadPhaseKind::IncrementalSap,
            Inner::Grid(_) => BroadPhaseKind::HashGrid,
            Inner::Columns(_) => BroadPhaseKind::ColumnGrid,
            Inner::Skin(_) => BroadPhaseKind::SkinGrid,
        }
    }

    /// Number of bodies.
    #[must_use]
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether there are no bodies.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Whether `body` is in the broad phase.
    #[must_use]
    pub fn contains(&self, body: u32) -> bool {
        self.entries.contains_key(&body)
    }

    /// The bodies as proxies, in no particular order.
    #[must_use]
    pub fn proxies(&self) -> &[Proxy] {
        with_kind!(&self.inner, k => k.proxies())
    }

    /// Adds `body` with its margin-grown world box `bounds` (metres; finite, `min <= max`).
    /// Inserting an id that is already present replaces that body.
    pub fn insert(&mut self, body: u32, bounds: Aabb, is_static: bool, filter: CollisionFilter) {
        if self.contains(body) {
            self.remove(body);
        }
        with_kind!(&mut self.inner, k => k.insert(body, bounds, is_static, filter));
        self.entries.insert(
            body,
            Entry {
                is_static,
                filter,
                bounds,
            },
        );
    }

    /// Removes `body` and its pairs; `false` when it was not present.
    pub fn remove(&mut self, body: u32) -> bool {
        if self.entries.remove(&body).is_none() {
            return false;
        }
        with_kind!(&mut self.inner, k => {
            k.remove(body);
        });
        true
    }

    /// Moves `body`'s box to `bounds` (metres; finite, `min <= max`). Updating a body that is
    /// not present is a contract violation (`debug_assert!`; ignored in release builds).
    pub fn update(&mut self, body: u32, bounds: Aabb) {
        let Some(entry) = self.entries.get_mut(&body) else {
            debug_assert!(false, "update of absent body {body}");
            return;
        };
        entry.note_move(bounds, &mut self.counts);
        with_kind!(&mut self.inner, k => k.update(body, bounds));
    }

    /// The updates since the last call, measured ([`MoveCounts`]); resets them.
    pub fn take_move_counts(&mut self) -> MoveCounts {
        std::mem::take(&mut self.counts)
    }

    /// Brings `proxy.body` in line with `proxy`, whatever its state: inserted when absent,
    /// updated when present with the same static flag and filter, replaced (removed and
    /// inserted) when either changed. Applying it twice is the same as once.
    pub fn set(&mut self, proxy: &Proxy) {
        match self.entries.get(&proxy.body) {
            Some(e) if e.is_static == proxy.is_static && e.filter == proxy.filter => {
                self.update(proxy.body, proxy.bounds);
            }
            _ => self.insert(proxy.body, proxy.bounds, proxy.is_static, proxy.filter),
        }
    }

    /// [`set`](Self::set) of every proxy in `proxies`, the plain moves (same static flag
    /// and filter) handed over as one batch, flushed before any replacement so each kind
    /// sees the same sequence as one `set` at a time: [`ColumnGrid::update_all`] reads all
    /// their records before moving any, [`SkinGrid::update_all`] refiles the bodies that
    /// left their skins as one batch; the other kinds update one by one.
    ///
    /// # Allocation
    /// None once the batch buffer has grown to the largest batch.
    pub fn set_all(&mut self, proxies: &[Proxy]) {
        let mut moves = std::mem::take(&mut self.batch);
        moves.clear();
        for proxy in proxies {
            // One look-up: the check that it is a plain move, and the move's record.
            match self.entries.get_mut(&proxy.body) {
                Some(e) if e.is_static == proxy.is_static && e.filter == proxy.filter => {
                    e.note_move(proxy.bounds, &mut self.counts);
                    moves.push((proxy.body, proxy.bounds));
                }
                _ => {
                    // The batch first: a later move of a replaced body must not undo it.
                    self.update_batch(&moves);
                    moves.clear();
                    self.insert(proxy.body, proxy.bounds, proxy.is_static, proxy.filter);
                }
            }
        }
        self.update_batch(&moves);
        self.batch = moves;
    }

    /// Hands `moves` to the kind (as one batch to those that take one).
    fn update_batch(&mut self, moves: &[(u32, Aabb)]) {
        with_kind!(&mut self.inner, k => k.update_all(moves));
    }

    /// Every pair of bodies whose boxes overlap (touching counts) and that may pair, once
    /// each with `a < b`, in increasing `(a, b)` order, written to `out` (cleared first):
    /// exactly the pairs of [`pairs_brute_force`] over
    /// [`proxies`](Self::proxies) (which the sort-and-sweep kind runs itself up to
    /// [`ALL_PAIRS_MAX`] bodies).
    pub fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        with_kind!(&mut self.inner, k => k.pairs(out));
    }

    /// Checks every invariant: the id map agrees with the wrapped broad phase's bodies (ids,
    /// static flags, filters, slots) and the wrapped broad phase's own `validate` (for sort
    /// and sweep: the kept order, when no body changed since the last [`Self::pairs`]).
    /// `O(n²)` for the stateful kinds: for tests.
    ///
    /// # Errors
    /// A description of the first violated invariant.
    pub fn validate(&self) -> Result<(), String> {
        let proxies = self.proxies();
        if proxies.len() != self.entries.len() {
            return Err(format!(
                "{} proxies, {} entries",
                proxies.len(),
                self.entries.len()
            ));
        }
        for p in proxies {
            let Some(e) = self.entries.get(&p.body) else {
                return Err(format!("body {} has no entry", p.body));
            };
            if e.is_static != p.is_static || e.filter != p.filter {
                return Err(format!("body {}: entry disagrees with its proxy", p.body));
            }
        }
        with_kind!(&self.inner, k => k.validate())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    fn random_bounds(rng: &mut TestRng, spread: f64) -> Aabb {
        crate::broad::conformance::random_box(rng, spread, 12)
    }

    fn random_filter(rng: &mut TestRng) -> CollisionFilter {
        CollisionFilter {
            group: 1 << rng.random_range(0..3),
            mask: rng.random_range(1..8),
        }
    }

    fn shifted(b: &Aabb, d: DVec3) -> Aabb {
        Aabb::new(b.min + d, b.max + d)
    }

    /// Seeded frames of coherent motion with teleports, insertions, removals, re-filtered
    /// and re-flagged bodies (through `set`, and in batches through `set_all` with some
    /// bodies listed twice) and repeated `set`s: every kind reports exactly
    /// brute force's pairs over the bodies it was given, and validates, every frame.
    #[test]
    fn every_kind_reports_brute_force_pairs_over_random_insert_update_remove_frames() {
        for (k, kind) in BroadPhaseKind::ALL.into_iter().enumerate() {
            let mut rng = rng(600 + k as u64);
            let mut ops = [0usize; 6]; // update, insert, remove, set, absent remove, set_all
            let (mut total_pairs, mut empty_frames, mut frames) = (0usize, 0usize, 0usize);
            let (mut expected, mut found) = (Vec::new(), Vec::new());
            for scene in 0..6 {
                let spread = [3.0, 12.0, 40.0][scene % 3];
                let mut truth: Vec<Proxy> = Vec::new();
                let mut next_id = 7u32;
                for _ in 0..rng.random_range(0..120) {
                    truth.push(Proxy {
                        body: next_id,
                        bounds: random_bounds(&mut rng, spread),
                        is_static: rng.random_range(0..4) == 0,
                        filter: random_filter(&mut rng),
                    });
                    next_id += 3;
                }
                // Odd scenes start from a broad phase built at once, even ones by insertion.
                let mut phase = if scene % 2 == 1 {
                    BroadPhase::from_proxies(kind, &truth)
                } else {
                    let mut phase = BroadPhase::new(kind);
                    for p in &truth {
                        phase.insert(p.body, p.bounds, p.is_static, p.filter);
                    }
                    phase
                };
                assert_eq!(phase.kind(), kind);
                for _ in 0..60 {
                    for p in &mut truth {
                        if p.is_static || rng.random_range(0..3) == 0 {
                            continue; // static or resting: not updated
                        }
                        p.bounds = if rng.random_range(0..60) == 0 {
                            random_bounds(&mut rng, spread) // teleport and resize
                        } else {
                            shifted(&p.bounds, point_in_cube(&mut rng, 0.1))
                        };
                        phase.update(p.body, p.bounds);
                        ops[0] += 1;
                    }
                    if rng.random_range(0..4) == 0 {
                        let p = Proxy {
                            body: next_id,
                            bounds: random_bounds(&mut rng, spread),
                            is_static: rng.random_range(0..4) == 0,
                            filter: random_filter(&mut rng),
                        };
                        next_id += 3;
                        phase.insert(p.body, p.bounds, p.is_static, p.filter);
                        truth.push(p);
                        ops[1] += 1;
                    }
                    if rng.random_range(0..4) == 0 && !truth.is_empty() {
                        let p = truth.swap_remove(rng.random_range(0..truth.len()));
                        assert!(phase.remove(p.body));
                        ops[2] += 1;
                    }
                    if rng.random_range(0..3) == 0 && !truth.is_empty() {
                        let i = rng.random_range(0..truth.len());
                        let p = &mut truth[i];
                        match rng.random_range(0..3) {
                            0 => p.filter = random_filter(&mut rng),
                            1 => p.is_static = !p.is_static,
                            _ => p.bounds = shifted(&p.bounds, point_in_cube(&mut rng, 1.0)),
                        }
                        phase.set(p);
                        phase.set(p); // idempotent
                        ops[3] += 1;
                    }
                    if rng.random_range(0..3) == 0 && !truth.is_empty() {
                        // A batch of moves, re-filters and re-flags, some bodies listed
                        // with an older state first: the last state of each counts.
                        let mut batch = Vec::new();
                        for _ in 0..rng.random_range(1..8) {
                            let i = rng.random_range(0..truth.len());
                            if rng.random_range(0..4) == 0 {
                                let older = truth[i].bounds;
                                batch.push(Proxy {
                                    bounds: shifted(&older, point_in_cube(&mut rng, 2.0)),
                                    ..truth[i]
                                });
                            }
                            let p = &mut truth[i];
                            match rng.random_range(0..5) {
                                0 => p.filter = random_filter(&mut rng),
                                1 => p.is_static = !p.is_static,
                                _ => p.bounds = shifted(&p.bounds, point_in_cube(&mut rng, 0.3)),
                            }
                            batch.push(*p);
                        }
                        phase.set_all(&batch);
                        ops[5] += 1;
                    }
                    if rng.random_range(0..10) == 0 {
                        assert!(!phase.remove(1)); // ids are 7 + 3k: never present
                        ops[4] += 1;
                    }
                    pairs_brute_force(&truth, &mut expected);
                    phase.pairs(&mut found);
                    assert_eq!(found, expected, "{kind:?} scene {scene} frame {frames}");
                    assert_eq!(phase.len(), truth.len());
                    phase.validate().unwrap();
                    total_pairs += expected.len();
                    empty_frames += usize::from(expected.is_empty());
                    frames += 1;
                }
            }
            assert!(
                total_pairs > 5_000 && empty_frames > 0 && ops.iter().all(|&n| n > 5),
                "{kind:?}: pairs {total_pairs}, empty frames {empty_frames}, ops {ops:?}"
            );
        }
    }

    #[test]
    fn far_moves_are_jumps_beyond_the_box_size_shifts_are_relative_and_counts_reset() {
        let mut broad = BroadPhase::new(BroadPhaseKind::HashGrid);
        let unit = |x: f64| Aabb::new(DVec3::new(x, 0.0, 0.0), DVec3::new(x + 1.0, 1.0, 1.0));
        broad.insert(0, unit(0.0), false, CollisionFilter::ALL);
        broad.update(0, unit(0.5)); // half its size: near, shift 0.5
        broad.update(0, unit(1.5)); // exactly its size: near, shift 1
        broad.update(0, unit(2.6)); // beyond: far, shift counted 1
        broad.set(&Proxy {
            body: 0,
            bounds: unit(-10.0),
            is_static: false,
            filter: CollisionFilter::ALL,
        }); // far, through `set`
        broad.update(0, unit(-10.0)); // not moved: shift 0
        let counts = broad.take_move_counts();
        assert_eq!((counts.moves, counts.far_moves), (5, 2));
        assert_eq!(counts.shift_sum, 3.5);
        assert_eq!((counts.far_fraction(), counts.mean_shift()), (0.4, 0.7));
        // Centre distances 0.5, 1, 1.1, 12.6 (through `set`), 0 metres.
        assert!((counts.mean_distance() - 15.2 / 5.0).abs() < 1e-12);
        assert_eq!(broad.take_move_counts(), MoveCounts::default());
        assert_eq!(MoveCounts::default().mean_shift(), 0.0);
        // A point's every move is a full shift; a zero-size box that stays, none.
        let point = |x: f64| Aabb::new(DVec3::splat(x), DVec3::splat(x));
        broad.insert(1, point(0.0), false, CollisionFilter::ALL);
        broad.update(1, point(1e-9));
        broad.update(1, point(1e-9));
        let counts = broad.take_move_counts();
        assert_eq!(
            (counts.moves, counts.far_moves, counts.shift_sum),
            (2, 1, 1.0)
        );
    }
}
