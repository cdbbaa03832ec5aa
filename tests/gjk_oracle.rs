//! GJK distance and EPA depth against independent oracles.
//!
//! - Separated polytopes (boxes, hulls of random clouds, flat hulls): the distance is the
//!   minimum of `distance_triangle_triangle` over every pair of surface triangles.
//! - Penetrating polytopes: the depth is the minimum, over candidate axes that include every
//!   face normal of `A − B` (face normals of both shapes and cross products of their edges,
//!   both signs), of the overlap `h_A(n) + h_B(−n)` computed by brute force over the
//!   vertices; for boxes these are the 15 SAT axes. Metamorphic check too: moving B by
//!   `(depth + ε)` along the normal separates the shapes (a separating plane exists), by
//!   `(depth − ε)` it does not (the triangle oracle finds crossing surfaces).
//! - Curved shapes (cylinders, cones): witness points are tested for membership with the
//!   shapes' closed-form inequalities, and the answer is checked against a dense sampling of
//!   directions (the gap or overlap along any direction bounds the distance or depth).
//! - Invariance: far from the origin (1e3, 1e5 m), scaled (1e-3 … 1e3), A and B swapped,
//!   `q` vs `−q`, warm vs cold start, accelerated vs plain.
#[path = "support/mod.rs"]
mod support;

use proxima::budget::WorkClock;
use proxima::geometry::{Capsule, Segment, Sphere};
use proxima::geometry::{Cone, ConvexPolyhedron, Cuboid, Cylinder, SupportMap, Triangle};
use proxima::math::{DQuat, DVec3, Isometry, Pose};
use proxima::narrow::gjk::{
    ConvexOutcome, EpaOutcome, EpaWorkspace, GjkCache, GjkOutcome, GjkParams, Rounded,
    gjk_distance, signed_distance_convex, signed_distance_convex_within,
};
use proxima::narrow::gjk::{POINT, capsule_core};
use proxima::narrow::{Reached, ShapeDistance, distance_triangle_triangle};
use rand::Rng;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use support::{TestRng, isometry, meshes, point_in_cube, rng, rotation};

/// Counts this thread's allocations, to prove that a warmed-up query allocates nothing.
struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; the counter is a const-initialised thread local,
// which never allocates.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(Cell::get)
}

/// A polytope as vertices (for support values) and surface triangles (for distances).
struct Poly {
    vertices: Vec<DVec3>,
    triangles: Vec<Triangle>,
    edges: Vec<DVec3>,
}

impl Poly {
    fn of_box(c: &Cuboid) -> Self {
        let m = meshes::cuboid(c.half_extents);
        Self::from_triangles(c.corners().to_vec(), meshes::triangles(&m))
    }

    fn of_hull(h: &ConvexPolyhedron) -> Self {
        let v = h.vertices();
        let t = h
            .triangles()
            .iter()
            .map(|t| Triangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
            .collect();
        Self::from_triangles(v.to_vec(), t)
    }

    fn of_segment(s: &Segment) -> Self {
        Self::from_triangles(vec![s.a, s.b], vec![Triangle::new(s.a, s.b, s.b)])
    }

    fn of_point(p: DVec3) -> Self {
        Self::from_triangles(vec![p], vec![Triangle::new(p, p, p)])
    }

    fn from_triangles(vertices: Vec<DVec3>, triangles: Vec<Triangle>) -> Self {
        let mut edges: Vec<DVec3> = Vec::new();
        for t in &triangles {
            for (p, q) in [(t.a, t.b), (t.b, t.c), (t.c, t.a)] {
                let e = (q - p).normalize_or_zero();
                if e != DVec3::ZERO && !edges.iter().any(|f| f.cross(e).length() < 1e-9) {
                    edges.push(e);
                }
            }
        }
        Self {
            vertices,
            triangles,
            edges,
        }
    }

    fn moved(&self, pose: &Isometry) -> Self {
        Self {
            vertices: self
                .vertices
                .iter()
                .map(|&p| pose.transform_point(p))
                .collect(),
            triangles: self.triangles.iter().map(|t| t.transformed(pose)).collect(),
            edges: self
                .edges
                .iter()
                .map(|&e| pose.transform_vector(e))
                .collect(),
        }
    }

    fn h(&self, n: DVec3) -> f64 {
        self.vertices
            .iter()
            .map(|p| p.dot(n))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Minimum distance over all triangle pairs (B already in A's frame).
fn triangle_oracle(a: &Poly, b: &Poly) -> f64 {
    let mut best = f64::INFINITY;
    for ta in &a.triangles {
        for tb in &b.triangles {
            best = best.min(distance_triangle_triangle(ta, tb).distance);
        }
    }
    best
}

/// Overlap along unit `n`: how far B must move along `n` to leave A.
fn overlap(a: &Poly, b: &Poly, n: DVec3) -> f64 {
    a.h(n) + b.h(-n)
}

/// Minimum overlap over face normals and edge crosses (both signs), B in A's frame.
fn depth_oracle(a: &Poly, b: &Poly) -> f64 {
    let mut axes: Vec<DVec3> = Vec::new();
    for t in a.triangles.iter().chain(&b.triangles) {
        if let Some(n) = t.normal() {
            axes.push(n);
        }
    }
    for ea in &a.edges {
        for eb in &b.edges {
            let n = ea.cross(*eb);
            if n.length() > 1e-9 {
                axes.push(n.normalize());
            }
        }
    }
    axes.iter()
        .flat_map(|&n| [n, -n])
        .map(|n| overlap(a, b, n))
        .fold(f64::INFINITY, f64::min)
}

fn query<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &Rounded<'_, A>,
    b: &Rounded<'_, B>,
    pose: &Isometry,
    params: &GjkParams,
) -> (ShapeDistance, ConvexOutcome) {
    signed_distance_convex(
        a,
        b,
        pose,
        params,
        &mut GjkCache::default(),
        &mut EpaWorkspace::new(),
    )
}

fn plain<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose: &Isometry,
) -> (ShapeDistance, ConvexOutcome) {
    query(
        &Rounded::plain(a),
        &Rounded::plain(b),
        pose,
        &GjkParams::default(),
    )
}

fn check_contract(d: &ShapeDistance, tol: f64) {
    assert!(
        d.distance.is_finite() && d.normal.is_finite() && d.point_a.is_finite(),
        "{d:?}"
    );
    assert!((d.normal.length() - 1.0).abs() < 1e-9, "{d:?}");
    let gap = d.point_b - d.point_a - d.normal * d.distance;
    assert!(gap.length() <= tol, "witnesses off by {gap}: {d:?}");
}

/// Checks a polytope pair against both oracles; returns whether it was separated.
fn check_polytopes(a: &Poly, b_local: &Poly, d: &ShapeDistance, pose: &Isometry, tol: f64) -> bool {
    let b = b_local.moved(pose);
    check_contract(d, tol);
    // The axis oracle decides overlap exactly (its axes include every face normal of
    // A − B); the triangle oracle alone would call a shape inside the other "apart".
    let depth = depth_oracle(a, &b);
    if depth < 0.0 {
        let tri = triangle_oracle(a, &b);
        assert!(
            (d.distance - tri).abs() <= tol,
            "distance {} vs triangle oracle {tri}",
            d.distance
        );
        true
    } else {
        assert!(
            (-d.distance - depth).abs() <= tol,
            "depth {} vs axis oracle {depth}",
            -d.distance
        );
        // The normal realises the depth.
        assert!((overlap(a, &b, d.normal) - depth).abs() <= tol);
        false
    }
}

fn random_box(r: &mut TestRng, lo: f64, hi: f64) -> Cuboid {
    Cuboid::new(DVec3::new(
        r.random_range(lo..hi),
        r.random_range(lo..hi),
        r.random_range(lo..hi),
    ))
}

#[test]
fn box_pairs_match_the_triangle_and_sat_oracles() {
    let mut r = rng(10);
    let (mut apart, mut deep) = (0, 0);
    for _ in 0..4000 {
        let (ca, cb) = (random_box(&mut r, 0.1, 1.0), random_box(&mut r, 0.1, 1.0));
        let pose = isometry(&mut r, 1.8);
        let (d, out) = plain(&ca, &cb, &pose);
        assert!(
            !matches!(
                out.epa,
                Some(EpaOutcome::Fallback | EpaOutcome::RoundingLimited)
            ),
            "{out:?}"
        );
        if check_polytopes(&Poly::of_box(&ca), &Poly::of_box(&cb), &d, &pose, 1e-9) {
            apart += 1;
        } else {
            deep += 1;
        }
    }
    println!("boxes: {apart} apart, {deep} penetrating");
    assert!(apart > 1000 && deep > 1000);
}

fn random_hull(r: &mut TestRng, n: usize, flat: bool) -> ConvexPolyhedron {
    let stretch = DVec3::new(
        r.random_range(0.2..1.0),
        r.random_range(0.2..1.0),
        if flat { 0.0 } else { r.random_range(0.2..1.0) },
    );
    let q = rotation(r);
    let pts: Vec<DVec3> = (0..n)
        .map(|_| q * (point_in_cube(r, 1.0) * stretch))
        .collect();
    ConvexPolyhedron::try_from_points(&pts).expect("finite cloud")
}

#[test]
fn hulls_of_random_clouds_match_the_oracles_and_move_apart_by_their_depth() {
    let mut r = rng(11);
    let (mut apart, mut deep) = (0, 0);
    for i in 0..1200 {
        // Small clouds for penetration (the axis oracle is quadratic in edges), large ones too.
        let n = if i % 4 == 0 {
            r.random_range(60..200)
        } else {
            r.random_range(8..30)
        };
        let (ha, hb) = (
            random_hull(&mut r, n, false),
            random_hull(&mut r, 8 + i % 20, false),
        );
        let pose = isometry(&mut r, 1.6);
        let (d, out) = plain(&ha, &hb, &pose);
        let (pa, pb) = (Poly::of_hull(&ha), Poly::of_hull(&hb));
        if check_polytopes(&pa, &pb, &d, &pose, 1e-8) {
            apart += 1;
        } else {
            deep += 1;
            assert_eq!(out.epa, Some(EpaOutcome::Converged), "{out:?}");
            // Metamorphic: by depth + ε along the normal a separating plane exists, by
            // depth − ε the surfaces still cross.
            let eps = 1e-6;
            let depth = -d.distance;
            for (shift, separate) in [(depth + eps, true), (depth - eps, false)] {
                if shift <= 0.0 {
                    continue;
                }
                let moved = Isometry::new(pose.rotation, pose.translation + d.normal * shift);
                let b = pb.moved(&moved);
                let gap = -overlap(&pa, &b, d.normal);
                if separate {
                    assert!(gap > 0.0 && triangle_oracle(&pa, &b) > 0.0, "gap {gap}");
                } else {
                    assert!(depth_oracle(&pa, &b) > 0.0);
                }
            }
        }
    }
    println!("hulls: {apart} apart, {deep} penetrating");
    assert!(apart > 150 && deep > 150);
}

/// EPA cut short by its iteration cap (the same exit as a full polytope) must not claim an
/// exact depth: its answer is bounded, and the bounds hold the axis oracle's depth. Caps of
/// 1 to 12 expansions on penetrating hulls of 8 to 80 points; both ends occur.
#[test]
fn an_epa_short_of_convergence_is_bounded_around_the_oracle_depth() {
    let mut r = rng(12);
    let (mut bounded, mut exact, mut gjk_capped) = (0, 0, 0);
    for i in 0..3000 {
        let (ha, hb) = (
            random_hull(&mut r, 8 + i % 73, false),
            random_hull(&mut r, 8 + i % 29, false),
        );
        let pose = isometry(&mut r, 0.8);
        let params = GjkParams {
            max_iterations: 1 + (i % 12) as u32,
            ..GjkParams::default()
        };
        let (reached, out) = signed_distance_convex_within(
            &Rounded::plain(&ha),
            &Rounded::plain(&hb),
            &pose,
            &params,
            &mut GjkCache::default(),
            &mut EpaWorkspace::new(),
            &mut WorkClock::default(),
            f64::INFINITY,
        );
        if out.gjk == GjkOutcome::DidNotConverge {
            gjk_capped += 1;
            continue;
        }
        let (pa, pb) = (Poly::of_hull(&ha), Poly::of_hull(&hb).moved(&pose));
        let depth = depth_oracle(&pa, &pb);
        if depth <= 0.0 {
            continue;
        }
        let tol = 1e-9;
        match reached {
            Reached::Exact(d) => {
                exact += 1;
                assert!(
                    (-d.distance - depth).abs() <= tol,
                    "case {i}: exact {} vs oracle {depth} ({out:?})",
                    -d.distance
                );
            }
            Reached::Bounded(bound) | Reached::Resolved(bound) => {
                bounded += 1;
                // Out of iterations, or stopped by rounding.
                let ended = match reached {
                    Reached::Resolved(_) => EpaOutcome::RoundingLimited,
                    _ => EpaOutcome::Fallback,
                };
                assert_eq!(out.epa, Some(ended), "case {i}");
                assert!(
                    bound.lower <= -depth + tol && -depth <= bound.upper + tol,
                    "case {i}: {bound:?} does not hold the oracle depth {depth}"
                );
                assert!(bound.upper - bound.lower > 0.0, "case {i}: {bound:?}");
                // The lower signed distance is the overlap along the bound's normal.
                assert!(
                    (overlap(&pa, &pb, bound.normal) + bound.lower).abs() <= tol,
                    "case {i}: {bound:?}"
                );
            }
        }
    }
    println!("capped EPA: {bounded} bounded, {exact} exact, {gjk_capped} GJK capped");
    assert!(
        bounded > 300 && exact > 300,
        "{bounded} bounded, {exact} exact"
    );
}

#[test]
fn flat_hulls_against_boxes_match_the_oracles() {
    let mut r = rng(12);
    let (mut apart, mut deep) = (0, 0);
    for _ in 0..1000 {
        let flat = random_hull(&mut r, 12, true);
        assert_eq!(flat.dimension(), 2);
        let cube = random_box(&mut r, 0.2, 0.8);
        let pose = isometry(&mut r, 1.5);
        let (d, _) = plain(&flat, &cube, &pose);
        if check_polytopes(&Poly::of_hull(&flat), &Poly::of_box(&cube), &d, &pose, 1e-8) {
            apart += 1;
        } else {
            deep += 1;
        }
        // Two flat hulls: still never NaN, distance matches when apart.
        let other = random_hull(&mut r, 6, true);
        let (d2, _) = plain(&flat, &other, &pose);
        check_contract(&d2, 1e-8);
        let (pf, po) = (Poly::of_hull(&flat), Poly::of_hull(&other).moved(&pose));
        if depth_oracle(&pf, &po) < 0.0 {
            let tri = triangle_oracle(&pf, &po);
            assert!((d2.distance - tri).abs() < 1e-8, "{} vs {tri}", d2.distance);
        } else {
            assert!(d2.distance <= 1e-8, "{d2:?}");
        }
    }
    println!("flat: {apart} apart, {deep} penetrating");
    assert!(apart > 100 && deep > 100);
}

#[test]
fn identical_boxes_slightly_offset_match_the_sat_depth() {
    let mut r = rng(13);
    for i in 0..1000 {
        let c = random_box(&mut r, 0.2, 1.0);
        let small = 10f64.powi(-(i % 7) - 1);
        let mut pose = Isometry::from_translation(point_in_cube(&mut r, small));
        if i % 2 == 0 {
            let q = DQuat::from_axis_angle(rotation(&mut r) * DVec3::X, small * 0.1);
            pose = Isometry::new(proxima::math::DMat3::from_quat(q), pose.translation);
        }
        let (d, out) = plain(&c, &c, &pose);
        check_contract(&d, 1e-9);
        let pc = Poly::of_box(&c);
        let want = depth_oracle(&pc, &pc.moved(&pose));
        assert!(
            (-d.distance - want).abs() < 1e-9,
            "offset {}: {} vs {want} ({out:?})",
            pose.translation,
            -d.distance
        );
    }
}

#[test]
fn boxes_touching_face_to_face_give_zero_without_nan() {
    let mut r = rng(14);
    for _ in 0..1000 {
        let (ca, cb) = (random_box(&mut r, 0.1, 1.0), random_box(&mut r, 0.1, 1.0));
        let axis = r.random_range(0..3);
        let sign = if r.random::<bool>() { 1.0 } else { -1.0 };
        let mut t = point_in_cube(&mut r, 0.05);
        t[axis] = sign * (ca.half_extents[axis] + cb.half_extents[axis]);
        let mut spin = DVec3::ZERO;
        spin[axis] = 1.0;
        let angle = if r.random::<bool>() {
            0.0
        } else {
            r.random_range(-3.0..3.0)
        };
        let q = DQuat::from_axis_angle(spin, angle);
        let pose = Pose::new(t, q).to_isometry();
        let (d, out) = plain(&ca, &cb, &pose);
        check_contract(&d, 1e-12);
        assert!(d.distance.abs() < 1e-12, "{d:?} {out:?}");
        assert!(out.gjk != GjkOutcome::DidNotConverge);
    }
}

/// Membership of a point in a cylinder or cone (local frame), to `tol`.
fn in_cylinder(c: &Cylinder, p: DVec3, tol: f64) -> bool {
    p.truncate().length() <= c.radius + tol && p.z.abs() <= c.half_height + tol
}

fn in_cone(c: &Cone, p: DVec3, tol: f64) -> bool {
    let h = c.half_height;
    let allowed = c.radius * (h - p.z) / (2.0 * h);
    p.z.abs() <= h + tol && p.truncate().length() <= allowed + tol
}

fn sample_directions(r: &mut TestRng, n: usize) -> Vec<DVec3> {
    (0..n).map(|_| rotation(r) * DVec3::Z).collect()
}

#[test]
fn cylinders_and_cones_agree_with_membership_and_sampled_support_functions() {
    let mut r = rng(15);
    let dirs = sample_directions(&mut r, 2000);
    let (mut apart, mut deep, mut fallbacks, mut stalled) = (0, 0, 0, 0);
    for i in 0..2000 {
        let cyl = Cylinder::new(r.random_range(0.2..1.0), r.random_range(0.2..1.0));
        let cone = Cone::new(r.random_range(0.2..1.0), r.random_range(0.2..1.0));
        let pose = isometry(&mut r, 1.8);
        let (d, out) = plain(&cyl, &cone, &pose);
        fallbacks += usize::from(matches!(
            out.epa,
            Some(EpaOutcome::Fallback | EpaOutcome::RoundingLimited)
        ));
        stalled += usize::from(out.gjk == GjkOutcome::DidNotConverge);
        check_contract(&d, 1e-7);
        let tol = 1e-6;
        let ov = |n: DVec3| {
            cyl.support(n).dot(n)
                + pose
                    .transform_point(cone.support(pose.inverse_transform_vector(-n)))
                    .dot(-n)
        };
        assert!(
            in_cylinder(&cyl, d.point_a, tol),
            "{i}: {d:?} {cyl:?} {out:?}"
        );
        assert!(
            in_cone(&cone, pose.inverse_transform_point(d.point_b), tol),
            "{i}: {d:?}"
        );
        // Along the normal, the overlap is −distance (the normal certifies the answer).
        assert!(
            (ov(d.normal) + d.distance).abs() < 1e-6,
            "{} vs {}",
            ov(d.normal),
            d.distance
        );
        // No sampled direction does better.
        let best = dirs.iter().map(|&n| ov(n)).fold(f64::INFINITY, f64::min);
        assert!(
            -d.distance <= best + tol,
            "{out:?} {} vs sampled {best}",
            -d.distance
        );
        if d.distance > 0.0 {
            apart += 1;
        } else {
            deep += 1;
        }
    }
    println!(
        "curved: {apart} apart, {deep} penetrating, {fallbacks} EPA fallbacks, {stalled} GJK at the cap"
    );
    assert!(apart > 300 && deep > 300);
    assert!(fallbacks * 50 < deep, "{fallbacks} fallbacks");
}

#[test]
fn answers_are_invariant_under_swap_sign_of_q_distance_from_origin_and_scale() {
    let mut r = rng(16);
    let (mut apart, mut deep) = (0, 0);
    for i in 0..3000 {
        let pts_a: Vec<DVec3> = (0..12).map(|_| point_in_cube(&mut r, 1.0)).collect();
        let pts_b: Vec<DVec3> = (0..12).map(|_| point_in_cube(&mut r, 0.7)).collect();
        let (qa, qb) = (rotation(&mut r), rotation(&mut r));
        let (ta, tb) = (point_in_cube(&mut r, 1.0), point_in_cube(&mut r, 1.0));
        let reference = {
            let ha = ConvexPolyhedron::try_from_points(&pts_a).unwrap();
            let hb = ConvexPolyhedron::try_from_points(&pts_b).unwrap();
            let pose = Pose::relative(&Pose::new(ta, qa), &Pose::new(tb, qb)).to_isometry();
            let (d, _) = plain(&ha, &hb, &pose);
            // Swapped.
            let (e, _) = plain(&hb, &ha, &pose.inverse());
            assert!((d.distance - e.distance).abs() < 1e-9, "{d:?} {e:?}");
            assert!(
                (d.normal + pose.transform_vector(e.normal)).length() < 1e-6
                    || d.distance.abs() < 1e-9
            );
            // −q.
            let pose_neg = Pose::relative(&Pose::new(ta, -qa), &Pose::new(tb, -qb)).to_isometry();
            let (f, _) = plain(&ha, &hb, &pose_neg);
            assert!((d.distance - f.distance).abs() < 1e-12);
            d.distance
        };
        if reference > 0.0 {
            apart += 1
        } else {
            deep += 1
        }
        let scale = [1e-3, 1e-1, 10.0, 1e3][i % 4];
        let far = [1e3, 1e5][i % 2] * rotation(&mut r).mul_vec3(DVec3::X);
        let ha = ConvexPolyhedron::try_from_points(
            &pts_a.iter().map(|&p| p * scale).collect::<Vec<_>>(),
        )
        .unwrap();
        let hb = ConvexPolyhedron::try_from_points(
            &pts_b.iter().map(|&p| p * scale).collect::<Vec<_>>(),
        )
        .unwrap();
        let pose = Pose::relative(
            &Pose::new(far + ta * scale, qa),
            &Pose::new(far + tb * scale, qb),
        )
        .to_isometry();
        let (d, _) = plain(&ha, &hb, &pose);
        // Rounding of the world poses far away: ~1e-16 × 1e5 m.
        let tol = 1e-9 * scale + 1e-10;
        assert!(
            (d.distance - reference * scale).abs() <= tol,
            "scale {scale}: {} vs {}",
            d.distance,
            reference * scale
        );
    }
    assert!(apart > 100 && deep > 100, "{apart} {deep}");
}

#[test]
fn warm_start_and_acceleration_agree_with_cold_plain_gjk_on_hulls() {
    let mut r = rng(17);
    let ha = random_hull(&mut r, 80, false);
    let hb = random_hull(&mut r, 40, false);
    let fast = GjkParams {
        accelerated: true,
        ..GjkParams::default()
    };
    let mut cache = GjkCache::default();
    let mut pose = isometry(&mut r, 2.0);
    let (mut apart, mut deep) = (0, 0);
    let mut iterations = [0u32; 3];
    for _ in 0..2000 {
        // A slowly moving pair, as between frames.
        let step = Pose::new(
            point_in_cube(&mut r, 0.05),
            DQuat::from_axis_angle(DVec3::Z, 0.02),
        );
        pose = pose.compose(&step.to_isometry());
        if pose.translation.length() > 2.5 {
            pose.translation *= 0.5;
        }
        let cold = gjk_distance(
            &ha,
            &hb,
            &pose,
            &GjkParams::default(),
            &mut GjkCache::default(),
        );
        let warm = gjk_distance(&ha, &hb, &pose, &GjkParams::default(), &mut cache);
        let acc = gjk_distance(&ha, &hb, &pose, &fast, &mut GjkCache::default());
        iterations[0] += cold.iterations;
        iterations[1] += warm.iterations;
        iterations[2] += acc.iterations;
        for other in [warm, acc] {
            assert_eq!(
                cold.distance > 0.0,
                other.distance > 0.0,
                "{cold:?} {other:?}"
            );
            assert!((cold.distance - other.distance).abs() < 1e-9);
        }
        let (d1, _) = plain(&ha, &hb, &pose);
        let (d2, _) = query(&Rounded::plain(&ha), &Rounded::plain(&hb), &pose, &fast);
        assert!((d1.distance - d2.distance).abs() < 1e-9, "{d1:?} {d2:?}");
        if cold.distance > 0.0 {
            apart += 1
        } else {
            deep += 1
        }
    }
    println!(
        "GJK iterations over 2000 frames: cold {}, warm {}, accelerated {}",
        iterations[0], iterations[1], iterations[2]
    );
    assert!(apart > 100 && deep > 100, "{apart} {deep}");
}

/// Checks a rounded pair (polytope cores) against the oracles on the cores.
fn check_rounded(
    a: &Poly,
    ra: f64,
    b_local: &Poly,
    rb: f64,
    d: &ShapeDistance,
    pose: &Isometry,
) -> bool {
    let b = b_local.moved(pose);
    check_contract(d, 1e-9);
    let depth = depth_oracle(a, &b);
    let core = if depth < 0.0 {
        triangle_oracle(a, &b)
    } else {
        -depth
    };
    let want = core - ra - rb;
    assert!(
        (d.distance - want).abs() < 1e-9,
        "{} vs {want} (core {core})",
        d.distance
    );
    // Moving B by −distance along the normal makes the cores' gap ra + rb: the normal
    // realises the answer.
    assert!((-overlap(a, &b, d.normal) - core).abs() < 1e-9 || core > 0.0);
    want > 0.0
}

#[test]
fn capsules_against_boxes_and_spheres_against_hulls_match_the_core_oracles() {
    let mut r = rng(18);
    let (mut apart, mut deep) = (0, 0);
    for i in 0..2000 {
        let pose = isometry(&mut r, 1.2);
        if i % 2 == 0 {
            let cube = random_box(&mut r, 0.1, 0.8);
            let cap = Capsule::new(r.random_range(0.0..0.8), r.random_range(0.05..0.4));
            let seg = capsule_core(&cap);
            let (d, _) = query(
                &Rounded::plain(&cube),
                &Rounded::new(&seg, cap.radius),
                &pose,
                &GjkParams::default(),
            );
            if check_rounded(
                &Poly::of_box(&cube),
                0.0,
                &Poly::of_segment(&seg),
                cap.radius,
                &d,
                &pose,
            ) {
                apart += 1;
            } else {
                deep += 1;
            }
        } else {
            let hull = random_hull(&mut r, 8 + i % 24, false);
            let ball = Sphere::new(r.random_range(0.05..0.5));
            let (d, _) = query(
                &Rounded::sphere(&ball),
                &Rounded::plain(&hull),
                &pose,
                &GjkParams::default(),
            );
            if check_rounded(
                &Poly::of_point(DVec3::ZERO),
                ball.radius,
                &Poly::of_hull(&hull),
                0.0,
                &d,
                &pose,
            ) {
                apart += 1;
            } else {
                deep += 1;
            }
        }
    }
    println!("rounded: {apart} apart, {deep} penetrating");
    assert!(apart > 300 && deep > 300);
    let _ = &POINT;
}

#[test]
fn warmed_up_queries_allocate_nothing() {
    let mut r = rng(19);
    let hulls: Vec<ConvexPolyhedron> = (0..8)
        .map(|i| random_hull(&mut r, 10 + 20 * i, false))
        .collect();
    let poses: Vec<Isometry> = (0..500).map(|_| isometry(&mut r, 1.5)).collect();
    let mut ws = EpaWorkspace::new();
    let mut cache = GjkCache::default();
    let params = GjkParams::default();
    let before = allocations();
    let mut deep = 0;
    for (k, pose) in poses.iter().enumerate() {
        let (a, b) = (&hulls[k % 8], &hulls[(k / 8) % 8]);
        let (d, _) = signed_distance_convex(
            &Rounded::plain(a),
            &Rounded::plain(b),
            pose,
            &params,
            &mut cache,
            &mut ws,
        );
        deep += usize::from(d.distance < 0.0);
    }
    assert_eq!(allocations() - before, 0);
    assert!(deep > 50, "{deep}");
}

#[test]
fn grazing_pairs_moved_along_the_normal_to_tiny_gaps_keep_exact_distances() {
    let mut r = rng(20);
    let (mut apart, mut deep) = (0, 0);
    for i in 0..3000 {
        let (ha, hb) = (
            random_hull(&mut r, 8 + i % 16, false),
            random_box(&mut r, 0.1, 0.9),
        );
        let pose = isometry(&mut r, 3.0);
        let (d, _) = plain(&ha, &hb, &pose);
        if d.distance <= 1e-3 {
            continue;
        }
        let g = [1e-3, 1e-6, 1e-9, 1e-12, 0.0, -1e-12, -1e-9, -1e-6, -1e-3][i % 9];
        let moved = Isometry::new(
            pose.rotation,
            pose.translation - d.normal * (d.distance - g),
        );
        let (e, out) = plain(&ha, &hb, &moved);
        check_contract(&e, 1e-9);
        let tol = 1e-13 + 1e-9 * g.abs();
        if g >= 0.0 {
            // The old separating plane still separates, by exactly g.
            assert!(
                (e.distance - g).abs() <= tol,
                "gap {g}: {} ({out:?})",
                e.distance
            );
            apart += 1;
        } else {
            // Pushed |g| past touching along n: the depth is at most |g|.
            assert!(
                e.distance <= tol && e.distance >= g - tol,
                "gap {g}: {} ({out:?})",
                e.distance
            );
            deep += 1;
        }
    }
    assert!(apart > 500 && deep > 500, "{apart} {deep}");
}

mod parry_cross_check {
    //! parry3d-f64 0.31 on the same pairs. Where parry and we differ by more than 1e-6, the
    //! oracle must side with us; the disagreements are counted and printed.
    use super::*;
    use parry3d_f64::math::{Pose as ParryPose, Rotation as ParryRotation, Vector as ParryVector};
    use parry3d_f64::query::contact;
    use parry3d_f64::shape::{
        ConvexPolyhedron as ParryHull, Cuboid as ParryCuboid, Cylinder as ParryCylinder, Shape,
    };

    fn v(p: DVec3) -> ParryVector {
        ParryVector::new(p.x, p.y, p.z)
    }

    fn parry_pose(p: &Pose) -> ParryPose {
        let q = p.rotation;
        ParryPose::from_parts(v(p.position), ParryRotation::from_xyzw(q.x, q.y, q.z, q.w))
    }

    /// parry's signed distance (a large prediction so separated pairs answer too).
    fn parry_distance(a: &dyn Shape, b: &dyn Shape, pose_ab: &Pose) -> f64 {
        contact(&ParryPose::IDENTITY, a, &parry_pose(pose_ab), b, 100.0)
            .expect("supported pair")
            .expect("within prediction")
            .dist
    }

    #[test]
    fn parry_and_proxima_disagree_only_where_the_oracle_sides_with_proxima() {
        let mut r = rng(21);
        let (mut cases, mut parry_wrong) = (0, 0);
        let mut worst: f64 = 0.0;
        for i in 0..1500 {
            let pose = support::pose(&mut r, 1.6);
            let iso = pose.to_isometry();
            let (ours, parry, pa, pb) = if i % 2 == 0 {
                let (ca, cb) = (random_box(&mut r, 0.1, 1.0), random_box(&mut r, 0.1, 1.0));
                let p = parry_distance(
                    &ParryCuboid::new(v(ca.half_extents)),
                    &ParryCuboid::new(v(cb.half_extents)),
                    &pose,
                );
                (
                    plain(&ca, &cb, &iso).0,
                    p,
                    Poly::of_box(&ca),
                    Poly::of_box(&cb),
                )
            } else {
                let (ha, hb) = (
                    random_hull(&mut r, 20, false),
                    random_hull(&mut r, 12, false),
                );
                let to_parry = |h: &ConvexPolyhedron| {
                    let pts: Vec<ParryVector> = h.vertices().iter().map(|&p| v(p)).collect();
                    ParryHull::from_convex_hull(&pts).expect("parry hull")
                };
                let p = parry_distance(&to_parry(&ha), &to_parry(&hb), &pose);
                (
                    plain(&ha, &hb, &iso).0,
                    p,
                    Poly::of_hull(&ha),
                    Poly::of_hull(&hb),
                )
            };
            cases += 1;
            let b = pb.moved(&iso);
            let depth = depth_oracle(&pa, &b);
            let truth = if depth < 0.0 {
                triangle_oracle(&pa, &b)
            } else {
                -depth
            };
            assert!(
                (ours.distance - truth).abs() < 1e-8,
                "{} vs {truth}",
                ours.distance
            );
            if (parry - truth).abs() > 1e-6 {
                parry_wrong += 1;
                worst = worst.max((parry - truth).abs());
            }
        }
        println!(
            "parry off the oracle by > 1e-6 in {parry_wrong} of {cases} polytope pairs (worst {worst:e})"
        );
    }

    #[test]
    fn parry_cylinders_agree_with_proxima_within_the_sampled_bounds() {
        let mut r = rng(22);
        // parry's cylinders stand on Y, ours on Z: B's parry pose is turned by X(−90°).
        let y_to_z = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let dirs = sample_directions(&mut r, 2000);
        let (mut cases, mut differ, mut parry_certainly_wrong) = (0, 0, 0);
        let mut worst: f64 = 0.0;
        for _ in 0..1000 {
            let (ca, cb) = (
                Cylinder::new(r.random_range(0.2..1.0), r.random_range(0.2..1.0)),
                Cylinder::new(r.random_range(0.2..1.0), r.random_range(0.2..1.0)),
            );
            let pose = support::pose(&mut r, 1.8);
            let iso = pose.to_isometry();
            let ours = plain(&ca, &cb, &iso).0;
            let pa = Pose::new(DVec3::ZERO, y_to_z);
            let pb = Pose::new(pose.position, pose.rotation * y_to_z);
            let parry = contact(
                &parry_pose(&pa),
                &ParryCylinder::new(ca.half_height, ca.radius),
                &parry_pose(&pb),
                &ParryCylinder::new(cb.half_height, cb.radius),
                100.0,
            )
            .expect("supported")
            .expect("within prediction")
            .dist;
            cases += 1;
            // Sampled bound: −distance ≤ min over sampled n of the overlap along n.
            let ov = |n: DVec3| {
                ca.support(n).dot(n)
                    + iso
                        .transform_point(cb.support(iso.inverse_transform_vector(-n)))
                        .dot(-n)
            };
            let best = dirs.iter().map(|&n| ov(n)).fold(f64::INFINITY, f64::min);
            assert!(-ours.distance <= best + 1e-6);
            // Certificates: the signed distance is ≥ −overlap(n) for every n (so ≥ −ov of
            // our normal), and ≤ |point_b − point_a| when apart with witnesses in the shapes.
            let lower = -ov(ours.normal);
            assert!(ours.distance >= lower - 1e-9);
            if (parry - ours.distance).abs() > 1e-6 {
                differ += 1;
                worst = worst.max((parry - ours.distance).abs());
                let upper = (ours.distance > 0.0
                    && in_cylinder(&ca, ours.point_a, 1e-9)
                    && in_cylinder(&cb, iso.inverse_transform_point(ours.point_b), 1e-9))
                .then_some(ours.distance);
                if parry < lower - 1e-9 || upper.is_some_and(|u| parry > u + 1e-9) {
                    parry_certainly_wrong += 1;
                }
            }
        }
        println!(
            "parry differs from Proxima by > 1e-6 on {differ} of {cases} cylinder pairs \
             (worst {worst:e}); in {parry_certainly_wrong} parry breaks a certified bound"
        );
    }
}

#[test]
fn needle_and_plate_boxes_of_mixed_sizes_match_the_oracles() {
    let mut r = rng(23);
    let (mut apart, mut deep) = (0, 0);
    for i in 0..3000 {
        let mut size = || 10f64.powf(r.random_range(-4.0..1.0));
        let (ca, cb) = (
            Cuboid::new(DVec3::new(size(), size(), size())),
            Cuboid::new(DVec3::new(size(), size(), size())),
        );
        let reach = ca.half_extents.length() + cb.half_extents.length();
        let pose = isometry(&mut r, [0.8, 0.2][i % 2] * reach);
        let (d, out) = plain(&ca, &cb, &pose);
        let tol = 1e-10 * reach;
        if check_polytopes(&Poly::of_box(&ca), &Poly::of_box(&cb), &d, &pose, tol) {
            apart += 1;
        } else {
            deep += 1;
            assert_eq!(out.epa, Some(EpaOutcome::Converged), "{out:?}");
        }
    }
    println!("mixed boxes: {apart} apart, {deep} penetrating");
    assert!(apart > 500 && deep > 300);
}

/// Hulls of 512 and 4,096 points on a sphere (the sizes where parry 0.31's EPA depths
/// differed from ours by up to 8.7 cm in `benches/narrow_phase.rs`): the depth must separate
/// the shapes when B moves by it along the normal, and the depth known to lie under the true
/// one (the exact depth, or a bounded answer's lower bound) must be no deeper than the
/// overlap along any of 2,000 sampled directions (each an upper bound of the true depth).
/// Nearly concentric poses fill EPA's polytope before its tolerance: those answers must be
/// bounded, not exact.
#[test]
fn large_hull_depths_separate_and_their_lower_bounds_are_no_deeper_than_any_sampled_direction() {
    let mut rng = rng(2_626);
    let mut epa = EpaWorkspace::new();
    for n in [512usize, 4096] {
        let cloud = |rng: &mut TestRng| -> Vec<DVec3> {
            (0..n).map(|_| rotation(rng) * DVec3::Z).collect()
        };
        let (a, b) = (
            ConvexPolyhedron::try_from_points(&cloud(&mut rng)).unwrap(),
            ConvexPolyhedron::try_from_points(&cloud(&mut rng)).unwrap(),
        );
        let (ra, rb) = (Rounded::plain(&a), Rounded::plain(&b));
        let (mut penetrating, mut apart, mut bounded) = (0, 0, 0);
        let mut worst_gap = 0.0_f64;
        for case in 0..240 {
            // Every other pose nearly concentric: the deepest overlaps, where EPA's polytope
            // can fill up before the tolerance.
            let reach = if case % 2 == 0 { 1.5 } else { 0.1 };
            let pose = Pose::new(point_in_cube(&mut rng, reach), rotation(&mut rng));
            let iso = pose.to_isometry();
            let params = GjkParams::default();
            let (d, _) =
                signed_distance_convex(&ra, &rb, &iso, &params, &mut GjkCache::default(), &mut epa);
            if d.distance >= 0.0 {
                apart += 1;
                continue;
            }
            penetrating += 1;
            let depth = -d.distance;
            // The depth known to lie under the true one: the polytope's, when EPA ran out of
            // room short of its tolerance (then the answer is bounded, not exact).
            let (within, _) = signed_distance_convex_within(
                &ra,
                &rb,
                &iso,
                &params,
                &mut GjkCache::default(),
                &mut epa,
                &mut WorkClock::default(),
                f64::INFINITY,
            );
            let depth_lower = match within {
                Reached::Exact(e) => {
                    assert_eq!(e.distance, d.distance, "n {n} case {case}");
                    depth
                }
                Reached::Bounded(bound) | Reached::Resolved(bound) => {
                    bounded += 1;
                    assert_eq!(bound.lower, d.distance, "n {n} case {case}");
                    worst_gap = worst_gap.max((bound.upper - bound.lower) / depth);
                    -bound.upper
                }
            };
            let moved = Pose::new(pose.position + d.normal * (depth + 1e-9), pose.rotation);
            let (after, _) = signed_distance_convex(
                &ra,
                &rb,
                &moved.to_isometry(),
                &params,
                &mut GjkCache::default(),
                &mut epa,
            );
            assert!(
                after.distance >= -1e-9,
                "n {n} case {case}: {}",
                after.distance
            );
            let mut min_overlap = f64::INFINITY;
            for _ in 0..2_000 {
                let u = rotation(&mut rng) * DVec3::Z;
                let reach_a = a.support(u).dot(u);
                let reach_b = iso
                    .transform_point(b.support(iso.inverse_transform_vector(-u)))
                    .dot(u);
                min_overlap = min_overlap.min(reach_a - reach_b);
            }
            assert!(
                depth_lower <= min_overlap + 1e-9,
                "n {n} case {case}: lower bound {depth_lower} above a sampled overlap \
                 {min_overlap}"
            );
        }
        println!(
            "n {n}: {penetrating} penetrating ({bounded} bounded, widest gap {:.2} % of the \
             depth), {apart} apart",
            100.0 * worst_gap
        );
        assert!(
            penetrating > 50 && apart > 5 && bounded > 5,
            "n {n}: {penetrating} / {apart} / {bounded}"
        );
    }
}

/// What a certificate answered, once [`check_certificate`] has checked it.
enum Certified {
    Overlapping,
    Apart(ShapeDistance),
    Beyond,
    Unknown,
}

/// Checks a certificate's answer for `a` and `b` placed by `pose` against GJK/EPA in f64 on
/// the same pair: an exact answer has the same signed distance (1e-9 relative) and
/// consistent witnesses, and when overlapping B moved by `depth + ε` along its normal is
/// apart, by `depth − ε` still overlapping; a lower bound beyond `limit` holds GJK's
/// distance.
fn check_certificate<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    certified: proxima::narrow::pairs::FaceCertificate,
    a: &A,
    b: &B,
    pose: &Isometry,
    limit: f64,
    label: &str,
) -> Certified {
    use proxima::narrow::pairs::FaceCertificate;
    let (g, _) = plain(a, b, pose);
    match certified {
        FaceCertificate::Exact(d) => {
            check_contract(&d, 1e-12);
            let tol = 1e-9 * d.distance.abs() + 1e-12;
            assert!(
                (d.distance - g.distance).abs() <= tol,
                "{label}: certified {} vs GJK/EPA {}",
                d.distance,
                g.distance
            );
            if d.distance >= 0.0 {
                return Certified::Apart(d);
            }
            let depth = -d.distance;
            let eps = 1e-9 * (1.0 + depth);
            for (shift, apart) in [(depth + eps, true), (depth - eps, false)] {
                let moved = Isometry {
                    translation: pose.translation + d.normal * shift,
                    ..*pose
                };
                let (m, _) = plain(a, b, &moved);
                assert_eq!(
                    m.distance > 0.0,
                    apart,
                    "{label}: moved by {shift} of depth {depth}: {}",
                    m.distance
                );
            }
            Certified::Overlapping
        }
        FaceCertificate::Beyond(d) => {
            assert!(d.distance > limit, "{label}: {d:?}");
            assert!(
                d.distance <= g.distance + 1e-12,
                "{label}: bound {} above GJK's {}",
                d.distance,
                g.distance
            );
            Certified::Beyond
        }
        FaceCertificate::Unknown => Certified::Unknown,
    }
}

/// The box face certificate (`pairs::face_distance_cuboid_convex`, the dispatcher's route
/// for a box against a cylinder, cone or hull) against GJK/EPA in f64 on the same pair
/// (depths, and distances over a face), and the metamorphic check: B moved by `depth + ε`
/// along the certified normal is apart, by `depth − ε` it still overlaps. Its lower bounds
/// beyond the limit hold GJK's distance. Poses put B across a random face of the box, so
/// every outcome occurs often.
#[test]
fn the_box_face_certificate_matches_epa_and_moves_apart_by_its_depth() {
    use proxima::narrow::pairs::face_distance_cuboid_convex;
    let mut r = rng(31);
    let limit = 0.02;
    let (mut exact, mut exact_apart, mut beyond, mut unknown) = ([0_usize; 3], 0, 0, 0);
    for case in 0..6000 {
        let a = random_box(&mut r, 0.05, 0.6);
        let half = a.half_extents;
        let kind = case % 3;
        let cylinder = Cylinder::new(r.random_range(0.02..0.3), r.random_range(0.02..0.3));
        let cone = Cone::new(r.random_range(0.02..0.3), r.random_range(0.02..0.3));
        // A hull of the pile's size (2–30 cm).
        let cloud: Vec<DVec3> = (0..20 + case % 40)
            .map(|_| point_in_cube(&mut r, 0.15) * DVec3::new(1.0, 0.7, 0.4))
            .collect();
        let hull = ConvexPolyhedron::try_from_points(&cloud).expect("finite cloud");
        let b: &dyn SupportMap = match kind {
            0 => &cylinder,
            1 => &cone,
            _ => &hull,
        };
        let q = rotation(&mut r);
        let size = b.support(q.inverse() * DVec3::Z).length();
        let k = r.random_range(0..3_usize);
        let sign = if r.random() { 1.0 } else { -1.0 };
        let mut t = DVec3::ZERO;
        for j in 0..3 {
            t[j] = half[j] * r.random_range(-1.2..1.2);
        }
        t[k] = sign * (half[k] + size * r.random_range(-0.3..1.3));
        let pose = Isometry {
            rotation: proxima::math::DMat3::from_quat(q),
            translation: t,
        };
        let certified = face_distance_cuboid_convex(&a, b, &pose, limit);
        match check_certificate(certified, &a, b, &pose, limit, &format!("case {case}")) {
            Certified::Overlapping => exact[kind] += 1,
            Certified::Apart(_) => exact_apart += 1,
            Certified::Beyond => beyond += 1,
            Certified::Unknown => unknown += 1,
        }
    }
    println!(
        "certified overlapping {exact:?} (cylinder, cone, hull), apart {exact_apart}, \
         beyond {beyond}, unknown {unknown}"
    );
    assert!(
        exact.iter().all(|&n| n > 200) && exact_apart > 500 && beyond > 300 && unknown > 500,
        "{exact:?} {exact_apart} {beyond} {unknown}"
    );
}

/// A rotation of quarter turns about X and Y, then any turn about Z: a body's faces, edges
/// and axes parallel or square to the cylinder's, as bodies resting in a pile are.
fn resting_rotation(r: &mut TestRng) -> DQuat {
    let quarter = |k: u32| f64::from(k) * std::f64::consts::FRAC_PI_2;
    DQuat::from_rotation_z(r.random_range(0.0..std::f64::consts::TAU))
        * DQuat::from_rotation_x(quarter(r.random_range(0..4)))
        * DQuat::from_rotation_y(quarter(r.random_range(0..4)))
}

/// The cylinder's certificate (`pairs::certified_distance_cylinder_convex`, the
/// dispatcher's route for a cylinder against a box, hull, cylinder or capsule before GJK)
/// against GJK/EPA in f64 on the same pair, with the metamorphic check of the box
/// certificate's test: B moved by `depth + ε` along the certified normal is apart, by
/// `depth − ε` it still overlaps. Apart answers have their witnesses on the cylinder, and
/// lower bounds beyond the limit hold GJK's distance. B is placed across a cap or beside
/// the side, half the time turned by quarter turns only (faces, edges and axes parallel to
/// the cylinder's, as bodies resting in a pile are) and else at random, so every outcome
/// occurs for every kind of B.
#[test]
fn the_cylinder_certificate_matches_epa_and_moves_apart_by_its_depth() {
    use proxima::narrow::pairs::certified_distance_cylinder_convex;
    let mut r = rng(37);
    let limit = 0.02;
    let kinds = ["box", "hull", "cylinder", "segment"];
    let (mut exact, mut exact_apart, mut beyond, mut unknown) = ([0_usize; 4], [0_usize; 4], 0, 0);
    for case in 0..8000 {
        let a = Cylinder::new(r.random_range(0.01..0.2), r.random_range(0.01..0.2));
        let kind = case % 4;
        let cuboid = random_box(&mut r, 0.01, 0.15);
        let cloud: Vec<DVec3> = (0..20 + case % 40)
            .map(|_| point_in_cube(&mut r, 0.1) * DVec3::new(1.0, 0.7, 0.4))
            .collect();
        let hull = ConvexPolyhedron::try_from_points(&cloud).expect("finite cloud");
        let cylinder = Cylinder::new(r.random_range(0.01..0.2), r.random_range(0.01..0.2));
        let half = r.random_range(0.01..0.2);
        let segment = Segment::new(DVec3::new(0.0, 0.0, -half), DVec3::new(0.0, 0.0, half));
        let b: &dyn SupportMap = match kind {
            0 => &cuboid,
            1 => &hull,
            2 => &cylinder,
            _ => &segment,
        };
        let q = if r.random() {
            resting_rotation(&mut r)
        } else {
            rotation(&mut r)
        };
        let (along, across) = if r.random() {
            (DVec3::Z, DVec3::X)
        } else {
            let angle = r.random_range(0.0..std::f64::consts::TAU);
            (DVec3::new(angle.cos(), angle.sin(), 0.0), DVec3::Z)
        };
        let reach = if along.z == 0.0 {
            a.radius
        } else {
            a.half_height
        };
        let size = b.support(q.inverse() * -along).dot(-along);
        let t = along * (reach + size * r.random_range(-0.3..1.3))
            + across * a.radius.max(a.half_height) * r.random_range(-1.2..1.2);
        let pose = Isometry {
            rotation: proxima::math::DMat3::from_quat(q),
            translation: t,
        };
        let certified = certified_distance_cylinder_convex(&a, b, &pose, 1e-10, limit);
        let label = format!("case {case} ({})", kinds[kind]);
        match check_certificate(certified, &a, b, &pose, limit, &label) {
            Certified::Overlapping => exact[kind] += 1,
            Certified::Apart(d) => {
                assert!(in_cylinder(&a, d.point_a, 1e-12), "{label}: {d:?}");
                exact_apart[kind] += 1;
            }
            Certified::Beyond => beyond += 1,
            Certified::Unknown => unknown += 1,
        }
    }
    println!(
        "certified overlapping {exact:?}, apart {exact_apart:?} ({kinds:?}), beyond {beyond}, \
         unknown {unknown}"
    );
    assert!(
        exact.iter().chain(&exact_apart).all(|&n| n > 50) && beyond > 200 && unknown > 500,
        "{exact:?} {exact_apart:?} {beyond} {unknown}"
    );
}

/// The capsule–cylinder search (`pairs::distance_capsule_cylinder`) against two oracles
/// over 6,000 seeded poses around, across and inside the cylinder (half of them turned by
/// quarter turns, as bodies resting in a pile are):
/// - brute force in f64: a golden-section search of the core point's distance to the solid
///   cylinder (its closed form), a convex function of the point's place on the core, to
///   1e-10 relative;
/// - GJK/EPA on the same pair (the capsule as its core rounded by its radius), to 1e-9 of
///   the core's distance plus 1e-11 m (GJK's own stopping test).
///
/// Answered pairs have consistent witnesses, `point_b` in the cylinder and `point_a` on the
/// capsule (to the search's tolerance: its core point's slope is 0 only to it); the cases
/// left to the caller are exactly those whose core reaches the cylinder (to 1e-9 m).
/// Apart, overlapping and left cases all occur.
#[test]
fn the_capsule_cylinder_search_matches_brute_force_and_gjk() {
    use proxima::narrow::pairs::distance_capsule_cylinder;
    let mut r = rng(41);
    let (mut apart, mut overlapping, mut left) = (0, 0, 0);
    for case in 0..6000 {
        let cylinder = Cylinder::new(r.random_range(0.01..0.2), r.random_range(0.01..0.2));
        let capsule = Capsule::new(r.random_range(0.0..0.2), r.random_range(0.001..0.05));
        let q = if case % 2 == 0 {
            resting_rotation(&mut r)
        } else {
            rotation(&mut r)
        };
        let reach = DVec3::new(cylinder.radius, cylinder.radius, cylinder.half_height)
            + DVec3::splat(capsule.half_height + capsule.radius);
        let centre = point_in_cube(&mut r, 1.0) * reach;
        // The capsule (A) at `centre` of the cylinder's frame, turned by `q`: B in A's frame.
        let capsule_in_b = Isometry {
            rotation: proxima::math::DMat3::from_quat(q),
            translation: centre,
        };
        let pose = capsule_in_b.inverse();
        let core = capsule.segment();
        let (p0, p1) = (
            capsule_in_b.transform_point(core.a),
            capsule_in_b.transform_point(core.b),
        );
        // Golden-section search of the convex distance along the core, to rounding.
        let f = |t: f64| {
            let x = p0.lerp(p1, t);
            (x - cylinder.closest_point(x)).length()
        };
        let brute = support::convex_minimum_on_unit_interval(f);
        let Some(d) = distance_capsule_cylinder(&capsule, &cylinder, &pose, 1e-10) else {
            assert!(
                brute <= 1e-9,
                "case {case}: left, but the core is {brute} away"
            );
            left += 1;
            continue;
        };
        check_contract(&d, 1e-12);
        let core_distance = d.distance + capsule.radius;
        assert!(
            (core_distance - brute).abs() <= 1e-10 * brute + 1e-13,
            "case {case}: {core_distance} vs brute force {brute}"
        );
        let (g, _) = query(
            &Rounded::new(&core, capsule.radius),
            &Rounded::plain(&cylinder),
            &pose,
            &GjkParams::default(),
        );
        assert!(
            (d.distance - g.distance).abs() <= 1e-9 * core_distance + 1e-11,
            "case {case}: {} vs GJK/EPA {}",
            d.distance,
            g.distance
        );
        assert!(
            in_cylinder(&cylinder, pose.inverse_transform_point(d.point_b), 1e-12),
            "case {case}: {d:?}"
        );
        let (_, _, on_core, _) = core.closest_points(&Segment::new(d.point_a, d.point_a));
        assert!(
            ((d.point_a - on_core).length() - capsule.radius).abs() <= 1e-9 * core_distance + 1e-12,
            "case {case}: {d:?}"
        );
        if d.distance > 0.0 {
            apart += 1;
        } else {
            overlapping += 1;
        }
    }
    println!("apart {apart}, overlapping (radius only) {overlapping}, left to the caller {left}");
    assert!(
        apart > 500 && overlapping > 200 && left > 200,
        "{apart} {overlapping} {left}"
    );
}

/// The sphere–cylinder closed form against GJK/EPA on the same shapes (the sphere as a
/// point rounded by its radius), over 6,000 seeded poses around and inside the cylinder:
/// the same signed distance to 1e-9 relative (where EPA does not converge on the curved
/// side, no deeper than its upper bound); overlapping, moving the cylinder by `depth + ε`
/// along the normal leaves it apart, by `depth − ε` still overlapping.
#[test]
fn the_sphere_cylinder_closed_form_matches_gjk_and_epa() {
    use proxima::narrow::gjk::EpaOutcome;
    use proxima::narrow::pairs::distance_sphere_cylinder;
    let mut r = rng(32);
    let (mut overlapping, mut apart, mut epa_fallbacks, mut bounded_fallbacks) = (0, 0, 0, 0);
    for case in 0..6000 {
        let sphere = Sphere::new(r.random_range(0.005..0.2));
        let cylinder = Cylinder::new(r.random_range(0.01..0.3), r.random_range(0.01..0.3));
        // The sphere's centre in B's frame: around the cylinder, inside it a third of the
        // time; B's rotation random.
        let reach = DVec3::new(cylinder.radius, cylinder.radius, cylinder.half_height)
            + DVec3::splat(sphere.radius);
        let centre = point_in_cube(&mut r, 1.0) * reach * r.random_range(0.3..1.3);
        let rotation = proxima::math::DMat3::from_quat(rotation(&mut r));
        let pose = Isometry {
            rotation,
            translation: -(rotation * centre),
        };
        let d = distance_sphere_cylinder(&sphere, &cylinder, &pose);
        check_contract(&d, 1e-12);
        let (g, outcome) = query(
            &Rounded::new(&POINT, sphere.radius),
            &Rounded::plain(&cylinder),
            &pose,
            &GjkParams::default(),
        );
        let tol = 1e-9 * (1.0 + d.distance.abs());
        if matches!(
            outcome.epa,
            Some(EpaOutcome::Fallback | EpaOutcome::RoundingLimited)
        ) {
            // EPA did not converge on the curved side: its depth is an upper bound, and the
            // moves below decide the depth.
            epa_fallbacks += 1;
            assert!(
                d.distance >= g.distance - tol,
                "case {case}: closed form {} deeper than EPA's upper bound {}",
                d.distance,
                g.distance
            );
            // Short of the tolerance, the answer is not exact: its bounds hold the closed
            // form (to rounding).
            let (reached, _) = signed_distance_convex_within(
                &Rounded::new(&POINT, sphere.radius),
                &Rounded::plain(&cylinder),
                &pose,
                &GjkParams::default(),
                &mut GjkCache::default(),
                &mut EpaWorkspace::new(),
                &mut WorkClock::default(),
                f64::INFINITY,
            );
            let rounding = 1e-15 * (1.0 + d.distance.abs());
            match reached {
                Reached::Exact(e) => assert!(
                    (e.distance - d.distance).abs() <= tol,
                    "case {case}: exact {} vs closed form {}",
                    e.distance,
                    d.distance
                ),
                Reached::Bounded(b) | Reached::Resolved(b) => {
                    bounded_fallbacks += 1;
                    assert!(
                        b.lower <= d.distance + rounding && d.distance <= b.upper + rounding,
                        "case {case}: {b:?} does not hold the closed form {}",
                        d.distance
                    );
                }
            }
        } else {
            assert!(
                (d.distance - g.distance).abs() <= tol,
                "case {case}: closed form {} vs GJK/EPA {} ({outcome:?})",
                d.distance,
                g.distance
            );
        }
        if d.distance > 0.0 {
            apart += 1;
            continue;
        }
        overlapping += 1;
        let depth = -d.distance;
        let eps = 1e-9 * (1.0 + depth);
        for (shift, separated) in [(depth + eps, true), (depth - eps, false)] {
            let moved = Isometry {
                translation: pose.translation + d.normal * shift,
                ..pose
            };
            let (m, _) = query(
                &Rounded::new(&POINT, sphere.radius),
                &Rounded::plain(&cylinder),
                &moved,
                &GjkParams::default(),
            );
            assert_eq!(
                m.distance > 0.0,
                separated,
                "case {case}: moved by {shift} of depth {depth}: {}",
                m.distance
            );
        }
    }
    println!(
        "overlapping {overlapping} (EPA fell back on {epa_fallbacks}, {bounded_fallbacks} of \
         them short of the tolerance), apart {apart}"
    );
    assert!(bounded_fallbacks > 0, "no answer short of the tolerance");
    assert!(
        overlapping > 1000 && apart > 1000 && epa_fallbacks < overlapping / 2,
        "{overlapping} {apart} {epa_fallbacks}"
    );
}
