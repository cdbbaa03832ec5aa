use super::*;
use crate::test_support::{point_in_cube, rng};
use rand::Rng;

/// Twice the area spanned by a set of up to 4 points: the largest of every triangle's and
/// every quadrilateral ordering's (diagonal cross product) — the hull area for coplanar
/// points, a fair span measure for nearly coplanar ones.
fn span(points: &[DVec3]) -> f64 {
    let mut best = 0.0f64;
    let n = points.len();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (points[i], points[j], points[k]);
                best = best.max((b - a).cross(c - a).length());
            }
        }
    }
    if let [a, b, c, d] = *points {
        for (w, x, y, z) in [(a, b, c, d), (a, c, b, d), (a, d, b, c)] {
            // Orderings w-y-x-z: diagonals w–x and y–z.
            best = best.max((x - w).cross(z - y).length());
        }
    }
    best
}

fn reduced(points: &[DVec3]) -> Vec<usize> {
    let mut out = Vec::new();
    reduce_manifold(points, &mut out);
    out
}

#[test]
fn small_sets_keep_at_most_four_distinct_input_points_with_the_farthest_pair_first() {
    let mut rng = rng(91);
    for case in 0..2000 {
        let n = rng.random_range(1..12);
        let flatness = if case % 2 == 0 { 0.0 } else { 0.05 };
        let points: Vec<DVec3> = (0..n)
            .map(|_| {
                let p = point_in_cube(&mut rng, 1.0);
                DVec3::new(p.x, p.y, p.z * flatness)
            })
            .collect();
        let kept = reduced(&points);
        assert!(!kept.is_empty() && kept.len() <= crate::narrow::MANIFOLD_POINTS);
        let mut sorted = kept.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), kept.len(), "case {case}: a point kept twice");
        assert!(kept.iter().all(|&i| i < n));
        if n >= 2 {
            let diameter = (0..n)
                .flat_map(|i| (0..n).map(move |j| (i, j)))
                .map(|(i, j)| points[i].distance(points[j]))
                .fold(0.0, f64::max);
            assert_eq!(points[kept[0]].distance(points[kept[1]]), diameter);
        }
    }
}

#[test]
fn the_kept_points_span_at_least_half_the_best_four_point_area() {
    let mut rng = rng(92);
    let mut worst = f64::INFINITY;
    for case in 0..3000 {
        let n = rng.random_range(4..10);
        let flatness = [0.0, 0.02, 0.3][case % 3];
        let points: Vec<DVec3> = (0..n)
            .map(|_| {
                let p = point_in_cube(&mut rng, 1.0);
                DVec3::new(p.x, p.y, p.z * flatness)
            })
            .collect();
        let kept: Vec<DVec3> = reduced(&points).iter().map(|&i| points[i]).collect();
        let mut best = 0.0f64;
        for i in 0..n {
            for j in i + 1..n {
                for k in j + 1..n {
                    for l in k + 1..n {
                        best = best.max(span(&[points[i], points[j], points[k], points[l]]));
                    }
                }
            }
        }
        let ratio = span(&kept) / best;
        assert!(ratio >= 0.5, "case {case}: kept {ratio} of the best area");
        worst = worst.min(ratio);
    }
    // The bound is not vacuous: the greedy choice is not always optimal.
    assert!(worst < 1.0, "worst {worst}");
}

#[test]
fn degenerate_sets_shrink_to_the_points_that_carry_information() {
    let p = DVec3::new(1.0, 2.0, 3.0);
    assert!(reduced(&[]).is_empty());
    assert_eq!(reduced(&[p, p, p]), vec![0]);
    let line: Vec<DVec3> = (0..7).map(|i| p + DVec3::X * f64::from(i)).collect();
    let mut kept = reduced(&line);
    kept.sort_unstable();
    assert_eq!(kept, vec![0, 6]);
    let triangle = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.2, 0.2, 0.0)];
    let mut kept = reduced(&triangle);
    kept.sort_unstable();
    assert_eq!(kept, vec![0, 1, 2], "an interior point adds no area");
}

#[test]
fn large_sets_use_the_double_sweep_and_still_keep_spanning_points() {
    let mut rng = rng(93);
    // A dense disc of radius 1 plus its four compass points: any good manifold keeps
    // points near the rim, far apart.
    let mut points: Vec<DVec3> = (0..5000)
        .map(|_| {
            let (r, t) = (
                rng.random_range(0.0f64..0.9).sqrt(),
                rng.random_range(0.0..6.3),
            );
            DVec3::new(r * f64::cos(t), r * f64::sin(t), 0.0)
        })
        .collect();
    points.extend([DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y]);
    let kept: Vec<DVec3> = reduced(&points).iter().map(|&i| points[i]).collect();
    assert_eq!(kept.len(), 4);
    // The square of the compass points has twice-area 4; ask for most of it.
    assert!(span(&kept) > 3.0, "span {}", span(&kept));
}
