use super::*;
use crate::geometry::Triangle;
use crate::math::DVec3;
use crate::narrow::distance_triangle_triangle;
use crate::test_support::meshes::{cuboid, grid, torus, triangle_soup, uv_sphere};
use crate::test_support::{isometry, rng};
use rand::Rng;

/// The meshes' distance by brute force over every triangle pair (f64), B placed by
/// `pose_ab`.
fn brute_force_distance(a: &TriMesh, b: &TriMesh, pose_ab: &Isometry) -> f64 {
    let placed: Vec<Triangle> = (0..b.triangle_count())
        .map(|j| b.triangle(j).transformed(pose_ab))
        .collect();
    (0..a.triangle_count())
        .flat_map(|i| {
            let ta = a.triangle(i);
            placed
                .iter()
                .map(move |tb| distance_triangle_triangle(&ta, tb).distance)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Over random poses of convex and non-convex meshes (a sphere, a box, a torus, a
/// triangle soup whose vertices the hull leaves inside): a hull gap is never more than
/// the meshes' distance by brute force, and for two convex meshes it is their distance
/// to GJK's tolerance. Both outcomes occur: proofs (most of them beyond 1 cm) and hulls
/// found meeting.
#[test]
fn a_hull_gap_is_a_lower_bound_of_the_meshes_distance() {
    let mut rng = rng(51);
    let meshes = [
        (uv_sphere(0.3, 8, 5), true),
        (cuboid(DVec3::new(0.3, 0.15, 0.45)), true),
        (torus(0.4, 0.12, 8, 5), false),
        (triangle_soup(&mut rng, 24, 0.35, 0.1), false),
    ];
    let hulls: Vec<MeshHull> = meshes
        .iter()
        .map(|(m, _)| MeshHull::of(m).expect("solid meshes have hulls"))
        .collect();
    let (mut proofs, mut beyond_a_centimetre, mut meeting) = (0, 0, 0);
    for case in 0..2_000 {
        let (i, j) = (rng.random_range(0..4), rng.random_range(0..4));
        let pose_ab = isometry(&mut rng, 1.0);
        let Some(gap) = hulls[i].gap(&hulls[j], &pose_ab, &mut GjkCache::default()) else {
            meeting += 1;
            continue;
        };
        proofs += 1;
        beyond_a_centimetre += usize::from(gap > 0.01);
        let truth = brute_force_distance(&meshes[i].0, &meshes[j].0, &pose_ab);
        assert!(
            gap <= truth,
            "case {case}: meshes {i}, {j}: hull gap {gap} beyond the distance {truth}"
        );
        if meshes[i].1 && meshes[j].1 {
            assert!(
                gap >= truth - 1e-6,
                "case {case}: convex meshes {i}, {j}: gap {gap}, distance {truth}"
            );
        }
    }
    assert!(
        proofs > 500 && beyond_a_centimetre > 400 && meeting > 300,
        "{proofs} proofs ({beyond_a_centimetre} beyond 1 cm), {meeting} meeting"
    );
}

/// Vertices the hull leaves out lie within its tolerance of it: the outside allowance
/// stays rounding-sized on closed meshes and on a soup with interior vertices. A flat
/// mesh has no hull to prove with.
#[test]
fn the_outside_allowance_is_small_and_flat_meshes_have_no_hull() {
    let mut rng = rng(52);
    for mesh in [
        uv_sphere(0.3, 16, 9),
        torus(0.4, 0.12, 16, 8),
        triangle_soup(&mut rng, 200, 0.35, 0.1),
    ] {
        let hull = MeshHull::of(&mesh).expect("a solid hull");
        assert!(
            hull.outside() <= hull.hull.tolerance() + 1e-12,
            "outside {} against tolerance {}",
            hull.outside(),
            hull.hull.tolerance()
        );
    }
    assert!(MeshHull::of(&grid(1.0, 4)).is_none());
}
