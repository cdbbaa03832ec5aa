//! Frames of `falling_bodies`' scene while its bodies fall: 300 spheres, capsules, boxes
//! and 256-triangle tori dropped into an 8 m bin, each frame whole, as the daemon answers it.
//!
//! # The frames
//! The scene of `examples/scenes/falling.rs` is dropped in-process at [`RATE_HZ`], each
//! frame a `CLOSE | CONTACTS` step without a budget whose contacts the point-mass solver of
//! `examples/scenes/point_mass.rs` bounces the bodies with, as `falling_bodies` does through
//! the daemon. The moving bodies' poses of the [`FALLING`] frames are kept: the stretch of
//! the drop in which most bodies move and land on one another.
//!
//! Answers that differ by rounding (the witnesses of tied closest pairs) steer a drop
//! differently, so two builds drop different frames. With `FALLING_POSES=FILE` the frames
//! are read from `FILE` when it exists, else dropped and written there: two builds run on
//! one file time the same frames.
//!
//! # What is measured (group `falling`)
//! - `proxima/frame-falling`: one whole step (broad phase, narrow phase, contacts) per
//!   iteration over the [`FALLING`] frames in order, on one thread;
//! - `proxima/frame-falling-pool`: the same with the daemon's workspace, a worker pool of
//!   one (its worker takes mesh pairs and tree walks, its helper convex pairs).
//!
//! Before timing, the frames are stepped once more in a plain loop on each workspace and the
//! distribution of the frame times printed (p50, p95, p99, max). Then the cost per pair
//! kind on frame [`KIND_FRAME`] (`falling: cost per pair kind`): for each pair of kinds
//! (the bin's floor and walls as `wall`) and outcome (apart beyond the margins, close
//! within them, touching), its pairs and the median over [`KIND_ROUNDS`] rounds of the
//! dispatcher's distance, exact up to the margins, and manifold (touching pairs), in µs in
//! all and per pair, as the pipeline asks them of a pair answered afresh. Mesh–mesh pairs
//! get the dispatcher's exact distance there, not the pipeline's (which proves most of
//! them apart by their hulls first).
//!
//! `cargo bench --bench falling`; names are `falling/proxima/<what>`.

#[path = "common/cycle.rs"]
mod cycle;
#[path = "../examples/scenes/falling.rs"]
// The bin's size is the example's.
#[allow(dead_code)]
mod falling;
#[path = "../examples/scenes/point_mass.rs"]
mod point_mass;
#[path = "common/simulated.rs"]
mod simulated;
// The daemon-facing half (registration over the protocol) is not used here.
#[path = "../examples/scenes/spec.rs"]
#[allow(dead_code)]
mod spec;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cycle::cycle_bench;
use falling::{falling_scene, falling_world};
use proxima::broad::CandidatePair;
use proxima::broad::brute_force::pairs_brute_force;
use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::{Manifold, Shape};
use proxima::pipeline::{Completeness, FrameResults, PipelineWorkspace, Query, WorkerPool, step};
use proxima::scene::{BodyId, Scene};
use simulated::{PoseSet, set_poses, simulate};
use std::collections::BTreeMap;
use std::hint::black_box;
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// `falling_bodies`' frame rate, Hz.
const RATE_HZ: f64 = 120.0;
/// The frames kept: 0.5–4.5 s of the drop, from the first landings until most bodies
/// rest.
const FALLING: std::ops::Range<usize> = 60..540;
/// The frame whose cost per pair kind is printed (2 s into the drop).
const KIND_FRAME: usize = 240;
const _: () = assert!(FALLING.start <= KIND_FRAME && KIND_FRAME < FALLING.end);
/// What every frame asks, as `falling_bodies` does.
const QUERY: Query = Query::CLOSE.union(Query::CONTACTS);
/// Falling bodies, as `falling_bodies` drops by default.
const BODIES: usize = 300;
/// Rounds of the per-kind timing loop; each figure is the median round.
const KIND_ROUNDS: usize = 21;

/// Drops the scene and keeps the [`FALLING`] frames' poses.
fn drop_bodies() -> (Scene, Vec<PoseSet>) {
    let spec = falling_scene(BODIES);
    let mut scene = spec.local_scene().expect("the falling scene is valid");
    let ids: Vec<u32> = (0..spec.bodies.len())
        .map(|i| u32::try_from(i).expect("few bodies"))
        .collect();
    let mut world = falling_world(&spec, &ids);
    let mut frames = simulate(&mut world, &mut scene, RATE_HZ, QUERY, FALLING.end);
    println!(
        "falling: {BODIES} bodies at {RATE_HZ} Hz, frames {}–{} kept; {} at rest at the end",
        FALLING.start,
        FALLING.end - 1,
        world.resting()
    );
    (scene, frames.split_off(FALLING.start))
}

/// The frames of `path` when it exists, else dropped here and written there (module docs).
fn frames_at(path: &Path) -> (Scene, Vec<PoseSet>) {
    let Ok(text) = std::fs::read_to_string(path) else {
        let (scene, frames) = drop_bodies();
        let mut text = String::new();
        for frame in &frames {
            for (id, pose) in frame {
                let (p, q) = (pose.position, pose.rotation);
                let values = [p.x, p.y, p.z, q.x, q.y, q.z, q.w].map(|v| format!("{v:e}"));
                text += &format!("{} {}\n", id.0, values.join(" "));
            }
            text += "\n";
        }
        std::fs::write(path, text).expect("the pose file is writable");
        println!("falling: frames written to {}", path.display());
        return (scene, frames);
    };
    let pose = |line: &str| {
        let v: Vec<f64> = (line.split(' ').map(|x| x.parse().expect("a number"))).collect();
        let (position, rotation) = (
            DVec3::new(v[1], v[2], v[3]),
            DQuat::from_xyzw(v[4], v[5], v[6], v[7]),
        );
        let id = BodyId(u32::try_from(v[0] as u64).expect("a body id"));
        (id, Pose::try_new(position, rotation).expect("a valid pose"))
    };
    let frames = (text.split("\n\n").filter(|f| !f.trim().is_empty()))
        .map(|frame| frame.lines().map(pose).collect())
        .collect();
    println!("falling: frames read from {}", path.display());
    let scene = (falling_scene(BODIES).local_scene()).expect("the falling scene is valid");
    (scene, frames)
}

/// Steps every frame of `frames` once in order and prints the distribution of the frame
/// times.
fn print_frame_times(
    name: &str,
    scene: &mut Scene,
    frames: &[PoseSet],
    workspace: &mut PipelineWorkspace,
) {
    let mut results = FrameResults::default();
    let mut exact = 0;
    let mut times: Vec<f64> = frames
        .iter()
        .map(|poses| {
            set_poses(scene, poses);
            let start = Instant::now();
            let report = step(scene, QUERY, workspace, &mut results);
            let us = start.elapsed().as_secs_f64() * 1e6;
            scene.end_frame();
            exact += usize::from(report.completeness == Completeness::Exact);
            us
        })
        .collect();
    times.sort_by(f64::total_cmp);
    let at = |q: f64| times[((times.len() - 1) as f64 * q).round() as usize];
    println!(
        "falling: proxima/{name}: frame µs p50 {:.0}  p95 {:.0}  p99 {:.0}  max {:.0}  \
         ({exact} of {} exact)",
        at(0.5),
        at(0.95),
        at(0.99),
        at(1.0),
        times.len()
    );
}

/// Name of a shape's kind in the per-kind table: the bin's boxes (a side over 1 m) are
/// walls.
fn kind_name(shape: &Shape) -> &'static str {
    match shape {
        Shape::Sphere(_) => "sphere",
        Shape::Capsule(_) => "capsule",
        Shape::Cuboid(c) if c.half_extents.max_element() > 1.0 => "wall",
        Shape::Cuboid(_) => "box",
        Shape::Mesh(_) => "torus",
        Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_) | Shape::Compound(_) => "other",
    }
}

/// The median over [`KIND_ROUNDS`] rounds of `work`'s time, µs.
fn median_us(mut work: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..KIND_ROUNDS)
        .map(|_| {
            let start = Instant::now();
            work();
            start.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[KIND_ROUNDS / 2]
}

/// What the per-kind table adds up for one kind pair and outcome.
#[derive(Default)]
struct KindCost {
    pairs: usize,
    distance_us: f64,
    manifold_us: f64,
}

/// Prints the cost per pair kind and outcome of `scene`'s candidate pairs (module docs).
fn print_kind_costs(scene: &Scene) {
    let (mut proxies, mut candidates) = (Vec::new(), Vec::new());
    scene.proxies(&mut proxies);
    pairs_brute_force(&proxies, &mut candidates);
    let (mut scratch, mut manifold) = (NarrowScratch::default(), Manifold::default());
    let mut table: BTreeMap<(&str, &str, &str), KindCost> = BTreeMap::new();
    for &CandidatePair { a, b } in &candidates {
        let body = |id| scene.body(BodyId(id)).expect("a candidate's body");
        let (ba, bb) = (body(a), body(b));
        let shape = |id| scene.shape(id).expect("a body's shape");
        let (sa, sb) = (shape(ba.shape), shape(bb.shape));
        let pose_ab = Pose::relative(&ba.pose, &bb.pose);
        let margins = ba.margin + bb.margin;
        let d = dispatch::distance(sa, sb, &pose_ab, margins, &mut scratch);
        let distance_us = median_us(|| {
            black_box(dispatch::distance(
                sa,
                sb,
                black_box(&pose_ab),
                margins,
                &mut scratch,
            ));
        });
        let touching = d.distance <= 0.0;
        let manifold_us = if touching {
            median_us(|| {
                dispatch::manifold(sa, sb, black_box(&pose_ab), &d, &mut scratch, &mut manifold);
                black_box(manifold.len());
            })
        } else {
            0.0
        };
        let outcome = match d.distance {
            d if d <= 0.0 => "touch",
            d if d <= margins => "close",
            _ => "apart",
        };
        let (ka, kb) = (kind_name(sa), kind_name(sb));
        let kinds = if ka <= kb { (ka, kb) } else { (kb, ka) };
        let cost = table.entry((kinds.0, kinds.1, outcome)).or_default();
        cost.pairs += 1;
        cost.distance_us += distance_us;
        cost.manifold_us += manifold_us;
    }
    println!(
        "falling: cost per pair kind, frame {KIND_FRAME} (median of {KIND_ROUNDS} rounds; µs \
         in all / per pair)"
    );
    let per = |total: f64, count: usize| total / count.max(1) as f64;
    for ((ka, kb, outcome), cost) in &table {
        println!(
            "falling: {:<16} {outcome:<6} {:>5} | distance {:>7.1} / {:>6.2} | manifold {:>7.1} \
             / {:>6.2}",
            format!("{ka}-{kb}"),
            cost.pairs,
            cost.distance_us,
            per(cost.distance_us, cost.pairs),
            cost.manifold_us,
            per(cost.manifold_us, cost.pairs),
        );
    }
}

fn bench_falling(c: &mut Criterion) {
    let (mut scene, frames) = match std::env::var_os("FALLING_POSES") {
        Some(path) => frames_at(Path::new(&path)),
        None => drop_bodies(),
    };
    set_poses(&mut scene, &frames[KIND_FRAME - FALLING.start]);
    print_kind_costs(&scene);
    let mut group = c.benchmark_group("falling");
    for (name, mut workspace) in [
        ("frame-falling", PipelineWorkspace::default()),
        (
            "frame-falling-pool",
            PipelineWorkspace::with_workers(Arc::new(WorkerPool::new(1))),
        ),
    ] {
        print_frame_times(name, &mut scene, &frames, &mut workspace);
        let mut results = FrameResults::default();
        cycle_bench(
            &mut group,
            BenchmarkId::new("proxima", name),
            &frames,
            |_, poses| {
                set_poses(&mut scene, poses);
                let report = step(&scene, QUERY, &mut workspace, &mut results);
                scene.end_frame();
                f64::from(report.contacts)
            },
        );
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // A frame takes milliseconds: fewer samples keep the run to about a minute.
    config = Criterion::default().sample_size(20);
    targets = bench_falling
}
criterion_main!(benches);
