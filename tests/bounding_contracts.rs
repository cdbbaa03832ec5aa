//! The `BoundingVolume` contract, checked for every bounding-volume type over thousands of
//! seeded clouds (every `CloudKind`, centres up to 1e6 from the origin, scales 1e-4..1e4):
//!
//! - containment: every point or triangle vertex a volume was fitted to lies inside it;
//! - merge contains both inputs; `transformed` contains the moved points;
//! - conservative overlap: two point sets that share a point give overlapping volumes under
//!   every relative pose (zero false negatives), and the distance lower bound never exceeds
//!   the exact distance between the bounded point sets (brute force over all point pairs);
//! - transform-then-overlap equals overlap under the relative pose:
//!   `a.overlaps(b, pose_ab) == a.intersects(b.transformed(pose_ab))`, except for pairs
//!   within 1e-9 of the coordinate magnitude of touching (the two paths round differently).
//!
//! Random pair tests also assert that both outcomes (overlap and separation) occur.

mod support;

use proxima::bounding::{
    Aabb, BoundingSphere, BoundingVolume, Kdop14, Kdop18, Kdop26, Lss, Obb, Rss,
};
use proxima::geometry::Triangle;
use proxima::math::DVec3;
use rand::Rng;
use support::{isometry, min_distance, random_cloud, rng};

/// Cases per contract and volume type.
const CASES: usize = 3000;

/// Most points in one random cloud.
const MAX_POINTS: usize = 63;

/// Triangles over consecutive point triples (wrapping), so degenerate clouds give
/// degenerate triangles.
fn triangles_of(points: &[DVec3]) -> Vec<Triangle> {
    let n = points.len();
    (0..n.div_ceil(3).max(1))
        .map(|i| {
            Triangle::new(
                points[(3 * i) % n],
                points[(3 * i + 1) % n],
                points[(3 * i + 2) % n],
            )
        })
        .collect()
}

fn check_containment<B: BoundingVolume>(seed: u64) {
    let mut rng = rng(seed);
    for case in 0..CASES {
        let (points, _) = random_cloud(&mut rng, MAX_POINTS);
        let bv = B::fit_points(&points);
        for p in &points {
            assert!(
                bv.contains_point(*p),
                "{} case {case}: fitted point {p} outside {bv:?}",
                B::NAME
            );
        }
        let triangles = triangles_of(&points);
        let bv = B::fit_triangles(&triangles);
        // A leaf refit keeps an old orientation: here that of the point fit above.
        let in_frame = B::fit_points(&points).fit_triangles_in_frame(&triangles);
        for t in &triangles {
            for v in t.vertices() {
                assert!(
                    bv.contains_point(v) && in_frame.contains_point(v),
                    "{} case {case}: triangle vertex {v} outside {bv:?} or {in_frame:?}",
                    B::NAME
                );
            }
        }
        assert!(
            bv.volume() >= 0.0 && bv.size() >= 0.0 && bv.stand_off() >= 0.0,
            "{} case {case}",
            B::NAME
        );
        assert!(
            bv.contains_point(bv.center()),
            "{} case {case}: centre outside",
            B::NAME
        );
    }
}

fn check_merge_and_transform<B: BoundingVolume>(seed: u64) {
    let mut rng = rng(seed);
    for case in 0..CASES {
        let (a, _) = random_cloud(&mut rng, MAX_POINTS);
        let (b, _) = random_cloud(&mut rng, MAX_POINTS);
        let (bv_a, bv_b) = (B::fit_points(&a), B::fit_points(&b));
        let merged = bv_a.merged(&bv_b);
        let mut merged_in_place = bv_a;
        merged_in_place.merge(&bv_b);
        // Refit's merge keeps an old orientation: any other volume's, here a third cloud's.
        let (c, _) = random_cloud(&mut rng, MAX_POINTS);
        let in_frame = B::fit_points(&c).merged_in_frame(&bv_a, &bv_b);
        for p in a.iter().chain(&b) {
            assert!(
                in_frame.contains_point(*p),
                "{} case {case}: merged in another frame lost {p}",
                B::NAME
            );
            assert!(
                merged.contains_point(*p),
                "{} case {case}: merged lost {p}",
                B::NAME
            );
            assert!(
                merged_in_place.contains_point(*p),
                "{} case {case}: merge lost {p}",
                B::NAME
            );
        }
        let pose = isometry(&mut rng, 10.0 * a[0].length().max(1.0));
        let moved = bv_a.transformed(&pose);
        for p in &a {
            let q = pose.transform_point(*p);
            assert!(
                moved.contains_point(q),
                "{} case {case}: transformed lost {q}",
                B::NAME
            );
        }
    }
}

/// Point sets in frames A and B that share one point, under a random pose: the volumes must
/// overlap and bound their distance by zero.
fn check_shared_point_overlaps<B: BoundingVolume>(seed: u64) {
    let mut rng = rng(seed);
    for case in 0..CASES {
        let (a, scale) = random_cloud(&mut rng, MAX_POINTS);
        let (mut b, _) = random_cloud(&mut rng, MAX_POINTS);
        let pose_ab = isometry(&mut rng, 1e3 * scale);
        let shared_a = a[rng.random_range(0..a.len())];
        b.push(pose_ab.inverse_transform_point(shared_a));
        let (bv_a, bv_b) = (B::fit_points(&a), B::fit_points(&b));
        assert!(
            bv_a.overlaps(&bv_b, &pose_ab),
            "{} case {case}: shared point but no overlap",
            B::NAME
        );
        assert!(
            bv_b.overlaps(&bv_a, &pose_ab.inverse()),
            "{} case {case}: not symmetric",
            B::NAME
        );
        let bound = bv_a.distance_lower_bound(&bv_b, &pose_ab);
        assert!(
            bound <= 0.0,
            "{} case {case}: shared point but distance bound {bound}",
            B::NAME
        );
    }
}

/// Random pairs at all distances: the lower bound never exceeds the brute-force distance,
/// overlap never misses a pair the bound cannot separate, and both outcomes occur.
fn check_distance_bound_and_outcomes<B: BoundingVolume>(seed: u64) {
    let mut rng = rng(seed);
    let (mut overlapping, mut separated, mut positive_bounds, mut borderline) = (0, 0, 0, 0);
    for case in 0..CASES {
        let (a, scale) = random_cloud(&mut rng, MAX_POINTS);
        let (b_local, _) = random_cloud(&mut rng, MAX_POINTS);
        // Put B near A: its centre within a few scales of A's first point.
        let mut pose_ab = isometry(&mut rng, 3.0 * scale);
        pose_ab.translation += a[0] - pose_ab.transform_point(b_local[0])
            + support::point_in_cube(&mut rng, 2.0 * scale);
        let b_in_a: Vec<DVec3> = b_local
            .iter()
            .map(|p| pose_ab.transform_point(*p))
            .collect();
        let truth = min_distance(&a, &b_in_a);
        let (bv_a, bv_b) = (B::fit_points(&a), B::fit_points(&b_local));
        let bound = bv_a.distance_lower_bound(&bv_b, &pose_ab);
        assert!(
            bound <= truth,
            "{} case {case}: distance bound {bound} exceeds the true distance {truth}",
            B::NAME
        );
        // The early-out form: the full bound below the limit, a valid bound at or past it.
        let limit = truth * rng.random_range(0.0..2.0);
        let within = bv_a.distance_lower_bound_within(&bv_b, &pose_ab, limit);
        assert!(
            within <= truth && (within == bound || (within >= limit && bound >= limit)),
            "{} case {case}: bound within {limit} is {within} (full {bound}, true {truth}) {bv_a:?} {bv_b:?}",
            B::NAME
        );
        // The two-volume form (a node's two children against one node) is the single form
        // twice, bit for bit.
        assert_eq!(
            B::distance_lower_bounds_within([&bv_a, &bv_a], &bv_b, &pose_ab, limit),
            [within; 2],
            "{} case {case}: the pair form differs from the single one",
            B::NAME
        );
        // Seen from B (the frontier's split of B's node): a bound of the same distance.
        let reverse = bv_b.distance_lower_bound(&bv_a, &pose_ab.inverse());
        assert!(
            reverse <= truth,
            "{} case {case}: bound from B's side {reverse} exceeds the true distance {truth}",
            B::NAME
        );
        let overlaps = bv_a.overlaps(&bv_b, &pose_ab);
        let moved = bv_b.transformed(&pose_ab);
        if overlaps != bv_a.intersects(&moved) {
            // The two paths round differently; they may disagree only on pairs within
            // rounding slack of touching.
            let magnitude = a
                .iter()
                .chain(&b_in_a)
                .chain(&b_local)
                .map(|p| p.abs().max_element())
                .fold(0.0, f64::max);
            let gap =
                bound.max(bv_a.distance_lower_bound(&moved, &proxima::math::Isometry::IDENTITY));
            assert!(
                gap <= 1e-9 * magnitude,
                "{} case {case}: transform-then-overlap differs from overlap under the pose, gap {gap}",
                B::NAME
            );
            borderline += 1;
        }
        if overlaps {
            overlapping += 1;
        } else {
            separated += 1;
        }
        if bound > 0.0 {
            positive_bounds += 1;
        }
    }
    let name = B::NAME;
    assert!(
        borderline <= CASES / 100,
        "{name}: {borderline} borderline disagreements of {CASES}"
    );
    assert!(
        overlapping > CASES / 10,
        "{name}: only {overlapping} overlapping cases of {CASES}"
    );
    assert!(
        separated > CASES / 10,
        "{name}: only {separated} separated cases of {CASES}"
    );
    assert!(
        positive_bounds > CASES / 10,
        "{name}: only {positive_bounds} positive bounds of {CASES}"
    );
}

/// Instantiates every contract for one volume type, each with its own seed.
macro_rules! contracts {
    ($module:ident, $bv:ty, $seed:expr) => {
        mod $module {
            use super::*;

            #[test]
            fn fitted_points_and_triangles_lie_inside() {
                check_containment::<$bv>($seed);
            }

            #[test]
            fn merge_and_transform_keep_every_point() {
                check_merge_and_transform::<$bv>($seed + 1);
            }

            #[test]
            fn sets_sharing_a_point_always_overlap() {
                check_shared_point_overlaps::<$bv>($seed + 2);
            }

            #[test]
            fn distance_bound_never_exceeds_truth_and_both_outcomes_occur() {
                check_distance_bound_and_outcomes::<$bv>($seed + 3);
            }
        }
    };
}

contracts!(sphere, BoundingSphere, 100);
contracts!(aabb, Aabb, 200);
contracts!(obb, Obb, 300);
contracts!(kdop14, Kdop14, 400);
contracts!(kdop18, Kdop18, 500);
contracts!(kdop26, Kdop26, 600);
contracts!(lss, Lss, 700);
contracts!(rss, Rss, 800);
