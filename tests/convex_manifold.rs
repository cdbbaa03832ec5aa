//! Multi-point manifolds of the GJK pairs ([`proxima::narrow::convex_manifold`]) against
//! independent oracles:
//! - analytic resting contacts: a box face down on the same box given as a hull (depths and
//!   the overlap square), a cylinder standing on a box (rim points, one depth), a cylinder
//!   lying on a box (the two ends of its side line);
//! - parallel lines: a cylinder, a capsule or a cone's slant lying along a cylinder's side
//!   touches at the two ends of their overlap, at the analytic depth;
//! - boxes given as hulls of their corners against the closed-form box–box manifold: same
//!   number of points (when it has two or more) and the same deepest depth;
//! - every GJK kind against every convex kind, resting and random poses: the contact
//!   contract of every point, with each shape's own surface function as the on-surface
//!   oracle (hull: its largest plane distance; cylinder, cone, box, sphere, capsule:
//!   closed-form); degenerate shapes (segments, discs, flat hulls); the same count and
//!   deepest depth with A and B swapped; and through the public pipeline far from the
//!   origin.
#[path = "support/mod.rs"]
mod support;

use proxima::geometry::{
    Capsule, Cone, ConvexPolyhedron, Cuboid, Cylinder, Segment, Sphere, SupportMap,
};
use proxima::math::{DMat3, DQuat, DVec3, Isometry};
use proxima::narrow::convex_manifold::{ContactFeatures, manifold_convex_convex};
use proxima::narrow::gjk::{
    EpaWorkspace, GjkCache, GjkParams, POINT, Rounded, signed_distance_convex,
};
use proxima::narrow::{Manifold, ShapeDistance, manifold_cuboid_cuboid};
use rand::Rng;
use support::{TestRng, rng, rotation};

const GJK: GjkParams = GjkParams {
    rel_tol: 1e-10,
    epa_rel_tol: 1e-10,
    abs_tol: 0.0,
    max_iterations: 128,
    accelerated: false,
};

/// The shapes under test, with their own surface oracles.
#[derive(Debug, Clone)]
enum Solid {
    Sphere(Sphere),
    Capsule(Capsule, Segment),
    Cuboid(Cuboid),
    Cylinder(Cylinder),
    Cone(Cone),
    Hull(ConvexPolyhedron),
}

impl Solid {
    fn features(&self) -> &dyn ContactFeatures {
        match self {
            Solid::Sphere(s) => s,
            Solid::Capsule(c, _) => c,
            Solid::Cuboid(b) => b,
            Solid::Cylinder(c) => c,
            Solid::Cone(c) => c,
            Solid::Hull(h) => h,
        }
    }

    fn rounded(&self) -> Rounded<'_, dyn SupportMap> {
        match self {
            Solid::Sphere(s) => Rounded::new(&POINT as &dyn SupportMap, s.radius),
            Solid::Capsule(c, seg) => Rounded::new(seg as &dyn SupportMap, c.radius),
            Solid::Cuboid(b) => Rounded::plain(b as &dyn SupportMap),
            Solid::Cylinder(c) => Rounded::plain(c as &dyn SupportMap),
            Solid::Cone(c) => Rounded::plain(c as &dyn SupportMap),
            Solid::Hull(h) => Rounded::plain(h as &dyn SupportMap),
        }
    }

    /// Support value along unit `n` (local frame), radius included.
    fn h(&self, n: DVec3) -> f64 {
        let r = self.rounded();
        r.core.support(n).dot(n) + r.radius
    }

    /// A function of a local point that is 0 on the surface, negative inside, and within
    /// the point's distance from the surface in magnitude (closed forms, not the code under
    /// test).
    fn surface(&self, p: DVec3) -> f64 {
        match self {
            Solid::Sphere(s) => p.length() - s.radius,
            Solid::Capsule(c, _) => {
                let z = p.z.clamp(-c.half_height, c.half_height);
                (p - DVec3::new(0.0, 0.0, z)).length() - c.radius
            }
            Solid::Cuboid(b) => (p.abs() - b.half_extents).max_element(),
            Solid::Cylinder(c) => {
                let rho = DVec3::new(p.x, p.y, 0.0).length();
                (rho - c.radius).max(p.z.abs() - c.half_height)
            }
            Solid::Cone(c) => {
                let (h, r) = (c.half_height, c.radius);
                let rho = DVec3::new(p.x, p.y, 0.0).length();
                let slant = (2.0 * h * rho + r * (p.z - h)) / (4.0 * h * h + r * r).sqrt();
                // The radial bound matters only for a flat cone (a disc).
                slant.max(-p.z - h).max(rho - r)
            }
            Solid::Hull(hull) => hull.max_plane_distance(p).expect("solid hulls only"),
        }
    }

    /// Outward face normals to rest on (local frame); a random direction for shapes
    /// without faces.
    fn resting_direction(&self, r: &mut TestRng) -> DVec3 {
        let axes = [
            DVec3::X,
            -DVec3::X,
            DVec3::Y,
            -DVec3::Y,
            DVec3::Z,
            -DVec3::Z,
        ];
        match self {
            Solid::Cuboid(_) => axes[r.random_range(0..6)],
            Solid::Cylinder(_) => axes[r.random_range(4..6)],
            Solid::Cone(_) => -DVec3::Z,
            Solid::Hull(h) => h.faces()[r.random_range(0..h.faces().len())].normal,
            Solid::Sphere(_) | Solid::Capsule(..) => rotation(r) * DVec3::X,
        }
    }

    fn size(&self) -> f64 {
        [DVec3::X, DVec3::Y, DVec3::Z]
            .iter()
            .map(|&a| self.h(a) + self.h(-a))
            .fold(f64::INFINITY, f64::min)
    }
}

fn capsule(half_height: f64, radius: f64) -> Solid {
    let c = Capsule::new(half_height, radius);
    Solid::Capsule(c, c.segment())
}

fn random_solid(r: &mut TestRng, kind: usize) -> Solid {
    let mut s = || r.random_range(0.3..1.0);
    match kind {
        0 => Solid::Sphere(Sphere::new(s())),
        1 => capsule(s(), s()),
        2 => Solid::Cuboid(Cuboid::new(DVec3::new(s(), s(), s()))),
        3 => Solid::Cylinder(Cylinder::new(s(), s())),
        4 => Solid::Cone(Cone::new(s(), s())),
        _ => {
            let pts: Vec<DVec3> = (0..12)
                .map(|_| {
                    DVec3::new(
                        r.random_range(-1.0..1.0),
                        r.random_range(-1.0..1.0),
                        r.random_range(-1.0..1.0),
                    )
                })
                .collect();
            Solid::Hull(ConvexPolyhedron::try_from_points(&pts).unwrap())
        }
    }
}

fn distance(a: &Solid, b: &Solid, pose_ab: &Isometry) -> ShapeDistance {
    signed_distance_convex(
        &a.rounded(),
        &b.rounded(),
        pose_ab,
        &GJK,
        &mut GjkCache::default(),
        &mut EpaWorkspace::default(),
    )
    .0
}

fn manifold(a: &Solid, b: &Solid, pose_ab: &Isometry, d: &ShapeDistance) -> Manifold {
    let mut m = Manifold::new();
    manifold_convex_convex(a.features(), b.features(), pose_ab, d, &mut m);
    m
}

fn hull_of_box(half: DVec3) -> ConvexPolyhedron {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { -half.x } else { half.x },
                if i & 2 == 0 { -half.y } else { half.y },
                if i & 4 == 0 { -half.z } else { half.z },
            )
        })
        .collect();
    ConvexPolyhedron::try_from_points(&corners).unwrap()
}

/// B resting on A: B's face (or a random direction) `g` turned against A's face `f`,
/// spun about it, shifted sideways by up to `lateral`, overlapping by `depth`.
fn resting_pose(r: &mut TestRng, a: &Solid, b: &Solid, depth: f64, lateral: f64) -> Isometry {
    let f = a.resting_direction(r);
    let g = b.resting_direction(r);
    let spin = DQuat::from_axis_angle(f, r.random_range(0.0..std::f64::consts::TAU));
    let q = spin * DQuat::from_rotation_arc(g, -f);
    let rot = DMat3::from_quat(q);
    let t_f = a.h(f) + b.h(rot.transpose() * -f) - depth;
    let side = (rotation(r) * DVec3::X).reject_from(f).normalize_or_zero();
    let t = f * t_f + side * r.random_range(0.0..lateral);
    Isometry::new(rot, t)
}

fn assert_contract(
    a: &Solid,
    b: &Solid,
    pose: &Isometry,
    d: &ShapeDistance,
    m: &Manifold,
    tol: f64,
    what: &str,
) {
    assert!(m.len() <= 4);
    assert_eq!(m.normal, d.normal, "{what}");
    if d.distance > 0.0 {
        assert!(m.is_empty(), "{what}: apart but {m:?}");
        return;
    }
    assert!(!m.is_empty(), "{what}");
    // The manifold cannot be more accurate than the distance it starts from: EPA's
    // witnesses on curved shapes are off the surfaces by up to ~1e-7.
    let d_error = a
        .surface(d.point_a)
        .abs()
        .max(b.surface(pose.inverse_transform_point(d.point_b)).abs());
    let tol = tol + 2.0 * d_error;
    for p in m.points() {
        assert!(p.point_a.is_finite() && p.point_b.is_finite() && p.distance.is_finite());
        let residual = (p.point_b - p.point_a - m.normal * p.distance).length();
        assert!(residual <= tol, "{what}: residual {residual:e} {m:?}");
        assert!(p.distance <= tol, "{what}: {m:?}");
        let sa = a.surface(p.point_a);
        let sb = b.surface(pose.inverse_transform_point(p.point_b));
        assert!(
            sa.abs() <= tol && sb.abs() <= tol,
            "{what}: off the surfaces {sa:e} {sb:e} {m:?}"
        );
    }
    let deepest = m
        .points()
        .iter()
        .map(|p| p.distance)
        .fold(f64::INFINITY, f64::min);
    assert!(
        (deepest - d.distance).abs() <= tol,
        "{what}: deepest {deepest} vs {} {m:?}",
        d.distance
    );
}

#[test]
fn a_cube_face_down_on_the_same_cube_as_a_hull_touches_at_four_points_of_the_overlap() {
    let mut r = rng(501);
    let hull = Solid::Hull(hull_of_box(DVec3::ONE));
    let cube = Solid::Cuboid(Cuboid::new(DVec3::ONE));
    for case in 0..2000 {
        let angle = r.random_range(0.0..std::f64::consts::TAU);
        let depth = r.random_range(0.0..0.2);
        let shift = DVec3::new(r.random_range(-0.3..0.3), r.random_range(-0.3..0.3), 0.0);
        let rot = DMat3::from_rotation_z(angle);
        let pose = Isometry::new(rot, DVec3::new(0.0, 0.0, 2.0 - depth) + shift);
        // Both orders: the hull below the cube, and the cube below the hull.
        for (a, b) in [(&hull, &cube), (&cube, &hull)] {
            let d = distance(a, b, &pose);
            assert!((d.distance + depth).abs() < 1e-9, "case {case}: {d:?}");
            let m = manifold(a, b, &pose, &d);
            assert_eq!(m.len(), 4, "case {case}: {m:?}");
            for p in m.points() {
                assert!((p.distance + depth).abs() < 1e-9, "case {case}: {m:?}");
                // In the overlap of A's top square and B's bottom square (xy).
                let local = pose.inverse_transform_point(p.point_b);
                assert!(p.point_a.x.abs().max(p.point_a.y.abs()) <= 1.0 + 1e-9);
                assert!(
                    local.x.abs().max(local.y.abs()) <= 1.0 + 1e-9,
                    "case {case}"
                );
                assert!(
                    (p.point_a.z - 1.0).abs() < 1e-9 && (local.z + 1.0).abs() < 1e-9,
                    "case {case}"
                );
            }
            assert_contract(a, b, &pose, &d, &m, 1e-9, "cube on hull");
        }
    }
}

#[test]
fn a_cylinder_standing_on_a_box_touches_at_rim_points_of_one_depth() {
    let mut r = rng(502);
    let slab = Solid::Cuboid(Cuboid::new(DVec3::new(2.0, 2.0, 1.0)));
    for case in 0..1000 {
        let (h, rad) = (r.random_range(0.2..1.0), r.random_range(0.2..0.9));
        let cyl = Solid::Cylinder(Cylinder::new(h, rad));
        let depth = r.random_range(0.0..0.1);
        let shift = DVec3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), 0.0);
        let rot = DMat3::from_rotation_z(r.random_range(0.0..std::f64::consts::TAU));
        let pose = Isometry::new(rot, DVec3::new(0.0, 0.0, 1.0 + h - depth) + shift);
        let d = distance(&slab, &cyl, &pose);
        let m = manifold(&slab, &cyl, &pose, &d);
        assert_eq!(m.len(), 4, "case {case}: {d:?} {m:?}");
        for p in m.points() {
            let local = pose.inverse_transform_point(p.point_b);
            let rho = DVec3::new(local.x, local.y, 0.0).length();
            assert!(
                (rho - rad).abs() < 1e-9 && (local.z + h).abs() < 1e-9,
                "case {case}"
            );
            assert!((p.distance + depth).abs() < 1e-9, "case {case}: {m:?}");
        }
        assert_contract(&slab, &cyl, &pose, &d, &m, 1e-9, "standing cylinder");
    }
}

#[test]
fn a_cylinder_lying_on_a_box_touches_at_the_two_ends_of_its_side_line() {
    let mut r = rng(503);
    let slab = Solid::Cuboid(Cuboid::new(DVec3::new(3.0, 3.0, 1.0)));
    for case in 0..1000 {
        let (h, rad) = (r.random_range(0.2..1.0), r.random_range(0.2..0.9));
        let cyl = Solid::Cylinder(Cylinder::new(h, rad));
        let depth = r.random_range(0.0..0.1);
        let shift = DVec3::new(r.random_range(-1.0..1.0), r.random_range(-1.0..1.0), 0.0);
        // Axis along X, spun about Z.
        let rot = DMat3::from_rotation_z(r.random_range(0.0..std::f64::consts::TAU))
            * DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2)
            * DMat3::from_rotation_z(r.random_range(0.0..std::f64::consts::TAU));
        let pose = Isometry::new(rot, DVec3::new(0.0, 0.0, 1.0 + rad - depth) + shift);
        let d = distance(&slab, &cyl, &pose);
        let m = manifold(&slab, &cyl, &pose, &d);
        assert_eq!(m.len(), 2, "case {case}: {d:?} {m:?}");
        let mut ends: Vec<f64> = m
            .points()
            .iter()
            .map(|p| pose.inverse_transform_point(p.point_b).z)
            .collect();
        ends.sort_by(f64::total_cmp);
        assert!(
            (ends[0] + h).abs() < 1e-9 && (ends[1] - h).abs() < 1e-9,
            "case {case}: {ends:?}"
        );
        for p in m.points() {
            assert!((p.distance + depth).abs() < 1e-9, "case {case}: {m:?}");
        }
        assert_contract(&slab, &cyl, &pose, &d, &m, 1e-9, "lying cylinder");
    }
}

#[test]
fn boxes_as_hulls_match_the_closed_form_box_manifold() {
    let mut r = rng(504);
    let (mut faces, mut edges, mut compared, mut tilted) = (0, 0, 0, 0);
    for case in 0..4000 {
        let mut size = || {
            DVec3::new(
                r.random_range(0.2..1.0),
                r.random_range(0.2..1.0),
                r.random_range(0.2..1.0),
            )
        };
        let (ha, hb) = (size(), size());
        let (ca, cb) = (Cuboid::new(ha), Cuboid::new(hb));
        let (a, b) = (Solid::Hull(hull_of_box(ha)), Solid::Hull(hull_of_box(hb)));
        let pose = if case % 2 == 0 {
            let depth = r.random_range(0.0..0.1);
            resting_pose(&mut r, &a, &b, depth, 0.3)
        } else {
            // Random orientation, moved along the closed-form normal into contact.
            let rot = DMat3::from_quat(rotation(&mut r));
            let t = rotation(&mut r) * DVec3::X * 3.0;
            let far = Isometry::new(rot, t);
            let d = proxima::narrow::distance_cuboid_cuboid(&ca, &cb, &far);
            Isometry::new(rot, t - d.normal * (d.distance + r.random_range(0.0..0.1)))
        };
        let mut closed = Manifold::new();
        manifold_cuboid_cuboid(&ca, &cb, &pose, &mut closed);
        let d = distance(&a, &b, &pose);
        let m = manifold(&a, &b, &pose, &d);
        assert_contract(&a, &b, &pose, &d, &m, 1e-9, "box hulls");
        if closed.is_empty() {
            continue;
        }
        compared += 1;
        let deepest = |m: &Manifold| {
            m.points()
                .iter()
                .map(|p| p.distance)
                .fold(f64::INFINITY, f64::min)
        };
        let closed_d = proxima::narrow::distance_cuboid_cuboid(&ca, &cb, &pose);
        // The closed form reports along its reference face's normal, which may differ from
        // the distance's normal by up to 0.8°: its deepest depth is then along another
        // direction, and the distance is the comparable value.
        let same_normal = (closed.normal - closed_d.normal).length() <= 1e-9;
        let expected = if same_normal {
            deepest(&closed)
        } else {
            tilted += 1;
            closed_d.distance
        };
        assert!(
            (deepest(&m) - expected).abs() <= 1e-9,
            "case {case}: {d:?} {closed_d:?} {m:?} vs {closed:?}"
        );
        if closed.len() >= 2 {
            assert_eq!(m.len(), closed.len(), "case {case}: {m:?} vs {closed:?}");
        }
        if m.len() >= 3 {
            faces += 1;
        } else {
            edges += 1;
        }
    }
    eprintln!(
        "compared {compared}: face {faces}, edge/vertex {edges}, closed-form normal tilted {tilted}"
    );
    assert!(faces > 1000 && edges > 1000, "faces {faces}, edges {edges}");
}

#[test]
fn every_gjk_kind_against_every_convex_kind_keeps_the_contact_contract() {
    let mut r = rng(505);
    let mut counts = [0usize; 5]; // apart, 1, 2, 3, 4 points
    for case in 0..6000 {
        let gjk_kind = r.random_range(3..6);
        let other = r.random_range(0..6);
        let (x, y) = (random_solid(&mut r, gjk_kind), random_solid(&mut r, other));
        let (a, b) = if r.random_bool(0.5) { (x, y) } else { (y, x) };
        let pose = if case % 3 == 2 {
            let rot = DMat3::from_quat(rotation(&mut r));
            Isometry::new(rot, support::point_in_cube(&mut r, 1.2))
        } else {
            let depth = r.random_range(-0.01..0.1) * a.size().min(b.size());
            resting_pose(&mut r, &a, &b, depth, 0.2)
        };
        let d = distance(&a, &b, &pose);
        let m = manifold(&a, &b, &pose, &d);
        let what = format!("case {case}: {a:?} / {b:?}");
        assert_contract(&a, &b, &pose, &d, &m, 1e-8, &what);
        counts[if d.distance > 0.0 { 0 } else { m.len() }] += 1;
    }
    eprintln!("apart, 1, 2, 3, 4 points: {counts:?}");
    assert!(counts.iter().all(|&c| c > 100), "{counts:?}");
}

/// Through the public pipeline: the dispatcher sends the GJK pairs here, and the world-frame
/// contacts keep the contract far from the origin, under a rotated frame.
#[test]
fn resting_hulls_and_cylinders_get_four_world_contacts_from_the_pipeline() {
    use proxima::math::Pose;
    use proxima::narrow::Shape;
    use proxima::pipeline::{FrameResults, PipelineWorkspace, Query, step};
    use proxima::scene::{BodyDesc, CollisionFilter, Motion, Scene, SceneLimits};
    use std::sync::Arc;
    let mut r = rng(506);
    let mut checked = 0;
    for case in 0..50 {
        let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
        let frame = Pose::new(DVec3::new(1e5, -2e5, 3e4), rotation(&mut r));
        let mut add = |shape: Shape, local: Pose| {
            let shape = scene.register_shape(shape).unwrap();
            let desc = BodyDesc {
                shape,
                pose: frame.compose(&local),
                motion: Motion::Dynamic,
                filter: CollisionFilter::ALL,
                margin: Some(0.0),
            };
            scene.add_body(&desc).unwrap()
        };
        let depth = r.random_range(1e-4..0.05);
        let spin = |r: &mut TestRng| DQuat::from_rotation_z(r.random_range(0.0..6.3));
        add(
            Shape::Cuboid(Cuboid::new(DVec3::new(4.0, 2.0, 1.0))),
            Pose::IDENTITY,
        );
        add(
            Shape::Convex(Arc::new(hull_of_box(DVec3::splat(0.5)))),
            Pose::new(DVec3::new(-2.0, 0.0, 1.5 - depth), spin(&mut r)),
        );
        add(
            Shape::Cylinder(Cylinder::new(0.5, 0.6)),
            Pose::new(DVec3::new(2.0, 0.0, 1.5 - depth), spin(&mut r)),
        );
        let query = Query {
            contacts: true,
            ..Query::NONE
        };
        let mut results = FrameResults::default();
        step(
            &scene,
            query,
            &mut PipelineWorkspace::default(),
            &mut results,
        );
        assert_eq!(results.pairs.len(), 2, "case {case}: {:?}", results.pairs);
        for pair in &results.pairs {
            assert_eq!(pair.contact_count, 4, "case {case}: {pair:?}");
            let first = pair.first_contact as usize;
            for c in &results.contacts[first..first + 4] {
                let residual = c.point_b - c.point_a - c.normal * c.distance;
                // World coordinates near 2e5 m: rounding of the frame change is ~1e-10.
                assert!(residual.length() < 1e-9, "case {case}: {c:?}");
                assert!((c.distance + depth).abs() < 1e-9, "case {case}: {c:?}");
                let up = frame.transform_vector(DVec3::Z);
                assert!((c.normal - up).length() < 1e-9, "case {case}: {c:?}");
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 400);
}

#[test]
fn swapping_the_shapes_gives_the_same_count_and_deepest_depth() {
    let mut r = rng(507);
    let (mut multi, mut compared) = (0, 0);
    for case in 0..3000 {
        let (kx, ky) = (r.random_range(3..6), r.random_range(0..6));
        let (x, y) = (random_solid(&mut r, kx), random_solid(&mut r, ky));
        let depth = r.random_range(0.0..0.1) * x.size().min(y.size());
        let pose = resting_pose(&mut r, &x, &y, depth, 0.2);
        let d = distance(&x, &y, &pose);
        if d.distance > 0.0 {
            continue;
        }
        let inverse = {
            let rot = pose.rotation.transpose();
            Isometry::new(rot, -(rot * pose.translation))
        };
        let d_swapped = d.flipped(&inverse);
        let (m, m_swapped) = (
            manifold(&x, &y, &pose, &d),
            manifold(&y, &x, &inverse, &d_swapped),
        );
        // Discs are inscribed polygons turned differently as reference and as incident
        // feature, so only polytope pairs must give the same count both ways.
        let polytope = |s: &Solid| matches!(s, Solid::Hull(_) | Solid::Cuboid(_));
        if polytope(&x) && polytope(&y) {
            assert_eq!(m.len(), m_swapped.len(), "case {case}: {m:?} {m_swapped:?}");
            compared += 1;
        }
        let deepest = |m: &Manifold| {
            m.points()
                .iter()
                .map(|p| p.distance)
                .fold(f64::INFINITY, f64::min)
        };
        assert!(
            (deepest(&m) - deepest(&m_swapped)).abs() <= 1e-12 * (1.0 + d.distance.abs()) + 1e-12
        );
        multi += usize::from(m.len() >= 3);
    }
    assert!(multi > 500 && compared > 300, "{multi} {compared}");
}

#[test]
fn degenerate_shapes_keep_the_contact_contract() {
    let mut r = rng(508);
    let flat_pentagon: Vec<DVec3> = (0..5)
        .map(|k| {
            let t = f64::from(k) * std::f64::consts::TAU / 5.0;
            DVec3::new(0.6 * t.cos(), 0.6 * t.sin(), 0.0)
        })
        .collect();
    let degenerate = [
        Solid::Cylinder(Cylinder::new(0.5, 0.0)),
        Solid::Cylinder(Cylinder::new(0.0, 0.5)),
        Solid::Cone(Cone::new(0.0, 0.5)),
        Solid::Cone(Cone::new(0.5, 0.0)),
        Solid::Hull(ConvexPolyhedron::try_from_points(&flat_pentagon).unwrap()),
        Solid::Cuboid(Cuboid::new(DVec3::new(0.5, 0.5, 0.0))),
        Solid::Sphere(Sphere::new(0.0)),
        capsule(0.0, 0.4),
    ];
    let mut counts = [0usize; 5];
    for case in 0..4000 {
        let a = degenerate[r.random_range(0..degenerate.len())].clone();
        let kind = r.random_range(2..6);
        let b = random_solid(&mut r, kind);
        let (a, b) = if r.random_bool(0.5) { (a, b) } else { (b, a) };
        let pose = if case % 2 == 0 {
            let depth = r.random_range(-0.01..0.05);
            resting_pose(&mut r, &a, &b, depth, 0.2)
        } else {
            Isometry::new(
                DMat3::from_quat(rotation(&mut r)),
                support::point_in_cube(&mut r, 1.0),
            )
        };
        let d = distance(&a, &b, &pose);
        let m = manifold(&a, &b, &pose, &d);
        assert_contract(
            &a,
            &b,
            &pose,
            &d,
            &m,
            1e-8,
            &format!("case {case}: {a:?} / {b:?}"),
        );
        counts[if d.distance > 0.0 { 0 } else { m.len() }] += 1;
    }
    eprintln!("degenerate: apart, 1, 2, 3, 4 points: {counts:?}");
    assert!(
        counts[0] > 100 && counts[1] > 100 && counts[4] > 100,
        "{counts:?}"
    );
}

/// A shape whose line feature lies along Z at distance `radius − depth` from A's axis, on
/// the side `w` (unit, ⟂ Z), shifted by `shift` along Z: a cylinder's or capsule's axis
/// parallel to Z, or a cone turned so that its slant runs along Z.
fn parallel_pose(b: &Solid, w: DVec3, reach: f64, shift: f64, flip: bool) -> Isometry {
    let up = if flip { -DVec3::Z } else { DVec3::Z };
    match b {
        Solid::Cone(c) => {
            let (h, r) = (c.half_height, c.radius);
            let slant = DVec3::new(r, 0.0, -2.0 * h).normalize();
            let normal = DVec3::new(2.0 * h, 0.0, r).normalize();
            let source = DMat3::from_cols(slant, normal, slant.cross(normal));
            let target = DMat3::from_cols(up, -w, up.cross(-w));
            let rot = target * source.transpose();
            let apex = DVec3::new(0.0, 0.0, h);
            // The slant's middle at the chosen place.
            let middle = (apex + DVec3::new(r, 0.0, -h)) * 0.5;
            Isometry::new(rot, w * reach + DVec3::Z * shift - rot * middle)
        }
        _ => {
            let rot = DMat3::from_rotation_z(shift * 7.0)
                * DMat3::from_rotation_x(if flip { std::f64::consts::PI } else { 0.0 });
            let radius = match b {
                Solid::Cylinder(c) => c.radius,
                Solid::Capsule(c, _) => c.radius,
                _ => unreachable!(),
            };
            Isometry::new(rot, w * (reach + radius) + DVec3::Z * shift)
        }
    }
}

#[test]
fn parallel_cylinders_capsules_and_cone_slants_touch_at_the_two_ends_of_their_overlap() {
    let mut r = rng(509);
    let mut seen = [0usize; 3];
    for case in 0..3000 {
        let (ha, ra) = (r.random_range(0.3..1.0), r.random_range(0.2..0.8));
        let cyl = Solid::Cylinder(Cylinder::new(ha, ra));
        let kind = case % 3;
        let other = match kind {
            0 => Solid::Cylinder(Cylinder::new(
                r.random_range(0.3..1.0),
                r.random_range(0.2..0.8),
            )),
            1 => capsule(r.random_range(0.3..1.0), r.random_range(0.2..0.8)),
            _ => Solid::Cone(Cone::new(
                r.random_range(0.3..1.0),
                r.random_range(0.2..0.8),
            )),
        };
        // Half the length of the other's line feature along Z.
        let half_line = match &other {
            Solid::Cylinder(c) => c.half_height,
            Solid::Capsule(c, _) => c.half_height,
            Solid::Cone(c) => {
                0.5 * (c.radius * c.radius + 4.0 * c.half_height * c.half_height).sqrt()
            }
            _ => unreachable!(),
        };
        let depth = r.random_range(0.0..0.1) * ra;
        let angle = r.random_range(0.0..std::f64::consts::TAU);
        let w = DVec3::new(angle.cos(), angle.sin(), 0.0);
        let shift = r.random_range(-0.8..0.8) * (ha + half_line);
        let pose = parallel_pose(&other, w, ra - depth, shift, r.random_bool(0.5));
        let (lo, hi) = ((shift - half_line).max(-ha), (shift + half_line).min(ha));
        let inverse = Isometry::new(
            pose.rotation.transpose(),
            -(pose.rotation.transpose() * pose.translation),
        );
        // Both orders: the cylinder as A, then as B.
        for (a, b, iso, cyl_is_a) in [(&cyl, &other, pose, true), (&other, &cyl, inverse, false)] {
            let d = distance(a, b, &iso);
            assert!((d.distance + depth).abs() < 1e-9, "case {case}: {d:?}");
            let m = manifold(a, b, &iso, &d);
            assert_eq!(
                m.len(),
                2,
                "case {case} ({kind}, A cylinder: {cyl_is_a}): {d:?} {m:?}"
            );
            // The ends' heights in the cylinder's frame.
            let mut ends: Vec<f64> = m
                .points()
                .iter()
                .map(|p| {
                    if cyl_is_a {
                        p.point_a.z
                    } else {
                        iso.inverse_transform_point(p.point_b).z
                    }
                })
                .collect();
            ends.sort_by(f64::total_cmp);
            // The ends are pulled in by the columns' drift (depth × the normal's tilt from
            // the lines, EPA's error on curved shapes: ~1e-6 rad) and rounding.
            assert!(
                ends[0] >= lo - 1e-12
                    && ends[0] - lo < 1e-6
                    && ends[1] <= hi + 1e-12
                    && hi - ends[1] < 1e-6,
                "case {case}: {ends:?} vs {lo} {hi}"
            );
            for p in m.points() {
                assert!((p.distance + depth).abs() < 1e-9, "case {case}: {m:?}");
            }
            assert_contract(a, b, &iso, &d, &m, 1e-9, "parallel lines");
        }
        seen[kind] += 1;
    }
    assert!(seen.iter().all(|&c| c == 1000));
}
