//! Compound shapes made by `decompose`, against the closed meshes they came from, by an
//! independent oracle: the mesh's signed distance field, brute force in f64 (the nearest of
//! all triangles, signed by the winding number), and the brute-force triangle distance of
//! two meshes.
//!
//! The contract checked, for a decomposition of concavity `c` (metres):
//! - a ball's signed distance to the compound is never deeper than its distance to the
//!   mesh by more than `c`, and apart it lies within `[d − c, d]` (the hulls contain the
//!   solid and stay within `c` of its surface);
//! - two compounds apart are within `[d − c_a − c_b, d]` of the meshes' distance.
//!
//! Inside, each part pair is answered on its own (GJK/EPA): a ball reaching across a cut
//! between two parts gets the deeper part's depth, which can be less than the solid's.
//! The test prints how often the depth is within `c` of the solid's.

mod support;

use proxima::decompose::{Options, decompose};
use proxima::geometry::{Sphere, TriMesh, Triangle};
use proxima::math::{DVec3, Pose};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::{CompoundShape, Shape, distance_triangle_triangle};
use rand::Rng;
use std::sync::Arc;
use support::meshes::{brute_force_distance, l_prism, torus, u_prism, winding_number};
use support::{point_in_cube, rng, rotation};

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

/// Balls of 0.02–0.3 m about random points near each solid: never deeper than the mesh's
/// field says by more than the concavity, within it when apart; both sides occur.
#[test]
fn a_ball_is_never_deeper_in_a_compound_than_in_its_mesh_by_more_than_the_concavity() {
    let mut r = rng(3310);
    let mut s = NarrowScratch::default();
    for solid in solids() {
        let (min, max) = solid.mesh.bounds();
        let (centre, half) = ((min + max) / 2.0, (max - min) / 2.0 + DVec3::splat(0.2));
        let (mut apart, mut inside, mut inside_within) = (0, 0, 0);
        let mut worst_shallower: f64 = 0.0;
        for case in 0..1500 {
            let c = centre + point_in_cube(&mut r, 1.0) * half;
            let radius = r.random_range(0.02..0.3);
            let ball = Shape::Sphere(Sphere::new(radius));
            let pose = Pose::new(c, rotation(&mut r));
            let d = dispatch::distance(&solid.compound, &ball, &pose, f64::INFINITY, &mut s);
            let truth = signed_distance(&solid.mesh, c) - radius;
            let slack = 1e-9 + solid.concavity;
            assert!(
                d.distance >= truth - slack,
                "{} case {case}: {} deeper than {truth}",
                solid.name,
                d.distance
            );
            if truth > 0.0 {
                apart += 1;
                assert!(
                    d.distance <= truth + 1e-9,
                    "{} case {case}: {} farther than {truth}",
                    solid.name,
                    d.distance
                );
            } else if signed_distance(&solid.mesh, c) < 0.0 {
                inside += 1;
                inside_within += usize::from((d.distance - truth).abs() <= slack);
                worst_shallower = worst_shallower.max(d.distance - truth);
            }
        }
        assert!(
            apart > 200 && inside > 200,
            "{}: {apart} apart, {inside} inside",
            solid.name
        );
        println!(
            "{}: concavity {:.4} m; centres inside: {inside_within} of {inside} within it, \
             the worst {worst_shallower:.3} m shallower",
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
