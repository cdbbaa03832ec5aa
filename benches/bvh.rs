//! BVH construction and refit: time per build for every builder preset, and per refit in
//! both modes, for the volume types the mesh queries use.
//!
//! Input: a torus of 10,000 triangles (`support::meshes::torus`); refit moves every vertex
//! by a seeded random offset of 1% of the minor radius, generated before timing.
//! Names `bvh/<stage>/<variant>/<volume>`.
//!
//! `cargo bench --bench bvh`

#[path = "../tests/support/mod.rs"]
mod support;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use proxima::bounding::{Aabb, BoundingVolume, Obb, Rss};
use proxima::bvh::{BuildParams, Bvh, RefitMode};
use proxima::geometry::Triangle;
use std::hint::black_box;
use support::meshes;

const PRESETS: [(&str, BuildParams); 4] = [
    ("median", BuildParams::MEDIAN),
    ("mean_variance", BuildParams::MEAN_VARIANCE),
    ("binned_sah", BuildParams::BINNED_SAH),
    ("agglomerative", BuildParams::AGGLOMERATIVE),
];

fn build_and_refit<B: BoundingVolume>(
    c: &mut Criterion,
    triangles: &[Triangle],
    moved: &[Triangle],
) {
    let mut group = c.benchmark_group("bvh");
    group.sample_size(10);
    for (name, params) in PRESETS {
        group.bench_function(
            BenchmarkId::new(format!("build/{name}"), B::NAME),
            |bench| {
                bench.iter(|| Bvh::<B>::from_triangles(black_box(triangles), &params));
            },
        );
    }
    let built = Bvh::<B>::from_triangles(triangles, &BuildParams::BINNED_SAH);
    for (name, mode) in [
        ("merge", RefitMode::Merge),
        ("keep_frames", RefitMode::KeepFrames),
        ("fit", RefitMode::Fit),
    ] {
        let mut bvh = built.clone();
        let mut flip = false;
        group.bench_function(
            BenchmarkId::new(format!("refit/{name}"), B::NAME),
            |bench| {
                bench.iter(|| {
                    // Alternate between the two vertex sets so every refit sees real motion.
                    flip = !flip;
                    bvh.refit(black_box(if flip { moved } else { triangles }), mode);
                });
            },
        );
    }
    group.finish();
}

fn bench(c: &mut Criterion) {
    let torus = meshes::torus(1.0, 0.25, 100, 50);
    let triangles = meshes::triangles(&torus);
    let mut rng = support::rng(11);
    let moved: Vec<Triangle> = triangles
        .iter()
        .map(|t| {
            let mut nudge = |p| p + support::point_in_cube(&mut rng, 0.0025);
            Triangle::new(nudge(t.a), nudge(t.b), nudge(t.c))
        })
        .collect();
    build_and_refit::<Aabb>(c, &triangles, &moved);
    build_and_refit::<Obb>(c, &triangles, &moved);
    build_and_refit::<Rss>(c, &triangles, &moved);
}

criterion_group!(benches, bench);
criterion_main!(benches);
