//! Hand-computed cases for the triangle–triangle queries.

use super::*;

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

fn tri(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Triangle {
    Triangle::new(DVec3::from(a), DVec3::from(b), DVec3::from(c))
}

/// The unit right triangle in the plane z = 0.
fn base() -> Triangle {
    tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
}

fn both_ways(a: &Triangle, b: &Triangle) -> bool {
    let ab = intersects_triangle_triangle(a, b);
    assert_eq!(
        ab,
        intersects_triangle_triangle(b, a),
        "asymmetric on {a:?} {b:?}"
    );
    ab
}

#[test]
fn crossing_triangles_intersect_along_the_expected_segment() {
    let a = base();
    let b = tri([0.25, 0.25, -1.0], [0.25, 0.25, 1.0], [2.0, 0.25, 0.0]);
    assert!(both_ways(&a, &b));
    let (p, q) = intersection_segment_triangle_triangle(&a, &b).unwrap();
    // B cuts z = 0 along y = 0.25 from x = 0.25 to x = 2; A spans x in [0, 0.75] there.
    let (lo, hi) = if p.x < q.x { (p, q) } else { (q, p) };
    assert!(lo.distance(v(0.25, 0.25, 0.0)) < 1e-15, "{lo}");
    assert!(hi.distance(v(0.75, 0.25, 0.0)) < 1e-15, "{hi}");
    assert_eq!(distance_triangle_triangle(&a, &b).distance, 0.0);
}

#[test]
fn separated_parallel_triangles_are_their_plane_gap_apart() {
    let a = base();
    let b = tri([0.1, 0.1, 2.0], [0.4, 0.1, 2.0], [0.1, 0.4, 2.0]);
    assert!(!both_ways(&a, &b));
    assert_eq!(intersection_segment_triangle_triangle(&a, &b), None);
    let d = distance_triangle_triangle(&a, &b);
    assert!((d.distance - 2.0).abs() < 1e-15);
    assert!((d.point_a - d.point_b - v(0.0, 0.0, -2.0)).length() < 1e-15);
}

#[test]
fn shared_vertex_and_shared_edge_count_as_intersecting() {
    let a = base();
    let vertex = tri([0.0, 0.0, 0.0], [-1.0, -1.0, 1.0], [-1.0, 0.0, -1.0]);
    let edge = tri([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, -1.0, 0.3]);
    let coplanar_edge = tri([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]);
    for b in [vertex, edge, coplanar_edge] {
        assert!(both_ways(&a, &b), "{b:?}");
        assert_eq!(distance_triangle_triangle(&a, &b).distance, 0.0);
    }
}

#[test]
fn touching_at_one_point_from_above_intersects_and_a_hair_away_does_not() {
    let a = base();
    let touching = tri([0.2, 0.2, 0.0], [0.2, 0.3, 1.0], [0.3, 0.2, 1.0]);
    assert!(both_ways(&a, &touching));
    let lifted = tri([0.2, 0.2, 1e-100], [0.2, 0.3, 1.0], [0.3, 0.2, 1.0]);
    assert!(!both_ways(&a, &lifted));
    let d = distance_triangle_triangle(&a, &lifted);
    assert!(d.distance > 0.0 && d.distance <= 1e-100, "{d:?}");
}

#[test]
fn coplanar_overlap_containment_and_disjointness_are_decided_in_the_plane() {
    let a = base();
    let inside = tri([0.1, 0.1, 0.0], [0.2, 0.1, 0.0], [0.1, 0.2, 0.0]);
    let crossing = tri([0.5, -0.5, 0.0], [0.5, 2.0, 0.0], [-2.0, 0.5, 0.0]);
    let apart = tri([0.6, 0.6, 0.0], [2.0, 0.6, 0.0], [0.6, 2.0, 0.0]);
    assert!(both_ways(&a, &inside));
    assert!(both_ways(&inside, &a));
    assert!(both_ways(&a, &crossing));
    assert!(!both_ways(&a, &apart));
    let d = distance_triangle_triangle(&a, &apart);
    // Closest: the hypotenuse x + y = 1 to the vertex (0.6, 0.6): (1.2 - 1) / √2.
    assert!((d.distance - 0.2 / 2f64.sqrt()).abs() < 1e-15, "{d:?}");
    let (p, q) = intersection_segment_triangle_triangle(&a, &inside).unwrap();
    assert_eq!(p, q);
    assert!(intersects_triangle_triangle(&a, &Triangle::new(p, p, p)));
}

#[test]
fn zero_area_triangles_are_decided_as_segments_and_points() {
    let a = base();
    let needle_through = tri([0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [0.2, 0.2, 0.5]);
    let needle_beside = tri([0.6, 0.6, -1.0], [0.6, 0.6, 1.0], [0.6, 0.6, 0.0]);
    let needle_on_edge = tri([-1.0, 0.0, 0.0], [3.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
    let point_inside = tri([0.3, 0.3, 0.0], [0.3, 0.3, 0.0], [0.3, 0.3, 0.0]);
    let point_above = tri([0.3, 0.3, 0.5], [0.3, 0.3, 0.5], [0.3, 0.3, 0.5]);
    assert!(both_ways(&a, &needle_through));
    assert!(!both_ways(&a, &needle_beside));
    assert!(both_ways(&a, &needle_on_edge));
    assert!(both_ways(&a, &point_inside));
    assert!(!both_ways(&a, &point_above));
    assert!(both_ways(&point_inside, &point_inside));
    assert!(both_ways(&needle_on_edge, &point_on(0.5)));
    assert!(!both_ways(&needle_on_edge, &needle_beside));
    let d = distance_triangle_triangle(&a, &point_above);
    assert!((d.distance - 0.5).abs() < 1e-15 && d.point_a.distance(v(0.3, 0.3, 0.0)) < 1e-15);
    let d = distance_triangle_triangle(&a, &needle_beside);
    assert!((d.distance - 0.2 / 2f64.sqrt()).abs() < 1e-15, "{d:?}");
}

fn point_on(x: f64) -> Triangle {
    let p = v(x, 0.0, 0.0);
    Triangle::new(p, p, p)
}

#[test]
fn skew_edges_give_the_edge_edge_distance() {
    let a = tri([0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, -3.0]);
    let b = tri([1.0, -1.0, 0.5], [1.0, 1.0, 0.5], [1.0, 0.0, 4.0]);
    assert!(!both_ways(&a, &b));
    let d = distance_triangle_triangle(&a, &b);
    assert!((d.distance - 0.5).abs() < 1e-15, "{d:?}");
    assert!(d.point_a.distance(v(1.0, 0.0, 0.0)) < 1e-15);
    assert!(d.point_b.distance(v(1.0, 0.0, 0.5)) < 1e-15);
    let back = distance_triangle_triangle(&b, &a);
    assert_eq!(back.distance, d.distance);
}

#[test]
fn near_miss_at_large_offset_is_decided_exactly() {
    // B's tip is one ulp above A's plane z = 1e5; A's plane is exact in f64.
    let z: f64 = 1e5;
    let up = f64::from_bits(z.to_bits() + 1);
    let a = tri([1e5, 1e5, z], [1e5 + 1.0, 1e5, z], [1e5, 1e5 + 1.0, z]);
    let b = tri(
        [1e5 + 0.25, 1e5 + 0.25, up],
        [1e5, 1e5, 1e5 + 1.0],
        [1e5 + 1.0, 1e5, 1e5 + 1.0],
    );
    assert!(!both_ways(&a, &b));
    let on = Triangle::new(v(1e5 + 0.25, 1e5 + 0.25, z), b.b, b.c);
    assert!(both_ways(&a, &on));
}

/// The distance from the closed segment `p q` to triangle `t`, by golden-section search
/// of `s ↦ dist(p + s (q − p), t)`, convex as the distance to a convex set along a line
/// (an oracle independent of the feature-pair method: it needs only the point–triangle
/// closest point, checked against its own oracle in `closest_points`).
fn segment_triangle_distance_by_search(p: DVec3, q: DVec3, t: &Triangle) -> f64 {
    let f = |s: f64| {
        let x = p + (q - p) * s;
        x.distance(crate::narrow::closest_points::closest_point_triangle(
            x, t.a, t.b, t.c,
        ))
    };
    crate::test_support::convex_minimum_on_unit_interval(f)
}

#[test]
fn distances_to_sliver_triangles_match_a_line_search_oracle() {
    use crate::test_support::{point_in_cube, rng, rotation};
    use rand::Rng;
    let mut r = rng(0x5_11e4);
    let (mut touching, mut apart) = (0, 0);
    for case in 0..3000 {
        // A: generic, or itself a sliver half of the time.
        let a = {
            let (x, y) = (point_in_cube(&mut r, 1.0), point_in_cube(&mut r, 1.0));
            let z = if r.random_bool(0.5) {
                x + (y - x) * r.random_range(-0.5..1.5)
            } else {
                point_in_cube(&mut r, 1.0)
            };
            Triangle::new(x, y, z)
        };
        // B: x, y, x + 0.3 (y − x) (zero area before placement) through a point near A.
        let centre = a.a + (a.b - a.a) * r.random_range(0.0..0.7) + (a.c - a.a) * 0.2;
        let half = point_in_cube(&mut r, 1.0);
        let (x, y) = (centre - half, centre + half + point_in_cube(&mut r, 0.3));
        let b = Triangle::new(x, y, x + (y - x) * r.random_range(-0.5..1.5));
        let rot = crate::math::DMat3::from_quat(rotation(&mut r));
        let offset = point_in_cube(&mut r, 20.0);
        let place = |t: &Triangle| {
            let m = |v: DVec3| rot * v + offset;
            Triangle::new(m(t.a), m(t.b), m(t.c))
        };
        let (a, b) = (place(&a), place(&b));
        let scale = a
            .vertices()
            .iter()
            .chain(b.vertices().iter())
            .fold(0.0f64, |m, v| m.max(v.abs().max_element()));
        // B's hull is its longest edge (to rounding).
        let edges = [(b.a, b.b), (b.b, b.c), (b.c, b.a)];
        let (p, q) = edges
            .into_iter()
            .max_by(|e, f| e.0.distance(e.1).total_cmp(&f.0.distance(f.1)))
            .unwrap();
        let want = segment_triangle_distance_by_search(p, q, &a);
        for (first, second, swapped) in [(&a, &b, false), (&b, &a, true)] {
            let d = distance_triangle_triangle(first, second);
            let (pa, pb) = if swapped {
                (d.point_b, d.point_a)
            } else {
                (d.point_a, d.point_b)
            };
            let on_a = pa.distance(crate::narrow::closest_points::closest_point_triangle(
                pa, a.a, a.b, a.c,
            ));
            let on_b = pb.distance(crate::narrow::closest_points::closest_point_segment(
                pb, p, q,
            ));
            assert!(
                (d.distance - want).abs() <= 1e-13 * scale
                    && on_a <= 1e-13 * scale
                    && on_b <= 1e-13 * scale
                    && (pa.distance(pb) - d.distance).abs() <= 1e-13 * scale,
                "case {case} (swapped {swapped}): {d:?}, oracle {want}, witnesses {on_a} \
                 off A and {on_b} off B; A {a:?} B {b:?}"
            );
        }
        if want <= 1e-13 * scale {
            touching += 1;
        } else {
            apart += 1;
        }
    }
    assert!(
        touching > 100 && apart > 1000,
        "{touching} touching, {apart} apart"
    );
}
