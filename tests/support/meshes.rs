//! Procedural meshes for the integration tests and benches (the single home of them), and
//! the real meshes kept in `tests/data`.
//!
//! Closed solids ([`uv_sphere`], [`torus`], [`cuboid`], [`subdivided_cuboid`], and the
//! concave prisms [`prism`], [`l_prism`], [`u_prism`]) are welded
//! (neighbouring triangles share vertex indices) and oriented counter-clockwise seen from
//! outside. [`grid`] is an open surface of many coplanar triangles, [`triangle_soup`] an
//! unwelded set of random triangles, [`zero_area_triangles`] a set of nothing but point- and
//! segment-like triangles, and [`with_zero_area_triangles`] a closed box with such triangles
//! mixed in. Everything random takes the caller's seeded [`TestRng`]. Where a test needs
//! bare triangles, [`triangles`] lists a mesh's; move or scale a mesh with
//! `TriMesh::translated` and `TriMesh::scaled`.

use super::{TestRng, point_in_cube};
use proxima::geometry::{TriMesh, Triangle};
use proxima::math::{DVec3, Pose};
use proxima::narrow::distance_triangle_triangle;
use rand::Rng;
use rand::seq::SliceRandom;
use std::collections::HashMap;
use std::path::PathBuf;

/// A mesh from vertices and index triples the generators made (valid by construction).
pub fn mesh(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> TriMesh {
    TriMesh::try_new(vertices, triangles).expect("procedural mesh is valid")
}

/// Generalised winding number of the closed `mesh` about `p` (solid angles, Van Oosterom
/// and Strackee): 1 inside, 0 outside. An oracle independent of every query.
pub fn winding_number(mesh: &TriMesh, p: DVec3) -> f64 {
    let mut total = 0.0;
    for i in 0..mesh.triangle_count() {
        let t = mesh.triangle(i);
        let (a, b, c) = (t.a - p, t.b - p, t.c - p);
        let (la, lb, lc) = (a.length(), b.length(), c.length());
        let numerator = a.dot(b.cross(c));
        let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2.0 * numerator.atan2(denominator);
    }
    total / (4.0 * std::f64::consts::PI)
}

/// The smallest distance over every triangle pair of `a` and `b` placed by `pose_ab`, in
/// f64: the brute-force oracle of mesh distance.
pub fn brute_force_distance(a: &TriMesh, b: &TriMesh, pose_ab: &Pose) -> f64 {
    let iso = pose_ab.to_isometry();
    let moved: Vec<Triangle> = (0..b.triangle_count())
        .map(|j| b.triangle(j).transformed(&iso))
        .collect();
    (0..a.triangle_count())
        .flat_map(|i| {
            let ta = a.triangle(i);
            moved
                .iter()
                .map(move |tb| distance_triangle_triangle(&ta, tb).distance)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The triangles of `mesh`, in its own order (index `i` is triangle id `i`).
pub fn triangles(mesh: &TriMesh) -> Vec<Triangle> {
    (0..mesh.triangle_count())
        .map(|i| mesh.triangle(i))
        .collect()
}

/// Largest distance of a vertex of `mesh` from its frame's origin, metres.
pub fn reach(mesh: &TriMesh) -> f64 {
    mesh.vertices()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f64::max)
}

/// Closed UV sphere: see `TriMesh::uv_sphere`.
pub fn uv_sphere(radius: f64, segments: u32, rings: u32) -> TriMesh {
    TriMesh::uv_sphere(radius, segments, rings)
}

/// Closed torus about the z axis: see `TriMesh::torus`.
pub fn torus(major: f64, minor: f64, around: u32, across: u32) -> TriMesh {
    TriMesh::torus(major, minor, around, across)
}

/// The closed prism over a simple counter-clockwise polygon `outline` (x, y, metres), from
/// `z = 0` to `height`, its caps ear-clipped. Welded, oriented outward, so its enclosed
/// volume is exact.
///
/// # Panics
/// When the outline has fewer than 3 vertices or is not simple and counter-clockwise (the
/// ear clipping finds no ear).
pub fn prism(outline: &[[f64; 2]], height: f64) -> TriMesh {
    let n = outline.len() as u32;
    let mut vertices: Vec<DVec3> = Vec::with_capacity(2 * outline.len());
    for z in [0.0, height] {
        vertices.extend(outline.iter().map(|&[x, y]| DVec3::new(x, y, z)));
    }
    let cap = ear_clip(outline);
    let mut triangles = Vec::with_capacity(2 * cap.len() + 2 * outline.len());
    for [a, b, c] in cap {
        triangles.push([a, c, b]);
        triangles.push([n + a, n + b, n + c]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([i, j, n + j]);
        triangles.push([i, n + j, n + i]);
    }
    mesh(vertices, triangles)
}

/// Triangles (counter-clockwise, indices into `outline`) covering a simple counter-clockwise
/// polygon, by ear clipping.
///
/// # Panics
/// When no ear is found (fewer than 3 vertices, or not simple and counter-clockwise).
fn ear_clip(outline: &[[f64; 2]]) -> Vec<[u32; 3]> {
    let cross = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut left: Vec<u32> = (0..outline.len() as u32).collect();
    let mut triangles = Vec::new();
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m)
            .find(|&k| {
                let [a, b, c] = [left[(k + m - 1) % m], left[k], left[(k + 1) % m]];
                let [pa, pb, pc] = [a, b, c].map(|i| outline[i as usize]);
                cross(pa, pb, pc) > 0.0
                    && left.iter().filter(|i| ![a, b, c].contains(i)).all(|&i| {
                        let p = outline[i as usize];
                        cross(pa, pb, p) < 0.0 || cross(pb, pc, p) < 0.0 || cross(pc, pa, p) < 0.0
                    })
            })
            .expect("a simple counter-clockwise polygon has an ear");
        triangles.push([left[(ear + m - 1) % m], left[ear], left[(ear + 1) % m]]);
        left.remove(ear);
    }
    assert_eq!(left.len(), 3, "a polygon has at least 3 vertices");
    triangles.push([left[0], left[1], left[2]]);
    triangles
}

/// The L outline of [`l_prism`]: the square `[0, 2]²` without `[1, 2]²`.
pub const L_OUTLINE: [[f64; 2]; 6] = [
    [0.0, 0.0],
    [2.0, 0.0],
    [2.0, 1.0],
    [1.0, 1.0],
    [1.0, 2.0],
    [0.0, 2.0],
];

/// An L-shaped prism: two unit squares' worth of arm on a unit corner, 1 high (volume 3).
pub fn l_prism() -> TriMesh {
    prism(&L_OUTLINE, 1.0)
}

/// A U-shaped prism, 3 wide, 2 deep and 1 high, its notch 1 × 1 (volume 5): the comb of two
/// teeth.
pub fn u_prism() -> TriMesh {
    comb_prism(2)
}

/// A comb of `teeth` (≥ 1) unit-wide teeth 1 apart on a unit-deep bar, all 1 high: 2 teeth − 1
/// wide, 2 deep (volume 3 teeth − 1). Its outline runs along the bottom, then back along the
/// teeth from the right.
pub fn comb_prism(teeth: u32) -> TriMesh {
    assert!(teeth >= 1);
    let width = f64::from(2 * teeth - 1);
    let mut outline = vec![[0.0, 0.0], [width, 0.0]];
    for t in (0..teeth).rev() {
        let (left, right) = (f64::from(2 * t), f64::from(2 * t + 1));
        outline.extend([[right, 2.0], [left, 2.0]]);
        if t > 0 {
            outline.extend([[left, 1.0], [left - 1.0, 1.0]]);
        }
    }
    prism(&outline, 1.0)
}

/// Three steps, each 1 × 1 × 1 tread on the one below (volume 6).
pub fn stairs_prism() -> TriMesh {
    let outline = [
        [0.0, 0.0],
        [3.0, 0.0],
        [3.0, 1.0],
        [2.0, 1.0],
        [2.0, 2.0],
        [1.0, 2.0],
        [1.0, 3.0],
        [0.0, 3.0],
    ];
    prism(&outline, 1.0)
}

/// The box `[-half, half]` with 12 triangles (8 vertices).
pub fn cuboid(half: DVec3) -> TriMesh {
    subdivided_cuboid(half, 1)
}

/// The box `[-half, half]` with each face cut into `n × n` squares of two triangles
/// (`12 n²` triangles), welded along the box's edges. Vertices lie on an exact lattice:
/// coordinate `−h + 2h · i / n`.
pub fn subdivided_cuboid(half: DVec3, n: u32) -> TriMesh {
    assert!(n >= 1);
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut vertices = Vec::new();
    let mut vertex = |lattice: [u32; 3]| -> u32 {
        *index.entry(lattice).or_insert_with(|| {
            let at = |axis: usize| {
                let h = half[axis];
                -h + 2.0 * h * f64::from(lattice[axis]) / f64::from(n)
            };
            vertices.push(DVec3::new(at(0), at(1), at(2)));
            (vertices.len() - 1) as u32
        })
    };
    let mut tris = Vec::new();
    for axis in 0..3 {
        // (u, v, axis) is a right-handed cycle, so u × v points along +axis.
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, n] {
            for i in 0..n {
                for j in 0..n {
                    let mut corner = |di: u32, dj: u32| {
                        let mut l = [0; 3];
                        l[axis] = side;
                        l[u] = i + di;
                        l[v] = j + dj;
                        vertex(l)
                    };
                    let (a, b, c, d) = (corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1));
                    if side == n {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    } else {
                        tris.push([a, c, b]);
                        tris.push([a, d, c]);
                    }
                }
            }
        }
    }
    mesh(vertices, tris)
}

/// A flat open grid in the plane `z = 0`: `[-half, half]²` cut into `n × n` squares of
/// two triangles (`2 n²` coplanar triangles), welded.
pub fn grid(half: f64, n: u32) -> TriMesh {
    rectangle_grid([half, half], [n, n])
}

/// A flat open grid in the plane `z = 0`: `[-half[0], half[0]] × [-half[1], half[1]]` cut
/// into `n[0] × n[1]` rectangles of two triangles (`2 n[0] n[1]` coplanar triangles),
/// welded.
pub fn rectangle_grid(half: [f64; 2], n: [u32; 2]) -> TriMesh {
    assert!(n[0] >= 1 && n[1] >= 1);
    let at =
        |axis: usize, i: u32| -half[axis] + 2.0 * half[axis] * f64::from(i) / f64::from(n[axis]);
    let vertices = (0..=n[0])
        .flat_map(|i| (0..=n[1]).map(move |j| DVec3::new(at(0, i), at(1, j), 0.0)))
        .collect();
    let id = |i: u32, j: u32| i * (n[1] + 1) + j;
    let mut tris = Vec::new();
    for i in 0..n[0] {
        for j in 0..n[1] {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    mesh(vertices, tris)
}

/// `count` random unwelded triangles: centres uniform in `[-half, half]³`, vertices within
/// `size` of their centre.
pub fn triangle_soup(rng: &mut TestRng, count: usize, half: f64, size: f64) -> TriMesh {
    let mut vertices = Vec::with_capacity(3 * count);
    let mut tris = Vec::with_capacity(count);
    for t in 0..count {
        let centre = point_in_cube(rng, half);
        for _ in 0..3 {
            vertices.push(centre + point_in_cube(rng, size));
        }
        let first = 3 * t as u32;
        tris.push([first, first + 1, first + 2]);
    }
    mesh(vertices, tris)
}

/// `count` random unwelded triangles with centres uniform in the ball of `radius` about the
/// origin and vertices within `size` of their centre: a cloud of loose pieces (debris,
/// foliage), the class of mesh whose sphere tree is nearly as tight as its boxes.
pub fn dust_ball(rng: &mut TestRng, count: usize, radius: f64, size: f64) -> TriMesh {
    let mut vertices = Vec::with_capacity(3 * count);
    let mut tris = Vec::with_capacity(count);
    for t in 0..count {
        let centre = loop {
            let p = point_in_cube(rng, radius);
            if p.length() <= radius {
                break p;
            }
        };
        for _ in 0..3 {
            vertices.push(centre + point_in_cube(rng, size));
        }
        let first = 3 * t as u32;
        tris.push([first, first + 1, first + 2]);
    }
    mesh(vertices, tris)
}

/// `count` zero-area triangles in the cube `[-half, half]³` and nothing else, unwelded, in
/// turn: a point (one vertex, index repeated three times); three collinear points `p`,
/// `p + d`, `p + 2.5 d` (collinear up to the rounding of the sums); a segment with a
/// repeated end (`[p, p + d, p]`), with `|dᵢ| ≤ half / 10`.
pub fn zero_area_triangles(rng: &mut TestRng, count: usize, half: f64) -> TriMesh {
    let mut vertices = Vec::with_capacity(3 * count);
    let mut tris = Vec::with_capacity(count);
    for k in 0..count {
        let p = point_in_cube(rng, half);
        let d = point_in_cube(rng, half * 0.1);
        let first = vertices.len() as u32;
        match k % 3 {
            0 => {
                vertices.push(p);
                tris.push([first; 3]);
            }
            1 => {
                vertices.extend([p, p + d, p + 2.5 * d]);
                tris.push([first, first + 1, first + 2]);
            }
            _ => {
                vertices.extend([p, p + d]);
                tris.push([first, first + 1, first]);
            }
        }
    }
    mesh(vertices, tris)
}

/// A closed box (`subdivided_cuboid(half, 3)`) with `extra` zero-area triangles mixed in,
/// then the triangle order shuffled: segment-like triangles with a repeated index (a mesh
/// edge, a chord through the box or a new segment), exactly collinear triples (the three
/// points differ in one coordinate only) and point triangles, on the surface and inside.
pub fn with_zero_area_triangles(rng: &mut TestRng, half: DVec3, extra: usize) -> TriMesh {
    let base = subdivided_cuboid(half, 3);
    let mut vertices = base.vertices().to_vec();
    let mut tris = base.triangles().to_vec();
    let n_surface = vertices.len() as u32;
    for k in 0..extra {
        let any = |rng: &mut TestRng| rng.random_range(0..n_surface);
        match k % 4 {
            0 => {
                let (i, j) = (any(rng), any(rng));
                tris.push([i, j, i]);
            }
            1 => {
                let i = any(rng);
                tris.push([i, i, i]);
            }
            2 => {
                // Collinear along one axis: only that coordinate changes.
                let p = point_in_cube(rng, 1.0) * half;
                let axis = rng.random_range(0..3);
                let mut q = p;
                let mut m = p;
                q[axis] = rng.random_range(-half[axis]..=half[axis]);
                m[axis] = 0.5 * (p[axis] + q[axis]);
                let first = vertices.len() as u32;
                vertices.extend([p, m, q]);
                tris.push([first, first + 1, first + 2]);
            }
            _ => {
                // A point inside the box, as a triangle of one repeated new vertex.
                let first = vertices.len() as u32;
                vertices.push(point_in_cube(rng, 1.0) * half);
                tris.push([first, first, first]);
            }
        }
    }
    tris.shuffle(rng);
    mesh(vertices, tris)
}

/// The triangles of `mesh` split in two meshes by the sign of their centroid's `x`, both
/// keeping every vertex (so the halves share the vertices along the cut exactly).
pub fn halves(mesh: &TriMesh) -> (TriMesh, TriMesh) {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    for (i, &t) in mesh.triangles().iter().enumerate() {
        if mesh.triangle(i).centroid().x < 0.0 {
            left.push(t);
        } else {
            right.push(t);
        }
    }
    let vertices = mesh.vertices().to_vec();
    (
        self::mesh(vertices.clone(), left),
        self::mesh(vertices, right),
    )
}

/// A mesh of `tests/data` (see its README for origin and licence).
pub fn data_mesh(file: &str) -> TriMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(file);
    TriMesh::load(&path).unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
}

/// A mesh of the data folder's `meshes/` (real meshes, not part of the repository; see
/// [`super::data`]), or `None` after the visible line saying that the suite `who` skipped.
///
/// # Panics
/// When the data folder exists but the mesh does not load.
pub fn shared_data_mesh(who: &str, file: &str) -> Option<TriMesh> {
    let path = super::data::mesh_path_or_skip(who, file)?;
    Some(TriMesh::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
}
