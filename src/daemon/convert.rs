//! Wire records to validated domain values, once, at the boundary. Every function here
//! takes untrusted input and returns either a value the engine may trust or a
//! [`Rejection`] naming the wire error code and the reason.

use crate::geometry::{
    Capsule, Cone, ConvexHullError, ConvexPolyhedron, Cuboid, Cylinder, MeshError, MeshLimits,
    Sphere, TriMesh,
};
use crate::math::{DQuat, DVec3, Pose};
use crate::narrow::{MeshShape, Shape};
use crate::pipeline::Query;
use crate::scene::{CollisionFilter, Motion};
use proxima_ipc::wire::{self, ControlRequest, ErrorCode, MotionCode, ShapeKindCode, query};
use std::sync::Arc;

/// Why an input was refused: the code for the wire and a reason for people.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rejection {
    /// The wire error code.
    pub code: ErrorCode,
    /// What exactly was wrong.
    pub reason: String,
}

impl Rejection {
    pub(crate) fn new(code: ErrorCode, reason: impl Into<String>) -> Self {
        Self {
            code,
            reason: reason.into(),
        }
    }
}

/// A pose from wire arrays (world frame, quaternion `[x, y, z, w]`).
pub fn pose(position: [f64; 3], orientation: [f64; 4]) -> Result<Pose, Rejection> {
    let [x, y, z, w] = orientation;
    Pose::try_new(DVec3::from(position), DQuat::from_xyzw(x, y, z, w))
        .map_err(|e| Rejection::new(ErrorCode::InvalidPose, e.to_string()))
}

// The wire promises clients the engine's manifold size.
const _: () = assert!(crate::narrow::MANIFOLD_POINTS as u32 == wire::MAX_CONTACTS_PER_PAIR);

/// The [`Query`] a pose frame's `query_flags` ask for.
///
/// Refused with [`ErrorCode::MalformedMessage`]: undefined bits; no flag at all (a frame
/// that asks nothing is a client mistake, not an empty answer).
pub fn query(flags: u32) -> Result<Query, Rejection> {
    let refuse = |reason: String| Err(Rejection::new(ErrorCode::MalformedMessage, reason));
    if flags & !query::ALL != 0 {
        return refuse(format!("undefined query flags {:#x}", flags & !query::ALL));
    }
    if flags == 0 {
        return refuse("no query flags: the frame asks for nothing".to_owned());
    }
    Ok(Query {
        overlap: flags & query::OVERLAP != 0,
        close: flags & query::CLOSE != 0,
        distance: flags & query::DISTANCE != 0,
        contacts: flags & query::CONTACTS != 0,
        toi: flags & query::TOI != 0,
    })
}

/// A motion kind from its wire code.
pub fn motion(code: u32) -> Result<Motion, Rejection> {
    match MotionCode::from_u32(code) {
        Some(MotionCode::Static) => Ok(Motion::Static),
        Some(MotionCode::Kinematic) => Ok(Motion::Kinematic),
        Some(MotionCode::Dynamic) => Ok(Motion::Dynamic),
        None => Err(Rejection::new(
            ErrorCode::MalformedMessage,
            format!("unknown motion kind {code}"),
        )),
    }
}

/// A collision filter from a request.
#[must_use]
pub fn filter(request: &ControlRequest) -> CollisionFilter {
    CollisionFilter {
        group: request.group,
        mask: request.mask,
    }
}

/// A body's margin: negative on the wire means "the scene's default".
#[must_use]
pub fn margin(value: f64) -> Option<f64> {
    (value >= 0.0 || value.is_nan()).then_some(value)
}

/// What a `RegisterShape` request asks for, checked without reading its geometry.
#[derive(Debug, Clone)]
pub enum ShapeRequest {
    /// A primitive, built already (O(1)).
    Primitive(Shape),
    /// A convex or mesh shape whose payload is to be decoded and built
    /// ([`geometry_shape`]).
    Geometry(GeometryRequest),
}

/// A convex or mesh registration whose counts are within the limits and whose payload
/// length matches them (see [`shape_request`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GeometryRequest {
    /// Whether the points are a convex hull's or a mesh's.
    pub mesh: bool,
    /// Points in the payload.
    pub vertex_count: u32,
    /// Indices after the points (a multiple of 3; none for a convex shape).
    pub index_count: u32,
}

/// Checks a `RegisterShape` request in O(1): its kind, a primitive's dimensions, a convex
/// or mesh shape's counts against the limits and `payload_len` against the counts. The
/// geometry itself is [`geometry_shape`]'s to check.
pub fn shape_request(
    request: &ControlRequest,
    payload_len: usize,
    mesh_limits: &MeshLimits,
    max_convex_points: u32,
) -> Result<ShapeRequest, Rejection> {
    let Some(kind) = ShapeKindCode::from_u32(request.shape_kind) else {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            format!("unknown shape kind {}", request.shape_kind),
        ));
    };
    let [d0, d1, d2, _] = request.dimensions;
    let primitive = |result: Result<Shape, crate::geometry::ShapeError>| {
        let has_geometry =
            payload_len != 0 || request.vertex_count != 0 || request.index_count != 0;
        if has_geometry {
            return Err(Rejection::new(
                ErrorCode::MalformedMessage,
                "a primitive shape carries no geometry payload",
            ));
        }
        result
            .map(ShapeRequest::Primitive)
            .map_err(|e| Rejection::new(ErrorCode::InvalidShape, e.to_string()))
    };
    match kind {
        ShapeKindCode::Sphere => primitive(Sphere::try_new(d0).map(Shape::Sphere)),
        ShapeKindCode::Capsule => primitive(Capsule::try_new(d1, d0).map(Shape::Capsule)),
        ShapeKindCode::Cuboid => {
            primitive(Cuboid::try_new(DVec3::new(d0, d1, d2)).map(Shape::Cuboid))
        }
        ShapeKindCode::Cylinder => primitive(Cylinder::try_new(d1, d0).map(Shape::Cylinder)),
        ShapeKindCode::Cone => primitive(Cone::try_new(d1, d0).map(Shape::Cone)),
        ShapeKindCode::Convex => convex_request(request, payload_len, max_convex_points),
        ShapeKindCode::Mesh => mesh_request(request, payload_len, mesh_limits),
    }
}

/// A convex registration: at most `max_points` points, no indices.
fn convex_request(
    request: &ControlRequest,
    payload_len: usize,
    max_points: u32,
) -> Result<ShapeRequest, Rejection> {
    if request.vertex_count > max_points {
        return Err(Rejection::new(
            ErrorCode::LimitExceeded,
            format!("{} points, the limit is {max_points}", request.vertex_count),
        ));
    }
    check_payload_len(request.vertex_count, request.index_count, payload_len)?;
    if request.index_count != 0 {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            "a convex shape carries no indices",
        ));
    }
    Ok(ShapeRequest::Geometry(GeometryRequest {
        mesh: false,
        vertex_count: request.vertex_count,
        index_count: 0,
    }))
}

/// A mesh registration: index triples, vertex and triangle counts within `limits`.
fn mesh_request(
    request: &ControlRequest,
    payload_len: usize,
    limits: &MeshLimits,
) -> Result<ShapeRequest, Rejection> {
    // The limits first, from the header alone: nothing sized by the client is touched.
    let (vertices, triangles) = (
        request.vertex_count as usize,
        request.index_count as usize / 3,
    );
    if vertices > limits.max_vertices || triangles > limits.max_triangles {
        return Err(Rejection::new(
            ErrorCode::LimitExceeded,
            format!(
                "{vertices} vertices and {triangles} triangles, the limits are {} and {}",
                limits.max_vertices, limits.max_triangles
            ),
        ));
    }
    check_payload_len(request.vertex_count, request.index_count, payload_len)?;
    if !request.index_count.is_multiple_of(3) {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            "mesh indices are not a multiple of 3",
        ));
    }
    Ok(ShapeRequest::Geometry(GeometryRequest {
        mesh: true,
        vertex_count: request.vertex_count,
        index_count: request.index_count,
    }))
}

/// Refuses a payload whose length is not `24·vertex_count + 4·index_count` bytes.
fn check_payload_len(
    vertex_count: u32,
    index_count: u32,
    payload_len: usize,
) -> Result<(), Rejection> {
    let (points, indices) = (vertex_count as usize, index_count as usize);
    let expected = points
        .checked_mul(24)
        .and_then(|v| indices.checked_mul(4).and_then(|i| v.checked_add(i)));
    if expected != Some(payload_len) {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            format!(
                "{points} points and {indices} indices need {expected:?} bytes, the payload has {payload_len}"
            ),
        ));
    }
    Ok(())
}

/// Decodes and builds the shape of a checked registration ([`shape_request`]) from its
/// `payload`: the hull of a convex shape's points, a mesh (checked against `mesh_limits`)
/// with its BVHs. O(n log n) and more: the builder thread's work.
pub fn geometry_shape(
    geometry: GeometryRequest,
    payload: &[u8],
    mesh_limits: &MeshLimits,
) -> Result<Shape, Rejection> {
    let (points, indices) = decode(geometry, payload)?;
    if geometry.mesh {
        mesh(points, &indices, mesh_limits)
    } else {
        convex(&points)
    }
}

/// The convex hull of `points`.
fn convex(points: &[DVec3]) -> Result<Shape, Rejection> {
    ConvexPolyhedron::try_from_points(points)
        .map(|hull| Shape::Convex(Arc::new(hull)))
        .map_err(|e| {
            // A coordinate beyond the limit is a bad shape, not a size limit (the number of
            // points was checked against the limit before decoding).
            let code = match e {
                ConvexHullError::Empty => ErrorCode::EmptyGeometry,
                ConvexHullError::NonFinite { .. } | ConvexHullError::TooLarge { .. } => {
                    ErrorCode::InvalidShape
                }
            };
            Rejection::new(code, e.to_string())
        })
}

/// A triangle mesh of `vertices` and index triples `indices`, with its BVHs.
fn mesh(vertices: Vec<DVec3>, indices: &[u32], limits: &MeshLimits) -> Result<Shape, Rejection> {
    let triangles = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    TriMesh::try_new_with_limits(vertices, triangles, limits)
        .map(|mesh| Shape::Mesh(Arc::new(MeshShape::new(mesh))))
        .map_err(|e| {
            let code = match e {
                MeshError::Empty => ErrorCode::EmptyGeometry,
                MeshError::IndexOutOfRange { .. } => ErrorCode::MeshIndexOutOfRange,
                MeshError::TooManyVertices { .. } | MeshError::TooManyTriangles { .. } => {
                    ErrorCode::LimitExceeded
                }
                _ => ErrorCode::InvalidShape,
            };
            Rejection::new(code, e.to_string())
        })
}

/// Decodes the geometry payload: `vertex_count` points, then `index_count` indices.
fn decode(geometry: GeometryRequest, payload: &[u8]) -> Result<(Vec<DVec3>, Vec<u32>), Rejection> {
    check_payload_len(geometry.vertex_count, geometry.index_count, payload.len())?;
    let points = geometry.vertex_count as usize;
    let (vertex_bytes, index_bytes) = payload.split_at(points * 24);
    let coordinate = |b: &[u8]| f64::from_ne_bytes(b.try_into().expect("8 bytes"));
    let vertices = vertex_bytes
        .chunks_exact(24)
        .map(|v| {
            DVec3::new(
                coordinate(&v[..8]),
                coordinate(&v[8..16]),
                coordinate(&v[16..]),
            )
        })
        .collect();
    let indices = index_bytes
        .chunks_exact(4)
        .map(|b| u32::from_ne_bytes(b.try_into().expect("4 bytes")))
        .collect();
    Ok((vertices, indices))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_defined_flag_combination_becomes_the_matching_query() {
        let mut with_toi = 0;
        for flags in 1..=query::ALL {
            let q = query(flags).unwrap_or_else(|r| panic!("flags {flags:#x} refused: {r:?}"));
            assert_eq!(q.overlap, flags & query::OVERLAP != 0);
            assert_eq!(q.close, flags & query::CLOSE != 0);
            assert_eq!(q.distance, flags & query::DISTANCE != 0);
            assert_eq!(q.contacts, flags & query::CONTACTS != 0);
            assert_eq!(q.toi, flags & query::TOI != 0);
            with_toi += usize::from(q.toi);
        }
        // TOI alone and with each of the 15 combinations of the others.
        assert_eq!(with_toi, 16);
    }

    #[test]
    fn no_flags_and_undefined_bits_are_refused_with_a_reason() {
        for flags in [0, 1 << 5, query::CLOSE | 1 << 31] {
            let r = query(flags).expect_err("refused");
            assert_eq!(r.code, ErrorCode::MalformedMessage);
            assert!(!r.reason.is_empty());
        }
    }
}
