//! Contract of `TriMesh`: validation rejects bad input with the right error, OBJ and STL
//! round-trip procedural meshes, the report finds degenerate triangles, and the real meshes
//! load with their known counts.
mod support;

use proxima::geometry::mesh::ParseReason;
use proxima::geometry::{MeshError, MeshLimits, TriMesh};
use proxima::math::DVec3;
use rand::Rng;
use support::{point_in_cube, rng};

/// A box `[-1, 1]³` with each face split into `n × n` quads (two triangles each), welded.
fn subdivided_box(n: u32) -> TriMesh {
    let mut vertices = Vec::new();
    let mut index = std::collections::HashMap::new();
    let mut triangles = Vec::new();
    let mut vid = |p: DVec3, vertices: &mut Vec<DVec3>| {
        let key = p.to_array().map(|x| (x * 1e6).round() as i64);
        *index.entry(key).or_insert_with(|| {
            vertices.push(p);
            (vertices.len() - 1) as u32
        })
    };
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let n_axis = DVec3::AXES[axis] * sign;
            let (u, v) = (DVec3::AXES[(axis + 1) % 3], DVec3::AXES[(axis + 2) % 3]);
            let (u, v) = if sign > 0.0 { (u, v) } else { (v, u) };
            let at = |i: u32, j: u32| {
                n_axis
                    + u * (2.0 * i as f64 / n as f64 - 1.0)
                    + v * (2.0 * j as f64 / n as f64 - 1.0)
            };
            for i in 0..n {
                for j in 0..n {
                    let a = vid(at(i, j), &mut vertices);
                    let b = vid(at(i + 1, j), &mut vertices);
                    let c = vid(at(i + 1, j + 1), &mut vertices);
                    let d = vid(at(i, j + 1), &mut vertices);
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
    }
    TriMesh::try_new(vertices, triangles).unwrap()
}

/// A UV sphere of radius `r` with `rings` latitude bands and `segments` longitude bands.
fn uv_sphere(r: f64, rings: u32, segments: u32) -> TriMesh {
    let mut vertices = vec![DVec3::Z * r, -DVec3::Z * r];
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = std::f64::consts::TAU * j as f64 / segments as f64;
            vertices.push(
                DVec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ) * r,
            );
        }
    }
    let ring = |i: u32, j: u32| 2 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([1, ring(rings - 1, j + 1), ring(rings - 1, j)]);
        for i in 1..rings - 1 {
            let (a, b) = (ring(i, j), ring(i, j + 1));
            let (c, d) = (ring(i + 1, j), ring(i + 1, j + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    TriMesh::try_new(vertices, triangles).unwrap()
}

fn signed_volume(m: &TriMesh) -> f64 {
    (0..m.triangle_count())
        .map(|i| {
            let t = m.triangle(i);
            t.a.dot(t.b.cross(t.c)) / 6.0
        })
        .sum()
}

#[test]
fn procedural_meshes_are_closed_and_outward() {
    let b = subdivided_box(4);
    assert_eq!(b.triangle_count(), 6 * 16 * 2);
    assert_eq!(b.vertex_count(), 6 * 16 + 2);
    let report = b.report();
    assert!(report.closed && report.degenerate_triangles.is_empty());
    assert_eq!(report.unreferenced_vertices, 0);
    assert!((signed_volume(&b) - 8.0).abs() < 1e-12);
    let s = uv_sphere(2.0, 12, 24);
    assert!(s.report().closed);
    assert!(signed_volume(&s) > 0.0);
    let (lo, hi) = s.bounds();
    assert_eq!((lo.z, hi.z), (-2.0, 2.0));
    assert!((hi - DVec3::splat(2.0)).abs().max_element() < 1e-12);
}

#[test]
fn obj_round_trip_is_exact() {
    let mut r = rng(1);
    for n in 1..6 {
        let meshes = [
            subdivided_box(n),
            uv_sphere(r.random_range(0.1..10.0), 3 + n, 4 + 2 * n),
        ];
        for m in meshes {
            let moved = m
                .scaled(r.random_range(1e-3..1e3))
                .translated(point_in_cube(&mut r, 1e6));
            let back = TriMesh::from_obj_str(&moved.to_obj_string()).unwrap();
            assert_eq!(back, moved);
        }
    }
}

#[test]
fn stl_round_trip_welds_back_to_the_same_mesh() {
    for m in [subdivided_box(3), uv_sphere(1.5, 8, 16)] {
        let bytes = m.to_stl_binary();
        assert_eq!(bytes.len(), 84 + 50 * m.triangle_count());
        let back = TriMesh::from_stl_bytes(&bytes).unwrap();
        assert_eq!(back.triangle_count(), m.triangle_count());
        assert_eq!(back.vertex_count(), m.vertex_count());
        for i in 0..m.triangle_count() {
            let (a, b) = (m.triangle(i), back.triangle(i));
            for (p, q) in a.vertices().iter().zip(b.vertices()) {
                assert!((*p - q).length() <= 1e-6 * p.length().max(1.0));
            }
        }
        assert!(back.report().closed);
    }
}

#[test]
fn binary_stl_starting_with_solid_is_still_binary() {
    let m = subdivided_box(1);
    let mut bytes = m.to_stl_binary();
    bytes[..5].copy_from_slice(b"solid");
    let back = TriMesh::from_stl_bytes(&bytes).unwrap();
    assert_eq!(back.triangle_count(), 12);
    assert_eq!(back.vertex_count(), 8);
}

#[test]
fn ascii_stl_is_read_and_welded() {
    let text = "solid two\n\
        facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 1 1 0\n endloop\nendfacet\n\
        facet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 1 0\n  vertex 0 1 0\n endloop\nendfacet\n\
        endsolid two\n";
    let m = TriMesh::from_stl_bytes(text.as_bytes()).unwrap();
    assert_eq!(m.triangle_count(), 2);
    assert_eq!(m.vertex_count(), 4);
    assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
    let bad = text.replace(
        "vertex 1 1 0\n endloop\nendfacet\nfacet",
        "vertex 1 x 0\n endloop\nendfacet\nfacet",
    );
    assert_eq!(
        TriMesh::from_stl_bytes(bad.as_bytes()),
        Err(MeshError::Parse {
            line: 6,
            reason: ParseReason::BadNumber
        })
    );
    let short = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n";
    assert_eq!(
        TriMesh::from_stl_bytes(short.as_bytes()),
        Err(MeshError::Parse {
            line: 6,
            reason: ParseReason::IncompleteFacet
        })
    );
    assert_eq!(
        TriMesh::from_stl_bytes(b"not a mesh at all"),
        Err(MeshError::Parse {
            line: 0,
            reason: ParseReason::NotStl
        })
    );
}

#[test]
fn every_construction_error_is_reported() {
    let tri = vec![[0, 1, 2]];
    let three = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
    assert_eq!(
        TriMesh::try_new(three.clone(), vec![]),
        Err(MeshError::Empty)
    );
    let mut nan = three.clone();
    nan[1].y = f64::NAN;
    assert_eq!(
        TriMesh::try_new(nan, tri.clone()),
        Err(MeshError::NonFiniteVertex { index: 1 })
    );
    let mut huge = three.clone();
    huge[2].z = -2e9;
    assert_eq!(
        TriMesh::try_new(huge, tri.clone()),
        Err(MeshError::CoordinateTooLarge { index: 2 })
    );
    let err = TriMesh::try_new(three.clone(), vec![[0, 1, 2], [0, 3, 1]]).unwrap_err();
    assert_eq!(
        err,
        MeshError::IndexOutOfRange {
            triangle: 1,
            index: 3,
            vertex_count: 3
        }
    );
    assert!(err.to_string().contains("triangle 1"));
    let limits = MeshLimits {
        max_vertices: 2,
        max_triangles: 10,
    };
    assert_eq!(
        TriMesh::try_new_with_limits(three.clone(), tri.clone(), &limits),
        Err(MeshError::TooManyVertices { count: 3, limit: 2 })
    );
    let limits = MeshLimits {
        max_vertices: 10,
        max_triangles: 1,
    };
    assert_eq!(
        TriMesh::try_new_with_limits(three.clone(), vec![[0, 1, 2]; 2], &limits),
        Err(MeshError::TooManyTriangles { count: 2, limit: 1 })
    );
    assert!(TriMesh::try_new_with_limits(three, tri, &MeshLimits::standard()).is_ok());
    assert_eq!(MeshLimits::default(), MeshLimits::standard());
}

#[test]
fn obj_parse_errors_name_the_line() {
    let cases: [(&str, usize, ParseReason); 6] = [
        ("v 0 0 0\nv 1 0\n", 2, ParseReason::MissingCoordinate),
        ("v 0 0 0\nv 1 zero 0\n", 2, ParseReason::BadNumber),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
            4,
            ParseReason::FaceTooShort,
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 0 2\n",
            5,
            ParseReason::BadIndex,
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x/1\n",
            4,
            ParseReason::BadIndex,
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            4,
            ParseReason::RelativeIndexOutOfRange,
        ),
    ];
    for (text, line, reason) in cases {
        let err = TriMesh::from_obj_str(text).unwrap_err();
        assert_eq!(err, MeshError::Parse { line, reason }, "{text:?}");
        assert!(err.to_string().contains(&format!("line {line}")));
    }
    assert_eq!(TriMesh::from_obj_str("v 0 0 0\n"), Err(MeshError::Empty));
    assert_eq!(
        TriMesh::from_obj_str("v 0 0 0\nf 1 2 3\n"),
        Err(MeshError::IndexOutOfRange {
            triangle: 0,
            index: 1,
            vertex_count: 1
        })
    );
}

#[test]
fn load_checks_extension_and_io() {
    let dir = std::env::temp_dir().join(format!("proxima-mesh-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let m = uv_sphere(1.0, 6, 8);
    std::fs::write(dir.join("s.OBJ"), m.to_obj_string()).unwrap();
    std::fs::write(dir.join("s.Stl"), m.to_stl_binary()).unwrap();
    assert_eq!(TriMesh::load(dir.join("s.OBJ")).unwrap(), m);
    assert_eq!(
        TriMesh::load(dir.join("s.Stl")).unwrap().triangle_count(),
        m.triangle_count()
    );
    assert_eq!(
        TriMesh::load(dir.join("s.ply")),
        Err(MeshError::UnknownExtension)
    );
    assert_eq!(
        TriMesh::load(dir.join("missing.obj")),
        Err(MeshError::Io {
            kind: std::io::ErrorKind::NotFound
        })
    );
    let limits = MeshLimits {
        max_vertices: 1 << 20,
        max_triangles: 10,
    };
    assert!(matches!(
        TriMesh::load_with_limits(dir.join("s.OBJ"), &limits),
        Err(MeshError::TooManyTriangles { limit: 10, .. })
    ));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn report_lists_degenerate_triangles_and_unused_vertices() {
    let mut r = rng(9);
    for case in 0..1000 {
        let center = point_in_cube(&mut r, [0.0, 1.0, 1e3, 1e6][case % 4]);
        let scale = [1e-4, 1e-2, 1.0, 1e2, 1e4][case % 5];
        let mut vertices: Vec<DVec3> = (0..6)
            .map(|_| center + point_in_cube(&mut r, scale))
            .collect();
        // Vertex 6 lies on segment 0-1 (zero area with 0 and 1); 7 is never used.
        vertices.push(vertices[0] + (vertices[1] - vertices[0]) * 0.5);
        vertices.push(center);
        let triangles = vec![[0, 1, 2], [3, 3, 4], [0, 6, 1], [2, 4, 5], [5, 2, 5]];
        let m = TriMesh::try_new(vertices, triangles).unwrap();
        let report = m.report();
        assert_eq!(report.degenerate_triangles, vec![1, 2, 4], "case {case}");
        assert_eq!(report.unreferenced_vertices, 1);
        assert!(!report.closed);
        assert_eq!(report.bounds, m.bounds());
    }
}

#[test]
fn transforms_move_and_scale_the_bounds() {
    let m = uv_sphere(1.0, 8, 16)
        .translated(DVec3::new(5.0, -3.0, 2.0))
        .scaled(2.0);
    let (lo, hi) = m.bounds();
    assert!(((lo + hi) * 0.5 - DVec3::new(10.0, -6.0, 4.0)).length() < 1e-12);
    let c = m.centered_on_bounds();
    let (lo, hi) = c.bounds();
    assert!((lo + hi).length() < 1e-12);
    assert!((hi - lo - DVec3::splat(4.0)).abs().max_element() < 1e-12);
}

#[test]
fn real_meshes_load_with_their_known_counts() {
    let Some(dir) = support::data::data_dir_or_skip("real_meshes_load_with_their_known_counts")
    else {
        return;
    };
    let dir = dir.join("meshes");
    let expected = [
        ("env.obj", 2180, 6540),
        ("rob.obj", 216, 648),
        ("stanford-bunny.obj", 69451, 35947),
        ("fandisk.obj", 12946, 6475),
        ("spot.obj", 5856, 2930),
    ];
    for (name, triangles, vertices) in expected {
        let m = TriMesh::load(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.triangle_count(), triangles, "{name}");
        assert_eq!(m.vertex_count(), vertices, "{name}");
        let report = m.report();
        let (lo, hi) = report.bounds;
        assert!(lo.cmple(hi).all(), "{name}");
        if name == "spot.obj" || name == "fandisk.obj" {
            assert!(report.closed, "{name} is closed");
        }
        let back = TriMesh::from_obj_str(&m.to_obj_string()).unwrap();
        assert_eq!(back, m, "{name}");
    }
}
