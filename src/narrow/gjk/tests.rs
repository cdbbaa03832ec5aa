//! Unit tests of GJK/EPA on shapes with closed-form answers. The brute-force oracles over
//! hulls, boxes and random poses are in `tests/gjk_oracle.rs`.

use super::*;
use crate::geometry::Cuboid;
use crate::math::{DQuat, Pose};
use crate::test_support::{isometry, point_in_cube, rng};

fn query<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &Rounded<'_, A>,
    b: &Rounded<'_, B>,
    pose: &Isometry,
) -> (ShapeDistance, ConvexOutcome) {
    signed_distance_convex(
        a,
        b,
        pose,
        &GjkParams::default(),
        &mut GjkCache::default(),
        &mut EpaWorkspace::new(),
    )
}

fn check_contract(d: &ShapeDistance, tol: f64) {
    assert!(d.distance.is_finite() && d.normal.is_finite(), "{d:?}");
    assert!((d.normal.length() - 1.0).abs() < 1e-9, "{d:?}");
    let gap = d.point_b - d.point_a - d.normal * d.distance;
    assert!(gap.length() <= tol, "witnesses off by {gap}: {d:?}");
}

#[test]
fn spheres_at_random_poses_match_the_centre_distance_minus_radii() {
    let mut r = rng(1);
    let (mut apart, mut deep) = (0, 0);
    for _ in 0..2000 {
        let (ra, rb) = (
            0.1 + point_in_cube(&mut r, 1.0).x.abs(),
            0.1 + point_in_cube(&mut r, 1.0).y.abs(),
        );
        let pose = isometry(&mut r, 2.0);
        let (a, b) = (Sphere::new(ra), Sphere::new(rb));
        let (d, _) = query(&Rounded::sphere(&a), &Rounded::sphere(&b), &pose);
        let want = pose.translation.length() - ra - rb;
        assert!(
            (d.distance - want).abs() < 1e-12,
            "{} vs {want}",
            d.distance
        );
        check_contract(&d, 1e-12);
        assert!((d.normal - pose.translation.normalize()).length() < 1e-9);
        if want > 0.0 { apart += 1 } else { deep += 1 }
    }
    assert!(apart > 100 && deep > 100, "{apart} {deep}");
}

#[test]
fn concentric_spheres_answer_the_sum_of_radii_with_a_fixed_normal() {
    let (d, _) = query(
        &Rounded::sphere(&Sphere::new(1.0)),
        &Rounded::sphere(&Sphere::new(2.0)),
        &Isometry::IDENTITY,
    );
    assert_eq!(d.distance, -3.0);
    assert_eq!(d.normal, DVec3::X);
    check_contract(&d, 1e-15);
}

#[test]
fn a_sphere_against_a_box_matches_the_clamped_point_distance() {
    let mut r = rng(2);
    let (mut apart, mut deep) = (0, 0);
    let cube = Cuboid::new(DVec3::new(1.0, 0.5, 0.25));
    for _ in 0..2000 {
        let c = point_in_cube(&mut r, 2.0);
        let radius = 0.3;
        let pose = Isometry::from_translation(c);
        let (d, _) = query(
            &Rounded::plain(&cube),
            &Rounded::sphere(&Sphere::new(radius)),
            &pose,
        );
        let h = cube.half_extents;
        let outside = (c.abs() - h).max(DVec3::ZERO).length();
        let inside = (h - c.abs()).min_element();
        let want = if outside > 0.0 { outside } else { -inside } - radius;
        assert!(
            (d.distance - want).abs() < 1e-9,
            "{c}: {} vs {want}",
            d.distance
        );
        check_contract(&d, 1e-9);
        if want > 0.0 { apart += 1 } else { deep += 1 }
    }
    assert!(apart > 100 && deep > 100, "{apart} {deep}");
}

#[test]
fn capsules_match_the_segment_segment_distance() {
    let mut r = rng(3);
    let (mut apart, mut deep) = (0, 0);
    for _ in 0..2000 {
        let (a, b) = (Capsule::new(0.7, 0.2), Capsule::new(0.4, 0.3));
        let pose = isometry(&mut r, 1.5);
        let (sa, sb) = (capsule_core(&a), capsule_core(&b));
        let (d, _) = query(
            &Rounded::new(&sa, a.radius),
            &Rounded::new(&sb, b.radius),
            &pose,
        );
        let sb_in_a = Segment::new(pose.transform_point(sb.a), pose.transform_point(sb.b));
        let (_, _, p, q) = crate::geometry::closest_points_segment_segment(&sa, &sb_in_a);
        let core = (q - p).length();
        if core > 1e-6 {
            let want = core - a.radius - b.radius;
            assert!((d.distance - want).abs() < 1e-9, "{} vs {want}", d.distance);
            check_contract(&d, 1e-9);
            if want > 0.0 { apart += 1 } else { deep += 1 }
        } else {
            // Crossing cores: depth at least the radii.
            assert!(d.distance <= -(a.radius + b.radius) + 1e-9);
        }
    }
    assert!(apart > 100 && deep > 100, "{apart} {deep}");
}

#[test]
fn boxes_face_to_face_touch_at_zero_without_nan() {
    let a = Cuboid::new(DVec3::splat(1.0));
    for (t, rot) in [
        (DVec3::new(2.0, 0.0, 0.0), DQuat::IDENTITY),
        (DVec3::new(0.0, 2.0, 0.3), DQuat::IDENTITY),
        (DVec3::new(0.5, 0.2, 2.0), DQuat::from_rotation_z(0.3)),
    ] {
        let pose = Pose::new(t, rot).to_isometry();
        let (d, out) = query(&Rounded::plain(&a), &Rounded::plain(&a), &pose);
        assert!(d.distance.abs() < 1e-12, "{d:?} {out:?}");
        check_contract(&d, 1e-12);
        assert!(d.normal.dot(t.normalize()) > 0.5, "{d:?}");
    }
}

#[test]
fn the_accelerated_variant_and_a_warm_start_agree_with_plain_gjk() {
    let mut r = rng(4);
    let a = Cuboid::new(DVec3::new(1.0, 0.3, 0.6));
    let seg = capsule_core(&Capsule::new(0.5, 0.2));
    let cyl = crate::geometry::Cylinder::new(0.5, 0.2);
    let fast = GjkParams {
        accelerated: true,
        ..GjkParams::default()
    };
    let (mut warm_seg, mut warm_cyl) = (GjkCache::default(), GjkCache::default());
    let mut stalled = 0;
    for _ in 0..2000 {
        let pose = isometry(&mut r, 2.0);
        // Polytopes: GJK terminates exactly, so all three agree to rounding.
        let plain = gjk_distance(
            &a,
            &seg,
            &pose,
            &GjkParams::default(),
            &mut GjkCache::default(),
        );
        let acc = gjk_distance(&a, &seg, &pose, &fast, &mut GjkCache::default());
        let w = gjk_distance(&a, &seg, &pose, &GjkParams::default(), &mut warm_seg);
        for other in [acc, w] {
            assert_eq!(plain.outcome, other.outcome, "{plain:?} {other:?}");
            assert!((plain.distance - other.distance).abs() <= 1e-12 * (1.0 + plain.distance));
        }
        // A curved side: convergence is linear, a few runs hit the cap; answers agree to
        // the cap's accuracy.
        let plain = gjk_distance(
            &a,
            &cyl,
            &pose,
            &GjkParams::default(),
            &mut GjkCache::default(),
        );
        let acc = gjk_distance(&a, &cyl, &pose, &fast, &mut GjkCache::default());
        let w = gjk_distance(&a, &cyl, &pose, &GjkParams::default(), &mut warm_cyl);
        for other in [acc, w] {
            stalled += usize::from(other.outcome == GjkOutcome::DidNotConverge);
            assert_eq!(
                plain.distance > 0.0,
                other.distance > 0.0,
                "{plain:?} {other:?}"
            );
            assert!((plain.distance - other.distance).abs() <= 1e-7 * (1.0 + plain.distance));
        }
    }
    assert!(stalled < 40, "{stalled} runs hit the iteration cap");
}

#[test]
fn sphere_centres_on_a_box_face_edge_or_corner_give_the_radius_as_depth() {
    let cube = Cuboid::new(DVec3::new(1.0, 0.5, 0.25));
    let h = cube.half_extents;
    let mut r = rng(5);
    for i in 0..3000 {
        // A surface point: clamp a random point to the surface, on 1, 2 or 3 faces.
        let mut c = point_in_cube(&mut r, 1.0) * h;
        for k in 0..=(i % 3) {
            let axis = (i / 3 + k) % 3;
            c[axis] = h[axis].copysign(c[axis]);
        }
        // Every other case a hair off the surface (inside or out): GJK's "touching".
        let hair = if i % 2 == 0 {
            DVec3::ZERO
        } else {
            point_in_cube(&mut r, 1e-13)
        };
        let pose = Isometry::from_translation(c + hair);
        let radius = 0.1;
        let (d, out) = query(
            &Rounded::plain(&cube),
            &Rounded::sphere(&Sphere::new(radius)),
            &pose,
        );
        assert!((d.distance + radius).abs() < 1e-12, "{c}: {d:?} {out:?}");
        check_contract(&d, 1e-12);
        // The normal points out of the box at c (into the face's outer normal cone). A hair
        // off an edge or a corner, GJK's direction `−v/|v|` carries the rounding of a
        // 1e-13-long `v`: about 1e-16 / |v| radians.
        let outside = ((c + hair).abs() - h).max(DVec3::ZERO).length();
        let slack = if outside > 0.0 {
            (1e-15 / outside).clamp(1e-9, 1.0)
        } else {
            1e-9
        };
        // Moving the sphere by the depth along the normal leaves it touching, not inside.
        let moved = c + hair + d.normal * radius;
        let gap = (moved.abs() - h).max(DVec3::ZERO).length();
        assert!(
            (gap - radius).abs() < radius * slack * slack + 1e-12,
            "{c}: {d:?} {out:?}"
        );
        for k in 0..3 {
            if (c[k].abs() - h[k]).abs() > 0.0 {
                assert!(d.normal[k].abs() < slack, "{c}: {d:?} {out:?}");
            } else {
                assert!(d.normal[k] * c[k] >= -slack, "{c}: {d:?} {out:?}");
            }
        }
    }
}

#[test]
fn capsules_with_crossing_cores_penetrate_by_both_radii_across_both_axes() {
    let mut r = rng(6);
    for _ in 0..2000 {
        let (a, b) = (Capsule::new(0.6, 0.2), Capsule::new(0.9, 0.1));
        // B's core crosses A's core at a random point of both.
        let q = crate::test_support::rotation(&mut r);
        let on_a = DVec3::new(0.0, 0.0, 0.5 * point_in_cube(&mut r, 1.0).z);
        let along_b = 0.8 * point_in_cube(&mut r, 1.0).z;
        let t = on_a - q * DVec3::new(0.0, 0.0, along_b);
        let pose = Pose::new(t, q).to_isometry();
        let (sa, sb) = (capsule_core(&a), capsule_core(&b));
        let (d, out) = query(
            &Rounded::new(&sa, a.radius),
            &Rounded::new(&sb, b.radius),
            &pose,
        );
        assert!(
            (d.distance + a.radius + b.radius).abs() < 1e-9,
            "{d:?} {out:?}"
        );
        check_contract(&d, 1e-9);
        let axis = DVec3::Z.cross(q * DVec3::Z);
        if axis.length() > 1e-3 {
            assert!(
                d.normal.cross(axis.normalize()).length() < 1e-6,
                "{d:?} {out:?}"
            );
        }
    }
}

#[test]
fn an_iteration_cap_of_one_is_reported_with_a_real_upper_bound() {
    let a = Cuboid::new(DVec3::new(1.0, 0.5, 0.25));
    let b = crate::geometry::Cylinder::new(0.5, 0.3);
    let pose = Pose::new(DVec3::new(2.0, 1.5, 0.7), DQuat::from_rotation_y(0.7)).to_isometry();
    let capped = GjkParams {
        max_iterations: 1,
        ..GjkParams::default()
    };
    let g = gjk_distance(&a, &b, &pose, &capped, &mut GjkCache::default());
    let full = gjk_distance(
        &a,
        &b,
        &pose,
        &GjkParams::default(),
        &mut GjkCache::default(),
    );
    assert_eq!(g.outcome, GjkOutcome::DidNotConverge);
    assert_eq!(full.outcome, GjkOutcome::Separated);
    assert!(g.distance.is_finite() && g.distance >= full.distance);
    assert!(((g.point_a - g.point_b).length() - g.distance).abs() < 1e-12);
}

/// The largest support-plane gap `plane(n)` over unit directions `n` near `start`, by a
/// pattern search on the sphere (eight directions, turned by the golden angle each step
/// so that no ridge of a box's gap stops it; steps from 1e-4 down to 1e-15 rad): a lower
/// bound of the distance, equal to it at the optimum (the gap is concave in `n` there).
fn best_plane(plane: &impl Fn(DVec3) -> f64, start: DVec3) -> f64 {
    let (mut n, mut best) = (start, plane(start));
    let (mut step, mut turn) = (1e-4, 0.0_f64);
    while step > 1e-15 {
        let t1 = n.any_orthonormal_vector();
        let t2 = n.cross(t1);
        turn += 2.399_963;
        let improved = (0..8)
            .map(|k| turn + f64::from(k) * std::f64::consts::FRAC_PI_4)
            .map(|angle| (n + (t1 * angle.cos() + t2 * angle.sin()) * step).normalize())
            .map(|m| (m, plane(m)))
            .find(|&(_, value)| value > best);
        match improved {
            Some((m, value)) => (n, best) = (m, value),
            None => step *= 0.5,
        }
    }
    best
}

/// GJK's distance agrees with its own witnesses and is bracketed by the support planes,
/// to the stated tolerance, whenever it reports [`GjkOutcome::Separated`]; and when
/// rounding stops it short, it says so, with bounds that hold. Pairs near a cylinder's
/// rim: there the last simplex holds nearly equal points, where |v| once fell 1e-8
/// (relative) short of its witnesses and 3 % of the searches stopped short.
#[test]
fn separated_answers_meet_the_tolerance_and_stalled_ones_say_so() {
    use crate::test_support::{around_the_rim, random_cylinder, support_gap};
    use rand::Rng;
    let params = GjkParams::default();
    let mut r = rng(0x6a_6b);
    let (mut separated, mut stalled, mut other, mut tight) = (0, 0, 0, 0);
    for case in 0..20_000 {
        let a = random_cylinder(&mut r);
        let b: Box<dyn SupportMap> = if r.random_bool(0.5) {
            Box::new(random_cylinder(&mut r))
        } else {
            Box::new(Cuboid::new(DVec3::new(
                r.random_range(0.002..0.03),
                r.random_range(0.002..0.03),
                r.random_range(0.002..0.03),
            )))
        };
        let pose = around_the_rim(&mut r, &a, 0.03);
        let g = gjk_distance(&a, b.as_ref(), &pose, &params, &mut GjkCache::default());
        let witnessed = (g.point_b - g.point_a).length();
        let plane = |n: DVec3| support_gap(&a, b.as_ref(), &pose, n);
        let scale = 0.1 + pose.translation.length();
        let tol = params.rel_tol * g.distance + ROUNDING_ULPS * f64::EPSILON * scale;
        let ctx = format!("case {case}: {a:?}, pose {pose:?}: {g:?}, witnesses {witnessed:e}");
        match g.outcome {
            GjkOutcome::Separated => {
                separated += 1;
                // Its own claim: the witnesses that far apart, a support plane that close.
                assert!((g.distance - witnessed).abs() <= tol, "{ctx}: witnesses");
                assert!(
                    g.distance - g.lower_bound <= tol,
                    "{ctx}: no plane that close"
                );
                // The oracle's bracket: the best plane it finds by itself, the witnesses.
                let lower = [
                    g.normal(),
                    -g.v.normalize(),
                    (g.point_b - g.point_a) / witnessed,
                ]
                .map(|n| best_plane(&plane, n))
                .into_iter()
                .fold(f64::NEG_INFINITY, f64::max);
                assert!(
                    g.distance >= lower - tol && g.lower_bound <= witnessed + tol,
                    "{ctx}: outside the oracle's bracket from {lower:e}"
                );
                tight += usize::from(witnessed - lower <= 10.0 * tol);
            }
            GjkOutcome::DidNotConverge => {
                stalled += 1;
                assert_eq!(g.distance, witnessed, "{ctx}");
                assert!(
                    g.lower_bound > 0.0 && g.lower_bound <= g.distance,
                    "{ctx}: bounds"
                );
                // Short of the tolerance, yet the bounds are close: rounding, not a bug.
                assert!(
                    g.distance - g.lower_bound <= 1e-6 * g.distance,
                    "{ctx}: wide"
                );
            }
            _ => other += 1,
        }
    }
    eprintln!(
        "{separated} separated ({tight} in a tight oracle bracket), {stalled} stopped short, \
         {other} touching or overlapping"
    );
    assert!(
        tight * 10 >= separated * 9,
        "{tight} of {separated} in a tight bracket"
    );
    assert!(
        separated > 2_000 && other > 2_000,
        "{separated} separated, {other} other"
    );
    assert!(stalled * 10 < separated, "{stalled} stopped short");
}
