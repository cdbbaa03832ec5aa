//! The narrow routes a frame's clock can stop: a convex shape's walk of a mesh and EPA
//! (`dispatch::distance_within`), and the mesh–mesh searches (overlap, proximity,
//! distance, contacts). Each is stopped after every count of work units from 0 (or a
//! growing sample of them) to what its whole run takes (a counted clock, `Stop::AfterWork`,
//! never wall time), and every stopped answer must be conservative against the same query
//! run to the end:
//!
//! - `Bounded { lower, upper }` holds the exact signed distance (`lower ≤ exact ≤ upper`,
//!   to rounding), so a pair that touches is never reported apart;
//! - more work never loosens the bounds (`lower` never falls, `upper` never rises);
//! - enough work gives the exact answer, bit for bit.
//!
//! The seeded cases include both outcomes of the query (touching and apart) and both kinds
//! of answer (stopped and finished), and the test asserts they all occur.

#[path = "support/mod.rs"]
mod support;

use proxima::budget::{Stop, WorkClock};
use proxima::geometry::{Capsule, ConvexPolyhedron, Cuboid, Cylinder, Sphere};
use proxima::math::{DVec3, Pose};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::{MeshShape, Reached, Shape, ShapeDistance};
use rand::Rng;
use std::sync::Arc;
use support::{TestRng, meshes, point_in_cube, rng, rotation};

/// Relative slack of the bounds against the exact answer (rounding of the bounds' sums).
const RELATIVE: f64 = 1e-9;

/// How often each outcome occurred over a test's cases.
#[derive(Debug, Default)]
struct Seen {
    touching: usize,
    apart: usize,
    stopped: usize,
    finished: usize,
}

/// Runs the pair's query under every counted clock from 0 up, until it finishes, checking
/// each answer against the exact one.
fn check_every_stop(a: &Shape, b: &Shape, pose_ab: &Pose, seen: &mut Seen, case: usize) {
    let scratch = &mut NarrowScratch::default();
    let exact = dispatch::distance(a, b, pose_ab, f64::INFINITY, scratch);
    let tol = RELATIVE * (1.0 + exact.distance.abs());
    if exact.distance <= 0.0 {
        seen.touching += 1;
    } else {
        seen.apart += 1;
    }
    let (mut lower_before, mut upper_before) = (f64::NEG_INFINITY, f64::INFINITY);
    for work in 0.. {
        scratch.clock = WorkClock::new(Stop::AfterWork(work));
        match dispatch::distance_within(a, b, pose_ab, f64::INFINITY, scratch) {
            Reached::Exact(d) => {
                assert_same(&d, &exact, case, work);
                seen.finished += 1;
                return;
            }
            // Finished short of the tolerance by rounding: the bounds must hold the exact
            // answer.
            Reached::Resolved(bound) => {
                assert!(
                    bound.lower <= exact.distance + tol && exact.distance <= bound.upper + tol,
                    "case {case}, resolved after {work} units: {bound:?} does not hold the \
                     exact {}",
                    exact.distance
                );
                seen.finished += 1;
                return;
            }
            Reached::Bounded(bound) => {
                seen.stopped += 1;
                assert!(bound.lower.is_finite(), "case {case}: {bound:?}");
                assert!(
                    bound.lower <= exact.distance + tol && exact.distance <= bound.upper + tol,
                    "case {case}, stopped after {work} units: {bound:?} does not hold the \
                     exact {}",
                    exact.distance
                );
                assert!(
                    bound.lower >= lower_before - tol && bound.upper <= upper_before + tol,
                    "case {case}, stopped after {work} units: bounds [{}, {}] looser than \
                     [{lower_before}, {upper_before}] with less work",
                    bound.lower,
                    bound.upper
                );
                assert!(
                    (bound.normal.length() - 1.0).abs() < 1e-9 || bound.upper.is_infinite(),
                    "case {case}: normal {:?}",
                    bound.normal
                );
                (lower_before, upper_before) = (bound.lower, bound.upper);
            }
        }
        assert!(work < 1_000_000, "case {case}: the query never finished");
    }
}

fn assert_same(d: &ShapeDistance, exact: &ShapeDistance, case: usize, work: u64) {
    assert_eq!(
        d, exact,
        "case {case}: finished after {work} units with another answer than the exact run"
    );
}

/// A random convex shape 5–30 cm across.
fn convex_shape(r: &mut TestRng) -> Shape {
    let size = r.random_range(0.05..0.3);
    match r.random_range(0..5) {
        0 => Shape::Sphere(Sphere::new(size / 2.0)),
        1 => Shape::Capsule(Capsule::new(size / 2.0, size / 4.0)),
        2 => Shape::Cuboid(Cuboid::new(DVec3::new(size / 2.0, size / 3.0, size / 4.0))),
        3 => Shape::Cylinder(Cylinder::new(size / 2.0, size / 3.0)),
        _ => Shape::Convex(Arc::new(hull(r, size / 2.0, 40))),
    }
}

/// The hull of `n` random points in a ball of radius `radius`.
fn hull(r: &mut TestRng, radius: f64, n: usize) -> ConvexPolyhedron {
    let points: Vec<DVec3> = (0..n)
        .map(|_| {
            let d = DVec3::new(
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
                r.random_range(-1.0..1.0),
            );
            d.normalize_or_zero() * radius * r.random_range(0.6..1.0)
        })
        .collect();
    ConvexPolyhedron::try_from_points(&points).expect("a hull of random points in a ball")
}

#[test]
fn a_stopped_walk_of_a_mesh_holds_the_exact_distance_and_tightens_with_work() {
    let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.5, 0.15, 48, 16))));
    let mut r = rng(2901);
    let mut seen = Seen::default();
    for case in 0..300 {
        let shape = convex_shape(&mut r);
        // Near the tube (radius 0.35–0.65 from the axis, |z| < 0.2): touching and apart.
        let angle = r.random_range(0.0..std::f64::consts::TAU);
        let rho = r.random_range(0.3..0.7);
        let position = DVec3::new(
            rho * angle.cos(),
            rho * angle.sin(),
            r.random_range(-0.25..0.25),
        );
        let pose = Pose::new(position, rotation(&mut r));
        // Both orders: the shape first, and the mesh first (the flipped route).
        if case % 2 == 0 {
            check_every_stop(&shape, &torus, &pose, &mut seen, case);
        } else {
            check_every_stop(&torus, &shape, &pose.inverse(), &mut seen, case);
        }
    }
    println!("{seen:?}");
    assert!(seen.touching > 30 && seen.apart > 30, "{seen:?}");
    assert!(seen.stopped > 300 && seen.finished == 300, "{seen:?}");
}

#[test]
fn a_stopped_epa_holds_the_exact_depth_and_tightens_with_work() {
    let mut r = rng(2902);
    let mut seen = Seen::default();
    for case in 0..300 {
        let n = r.random_range(20..60);
        let a = Shape::Convex(Arc::new(hull(&mut r, 0.2, n)));
        let n = r.random_range(20..60);
        let b = match case % 3 {
            0 => Shape::Convex(Arc::new(hull(&mut r, 0.15, n))),
            1 => Shape::Cylinder(Cylinder::new(0.1, 0.08)),
            _ => Shape::Cuboid(Cuboid::new(DVec3::new(0.1, 0.05, 0.2))),
        };
        let pose = Pose::new(point_in_cube(&mut r, 0.3), rotation(&mut r));
        check_every_stop(&a, &b, &pose, &mut seen, case);
    }
    println!("{seen:?}");
    assert!(seen.touching > 30 && seen.apart > 30, "{seen:?}");
    assert!(seen.stopped > 100 && seen.finished == 300, "{seen:?}");
}

/// A convex shape's manifold against a mesh, stopped after every count of work units from
/// 0: either it finished (not cut short), and is the unlimited manifold exactly, or it says
/// it was cut short and is the distance's one point (the deepest, with its normal), never
/// a partial set that could miss the deepest point. Boxes and capsules (whose triangle
/// manifolds are queried, and so polled) deep in a finely tessellated torus, both orders;
/// each manifold both from the distance walk's record of touching triangles (as the
/// pipeline asks it) and from a walk of its own (a scratch without that record).
#[test]
fn a_stopped_manifold_against_a_mesh_is_the_deepest_point_or_the_whole_manifold() {
    use proxima::narrow::Manifold;
    let torus = Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(0.5, 0.15, 64, 24))));
    let mut r = rng(2906);
    // Stopped runs without and with the walk's record.
    let (mut cut, mut whole, mut cases) = ([0; 2], 0, 0);
    while cases < 120 {
        let size = r.random_range(0.05..0.3);
        let shape = if r.random_bool(0.5) {
            Shape::Cuboid(Cuboid::new(DVec3::new(size / 2.0, size / 3.0, size / 4.0)))
        } else {
            Shape::Capsule(Capsule::new(size / 2.0, size / 4.0))
        };
        // On the tube's surface (0.15 from the core circle), so that it touches.
        let angle = r.random_range(0.0..std::f64::consts::TAU);
        let around = r.random_range(0.0..std::f64::consts::TAU);
        let rho = 0.5 + 0.15 * around.cos();
        let position = DVec3::new(rho * angle.cos(), rho * angle.sin(), 0.15 * around.sin());
        let pose = Pose::new(position, rotation(&mut r));
        let (a, b, pose) = if cases % 2 == 0 {
            (&shape, &torus, pose)
        } else {
            (&torus, &shape, pose.inverse())
        };
        let scratch = &mut NarrowScratch::default();
        let d = dispatch::distance(a, b, &pose, f64::INFINITY, scratch);
        if d.distance > 0.0 {
            continue;
        }
        cases += 1;
        // The unlimited manifold, from the walk's record and from a walk of its own (the
        // same points, perhaps in another order).
        let mut full = [Manifold::default(); 2];
        dispatch::manifold(a, b, &pose, &d, scratch, &mut full[1]);
        dispatch::manifold(a, b, &pose, &d, &mut NarrowScratch::default(), &mut full[0]);
        assert!(
            !scratch.manifold_cut_short,
            "an unlimited clock cut it short"
        );
        let mut deepest = Manifold::default();
        deepest.set_from_distance(&d);
        for walked in [true, false] {
            let full = &full[usize::from(walked)];
            for work in 0.. {
                let scratch = &mut NarrowScratch::default();
                if walked {
                    // As the pipeline does: the distance walk, then the manifold.
                    let d_again = dispatch::distance(a, b, &pose, f64::INFINITY, scratch);
                    assert_eq!(d_again, d);
                }
                scratch.clock = WorkClock::new(Stop::AfterWork(work));
                let mut found = Manifold::default();
                dispatch::manifold(a, b, &pose, &d, scratch, &mut found);
                if scratch.manifold_cut_short {
                    cut[usize::from(walked)] += 1;
                    // The flipped order rebuilds the point through two pose changes.
                    assert!(
                        same_to_rounding(&found, &deepest),
                        "case {cases}, {work} units: {found:?}, not the deepest {deepest:?}"
                    );
                } else {
                    whole += 1;
                    assert_eq!(&found, full, "case {cases}, {work} units: another manifold");
                    break;
                }
                assert!(work < 1_000_000, "case {cases}: never finished");
            }
        }
    }
    println!("{cut:?} cut short (own walk, walk's record), {whole} whole");
    assert!(
        cut.iter().all(|&n| n > 100) && whole == 240,
        "{cut:?} cut short, {whole} whole"
    );
}

/// Whether two manifolds have the same points and normal to 1e-12 m.
fn same_to_rounding(x: &proxima::narrow::Manifold, y: &proxima::narrow::Manifold) -> bool {
    let near = |p: DVec3, q: DVec3| (p - q).abs().max_element() <= 1e-12;
    x.points().len() == y.points().len()
        && near(x.normal, y.normal)
        && x.points().iter().zip(y.points()).all(|(p, q)| {
            near(p.point_a, q.point_a)
                && near(p.point_b, q.point_b)
                && (p.distance - q.distance).abs() <= 1e-12
        })
}

/// The mesh–mesh overlap and proximity tests stopped after a growing count of work units
/// (each an eighth more than the last, from 0): each says it stopped (`None`) or gives the
/// unlimited run's answer, bit for bit; once a count finishes, every larger one does; every
/// run finishes with enough work.
#[test]
fn stopped_mesh_overlap_and_proximity_tests_say_so_or_answer_exactly() {
    use proxima::narrow::mesh_mesh::{MeshMeshWorkspace, intersects_mesh_mesh_within};
    let a = MeshShape::new(meshes::torus(0.5, 0.15, 32, 12));
    let b = MeshShape::new(meshes::uv_sphere(0.3, 16, 10));
    let mut r = rng(2905);
    let workspace = &mut MeshMeshWorkspace::default();
    let (mut intersecting, mut within, mut apart, mut stopped) = (0, 0, 0, 0);
    for case in 0..200 {
        let pose = Pose::new(point_in_cube(&mut r, 0.8), rotation(&mut r));
        let margin = 0.05;
        let overlap = |work, workspace: &mut MeshMeshWorkspace| {
            let (ta, tb) = (&a.overlap_tree, &b.overlap_tree);
            intersects_mesh_mesh_within(ta, tb, &pose, workspace, &mut WorkClock::new(work))
        };
        let proximity = |work, workspace: &mut MeshMeshWorkspace| {
            a.proximity_within(&b, &pose, margin, workspace, &mut WorkClock::new(work))
        };
        let truth = (
            overlap(Stop::Never, workspace).expect("an unlimited clock never stops"),
            proximity(Stop::Never, workspace).expect("an unlimited clock never stops"),
        );
        intersecting += usize::from(truth.0);
        match truth.1 {
            proxima::narrow::mesh_mesh::Proximity::Within => within += 1,
            proxima::narrow::mesh_mesh::Proximity::Apart { .. } => apart += 1,
        }
        let (mut overlap_done, mut proximity_done) = (false, false);
        let mut work = 0;
        loop {
            let found = overlap(Stop::AfterWork(work), workspace);
            stopped += check_stop(found, &truth.0, &mut overlap_done, (case, work));
            let found = proximity(Stop::AfterWork(work), workspace);
            stopped += check_stop(found, &truth.1, &mut proximity_done, (case, work));
            if overlap_done && proximity_done {
                break;
            }
            assert!(work < 10_000_000, "case {case}: never finished");
            work = (work + work / 8).max(work + 1);
        }
    }
    println!("{intersecting} intersecting, {within} within, {apart} apart, {stopped} stopped");
    assert!(intersecting > 30 && apart > 30 && within > intersecting && stopped > 400);
}

/// Checks a run stopped after `work` units: finished (`Some`), it is `truth` and `done`
/// becomes true; stopped (`None`), no run with less work may have finished. Returns 1 for a
/// stopped run.
fn check_stop<T: PartialEq + std::fmt::Debug>(
    found: Option<T>,
    truth: &T,
    done: &mut bool,
    (case, work): (usize, u64),
) -> usize {
    match found {
        Some(found) => {
            assert_eq!(&found, truth, "case {case}, {work} units");
            *done = true;
            0
        }
        None => {
            assert!(
                !*done,
                "case {case}: stopped after {work} units, with more work"
            );
            1
        }
    }
}

#[test]
fn stopped_mesh_contacts_are_the_first_of_the_full_set_and_grow_with_work() {
    use proxima::narrow::mesh_mesh::{MeshMeshWorkspace, contacts_mesh_mesh_within};
    let a = MeshShape::new(meshes::torus(0.5, 0.15, 32, 12));
    let b = MeshShape::new(meshes::uv_sphere(0.3, 16, 10));
    let mut r = rng(2903);
    let workspace = &mut MeshMeshWorkspace::default();
    let (mut intersecting, mut apart, mut stopped) = (0, 0, 0);
    for case in 0..200 {
        let pose = Pose::new(point_in_cube(&mut r, 0.8), rotation(&mut r));
        let mut collect = |work: Stop| {
            let mut found = Vec::new();
            let finished = contacts_mesh_mesh_within(
                &a.overlap_tree,
                &b.overlap_tree,
                &pose,
                workspace,
                &mut WorkClock::new(work),
                |c| {
                    found.push(c.triangles);
                    std::ops::ControlFlow::Continue(())
                },
            );
            (finished, found)
        };
        let (finished, all) = collect(Stop::Never);
        assert!(finished, "case {case}");
        if all.is_empty() {
            apart += 1;
        } else {
            intersecting += 1;
        }
        let mut before = 0;
        for work in 0.. {
            let (finished, found) = collect(Stop::AfterWork(work));
            assert!(
                found.len() >= before && all.starts_with(&found),
                "case {case}, {work} units: not the first contacts of the full set"
            );
            before = found.len();
            if finished {
                assert_eq!(found, all, "case {case}: finished with another set");
                break;
            }
            stopped += 1;
            assert!(work < 10_000_000, "case {case}: never finished");
        }
    }
    println!("{intersecting} intersecting, {apart} apart, {stopped} stopped runs");
    assert!(intersecting > 30 && apart > 30 && stopped > 200);
}

/// A mesh–mesh distance search stopped after a growing amount of work (counted clocks, each
/// about a quarter more than the last) holds the exact run's distance between its lower
/// bound (`distance − error_bound`) and its closest pair found (`distance`), never loosens
/// with more work, and once it finishes is the exact run, bit for bit.
#[test]
fn a_stopped_mesh_distance_holds_the_exact_distance_and_tightens_with_work() {
    use proxima::narrow::mesh_mesh::{DistanceCache, MeshMeshWorkspace};
    let a = MeshShape::new(meshes::torus(0.5, 0.15, 32, 12));
    let b = MeshShape::new(meshes::uv_sphere(0.3, 16, 10));
    let mut r = rng(2904);
    let workspace = &mut MeshMeshWorkspace::default();
    let mut seen = Seen::default();
    for case in 0..150 {
        let pose = Pose::new(point_in_cube(&mut r, 0.9), rotation(&mut r));
        let exact = a.distance_to(&b, &pose, &mut DistanceCache::default(), workspace);
        if exact.distance <= 0.0 {
            seen.touching += 1;
        } else {
            seen.apart += 1;
        }
        let tol = RELATIVE * (1.0 + exact.distance);
        let (mut lower_before, mut upper_before) = (f64::NEG_INFINITY, f64::INFINITY);
        let mut work = 0;
        loop {
            let mut clock = WorkClock::new(Stop::AfterWork(work));
            let cache = &mut DistanceCache::default();
            let d = a.distance_to_within(&b, &pose, cache, workspace, &mut clock);
            if !clock.stopped() {
                assert_eq!(
                    d, exact,
                    "case {case}: finished after {work} units otherwise"
                );
                seen.finished += 1;
                break;
            }
            seen.stopped += 1;
            let (lower, upper) = (d.distance - d.error_bound, d.distance);
            assert!(
                lower <= exact.distance + tol && exact.distance <= upper + tol,
                "case {case}, stopped after {work} units: [{lower}, {upper}] does not hold \
                 the exact {}",
                exact.distance
            );
            assert!(
                lower >= lower_before - tol && upper <= upper_before + tol,
                "case {case}, stopped after {work} units: [{lower}, {upper}] looser than \
                 [{lower_before}, {upper_before}] with less work"
            );
            (lower_before, upper_before) = (lower, upper);
            assert!(work < 100_000_000, "case {case}: the search never finished");
            work = (work + work / 4).max(work + 8);
        }
    }
    println!("{seen:?}");
    assert!(seen.touching > 20 && seen.apart > 20, "{seen:?}");
    assert!(seen.stopped > 500 && seen.finished == 150, "{seen:?}");
}
