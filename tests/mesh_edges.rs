//! Contract of `MeshEdges` (edge adjacency and bends, for ghost-normal removal) against an
//! independent oracle on procedural, random and real meshes: neighbours from a plain map of
//! undirected edges, bends from the exact orientation predicate (the neighbour's far vertex
//! below the triangle's plane: convex; above: concave), flatness and folds from the angle
//! between the two triangles' half-planes (no normals, no winding).
#[path = "support/mod.rs"]
mod support;

use proxima::geometry::TriMesh;
use proxima::geometry::mesh::{EdgeKind, FLAT_EDGE_ANGLE, MeshEdges, NO_NEIGHBOUR};
use proxima::geometry::predicates::orient3d;
use proxima::math::DVec3;
use rand::Rng;
use std::collections::HashMap;
use support::{meshes, rng};

/// How many edges of each kind a mesh has (counted per triangle side).
#[derive(Debug, Default)]
struct Census {
    open: usize,
    convex: usize,
    flat: usize,
    concave: usize,
}

/// Checks every triangle edge of `mesh` against the oracle and returns the census.
fn check(mesh: &TriMesh) -> Census {
    let edges = MeshEdges::new(mesh);
    assert_eq!(edges.triangle_count(), mesh.triangle_count());
    let tris = mesh.triangles();
    let v = mesh.vertices();
    let mut users: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
    for (t, tri) in tris.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            users.entry((a.min(b), a.max(b))).or_default().push(t);
        }
    }
    let mut census = Census::default();
    let mut exposed = vec![[false; 2]; mesh.vertex_count()];
    for (t, tri) in tris.iter().enumerate() {
        let e = edges.triangle(t);
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let kind = e.kinds[k];
            match kind {
                EdgeKind::Open => census.open += 1,
                EdgeKind::Convex => census.convex += 1,
                EdgeKind::Flat => census.flat += 1,
                EdgeKind::Concave => census.concave += 1,
            }
            for (side, bent) in [(0, EdgeKind::Convex), (1, EdgeKind::Concave)] {
                if kind == EdgeKind::Open || kind == bent {
                    exposed[a as usize][side] = true;
                    exposed[b as usize][side] = true;
                }
            }
            let sharing = &users[&(a.min(b), a.max(b))];
            let normal = mesh.triangle(t).normal();
            let other = sharing.iter().copied().find(|&u| u != t);
            let single = sharing.len() == 2 && a != b;
            let (Some(_), Some(u), true) = (normal, other, single) else {
                assert_eq!(kind, EdgeKind::Open, "triangle {t} edge {k}");
                assert_eq!(e.neighbours[k], NO_NEIGHBOUR);
                continue;
            };
            if mesh.triangle(u).normal().is_none() {
                assert_eq!(kind, EdgeKind::Open, "triangle {t} edge {k}");
                continue;
            }
            // The half-planes of both triangles, as directions across the edge.
            let (pa, pb) = (v[a as usize], v[b as usize]);
            let along = (pb - pa).normalize();
            let across = |p: DVec3| {
                let w = p - pa;
                w - along * w.dot(along)
            };
            let own = tri.iter().copied().find(|&i| i != a && i != b).unwrap();
            let far = tris[u].into_iter().find(|&i| i != a && i != b).unwrap();
            let (wt, wu) = (across(v[own as usize]), across(v[far as usize]));
            // π for a flat continuation, 0 for a fold back onto the triangle.
            let opening = wt.cross(wu).length().atan2(wt.dot(wu));
            let bend = std::f64::consts::PI - opening;
            let below = orient3d(
                v[tri[0] as usize],
                v[tri[1] as usize],
                v[tri[2] as usize],
                v[far as usize],
            );
            if bend > 2.0 * FLAT_EDGE_ANGLE && opening > 2.0 * FLAT_EDGE_ANGLE {
                assert_eq!(e.neighbours[k], u as u32, "triangle {t} edge {k}");
                let want = if below < 0.0 {
                    EdgeKind::Convex
                } else {
                    EdgeKind::Concave
                };
                assert_eq!(kind, want, "triangle {t} edge {k}: bend {bend}");
            } else if bend < 0.5 * FLAT_EDGE_ANGLE {
                assert_eq!(kind, EdgeKind::Flat, "triangle {t} edge {k}");
            } else if opening < 0.5 * FLAT_EDGE_ANGLE {
                assert_eq!(kind, EdgeKind::Open, "triangle {t} edge {k}: a fold");
            }
        }
    }
    for (i, want) in exposed.iter().enumerate() {
        assert_eq!(edges.vertex_exposed(i as u32, true), want[0], "vertex {i}");
        assert_eq!(edges.vertex_exposed(i as u32, false), want[1], "vertex {i}");
    }
    census
}

/// A random height field over `n × n` squares: bumps and dips, so convex and concave
/// internal edges, flat-free.
fn terrain(seed: u64, n: u32) -> TriMesh {
    let mut rng = rng(seed);
    let vertices = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| DVec3::new(f64::from(i), f64::from(j), rng.random_range(-0.3..0.3)))
        .collect();
    let id = |i: u32, j: u32| i * (n + 1) + j;
    let mut tris = Vec::new();
    for i in 0..n {
        for j in 0..n {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    meshes::mesh(vertices, tris)
}

#[test]
fn closed_convex_meshes_have_only_convex_and_flat_edges() {
    let sphere = check(&meshes::uv_sphere(1.5, 24, 12));
    assert_eq!(sphere.open + sphere.concave, 0, "{sphere:?}");
    assert!(sphere.convex > 0);
    let cube = check(&meshes::subdivided_cuboid(DVec3::new(1.0, 0.5, 2.0), 4));
    assert_eq!(cube.open + cube.concave, 0, "{cube:?}");
    // 12 box edges of 4 segments, each seen from both sides.
    assert_eq!(cube.convex, 12 * 4 * 2, "{cube:?}");
}

#[test]
fn open_and_bent_surfaces_match_the_orientation_oracle() {
    let grid = check(&meshes::grid(3.0, 12));
    assert_eq!(grid.convex + grid.concave, 0, "{grid:?}");
    assert_eq!(grid.open, 4 * 12, "{grid:?}");
    let torus = check(&meshes::torus(1.0, 0.4, 32, 16));
    assert!(
        torus.convex > 0 && torus.concave > 0 && torus.open == 0,
        "{torus:?}"
    );
    for seed in 0..20 {
        let t = check(&terrain(600 + seed, 10));
        assert!(t.convex > 20 && t.concave > 20, "{t:?}");
    }
}

#[test]
fn soups_zero_area_triangles_and_real_meshes_match_the_oracle() {
    let mut rng = rng(601);
    check(&meshes::triangle_soup(&mut rng, 300, 2.0, 0.8));
    check(&meshes::zero_area_triangles(&mut rng, 100, 1.0));
    check(&meshes::with_zero_area_triangles(
        &mut rng,
        DVec3::splat(1.0),
        40,
    ));
    let spot = check(&meshes::data_mesh("spot.obj"));
    assert!(spot.convex > 0 && spot.concave > 0, "{spot:?}");
    // FCL's robot is an unwelded soup: every edge open.
    let rob = check(&meshes::data_mesh("rob.obj"));
    assert_eq!(rob.convex + rob.flat + rob.concave, 0, "{rob:?}");
}
