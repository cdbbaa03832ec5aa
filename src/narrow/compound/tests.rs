//! Compound queries against two oracles: the triangles of the parts' hulls in f64 (apart
//! pairs: the distance of two apart convex solids is their surfaces'), and every part pair
//! through the dispatcher with no tree (depths, and the order of the search).

use super::*;
use crate::budget::{Stop, WorkClock};
use crate::geometry::{Capsule, Cuboid, Sphere, Triangle};
use crate::math::Pose;
use crate::narrow::contact::Reached;
use crate::narrow::dispatch::{self, NarrowScratch};
use crate::narrow::{Manifold, distance_triangle_triangle};
use crate::test_support::{TestRng, point_in_cube, pose, rng};
use rand::Rng;

/// A hull of 6–20 points in a ball of radius 0.05–0.3 m about a point within 0.5 m.
fn random_hull(r: &mut TestRng) -> ConvexPolyhedron {
    let centre = point_in_cube(r, 0.5);
    let radius = r.random_range(0.05..0.3);
    let n = r.random_range(6..=20);
    let points: Vec<DVec3> = (0..n)
        .map(|_| centre + point_in_cube(r, 1.0).normalize_or(DVec3::X) * radius)
        .collect();
    ConvexPolyhedron::try_from_points(&points).expect("finite points")
}

/// A compound of 2–7 random hulls.
fn random_compound(r: &mut TestRng) -> CompoundShape {
    let n = r.random_range(2..=7);
    CompoundShape::from_hulls((0..n).map(|_| random_hull(r)).collect()).expect("2–7 hulls")
}

/// A shape for B: a sphere, capsule, box, hull or compound.
fn random_other(r: &mut TestRng) -> Shape {
    match r.random_range(0..5) {
        0 => Shape::Sphere(Sphere::new(r.random_range(0.05..0.4))),
        1 => Shape::Capsule(Capsule::new(
            r.random_range(0.05..0.4),
            r.random_range(0.05..0.2),
        )),
        2 => Shape::Cuboid(Cuboid::new(DVec3::new(
            r.random_range(0.05..0.4),
            r.random_range(0.05..0.4),
            r.random_range(0.05..0.4),
        ))),
        3 => Shape::Convex(Arc::new(random_hull(r))),
        _ => Shape::Compound(Arc::new(random_compound(r))),
    }
}

/// The smallest signed distance over every part pair, through the dispatcher (no tree).
fn every_part_pair(a: &CompoundShape, b: &Shape, pose_ab: &Pose, s: &mut NarrowScratch) -> f64 {
    let parts_b: Vec<&Shape> = match b {
        Shape::Compound(c) => c.parts().iter().collect(),
        _ => vec![b],
    };
    a.parts()
        .iter()
        .flat_map(|pa| parts_b.iter().map(move |pb| (pa, *pb)))
        .map(|(pa, pb)| dispatch::distance(pa, pb, pose_ab, f64::INFINITY, s).distance)
        .fold(f64::INFINITY, f64::min)
}

/// A convex part's hull triangles, its frame (primitives are not checked this way).
fn hull_triangles(part: &Shape) -> Option<Vec<Triangle>> {
    let Shape::Convex(hull) = part else {
        return None;
    };
    let v = hull.vertices();
    Some(
        hull.triangles()
            .iter()
            .map(|t| Triangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
            .collect(),
    )
}

/// The f64 triangle oracle when every part of both shapes is a hull: `Some(d)` with `d`
/// the smallest triangle distance when no part pair overlaps (no surface contact, no
/// vertex of one inside the other), `Some(0)` when one does.
fn triangle_oracle(a: &CompoundShape, b: &Shape, pose_ab: &Pose) -> Option<f64> {
    let iso = pose_ab.to_isometry();
    let parts_b: Vec<&Shape> = match b {
        Shape::Compound(c) => c.parts().iter().collect(),
        _ => vec![b],
    };
    let mut best = f64::INFINITY;
    for pa in a.parts() {
        let ta = hull_triangles(pa)?;
        for pb in &parts_b {
            let tb: Vec<Triangle> = hull_triangles(pb)?
                .iter()
                .map(|t| t.transformed(&iso))
                .collect();
            let (Shape::Convex(ha), Shape::Convex(hb)) = (pa, *pb) else {
                return None;
            };
            let inside = ha
                .vertices()
                .iter()
                .any(|&p| hb.contains_point(iso.inverse_transform_point(p)))
                || hb
                    .vertices()
                    .iter()
                    .any(|&p| ha.contains_point(iso.transform_point(p)));
            if inside {
                return Some(0.0);
            }
            for x in &ta {
                for y in &tb {
                    best = best.min(distance_triangle_triangle(x, y).distance);
                }
            }
        }
    }
    Some(best)
}

/// One random case: a compound, a B of any kind, a pose of B in A.
fn random_case(r: &mut TestRng) -> (Arc<CompoundShape>, Shape, Pose) {
    let a = Arc::new(random_compound(r));
    let b = random_other(r);
    (a, b, pose(r, 0.6))
}

/// The smallest signed distance over the part pairs of `a` and `b` with B moved by
/// `offset` (A's frame), through the dispatcher.
fn moved_part_pairs(
    a: &CompoundShape,
    b: &Shape,
    pose_ab: &Pose,
    offset: DVec3,
    s: &mut NarrowScratch,
) -> f64 {
    let moved = Pose::new(pose_ab.position + offset, pose_ab.rotation);
    every_part_pair(a, b, &moved, s)
}

/// Over 3,000 seeded pairs (a compound against every kind, a compound among them), with
/// every part pair searched without the tree as the oracle: apart, the distance is the
/// smallest over the part pairs; overlapping, at least as deep as the deepest pair, and
/// moving B out by the depth along the normal frees it from every part (the whole
/// compound's depth; deeper than the deepest pair's in some cases). Witnesses are
/// `distance · normal` apart; when every part is a hull, apart pairs match the f64
/// triangle oracle and overlapping ones are not reported apart; B against the compound
/// gives the same distance and the opposite normal. Both sides of contact occur.
#[test]
fn distances_match_every_part_pair_and_the_triangle_oracle() {
    let mut r = rng(3301);
    let mut s = NarrowScratch::default();
    let (mut apart, mut overlapping, mut by_triangles, mut deeper) = (0, 0, 0, 0);
    for case in 0..3000 {
        let (a, b, pose_ab) = random_case(&mut r);
        let truth = every_part_pair(&a, &b, &pose_ab, &mut s);
        let shape_a = Shape::Compound(a.clone());
        // Never bounds without a clock that stops.
        let Reached::Exact(d) =
            dispatch::distance_within(&shape_a, &b, &pose_ab, f64::INFINITY, &mut s)
        else {
            panic!("case {case}: bounds from an unlimited clock");
        };
        if truth > 0.0 {
            assert!(
                (d.distance - truth).abs() <= 1e-12,
                "case {case}: {} against {truth}",
                d.distance
            );
        } else {
            assert!(
                d.distance <= truth + 1e-12,
                "case {case}: {} against {truth}",
                d.distance
            );
            let freed = moved_part_pairs(&a, &b, &pose_ab, -d.distance * d.normal, &mut s);
            assert!(
                freed >= -1e-8,
                "case {case}: moved out by {d:?}, still {freed}"
            );
            deeper += usize::from(d.distance < truth - 1e-9);
        }
        let gap = d.point_b - d.point_a - d.distance * d.normal;
        assert!(
            (d.normal.length() - 1.0).abs() < 1e-9 && gap.length() < 1e-9,
            "case {case}: {d:?}"
        );
        if let Some(oracle) = triangle_oracle(&a, &b, &pose_ab) {
            by_triangles += 1;
            if oracle > 0.0 {
                assert!(
                    (d.distance - oracle).abs() <= 1e-9,
                    "case {case}: {} against the triangles' {oracle}",
                    d.distance
                );
            } else {
                assert!(d.distance <= 1e-9, "case {case}: {} apart", d.distance);
            }
        }
        let pose_ba = pose_ab.inverse();
        let flipped = dispatch::distance(&b, &shape_a, &pose_ba, f64::INFINITY, &mut s);
        let back = pose_ab.transform_vector(-flipped.normal);
        assert!(
            (flipped.distance - d.distance).abs() <= 1e-8 && back.distance(d.normal) < 1e-6,
            "case {case}: {flipped:?} against {d:?}"
        );
        if truth > 0.0 {
            apart += 1;
        } else {
            overlapping += 1;
        }
    }
    assert!(
        apart > 500 && overlapping > 500 && by_triangles > 1000 && deeper > 20,
        "{apart} apart, {overlapping} overlapping, {by_triangles} by the triangles, \
         {deeper} deeper than every part pair"
    );
}

/// Under a reporting limit the distance is exact up to it; beyond it, a lower bound above
/// the limit.
#[test]
fn beyond_the_limit_the_answer_is_a_lower_bound_above_it() {
    let mut r = rng(3302);
    let mut s = NarrowScratch::default();
    let (mut within, mut beyond) = (0, 0);
    for case in 0..2000 {
        let (a, b, pose_ab) = random_case(&mut r);
        let limit = r.random_range(0.0..0.3);
        let shape_a = Shape::Compound(a);
        let truth = dispatch::distance(&shape_a, &b, &pose_ab, f64::INFINITY, &mut s).distance;
        let d = dispatch::distance(&shape_a, &b, &pose_ab, limit, &mut s).distance;
        if truth <= limit {
            within += 1;
            assert!(
                (d - truth).abs() <= 1e-12,
                "case {case}: {d} against {truth}"
            );
        } else {
            beyond += 1;
            assert!(
                d > limit && d <= truth + 1e-12,
                "case {case}: {d}, limit {limit}, truth {truth}"
            );
        }
    }
    assert!(
        within > 300 && beyond > 300,
        "{within} within, {beyond} beyond"
    );
}

/// Stopped after every count of work units, the answer is the unlimited one or bounds that
/// hold it; both occur.
#[test]
fn a_stopped_search_answers_bounds_that_hold_the_truth() {
    let mut r = rng(3303);
    let mut s = NarrowScratch::default();
    let (mut exact, mut bounded) = (0, 0);
    for case in 0..300 {
        let a = Arc::new(random_compound(&mut r));
        let b = Shape::Compound(Arc::new(random_compound(&mut r)));
        let pose_ab = pose(&mut r, 0.6);
        let shape_a = Shape::Compound(a);
        s.clock = WorkClock::default();
        let truth = dispatch::distance(&shape_a, &b, &pose_ab, f64::INFINITY, &mut s).distance;
        for units in [0, 1, 8, 9, 16, 17, 24, 40, 64, 120, 400] {
            s.clock = WorkClock::new(Stop::AfterWork(units));
            match dispatch::distance_within(&shape_a, &b, &pose_ab, f64::INFINITY, &mut s) {
                // Finished: the unlimited answer (a resolved one at its lower end).
                finished @ (Reached::Exact(_) | Reached::Resolved(_)) => {
                    exact += 1;
                    assert!(
                        (finished.at_lower().distance - truth).abs() <= 1e-12,
                        "case {case} at {units}"
                    );
                }
                Reached::Bounded(bound) => {
                    bounded += 1;
                    assert!(
                        bound.lower <= truth + 1e-12 && truth <= bound.upper + 1e-12,
                        "case {case} at {units}: {bound:?} against {truth}"
                    );
                }
            }
        }
    }
    s.clock = WorkClock::default();
    assert!(
        exact > 300 && bounded > 300,
        "{exact} exact, {bounded} bounded"
    );
}

/// Touching pairs get a manifold of one to four points, none apart, with a unit normal
/// and the deepest point at the pair's depth; B against the compound gives the opposite
/// normal; apart pairs get none.
#[test]
fn manifolds_gather_the_touching_part_pairs() {
    let mut r = rng(3304);
    let mut s = NarrowScratch::default();
    let (mut touching, mut apart) = (0, 0);
    let mut m = Manifold::new();
    for case in 0..2000 {
        let (a, b, pose_ab) = random_case(&mut r);
        let shape_a = Shape::Compound(a);
        let d = dispatch::distance(&shape_a, &b, &pose_ab, 0.0, &mut s);
        dispatch::manifold(&shape_a, &b, &pose_ab, &d, &mut s, &mut m);
        if d.distance > 0.0 {
            apart += 1;
            assert!(m.is_empty(), "case {case}");
            continue;
        }
        touching += 1;
        assert!(!m.is_empty() && m.len() <= 4, "case {case}: {m:?}");
        assert!((m.normal.length() - 1.0).abs() < 1e-9, "case {case}");
        let deepest = m.points().iter().map(|p| p.distance).fold(0.0, f64::min);
        assert!(
            m.points().iter().all(|p| p.distance <= 1e-9)
                && deepest <= d.distance + 1e-6 * (1.0 + d.distance.abs()),
            "case {case}: {m:?} against {}",
            d.distance
        );
        let pose_ba = pose_ab.inverse();
        let d_ba = d.flipped(&pose_ba.to_isometry());
        let mut flipped = Manifold::new();
        dispatch::manifold(&b, &shape_a, &pose_ba, &d_ba, &mut s, &mut flipped);
        // The same normal and depth (the points kept may differ: they are chosen by their
        // positions on the side queried as A).
        let back = pose_ab.transform_vector(-flipped.normal);
        let deepest_ba = flipped
            .points()
            .iter()
            .map(|p| p.distance)
            .fold(0.0, f64::min);
        assert!(
            back.distance(m.normal) < 1e-6 && (deepest_ba - deepest).abs() < 1e-8,
            "case {case}: {flipped:?} against {m:?}"
        );
    }
    assert!(
        touching > 400 && apart > 400,
        "{touching} touching, {apart} apart"
    );
}

/// The tree holds every part once, and each node's box every point of its parts.
#[test]
fn the_part_tree_bounds_its_parts() {
    let mut r = rng(3305);
    for _ in 0..100 {
        let mut parts: Vec<Shape> = (0..r.random_range(1..=40))
            .map(|_| Shape::Convex(Arc::new(random_hull(&mut r))))
            .collect();
        parts.push(Shape::Cuboid(Cuboid::new(DVec3::splat(0.1))));
        let c = CompoundShape::new(parts).expect("convex parts");
        let nodes = c.tree().nodes();
        let mut seen = vec![0; c.parts().len()];
        let mut below: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
        // Each node's parts, children first (they come after their parent).
        for i in (0..nodes.len()).rev() {
            below[i] = match (nodes[i].part(), nodes[i].children()) {
                (Some(p), None) => {
                    seen[p] += 1;
                    vec![p]
                }
                (None, Some([l, r])) => {
                    assert!(l > i && r == l + 1 && r < nodes.len());
                    [below[l].clone(), below[r].clone()].concat()
                }
                _ => unreachable!("a node is a leaf or has two children"),
            };
            for &p in &below[i] {
                for q in super::part_points(&c.parts()[p]) {
                    assert!(nodes[i].bv.contains_point(q), "node {i}, part {p}");
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
        assert_eq!(below[0].len(), c.parts().len());
    }
}

#[test]
fn a_compound_needs_one_to_max_parts_all_convex() {
    assert_eq!(
        CompoundShape::new(Vec::new()).unwrap_err(),
        CompoundError::Empty
    );
    let ball = || Shape::Sphere(Sphere::new(0.1));
    assert_eq!(
        CompoundShape::new(vec![ball(); MAX_PARTS + 1]).unwrap_err(),
        CompoundError::TooManyParts {
            parts: MAX_PARTS + 1
        }
    );
    let torus = crate::test_support::meshes::torus(0.4, 0.1, 8, 6);
    let mesh = Shape::Mesh(Arc::new(crate::narrow::MeshShape::new(torus)));
    assert_eq!(
        CompoundShape::new(vec![ball(), mesh]).unwrap_err(),
        CompoundError::NotConvex { index: 1 }
    );
    assert!(CompoundShape::new(vec![ball(); MAX_PARTS]).is_ok());
}

/// A manifold the frame's clock stops keeps the deepest point and the normal, and says it
/// was cut short; an unlimited clock gathers every part pair and says nothing.
#[test]
fn a_stopped_manifold_keeps_the_deepest_point_and_says_so() {
    let mut r = rng(3306);
    let mut s = NarrowScratch::default();
    let mut cut = 0;
    for case in 0..400 {
        let a = Arc::new(random_compound(&mut r));
        let b = Shape::Compound(Arc::new(random_compound(&mut r)));
        let pose_ab = pose(&mut r, 0.4);
        let Shape::Compound(parts_b) = &b else {
            unreachable!()
        };
        let touching = a
            .parts()
            .iter()
            .flat_map(|pa| parts_b.parts().iter().map(move |pb| (pa, pb)))
            .filter(|(pa, pb)| dispatch::distance(pa, pb, &pose_ab, 0.0, &mut s).distance < 0.0)
            .count();
        if touching < 2 {
            continue;
        }
        let shape_a = Shape::Compound(a);
        let d = dispatch::distance(&shape_a, &b, &pose_ab, 0.0, &mut s);
        let mut m = Manifold::new();
        for (stop, expect_cut) in [(Stop::Never, false), (Stop::AfterWork(0), true)] {
            s.clock = WorkClock::new(stop);
            s.manifold_cut_short = false;
            dispatch::manifold(&shape_a, &b, &pose_ab, &d, &mut s, &mut m);
            assert_eq!(s.manifold_cut_short, expect_cut, "case {case}");
            let deepest = m.points().iter().map(|p| p.distance).fold(0.0, f64::min);
            assert!(
                m.normal.distance(d.normal) < 1e-12 && (deepest - d.distance).abs() < 1e-12,
                "case {case}: {m:?} against {d:?}"
            );
        }
        cut += 1;
    }
    s.clock = WorkClock::default();
    assert!(cut > 30, "{cut} pairs with two touching part pairs");
}
