//! Bounding-volume costs: ns per overlap test and per distance lower bound under a random
//! relative pose, for every volume type, and fit time per 1,000 points.
//!
//! Inputs are made before the timed loop from a fixed seed: 1,024 pairs of volumes, each
//! fitted to a 32-point random box cloud of unit size, under relative poses whose
//! translations put roughly half of the pairs in overlap. Each timed iteration takes the
//! next pair from the power-of-two ring.
//!
//! `cargo bench --bench bounding`; names are `bounding/<query>/<type>`.

#[path = "../tests/support/mod.rs"]
mod support;

use criterion::{Criterion, criterion_group, criterion_main};
use proxima::bounding::{
    Aabb, BoundingSphere, BoundingVolume, Kdop14, Kdop18, Kdop26, Lss, Obb, Rss,
};
use proxima::math::{DVec3, Isometry};
use std::hint::black_box;
use support::{CloudKind, cloud, isometry, rng};

const RING: usize = 1024;
const SEED: u64 = 0x5EED_B0B5;

struct Inputs<B> {
    pairs: Vec<(B, B, Isometry)>,
    clouds_1000: Vec<Vec<DVec3>>,
}

fn inputs<B: BoundingVolume>() -> Inputs<B> {
    let mut rng = rng(SEED);
    let pairs: Vec<(B, B, Isometry)> = (0..RING)
        .map(|_| {
            let a = B::fit_points(&cloud(&mut rng, CloudKind::Box, 32, DVec3::ZERO, 1.0));
            let b = B::fit_points(&cloud(&mut rng, CloudKind::Box, 32, DVec3::ZERO, 1.0));
            (a, b, isometry(&mut rng, 1.6))
        })
        .collect();
    let overlapping = pairs.iter().filter(|(a, b, p)| a.overlaps(b, p)).count();
    eprintln!("{}: {overlapping} of {RING} bench pairs overlap", B::NAME);
    let clouds_1000 = (0..16)
        .map(|_| cloud(&mut rng, CloudKind::Box, 1000, DVec3::ZERO, 1.0))
        .collect();
    Inputs { pairs, clouds_1000 }
}

fn bench_type<B: BoundingVolume>(c: &mut Criterion) {
    let Inputs { pairs, clouds_1000 } = inputs::<B>();

    ring_bench(c, "bounding/overlap", B::NAME, &pairs, |(a, b, pose)| {
        f64::from(u8::from(
            black_box(a).overlaps(black_box(b), black_box(pose)),
        ))
    });
    ring_bench(
        c,
        "bounding/distance_lower_bound",
        B::NAME,
        &pairs,
        |(a, b, pose)| black_box(a).distance_lower_bound(black_box(b), black_box(pose)),
    );
    ring_bench(
        c,
        "bounding/fit_1000_points",
        B::NAME,
        &clouds_1000,
        |points| B::fit_points(black_box(points)).volume(),
    );
}

/// Times `query` on the next input of a power-of-two ring at each iteration.
fn ring_bench<T>(
    c: &mut Criterion,
    group: &str,
    name: &str,
    inputs: &[T],
    query: impl Fn(&T) -> f64,
) {
    assert!(inputs.len().is_power_of_two());
    let mask = inputs.len() - 1;
    c.bench_function(&format!("{group}/{name}"), |bench| {
        let mut i = 0;
        bench.iter(|| {
            let input = &inputs[i & mask];
            i += 1;
            black_box(query(input))
        });
    });
}

fn bounding(c: &mut Criterion) {
    bench_type::<BoundingSphere>(c);
    bench_type::<Aabb>(c);
    bench_type::<Obb>(c);
    bench_type::<Kdop14>(c);
    bench_type::<Kdop18>(c);
    bench_type::<Kdop26>(c);
    bench_type::<Lss>(c);
    bench_type::<Rss>(c);
}

criterion_group!(benches, bounding);
criterion_main!(benches);
