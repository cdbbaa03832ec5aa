//! The metrics against analytic answers.

use super::*;
use crate::meshes::u_block;
use crate::support::meshes::{L_OUTLINE, cuboid, prism};
use rand::Rng;

/// The unit cube `[-0.5, 0.5]³` as a closed mesh (12 triangles).
fn unit_cube() -> TriMesh {
    cuboid(DVec3::splat(0.5))
}

/// The hull of the box `[lo, hi]`.
fn box_hull(lo: DVec3, hi: DVec3) -> ConvexPolyhedron {
    ConvexPolyhedron::try_from_points(&Aabb::new(lo, hi).corners()).unwrap()
}

/// The hull of the mesh's vertices.
fn mesh_hull(mesh: &TriMesh) -> ConvexPolyhedron {
    ConvexPolyhedron::try_from_points(mesh.vertices()).unwrap()
}

/// Rounding of coordinates of size 1, far below any sampling error.
const EXACT: f64 = 1e-12;

/// Asserts that `hulls` fit the unit cube exactly: no Hausdorff distance, no overshoot.
fn assert_fit_the_cube_exactly(hulls: &[ConvexPolyhedron]) {
    let m = Reference::new(&unit_cube()).measure(hulls);
    assert!(m.hausdorff_rel < EXACT, "{m:?}");
    assert!(m.volume_overshoot.abs() < EXACT, "{m:?}");
}

#[test]
fn unit_cube_as_its_own_hull_scores_zero() {
    assert_fit_the_cube_exactly(&[mesh_hull(&unit_cube())]);
}

#[test]
fn cube_cut_in_two_scores_zero_because_the_cut_faces_are_dropped() {
    let half = DVec3::splat(0.5);
    let hulls = [
        box_hull(-half, DVec3::new(0.0, 0.5, 0.5)),
        box_hull(DVec3::new(0.0, -0.5, -0.5), half),
    ];
    assert_fit_the_cube_exactly(&hulls);
}

#[test]
fn cube_cut_along_a_diagonal_plane_scores_zero() {
    // Two triangular prisms meeting on the plane x = y, whose rounding is not axis-aligned.
    let cube = unit_cube();
    let side = |keep: fn(&DVec3) -> bool| {
        let points: Vec<DVec3> = cube.vertices().iter().copied().filter(keep).collect();
        ConvexPolyhedron::try_from_points(&points).unwrap()
    };
    let hulls = [side(|v| v.x <= v.y), side(|v| v.x >= v.y)];
    assert_fit_the_cube_exactly(&hulls);
}

/// The convex polytope `{x : n · x ≤ d}` for the given planes `(n, d)`, as a hull: its
/// corners are the points where three planes meet that every plane keeps.
fn polytope(planes: &[(DVec3, f64)]) -> ConvexPolyhedron {
    let mut corners = Vec::new();
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            for k in j + 1..planes.len() {
                let (a, b, c) = (planes[i], planes[j], planes[k]);
                let det = a.0.dot(b.0.cross(c.0));
                if det.abs() < 1e-9 {
                    continue;
                }
                let p = (b.0.cross(c.0) * a.1 + c.0.cross(a.0) * b.1 + a.0.cross(b.0) * c.1) / det;
                if planes.iter().all(|(n, d)| n.dot(p) <= d + 1e-12) {
                    corners.push(p);
                }
            }
        }
    }
    ConvexPolyhedron::try_from_points(&corners).unwrap()
}

#[test]
fn cube_cut_by_three_oblique_planes_scores_zero_at_their_inner_corner() {
    // The eight pieces meet at `centre`, inside the cube: a corner of each hull but not on
    // the union's boundary, whatever direction its hull's centroid lies in.
    let centre = DVec3::new(0.1, 0.2, -0.1);
    let normals = [
        DVec3::new(1.0, 0.3, 0.0).normalize(),
        DVec3::new(0.2, 1.0, 0.5).normalize(),
        DVec3::new(0.0, -0.4, 1.0).normalize(),
    ];
    let cube: Vec<(DVec3, f64)> = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .flat_map(|a| [(a, 0.5), (-a, 0.5)])
        .collect();
    let hulls: Vec<ConvexPolyhedron> = (0..8)
        .map(|octant: usize| {
            let mut planes = cube.clone();
            for (k, n) in normals.iter().enumerate() {
                let n = if octant & (1 << k) == 0 { *n } else { -*n };
                planes.push((n, n.dot(centre)));
            }
            polytope(&planes)
        })
        .collect();
    assert_fit_the_cube_exactly(&hulls);
}

#[test]
fn a_spike_over_a_cut_cube_scores_its_tip_exactly() {
    // The tip is a vertex of one hull, sharp, beside another hull: it is on the boundary
    // and its distance, 1 m, is a vertex's, exact.
    let cube = unit_cube();
    let half = DVec3::splat(0.5);
    let mut spiked = Aabb::new(-half, DVec3::new(0.0, 0.5, 0.5))
        .corners()
        .to_vec();
    spiked.push(DVec3::new(0.0, 0.0, 1.5));
    let hulls = [
        ConvexPolyhedron::try_from_points(&spiked).unwrap(),
        box_hull(DVec3::new(0.0, -0.5, -0.5), half),
    ];
    let m = Reference::new(&cube).measure(&hulls);
    let expected = 1.0 / 3f64.sqrt();
    assert!((m.hull_to_mesh_rel - expected).abs() < EXACT, "{m:?}");
}

#[test]
fn cube_under_a_hull_shrunk_by_ten_percent_scores_its_corner_gap() {
    // The shrunk cube [-0.45, 0.45]³ is 0.05 inside every face: 0.05 from the hull to the
    // cube, 0.05 √3 from a cube corner to the hull's. Over the diagonal √3: 0.05 / √3 and
    // exactly 0.05 (corners are samples, so no sampling error).
    let shrunk = box_hull(DVec3::splat(-0.45), DVec3::splat(0.45));
    let m = Reference::new(&unit_cube()).measure(&[shrunk]);
    let sqrt3 = 3.0_f64.sqrt();
    assert!((m.hull_to_mesh_rel - 0.05 / sqrt3).abs() < EXACT, "{m:?}");
    assert!((m.mesh_to_hulls_rel - 0.05).abs() < EXACT, "{m:?}");
    assert!((m.hausdorff_rel - 0.05).abs() < EXACT, "{m:?}");
    assert!(
        (m.volume_overshoot - (0.9_f64.powi(3) - 1.0)).abs() < EXACT,
        "{m:?}"
    );
}

/// The L-shaped prism: the square `[0, 2]²` without `[1, 2]²`, 2 m tall.
fn l_block() -> TriMesh {
    prism(&L_OUTLINE, 2.0)
}

/// Sampling error allowed on the L-block, in units of its diagonal (about 3.5 m): both
/// largest distances are reached away from vertices (see the test), and the samples nearest
/// those places fall short by 6e-5 (mesh to hull) and 1.5e-5 (hull to mesh).
const L_BLOCK_SAMPLING: f64 = 2e-4;

#[test]
fn l_block_under_its_hull_scores_the_depth_of_its_notch_corner() {
    // The hull adds the triangle (2, 1), (2, 2), (1, 2) over the whole height. The notch's
    // corner edge x = y = 1 is 1/√2 from the hull's slanted face x + y = 3 and, at mid
    // height, 1 from its top and bottom: the farthest mesh point from the hull's boundary.
    // The hull's points are at most 1/2 from the mesh (the slanted face's middle line, the
    // caps' notch triangles). Diagonal √12.
    let l = l_block();
    let m = Reference::new(&l).measure(&[mesh_hull(&l)]);
    let notch_depth = 0.5_f64.sqrt();
    let diagonal = 12.0_f64.sqrt();
    assert!(
        (m.hull_to_mesh_rel - 0.5 / diagonal).abs() < L_BLOCK_SAMPLING,
        "{m:?}"
    );
    assert!(
        (m.hausdorff_rel - notch_depth / diagonal).abs() < L_BLOCK_SAMPLING,
        "{m:?} against {}",
        notch_depth / diagonal
    );
    // Hull cross-section 3.5 m² over the L's 3 m².
    assert!((m.volume_overshoot - 0.5 / 3.0).abs() < EXACT, "{m:?}");
}

#[test]
fn no_hulls_score_infinite_distance_and_minus_one_overshoot() {
    let m = Reference::new(&unit_cube()).measure(&[]);
    assert!(m.hausdorff_rel.is_infinite(), "{m:?}");
    assert_eq!(m.volume_overshoot, -1.0);
}

#[test]
fn nearest_triangle_matches_brute_force() {
    let torus = TriMesh::torus(1.0, 0.3, 24, 12);
    let triangles: Vec<Triangle> = (0..torus.triangle_count())
        .map(|i| torus.triangle(i))
        .collect();
    let search = NearestTriangle::new(&triangles).unwrap();
    let mut rng = Pcg64Mcg::seed_from_u64(7);
    for _ in 0..500 {
        let p = DVec3::new(
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-1.0..1.0),
        );
        let brute = triangles
            .iter()
            .map(|t| distance_squared_to_triangle(p, t))
            .fold(f64::INFINITY, f64::min)
            .sqrt();
        assert_eq!(search.distance(p), brute, "at {p}");
    }
}

#[test]
fn prisms_are_closed_with_their_polygon_volume() {
    let u = u_block();
    assert_eq!(open_edges(&u), 0);
    assert!((enclosed_volume(&u) - 4.6).abs() < EXACT);
    assert_eq!(open_edges(&l_block()), 0);
    assert!((enclosed_volume(&l_block()) - 6.0).abs() < EXACT);
}

#[test]
fn a_missing_triangle_leaves_three_open_edges() {
    let cube = unit_cube();
    let open = TriMesh::try_new(cube.vertices().to_vec(), cube.triangles()[1..].to_vec()).unwrap();
    assert_eq!(open_edges(&open), 3);
}
