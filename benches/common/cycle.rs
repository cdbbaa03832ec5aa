//! Timing a query over a fixed sequence of inputs, one input per iteration.

use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId};
use std::hint::black_box;

/// Times `query` on the next input of `inputs` at each iteration, going round the sequence
/// in order, so every input is timed equally often (to within one lap).
///
/// `query` gets the input's index too, for per-input state such as a warm-start cache.
///
/// Unlike the power-of-two ring of the bounding bench, the length is free: the mesh
/// protocols fix their pose count (200 for bunny×fandisk), and padding to a power of two
/// would time some poses twice as often as others. One compare per iteration costs nothing
/// next to a mesh–mesh query. The position is kept across criterion's samples (criterion
/// calls the routine once per sample): resetting it per sample would time only the first few
/// inputs of a slow query.
///
/// # Panics
/// When `inputs` is empty.
pub fn cycle_bench<T>(
    group: &mut BenchmarkGroup<'_, WallTime>,
    id: BenchmarkId,
    inputs: &[T],
    mut query: impl FnMut(usize, &T) -> f64,
) {
    assert!(!inputs.is_empty(), "no inputs to time");
    let mut next = 0;
    group.bench_function(id, |bench| {
        bench.iter(|| {
            let out = query(next, black_box(&inputs[next]));
            next += 1;
            if next == inputs.len() {
                next = 0;
            }
            black_box(out)
        });
    });
}
