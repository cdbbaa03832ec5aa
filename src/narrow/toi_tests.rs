use super::*;
use crate::test_support::{point_in_cube, rng, rotation};
use rand::Rng;

/// Two spheres, world frame: the closed form the tests check the driver against.
fn spheres(ra: f64, rb: f64) -> impl FnMut(&Pose, &Pose) -> ShapeDistance {
    move |a: &Pose, b: &Pose| {
        let normal = (b.position - a.position)
            .try_normalize()
            .unwrap_or(DVec3::X);
        ShapeDistance {
            distance: a.position.distance(b.position) - ra - rb,
            point_a: a.position + normal * ra,
            point_b: b.position - normal * rb,
            normal,
        }
    }
}

/// Linear motion of two spheres: the first time `|c_b(t) − c_a(t)| = r_a + r_b` solves
/// a quadratic; the driver's `t` must be within the tolerance's time equivalent before it,
/// and never after.
#[test]
fn moving_spheres_hit_at_the_root_of_the_quadratic_and_never_later() {
    let mut rng = rng(101);
    let params = ToiParams {
        convex: true,
        ..ToiParams::default()
    };
    let (mut hits, mut misses, mut initial) = (0, 0, 0);
    for case in 0..5_000 {
        let (ra, rb) = (rng.random_range(0.05..1.0), rng.random_range(0.05..1.0));
        let motion = |rng: &mut crate::test_support::TestRng| FrameMotion {
            start: Pose::new(point_in_cube(rng, 2.5), rotation(rng)),
            end: Pose::new(point_in_cube(rng, 2.5), rotation(rng)),
        };
        let (ma, mb) = (motion(&mut rng), motion(&mut rng));
        // Spheres rotate about their centres: reach 0 (rotation cannot bring them closer).
        let outcome = time_of_impact(&ma, 0.0, &mb, 0.0, &params, spheres(ra, rb));
        // Closed form: |d0 + t·dv| = R.
        let (d0, dv) = (
            mb.start.position - ma.start.position,
            mb.displacement() - ma.displacement(),
        );
        let r = ra + rb;
        let (qa, qb, qc) = (dv.dot(dv), 2.0 * d0.dot(dv), d0.dot(d0) - r * r);
        let disc = qb * qb - 4.0 * qa * qc;
        let root = (qa > 0.0 && disc >= 0.0).then(|| (-qb - disc.sqrt()) / (2.0 * qa));
        match outcome {
            ToiOutcome::Initially { contact } => {
                assert!(
                    qc <= 1e-9 || contact.distance <= params.tolerance,
                    "case {case}"
                );
                initial += 1;
            }
            ToiOutcome::Impact { t, contact } => {
                let root = root.unwrap_or_else(|| panic!("case {case}: impact without a root"));
                assert!(t <= root + 1e-12, "case {case}: {t} after the root {root}");
                // Within the tolerance in distance, and not yet touching.
                assert!(
                    contact.distance <= params.tolerance && contact.distance >= 0.0,
                    "case {case}: gap {}",
                    contact.distance
                );
                hits += 1;
            }
            ToiOutcome::Miss => {
                assert!(
                    root.is_none_or(|t| !(0.0..=1.0).contains(&t)),
                    "case {case}: missed the impact at {root:?}"
                );
                misses += 1;
            }
            ToiOutcome::DidNotConverge { t, .. } => {
                panic!("case {case}: no convergence at {t}")
            }
        }
    }
    assert!(
        hits > 500 && misses > 500 && initial > 50,
        "hits {hits}, misses {misses}, initially touching {initial}"
    );
}

/// A search stopped by its caller after `k` queries reports how far it safely got,
/// with the distance query there: still apart, never past the first contact, and the
/// same time a search allowed `k` iterations reaches.
#[test]
fn a_stopped_search_reports_the_time_it_safely_reached_and_the_query_there() {
    let mut rng = rng(107);
    let params = ToiParams::default();
    let (mut stopped, mut finished) = (0, 0);
    for case in 0..2_000 {
        let (ra, rb) = (rng.random_range(0.05..1.0), rng.random_range(0.05..1.0));
        let (ma, mb) = (
            FrameMotion {
                start: Pose::from_translation(point_in_cube(&mut rng, 3.0)),
                end: Pose::from_translation(point_in_cube(&mut rng, 3.0)),
            },
            FrameMotion::at_rest(Pose::from_translation(point_in_cube(&mut rng, 3.0))),
        );
        let k = rng.random_range(0..6);
        let mut asked = 0;
        let outcome = time_of_impact_until(&ma, 0.0, &mb, 0.0, &params, spheres(ra, rb), || {
            asked += 1;
            asked <= k
        });
        let limited = ToiParams {
            max_iterations: k,
            ..params
        };
        let unstopped = time_of_impact(&ma, 0.0, &mb, 0.0, &params, spheres(ra, rb));
        let first_contact = match unstopped {
            ToiOutcome::Impact { t, .. } => t,
            ToiOutcome::Initially { .. } => 0.0,
            _ => 1.0,
        };
        match outcome {
            ToiOutcome::DidNotConverge { t, contact } => {
                let at_t = spheres(ra, rb)(&ma.pose_at(t), &mb.pose_at(t));
                assert_eq!(contact, at_t, "case {case}");
                assert!(contact.distance > params.tolerance, "case {case}");
                assert!(t <= first_contact, "case {case}: {t} after {first_contact}");
                assert_eq!(
                    time_of_impact(&ma, 0.0, &mb, 0.0, &limited, spheres(ra, rb)),
                    outcome,
                    "case {case}"
                );
                stopped += 1;
            }
            other => {
                assert_eq!(other, unstopped, "case {case}");
                finished += 1;
            }
        }
    }
    assert!(
        stopped > 300 && finished > 300,
        "stopped {stopped}, finished {finished}"
    );
}

/// A rotating long body (a point at `reach` on a rotating arm, as a tiny sphere) against
/// a resting sphere: conservative advancement must stop before the arm's tip enters it.
#[test]
fn a_rotating_arm_stops_before_its_tip_touches() {
    let mut rng = rng(103);
    let params = ToiParams {
        convex: true,
        ..ToiParams::default()
    };
    let (mut hits, mut misses) = (0, 0);
    for case in 0..2_000 {
        let reach = rng.random_range(0.5..3.0);
        let angle = rng.random_range(0.1..3.0);
        let axis = DVec3::Z;
        let arm = FrameMotion {
            start: Pose::IDENTITY,
            end: Pose::from_rotation(DQuat::from_axis_angle(axis, angle)),
        };
        // Near the tip's arc, before, on or beyond its end.
        let (at_angle, at_radius) = (
            rng.random_range(-0.3..angle + 0.6),
            reach + rng.random_range(-0.4..0.4),
        );
        let ball_at = DVec3::new(
            at_radius * at_angle.cos(),
            at_radius * at_angle.sin(),
            rng.random_range(-0.3..0.3),
        );
        let ball = FrameMotion::at_rest(Pose::from_translation(ball_at));
        let radius = 0.2;
        // The arm's tip: a point at (reach, 0, 0) in the arm's frame.
        let tip_distance = |a: &Pose, b: &Pose| {
            let tip = a.transform_point(DVec3::X * reach);
            let normal = (b.position - tip).try_normalize().unwrap_or(DVec3::X);
            ShapeDistance {
                distance: tip.distance(b.position) - radius,
                point_a: tip,
                point_b: b.position - normal * radius,
                normal,
            }
        };
        // Dense sampling of the true first contact time.
        let truth = (0..=20_000)
            .map(|i| f64::from(i) / 20_000.0)
            .find(|&t| tip_distance(&arm.pose_at(t), &ball.start).distance <= 0.0);
        match time_of_impact(&arm, reach, &ball, 0.0, &params, tip_distance) {
            ToiOutcome::Impact { t, .. } => {
                if let Some(truth) = truth {
                    assert!(t <= truth + 1e-4, "case {case}: {t} after {truth}");
                }
                hits += 1;
            }
            ToiOutcome::Miss => {
                assert!(truth.is_none(), "case {case}: missed contact at {truth:?}");
                misses += 1;
            }
            ToiOutcome::Initially { .. } => {}
            ToiOutcome::DidNotConverge { t, .. } => {
                // Allowed (grazing contact), but must still be conservative.
                if let Some(truth) = truth {
                    assert!(t <= truth + 1e-4, "case {case}");
                }
            }
        }
    }
    assert!(hits > 100 && misses > 100, "hits {hits}, misses {misses}");
}

/// A non-convex A (two balls, a dumbbell) and a small ball sliding past: the normal at
/// the nearer ball says little about the other, so only the full-speed bound is safe.
/// With it the reported time is never after the densely sampled first contact; the
/// convex bound overshoots on some of these cases (why `convex` is opt-in).
#[test]
fn a_non_convex_pair_is_never_passed_with_the_default_bound() {
    let mut rng = rng(113);
    let (mut hits, mut misses, mut convex_overshoots) = (0, 0, 0);
    for case in 0..1_000 {
        let lobes = [
            (point_in_cube(&mut rng, 2.0), rng.random_range(0.3..1.0)),
            (point_in_cube(&mut rng, 2.0), rng.random_range(0.3..1.0)),
        ];
        let rb = rng.random_range(0.05..0.3);
        let dumbbell = |a: &Pose, b: &Pose| {
            lobes
                .iter()
                .map(|&(centre, r)| {
                    let c = a.transform_point(centre);
                    let normal = (b.position - c).try_normalize().unwrap_or(DVec3::X);
                    ShapeDistance {
                        distance: c.distance(b.position) - r - rb,
                        point_a: c + normal * r,
                        point_b: b.position - normal * rb,
                        normal,
                    }
                })
                .min_by(|x, y| x.distance.total_cmp(&y.distance))
                .expect("two lobes")
        };
        let ma = FrameMotion::at_rest(Pose::IDENTITY);
        // Across the dumbbell's region, to hit or pass close by.
        let from = point_in_cube(&mut rng, 5.0);
        let mb = FrameMotion {
            start: Pose::from_translation(from),
            end: Pose::from_translation(-from + point_in_cube(&mut rng, 2.0)),
        };
        let truth = (0..=4_000)
            .map(|i| f64::from(i) / 4_000.0)
            .find(|&t| dumbbell(&ma.start, &mb.pose_at(t)).distance <= 0.0);
        if truth == Some(0.0) {
            continue;
        }
        let reach = 0.0;
        match time_of_impact(&ma, reach, &mb, 0.0, &ToiParams::default(), dumbbell) {
            ToiOutcome::Impact { t, .. } => {
                let truth = truth.unwrap_or(1.0);
                assert!(t <= truth + 1e-12, "case {case}: {t} after {truth}");
                hits += 1;
            }
            ToiOutcome::Miss => {
                assert!(truth.is_none(), "case {case}: missed contact at {truth:?}");
                misses += 1;
            }
            ToiOutcome::Initially { .. } => panic!("case {case}: apart at t = 0"),
            ToiOutcome::DidNotConverge { t, .. } => {
                assert!(t <= truth.unwrap_or(1.0), "case {case}");
            }
        }
        let convex = ToiParams {
            convex: true,
            ..ToiParams::default()
        };
        if let (ToiOutcome::Impact { t, .. }, Some(truth)) = (
            time_of_impact(&ma, reach, &mb, 0.0, &convex, dumbbell),
            truth,
        ) && t > truth + 1e-3
        {
            convex_overshoots += 1;
        }
    }
    assert!(
        hits > 100 && misses > 100 && convex_overshoots > 0,
        "hits {hits}, misses {misses}, convex bound overshoots {convex_overshoots}"
    );
}

/// Every point of a box moving by a random motion stays in its swept box at every
/// sampled time.
#[test]
fn swept_bounds_contain_the_shape_at_every_time_of_the_motion() {
    let mut rng = rng(107);
    for case in 0..500 {
        let half = DVec3::new(
            rng.random_range(0.01..2.0),
            rng.random_range(0.01..2.0),
            rng.random_range(0.01..2.0),
        );
        let local = Aabb::new(-half, half);
        let motion = FrameMotion {
            start: Pose::new(point_in_cube(&mut rng, 5.0), rotation(&mut rng)),
            end: Pose::new(point_in_cube(&mut rng, 5.0), rotation(&mut rng)),
        };
        let swept = swept_bounds(&local, half.length(), &motion);
        for i in 0..=64 {
            let pose = motion.pose_at(f64::from(i) / 64.0);
            for corner in 0..8 {
                let c = DVec3::new(
                    if corner & 1 == 0 { -half.x } else { half.x },
                    if corner & 2 == 0 { -half.y } else { half.y },
                    if corner & 4 == 0 { -half.z } else { half.z },
                );
                let p = pose.transform_point(c);
                assert!(
                    swept.grown(1e-9).contains_point(p),
                    "case {case}: corner {corner} at t {i}/64"
                );
            }
        }
    }
    // A pure translation sweeps exactly the two end boxes' hull.
    let local = Aabb::new(-DVec3::ONE, DVec3::ONE);
    let slide = FrameMotion {
        start: Pose::IDENTITY,
        end: Pose::from_translation(DVec3::X * 5.0),
    };
    let swept = swept_bounds(&local, 3f64.sqrt(), &slide);
    assert!((swept.max.x - 6.0).abs() < 1e-9 && (swept.min.x + 1.0).abs() < 1e-9);
}

#[test]
fn q_and_minus_q_give_the_same_motion() {
    let mut rng = rng(109);
    for _ in 0..200 {
        let (q0, q1) = (rotation(&mut rng), rotation(&mut rng));
        let a = FrameMotion {
            start: Pose::from_rotation(q0),
            end: Pose::from_rotation(q1),
        };
        let b = FrameMotion {
            start: Pose::from_rotation(q0),
            end: Pose::from_rotation(-q1),
        };
        assert!((a.angle() - b.angle()).abs() < 1e-12);
        for i in 0..=8 {
            let t = f64::from(i) / 8.0;
            let (pa, pb) = (a.pose_at(t), b.pose_at(t));
            let v = DVec3::new(0.3, -1.2, 2.0);
            assert!(pa.transform_point(v).distance(pb.transform_point(v)) < 1e-12);
        }
    }
}
