//! The mesh pairs and relative poses the mesh–mesh benches run on.
//!
//! A [`MeshScene`] is two meshes, each in its own local frame, and a list of `pose_ab` (B's
//! frame expressed in A's), so every engine is handed exactly the same relative placements.

use crate::support::meshes::torus;
use crate::support::{point_in_cube, rng, rotation};
use proxima::geometry::TriMesh;
use proxima::math::{DMat3, DQuat, DVec3, Pose};

/// Two meshes and the relative poses to query them under.
pub struct MeshScene {
    /// Name used in bench ids.
    pub name: &'static str,
    /// Mesh A, in its own frame; query results are in this frame.
    pub a: TriMesh,
    /// Mesh B, in its own frame.
    pub b: TriMesh,
    /// B's frame expressed in A's frame, one per query.
    pub poses_ab: Vec<Pose>,
}

/// The bunny×fandisk protocol (FCL's mesh–mesh benchmark): A = the Stanford bunny scaled by
/// 10, B = fandisk scaled by 0.3, each centred on its bounding box; the 200 transforms of
/// `poses/bunny_fandisk.txt` place the bunny in the world while fandisk stays at the
/// identity, so `pose_ab = transform⁻¹`.
///
/// `None`, after a line saying the scene is skipped, when there is no data folder
/// (`PROXIMA_DATA`, see [`crate::support::data`]).
///
/// # Panics
/// When a data file in the data folder is missing or malformed.
pub fn bunny_fandisk() -> Option<MeshScene> {
    let dir = crate::support::data::data_dir_or_skip("the bunny-fandisk scene")?;
    let load = |name: &str, scale: f64| {
        let path = dir.join("meshes").join(name);
        TriMesh::load(&path)
            .unwrap_or_else(|e| panic!("cannot load {}: {e}", path.display()))
            .scaled(scale)
            .centered_on_bounds()
    };
    let poses_path = dir.join("poses/bunny_fandisk.txt");
    let text = std::fs::read_to_string(&poses_path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", poses_path.display()));
    Some(MeshScene {
        name: "bunny-fandisk",
        a: load("stanford-bunny.obj", 10.0),
        b: load("fandisk.obj", 0.3),
        poses_ab: parse_transforms(&text).iter().map(Pose::inverse).collect(),
    })
}

/// Transforms from the protocol's text format: `#` comment lines and blank lines are
/// skipped; the first other line is the count `N`, then `N` lines of 12 numbers: a 3×3
/// rotation matrix row by row, then the translation.
///
/// # Panics
/// When the text does not follow that format or a matrix is not a rotation (to 1e-9).
pub fn parse_transforms(text: &str) -> Vec<Pose> {
    let mut lines = text
        .lines()
        .map(str::trim)
        .filter(|line| !line.is_empty() && !line.starts_with('#'));
    let count: usize = lines
        .next()
        .and_then(|line| line.parse().ok())
        .expect("pose file: first line must be the transform count");
    let poses: Vec<Pose> = lines
        .take(count)
        .map(|line| {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|word| word.parse().expect("pose file: not a number"))
                .collect();
            assert_eq!(v.len(), 12, "pose file: a transform has 12 numbers");
            // Row-major in the file; glam builds from columns.
            let m = DMat3::from_cols_array(&[v[0], v[3], v[6], v[1], v[4], v[7], v[2], v[5], v[8]]);
            let orthonormal = (m.transpose() * m).abs_diff_eq(DMat3::IDENTITY, 1e-9);
            assert!(
                orthonormal && m.determinant() > 0.0,
                "pose file: not a rotation"
            );
            Pose::new(
                DVec3::new(v[9], v[10], v[11]),
                DQuat::from_mat3(&m).normalize(),
            )
        })
        .collect();
    assert_eq!(
        poses.len(),
        count,
        "pose file: fewer transforms than its count"
    );
    poses
}

/// Two tori of 10,000 triangles each (A: radii 1 and 0.25 m, B: radii 0.7 and 0.2 m) under
/// `pose_count` random poses from `seed`: uniform rotations and translations in a 3 m cube,
/// kept so that exactly half intersect, as decided by the test `classifier` makes for the
/// two meshes (it is asked once, so it can build its acceleration structures once).
///
/// # Panics
/// When `pose_count` is odd.
pub fn tori<C: FnMut(&Pose) -> bool>(
    seed: u64,
    pose_count: usize,
    classifier: impl FnOnce(&TriMesh, &TriMesh) -> C,
) -> MeshScene {
    assert!(
        pose_count.is_multiple_of(2),
        "half the poses must intersect"
    );
    let a = torus(1.0, 0.25, 100, 50);
    let b = torus(0.7, 0.2, 100, 50);
    let mut intersects = classifier(&a, &b);
    let mut rng = rng(seed);
    let (mut hits, mut misses) = (0, 0);
    let mut poses_ab = Vec::with_capacity(pose_count);
    while poses_ab.len() < pose_count {
        let pose = Pose::new(point_in_cube(&mut rng, 1.5), rotation(&mut rng));
        let count = if intersects(&pose) {
            &mut hits
        } else {
            &mut misses
        };
        if *count < pose_count / 2 {
            *count += 1;
            poses_ab.push(pose);
        }
    }
    MeshScene {
        name: "tori",
        a,
        b,
        poses_ab,
    }
}
