//! One stateful broad phase behind one API, and the choice of which one a scene uses.
//!
//! [`BroadPhase`] holds one of the five broad phases ([`BroadPhaseKind`]) and gives them the
//! same body-level API: [`insert`](BroadPhase::insert), [`update`](BroadPhase::update),
//! [`remove`](BroadPhase::remove), [`pairs`](BroadPhase::pairs). The stateful
//! [`IncrementalSap`], [`HashGrid`], [`ColumnGrid`] and [`SkinGrid`] take it as is; for the stateless [`SortAndSweep`] it
//! keeps the proxy list itself (a dense list with an id → slot map; removal swaps the last
//! proxy into the freed slot, which the sweep's kept order re-keys for free) and sweeps it in
//! [`pairs`](BroadPhase::pairs). Every kind reports exactly the pairs of
//! [`pairs_brute_force`] over its bodies, in `(a, b)` order.
//!
//! [`BroadPhaseStats::measure`] summarises a scene's proxies (body count, fraction moving,
//! spread of sizes, clustering along the sweep axis) and [`choose`] maps the summary to a
//! kind: what a scene with [`BroadPhaseChoice::Auto`] runs.

use super::body_map::BodyMap;
use super::sort_sweep::widest_spread_axis;
use super::{
    CandidatePair, CollisionFilter, ColumnGrid, HashGrid, IncrementalSap, Proxy, SkinGrid,
    SortAndSweep, pairs_brute_force,
};
use crate::bounding::Aabb;

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

/// Per-body record of [`BroadPhase`]: what `update` must not change, and the body's slot in
/// the sort-and-sweep proxy list.
#[derive(Debug, Clone, Copy)]
struct Entry {
    is_static: bool,
    filter: CollisionFilter,
    /// Its box, to measure its moves ([`BroadPhase::take_move_counts`]).
    bounds: Aabb,
    /// Index into [`Sweep::proxies`] (sort and sweep only; 0 otherwise).
    slot: u32,
}

impl Entry {
    /// Keeps the body's new box, its move counted in `counts`
    /// ([`BroadPhase::take_move_counts`]).
    fn note_move(&mut self, bounds: Aabb, counts: &mut MoveCounts) {
        counts.add(&self.bounds, &bounds);
        self.bounds = bounds;
    }
}

/// Sort and sweep with its proxy list.
#[derive(Debug, Clone, Default)]
struct Sweep {
    proxies: Vec<Proxy>,
    sweep: SortAndSweep,
    /// Whether `sweep`'s kept order matches `proxies` (no change since the last `pairs`).
    swept: bool,
}

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
                    slot: 0,
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
        match &self.inner {
            Inner::Sweep(s) => &s.proxies,
            Inner::Sap(s) => s.proxies(),
            Inner::Grid(g) => g.proxies(),
            Inner::Columns(c) => c.proxies(),
            Inner::Skin(c) => c.proxies(),
        }
    }

    /// Adds `body` with its margin-grown world box `bounds` (metres; finite, `min <= max`).
    /// Inserting an id that is already present replaces that body.
    pub fn insert(&mut self, body: u32, bounds: Aabb, is_static: bool, filter: CollisionFilter) {
        if self.contains(body) {
            self.remove(body);
        }
        let mut slot = 0;
        match &mut self.inner {
            Inner::Sweep(s) => {
                debug_assert!(
                    bounds.min.is_finite() && bounds.max.is_finite(),
                    "non-finite bounds {bounds:?}"
                );
                debug_assert!(bounds.min.cmple(bounds.max).all(), "inverted bounds");
                slot = s.proxies.len() as u32;
                s.proxies.push(Proxy {
                    body,
                    bounds,
                    is_static,
                    filter,
                });
                s.swept = false;
            }
            Inner::Sap(s) => s.insert(body, bounds, is_static, filter),
            Inner::Grid(g) => g.insert(body, bounds, is_static, filter),
            Inner::Columns(c) => c.insert(body, bounds, is_static, filter),
            Inner::Skin(c) => c.insert(body, bounds, is_static, filter),
        }
        self.entries.insert(
            body,
            Entry {
                is_static,
                filter,
                bounds,
                slot,
            },
        );
    }

    /// Removes `body` and its pairs; `false` when it was not present.
    pub fn remove(&mut self, body: u32) -> bool {
        let Some(entry) = self.entries.remove(&body) else {
            return false;
        };
        match &mut self.inner {
            Inner::Sweep(s) => {
                let slot = entry.slot as usize;
                s.proxies.swap_remove(slot);
                if let Some(moved) = s.proxies.get(slot) {
                    self.entries
                        .get_mut(&moved.body)
                        .expect("every listed proxy has an entry")
                        .slot = slot as u32;
                }
                s.swept = false;
            }
            Inner::Sap(s) => {
                s.remove(body);
            }
            Inner::Grid(g) => {
                g.remove(body);
            }
            Inner::Columns(c) => {
                c.remove(body);
            }
            Inner::Skin(c) => {
                c.remove(body);
            }
        }
        true
    }

    /// Moves `body`'s box to `bounds` (metres; finite, `min <= max`). Updating a body that is
    /// not present is a contract violation (`debug_assert!`; ignored in release builds).
    pub fn update(&mut self, body: u32, bounds: Aabb) {
        let Some(slot) = self.record_move(body, bounds) else {
            return;
        };
        match &mut self.inner {
            Inner::Sweep(s) => {
                debug_assert!(
                    bounds.min.is_finite()
                        && bounds.max.is_finite()
                        && bounds.min.cmple(bounds.max).all(),
                    "invalid bounds {bounds:?}"
                );
                s.proxies[slot as usize].bounds = bounds;
                s.swept = false;
            }
            Inner::Sap(s) => s.update(body, bounds),
            Inner::Grid(g) => g.update(body, bounds),
            Inner::Columns(c) => c.update(body, bounds),
            Inner::Skin(c) => c.update(body, bounds),
        }
    }

    /// Counts `body`'s move to `bounds` and keeps its box; its sort-and-sweep slot, `None`
    /// (with a `debug_assert!`) when absent.
    fn record_move(&mut self, body: u32, bounds: Aabb) -> Option<u32> {
        let Some(entry) = self.entries.get_mut(&body) else {
            debug_assert!(false, "update of absent body {body}");
            return None;
        };
        entry.note_move(bounds, &mut self.counts);
        Some(entry.slot)
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
    /// and filter) handed over as one batch: [`ColumnGrid::update_all`] reads all their
    /// records before moving any, [`SkinGrid::update_all`] refiles the bodies that left
    /// their skins as one batch; the other kinds update one by one.
    ///
    /// # Allocation
    /// None once the batch buffer has grown to the largest batch.
    pub fn set_all(&mut self, proxies: &[Proxy]) {
        if !matches!(self.inner, Inner::Columns(_) | Inner::Skin(_)) {
            for proxy in proxies {
                self.set(proxy);
            }
            return;
        }
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

    /// Hands `moves` to the kinds that take them as one batch (the others got them one by
    /// one).
    fn update_batch(&mut self, moves: &[(u32, Aabb)]) {
        match &mut self.inner {
            Inner::Columns(c) => c.update_all(moves),
            Inner::Skin(c) => c.update_all(moves),
            Inner::Sweep(_) | Inner::Sap(_) | Inner::Grid(_) => {}
        }
    }

    /// Every pair of bodies whose boxes overlap (touching counts) and that may pair, once
    /// each with `a < b`, in increasing `(a, b)` order, written to `out` (cleared first):
    /// exactly the pairs of [`pairs_brute_force`] over
    /// [`proxies`](Self::proxies) (which the sort-and-sweep kind runs itself up to
    /// [`ALL_PAIRS_MAX`] bodies).
    pub fn pairs(&mut self, out: &mut Vec<CandidatePair>) {
        match &mut self.inner {
            Inner::Sweep(s) if s.proxies.len() <= ALL_PAIRS_MAX => {
                pairs_brute_force(&s.proxies, out);
                s.swept = false;
            }
            Inner::Sweep(s) => {
                s.sweep.pairs(&s.proxies, out);
                s.swept = true;
            }
            Inner::Sap(s) => s.pairs(out),
            Inner::Grid(g) => g.pairs(out),
            Inner::Columns(c) => c.pairs(out),
            Inner::Skin(c) => c.pairs(out),
        }
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
        let sweep = matches!(self.inner, Inner::Sweep(_));
        for (slot, p) in proxies.iter().enumerate() {
            let Some(e) = self.entries.get(&p.body) else {
                return Err(format!("body {} has no entry", p.body));
            };
            if e.is_static != p.is_static || e.filter != p.filter {
                return Err(format!("body {}: entry disagrees with its proxy", p.body));
            }
            if sweep && e.slot as usize != slot {
                return Err(format!(
                    "body {} at slot {slot}, entry says {}",
                    p.body, e.slot
                ));
            }
        }
        match &self.inner {
            Inner::Sweep(s) if s.swept => s.sweep.validate(&s.proxies),
            Inner::Sweep(_) => Ok(()),
            Inner::Sap(s) => s.validate(),
            Inner::Grid(g) => g.validate(),
            Inner::Columns(c) => c.validate(),
            Inner::Skin(c) => c.validate(),
        }
    }
}

/// What the automatic choice looks at, measured on a scene's proxies
/// ([`BroadPhaseStats::measure`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BroadPhaseStats {
    /// Number of bodies.
    pub bodies: usize,
    /// Fraction of the bodies that changed (moved, added, re-filtered) in the measured
    /// frame, in `[0, 1]`; 0 with no bodies.
    pub moving_fraction: f64,
    /// `p90 / p10` of the boxes' largest edge lengths: 1 when all are alike; infinite when
    /// at least 10 % of the boxes are points and some are not; 1 with no bodies or when
    /// both percentiles are 0.
    pub size_spread: f64,
    /// Pairs of boxes whose intervals overlap (touching counts) on the axis where the box
    /// centres spread most, divided by the number of bodies: about the mean number of
    /// neighbours a body's interval meets there, a clustering measure (0 with no bodies).
    pub sweep_overlap_ratio: f64,
    /// Fraction of the recent updates that were far moves ([`MoveCounts`]);
    /// [`measure`](Self::measure) sets 0 (it sees one frame's boxes, not their motion) and
    /// [`with_moves`](Self::with_moves) fills it in from the kept broad phase.
    pub far_move_fraction: f64,
    /// Mean relative shift of the recent updates ([`MoveCounts::mean_shift`]); as
    /// [`far_move_fraction`](Self::far_move_fraction), 0 until
    /// [`with_moves`](Self::with_moves).
    pub mean_shift: f64,
    /// The 75th percentile of the boxes' largest edge lengths, metres: the typical box.
    pub typical_edge: f64,
    /// Mean shift of the recent updates in metres ([`MoveCounts::mean_distance`]) over
    /// [`typical_edge`](Self::typical_edge): how far the bodies move for the typical box
    /// (1 when that box is a point and they move, 0 when they do not). What the rule reads
    /// ([`choose`]); 0 until [`with_moves`](Self::with_moves).
    pub typical_shift: f64,
}

/// What a broad phase's updates were like ([`BroadPhase::take_move_counts`]).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MoveCounts {
    /// Updates counted.
    pub moves: u64,
    /// How many of them were *far moves*: the box's centre moved farther, on some axis,
    /// than the box's largest edge (a jump across its own size, which a sweep and prune
    /// pays for in endpoint swaps with every body passed).
    pub far_moves: u64,
    /// Sum over the updates of the *relative shift*: the farthest the centre moved on one
    /// axis over the box's largest edge, at most 1 (a far move counts 1; so does any move
    /// of a zero-size box).
    pub shift_sum: f64,
    /// Sum over the updates of the farthest the centre moved on one axis, metres.
    pub distance_sum: f64,
}

impl MoveCounts {
    /// Counts the move of a box from `old` to `new`.
    pub fn add(&mut self, old: &Aabb, new: &Aabb) {
        let shift = (((new.min + new.max) - (old.min + old.max)).abs() * 0.5).max_element();
        let edge = (old.max - old.min).max_element();
        self.moves += 1;
        self.far_moves += u64::from(shift > edge);
        self.distance_sum += shift;
        // A far move (a zero-size box's too: `shift / 0` is infinite) counts 1.
        if shift > 0.0 {
            self.shift_sum += (shift / edge).min(1.0);
        }
    }

    /// Fraction of the updates that were far moves; 0 with none.
    #[must_use]
    pub fn far_fraction(&self) -> f64 {
        self.per_move(self.far_moves as f64)
    }

    /// Mean of the farthest the centre moved on one axis per update, metres; 0 with none.
    #[must_use]
    pub fn mean_distance(&self) -> f64 {
        self.per_move(self.distance_sum)
    }

    /// Mean relative shift per update, in `[0, 1]`; 0 with none.
    #[must_use]
    pub fn mean_shift(&self) -> f64 {
        self.per_move(self.shift_sum)
    }

    /// `sum` over the updates counted; 0 with none.
    fn per_move(&self, sum: f64) -> f64 {
        if self.moves == 0 {
            0.0
        } else {
            sum / self.moves as f64
        }
    }
}

impl BroadPhaseStats {
    /// Measures `proxies`, of which `moved` changed this frame (clamped to the count).
    /// `O(n log n)`; allocates two scratch lists.
    ///
    /// Percentiles are nearest-rank on the sorted values: `p_q = v[round(q · (n − 1))]`.
    #[must_use]
    pub fn measure(proxies: &[Proxy], moved: usize) -> Self {
        let n = proxies.len();
        if n == 0 {
            return Self {
                bodies: 0,
                moving_fraction: 0.0,
                size_spread: 1.0,
                sweep_overlap_ratio: 0.0,
                far_move_fraction: 0.0,
                mean_shift: 0.0,
                typical_edge: 0.0,
                typical_shift: 0.0,
            };
        }
        let mut sizes: Vec<f64> = proxies
            .iter()
            .map(|p| (p.bounds.max - p.bounds.min).max_element())
            .collect();
        sizes.sort_unstable_by(f64::total_cmp);
        let percentile = |q: f64| sizes[(q * (n - 1) as f64).round() as usize];
        let (p10, p75, p90) = (percentile(0.1), percentile(0.75), percentile(0.9));
        let size_spread = if p90 == 0.0 { 1.0 } else { p90 / p10 };
        Self {
            bodies: n,
            moving_fraction: moved.min(n) as f64 / n as f64,
            size_spread,
            sweep_overlap_ratio: interval_overlaps(proxies, widest_spread_axis(proxies)) as f64
                / n as f64,
            far_move_fraction: 0.0,
            mean_shift: 0.0,
            typical_edge: p75,
            typical_shift: 0.0,
        }
    }

    /// These statistics with the motion measures taken from a broad phase's `counts`.
    #[must_use]
    pub fn with_moves(self, counts: &MoveCounts) -> Self {
        Self {
            far_move_fraction: counts.far_fraction(),
            mean_shift: counts.mean_shift(),
            typical_shift: {
                let distance = counts.mean_distance();
                if distance == 0.0 {
                    0.0
                } else if self.typical_edge == 0.0 {
                    1.0
                } else {
                    distance / self.typical_edge
                }
            },
            ..self
        }
    }
}

/// Above this fraction of bodies changing per frame, moving faster than [`CREEPING`], the
/// stateless sort and sweep (which costs the same whatever moved) is chosen.
pub const MOSTLY_MOVING: f64 = 0.5;
/// Shift per update for the typical box ([`BroadPhaseStats::typical_shift`]) up to which
/// bodies count as creeping and the skin grid keeps them even when most move: where the
/// skin grid and the sort and sweep cross, on the uniform and the clustered layouts alike.
pub const CREEPING: f64 = 0.011;
/// Above this fraction of far moves among the updates, a scene counts as teleporting: every
/// jump leaves its skin, which costs the skin grid a refiling.
pub const TELEPORTING: f64 = 0.01;
/// Size spread ([`BroadPhaseStats::size_spread`]) above which a scene of fewer than
/// [`FEW_BODIES`] keeps the skin grid even when most of its bodies move fast: fitted to the
/// bench's clustered layout (spread 5.9) against its uniform one (1.5) and its dice (1.0).
pub const WIDE_SIZE_SPREAD: f64 = 4.0;
/// See [`WIDE_SIZE_SPREAD`]: where the two kinds cross on the clustered layout with all
/// bodies moving at full speed.
pub const FEW_BODIES: usize = 6_000;
/// Bodies up to which the [`SortAndSweep`] kind tests every pair instead of sweeping: the
/// sweep's fixed cost (the axis, the column grid, listing the columns) exceeds `n²/2` box
/// tests there.
pub const ALL_PAIRS_MAX: usize = 32;

/// The broad phase a scene with [`BroadPhaseChoice::Auto`] runs, given its statistics:
///
/// 1. more than [`MOSTLY_MOVING`] of the bodies changing per frame, and moving more than
///    [`CREEPING`] for the typical box ([`BroadPhaseStats::typical_shift`]): [`SortAndSweep`],
///    unless the scene has fewer than [`FEW_BODIES`] bodies of sizes spread wider than
///    [`WIDE_SIZE_SPREAD`] and is not teleporting (line 2): then the skin grid;
/// 2. more than [`TELEPORTING`] of the updates far moves: [`ColumnGrid`] (a jump costs it
///    two queries, and always leaves a skin);
/// 3. else [`SkinGrid`].
///
/// The skin grid re-tests a moved body against its few listed neighbours and refiles it only
/// when it leaves its skin: the fastest while few bodies move or they creep. Sort and sweep
/// costs the same whatever moved and wins once most bodies move fast for their size. A
/// teleporting scene has a shift for the typical box far over [`CREEPING`], so when most of
/// its bodies move the first line takes it.
///
/// The [`IncrementalSap`] and the [`HashGrid`] are never chosen: on every measured class one
/// of the three above is faster; they stay available as fixed choices.
/// [`BroadPhaseStats::sweep_overlap_ratio`] is measured and reported
/// ([`StepReport::broad_stats`](crate::pipeline::StepReport)) but not read: no threshold on
/// it picks a faster kind.
///
/// `examples/broad_bench` measures the thresholds: every kind on the same frames of the
/// uniform, clustered and stacked layouts (`--speed-scale` for slower bodies,
/// `--one-at-a-time` for each kind alone on the core).
pub fn choose(stats: &BroadPhaseStats) -> BroadPhaseKind {
    let fast = stats.moving_fraction > MOSTLY_MOVING && stats.typical_shift > CREEPING;
    let teleporting = stats.far_move_fraction > TELEPORTING;
    // Few bodies of widely spread sizes stay in the skin grid, unless teleporting.
    let skin_keeps =
        stats.bodies < FEW_BODIES && stats.size_spread > WIDE_SIZE_SPREAD && !teleporting;
    if fast && !skin_keeps {
        BroadPhaseKind::SortAndSweep
    } else if teleporting {
        BroadPhaseKind::ColumnGrid
    } else {
        BroadPhaseKind::SkinGrid
    }
}

/// Pairs `i < j` whose closed intervals on `axis` overlap, counted without enumerating
/// them: interval `i` meets every `j` whose min is `≤ max_i`, except those whose max is
/// `< min_i` (which also have their min `≤ max_i`).
fn interval_overlaps(proxies: &[Proxy], axis: usize) -> u64 {
    let mut mins: Vec<f64> = proxies.iter().map(|p| p.bounds.min[axis]).collect();
    let mut maxs: Vec<f64> = proxies.iter().map(|p| p.bounds.max[axis]).collect();
    mins.sort_unstable_by(f64::total_cmp);
    maxs.sort_unstable_by(f64::total_cmp);
    let twice: u64 = proxies
        .iter()
        .map(|p| {
            let (lo, hi) = (p.bounds.min[axis], p.bounds.max[axis]);
            let starts_before_end = mins.partition_point(|&m| m <= hi);
            let ends_before_start = maxs.partition_point(|&m| m < lo);
            // Minus itself.
            (starts_before_end - ends_before_start - 1) as u64
        })
        .sum();
    twice / 2
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

    fn cube(body: u32, low: DVec3, edge: f64) -> Proxy {
        Proxy {
            body,
            bounds: Aabb::new(low, low + DVec3::splat(edge)),
            is_static: false,
            filter: CollisionFilter::ALL,
        }
    }

    #[test]
    fn stats_of_an_empty_scene_are_neutral() {
        let stats = BroadPhaseStats::measure(&[], 5);
        assert_eq!(
            stats,
            BroadPhaseStats {
                bodies: 0,
                moving_fraction: 0.0,
                size_spread: 1.0,
                sweep_overlap_ratio: 0.0,
                far_move_fraction: 0.0,
                mean_shift: 0.0,
                typical_edge: 0.0,
                typical_shift: 0.0,
            }
        );
    }

    /// The typical shift is the mean distance moved over the 75th percentile of the largest
    /// edges, whatever each body's own size; 1 for a point-sized typical box that moves.
    #[test]
    fn typical_shift_is_the_mean_distance_over_the_typical_edge() {
        // Largest edges 1, 2, ..., 9: nearest-rank p75 is v[round(0.75 · 8)] = v[6] = 7.
        let proxies: Vec<Proxy> = (1..=9)
            .map(|k| cube(k, DVec3::ZERO, f64::from(k)))
            .collect();
        let stats = BroadPhaseStats::measure(&proxies, 9);
        assert_eq!(stats.typical_edge, 7.0);
        let counts = MoveCounts {
            moves: 4,
            far_moves: 0,
            shift_sum: 0.9,
            distance_sum: 0.56,
        };
        let moved = stats.with_moves(&counts);
        assert!(
            (moved.typical_shift - 0.02).abs() < 1e-15,
            "{}",
            moved.typical_shift
        );
        assert!((moved.mean_shift - 0.225).abs() < 1e-15);
        assert_eq!(stats.with_moves(&MoveCounts::default()).typical_shift, 0.0);
        let points: Vec<Proxy> = (0..4)
            .map(|k| cube(k, DVec3::splat(f64::from(k)), 0.0))
            .collect();
        let still = BroadPhaseStats::measure(&points, 4);
        assert_eq!(still.typical_edge, 0.0);
        assert_eq!(still.with_moves(&counts).typical_shift, 1.0);
    }

    /// A row of unit cubes along y: apart (no overlaps), touching face to face (each meets
    /// its neighbour: 9 pairs), all in one place (45 pairs); measured on y, where the centres
    /// spread, not on x or z, where every interval is the same.
    #[test]
    fn sweep_overlaps_are_counted_on_the_widest_spread_axis_touching_included() {
        let row = |gap: f64| -> Vec<Proxy> {
            (0..10)
                .map(|i| cube(i, DVec3::new(0.0, f64::from(i) * (1.0 + gap), 0.0), 1.0))
                .collect()
        };
        assert_eq!(
            BroadPhaseStats::measure(&row(1.0), 0).sweep_overlap_ratio,
            0.0
        );
        assert_eq!(
            BroadPhaseStats::measure(&row(0.0), 0).sweep_overlap_ratio,
            0.9
        );
        let heap: Vec<Proxy> = (0..10).map(|i| cube(i, DVec3::ZERO, 1.0)).collect();
        assert_eq!(BroadPhaseStats::measure(&heap, 0).sweep_overlap_ratio, 4.5);
        // Dice on a table: a 10 × 10 grid on x, y, all sharing one z range. On z every pair
        // overlaps (4,950); on x (tie with y, the lower axis) each die meets the 9 others of
        // its column and nothing else: 10 · 45 pairs.
        let dice: Vec<Proxy> = (0..100)
            .map(|i| {
                cube(
                    i,
                    DVec3::new(f64::from(i % 10) * 3.0, f64::from(i / 10) * 3.0, 0.0),
                    1.0,
                )
            })
            .collect();
        assert_eq!(BroadPhaseStats::measure(&dice, 0).sweep_overlap_ratio, 4.5);
        assert_eq!(widest_spread_axis(&dice), 0);
        assert_eq!(widest_spread_axis(&row(0.0)), 1);
        // Against a direct count over random boxes.
        let mut rng = rng(611);
        for case in 0..200 {
            let proxies: Vec<Proxy> = (0..rng.random_range(1..60))
                .map(|i| Proxy {
                    body: i,
                    bounds: random_bounds(&mut rng, 5.0),
                    is_static: false,
                    filter: CollisionFilter::ALL,
                })
                .collect();
            let axis = widest_spread_axis(&proxies);
            let mut direct = 0u64;
            for (i, p) in proxies.iter().enumerate() {
                for q in &proxies[i + 1..] {
                    direct += u64::from(
                        p.bounds.min[axis] <= q.bounds.max[axis]
                            && q.bounds.min[axis] <= p.bounds.max[axis],
                    );
                }
            }
            assert_eq!(interval_overlaps(&proxies, axis), direct, "case {case}");
        }
    }

    #[test]
    fn size_spread_is_p90_over_p10_of_the_largest_edges_and_moving_fraction_is_clamped() {
        // Edges 1..=10: p10 = v[round(0.9)] = 2, p90 = v[round(8.1)] = 9.
        let sizes: Vec<Proxy> = (0..10u32)
            .map(|i| cube(i, DVec3::splat(f64::from(i) * 100.0), f64::from(10 - i)))
            .collect();
        let stats = BroadPhaseStats::measure(&sizes, 3);
        assert_eq!(stats.size_spread, 4.5);
        assert_eq!(stats.moving_fraction, 0.3);
        assert_eq!(stats.bodies, 10);
        assert_eq!(BroadPhaseStats::measure(&sizes, 25).moving_fraction, 1.0);
        // The largest edge, not the smallest: flat boxes 4 × 1 × 1 and 1 × 8 × 1 alike.
        let flat = [
            Proxy {
                bounds: Aabb::new(DVec3::ZERO, DVec3::new(4.0, 1.0, 1.0)),
                ..cube(0, DVec3::ZERO, 1.0)
            },
            Proxy {
                bounds: Aabb::new(DVec3::ZERO, DVec3::new(1.0, 8.0, 1.0)),
                ..cube(1, DVec3::ZERO, 1.0)
            },
        ];
        assert_eq!(BroadPhaseStats::measure(&flat, 0).size_spread, 2.0);
        // Points: all points is "alike" (1); mostly points with some boxes is unbounded.
        let points: Vec<Proxy> = (0..10).map(|i| cube(i, DVec3::ZERO, 0.0)).collect();
        assert_eq!(BroadPhaseStats::measure(&points, 0).size_spread, 1.0);
        let mut mixed = points;
        mixed.extend((10..12).map(|i| cube(i, DVec3::ZERO, 1.0)));
        assert_eq!(
            BroadPhaseStats::measure(&mixed, 0).size_spread,
            f64::INFINITY
        );
    }

    #[test]
    fn the_rule_picks_the_measured_fastest_kind_for_each_scene_class() {
        use BroadPhaseKind::{ColumnGrid as Grid, SkinGrid as Skin, SortAndSweep as Sweep};
        // Shifts for the typical box; the per-body mean shift alike (bodies of one size).
        let stats = |bodies, moving_fraction, far_move_fraction, shift| BroadPhaseStats {
            bodies,
            moving_fraction,
            size_spread: 3.0,
            sweep_overlap_ratio: 2.0,
            far_move_fraction,
            mean_shift: shift,
            typical_edge: 1.0,
            typical_shift: shift,
        };
        // The bench's scattered bodies shift about 0.02 of their size a frame, its stacked
        // dice 0.004.
        let cases = [
            // (bodies, moving, far moves, mean shift) → kind, as the table in `choose`
            // measured.
            ((1_000, 0.1, 0.0, 0.02), Skin),
            ((1_000, 0.25, 0.0, 0.02), Skin),
            ((1_000, 0.5, 0.0, 0.02), Skin),
            ((10_000, 0.1, 0.0, 0.02), Skin),
            ((10_000, 0.5, 0.0, 0.02), Skin),
            ((100_000, 0.1, 0.0, 0.02), Skin),
            ((1_000, 0.1, 0.005, 0.02), Skin),
            ((1_000, 0.1, 0.02, 0.03), Grid),
            ((10_000, 0.1, 0.5, 0.6), Grid),
            ((10_000, 0.5, 1.0, 1.0), Grid),
            ((1_000, 0.51, 0.0, 0.02), Sweep),
            ((1_000, 1.0, 0.0, 0.02), Sweep),
            ((100_000, 1.0, 1.0, 1.0), Sweep),
            // Most bodies creeping: the skin grid still.
            ((10_000, 1.0, 0.0, 0.004), Skin),
            ((10_000, 1.0, 0.0, CREEPING), Skin),
            // A scene's first measurement sees no motion.
            ((10_000, 1.0, 0.0, 0.0), Skin),
            ((0, 0.0, 0.0, 0.0), Skin),
        ];
        for ((bodies, moving, far, shift), kind) in cases {
            assert_eq!(
                choose(&stats(bodies, moving, far, shift)),
                kind,
                "{bodies} {moving} {far} {shift}"
            );
        }
        // Fast bodies of widely spread sizes (the bench's clustered layout, spread 5.9):
        // the skin grid below `FEW_BODIES`, unless teleporting; scattered bodies (1.5)
        // take the sort and sweep at every count.
        for ((bodies, spread, far), kind) in [
            ((1_000, 5.9, 0.004), Skin),
            ((5_000, 5.9, 0.009), Skin),
            ((FEW_BODIES, 5.9, 0.009), Sweep),
            ((10_000, 5.9, 0.009), Sweep),
            ((1_000, 5.9, 0.02), Sweep),
            ((1_000, 1.5, 0.0), Sweep),
            ((1_000, WIDE_SIZE_SPREAD, 0.0), Sweep),
        ] {
            let stats = BroadPhaseStats {
                size_spread: spread,
                ..stats(bodies, 1.0, far, 0.047)
            };
            assert_eq!(choose(&stats), kind, "{bodies} {spread} {far}");
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
