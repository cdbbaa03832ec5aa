//! Unit tests of the rule: the statistics it reads and the kind it picks.

use super::*;
use crate::broad::CollisionFilter;
use crate::math::DVec3;
use crate::test_support::{TestRng, rng};
use rand::Rng;

fn random_bounds(rng: &mut TestRng, spread: f64) -> Aabb {
    crate::broad::conformance::random_box(rng, spread, 12)
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
