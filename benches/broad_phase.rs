//! Broad phase per frame: Proxima's sort and sweep, incremental sweep and prune,
//! hierarchical hash grid and column grid, and rapier's broad phase on parry3d-f64's BVH (the peer; see
//! `common/parry_broad.rs`), on the same frames in the same run.
//!
//! Workloads (`common/broad_scenes.rs`): uniform, clustered and stacked boxes, 10 % of the
//! bodies moving coherently, plus uniform boxes teleporting; 1,000 and 10,000 bodies. Each
//! broad phase gets its own copy of the workload, built from the same seed, so all are
//! handed exactly the same frames. One iteration is one frame: the workload moves its
//! bodies (not timed), then the broad phase takes the moved boxes and brings its pairs up
//! to date (timed, `iter_custom`). Proxima's broad phases also write the sorted pair list;
//! rapier's keeps its pair map. 100,000 bodies take too long per sample for criterion: run
//! `cargo run --release --example broad_bench -- --bodies 100000` for them.

// Shared with the other broad-phase target, which uses the items this one does not.
#[allow(dead_code)]
#[path = "common/broad_phases.rs"]
mod broad_phases;
// Shared with the other broad-phase target, which uses the items this one does not.
#[allow(dead_code)]
#[path = "common/broad_scenes.rs"]
mod broad_scenes;
#[path = "common/parry_broad.rs"]
mod parry_broad;

use broad_phases::{NAMES, Phase};
use broad_scenes::{BroadScene, Layout, Motion};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// Fraction of the bodies moving every frame.
const MOVING: f64 = 0.1;
/// Seed of every workload.
const SEED: u64 = 7;

fn broad_phase(c: &mut Criterion) {
    let workloads = [
        (Layout::Uniform, Motion::Coherent),
        (Layout::Clustered, Motion::Coherent),
        (Layout::Stack, Motion::Coherent),
        (Layout::Uniform, Motion::Teleport),
    ];
    for (layout, motion) in workloads {
        let mut group = c.benchmark_group(format!("broad/{}_{}", layout.name(), motion.name()));
        for bodies in [1_000, 10_000] {
            for name in NAMES {
                let mut scene = BroadScene::new(layout, bodies, MOVING, motion, SEED);
                let mut out = Vec::new();
                let mut moved = Vec::new();
                let mut phase = Phase::new(name, &scene.proxies, &mut out)
                    .expect("every listed broad phase exists");
                group.bench_function(BenchmarkId::new(name, bodies), |bench| {
                    bench.iter_custom(|iters| {
                        let mut timed = Duration::ZERO;
                        for _ in 0..iters {
                            scene.next_frame(&mut moved);
                            let started = Instant::now();
                            phase.step(&scene.proxies, &moved, &mut out);
                            timed += started.elapsed();
                            black_box(phase.pair_count(&out));
                        }
                        timed
                    });
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
