//! Compound shapes made by `decompose`, against the closed meshes they came from, by an
//! independent oracle: the mesh's signed distance field, brute force in f64 (the nearest of
//! all triangles, signed by the winding number), and the brute-force triangle distance of
//! two meshes.
//!
//! The contract checked, for a decomposition of concavity `c` (metres):
//! - a ball apart from the compound is within `[d − c, d]` of its distance `d` to the mesh
//!   (the hulls contain the solid and stay within `c` of its surface);
//! - a ball overlapping it is never shallower than the shortest move that frees it from
//!   the mesh (searched over many directions with the mesh's field) by more than `c`;
//! - two compounds apart are within `[d − c_a − c_b, d]` of the meshes' distance.
//!
//! The compound's depth is the length of a move that frees the ball from every part
//! (`narrow::compound::union_depth`), found among a few candidate directions, so it may be
//! deeper than the best move; the test prints how often it is within `c` either way.

mod support;

use proxima::decompose::{Options, decompose};
use proxima::geometry::{Sphere, TriMesh, Triangle};
use proxima::math::{DVec3, Pose};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::{CompoundShape, Shape, distance_triangle_triangle};
use rand::Rng;
use std::sync::Arc;
use support::meshes::{brute_force_distance, l_prism, torus, u_prism, winding_number};
use support::{point_in_cube, rng, rotation, sphere_directions};

/// The signed distance from `p` to the closed `mesh`'s surface, negative inside.
fn signed_distance(mesh: &TriMesh, p: DVec3) -> f64 {
    let point = Triangle::new(p, p, p);
    let unsigned = (0..mesh.triangle_count())
        .map(|i| distance_triangle_triangle(&point, &mesh.triangle(i)).distance)
        .fold(f64::INFINITY, f64::min);
    if winding_number(mesh, p) > 0.5 {
        -unsigned
    } else {
        unsigned
    }
}

/// A closed mesh and the compound of its decomposition, with the decomposition's
/// concavity (metres).
struct Solid {
    name: &'static str,
    mesh: TriMesh,
    compound: Shape,
    concavity: f64,
}

fn solid(name: &'static str, mesh: TriMesh) -> Solid {
    let options = Options {
        max_concavity: 0.01,
        ..Options::default()
    };
    let parts = decompose(&mesh, &options).expect("a closed mesh");
    let compound = CompoundShape::from_decomposition(&parts).expect("some parts");
    Solid {
        name,
        mesh,
        compound: Shape::Compound(Arc::new(compound)),
        concavity: parts.concavity,
    }
}

fn solids() -> Vec<Solid> {
    vec![
        solid("L prism", l_prism()),
        solid("U prism", u_prism()),
        solid("torus", torus(0.6, 0.25, 24, 12)),
    ]
}

/// The shortest move of a ball of `radius` at `c` that frees it from the closed `mesh`,
/// over `dirs`: along each, the first point where the mesh's field reaches the radius,
/// stepping by the field's shortfall (the field is 1-Lipschitz, so no step passes a free
/// point). An upper bound of the ball's penetration depth, as fine as the directions.
fn freeing_depth(mesh: &TriMesh, c: DVec3, radius: f64, dirs: &[DVec3]) -> f64 {
    let mut best = f64::INFINITY;
    for &n in dirs {
        let mut t = 0.0;
        while t < best {
            let shortfall = radius - signed_distance(mesh, c + t * n);
            if shortfall <= 1e-9 {
                best = t;
                break;
            }
            t += shortfall;
        }
    }
    best
}

/// Balls of 0.02–0.3 m about random points near each solid. Apart, the distance is within
/// the concavity below the mesh's field. Overlapping, the depth is compared with the
/// shortest move that frees the ball from the mesh (over 300 directions, by the mesh's
/// field): never shallower by more than the concavity (the compound's depth is that of a
/// move freeing the ball from every part, whose union holds the mesh), and how often it is
/// within the concavity either way is printed. Both sides occur.
#[test]
fn a_ball_in_a_compound_is_never_shallower_than_in_its_mesh_by_more_than_the_concavity() {
    let mut r = rng(3310);
    let mut s = NarrowScratch::default();
    let dirs = sphere_directions(300);
    for (solid, cases) in solids().into_iter().zip([1000, 1000, 200]) {
        let (min, max) = solid.mesh.bounds();
        let (centre, half) = ((min + max) / 2.0, (max - min) / 2.0 + DVec3::splat(0.2));
        let (mut apart, mut overlapping, mut within) = (0, 0, 0);
        let (mut deepest_over, mut shallowest_under): (f64, f64) = (0.0, 0.0);
        for case in 0..cases {
            let c = centre + point_in_cube(&mut r, 1.0) * half;
            let radius = r.random_range(0.02..0.3);
            let ball = Shape::Sphere(Sphere::new(radius));
            let pose = Pose::new(c, rotation(&mut r));
            let d = dispatch::distance(&solid.compound, &ball, &pose, f64::INFINITY, &mut s);
            let field = signed_distance(&solid.mesh, c) - radius;
            let slack = 1e-9 + solid.concavity;
            if field > 0.0 {
                apart += 1;
                assert!(
                    d.distance <= field + 1e-9 && d.distance >= field - slack,
                    "{} case {case}: {} against {field}",
                    solid.name,
                    d.distance
                );
                continue;
            }
            overlapping += 1;
            let truth = -freeing_depth(&solid.mesh, c, radius, &dirs);
            assert!(
                d.distance <= truth + slack,
                "{} case {case}: {} shallower than {truth}",
                solid.name,
                d.distance
            );
            within += usize::from((d.distance - truth).abs() <= slack);
            deepest_over = deepest_over.max(truth - d.distance);
            shallowest_under = shallowest_under.max(d.distance - truth);
        }
        assert!(
            apart > cases / 10 && overlapping > cases / 4,
            "{}: {apart} apart, {overlapping} overlapping",
            solid.name
        );
        println!(
            "{}: concavity {:.4} m; overlapping: {within} of {overlapping} within it of the \
             mesh's freeing depth, at worst {deepest_over:.4} m deeper and \
             {shallowest_under:.4} m shallower",
            solid.name, solid.concavity
        );
    }
}

/// Two compounds apart are within both concavities of their meshes' distance.
#[test]
fn two_compounds_apart_are_within_their_concavities_of_the_meshes() {
    let mut r = rng(3311);
    let mut s = NarrowScratch::default();
    let all = solids();
    let mut apart = 0;
    for case in 0..300 {
        let (a, b) = (&all[case % all.len()], &all[(case / 3) % all.len()]);
        let pose = Pose::new(point_in_cube(&mut r, 2.5), rotation(&mut r));
        let truth = brute_force_distance(&a.mesh, &b.mesh, &pose);
        let d = dispatch::distance(&a.compound, &b.compound, &pose, f64::INFINITY, &mut s);
        if truth <= 0.0 {
            continue;
        }
        apart += 1;
        let slack = a.concavity + b.concavity + 1e-9;
        assert!(
            d.distance <= truth + 1e-9 && d.distance >= truth - slack,
            "{} and {} case {case}: {} against {truth}",
            a.name,
            b.name,
            d.distance
        );
    }
    assert!(apart > 100, "{apart} apart");
}
