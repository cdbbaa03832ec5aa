//! Frames of the settling pile, Proxima against parry3d-f64 0.31 on the same pairs.
//!
//! # The frame
//! The pile of `examples/scenes/pile.rs` (seed [`SEED`]: 100 bodies, spheres, capsules,
//! boxes, cylinders and convex hulls of 20–60 points, 2–7 cm, 5 mm margins, in a 40 cm box
//! of 5 static boxes) is dropped and settled before timing: [`SETTLE_FRAMES`] frames at
//! `PILE_RATE_HZ`, each a `CLOSE | CONTACTS` [`step`] whose contacts the point-mass solver
//! of `examples/scenes/point_mass.rs` bounces the bodies with, as the `pile` scene of
//! `examples/deadline_bench.rs` does through the daemon. The poses of the last two frames
//! (`k` and `k + 1`) and of the [`SETTLING`] frames are kept; the statistics of frame `k`
//! are printed once.
//!
//! # What is measured (group `pile`)
//! - `proxima/frame`: one whole [`step`] (broad phase, narrow phase, contacts) at
//!   `CLOSE | CONTACTS`, after setting every moving body's pose, alternating frames `k` and
//!   `k + 1`. The pipeline keeps the answer of a pair whose two bodies did not move, so
//!   pairs of sleeping bodies are answered from memory, as the daemon answers them on such a
//!   frame; the printed `kept answers` says how many.
//! - `proxima/frame-all-pairs`: the same, alternating frame `k` and frame `k` with every
//!   moving body shifted by [`SHIFT_M`] (the same shift for all, so their relative poses do
//!   not change): every candidate pair is answered afresh each frame.
//! - `proxima/frame-settling`: the same step over the [`SETTLING`] frames of the drop, one
//!   per iteration, in order. Every body moves, so every pair is answered afresh at poses
//!   that change from frame to frame, as in the daemon: these frames make the p99 of
//!   `deadline_bench`'s pile. (The two benches above time a resting frame, and one
//!   frame's pairs answered over and over with warm caches and branch history.)
//! - `proxima/frame-settling-helped`: the same with the daemon's workspace, a worker pool
//!   of one, whose helper thread answers convex pairs on the other core
//!   (`src/pipeline/helper.rs`); the printed `answered by the helper thread` says how many.
//! - `proxima/narrow`: the narrow phase alone on frame `k`'s candidate pairs (the
//!   all-pairs broad phase of `proxima::broad::brute_force`, equal to the pipeline's), as
//!   the pipeline answers a pair: `dispatch::distance` exact up to the two margins, then
//!   `dispatch::manifold` (up to 4 points) when touching.
//! - `proxima/distance`: the same without the manifolds: one signed distance, witness
//!   pair and normal per pair, what `parry/contacts` returns.
//! - `parry/contacts`: `parry3d_f64::query::contact` on the same pairs at the same poses,
//!   with prediction the sum of the two margins (one deepest point per pair). Shapes are
//!   converted once: `Ball`, `Capsule::new_z`, `Cuboid`, `Cylinder` turned from parry's
//!   Y axis to Proxima's Z axis, `ConvexPolyhedron::from_convex_hull` of the same points.
//!
//! Before timing, both engines answer every candidate pair once and the agreement is
//! printed: the pairs each reports within the prediction and touching, and the largest
//! distance difference where both report one.
//!
//! Then the cost per pair kind (`pile: cost per pair kind`): for each pair of shape kinds
//! (canonical order), its candidate and touching pairs, and the median over
//! [`KIND_ROUNDS`] rounds (a plain `Instant` loop, outside criterion) of Proxima's
//! `distance` on every pair, Proxima's `manifold` on the touching ones (their distance
//! not counted) and parry's `contact` on every pair, in µs in total and per pair, with
//! parry's time over Proxima's (distance plus manifold).
//!
//! `cargo bench --bench pile`; names are `pile/<engine>/<what>`.

#[path = "common/cycle.rs"]
mod cycle;
#[path = "../examples/scenes/pile.rs"]
// The primitive pile is `deadline_bench`'s only.
#[allow(dead_code)]
mod pile;
#[path = "../examples/scenes/point_mass.rs"]
mod point_mass;
// The daemon-facing half (registration over the protocol, meshes) is not used here.
#[path = "../examples/scenes/spec.rs"]
#[allow(dead_code)]
mod spec;

#[path = "common/parry_convert.rs"]
mod parry_convert;
#[path = "common/simulated.rs"]
mod simulated;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use cycle::cycle_bench;
use parry_convert::{parry_cylinder_offset, parry_pose, parry_vector};
use parry3d_f64::math::{Pose as ParryPose, Vector as ParryVector};
use parry3d_f64::shape::SharedShape;
use pile::{PILE_RATE_HZ, pile_scene, pile_world};
use proxima::broad::CandidatePair;
use proxima::broad::brute_force::pairs_brute_force;
use proxima::math::{DVec3, Pose};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::{Manifold, Shape};
use proxima::pipeline::{FrameResults, PipelineWorkspace, Query, WorkerPool, step};
use proxima::scene::{BodyId, Scene};
use proxima_ipc::client::Primitive;
use simulated::{PoseSet, set_poses, simulate};
use spec::{SceneSpec, ShapeSpec};
use std::hint::black_box;
use std::sync::Arc;

/// The pile's seed (the one `examples/deadline_bench.rs` drops).
const SEED: u64 = 29;
/// Frames simulated before the kept frame `k`: 1.5 s at 240 Hz, when the pile has landed
/// and most bodies rest on others.
const SETTLE_FRAMES: usize = 360;
/// The settling frames `proxima/frame-settling` replays, in order: the frames of the drop
/// when every body moves and the p99 of `deadline_bench`'s pile is made (frames 80–300 of
/// its 1,000).
const SETTLING: std::ops::Range<usize> = 100..300;
const _: () = assert!(
    SETTLING.end <= SETTLE_FRAMES,
    "settling frames are simulated first"
);
/// What every frame asks, as the pile's client does.
const QUERY: Query = Query::CLOSE.union(Query::CONTACTS);
/// Shift of every moving body in `proxima/frame-all-pairs`'s second pose set, metres:
/// enough to change every body's pose, far below any tolerance of the answers.
const SHIFT_M: f64 = 1e-9;

/// The settled pile: the scene at frame `k`, the poses of frames `k` and `k + 1`, and of
/// the [`SETTLING`] frames.
struct Settled {
    spec: SceneSpec,
    scene: Scene,
    frame_k: PoseSet,
    frame_k1: PoseSet,
    settling: Vec<PoseSet>,
}

/// Drops the pile and runs [`SETTLE_FRAMES`] + 2 frames; the scene is left at frame `k`.
fn settle() -> Settled {
    let spec = pile_scene(SEED);
    let mut scene = spec.local_scene().expect("the pile is a valid scene");
    let ids: Vec<u32> = (0..spec.bodies.len())
        .map(|i| u32::try_from(i).expect("few bodies"))
        .collect();
    let mut world = pile_world(&spec, &ids, SEED);
    let mut kept = simulate(
        &mut world,
        &mut scene,
        PILE_RATE_HZ,
        QUERY,
        SETTLE_FRAMES + 2,
    );
    let frame_k1 = kept.pop().expect("two frames kept");
    let frame_k = kept.pop().expect("two frames kept");
    let settling = kept.drain(SETTLING).collect();
    set_poses(&mut scene, &frame_k);
    println!(
        "pile: seed {SEED}, frame {SETTLE_FRAMES} at {PILE_RATE_HZ} Hz: {} bodies, {} at rest",
        scene.body_count(),
        world.resting()
    );
    Settled {
        spec,
        scene,
        frame_k,
        frame_k1,
        settling,
    }
}

/// One candidate pair, in both engines' terms.
struct Pair<'s> {
    shapes: (&'s Shape, &'s Shape),
    poses: (Pose, Pose),
    /// The sum of the two margins, metres: Proxima's reporting limit, parry's prediction.
    margins: f64,
    parry_shapes: (&'s SharedShape, &'s SharedShape),
    parry_poses: (ParryPose, ParryPose),
}

/// parry's copy of a shape, with the pose of parry's shape in Proxima's shape frame.
struct ParryShape {
    shape: SharedShape,
    offset: Pose,
}

fn parry_shape(spec: &ShapeSpec) -> ParryShape {
    let plain = |shape| ParryShape {
        shape,
        offset: Pose::IDENTITY,
    };
    match *spec {
        ShapeSpec::Primitive(Primitive::Sphere { radius }) => plain(SharedShape::ball(radius)),
        ShapeSpec::Primitive(Primitive::Capsule {
            radius,
            half_height,
        }) => plain(SharedShape::capsule_z(half_height, radius)),
        ShapeSpec::Primitive(Primitive::Cuboid {
            half_extents: [x, y, z],
        }) => plain(SharedShape::cuboid(x, y, z)),
        ShapeSpec::Primitive(Primitive::Cylinder {
            radius,
            half_height,
        }) => ParryShape {
            shape: SharedShape::cylinder(half_height, radius),
            offset: parry_cylinder_offset(),
        },
        ShapeSpec::Convex(ref points) => {
            let points: Vec<ParryVector> = points.iter().map(|p| parry_vector(*p)).collect();
            plain(SharedShape::convex_hull(&points).expect("the pile's hulls are valid"))
        }
        ShapeSpec::Primitive(Primitive::Cone { .. })
        | ShapeSpec::Mesh(_)
        | ShapeSpec::Compound(_) => {
            unreachable!("the pile has no cones, meshes or compounds")
        }
    }
}

/// The candidate pairs of `scene` at its current poses, both engines' shapes and poses.
fn candidate_pairs<'s>(scene: &'s Scene, parry: &'s [ParryShape]) -> Vec<Pair<'s>> {
    let (mut proxies, mut candidates) = (Vec::new(), Vec::new());
    scene.proxies(&mut proxies);
    pairs_brute_force(&proxies, &mut candidates);
    candidates
        .iter()
        .map(|&CandidatePair { a, b }| {
            let body = |id| scene.body(BodyId(id)).expect("a candidate's body");
            let (ba, bb) = (body(a), body(b));
            let shape = |id| scene.shape(id).expect("a body's shape");
            let (pa, pb) = (&parry[ba.shape.0 as usize], &parry[bb.shape.0 as usize]);
            Pair {
                shapes: (shape(ba.shape), shape(bb.shape)),
                poses: (ba.pose, bb.pose),
                margins: ba.margin + bb.margin,
                parry_shapes: (&pa.shape, &pb.shape),
                parry_poses: (
                    parry_pose(&ba.pose.compose(&pa.offset)),
                    parry_pose(&bb.pose.compose(&pb.offset)),
                ),
            }
        })
        .collect()
}

/// Proxima's answer to `pair` as the pipeline gives it: the signed distance (exact up to
/// the margins), and when touching the manifold into `manifold` (else left empty).
fn proxima_pair(
    pair: &Pair<'_>,
    with_manifold: bool,
    scratch: &mut NarrowScratch,
    manifold: &mut Manifold,
) -> f64 {
    let (sa, sb) = pair.shapes;
    let pose_ab = Pose::relative(&pair.poses.0, &pair.poses.1);
    let d = dispatch::distance(sa, sb, &pose_ab, pair.margins, scratch);
    manifold.reset(DVec3::ZERO);
    if with_manifold && d.distance <= 0.0 {
        dispatch::manifold(sa, sb, &pose_ab, &d, scratch, manifold);
    }
    d.distance
}

/// parry's signed distance of `pair` when within the prediction.
fn parry_pair(pair: &Pair<'_>) -> Option<f64> {
    let (pa, pb) = pair.parry_poses;
    let (sa, sb) = pair.parry_shapes;
    parry3d_f64::query::contact(&pa, &**sa, &pb, &**sb, pair.margins)
        .expect("parry supports every convex pair")
        .map(|c| c.dist)
}

/// Name of a shape's kind, as the per-kind table writes it.
fn kind_name(shape: &Shape) -> &'static str {
    match shape {
        Shape::Sphere(_) => "sphere",
        Shape::Capsule(_) => "capsule",
        Shape::Cuboid(_) => "box",
        Shape::Cylinder(_) => "cylinder",
        Shape::Cone(_) => "cone",
        Shape::Convex(_) => "hull",
        Shape::Mesh(_) => "mesh",
        Shape::Compound(_) => "compound",
    }
}

/// Canonical rank of a kind name (the dispatcher's order), to name a pair's kinds once.
fn kind_rank(name: &str) -> usize {
    [
        "sphere", "capsule", "box", "cylinder", "cone", "hull", "mesh", "compound",
    ]
    .iter()
    .position(|k| *k == name)
    .unwrap_or(usize::MAX)
}

/// Rounds of the per-kind timing loop; each kind's figure is the median round.
const KIND_ROUNDS: usize = 201;

/// The median of `rounds` timings of `work` over all its pairs, microseconds.
fn median_us(rounds: usize, mut work: impl FnMut()) -> f64 {
    let mut times: Vec<f64> = (0..rounds)
        .map(|_| {
            let start = std::time::Instant::now();
            work();
            start.elapsed().as_secs_f64() * 1e6
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Prints the cost per pair kind on frame `k`'s candidate pairs: for each pair of kinds,
/// the pairs and touching pairs, then the median over [`KIND_ROUNDS`] rounds of Proxima's
/// `distance` (every pair), Proxima's `manifold` (touching pairs, after their distance,
/// which is not counted) and parry's `contact` (every pair), in total µs and µs per pair.
fn print_kind_costs(pairs: &[Pair<'_>]) {
    let mut kinds: Vec<(&str, &str)> = pairs
        .iter()
        .map(|p| kind_pair(p))
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    kinds.sort_by_key(|&(a, b)| (kind_rank(a), kind_rank(b)));
    let (mut scratch, mut manifold) = (NarrowScratch::default(), Manifold::default());
    println!("pile: cost per pair kind (median of {KIND_ROUNDS} rounds; µs total / µs per pair)");
    println!(
        "pile: {:<18} {:>5} {:>5} | {:>16} | {:>16} | {:>16} | {:>6}",
        "kinds", "pairs", "touch", "distance", "manifold", "parry contact", "parry/ours"
    );
    let (mut sum_d, mut sum_m, mut sum_p, mut sum_t) = (0.0, 0.0, 0.0, 0);
    for (ka, kb) in kinds {
        let of_kind: Vec<&Pair<'_>> = pairs.iter().filter(|p| kind_pair(p) == (ka, kb)).collect();
        let answers: Vec<(Pose, proxima::narrow::ShapeDistance)> = of_kind
            .iter()
            .map(|p| {
                let pose_ab = Pose::relative(&p.poses.0, &p.poses.1);
                let d =
                    dispatch::distance(p.shapes.0, p.shapes.1, &pose_ab, p.margins, &mut scratch);
                (pose_ab, d)
            })
            .collect();
        let touching = answers.iter().filter(|(_, d)| d.distance <= 0.0).count();
        let distance_us = median_us(KIND_ROUNDS, || {
            for (p, (pose_ab, _)) in of_kind.iter().zip(&answers) {
                black_box(dispatch::distance(
                    p.shapes.0,
                    p.shapes.1,
                    black_box(pose_ab),
                    p.margins,
                    &mut scratch,
                ));
            }
        });
        let manifold_us = median_us(KIND_ROUNDS, || {
            for (p, (pose_ab, d)) in of_kind.iter().zip(&answers) {
                if d.distance <= 0.0 {
                    dispatch::manifold(
                        p.shapes.0,
                        p.shapes.1,
                        black_box(pose_ab),
                        d,
                        &mut scratch,
                        &mut manifold,
                    );
                    black_box(manifold.len());
                }
            }
        });
        let parry_us = median_us(KIND_ROUNDS, || {
            for p in &of_kind {
                black_box(parry_pair(black_box(p)));
            }
        });
        let n = of_kind.len() as f64;
        let per = |total: f64, count: f64| if count > 0.0 { total / count } else { 0.0 };
        println!(
            "pile: {:<18} {:>5} {:>5} | {:>7.1} / {:>6.3} | {:>7.1} / {:>6.3} | {:>7.1} / {:>6.3} | {:>6.2}",
            format!("{ka}-{kb}"),
            of_kind.len(),
            touching,
            distance_us,
            per(distance_us, n),
            manifold_us,
            per(manifold_us, touching as f64),
            parry_us,
            per(parry_us, n),
            parry_us / (distance_us + manifold_us),
        );
        (sum_d, sum_m, sum_p) = (sum_d + distance_us, sum_m + manifold_us, sum_p + parry_us);
        sum_t += touching;
    }
    println!(
        "pile: {:<18} {:>5} {:>5} | {sum_d:>7.1} µs{:>8} | {sum_m:>7.1} µs{:>8} | {sum_p:>7.1} µs{:>8} | {:>6.2}",
        "all",
        pairs.len(),
        sum_t,
        "",
        "",
        "",
        sum_p / (sum_d + sum_m),
    );
}

/// The pair's kind names in canonical order.
fn kind_pair(pair: &Pair<'_>) -> (&'static str, &'static str) {
    let (a, b) = (kind_name(pair.shapes.0), kind_name(pair.shapes.1));
    if kind_rank(a) <= kind_rank(b) {
        (a, b)
    } else {
        (b, a)
    }
}

/// Prints frame `k`'s statistics and both engines' agreement on its candidate pairs.
fn print_frame(scene: &Scene, pairs: &[Pair<'_>]) {
    let mut results = FrameResults::default();
    let report = step(
        scene,
        QUERY,
        &mut PipelineWorkspace::default(),
        &mut results,
    );
    let touching = results.pairs.iter().filter(|p| p.distance <= 0.0).count();
    println!(
        "pile: {} candidate pairs ({} by brute force), {} close, {touching} touching, {} contacts",
        report.candidates,
        pairs.len(),
        results.pairs.len(),
        results.contacts.len()
    );
    let (mut scratch, mut manifold) = (NarrowScratch::default(), Manifold::default());
    let (mut close, mut touch) = ([0_usize; 3], [0_usize; 3]);
    let (mut max_close_m, mut max_touch_m) = (0.0_f64, 0.0_f64);
    for pair in pairs {
        let ours = proxima_pair(pair, false, &mut scratch, &mut manifold);
        let ours = (ours <= pair.margins).then_some(ours);
        let theirs = parry_pair(pair);
        let count = |counts: &mut [usize; 3], x: Option<f64>, y: Option<f64>| {
            counts[0] += usize::from(x.is_some());
            counts[1] += usize::from(y.is_some());
            if let (Some(x), Some(y)) = (x, y) {
                counts[2] += 1;
                return (x - y).abs();
            }
            0.0
        };
        max_close_m = max_close_m.max(count(&mut close, ours, theirs));
        let touching = |d: Option<f64>| d.filter(|&d| d <= 0.0);
        max_touch_m = max_touch_m.max(count(&mut touch, touching(ours), touching(theirs)));
    }
    println!(
        "pile: within prediction: proxima {}, parry {}, both {}; largest |distance difference| {max_close_m:.3e} m",
        close[0], close[1], close[2]
    );
    println!(
        "pile: touching: proxima {}, parry {}, both {}; largest |depth difference| {max_touch_m:.3e} m",
        touch[0], touch[1], touch[2]
    );
}

fn bench_pile(c: &mut Criterion) {
    let Settled {
        spec,
        mut scene,
        frame_k,
        frame_k1,
        settling,
    } = settle();
    let frozen = scene.clone();
    let parry: Vec<ParryShape> = spec.shapes.iter().map(parry_shape).collect();
    let pairs = candidate_pairs(&frozen, &parry);
    print_frame(&frozen, &pairs);
    print_kind_costs(&pairs);
    let shifted: PoseSet = frame_k
        .iter()
        .map(|&(id, pose)| {
            (
                id,
                Pose::new(pose.position + DVec3::splat(SHIFT_M), pose.rotation),
            )
        })
        .collect();

    let mut group = c.benchmark_group("pile");
    let (mut workspace, mut results) = (PipelineWorkspace::default(), FrameResults::default());
    let fixed = [&frame_k, &frame_k1];
    let all_pairs = [&frame_k, &shifted];
    let settling: Vec<&PoseSet> = settling.iter().collect();
    for (name, sets) in [
        ("frame", &fixed[..]),
        ("frame-all-pairs", &all_pairs[..]),
        ("frame-settling", &settling[..]),
        ("frame-settling-helped", &settling[..]),
    ] {
        if name == "frame-settling-helped" {
            // The daemon's workspace: a pool of one worker, whose helper takes pairs.
            workspace = PipelineWorkspace::with_workers(Arc::new(WorkerPool::new(1)));
        }
        let mut frame = |poses: &PoseSet| {
            set_poses(&mut scene, poses);
            let report = step(&scene, QUERY, &mut workspace, &mut results);
            scene.end_frame();
            report
        };
        // Untimed: the alternation's steady state, as the timed frames see it.
        frame(sets[0]);
        let report = frame(sets[1]);
        println!(
            "pile: proxima/{name}: {} of {} candidate answers kept from the frame before, \
             {} answered by the helper thread",
            report.reused_pairs, report.candidates, report.helped_pairs
        );
        cycle_bench(
            &mut group,
            BenchmarkId::new("proxima", name),
            sets,
            |_, poses| f64::from(frame(poses).contacts),
        );
    }

    let (mut scratch, mut manifold) = (NarrowScratch::default(), Manifold::default());
    for (name, with_manifold) in [("narrow", true), ("distance", false)] {
        group.bench_function(BenchmarkId::new("proxima", name), |bench| {
            bench.iter(|| {
                let mut contacts = 0;
                for pair in black_box(&pairs) {
                    proxima_pair(pair, with_manifold, &mut scratch, &mut manifold);
                    contacts += manifold.len();
                }
                contacts
            });
        });
    }
    group.bench_function(BenchmarkId::new("parry", "contacts"), |bench| {
        bench.iter(|| {
            black_box(&pairs)
                .iter()
                .filter(|pair| parry_pair(pair).is_some())
                .count()
        });
    });
    group.finish();
}

criterion_group!(benches, bench_pile);
criterion_main!(benches);
