//! Time of impact through the in-process pipeline (`Query::TOI`), against oracles that
//! share no code with the search:
//!
//! - two spheres that pass through each other between two frames: `CLOSE` misses them at
//!   both poses, `TOI` reports them at the analytic root of `|d₀ + t·Δv| = R` (never
//!   later, within the tolerance's time equivalent);
//! - seeded random motions of every pair of sphere, capsule, box, convex hull and mesh,
//!   against dense sampling of the motion (2,000 steps) with a brute-force distance: each
//!   shape as its core (a point, a segment, the boundary triangles) swept by a radius, the
//!   distance the smallest over every triangle pair (`distance_triangle_triangle`) minus
//!   the radii. Starts are separated, so the first contact is a contact of the boundaries,
//!   which is what the oracle measures. A reported `t` is never after the first sampled
//!   contact, and the oracle finds the pair within its margins plus the tolerance there;
//!   a pair with a sampled contact is always reported, and both outcomes occur;
//! - pairs already overlapping at the start report `t = 0`; a body that did not move
//!   (static or just not posed this frame) against one that did;
//! - a frame whose deadline has passed reports every candidate unsearched and
//!   conservatively (box distances against the brute-force distance at the start).

#[path = "support/mod.rs"]
mod support;

use proxima::geometry::{Capsule, ConvexPolyhedron, Cuboid, Sphere, Triangle};
use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::distance_triangle_triangle;
use proxima::narrow::toi::FrameMotion;
use proxima::narrow::{MeshShape, Shape};
use proxima::pipeline::{
    Completeness, Deadline, FrameResults, PipelineWorkspace, Query, TOI_TOLERANCE, step,
    step_within,
};
use proxima::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits};
use rand::Rng;
use std::sync::Arc;
use std::time::Instant;
use support::{TestRng, meshes, point_in_cube, rng, rotation};

/// Oracle steps over the motion.
const SAMPLES: u32 = 2_000;

/// A shape as the oracle sees it: boundary (core) triangles in the local frame, and the
/// radius that sweeps them.
struct Cored {
    triangles: Vec<Triangle>,
    radius: f64,
    /// Largest distance of a shape point from the origin (cores plus radius).
    reach: f64,
}

impl Cored {
    fn of(shape: &Shape) -> Self {
        let point = |p: DVec3| Triangle::new(p, p, p);
        let (triangles, radius) = match shape {
            Shape::Sphere(s) => (vec![point(DVec3::ZERO)], s.radius),
            Shape::Capsule(c) => {
                let (top, bottom) = (DVec3::Z * c.half_height, -DVec3::Z * c.half_height);
                (vec![Triangle::new(bottom, top, top)], c.radius)
            }
            Shape::Cuboid(c) => (meshes::triangles(&meshes::cuboid(c.half_extents)), 0.0),
            Shape::Convex(hull) => {
                let v = hull.vertices();
                let triangles = hull
                    .triangles()
                    .iter()
                    .map(|t| Triangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
                    .collect();
                (triangles, 0.0)
            }
            Shape::Mesh(m) => (meshes::triangles(&m.mesh), 0.0),
            _ => unreachable!("the oracle covers spheres, capsules, boxes, hulls and meshes"),
        };
        let reach = triangles
            .iter()
            .flat_map(|t| [t.a, t.b, t.c])
            .map(DVec3::length)
            .fold(0.0, f64::max)
            + radius;
        Self {
            triangles,
            radius,
            reach,
        }
    }
}

/// The brute-force distance of two cored shapes at world poses (exact while they are
/// apart; a lower bound of 0 once the cores' boundaries cross).
fn oracle_distance(a: &Cored, pa: &Pose, b: &Cored, pb: &Pose) -> f64 {
    let moved = |c: &Cored, p: &Pose| -> Vec<(Triangle, DVec3, f64)> {
        c.triangles
            .iter()
            .map(|t| {
                let t = Triangle::new(
                    p.transform_point(t.a),
                    p.transform_point(t.b),
                    p.transform_point(t.c),
                );
                let centre = (t.a + t.b + t.c) / 3.0;
                let r = [t.a, t.b, t.c]
                    .iter()
                    .map(|v| v.distance(centre))
                    .fold(0.0, f64::max);
                (t, centre, r)
            })
            .collect()
    };
    let (ta, tb) = (moved(a, pa), moved(b, pb));
    let mut best = f64::INFINITY;
    for (x, cx, rx) in &ta {
        for (y, cy, ry) in &tb {
            // Bounding spheres of the two triangles: skip pairs that cannot be nearer.
            if cx.distance(*cy) - rx - ry >= best {
                continue;
            }
            best = best.min(distance_triangle_triangle(x, y).distance);
        }
    }
    best - a.radius - b.radius
}

/// The oracle's sampled motion: the first sample at which the pair is within `margins`,
/// found by stepping through all `SAMPLES` steps (steps the pair provably cannot be within
/// its margins at, by the speed bound of its points, are not evaluated).
fn first_sampled_contact(
    (a, ma): (&Cored, &FrameMotion),
    (b, mb): (&Cored, &FrameMotion),
    margins: f64,
) -> Option<f64> {
    // Fastest relative speed of any two points, per unit time.
    let speed = (mb.displacement() - ma.displacement()).length()
        + ma.angle() * a.reach
        + mb.angle() * b.reach;
    let mut i = 0;
    while i <= SAMPLES {
        let t = f64::from(i) / f64::from(SAMPLES);
        let (pa, pb) = (ma.pose_at(t), mb.pose_at(t));
        // Cheap bound first: the bounding balls about the origins.
        let lower = pa.position.distance(pb.position) - a.reach - b.reach;
        let gap = if lower > margins {
            lower
        } else {
            oracle_distance(a, &pa, b, &pb)
        } - margins;
        if gap <= 0.0 {
            return Some(t);
        }
        // No sample before `t + gap / speed` can be within the margins.
        let skip = if speed > 0.0 {
            (gap / speed * f64::from(SAMPLES)).floor()
        } else {
            f64::INFINITY
        };
        i += 1 + skip.min(f64::from(SAMPLES)) as u32;
    }
    None
}

fn body(scene: &mut Scene, shape: Shape, pose: Pose, motion: Motion, margin: f64) -> BodyId {
    let shape = scene.register_shape(shape).unwrap();
    scene
        .add_body(&BodyDesc {
            shape,
            pose,
            motion,
            filter: CollisionFilter::ALL,
            margin: Some(margin),
        })
        .unwrap()
}

/// A scene of two bodies moved over one frame by `ma` and `mb` (added at the starts, one
/// frame answered, then moved to the ends), answered with `query`.
fn two_bodies(
    (sa, ma, static_a): (&Shape, &FrameMotion, bool),
    (sb, mb): (&Shape, &FrameMotion),
    margins: (f64, f64),
    query: Query,
) -> (FrameResults, proxima::pipeline::StepReport) {
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let kind = if static_a {
        Motion::Static
    } else {
        Motion::Dynamic
    };
    let a = body(&mut scene, sa.clone(), ma.start, kind, margins.0);
    let b = body(&mut scene, sb.clone(), mb.start, Motion::Dynamic, margins.1);
    scene.end_frame();
    scene.set_pose(a, ma.end).unwrap();
    scene.set_pose(b, mb.end).unwrap();
    assert_eq!(scene.validate(), Ok(()));
    assert_eq!(scene.frame_motion(scene.body(a).unwrap()), *ma);
    assert_eq!(scene.frame_motion(scene.body(b).unwrap()), *mb);
    let mut results = FrameResults::default();
    let report = step(
        &scene,
        query,
        &mut PipelineWorkspace::default(),
        &mut results,
    );
    (results, report)
}

/// Two balls swapping places along a line (with a random sideways offset) pass through
/// each other between the frames: `CLOSE` finds nothing at either pose, `TOI` reports the
/// pair at the first root of `|d₀ + t·Δv| = r_a + r_b + margins`, never later, and no
/// earlier than the tolerance allows.
#[test]
fn tunnelling_spheres_are_caught_at_the_root_of_the_quadratic() {
    let mut rng = rng(301);
    let mut caught = 0;
    for case in 0..500 {
        let (ra, rb) = (rng.random_range(0.05..0.5), rng.random_range(0.05..0.5));
        let margins = (rng.random_range(0.0..0.02), rng.random_range(0.0..0.02));
        let reach = ra + rb + margins.0 + margins.1;
        let dir = rotation(&mut rng) * DVec3::X;
        let offset = point_in_cube(&mut rng, reach)
            .reject_from(dir)
            .clamp_length_max(0.9 * reach);
        let half = reach + rng.random_range(0.1..3.0);
        let centre = point_in_cube(&mut rng, 10.0);
        let ma = FrameMotion {
            start: Pose::new(centre - dir * half, rotation(&mut rng)),
            end: Pose::new(centre + dir * half, rotation(&mut rng)),
        };
        let mb = FrameMotion {
            start: Pose::new(centre + dir * half + offset, rotation(&mut rng)),
            end: Pose::new(centre - dir * half + offset, rotation(&mut rng)),
        };
        let (sa, sb) = (
            Shape::Sphere(Sphere::new(ra)),
            Shape::Sphere(Sphere::new(rb)),
        );
        // CLOSE at the start poses and at the end poses: too far apart both times.
        for poses in [FrameMotion::at_rest(ma.start), FrameMotion::at_rest(ma.end)] {
            let other = if poses.start == ma.start {
                mb.start
            } else {
                mb.end
            };
            let (close, _) = two_bodies(
                (&sa, &poses, false),
                (&sb, &FrameMotion::at_rest(other)),
                margins,
                Query::CLOSE,
            );
            assert!(close.pairs.is_empty(), "case {case}: CLOSE sees the pair");
        }
        let (results, report) = two_bodies(
            (&sa, &ma, false),
            (&sb, &mb),
            margins,
            Query::CLOSE.union(Query::TOI),
        );
        assert!(results.pairs.is_empty() && report.candidates == 0);
        assert_eq!(report.toi_candidates, 1, "case {case}");
        let [toi] = results.tois.as_slice() else {
            panic!("case {case}: {} TOI records", results.tois.len())
        };
        // |d0 + t dv|² = R²: the smaller root.
        let (d0, dv) = (
            mb.start.position - ma.start.position,
            mb.displacement() - ma.displacement(),
        );
        let (qa, qb, qc) = (dv.dot(dv), 2.0 * d0.dot(dv), d0.dot(d0) - reach * reach);
        let root = (-qb - (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
        assert!(
            toi.time <= root + 1e-12,
            "case {case}: {} after {root}",
            toi.time
        );
        // The distance closes at |dv·n| ≥ the speed along the normal at the root.
        let normal = (d0 + dv * root).normalize();
        let closing = -dv.dot(normal);
        assert!(closing > 0.0);
        assert!(
            root - toi.time <= (TOI_TOLERANCE + 1e-9) / closing,
            "case {case}: {} too early for {root}",
            toi.time
        );
        assert!(toi.reached && (toi.a, toi.b) == (0, 1));
        // The record is the pair at time t: within the margins plus the tolerance.
        let gap = toi.distance - margins.0 - margins.1;
        assert!(
            (-1e-9..=TOI_TOLERANCE + 1e-9).contains(&gap),
            "case {case}: {gap}"
        );
        let (pa, pb) = (ma.pose_at(toi.time), mb.pose_at(toi.time));
        let n = (pb.position - pa.position).normalize();
        assert!((toi.normal - n).length() < 1e-9, "case {case}");
        assert!(
            toi.point_a.distance(pa.position + n * ra) < 1e-9,
            "case {case}"
        );
        assert!(
            toi.point_b.distance(pb.position - n * rb) < 1e-9,
            "case {case}"
        );
        caught += 1;
    }
    assert_eq!(caught, 500);
}

/// The shapes of the random sweeps, with a name for messages.
fn kinds() -> Vec<(&'static str, Shape)> {
    let hull_points = meshes::uv_sphere(0.3, 8, 5).vertices().to_vec();
    vec![
        ("sphere", Shape::Sphere(Sphere::new(0.25))),
        ("capsule", Shape::Capsule(Capsule::new(0.3, 0.12))),
        (
            "box",
            Shape::Cuboid(Cuboid::new(DVec3::new(0.3, 0.15, 0.2))),
        ),
        (
            "convex",
            Shape::Convex(Arc::new(
                ConvexPolyhedron::try_from_points(&hull_points).unwrap(),
            )),
        ),
        (
            "mesh",
            Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.3, 0.1, 10, 5)))),
        ),
    ]
}

/// A random motion over a frame: from `start` by a step of up to `step` metres and a turn
/// of up to `turn` radians.
fn motion(rng: &mut TestRng, start: DVec3, end: DVec3, turn: f64) -> FrameMotion {
    let q = rotation(rng);
    let axis = rotation(rng) * DVec3::X;
    FrameMotion {
        start: Pose::new(start, q),
        end: Pose::new(
            end,
            (DQuat::from_axis_angle(axis, rng.random_range(0.0..turn)) * q).normalize(),
        ),
    }
}

/// Every pair of kinds, random separated starts, B sent toward where A ends up (hitting
/// or passing close by), both turning: the pipeline's TOI against the sampled oracle.
#[test]
fn random_sweeps_of_every_pair_of_kinds_agree_with_dense_sampling() {
    let kinds = kinds();
    let cored: Vec<Cored> = kinds.iter().map(|(_, s)| Cored::of(s)).collect();
    let mut rng = rng(307);
    let (mut hits, mut misses, mut grazing) = (0, 0, 0);
    let mut per_pair = vec![(0, 0); kinds.len() * kinds.len()];
    let started = std::time::Instant::now();
    for case in 0..3_000 {
        let (i, j) = (case % kinds.len(), (case / kinds.len()) % kinds.len());
        let (ca, cb) = (&cored[i], &cored[j]);
        let margins = if rng.random_bool(0.5) {
            (0.0, 0.0)
        } else {
            (rng.random_range(0.0..0.05), rng.random_range(0.0..0.05))
        };
        let apart = ca.reach + cb.reach + margins.0 + margins.1;
        let a_start = point_in_cube(&mut rng, 0.5);
        let a_end = a_start + point_in_cube(&mut rng, 0.4);
        let ma = motion(&mut rng, a_start, a_end, 1.5);
        let b_start =
            a_start + rotation(&mut rng) * DVec3::X * (apart + rng.random_range(0.01..1.0));
        let b_end = a_end + point_in_cube(&mut rng, 0.9 * apart);
        let mb = motion(&mut rng, b_start, b_end, 1.5);
        let (results, _) = two_bodies(
            (&kinds[i].1, &ma, false),
            (&kinds[j].1, &mb),
            margins,
            Query::TOI,
        );
        let within = margins.0 + margins.1;
        let first = first_sampled_contact((ca, &ma), (cb, &mb), within);
        let name = format!("case {case} ({} vs {})", kinds[i].0, kinds[j].0);
        match results.tois.as_slice() {
            [] => {
                assert!(first.is_none(), "{name}: missed the contact at {first:?}");
                misses += 1;
                per_pair[i * kinds.len() + j].1 += 1;
            }
            [toi] => {
                assert!((0.0..=1.0).contains(&toi.time), "{name}");
                if let Some(first) = first {
                    assert!(
                        toi.time <= first + 1e-9,
                        "{name}: {} after {first}",
                        toi.time
                    );
                }
                // The oracle at the reported time: within the margins plus the tolerance
                // (when the search reached contact), and the record's distance is its.
                let (pa, pb) = (ma.pose_at(toi.time), mb.pose_at(toi.time));
                let truth = oracle_distance(ca, &pa, cb, &pb);
                if toi.reached {
                    assert!(
                        truth - within <= TOI_TOLERANCE + 1e-9,
                        "{name}: oracle gap {} at t = {}",
                        truth - within,
                        toi.time
                    );
                } else {
                    grazing += 1;
                }
                assert!(
                    (toi.distance - truth).abs() <= 1e-7,
                    "{name}: distance {} vs oracle {truth}",
                    toi.distance
                );
                assert!((toi.normal.length() - 1.0).abs() < 1e-9, "{name}");
                assert!(toi.time > 0.0, "{name}: separated at the start");
                if first.is_none() {
                    // Within the tolerance between two samples: a graze.
                    grazing += 1;
                } else {
                    hits += 1;
                    per_pair[i * kinds.len() + j].0 += 1;
                }
            }
            more => panic!("{name}: {} records", more.len()),
        }
    }
    eprintln!(
        "{hits} hits, {misses} misses, {grazing} grazes in {:?}",
        started.elapsed()
    );
    assert!(
        hits > 800 && misses > 600 && grazing < 30,
        "hits {hits}, misses {misses}, grazes {grazing}"
    );
    assert!(
        per_pair.iter().all(|&(h, m)| h > 5 && m > 2),
        "hits and misses per pair of kinds: {per_pair:?}"
    );
}

/// Convex shapes placed at one point (both contain their origin, so they overlap) report
/// `t = 0` with a non-positive distance, whatever their motion after.
#[test]
fn pairs_overlapping_at_the_start_report_time_zero() {
    let kinds = kinds();
    let mut rng = rng(311);
    for case in 0..200 {
        let (i, j) = (case % 4, (case / 4) % 4);
        let at = point_in_cube(&mut rng, 2.0);
        let (a_end, b_start, b_end) = (
            at + point_in_cube(&mut rng, 1.0),
            at + point_in_cube(&mut rng, 0.02),
            point_in_cube(&mut rng, 3.0),
        );
        let ma = motion(&mut rng, at, a_end, 1.0);
        let mb = motion(&mut rng, b_start, b_end, 1.0);
        let (results, _) = two_bodies(
            (&kinds[i].1, &ma, false),
            (&kinds[j].1, &mb),
            (0.0, 0.0),
            Query::TOI,
        );
        let [toi] = results.tois.as_slice() else {
            panic!("case {case}: {} records", results.tois.len())
        };
        assert!(
            toi.time == 0.0 && toi.distance <= 0.0,
            "case {case}: {toi:?}"
        );
    }
}

/// A static body (and a dynamic one simply not posed this frame) at rest against a body
/// that moves through it, and against one that passes by: TOI finds the first and not the
/// second; two bodies at rest get `t = 0` only when already within their margins.
#[test]
fn a_body_at_rest_is_hit_by_a_moving_one() {
    let wall = Shape::Cuboid(Cuboid::new(DVec3::new(0.05, 1.0, 1.0)));
    let ball = Shape::Sphere(Sphere::new(0.1));
    for static_wall in [true, false] {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let kind = if static_wall {
            Motion::Static
        } else {
            Motion::Dynamic
        };
        let w = body(&mut scene, wall.clone(), Pose::IDENTITY, kind, 0.0);
        let through = body(
            &mut scene,
            ball.clone(),
            Pose::from_translation(DVec3::new(-2.5, 0.0, 0.0)),
            Motion::Dynamic,
            0.0,
        );
        let past = body(
            &mut scene,
            ball.clone(),
            Pose::from_translation(DVec3::new(-2.0, 1.5, 0.0)),
            Motion::Dynamic,
            0.0,
        );
        let resting = body(
            &mut scene,
            ball.clone(),
            Pose::from_translation(DVec3::new(0.0, 0.0, 3.0)),
            Motion::Dynamic,
            0.0,
        );
        // Added this frame: nobody moves yet, whatever the poses say.
        scene
            .set_pose(through, Pose::from_translation(DVec3::new(-2.0, 0.0, 0.0)))
            .unwrap();
        for id in [w, through, past, resting] {
            let b = scene.body(id).unwrap();
            assert_eq!(scene.frame_motion(b), FrameMotion::at_rest(b.pose));
        }
        scene.end_frame();
        scene
            .set_pose(through, Pose::from_translation(DVec3::new(2.0, 0.0, 0.0)))
            .unwrap();
        scene
            .set_pose(past, Pose::from_translation(DVec3::new(2.0, 1.5, 0.0)))
            .unwrap();
        let mut results = FrameResults::default();
        step(
            &scene,
            Query::TOI,
            &mut PipelineWorkspace::default(),
            &mut results,
        );
        // The ball's surface meets the wall's face x = −0.05 when its centre is at −0.15:
        // t = (2 − 0.15) / 4.
        let [toi] = results.tois.as_slice() else {
            panic!("{} records", results.tois.len())
        };
        assert_eq!((toi.a, toi.b), (w.0, through.0));
        let root = (2.0 - 0.15) / 4.0;
        assert!(toi.time <= root && root - toi.time <= 1e-6, "{}", toi.time);
        // From A (the wall) to B (the ball, on its −x side).
        assert!((toi.normal + DVec3::X).length() < 1e-9, "{:?}", toi.normal);
        // Next frame nobody moves: the ball now sits past the wall, apart: nothing.
        scene.end_frame();
        step(
            &scene,
            Query::TOI,
            &mut PipelineWorkspace::default(),
            &mut results,
        );
        assert!(results.tois.is_empty());
        // Resting on the wall (margins cover the gap): t = 0 without any motion.
        scene.end_frame();
        scene
            .update_body(resting, Motion::Dynamic, CollisionFilter::ALL, Some(0.2))
            .unwrap();
        scene
            .set_pose(resting, Pose::from_translation(DVec3::new(0.0, 0.0, 1.15)))
            .unwrap();
        scene.end_frame();
        step(
            &scene,
            Query::TOI,
            &mut PipelineWorkspace::default(),
            &mut results,
        );
        let [toi] = results.tois.as_slice() else {
            panic!("{} records", results.tois.len())
        };
        assert_eq!((toi.a, toi.b, toi.time), (w.0, resting.0, 0.0));
        assert!((toi.distance - 0.05).abs() < 1e-9);
    }
}

/// A frame whose deadline has already passed searches no time of impact: every swept
/// candidate is reported unsearched (`t = 0`, not reached, not exact) with the bodies'
/// start boxes for distance, so every pair the unlimited frame reports is there, never
/// later; each box distance is at most the brute-force distance at the start, and within
/// its error bound of it. A deadline an hour away gives the unlimited frame's records.
#[test]
fn a_passed_deadline_reports_every_toi_candidate_unsearched_and_conservative() {
    let kinds = kinds();
    let cored: Vec<Cored> = kinds.iter().map(|(_, s)| Cored::of(s)).collect();
    let mut rng = rng(317);
    let (mut hit_pairs, mut extra_pairs, mut checked_distances) = (0, 0, 0);
    for case in 0..40 {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let mut motions = Vec::new();
        for i in 0..8 {
            let kind = (case + i) % kinds.len();
            let start = point_in_cube(&mut rng, 1.5);
            let end = start + point_in_cube(&mut rng, 0.8);
            let m = motion(&mut rng, start, end, 1.0);
            let margin = rng.random_range(0.0..0.05);
            let id = body(
                &mut scene,
                kinds[kind].1.clone(),
                m.start,
                Motion::Dynamic,
                margin,
            );
            motions.push((id, kind, m));
        }
        scene.end_frame();
        for (id, _, m) in &motions {
            scene.set_pose(*id, m.end).unwrap();
        }
        let mut exact = FrameResults::default();
        step(
            &scene,
            Query::TOI,
            &mut PipelineWorkspace::default(),
            &mut exact,
        );
        let mut cut = FrameResults::default();
        let report = step_within(
            &scene,
            Query::TOI,
            &mut Deadline(Instant::now()),
            &mut PipelineWorkspace::default(),
            &mut cut,
        );
        assert_eq!(report.truncated_tois, report.toi_candidates, "case {case}");
        assert_eq!(report.completeness, Completeness::Truncated { level: 0 });
        for want in &exact.tois {
            let got = cut
                .tois
                .iter()
                .find(|t| (t.a, t.b) == (want.a, want.b))
                .unwrap_or_else(|| panic!("case {case}: pair {}–{} left out", want.a, want.b));
            assert!(got.time <= want.time);
        }
        for got in &cut.tois {
            assert!(
                !got.exact && !got.reached && got.time == 0.0,
                "case {case}: {got:?}"
            );
            let hit = exact.tois.iter().any(|t| (t.a, t.b) == (got.a, got.b));
            hit_pairs += usize::from(hit);
            extra_pairs += usize::from(!hit);
            let start = |id: u32| {
                let (_, kind, m) = motions.iter().find(|(b, _, _)| b.0 == id).unwrap();
                (&cored[*kind], m.start)
            };
            let ((ca, pa), (cb, pb)) = (start(got.a), start(got.b));
            let truth = oracle_distance(ca, &pa, cb, &pb);
            // The oracle is exact while the shapes are apart (a lower bound of 0 once the
            // cores cross, where only `distance ≤ 0` can be checked).
            if truth > 0.0 {
                assert!(
                    got.distance <= truth + 1e-9,
                    "case {case}: {got:?} above {truth}"
                );
                assert!(
                    truth <= got.distance + got.error_bound,
                    "case {case}: {got:?}"
                );
                checked_distances += 1;
            } else {
                assert!(
                    got.distance <= 1e-9,
                    "case {case}: {got:?} for crossing cores"
                );
            }
        }
        let later = Instant::now() + std::time::Duration::from_secs(3600);
        let mut unhurried = FrameResults::default();
        let report = step_within(
            &scene,
            Query::TOI,
            &mut Deadline(later),
            &mut PipelineWorkspace::default(),
            &mut unhurried,
        );
        assert_eq!(report.truncated_tois, 0);
        assert_eq!(unhurried.tois, exact.tois, "case {case}");
    }
    assert!(
        hit_pairs > 20 && extra_pairs > 20 && checked_distances > 50,
        "hits {hit_pairs}, extra {extra_pairs}, distances checked {checked_distances}"
    );
}
