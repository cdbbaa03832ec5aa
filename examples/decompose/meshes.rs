//! The meshes `decompose` measures: files by path, the shared meshes by name (found in the
//! data folder by `tests/support/data.rs`'s rule), and closed procedural solids made here.
//!
//! The procedural solids are the torus and prisms of `tests/support/meshes.rs` (welded,
//! oriented outward, so their enclosed volume is exact).

use crate::support::data;
use crate::support::meshes::prism;
use proxima::geometry::{MeshError, TriMesh};
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
    prism(&outline, 1.0)
}
