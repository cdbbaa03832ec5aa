//! Why a triangle mesh was rejected or could not be read.

use crate::math::tolerance;
use std::{fmt, io};

/// Why a line of an OBJ or ASCII STL file could not be parsed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ParseReason {
    /// A number could not be read.
    BadNumber,
    /// A vertex line has fewer than three coordinates.
    MissingCoordinate,
    /// A face line has fewer than three vertices.
    FaceTooShort,
    /// A face index is zero, not an integer, or malformed (`v/vt/vn` forms).
    BadIndex,
    /// A negative (relative) face index points before the first vertex.
    RelativeIndexOutOfRange,
    /// An ASCII STL ended with a facet that has not exactly three vertices.
    IncompleteFacet,
    /// The data is neither a binary STL (84 + 50·n bytes) nor an ASCII one (`solid`).
    NotStl,
}

impl fmt::Display for ParseReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::BadNumber => "a number could not be read",
            Self::MissingCoordinate => "a vertex needs three coordinates",
            Self::FaceTooShort => "a face needs at least three vertices",
            Self::BadIndex => "a face index is zero or malformed",
            Self::RelativeIndexOutOfRange => "a relative face index points before vertex 1",
            Self::IncompleteFacet => "a facet does not have exactly three vertices",
            Self::NotStl => "neither binary STL (84 + 50 n bytes) nor ASCII STL (`solid`)",
        })
    }
}

/// Why a [`TriMesh`](super::TriMesh) was rejected or could not be loaded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshError {
    /// The mesh has no triangles.
    Empty,
    /// The vertex at this index has a NaN or infinite coordinate.
    NonFiniteVertex {
        /// Index of the vertex.
        index: usize,
    },
    /// The vertex at this index has a coordinate above
    /// [`tolerance::MAX_COORDINATE`](crate::math::tolerance::MAX_COORDINATE).
    CoordinateTooLarge {
        /// Index of the vertex.
        index: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// How many vertices the mesh has.
        vertex_count: usize,
    },
    /// More vertices than [`MeshLimits::max_vertices`](super::MeshLimits::max_vertices).
    TooManyVertices {
        /// Vertices in the input.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// More triangles than [`MeshLimits::max_triangles`](super::MeshLimits::max_triangles).
    TooManyTriangles {
        /// Triangles in the input.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// A line of an OBJ or ASCII STL file could not be parsed.
    Parse {
        /// 1-based line number (0 for binary data).
        line: usize,
        /// What was wrong with it.
        reason: ParseReason,
    },
    /// The file name has no `.obj` or `.stl` extension.
    UnknownExtension,
    /// The file could not be read.
    Io {
        /// The kind of I/O failure.
        kind: io::ErrorKind,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => f.write_str("mesh has no triangles"),
            Self::NonFiniteVertex { index } => {
                write!(f, "mesh vertex {index} has a NaN or infinite coordinate")
            }
            Self::CoordinateTooLarge { index } => write!(
                f,
                "mesh vertex {index} exceeds the largest accepted coordinate ({:e} m)",
                tolerance::MAX_COORDINATE
            ),
            Self::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "mesh triangle {triangle} refers to vertex {index}, \
                 but there are only {vertex_count} vertices"
            ),
            Self::TooManyVertices { count, limit } => {
                write!(f, "mesh has {count} vertices, more than the limit {limit}")
            }
            Self::TooManyTriangles { count, limit } => {
                write!(f, "mesh has {count} triangles, more than the limit {limit}")
            }
            Self::Parse { line, reason } => write!(f, "mesh file line {line}: {reason}"),
            Self::UnknownExtension => f.write_str("mesh file name must end in .obj or .stl"),
            Self::Io { kind } => write!(f, "mesh file could not be read: {kind}"),
        }
    }
}

impl std::error::Error for MeshError {}

impl From<io::Error> for MeshError {
    fn from(e: io::Error) -> Self {
        Self::Io { kind: e.kind() }
    }
}
