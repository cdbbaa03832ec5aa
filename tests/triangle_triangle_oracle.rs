//! Triangle–triangle queries against oracles that share no code with them.
//!
//! - Overlap: small-integer triangles decided by an exact separating-axis test in `i128`
//!   (complete axis set, degenerate triangles included), plus invariance under exact
//!   integer isometries (axis permutations, sign flips, translations).
//! - Distance: optimality conditions of the witness pair (for convex sets they prove global
//!   optimality), consistency with the exact overlap test, symmetry, and a dense sampled
//!   minimum; stress cases at offsets 1e5 and scales 1e-3..1e3.
mod support;

#[path = "support/exact_sat.rs"]
mod exact_sat;

use exact_sat::{I3, exact_sat, sub};
use proxima::geometry::Triangle;
use proxima::math::{DQuat, DVec3};
use proxima::narrow::{
    TriangleDistance, distance_triangle_triangle, intersection_segment_triangle_triangle,
    intersects_triangle_triangle,
};
use rand::Rng;
use support::{TestRng, rng, rotation};

// ---------------------------------------------------------------------------------------
// Exact integer oracle.

/// Whether the closed triangles meet, by the exact integer SAT of `support/exact_sat.rs`
/// (complete axis set, degenerate triangles included; see its docs for why it is complete).
fn sat_intersects(a: &[I3; 3], b: &[I3; 3]) -> bool {
    exact_sat(a, b).intersects
}

fn to_triangle(t: &[I3; 3]) -> Triangle {
    let f = |p: I3| DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64);
    Triangle::new(f(t[0]), f(t[1]), f(t[2]))
}

fn ipoint(r: &mut TestRng, half: i128) -> I3 {
    [0; 3].map(|_| r.random_range(-half..=half))
}

fn add(a: I3, b: I3) -> I3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn scale(a: I3, k: i128) -> I3 {
    a.map(|x| x * k)
}

/// A random pair biased to hard cases. Coordinates stay small (|x| ≤ 100), so every
/// coordinate is exact in f64 and every SAT product is exact in i128.
fn hard_pair(r: &mut TestRng) -> ([I3; 3], [I3; 3]) {
    let mut a = [ipoint(r, 8), ipoint(r, 8), ipoint(r, 8)];
    let mut b = [ipoint(r, 8), ipoint(r, 8), ipoint(r, 8)];
    match r.random_range(0..9) {
        0 => {}
        1 => b[r.random_range(0..3)] = a[r.random_range(0..3)], // shared vertex
        2 => {
            // Shared edge.
            let i = r.random_range(0..3);
            b[0] = a[i];
            b[1] = a[(i + 1) % 3];
        }
        3 | 4 => {
            // Coplanar: B's vertices are small integer combinations in A's plane.
            let (u, v) = (sub(a[1], a[0]), sub(a[2], a[0]));
            let (u, v) = (
                u.map(|x| x.signum() * x.abs().min(3)),
                v.map(|x| x.clamp(-3, 3)),
            );
            a = [a[0], add(a[0], u), add(a[0], v)];
            for p in &mut b {
                let (i, j) = (r.random_range(-2..=3), r.random_range(-2..=3));
                *p = add(a[0], add(scale(u, i), scale(v, j)));
            }
        }
        5 => {
            // Touching: a vertex of B on an edge midpoint or the centroid of 2A / 6A.
            let k = if r.random_bool(0.5) { 2 } else { 6 };
            a = a.map(|p| scale(p, k));
            let i = r.random_range(0..3);
            b[0] = if k == 2 {
                add(a[i], a[(i + 1) % 3]).map(|x| x / 2)
            } else {
                add(add(a[0], a[1]), a[2]).map(|x| x / 3)
            };
            b[1] = add(b[0], ipoint(r, 8));
            b[2] = add(b[0], ipoint(r, 8));
        }
        6 => {
            // Degenerate B: collinear or a point.
            let d = ipoint(r, 3);
            let (i, j) = (r.random_range(-2..=2), r.random_range(-2..=2));
            b = [b[0], add(b[0], scale(d, i)), add(b[0], scale(d, j))];
        }
        7 => {
            // Both degenerate, sharing a line often.
            let d = ipoint(r, 2);
            a = [
                a[0],
                add(a[0], scale(d, 2)),
                add(a[0], scale(d, r.random_range(-1..=1))),
            ];
            let start = add(a[0], scale(d, r.random_range(-3..=3)));
            b = [start, add(start, scale(d, r.random_range(-2..=2))), start];
            if r.random_bool(0.5) {
                b[2] = add(start, ipoint(r, 1));
            }
        }
        _ => {
            // Crowded: tiny coordinates make coincidences frequent.
            a = [ipoint(r, 2), ipoint(r, 2), ipoint(r, 2)];
            b = [ipoint(r, 2), ipoint(r, 2), ipoint(r, 2)];
        }
    }
    (a, b)
}

/// An exact integer isometry: axis permutation with sign flips, then a translation.
fn integer_isometry(r: &mut TestRng) -> impl Fn(I3) -> I3 {
    let perms = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    let perm = perms[r.random_range(0..6)];
    let signs = [0; 3].map(|_| if r.random_bool(0.5) { 1 } else { -1 });
    let shift = ipoint(r, 1000);
    move |p: I3| [0, 1, 2].map(|i| signs[i] * p[perm[i]] + shift[i])
}

#[test]
fn overlap_matches_exact_integer_separating_axis_oracle() {
    let mut r = rng(0x7417);
    let (mut hits, mut misses) = (0, 0);
    for case in 0..60_000 {
        let (a, b) = hard_pair(&mut r);
        let expected = sat_intersects(&a, &b);
        let (ta, tb) = (to_triangle(&a), to_triangle(&b));
        let got = intersects_triangle_triangle(&ta, &tb);
        assert_eq!(got, expected, "case {case}: {a:?} {b:?}");
        assert_eq!(
            intersects_triangle_triangle(&tb, &ta),
            expected,
            "swapped {case}"
        );
        let rolled = Triangle::new(ta.c, ta.a, ta.b);
        let flipped = Triangle::new(tb.b, tb.a, tb.c);
        assert_eq!(
            intersects_triangle_triangle(&rolled, &flipped),
            expected,
            "order {case}"
        );
        let m = integer_isometry(&mut r);
        let (ma, mb) = (a.map(&m), b.map(&m));
        assert_eq!(
            sat_intersects(&ma, &mb),
            expected,
            "oracle not invariant {case}"
        );
        assert_eq!(
            intersects_triangle_triangle(&to_triangle(&ma), &to_triangle(&mb)),
            expected,
            "moved {case}: {ma:?} {mb:?}"
        );
        let segment = intersection_segment_triangle_triangle(&ta, &tb);
        assert_eq!(segment.is_some(), expected, "segment {case}");
        let d = distance_triangle_triangle(&ta, &tb);
        assert_eq!(d.distance == 0.0, expected, "distance {case}: {d:?}");
        check_distance(&ta, &tb, &d, 16.0, &format!("integer {case}: {a:?} {b:?}"));
        if expected {
            hits += 1;
        } else {
            misses += 1;
            // Integer triangles that do not meet are at least 1 / (a small integer) apart,
            // far above rounding.
            assert!(d.distance > 1e-4, "case {case}: {d:?}");
        }
    }
    assert!(
        hits > 15_000 && misses > 15_000,
        "{hits} hits, {misses} misses"
    );
}

#[test]
fn intersection_segment_lies_on_both_triangles() {
    let mut r = rng(0x5e6);
    let mut proper = 0;
    for case in 0..20_000 {
        let (a, b) = hard_pair(&mut r);
        let (ta, tb) = (to_triangle(&a), to_triangle(&b));
        let Some((p, q)) = intersection_segment_triangle_triangle(&ta, &tb) else {
            continue;
        };
        for x in [p, q, (p + q) * 0.5] {
            // NOTE: the oracle's Gram-matrix solve loses digits on thin integer triangles.
            assert!(
                distance_to(x, &ta) < 1e-9,
                "case {case}: {x} off A {a:?} {b:?}"
            );
            assert!(
                distance_to(x, &tb) < 1e-9,
                "case {case}: {x} off B {a:?} {b:?}"
            );
        }
        proper += usize::from(p != q);
    }
    assert!(proper > 1000, "{proper} proper segments");
}

// ---------------------------------------------------------------------------------------
// Distance oracle for floating-point triangles.

/// Distance from `x` to the closed triangle `t` by brute minimisation over its parameters,
/// independent of the library: Gram-matrix barycentrics for the face, clamped projections
/// for the edges.
fn distance_to(x: DVec3, t: &Triangle) -> f64 {
    let seg = |a: DVec3, b: DVec3| {
        let d = b - a;
        let s = if d.length_squared() > 0.0 {
            ((x - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        x.distance(a + d * s)
    };
    let mut best = seg(t.a, t.b).min(seg(t.b, t.c)).min(seg(t.c, t.a));
    let (u, v, w) = (t.b - t.a, t.c - t.a, x - t.a);
    let (uu, uv, vv, wu, wv) = (u.dot(u), u.dot(v), v.dot(v), w.dot(u), w.dot(v));
    let det = uu * vv - uv * uv;
    if det > 1e-12 * uu * vv {
        let s = (wu * vv - wv * uv) / det;
        let k = (wv * uu - wu * uv) / det;
        if s >= 0.0 && k >= 0.0 && s + k <= 1.0 {
            best = best.min(x.distance(t.a + u * s + v * k));
        }
    }
    best
}

fn max_coordinate(a: &Triangle, b: &Triangle) -> f64 {
    [a.a, a.b, a.c, b.a, b.b, b.c]
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max)
}

/// Checks every property of `d = distance(a, b)` that does not depend on how it was found;
/// `size` is the triangles' size, for the tolerances.
fn check_distance(a: &Triangle, b: &Triangle, d: &TriangleDistance, size: f64, what: &str) {
    let m = max_coordinate(a, b);
    let tol = 1e-13 * m + 1e-11 * size;
    assert!(d.distance >= 0.0 && d.distance.is_finite(), "{what}: {d:?}");
    assert!(
        distance_to(d.point_a, a) <= tol,
        "{what}: point_a off A: {d:?}"
    );
    assert!(
        distance_to(d.point_b, b) <= tol,
        "{what}: point_b off B: {d:?}"
    );
    let gap = d.point_b - d.point_a;
    assert!(
        (gap.length() - d.distance).abs() <= 1e-12 * d.distance + 1e-300,
        "{what}"
    );
    // Optimality: no vertex of A lies beyond p along q - p, no vertex of B beyond q along
    // p - q. For convex sets this first-order condition is sufficient.
    for v in a.vertices() {
        let lhs = (v - d.point_a).dot(gap);
        let bound = tol * ((v - d.point_a).length() + d.distance);
        assert!(lhs <= bound, "{what}: A vertex {v} {lhs} > {bound} {d:?}");
    }
    for w in b.vertices() {
        let lhs = (w - d.point_b).dot(-gap);
        let bound = tol * ((w - d.point_b).length() + d.distance);
        assert!(lhs <= bound, "{what}: B vertex {w} {lhs} > {bound} {d:?}");
    }
    // Intersecting pairs have distance exactly 0; disjoint ones closer than rounding may
    // round to 0 too, which the contract allows.
    let exact = intersects_triangle_triangle(a, b);
    if exact {
        assert_eq!(d.distance, 0.0, "{what}: intersecting at {d:?}");
        assert_eq!(d.point_a, d.point_b, "{what}");
    } else {
        assert!(d.distance > 0.0 || d.point_a == d.point_b, "{what}: {d:?}");
    }
    let back = distance_triangle_triangle(b, a);
    assert!(
        (back.distance - d.distance).abs() <= tol,
        "{what}: asymmetric {back:?} {d:?}"
    );
}

fn random_triangle(r: &mut TestRng, center: DVec3, size: f64) -> Triangle {
    let mut p = || center + support::point_in_cube(r, size);
    Triangle::new(p(), p(), p())
}

const SCALES: [f64; 4] = [1e-3, 1e-1, 1.0, 1e3];
const OFFSETS: [f64; 4] = [0.0, 1.0, 1e3, 1e5];

#[test]
fn distance_witnesses_are_optimal_at_every_scale_and_offset() {
    let mut r = rng(0xd157);
    let (mut touching, mut apart) = (0, 0);
    for case in 0..12_000 {
        let size = SCALES[case % 4];
        let center = support::point_in_cube(&mut r, 1.0).normalize() * OFFSETS[(case / 4) % 4];
        let a = random_triangle(&mut r, center, size);
        let shift = support::point_in_cube(&mut r, 1.0) * size * r.random_range(0.0..0.8);
        let b = random_triangle(&mut r, center + shift, size);
        let d = distance_triangle_triangle(&a, &b);
        check_distance(&a, &b, &d, size, &format!("case {case}"));
        if d.distance == 0.0 {
            touching += 1;
        } else {
            apart += 1;
        }
    }
    assert!(
        touching > 2000 && apart > 2000,
        "{touching} touching, {apart} apart"
    );
}

#[test]
fn separated_and_crossing_constructions_are_classified_with_margin() {
    let mut r = rng(0x5eb);
    for case in 0..4_000 {
        let size = SCALES[case % 4];
        let center = DVec3::splat(OFFSETS[(case / 4) % 4]);
        let a = random_triangle(&mut r, center, size);
        // Separated along u by `gap`: the projection bound proves distance >= gap.
        let u = rotation(&mut r) * DVec3::X;
        let mut b = random_triangle(&mut r, center, size);
        let gap = size * r.random_range(1e-6..1.0);
        let reach_a = a
            .vertices()
            .map(|p| p.dot(u))
            .into_iter()
            .fold(f64::MIN, f64::max);
        let low_b = b
            .vertices()
            .map(|p| p.dot(u))
            .into_iter()
            .fold(f64::MAX, f64::min);
        let lift = u * (reach_a - low_b + gap);
        b = Triangle::new(b.a + lift, b.b + lift, b.c + lift);
        let d = distance_triangle_triangle(&a, &b);
        let slack = 1e-13 * max_coordinate(&a, &b) + 1e-12 * size;
        assert!(d.distance >= gap - slack, "case {case}: {d:?} < {gap}");
        check_distance(&a, &b, &d, size, &format!("separated {case}"));
        // Crossing: B built around an interior point of A, tilted out of A's plane.
        let x = a.a * 0.3 + a.b * 0.3 + a.c * 0.4;
        let normal = a.normal().unwrap();
        // Its centroid is x, an interior point of A, and it spans the normal: transversal.
        let w = support::point_in_cube(&mut r, size);
        let h = normal * size * r.random_range(0.1..1.0);
        let crossing = Triangle::new(x + h + w, x - h + w, x - w * 2.0);
        assert!(
            intersects_triangle_triangle(&a, &crossing),
            "crossing {case}"
        );
        check_distance(
            &a,
            &crossing,
            &distance_triangle_triangle(&a, &crossing),
            size,
            "x",
        );
    }
}

#[test]
fn distance_never_exceeds_a_dense_sampled_minimum() {
    let mut r = rng(0xb7f);
    const N: usize = 14;
    let samples = |t: &Triangle| {
        let mut out = Vec::with_capacity((N + 1) * (N + 2) / 2);
        for i in 0..=N {
            for j in 0..=N - i {
                let (s, k) = (i as f64 / N as f64, j as f64 / N as f64);
                out.push(t.a * (1.0 - s - k) + t.b * s + t.c * k);
            }
        }
        out
    };
    for case in 0..1_500 {
        let size = SCALES[case % 4];
        let center = DVec3::splat(OFFSETS[(case / 4) % 4]);
        let a = random_triangle(&mut r, center, size);
        let shift = support::point_in_cube(&mut r, 1.0) * size * 3.0;
        let b = random_triangle(&mut r, center + shift, size);
        let d = distance_triangle_triangle(&a, &b);
        let (sa, sb) = (samples(&a), samples(&b));
        let sampled = sa
            .iter()
            .flat_map(|p| sb.iter().map(move |q| p.distance(*q)))
            .fold(f64::MAX, f64::min);
        let slack = 1e-13 * max_coordinate(&a, &b) + 1e-12 * size;
        assert!(
            d.distance <= sampled + slack,
            "case {case}: {d:?} > {sampled}"
        );
    }
}

// ---------------------------------------------------------------------------------------
// Stress cases.

fn placed(q: DQuat, offset: DVec3, s: f64, pts: [[f64; 3]; 3]) -> Triangle {
    let p = |c: [f64; 3]| offset + q * (DVec3::from(c) * s);
    Triangle::new(p(pts[0]), p(pts[1]), p(pts[2]))
}

#[test]
fn coplanar_overlap_and_shared_edges_intersect_at_any_pose() {
    let mut r = rng(0xc0);
    for case in 0..4_000 {
        let (s, q) = (SCALES[case % 4], rotation(&mut r));
        let offset = DVec3::new(1e5, -1e5, 1e5) * (case % 2) as f64;
        let a = placed(
            q,
            offset,
            s,
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        );
        // Shared edge, other vertex on the far side: touching along the edge.
        let b = Triangle::new(a.b, a.c, placed(q, offset, s, [[1.0, 1.0, 0.0]; 3]).a);
        assert!(intersects_triangle_triangle(&a, &b), "shared edge {case}");
        check_distance(
            &a,
            &b,
            &distance_triangle_triangle(&a, &b),
            s,
            "shared edge",
        );
        // Coplanar overlap, well inside: robust to the rounding of the rotation.
        let c = placed(
            q,
            offset,
            s,
            [[0.2, 0.2, 0.0], [2.0, 0.1, 0.0], [0.1, 2.0, 0.0]],
        );
        // Rounding of the pose leaves them only nearly coplanar: the exact answer may be
        // either, the distance is 0 to rounding.
        let d = distance_triangle_triangle(&a, &c);
        assert!(
            d.distance <= 1e-15 * 1e5 + 1e-15 * s,
            "coplanar overlap {case}: {d:?}"
        );
        check_distance(&a, &c, &d, s, "coplanar overlap");
        // Coplanar, 0.2 / √2 (times the size) across the hypotenuse.
        let e = placed(
            q,
            offset,
            s,
            [[0.6, 0.6, 0.0], [2.0, 0.6, 0.0], [0.6, 2.0, 0.0]],
        );
        let d = distance_triangle_triangle(&a, &e);
        let expected = 0.2 / 2f64.sqrt() * s;
        assert!(
            (d.distance - expected).abs() <= 1e-10 * s + 1e-15 * 1e5,
            "{case} {d:?}"
        );
        check_distance(&a, &e, &d, s, "coplanar gap");
        // Nearly identical: every vertex moved by ~1e-12 of the size.
        let jitter = |p: DVec3, r: &mut TestRng| p + support::point_in_cube(r, 1e-12 * s);
        let f = Triangle::new(
            jitter(a.a, &mut r),
            jitter(a.b, &mut r),
            jitter(a.c, &mut r),
        );
        let d = distance_triangle_triangle(&a, &f);
        assert!(d.distance <= 2e-12 * s, "nearly identical {case}: {d:?}");
        check_distance(&a, &f, &d, s, "nearly identical");
    }
}

#[test]
fn nearly_parallel_edges_keep_their_exact_gap() {
    let mut r = rng(0xed9e);
    for case in 0..4_000 {
        let s = SCALES[case % 4];
        let angle = 10f64.powf(-r.random_range(3.0..9.0));
        let offset = DVec3::splat(1e5) * ((case / 4) % 2) as f64;
        let q = rotation(&mut r);
        let gap = s * r.random_range(1e-6..1e-1);
        // A's edge along x at z = 0, body below; B's edge at z = gap, turned by `angle`
        // about z, body above: the edges hold the closest pair, `gap` apart.
        let a = placed(
            q,
            offset,
            s,
            [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.3, -1.0]],
        );
        let (c, sn) = (angle.cos(), angle.sin());
        let g = gap / s;
        let b = placed(
            q,
            offset,
            s,
            [[-c, -sn, g], [c, sn, g], [0.0, -0.3, 1.0 + g]],
        );
        let d = distance_triangle_triangle(&a, &b);
        let tol = 1e-12 * gap + 1e-15 * 1e5 * ((case / 4) % 2) as f64 + 1e-15 * s;
        assert!(
            (d.distance - gap).abs() <= tol,
            "case {case} angle {angle}: {d:?} vs {gap}"
        );
        check_distance(&a, &b, &d, s, &format!("parallel {case}"));
    }
}

#[test]
fn edges_crossing_at_tiny_angles_touch() {
    let mut r = rng(0xc4055);
    for case in 0..4_000 {
        let s = SCALES[case % 4];
        let angle = 10f64.powf(-r.random_range(3.0..9.0));
        let (c, sn) = (angle.cos(), angle.sin());
        // Both edges pass exactly through the origin (their end points are negatives of
        // each other), the bodies on opposite sides of z = 0: they touch at one point.
        let a = placed(
            DQuat::IDENTITY,
            DVec3::ZERO,
            s,
            [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.3, -1.0]],
        );
        let b = placed(
            DQuat::IDENTITY,
            DVec3::ZERO,
            s,
            [[-c, -sn, 0.0], [c, sn, 0.0], [0.0, -0.3, 1.0]],
        );
        assert!(
            intersects_triangle_triangle(&a, &b),
            "case {case} angle {angle}"
        );
        let d = distance_triangle_triangle(&a, &b);
        assert!(d.point_a.length() <= 1e-15 * s, "case {case}: {d:?}");
        check_distance(&a, &b, &d, s, "crossing");
        // Lifted by one part in 1e12 of the size: apart, by exactly that gap to rounding.
        let lift = DVec3::Z * (1e-12 * s);
        let up = Triangle::new(b.a + lift, b.b + lift, b.c + lift);
        assert!(!intersects_triangle_triangle(&a, &up), "lifted {case}");
        let d = distance_triangle_triangle(&a, &up);
        // NOTE: the witnesses' in-plane rounding (~eps·s) adds in quadrature: relative
        // error about (1e-16 / 1e-12)².
        assert!(
            (d.distance - 1e-12 * s).abs() <= 1e-6 * 1e-12 * s,
            "lifted {case}: {d:?}"
        );
        // The same at a pose far from the origin: decided either way, distance ~ 0.
        let (q, offset) = (rotation(&mut r), DVec3::new(1e5, -1e5, 1e5));
        let pose =
            |t: &Triangle| Triangle::new(offset + q * t.a, offset + q * t.b, offset + q * t.c);
        let (fa, fb) = (pose(&a), pose(&b));
        let d = distance_triangle_triangle(&fa, &fb);
        assert!(d.distance <= 1e-15 * 1e5 * 4.0, "posed {case}: {d:?}");
        check_distance(&fa, &fb, &d, s, "posed crossing");
    }
}
