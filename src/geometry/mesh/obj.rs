//! Wavefront OBJ: `v` and `f` statements, everything else ignored.
//!
//! Faces accept `v`, `v/vt`, `v//vn` and `v/vt/vn` forms and negative (relative) indices;
//! polygons are fan-triangulated. Positive indices past the vertices read so far are left
//! to [`TriMesh::try_new`](super::TriMesh::try_new), which names the triangle.

use super::error::{MeshError, ParseReason};
use crate::math::DVec3;
use std::fmt::Write;

/// Vertices and triangles (0-based) of an OBJ text.
pub(super) fn parse(text: &str) -> Result<(Vec<DVec3>, Vec<[u32; 3]>), MeshError> {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let mut face = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let err = |reason| MeshError::Parse {
            line: i + 1,
            reason,
        };
        let line = raw.split('#').next().unwrap_or("");
        let mut tokens = line.split_whitespace();
        match tokens.next() {
            Some("v") => {
                let mut c = [0.0; 3];
                for slot in &mut c {
                    let t = tokens.next().ok_or(err(ParseReason::MissingCoordinate))?;
                    *slot = t.parse().map_err(|_| err(ParseReason::BadNumber))?;
                }
                vertices.push(DVec3::from_array(c));
            }
            Some("f") => {
                face.clear();
                for t in tokens {
                    face.push(resolve(t, vertices.len()).map_err(err)?);
                }
                if face.len() < 3 {
                    return Err(err(ParseReason::FaceTooShort));
                }
                for k in 1..face.len() - 1 {
                    triangles.push([face[0], face[k], face[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok((vertices, triangles))
}

/// The 0-based vertex index of one face token, given how many vertices precede it.
fn resolve(token: &str, seen: usize) -> Result<u32, ParseReason> {
    let first = token.split('/').next().unwrap_or("");
    let index: i64 = first.parse().map_err(|_| ParseReason::BadIndex)?;
    let zero_based = match index {
        0 => return Err(ParseReason::BadIndex),
        i if i > 0 => i - 1,
        i => {
            let j = seen as i64 + i;
            if j < 0 {
                return Err(ParseReason::RelativeIndexOutOfRange);
            }
            j
        }
    };
    u32::try_from(zero_based).map_err(|_| ParseReason::BadIndex)
}

/// OBJ text of a mesh; coordinates printed so they read back exactly.
pub(super) fn write(vertices: &[DVec3], triangles: &[[u32; 3]]) -> String {
    let mut out = String::with_capacity(32 * (vertices.len() + triangles.len()));
    for v in vertices {
        let _ = writeln!(out, "v {} {} {}", v.x, v.y, v.z);
    }
    for t in triangles {
        let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out
}
