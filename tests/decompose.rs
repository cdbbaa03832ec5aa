//! Convex decomposition's contracts (`proxima::decompose`), on procedural closed meshes and,
//! when `PROXIMA_DATA` has them, the shared real meshes:
//! - the parts cover the solid: every mesh vertex, and seeded random points inside the mesh
//!   (by its winding number, an independent oracle), lie in the union of the hulls;
//! - the parts' solid volumes add up to the mesh's volume;
//! - each part's reported concavity is what the options allowed, unless the part count ran
//!   out; a convex mesh is one part, an L two, a U three;
//! - the thread count does not change the parts;
//! - bad input is an error, not a panic.

mod support;

use proxima::decompose::{DecomposeError, Decomposition, Method, Options, decompose};
use proxima::geometry::TriMesh;
use proxima::math::DVec3;
use support::meshes::{self, cuboid, l_prism, torus, u_prism, uv_sphere, winding_number};
use support::{point_in_cube, rng};

fn in_union(d: &Decomposition, p: DVec3) -> bool {
    d.parts.iter().any(|part| part.hull.contains_point(p))
}

/// Checks coverage and volumes; returns (inside points tried, outside points seen).
fn assert_covers(name: &str, mesh: &TriMesh, d: &Decomposition, seed: u64) -> (usize, usize) {
    assert!(!d.parts.is_empty(), "{name}: no parts");
    for (i, &v) in mesh.vertices().iter().enumerate() {
        assert!(in_union(d, v), "{name}: vertex {i} {v} outside every hull");
    }
    let parts_volume: f64 = d.parts.iter().map(|p| p.volume).sum();
    assert!(
        (parts_volume - d.mesh_volume).abs() <= 1e-9 * d.mesh_volume,
        "{name}: parts hold {parts_volume} m³ of {}",
        d.mesh_volume
    );
    let (lo, hi) = mesh.bounds();
    let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
    let mut r = rng(seed);
    let (mut inside, mut outside) = (0, 0);
    for _ in 0..400 {
        let p = centre + point_in_cube(&mut r, 1.0) * half;
        if winding_number(mesh, p) > 0.5 {
            inside += 1;
            assert!(
                in_union(d, p),
                "{name}: inside point {p} outside every hull"
            );
        } else {
            outside += 1;
        }
    }
    (inside, outside)
}

fn options(method: Method, max_concavity: f64, max_parts: usize) -> Options {
    Options {
        method,
        max_concavity,
        max_parts,
        ..Options::default()
    }
}

#[test]
fn parts_cover_procedural_solids_with_both_methods() {
    let solids = [
        ("torus", torus(1.0, 0.3, 32, 16)),
        ("L", l_prism()),
        ("U", u_prism()),
        ("sphere", uv_sphere(1.0, 24, 12)),
        ("box", cuboid(DVec3::new(1.0, 0.2, 0.5))),
    ];
    let (mut inside, mut outside) = (0, 0);
    for (seed, (name, mesh)) in solids.iter().enumerate() {
        for method in Method::ALL {
            let d = decompose(mesh, &options(method, 0.02, 16)).expect("closed solid");
            let (i, o) = assert_covers(name, mesh, &d, 3400 + seed as u64);
            inside += i;
            outside += o;
        }
    }
    assert!(
        inside > 500 && outside > 500,
        "inside {inside}, outside {outside}"
    );
}

#[test]
fn cut_search_finds_the_fewest_convex_parts_of_simple_solids() {
    for (name, mesh, parts) in [
        ("sphere", uv_sphere(1.0, 24, 12), 1),
        ("box", cuboid(DVec3::ONE), 1),
        ("L", l_prism(), 2),
        ("U", u_prism(), 3),
    ] {
        let d = decompose(&mesh, &options(Method::CutSearch, 0.01, 16)).expect("solid");
        assert_eq!(d.parts.len(), parts, "{name}");
        let (lo, hi) = mesh.bounds();
        assert!(
            d.concavity <= 0.01 * (hi - lo).length(),
            "{name}: {}",
            d.concavity
        );
    }
}

#[test]
fn concavity_is_within_the_limit_when_parts_are_ample() {
    let mesh = torus(1.0, 0.3, 32, 16);
    let diagonal = {
        let (lo, hi) = mesh.bounds();
        (hi - lo).length()
    };
    // 64 parts are ample for a torus at these limits; 4 are not.
    for (limit, max_parts, ample) in [(0.05, 64, true), (0.02, 64, true), (0.02, 4, false)] {
        let d = decompose(&mesh, &options(Method::CutSearch, limit, max_parts)).expect("torus");
        assert!(d.parts.len() <= max_parts);
        let within = d.concavity <= limit * diagonal;
        assert!(
            within || !ample,
            "limit {limit}: concavity {} with {} parts",
            d.concavity / diagonal,
            d.parts.len()
        );
        // A torus is not convex: one part cannot do.
        assert!(d.parts.len() > 1);
    }
}

#[test]
fn the_thread_count_does_not_change_the_parts() {
    let mesh = torus(1.0, 0.3, 32, 16);
    for method in [Method::CutSearch, Method::Relaxation] {
        let with = |threads: usize| {
            let options = Options {
                threads,
                ..options(method, 0.02, 64)
            };
            decompose(&mesh, &options).expect("torus")
        };
        let one = with(1);
        assert!(one.parts.len() > 1, "a torus is not convex");
        for threads in [2, 3] {
            let many = with(threads);
            assert_eq!(
                many.parts.len(),
                one.parts.len(),
                "{method:?}, {threads} threads"
            );
            for (a, b) in one.parts.iter().zip(&many.parts) {
                let at = format!("{method:?}, {threads} threads");
                assert_eq!(a.volume.to_bits(), b.volume.to_bits(), "{at}");
                assert_eq!(a.concavity.to_bits(), b.concavity.to_bits(), "{at}");
                assert_eq!(a.hull.vertices(), b.hull.vertices(), "{at}");
            }
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    let flat = meshes::grid(1.0, 4);
    assert!(matches!(
        decompose(&flat, &Options::default()),
        Err(DecomposeError::NotSolid { .. })
    ));
    let cube = cuboid(DVec3::ONE);
    for bad in [
        options(Method::CutSearch, 0.0, 8),
        options(Method::CutSearch, f64::NAN, 8),
        options(Method::Relaxation, 0.02, 0),
    ] {
        assert_eq!(
            decompose(&cube, &bad).err(),
            Some(DecomposeError::BadOptions)
        );
    }
}

#[test]
fn parts_cover_the_shared_real_meshes() {
    let mut ran = 0;
    for file in ["spot.obj", "fandisk.obj", "rob.obj", "env.obj"] {
        let Some(mesh) = meshes::shared_data_mesh("decompose real meshes", file) else {
            continue;
        };
        let d = decompose(&mesh, &options(Method::CutSearch, 0.05, 8)).expect("repairable");
        assert!(d.parts.len() <= 8);
        for (i, &v) in mesh.vertices().iter().enumerate() {
            assert!(in_union(&d, v), "{file}: vertex {i} {v} outside every hull");
        }
        let parts_volume: f64 = d.parts.iter().map(|p| p.volume).sum();
        assert!((parts_volume - d.mesh_volume).abs() <= 1e-9 * d.mesh_volume.abs());
        ran += 1;
    }
    if ran == 0 {
        println!("decompose real meshes: no shared data, nothing ran");
    }
}
