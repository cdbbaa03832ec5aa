//! Pieces and cuts against analytic volumes; the repairs of `solid.rs`.

use super::fitted::QuickHull;
use super::piece::{Piece, Plane};
use super::solid::prepare;
use super::{DecomposeError, Fitted};
use crate::geometry::TriMesh;
use crate::math::{DQuat, DVec3};
use crate::test_support::meshes::{
    comb_prism, cuboid, l_prism, stairs_prism, torus, u_prism, uv_sphere, winding_number,
};
use crate::test_support::{point_in_cube, rng, rotation};
use rand::Rng;
use rand::seq::SliceRandom;
use std::f64::consts::PI;

fn solid_piece(mesh: &TriMesh) -> Piece {
    prepare(mesh).expect("closed test mesh").piece
}

fn random_plane(rng: &mut crate::test_support::TestRng, half: f64) -> Plane {
    let normal = point_in_cube(rng, 1.0).normalize_or(DVec3::X);
    Plane {
        normal,
        offset: normal.dot(point_in_cube(rng, half)),
    }
}

/// Volume of the unit-radius cap of height `h` of a sphere of radius `r`.
fn cap_volume(r: f64, h: f64) -> f64 {
    PI * h * h * (3.0 * r - h) / 3.0
}

#[test]
fn a_cut_splits_the_volume_exactly_and_keeps_each_half_closed() {
    let mut r = rng(3301);
    let meshes = [
        torus(1.0, 0.3, 48, 24),
        uv_sphere(1.0, 32, 16),
        u_prism().translated(DVec3::new(-1.5, -1.0, -0.5)),
    ];
    let (mut cut, mut missed) = (0, 0);
    for mesh in &meshes {
        let whole = solid_piece(mesh);
        let total = whole.volume();
        for _ in 0..60 {
            let plane = random_plane(&mut r, 1.2);
            let Some((below, above)) = whole.cut(&plane) else {
                missed += 1;
                continue;
            };
            cut += 1;
            let (a, b) = (below.volume(), above.volume());
            assert!(a > 0.0 && b > 0.0, "both halves hold volume: {a} {b}");
            assert!(
                (a + b - total).abs() <= 1e-12 * total,
                "{a} + {b} ≠ {total}"
            );
            assert_eq!(below.forced_caps + above.forced_caps, 0);
            // Cutting a half again by a second plane also adds up: the caps are closed.
            let second = random_plane(&mut r, 1.2);
            if let Some((c, d)) = below.cut(&second) {
                assert!((c.volume() + d.volume() - a).abs() <= 1e-12 * total);
            }
        }
    }
    assert!(cut > 100 && missed > 0, "cut {cut}, missed {missed}");
}

#[test]
fn sphere_caps_have_their_analytic_volume() {
    // A fine UV sphere's volume is below the sphere's by its facets: compare ratios.
    let sphere = solid_piece(&uv_sphere(1.0, 256, 128));
    let total = sphere.volume();
    for h in [0.2, 0.7, 1.0, 1.5] {
        let plane = Plane {
            normal: DVec3::Z,
            offset: 1.0 - h,
        };
        let (_, above) = sphere.cut(&plane).expect("plane through the sphere");
        let ratio = above.volume() / total;
        let analytic = cap_volume(1.0, h) / (4.0 / 3.0 * PI);
        assert!(
            (ratio - analytic).abs() < 2e-3,
            "h {h}: {ratio} vs {analytic}"
        );
    }
}

#[test]
fn the_corner_where_three_cuts_meet_inside_is_on_the_hull() {
    // The box octant's corner at the centre is on no input triangle: only the caps bring it.
    let mut piece = solid_piece(&cuboid(DVec3::ONE));
    for normal in [DVec3::X, DVec3::Y, DVec3::Z] {
        piece = piece
            .cut(&Plane {
                normal,
                offset: 0.0,
            })
            .expect("cut")
            .0;
    }
    let octant = Fitted::new(piece, 0.01).expect("octant");
    assert!((octant.volume - 1.0).abs() < 1e-12);
    assert!((octant.hull.volume() - 1.0).abs() < 1e-9);
    let hull = octant.polyhedron().expect("octant hull");
    assert!((hull.volume() - 1.0).abs() < 1e-9);
    assert!(hull.contains_point(DVec3::ZERO));
    // Sampled distances carry the sample spacing (0.01 m) as a floor.
    assert!(octant.concavity < 0.01, "{}", octant.concavity);
}

#[test]
fn an_l_prism_is_concave_until_cut_at_its_bend() {
    let l = Fitted::new(solid_piece(&l_prism()), 0.01).expect("L");
    // The notch edge (1, 1, z) is 1/√2 below the hull's diagonal face and z from its bottom
    // (1 − z from its top): deepest at mid-height, 1/2, which the sample lattice holds.
    assert!((l.concavity - 0.5).abs() < 1e-9, "{}", l.concavity);
    let plane = Plane {
        normal: DVec3::X,
        offset: 1.0,
    };
    let (a, b) = l.piece.cut(&plane).expect("cut");
    for half in [a, b] {
        let concavity = Fitted::new(half, 0.01).expect("half").concavity;
        assert!(concavity < 0.01, "{concavity}");
    }
}

#[test]
fn a_triangle_soup_is_welded_and_a_hole_closed() {
    let cube = cuboid(DVec3::splat(0.5));
    // Unweld every triangle, then take one away.
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for t in cube.triangles().iter().skip(1) {
        let base = vertices.len() as u32;
        vertices.extend(t.map(|i| cube.vertices()[i as usize]));
        triangles.push([base, base + 1, base + 2]);
    }
    let soup = TriMesh::try_new(vertices, triangles).expect("soup");
    let solid = prepare(&soup).expect("repairable");
    assert_eq!(solid.repairs.welded_vertices, 33 - 8);
    assert_eq!(solid.repairs.holes_closed, 1);
    assert!((solid.piece.volume() - 1.0).abs() < 1e-12);
}

#[test]
fn flipped_triangles_are_turned_and_an_inside_out_mesh_too() {
    let cube = cuboid(DVec3::splat(0.5));
    let mut r = rng(3302);
    let mut flipped: Vec<[u32; 3]> = cube.triangles().to_vec();
    for t in flipped.iter_mut() {
        if r.random_bool(0.4) {
            t.swap(1, 2);
        }
    }
    let everted: Vec<[u32; 3]> = cube
        .triangles()
        .iter()
        .map(|t| [t[0], t[2], t[1]])
        .collect();
    for triangles in [flipped, everted] {
        let mesh = TriMesh::try_new(cube.vertices().to_vec(), triangles).expect("mesh");
        let solid = prepare(&mesh).expect("repairable");
        assert!((solid.piece.volume() - 1.0).abs() < 1e-12);
    }
}

#[test]
fn a_flat_mesh_is_not_a_solid() {
    let square = TriMesh::try_new(
        vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
        vec![[0, 1, 2], [0, 2, 3]],
    )
    .expect("square");
    assert!(matches!(
        prepare(&square).err(),
        Some(DecomposeError::NotSolid { .. })
    ));
}

/// Whether `p` lies in or on [`u_prism`] (3 × 2 × 1, its notch `[1, 2] × [1, 2]`), within
/// `tol` metres.
fn in_u_prism(p: DVec3, tol: f64) -> bool {
    let in_box =
        p.cmpge(DVec3::splat(-tol)).all() && p.cmple(DVec3::new(3.0, 2.0, 1.0) + tol).all();
    let in_notch = p.x > 1.0 + tol && p.x < 2.0 - tol && p.y > 1.0 + tol;
    in_box && !in_notch
}

/// Cuts `piece` by each plane in turn, keeping every piece; returns them all.
fn cut_all(piece: Piece, planes: &[Plane]) -> Vec<Piece> {
    let mut pieces = vec![piece];
    for plane in planes {
        pieces = pieces
            .into_iter()
            .flat_map(|p| match p.cut(plane) {
                Some((a, b)) => vec![a, b],
                None => vec![p],
            })
            .collect();
    }
    pieces
}

#[test]
fn a_cut_through_a_concave_cap_puts_no_corner_outside_the_solid() {
    // z = 0.5 leaves U-shaped caps; y = 1.5 keeps both arms of one, two stretches of it;
    // x = 1.5 then crosses the gap between them, where a bridge joining the arms would be.
    let whole = solid_piece(&u_prism());
    let planes = [
        Plane {
            normal: DVec3::Z,
            offset: 0.5,
        },
        Plane {
            normal: DVec3::Y,
            offset: 1.5,
        },
        Plane {
            normal: DVec3::X,
            offset: 1.5,
        },
    ];
    let pieces = cut_all(whole.clone(), &planes);
    assert_eq!(pieces.len(), 8, "each cut splits every piece it meets");
    for piece in &pieces {
        for p in piece.used_points() {
            assert!(in_u_prism(p, 1e-12), "corner {p} outside the U");
        }
    }
    let total: f64 = pieces.iter().map(Piece::volume).sum();
    assert!((total - whole.volume()).abs() < 1e-12, "{total}");
}

#[test]
fn random_cuts_of_a_u_leave_every_corner_in_the_solid() {
    let mut r = rng(3302);
    let whole = solid_piece(&u_prism());
    let centre = DVec3::new(1.5, 1.0, 0.5);
    let (mut corners, mut split) = (0, 0);
    for _ in 0..300 {
        let planes: Vec<Plane> = (0..3)
            .map(|_| {
                let plane = random_plane(&mut r, 1.0);
                Plane {
                    offset: plane.offset + plane.normal.dot(centre),
                    ..plane
                }
            })
            .collect();
        let pieces = cut_all(whole.clone(), &planes);
        split += usize::from(pieces.len() > 4);
        for piece in &pieces {
            for p in piece.used_points() {
                corners += 1;
                assert!(
                    in_u_prism(p, 1e-9),
                    "corner {p} outside the U, planes {planes:?}"
                );
            }
        }
        let total: f64 = pieces.iter().map(Piece::volume).sum();
        assert!((total - whole.volume()).abs() < 1e-9, "{total}");
    }
    assert!(
        split > 50 && corners > 10_000,
        "{split} splits, {corners} corners"
    );
}

#[test]
fn cuts_along_faces_leave_pieces_whose_hulls_hold_only_their_solid() {
    // Rectilinear prisms cut by every axis plane through their vertices' coordinates (and
    // at ½ along each axis), in random order and orientation, some turned and moved off the
    // origin: every piece is one cell of that grid, a box, whose hull is exactly its solid.
    // A face along a plane sent to the side its solid is not on would be closed there by a
    // cap over it: a zero-volume fin whose corners stretch that piece's hull across a notch.
    let mut r = rng(3303);
    let (mut turned, mut reversed, mut pieces_seen) = (0, 0, 0);
    for mesh in [u_prism(), l_prism(), comb_prism(3), stairs_prism()] {
        let bounds = crate::math::bounds_of(mesh.vertices().iter().copied());
        let mut planes = Vec::new();
        for axis in 0..3 {
            let mut at: Vec<f64> = mesh.vertices().iter().map(|v| v[axis]).collect();
            at.push(0.5);
            at.sort_by(f64::total_cmp);
            at.dedup();
            at.retain(|&c| c > bounds.0[axis] && c < bounds.1[axis]);
            planes.extend(at.into_iter().map(|c| (DVec3::AXES[axis], c)));
        }
        let cells = grid_cells_inside(&mesh, &planes, bounds);
        for round in 0..20 {
            // Half the rounds turn and move the prism (and its planes) by a random pose.
            let pose = if round % 2 == 1 {
                turned += 1;
                (rotation(&mut r), point_in_cube(&mut r, 50.0))
            } else {
                (DQuat::IDENTITY, DVec3::ZERO)
            };
            let moved = mesh_moved(&mesh, pose);
            let mut cuts: Vec<Plane> = planes
                .iter()
                .map(|&(axis, c)| {
                    let normal = pose.0 * axis;
                    let offset = normal.dot(pose.0 * (axis * c) + pose.1);
                    if r.random_bool(0.5) {
                        reversed += 1;
                        Plane {
                            normal: -normal,
                            offset: -offset,
                        }
                    } else {
                        Plane { normal, offset }
                    }
                })
                .collect();
            cuts.shuffle(&mut r);
            let whole = solid_piece(&moved);
            let pieces = cut_all(whole.clone(), &cuts);
            assert_eq!(
                pieces.len(),
                cells,
                "one piece per solid cell, round {round}"
            );
            for piece in &pieces {
                let (solid, hull) = (piece.volume(), QuickHull::of(piece.used_points()).volume());
                assert!(
                    solid > 0.1 && (hull - solid).abs() <= 1e-9,
                    "a cell of solid {solid} has a hull of {hull}, round {round}"
                );
                pieces_seen += 1;
            }
            let total: f64 = pieces.iter().map(Piece::volume).sum();
            assert!((total - whole.volume()).abs() <= 1e-9, "{total}");
        }
    }
    assert!(turned > 10 && reversed > 100 && pieces_seen > 500);
}

/// How many cells of the grid the axis-aligned `planes` make of `bounds` have their centre
/// inside `mesh`.
fn grid_cells_inside(mesh: &TriMesh, planes: &[(DVec3, f64)], bounds: (DVec3, DVec3)) -> usize {
    let ticks = |axis: usize| {
        let mut at = vec![bounds.0[axis], bounds.1[axis]];
        at.extend(
            planes
                .iter()
                .filter(|(a, _)| a[axis] == 1.0)
                .map(|&(_, c)| c),
        );
        at.sort_by(f64::total_cmp);
        at.windows(2)
            .map(|w| (w[0] + w[1]) / 2.0)
            .collect::<Vec<f64>>()
    };
    let (xs, ys, zs) = (ticks(0), ticks(1), ticks(2));
    let mut inside = 0;
    for &x in &xs {
        for &y in &ys {
            for &z in &zs {
                inside += usize::from(winding_number(mesh, DVec3::new(x, y, z)) > 0.5);
            }
        }
    }
    inside
}

fn mesh_moved(mesh: &TriMesh, (turn, shift): (DQuat, DVec3)) -> TriMesh {
    let vertices = mesh.vertices().iter().map(|&v| turn * v + shift).collect();
    crate::test_support::meshes::mesh(vertices, mesh.triangles().to_vec())
}

/// Bars tried below, at and above a full measure, as fractions of it.
pub(super) const BAR_FRACTIONS: [f64; 7] = [0.0, 0.3, 0.9, 0.999, 1.0, 1.001, 2.0];

/// Checks a measure taken up to `bar` against the `full` one: the same when `full` is within
/// the bar, otherwise above the bar and no more than `full`. Counts the case in
/// `(within, above)`.
pub(super) fn check_barred(
    full: f64,
    bar: f64,
    barred: f64,
    counts: &mut (usize, usize),
    at: &str,
) {
    if full <= bar {
        counts.0 += 1;
        assert_eq!(barred.to_bits(), full.to_bits(), "{at}, bar {bar}");
    } else {
        counts.1 += 1;
        assert!(
            barred > bar && barred <= full,
            "{at}: {barred} for bar {bar}, in full {full}"
        );
    }
}

/// The concavity measured up to a bar is the concavity when that is within the bar, and
/// otherwise a value above the bar and no more than the concavity: on random halves of a
/// torus, a comb and a sphere and on their unions, at bars below, at and above each
/// concavity.
#[test]
fn a_concavity_measured_up_to_a_bar_is_exact_within_it_and_bounded_above_it() {
    let mut r = rng(5301);
    let solids = [
        (solid_piece(&torus(1.0, 0.3, 24, 12)), 1.3),
        (solid_piece(&comb_prism(3)), 2.0),
        (solid_piece(&uv_sphere(1.0, 16, 8)), 1.0),
    ];
    let mut counts = (0, 0);
    for round in 0..60 {
        let (solid, half) = &solids[round % solids.len()];
        let Some((a, b)) = solid.cut(&random_plane(&mut r, 0.5 * half)) else {
            continue;
        };
        for half in [&a, &b] {
            let Some(full) = Fitted::new(half.clone(), 0.05).map(|h| h.concavity) else {
                continue;
            };
            for bar in BAR_FRACTIONS.map(|f| f * full) {
                let barred = Fitted::new_up_to(half.clone(), 0.05, bar).expect("measured");
                let at = format!("round {round}, a half");
                check_barred(full, bar, barred.concavity, &mut counts, &at);
            }
        }
        let (Some(a), Some(b)) = (Fitted::new(a, 0.05), Fitted::new(b, 0.05)) else {
            continue;
        };
        let full = a.merged(&b).concavity;
        assert!(full > 0.0, "round {round}: no concavity to measure");
        for bar in BAR_FRACTIONS
            .map(|f| f * full)
            .into_iter()
            .chain([f64::INFINITY])
        {
            let barred = a.union_concavity(&b, bar);
            check_barred(full, bar, barred, &mut counts, &format!("round {round}"));
        }
    }
    assert!(
        counts.0 > 400 && counts.1 > 400,
        "{counts:?} (within, above)"
    );
}
