//! Every broad phase against the brute-force oracle over long runs of seeded random
//! *coherent* motion: after every frame its pairs equal [`pairs_brute_force`] over the same
//! boxes exactly (same pairs, same order), and its `validate()` is `Ok`.
//!
//! # Sizes
//! Each broad phase runs 10 scenes of 1,000 frames (10,000 frames), each scene starting
//! with 150 bodies and kept near 150 by random insertions and removals (between about 100
//! and 200). Per frame, a scene-dependent fraction of the dynamic bodies (10 %, 30 % or
//! all) takes a small step; each moving body teleports with probability 1/150, a fifth of
//! those 1,000 m away. Static bodies never move. Debug run time is a few seconds per
//! broad phase (the test profile of this crate is optimized).
//!
//! # Scenes
//! Three layouts, cycled:
//! - *uniform*: continuous random boxes in a 16 m cube, half-extents up to 1.5 m, steps up
//!   to 5 cm;
//! - *dice on a table*: unit dice on a grid of 1/8 m, all sharing the z range `[0, 1]`
//!   (or hopping to `[1/8, 9/8]` and back), resting on a static table slab whose top face
//!   is `z = 0`, so every die touches the table and neighbours touch at faces;
//! - *grid*: every coordinate and size a multiple of 1/4 m, steps of 1/4 m: equal
//!   coordinates and touching boxes everywhere.
//!
//! In every layout some bodies are zero-size (points), about 1 in 100 is huge (half-extents 15 to
//! 40 m, spanning the scene), some are static, and half carry random group/mask filters.
//! Removals, insertions of new ids, re-insertions of removed ids and remove-then-insert of
//! the same id within one frame all happen. The test asserts that each of these scenarios,
//! and pairs being created, destroyed, touching, filtered and static–static suppressed,
//! really occurred.

#[path = "support/mod.rs"]
mod support;

use std::time::Instant;

use proxima::bounding::{Aabb, BoundingVolume};
use proxima::broad::{
    CandidatePair, CollisionFilter, ColumnGrid, HashGrid, IncrementalSap, Proxy, SkinGrid,
    SortAndSweep, pairs_brute_force,
};
use proxima::math::DVec3;
use rand::Rng;
use support::{TestRng, point_in_cube, rng};

/// Frames per scene.
const FRAMES: usize = 1_000;
/// Scenes per broad phase (10 × 1,000 = 10,000 frames).
const SCENES: usize = 10;
/// Bodies each scene starts with and drifts around.
const BODIES: usize = 150;
/// Half-size of the region the scenes live in, metres.
const WORLD: f64 = 8.0;

/// What the harness needs from a broad phase. Stateful broad phases use the body
/// operations; `pairs` also receives the whole proxy list for those that take it.
trait BroadPhase {
    fn insert(&mut self, proxy: &Proxy);
    fn remove(&mut self, body: u32);
    fn update(&mut self, body: u32, bounds: Aabb);
    fn pairs(&mut self, proxies: &[Proxy], out: &mut Vec<CandidatePair>);
    fn validate(&self, proxies: &[Proxy]) -> Result<(), String>;
}

/// The stateful broad phases share one body-level API (`insert`, `remove`, `update`,
/// `pairs`, `validate`, `len`); one adapter serves them all.
macro_rules! stateful_broad_phase {
    ($($phase:ident),+) => {$(
        impl BroadPhase for $phase {
            fn insert(&mut self, p: &Proxy) {
                $phase::insert(self, p.body, p.bounds, p.is_static, p.filter);
            }
            fn remove(&mut self, body: u32) {
                assert!($phase::remove(self, body), "{body} was present");
            }
            fn update(&mut self, body: u32, bounds: Aabb) {
                $phase::update(self, body, bounds);
            }
            fn pairs(&mut self, _: &[Proxy], out: &mut Vec<CandidatePair>) {
                $phase::pairs(self, out);
            }
            fn validate(&self, proxies: &[Proxy]) -> Result<(), String> {
                if self.len() != proxies.len() {
                    return Err(format!(
                        "{} bodies, world has {}",
                        self.len(),
                        proxies.len()
                    ));
                }
                $phase::validate(self)
            }
        }
    )+};
}

stateful_broad_phase!(IncrementalSap, HashGrid, ColumnGrid, SkinGrid);

/// The broad phases that take a frame's moves as one batch.
trait UpdateAll: BroadPhase {
    fn update_all(&mut self, moves: &[(u32, Aabb)]);
}

macro_rules! update_all {
    ($($phase:ident),+) => {$(
        impl UpdateAll for $phase {
            fn update_all(&mut self, moves: &[(u32, Aabb)]) {
                $phase::update_all(self, moves);
            }
        }
    )+};
}

update_all!(ColumnGrid, SkinGrid);

/// A broad phase with a frame's moves gathered and handed over by `update_all`, as the
/// pipeline does: the batch is flushed before any insertion, removal or pair listing.
struct Batched<G> {
    grid: G,
    moves: Vec<(u32, Aabb)>,
}

impl<G: UpdateAll> Batched<G> {
    fn new(grid: G) -> Self {
        Self {
            grid,
            moves: Vec::new(),
        }
    }

    fn flush(&mut self) {
        self.grid.update_all(&self.moves);
        self.moves.clear();
    }
}

impl<G: UpdateAll> BroadPhase for Batched<G> {
    fn insert(&mut self, p: &Proxy) {
        self.flush();
        self.grid.insert(p);
    }
    fn remove(&mut self, body: u32) {
        self.flush();
        self.grid.remove(body);
    }
    fn update(&mut self, body: u32, bounds: Aabb) {
        self.moves.push((body, bounds));
    }
    fn pairs(&mut self, proxies: &[Proxy], out: &mut Vec<CandidatePair>) {
        self.flush();
        BroadPhase::pairs(&mut self.grid, proxies, out);
    }
    fn validate(&self, proxies: &[Proxy]) -> Result<(), String> {
        assert!(self.moves.is_empty(), "validated with moves pending");
        BroadPhase::validate(&self.grid, proxies)
    }
}

impl BroadPhase for SortAndSweep {
    fn insert(&mut self, _: &Proxy) {}
    fn remove(&mut self, _: u32) {}
    fn update(&mut self, _: u32, _: Aabb) {}
    fn pairs(&mut self, proxies: &[Proxy], out: &mut Vec<CandidatePair>) {
        SortAndSweep::pairs(self, proxies, out);
    }
    fn validate(&self, proxies: &[Proxy]) -> Result<(), String> {
        SortAndSweep::validate(self, proxies)
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    Uniform,
    Dice,
    Grid,
}

/// How often each scenario happened over a run.
#[derive(Debug, Default)]
struct Counts {
    frames: usize,
    updates: usize,
    teleports: usize,
    far_teleports: usize,
    insertions: usize,
    reused_ids: usize,
    removals: usize,
    same_frame_reinsertions: usize,
    pairs: usize,
    created: usize,
    destroyed: usize,
    touching: usize,
    zero_size_pairs: usize,
    huge_pairs: usize,
    static_dynamic_pairs: usize,
    static_static_suppressed: usize,
    filter_suppressed: usize,
    empty_frames: usize,
}

/// One scene's bodies and the generator that moves them.
struct World {
    rng: TestRng,
    layout: Layout,
    moving: f64,
    bodies: Vec<Proxy>,
    next_id: u32,
    removed_ids: Vec<u32>,
}

impl World {
    fn filter(&mut self) -> CollisionFilter {
        if self.rng.random_bool(0.5) {
            CollisionFilter::ALL
        } else {
            CollisionFilter {
                group: 1 << self.rng.random_range(0..3),
                mask: self.rng.random_range(1..8),
            }
        }
    }

    /// A grid coordinate: a multiple of `step` in `[-WORLD, WORLD]`.
    fn on_grid(&mut self, step: f64) -> f64 {
        let k = (WORLD / step) as i32;
        f64::from(self.rng.random_range(-k..=k)) * step
    }

    fn new_bounds(&mut self) -> Aabb {
        let r = self.rng.random_range(0..100);
        let (zero, huge) = (r < 10, r >= 99);
        if huge {
            let c = point_in_cube(&mut self.rng, WORLD);
            let h = DVec3::splat(self.rng.random_range(15.0..40.0));
            return Aabb::new(c - h, c + h);
        }
        match self.layout {
            Layout::Uniform => {
                let c = point_in_cube(&mut self.rng, WORLD);
                let h = if zero {
                    DVec3::ZERO
                } else {
                    DVec3::new(
                        self.rng.random_range(0.1..1.5),
                        self.rng.random_range(0.1..1.5),
                        self.rng.random_range(0.1..1.5),
                    )
                };
                Aabb::new(c - h, c + h)
            }
            Layout::Dice => {
                let lo = DVec3::new(self.on_grid(0.125), self.on_grid(0.125), 0.0);
                let size = if zero { DVec3::ZERO } else { DVec3::ONE };
                Aabb::new(lo, lo + size)
            }
            Layout::Grid => {
                let lo = DVec3::new(self.on_grid(0.25), self.on_grid(0.25), self.on_grid(0.25));
                let size = if zero {
                    DVec3::ZERO
                } else {
                    DVec3::new(
                        f64::from(self.rng.random_range(0..6)),
                        f64::from(self.rng.random_range(0..6)),
                        f64::from(self.rng.random_range(0..6)),
                    ) * 0.25
                };
                Aabb::new(lo, lo + size)
            }
        }
    }

    fn new_body(&mut self, counts: &mut Counts) -> Proxy {
        let body = if !self.removed_ids.is_empty() && self.rng.random_bool(0.2) {
            counts.reused_ids += 1;
            let i = self.rng.random_range(0..self.removed_ids.len());
            self.removed_ids.swap_remove(i)
        } else {
            self.next_id += 1;
            self.next_id
        };
        Proxy {
            body,
            bounds: self.new_bounds(),
            is_static: self.rng.random_range(0..100) < 15,
            filter: self.filter(),
        }
    }

    /// A small coherent step for a body, kept inside the world (far teleports come back by
    /// teleporting again).
    fn step(&mut self, bounds: &Aabb) -> DVec3 {
        let mut step = match self.layout {
            Layout::Uniform => point_in_cube(&mut self.rng, 0.05),
            Layout::Dice => {
                let mut s = DVec3::new(
                    f64::from(self.rng.random_range(-1..=1)),
                    f64::from(self.rng.random_range(-1..=1)),
                    0.0,
                ) * 0.125;
                // Hop off the table top and back.
                if self.rng.random_bool(0.1) {
                    s.z = if bounds.min.z == 0.0 {
                        0.125
                    } else {
                        -bounds.min.z
                    };
                }
                s
            }
            Layout::Grid => {
                DVec3::new(
                    f64::from(self.rng.random_range(-1..=1)),
                    f64::from(self.rng.random_range(-1..=1)),
                    f64::from(self.rng.random_range(-1..=1)),
                ) * 0.25
            }
        };
        let c = bounds.center() + step;
        for axis in 0..3 {
            if c[axis].abs() > WORLD + 2.0 && c[axis].abs() < 100.0 {
                step[axis] = -step[axis];
            }
        }
        step
    }

    fn teleport(&mut self, bounds: &Aabb, counts: &mut Counts) -> Aabb {
        counts.teleports += 1;
        let target = if self.rng.random_bool(0.2) {
            counts.far_teleports += 1;
            DVec3::splat(1_000.0) + point_in_cube(&mut self.rng, 1.0)
        } else {
            match self.layout {
                Layout::Uniform => point_in_cube(&mut self.rng, WORLD),
                _ => DVec3::new(self.on_grid(0.25), self.on_grid(0.25), bounds.center().z),
            }
        };
        // Keep exact grid coordinates: move by a grid multiple.
        let offset = target - bounds.min;
        let offset = if self.layout == Layout::Uniform {
            offset
        } else {
            DVec3::new(
                (offset.x * 4.0).round() / 4.0,
                (offset.y * 4.0).round() / 4.0,
                (offset.z * 4.0).round() / 4.0,
            )
        };
        let moved = Aabb::new(bounds.min + offset, bounds.max + offset);
        if self.layout == Layout::Dice && bounds.extents().z <= 1.0 {
            // Dice land back on the table.
            Aabb::new(
                DVec3::new(moved.min.x, moved.min.y, bounds.min.z),
                DVec3::new(moved.max.x, moved.max.y, bounds.max.z),
            )
        } else {
            moved
        }
    }
}

/// Drives `broad` through every scene and checks it against brute force after each frame.
fn run(mut make: impl FnMut() -> Box<dyn BroadPhase>, seed: u64) -> Counts {
    let mut counts = Counts::default();
    let (mut found, mut expected, mut previous) = (Vec::new(), Vec::new(), Vec::new());
    for scene in 0..SCENES {
        let mut broad = make();
        let mut world = World {
            rng: rng(seed + scene as u64),
            layout: [Layout::Uniform, Layout::Dice, Layout::Grid][scene % 3],
            moving: [0.1, 0.3, 1.0][(scene + scene / 3) % 3],
            bodies: Vec::new(),
            next_id: 0,
            removed_ids: Vec::new(),
        };
        if world.layout == Layout::Dice {
            let table = Proxy {
                body: 5_000,
                bounds: Aabb::new(
                    DVec3::new(-WORLD - 2.0, -WORLD - 2.0, -1.0),
                    DVec3::new(WORLD + 2.0, WORLD + 2.0, 0.0),
                ),
                is_static: true,
                filter: CollisionFilter::ALL,
            };
            broad.insert(&table);
            world.bodies.push(table);
        }
        for _ in 0..BODIES {
            let p = world.new_body(&mut counts);
            broad.insert(&p);
            world.bodies.push(p);
        }
        previous.clear();
        for frame in 0..FRAMES {
            apply_frame(&mut world, broad.as_mut(), &mut counts);
            broad.pairs(&world.bodies, &mut found);
            pairs_brute_force(&world.bodies, &mut expected);
            assert_eq!(found, expected, "scene {scene} frame {frame}");
            if let Err(e) = broad.validate(&world.bodies) {
                panic!("scene {scene} frame {frame}: {e}");
            }
            tally(&world.bodies, &expected, &previous, &mut counts);
            std::mem::swap(&mut previous, &mut expected);
        }
    }
    counts
}

/// One frame of motion, teleports, removals and insertions, applied to the world and the
/// broad phase alike.
fn apply_frame(world: &mut World, broad: &mut dyn BroadPhase, counts: &mut Counts) {
    counts.frames += 1;
    for i in 0..world.bodies.len() {
        let p = world.bodies[i];
        if p.is_static || !world.rng.random_bool(world.moving) {
            continue;
        }
        let bounds = if world.rng.random_range(0..150) == 0 || p.bounds.min.x > 500.0 {
            world.teleport(&p.bounds, counts)
        } else {
            let s = world.step(&p.bounds);
            Aabb::new(p.bounds.min + s, p.bounds.max + s)
        };
        world.bodies[i].bounds = bounds;
        broad.update(p.body, bounds);
        counts.updates += 1;
    }
    if world.rng.random_bool(0.15) && !world.bodies.is_empty() {
        let i = world.rng.random_range(0..world.bodies.len());
        let p = world.bodies.swap_remove(i);
        broad.remove(p.body);
        world.removed_ids.push(p.body);
        counts.removals += 1;
    }
    let below = world.bodies.len() < BODIES;
    if world.rng.random_bool(if below { 0.2 } else { 0.1 }) {
        let p = world.new_body(counts);
        broad.insert(&p);
        world.bodies.push(p);
        counts.insertions += 1;
    }
    if world.rng.random_bool(0.02) && !world.bodies.is_empty() {
        // The same id out and back in within one frame, as a new body.
        let i = world.rng.random_range(0..world.bodies.len());
        let body = world.bodies[i].body;
        broad.remove(body);
        let fresh = world.new_body(counts);
        let p = Proxy { body, ..fresh };
        world.removed_ids.push(fresh.body); // unused: free again
        broad.insert(&p);
        world.bodies[i] = p;
        counts.same_frame_reinsertions += 1;
    }
}

/// Counts the scenarios this frame's expected pairs and boxes show.
fn tally(bodies: &[Proxy], expected: &[CandidatePair], previous: &[CandidatePair], c: &mut Counts) {
    c.pairs += expected.len();
    c.empty_frames += usize::from(expected.is_empty());
    c.created += expected
        .iter()
        .filter(|p| previous.binary_search(p).is_err())
        .count();
    c.destroyed += previous
        .iter()
        .filter(|p| expected.binary_search(p).is_err())
        .count();
    for (i, p) in bodies.iter().enumerate() {
        for q in &bodies[i + 1..] {
            if !p.bounds.intersects(&q.bounds) {
                continue;
            }
            if p.is_static && q.is_static {
                c.static_static_suppressed += 1;
                continue;
            }
            if !p.filter.allows(&q.filter) {
                c.filter_suppressed += 1;
                continue;
            }
            let touching = (0..3)
                .any(|k| p.bounds.min[k] == q.bounds.max[k] || q.bounds.min[k] == p.bounds.max[k]);
            c.touching += usize::from(touching);
            let zero = |b: &Aabb| b.extents() == DVec3::ZERO;
            c.zero_size_pairs += usize::from(zero(&p.bounds) || zero(&q.bounds));
            let huge = |b: &Aabb| b.extents().min_element() >= 30.0;
            c.huge_pairs += usize::from(huge(&p.bounds) || huge(&q.bounds));
            c.static_dynamic_pairs += usize::from(p.is_static != q.is_static);
        }
    }
}

/// Every scenario the harness claims to exercise happened.
fn assert_scenarios_happened(c: &Counts) {
    assert_eq!(c.frames, SCENES * FRAMES);
    let happened = [
        ("updates", c.updates),
        ("teleports", c.teleports),
        ("far teleports", c.far_teleports),
        ("insertions", c.insertions),
        ("reused ids", c.reused_ids),
        ("removals", c.removals),
        ("same-frame reinsertions", c.same_frame_reinsertions),
        ("pairs", c.pairs),
        ("pairs created", c.created),
        ("pairs destroyed", c.destroyed),
        ("touching pairs", c.touching),
        ("zero-size pairs", c.zero_size_pairs),
        ("huge-body pairs", c.huge_pairs),
        ("static-dynamic pairs", c.static_dynamic_pairs),
        ("static-static suppressed", c.static_static_suppressed),
        ("filter suppressed", c.filter_suppressed),
    ];
    for (name, count) in happened {
        assert!(count > 0, "{name} never happened: {c:?}");
    }
    assert!(
        c.teleports > 1_000 && c.created > 10_000 && c.touching > 10_000,
        "{c:?}"
    );
}

#[test]
fn incremental_sap_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(IncrementalSap::new()), 6_000);
    eprintln!("incremental sap: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}

#[test]
fn sort_and_sweep_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(SortAndSweep::new()), 6_100);
    eprintln!("sort and sweep: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}

#[test]
fn hash_grid_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(HashGrid::new()), 6_200);
    eprintln!("hash grid: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}

#[test]
fn column_grid_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(ColumnGrid::new()), 6_300);
    eprintln!("column grid: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}

#[test]
fn column_grid_with_batched_moves_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(Batched::new(ColumnGrid::new())), 6_400);
    eprintln!("column grid, batched: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}

#[test]
fn skin_grid_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(SkinGrid::new()), 6_500);
    eprintln!("skin grid: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}

#[test]
fn skin_grid_with_batched_moves_equals_brute_force_after_every_one_of_ten_thousand_frames() {
    let start = Instant::now();
    let counts = run(|| Box::new(Batched::new(SkinGrid::new())), 6_600);
    eprintln!("skin grid, batched: {counts:?} in {:?}", start.elapsed());
    assert_scenarios_happened(&counts);
}
