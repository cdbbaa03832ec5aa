//! Indexed triangle meshes: validated construction, loading (OBJ, binary and ASCII STL),
//! writing, a quality report, the transforms benchmarks use, and edge adjacency with the
//! surface's bends ([`MeshEdges`], for ghost-normal removal in the narrow phase), and an
//! approximation of a closed surface's medial axis ([`medial_balls`], for sphere trees).
//!
//! A mesh is not assumed closed, manifold or free of degenerate triangles: [`TriMesh::report`]
//! tells which of these hold, and later stages (BVH fitting, narrow phase) handle them all.

mod edges;
mod error;
mod medial;
mod obj;
mod procedural;
mod stl;

pub use edges::{EdgeKind, FLAT_EDGE_ANGLE, MeshEdges, NO_NEIGHBOUR, TriangleEdges};
pub use error::{MeshError, ParseReason};
pub use medial::{MAX_BALLS, MedialBall, medial_balls};

use super::Triangle;
use crate::math::{DVec3, bounds_of, tolerance};
use std::collections::HashMap;
use std::path::Path;

/// Size limits a mesh must respect; the daemon sets them from its configuration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MeshLimits {
    /// Largest accepted vertex count.
    pub max_vertices: usize,
    /// Largest accepted triangle count.
    pub max_triangles: usize,
}

impl MeshLimits {
    /// The default preset: 16 Mi vertices and 16 Mi triangles.
    #[must_use]
    pub const fn standard() -> Self {
        Self {
            max_vertices: 1 << 24,
            max_triangles: 1 << 24,
        }
    }
}

impl Default for MeshLimits {
    fn default() -> Self {
        Self::standard()
    }
}

/// What [`TriMesh::report`] found about a mesh's quality. None of it is an error.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshReport {
    /// Indices of triangles with a repeated vertex index or zero area (within a tolerance
    /// relative to the mesh's size), ascending.
    pub degenerate_triangles: Vec<usize>,
    /// Vertices no triangle refers to.
    pub unreferenced_vertices: usize,
    /// Whether every edge is shared by exactly two triangles.
    pub closed: bool,
    /// Bounding box `(min, max)`, metres.
    pub bounds: (DVec3, DVec3),
}

/// An indexed triangle mesh in its local frame.
///
/// # Invariants
/// At least one triangle; every vertex finite with coordinates at most
/// [`tolerance::MAX_COORDINATE`]; every index below [`vertex_count`](Self::vertex_count);
/// counts within the [`MeshLimits`] it was built with.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// A mesh from untrusted data, with [`MeshLimits::standard`].
    ///
    /// # Errors
    /// See [`try_new_with_limits`](Self::try_new_with_limits).
    pub fn try_new(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshError> {
        Self::try_new_with_limits(vertices, triangles, &MeshLimits::standard())
    }

    /// A mesh from untrusted data.
    ///
    /// # Errors
    /// [`MeshError::Empty`] without triangles; [`MeshError::TooManyVertices`] and
    /// [`MeshError::TooManyTriangles`] past `limits`; [`MeshError::NonFiniteVertex`] and
    /// [`MeshError::CoordinateTooLarge`] naming the first bad vertex;
    /// [`MeshError::IndexOutOfRange`] naming the first bad triangle.
    pub fn try_new_with_limits(
        vertices: Vec<DVec3>,
        triangles: Vec<[u32; 3]>,
        limits: &MeshLimits,
    ) -> Result<Self, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        if vertices.len() > limits.max_vertices {
            return Err(MeshError::TooManyVertices {
                count: vertices.len(),
                limit: limits.max_vertices,
            });
        }
        if triangles.len() > limits.max_triangles {
            return Err(MeshError::TooManyTriangles {
                count: triangles.len(),
                limit: limits.max_triangles,
            });
        }
        for (index, v) in vertices.iter().enumerate() {
            if !v.is_finite() {
                return Err(MeshError::NonFiniteVertex { index });
            }
            if v.abs().max_element() > tolerance::MAX_COORDINATE {
                return Err(MeshError::CoordinateTooLarge { index });
            }
        }
        for (triangle, t) in triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    index,
                    vertex_count: vertices.len(),
                });
            }
        }
        Ok(Self {
            vertices,
            triangles,
        })
    }

    /// Loads an `.obj` or `.stl` file (extension case-insensitive) with
    /// [`MeshLimits::standard`].
    ///
    /// # Errors
    /// [`MeshError::UnknownExtension`], [`MeshError::Io`], parse errors, and everything
    /// [`try_new`](Self::try_new) rejects.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, MeshError> {
        Self::load_with_limits(path, &MeshLimits::standard())
    }

    /// Loads an `.obj` or `.stl` file under `limits`.
    ///
    /// # Errors
    /// As [`load`](Self::load).
    pub fn load_with_limits(
        path: impl AsRef<Path>,
        limits: &MeshLimits,
    ) -> Result<Self, MeshError> {
        let path = path.as_ref();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let (v, t) = match ext.as_deref() {
            Some("obj") => obj::parse(&String::from_utf8_lossy(&std::fs::read(path)?))?,
            Some("stl") => stl::parse(&std::fs::read(path)?)?,
            _ => return Err(MeshError::UnknownExtension),
        };
        Self::try_new_with_limits(v, t, limits)
    }

    /// Parses OBJ text.
    ///
    /// # Errors
    /// [`MeshError::Parse`] with the line number, and everything [`try_new`](Self::try_new)
    /// rejects.
    pub fn from_obj_str(text: &str) -> Result<Self, MeshError> {
        let (v, t) = obj::parse(text)?;
        Self::try_new(v, t)
    }

    /// Parses binary or ASCII STL data, welding equal coordinates.
    ///
    /// # Errors
    /// [`MeshError::Parse`], and everything [`try_new`](Self::try_new) rejects.
    pub fn from_stl_bytes(bytes: &[u8]) -> Result<Self, MeshError> {
        let (v, t) = stl::parse(bytes)?;
        Self::try_new(v, t)
    }

    /// OBJ text that [`from_obj_str`](Self::from_obj_str) reads back exactly.
    #[must_use]
    pub fn to_obj_string(&self) -> String {
        obj::write(&self.vertices, &self.triangles)
    }

    /// Binary STL (coordinates rounded to f32; vertices are welded again on reading).
    #[must_use]
    pub fn to_stl_binary(&self) -> Vec<u8> {
        stl::write_binary(&self.vertices, &self.triangles)
    }

    /// Vertices, local frame, metres.
    #[must_use]
    #[inline]
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// Triangles as vertex indices.
    #[must_use]
    #[inline]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Triangle `i` as points.
    ///
    /// # Panics
    /// When `i >= triangle_count()`.
    #[must_use]
    #[inline]
    pub fn triangle(&self, i: usize) -> Triangle {
        let [a, b, c] = self.triangles[i].map(|k| self.vertices[k as usize]);
        Triangle::new(a, b, c)
    }

    /// Number of triangles (≥ 1).
    #[must_use]
    #[inline]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Number of vertices, referenced or not.
    #[must_use]
    #[inline]
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// Bounding box `(min, max)` of the referenced vertices, metres.
    #[must_use]
    pub fn bounds(&self) -> (DVec3, DVec3) {
        bounds_of(
            self.triangles
                .iter()
                .flatten()
                .map(|&i| self.vertices[i as usize]),
        )
    }

    /// Quality report: degenerate triangles, unreferenced vertices, closedness, bounds.
    ///
    /// A triangle is degenerate when two of its indices are equal or its smallest height is
    /// at most `PLANE_RELATIVE × extent` plus the rounding of coordinates of its magnitude.
    #[must_use]
    pub fn report(&self) -> MeshReport {
        let bounds = self.bounds();
        let extent = (bounds.1 - bounds.0).max_element();
        let magnitude = bounds.0.abs().max(bounds.1.abs()).max_element();
        let height_tol = tolerance::PLANE_RELATIVE * extent + 8.0 * f64::EPSILON * magnitude;
        let degenerate_triangles = (0..self.triangles.len())
            .filter(|&i| {
                let [a, b, c] = self.triangles[i];
                if a == b || b == c || a == c {
                    return true;
                }
                let t = self.triangle(i);
                let longest = [t.b - t.a, t.c - t.b, t.a - t.c]
                    .map(DVec3::length)
                    .into_iter()
                    .fold(0.0, f64::max);
                t.scaled_normal().length() <= height_tol * longest
            })
            .collect();
        let mut used = vec![false; self.vertices.len()];
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * self.triangles.len());
        for t in &self.triangles {
            for k in 0..3 {
                used[t[k] as usize] = true;
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        MeshReport {
            degenerate_triangles,
            unreferenced_vertices: used.iter().filter(|u| !**u).count(),
            closed: edges.values().all(|&n| n == 2),
            bounds,
        }
    }

    /// The mesh scaled by `s` about the origin (`s > 0`: orientation kept).
    #[must_use]
    pub fn scaled(&self, s: f64) -> Self {
        debug_assert!(s.is_finite() && s > 0.0);
        self.mapped(|p| p * s)
    }

    /// The mesh moved by `offset`, metres.
    #[must_use]
    pub fn translated(&self, offset: DVec3) -> Self {
        debug_assert!(offset.is_finite());
        self.mapped(|p| p + offset)
    }

    /// The mesh moved so that its bounding-box centre is the origin.
    #[must_use]
    pub fn centered_on_bounds(&self) -> Self {
        let (lo, hi) = self.bounds();
        self.translated(-(lo + hi) * 0.5)
    }

    fn mapped(&self, f: impl Fn(DVec3) -> DVec3) -> Self {
        Self {
            vertices: self.vertices.iter().map(|p| f(*p)).collect(),
            triangles: self.triangles.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_faces_accept_every_index_form() {
        let text = "# comment\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
                    f 1/1/1 2/1/1 3//1\nf -4 -2 -1\ns off\n";
        let m = TriMesh::from_obj_str(text).unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
    }

    #[test]
    fn polygons_are_fan_triangulated() {
        let m = TriMesh::from_obj_str("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        assert_eq!(m.triangles(), &[[0, 1, 2], [0, 2, 3]]);
        assert!(!m.report().closed);
    }
}
