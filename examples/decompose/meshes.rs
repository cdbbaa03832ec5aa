//! The meshes `decompose` measures: files by path, the shared meshes by name (found in the
//! data folder by `tests/support/data.rs`'s rule), and closed procedural solids made here.
//!
//! The procedural solids are prisms: a simple polygon in the xy plane, ear-clipped into the
//! two caps, extruded along z. They are welded (every edge shared by exactly two triangles)
//! and oriented counter-clockwise seen from outside, so their enclosed volume is exact.

use crate::data;
use proxima::geometry::{MeshError, TriMesh};
use proxima::math::DVec3;
use std::path::{Path, PathBuf};

/// The shared meshes of `--all`: short name and file under the data folder's `meshes/`.
pub const SHARED: [(&str, &str); 5] = [
    ("bunny", "stanford-bunny.obj"),
    ("spot", "spot.obj"),
    ("fandisk", "fandisk.obj"),
    ("env", "env.obj"),
    ("rob", "rob.obj"),
];

/// The procedural solids of `--all`, by name (see [`procedural`]).
pub const PROCEDURAL: [&str; 2] = ["torus", "u-block"];

/// Why a mesh argument gave no mesh.
#[derive(Debug)]
pub enum MeshLoadError {
    /// Neither a file, a shared mesh's name nor a procedural solid's.
    NotFound(String),
    /// A shared mesh's name, but no data folder.
    NoDataFolder(String),
    /// The data folder variable names a folder without `meshes/`.
    BadDataFolder(PathBuf),
    /// The file exists but does not load.
    Load(PathBuf, MeshError),
}

impl std::fmt::Display for MeshLoadError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotFound(name) => write!(
                f,
                "{name}: no such file, and not a shared mesh ({}) nor a procedural one ({})",
                SHARED.map(|(n, _)| n).join(", "),
                PROCEDURAL.join(", ")
            ),
            Self::NoDataFolder(name) => write!(
                f,
                "{name}: a shared mesh, but no data folder (set {} to a folder with meshes/, \
                 or place ../shared/data beside the checkout)",
                data::DATA_VAR
            ),
            Self::BadDataFolder(dir) => write!(
                f,
                "{}={} has no meshes/ folder",
                data::DATA_VAR,
                dir.display()
            ),
            Self::Load(path, e) => write!(f, "{}: {e}", path.display()),
        }
    }
}

impl std::error::Error for MeshLoadError {}

/// The mesh `name` names, with a short label for tables and file names: a procedural
/// solid's name, else an existing file, else a shared mesh by short name or file name.
///
/// # Errors
/// [`MeshLoadError`] saying which of those failed.
pub fn load(name: &str) -> Result<(String, TriMesh), MeshLoadError> {
    if let Some(mesh) = procedural(name) {
        return Ok((name.to_owned(), mesh));
    }
    let path = if Path::new(name).is_file() {
        PathBuf::from(name)
    } else {
        shared_path(name)?
    };
    let label = path
        .file_stem()
        .map_or_else(|| name.to_owned(), |s| s.to_string_lossy().into_owned());
    let label = SHARED
        .iter()
        .find(|(_, file)| Path::new(file).file_stem() == Some(label.as_ref()))
        .map_or(label, |(short, _)| (*short).to_owned());
    TriMesh::load(&path)
        .map(|mesh| (label, mesh))
        .map_err(|e| MeshLoadError::Load(path, e))
}

/// The path of a shared mesh named by its short name (`bunny`) or its file name, with or
/// without `.obj`.
fn shared_path(name: &str) -> Result<PathBuf, MeshLoadError> {
    let file = SHARED
        .iter()
        .find(|(short, _)| *short == name)
        .map_or_else(|| name.to_owned(), |(_, file)| (*file).to_owned());
    // `data_dir` panics on a data folder variable without `meshes/`; say so instead.
    if let Some(dir) = std::env::var_os(data::DATA_VAR).map(PathBuf::from)
        && !dir.join("meshes").is_dir()
    {
        return Err(MeshLoadError::BadDataFolder(dir));
    }
    let dir = data::data_dir()
        .ok_or_else(|| MeshLoadError::NoDataFolder(name.to_owned()))?
        .join("meshes");
    [dir.join(&file), dir.join(format!("{file}.obj"))]
        .into_iter()
        .find(|p| p.is_file())
        .ok_or_else(|| MeshLoadError::NotFound(name.to_owned()))
}

/// A procedural solid by name: `torus` (major radius 1 m, tube radius 0.35 m, 64 × 24
/// squares) or `u-block` ([`u_block`]); `None` for other names.
#[must_use]
pub fn procedural(name: &str) -> Option<TriMesh> {
    match name {
        "torus" => Some(TriMesh::torus(1.0, 0.35, 64, 24)),
        "u-block" => Some(u_block()),
        _ => None,
    }
}

/// A U-shaped block: 3 m × 2 m × 1 m with a 1 m × 1.4 m slot from the top edge, 4.6 m³.
#[must_use]
pub fn u_block() -> TriMesh {
    let outline = [
        [0.0, 0.0],
        [3.0, 0.0],
        [3.0, 2.0],
        [2.0, 2.0],
        [2.0, 0.6],
        [1.0, 0.6],
        [1.0, 2.0],
        [0.0, 2.0],
    ];
    prism(&outline, 0.0, 1.0)
}

/// The closed prism over a simple counter-clockwise polygon `outline` (xy, metres) from
/// `z = bottom` to `z = top > bottom`.
///
/// # Panics
/// When the outline has fewer than 3 vertices or is not simple and counter-clockwise (the
/// ear clipping finds no ear).
#[must_use]
pub fn prism(outline: &[[f64; 2]], bottom: f64, top: f64) -> TriMesh {
    let n = outline.len() as u32;
    let mut vertices: Vec<DVec3> = outline
        .iter()
        .map(|[x, y]| DVec3::new(*x, *y, bottom))
        .collect();
    vertices.extend(outline.iter().map(|[x, y]| DVec3::new(*x, *y, top)));
    let mut triangles = Vec::new();
    for [a, b, c] in ear_clip(outline) {
        triangles.push([a, c, b]);
        triangles.push([a + n, b + n, c + n]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([i, j, j + n]);
        triangles.push([i, j + n, i + n]);
    }
    TriMesh::try_new(vertices, triangles).expect("a prism is a valid mesh")
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
