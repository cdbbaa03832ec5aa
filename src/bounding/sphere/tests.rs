//! Seeded tests of the bounding sphere.

use super::*;
use crate::test_support::{self as support, CloudKind};
use rand::Rng;

/// The exact minimum ball of a handful of points, by trying every ball through 2, 3 or 4
/// of them (and the 1-point ball).
fn brute_force_min_radius(points: &[DVec3]) -> f64 {
    let covers = |c: DVec3, r: f64| {
        points
            .iter()
            .all(|p| p.distance(c) <= r * (1.0 + 1e-9) + 1e-12)
    };
    let mut best = f64::INFINITY;
    let mut consider = |c: Option<DVec3>, support: &[DVec3]| {
        if let Some(c) = c {
            let r = support.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
            if r < best && covers(c, r) {
                best = r;
            }
        }
    };
    let n = points.len();
    consider(Some(points[0]), &points[..1]);
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (points[i], points[j]);
            consider(Some((a + b) * 0.5), &[a, b]);
            for k in j + 1..n {
                let c = points[k];
                consider(welzl_circumcenter3(a, b, c), &[a, b, c]);
                for &d in &points[k + 1..] {
                    consider(welzl_circumcenter4(a, b, c, d), &[a, b, c, d]);
                }
            }
        }
    }
    best
}

// Independent circumcentres by solving the linear systems with glam's inverse.
fn welzl_circumcenter3(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    let (u, v) = (b - a, c - a);
    let n = u.cross(v);
    let m = crate::math::DMat3::from_cols(u, v, n).transpose();
    let rhs = DVec3::new(u.length_squared() / 2.0, v.length_squared() / 2.0, 0.0);
    (m.determinant().abs() > 1e-18).then(|| a + m.inverse() * rhs)
}

fn welzl_circumcenter4(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<DVec3> {
    let (u, v, w) = (b - a, c - a, d - a);
    let m = crate::math::DMat3::from_cols(u, v, w).transpose();
    let rhs = DVec3::new(u.length_squared(), v.length_squared(), w.length_squared()) / 2.0;
    (m.determinant().abs() > 1e-12).then(|| a + m.inverse() * rhs)
}

#[test]
fn fitted_spheres_contain_every_point_across_the_degenerate_matrix() {
    let mut rng = support::rng(1);
    for case in 0..3000 {
        let (points, _) = support::random_cloud(&mut rng, 60);
        for sphere in [
            BoundingSphere::fit_points(&points),
            BoundingSphere::fit_points_ritter(&points),
        ] {
            assert!(sphere.radius.is_finite() && sphere.center.is_finite());
            for p in &points {
                assert!(
                    sphere.contains_point(*p),
                    "case {case}: {p} not in {sphere:?}"
                );
            }
        }
    }
}

#[test]
fn welzl_matches_the_brute_force_minimum_ball() {
    let mut rng = support::rng(2);
    for case in 0..2000 {
        let n = rng.random_range(1..=7);
        let points: Vec<DVec3> = (0..n)
            .map(|_| support::point_in_cube(&mut rng, 1.0))
            .collect();
        let welzl = BoundingSphere::fit_points(&points);
        let ritter = BoundingSphere::fit_points_ritter(&points);
        let exact = brute_force_min_radius(&points);
        assert!(
            (welzl.radius - exact).abs() <= 1e-9 * exact.max(1.0),
            "case {case}: welzl {} vs brute force {exact}",
            welzl.radius
        );
        assert!(welzl.radius <= ritter.radius + 1e-12, "case {case}");
    }
}

#[test]
fn welzl_is_minimal_on_large_clouds_far_from_the_origin() {
    let mut rng = support::rng(3);
    for kind in [
        CloudKind::Sphere,
        CloudKind::Box,
        CloudKind::Collinear,
        CloudKind::Coplanar,
    ] {
        for &offset in &support::CENTERS {
            let center = DVec3::new(offset, -offset, 0.5 * offset);
            let points = support::cloud(&mut rng, kind, 2000, center, 1.0);
            let welzl = BoundingSphere::fit_points(&points);
            let ritter = BoundingSphere::fit_points_ritter(&points);
            assert!(
                welzl.radius <= ritter.radius * (1.0 + 1e-9),
                "{kind:?} {offset}"
            );
            // Minimality: the farthest-point distance is convex in the centre, so the
            // centre is its minimum when no small step in any direction lowers it.
            let farthest = |c: DVec3| points.iter().map(|p| p.distance(c)).fold(0.0, f64::max);
            let at_center = farthest(welzl.center);
            for _ in 0..50 {
                let step = support::point_in_cube(&mut rng, 1.0).normalize_or(DVec3::X);
                let moved = farthest(welzl.center + step * 1e-4);
                assert!(
                    moved >= at_center - 1e-9 * (1.0 + offset),
                    "{kind:?} {offset}"
                );
            }
            if kind == CloudKind::Sphere {
                // Points on the unit sphere: the minimum ball is about that sphere.
                assert!((welzl.radius - 1.0).abs() < 1e-2, "radius {}", welzl.radius);
            }
        }
    }
}

#[test]
fn fit_handles_a_hundred_thousand_points() {
    let mut rng = support::rng(4);
    let points = support::cloud(&mut rng, CloudKind::Sphere, 100_000, DVec3::splat(1e6), 3.0);
    let sphere = BoundingSphere::fit_points(&points);
    assert!(
        (sphere.radius - 3.0).abs() < 1e-3,
        "radius {}",
        sphere.radius
    );
    assert!(points.iter().all(|p| sphere.contains_point(*p)));
}

#[test]
fn degenerate_inputs_give_finite_tight_spheres() {
    let p = DVec3::new(1e6, -2.0, 3.0);
    let single = BoundingSphere::fit_points(&[p]);
    assert!(single.contains_point(p) && single.radius < 1e-5);
    let duplicates = BoundingSphere::fit_points(&[p; 50]);
    assert!(duplicates.contains_point(p) && duplicates.radius < 1e-5);
    let line: Vec<DVec3> = (0..100).map(|i| DVec3::X * f64::from(i)).collect();
    let sphere = BoundingSphere::fit_points(&line);
    assert!(
        (sphere.radius - 49.5).abs() < 1e-9 && sphere.center.abs_diff_eq(DVec3::X * 49.5, 1e-9)
    );
    // A square: four concyclic coplanar points.
    let square = [DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y, DVec3::ZERO];
    let sphere = BoundingSphere::fit_points(&square);
    assert!((sphere.radius - 1.0).abs() < 1e-9 && sphere.center.length() < 1e-9);
    let tri = Triangle::new(DVec3::ZERO, DVec3::X, DVec3::X * 2.0);
    let sphere = BoundingSphere::fit_triangles(&[tri]);
    assert!((sphere.radius - 1.0).abs() < 1e-9);
}

#[test]
fn merged_is_the_smallest_sphere_containing_both() {
    let mut rng = support::rng(5);
    for case in 0..3000 {
        let scale = support::SCALES[case % 5];
        let offset = support::CENTERS[case % 4];
        let a = BoundingSphere::new(
            support::point_in_cube(&mut rng, scale) + DVec3::splat(offset),
            rng.random_range(0.0..scale),
        );
        let b = BoundingSphere::new(
            support::point_in_cube(&mut rng, scale) + DVec3::splat(offset),
            rng.random_range(0.0..scale),
        );
        let m = a.merged(&b);
        for s in [a, b] {
            // Far points of each input sphere, in random directions and towards the other.
            for dir in [
                support::point_in_cube(&mut rng, 1.0).normalize_or(DVec3::X),
                (s.center - m.center).normalize_or(DVec3::X),
            ] {
                assert!(m.contains_point(s.center + dir * s.radius), "case {case}");
            }
        }
        let expected = ((a.center.distance(b.center) + a.radius + b.radius) * 0.5)
            .max(a.radius)
            .max(b.radius);
        assert!(m.radius >= expected && m.radius <= expected + 1e-9 * (offset + scale));
    }
}

#[test]
fn transformed_contains_the_moved_points() {
    let mut rng = support::rng(6);
    for case in 0..2000 {
        let (points, _) = support::random_cloud(&mut rng, 40);
        let pose = support::isometry(&mut rng, 1e3);
        let moved = BoundingSphere::fit_points(&points).transformed(&pose);
        for p in &points {
            assert!(
                moved.contains_point(pose.transform_point(*p)),
                "case {case}"
            );
        }
    }
}

#[test]
fn overlap_and_distance_bound_are_conservative_against_brute_force() {
    let mut rng = support::rng(7);
    let (mut overlapping, mut apart) = (0, 0);
    for case in 0..3000 {
        let (a_points, scale) = support::random_cloud(&mut rng, 20);
        let (mut b_points, _) = support::random_cloud(&mut rng, 20);
        let pose_ab = support::isometry(&mut rng, 2.0 * scale);
        if case % 3 == 0 {
            // Force a shared point.
            b_points.push(pose_ab.inverse_transform_point(a_points[0]));
        }
        let a = BoundingSphere::fit_points(&a_points);
        let b = BoundingSphere::fit_points(&b_points);
        let b_in_a: Vec<DVec3> = b_points
            .iter()
            .map(|p| pose_ab.transform_point(*p))
            .collect();
        let truth = support::min_distance(&a_points, &b_in_a);
        let bound = a.distance_lower_bound(&b, &pose_ab);
        assert!(bound <= truth, "case {case}: bound {bound} > truth {truth}");
        let overlap = a.overlaps(&b, &pose_ab);
        if case % 3 == 0 {
            assert!(overlap && bound == 0.0, "case {case}: shared point missed");
        }
        if overlap {
            overlapping += 1;
            assert_eq!(bound, 0.0, "case {case}");
        } else {
            apart += 1;
            assert!(bound > 0.0, "case {case}");
        }
    }
    assert!(overlapping > 300 && apart > 300, "{overlapping} / {apart}");
}

#[test]
fn transformed_then_identity_overlap_equals_overlap_under_the_pose() {
    let mut rng = support::rng(8);
    for case in 0..3000 {
        let a = BoundingSphere::new(support::point_in_cube(&mut rng, 3.0), rng.random());
        let b = BoundingSphere::new(support::point_in_cube(&mut rng, 3.0), rng.random());
        let pose = support::isometry(&mut rng, 3.0);
        let moved = b.transformed(&pose);
        let d_direct = a.distance_lower_bound(&b, &pose);
        let d_moved = a.distance_lower_bound(&moved, &Isometry::IDENTITY);
        assert!((d_direct - d_moved).abs() < 1e-9, "case {case}");
        if (a.center.distance(moved.center) - a.radius - b.radius).abs() > 1e-9 {
            assert_eq!(
                a.overlaps(&b, &pose),
                a.overlaps(&moved, &Isometry::IDENTITY),
                "case {case}"
            );
        }
    }
}

#[test]
fn measures_follow_the_radius() {
    let s = BoundingSphere::new(DVec3::new(1.0, 2.0, 3.0), 2.0);
    assert_eq!(s.size(), 4.0);
    assert_eq!(s.stand_off(), 4.0);
    assert!((s.volume() - 32.0 / 3.0 * std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(BoundingVolume::center(&s), s.center);
    assert_eq!(BoundingSphere::NAME, "sphere");
}
