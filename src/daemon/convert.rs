//! Wire records to validated domain values, once, at the boundary. Every function here
//! takes untrusted input and returns either a value the engine may trust or a
//! [`Rejection`] naming the wire error code and the reason.

use crate::geometry::decompose;
use crate::geometry::{
    Capsule, Cone, ConvexHullError, ConvexPolyhedron, Cuboid, Cylinder, MeshError, MeshLimits,
    Sphere, TriMesh,
};
use crate::math::{DQuat, DVec3, Pose};
use crate::narrow::{CompoundShape, MeshShape, Shape};
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

/// What a geometry registration builds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GeometryKind {
    /// The convex hull of the points.
    Convex,
    /// A triangle mesh.
    Mesh,
    /// Convex parts: the indices are the number of points of each part.
    Compound,
    /// A closed triangle mesh, decomposed into convex parts with these options.
    Decomposed(decompose::Options),
}

impl GeometryKind {
    /// Whether the indices are triangles' vertex indices.
    #[must_use]
    pub fn is_mesh(self) -> bool {
        matches!(self, Self::Mesh | Self::Decomposed(_))
    }
}

/// The most triangles of a [`ShapeKindCode::DecomposedMesh`]: a decomposition of a
/// 70,000-triangle mesh takes about a minute on the builder thread.
pub const MAX_DECOMPOSED_TRIANGLES: usize = 200_000;

/// A geometry registration whose counts are within the limits and whose payload length
/// matches them (see [`shape_request`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeometryRequest {
    /// What the points and indices make.
    pub kind: GeometryKind,
    /// Points in the payload.
    pub vertex_count: u32,
    /// `u32` entries after the points: vertex indices (a multiple of 3) of a mesh, part
    /// sizes of a compound, none for a convex shape.
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
        ShapeKindCode::Mesh => mesh_request(request, payload_len, mesh_limits, GeometryKind::Mesh),
        ShapeKindCode::Compound => compound_request(request, payload_len, max_convex_points),
        ShapeKindCode::DecomposedMesh => {
            let options = decompose_options(request.dimensions)?;
            if request.index_count as usize / 3 > MAX_DECOMPOSED_TRIANGLES {
                return Err(Rejection::new(
                    ErrorCode::LimitExceeded,
                    format!(
                        "{} triangles; a decomposed mesh has at most {MAX_DECOMPOSED_TRIANGLES}",
                        request.index_count / 3
                    ),
                ));
            }
            mesh_request(
                request,
                payload_len,
                mesh_limits,
                GeometryKind::Decomposed(options),
            )
        }
    }
}

/// The decomposition options of a [`ShapeKindCode::DecomposedMesh`]'s `dimensions`:
/// `[max_concavity, max_parts, method, 0]`, zeros for the defaults.
fn decompose_options(dimensions: [f64; 4]) -> Result<decompose::Options, Rejection> {
    let [concavity, parts, method, unused] = dimensions;
    let bad = |what: String| Err(Rejection::new(ErrorCode::InvalidShape, what));
    let defaults = decompose::Options::default();
    if !(concavity.is_finite() && concavity >= 0.0) {
        return bad(format!(
            "max_concavity {concavity} is not a finite number ≥ 0"
        ));
    }
    let max_parts = f64::from(wire::MAX_COMPOUND_PARTS);
    if !(parts >= 0.0 && parts <= max_parts && parts.fract() == 0.0) {
        return bad(format!(
            "max_parts {parts} is not a whole number in 0..={max_parts}"
        ));
    }
    let method = match method {
        0.0 => decompose::Method::CutSearch,
        1.0 => decompose::Method::Relaxation,
        _ => {
            return bad(format!(
                "method {method} is neither 0 (cut search) nor 1 (relaxation)"
            ));
        }
    };
    if unused != 0.0 {
        return bad(format!("dimensions[3] is {unused}, not 0"));
    }
    Ok(decompose::Options {
        method,
        max_concavity: if concavity == 0.0 {
            defaults.max_concavity
        } else {
            concavity
        },
        // A whole number in 0..=MAX_COMPOUND_PARTS, checked above.
        max_parts: if parts == 0.0 {
            defaults.max_parts
        } else {
            parts as usize
        },
        // The builder thread keeps to itself: a second search thread would take the core
        // the frame thread counts on.
        threads: 1,
        ..defaults
    })
}

/// A compound registration: at most `max_points` points in all and
/// [`MAX_COMPOUND_PARTS`](wire::MAX_COMPOUND_PARTS) parts, as many points as the part
/// sizes say.
fn compound_request(
    request: &ControlRequest,
    payload_len: usize,
    max_points: u32,
) -> Result<ShapeRequest, Rejection> {
    if request.vertex_count > max_points || request.index_count > wire::MAX_COMPOUND_PARTS {
        return Err(Rejection::new(
            ErrorCode::LimitExceeded,
            format!(
                "{} points in {} parts, the limits are {max_points} and {}",
                request.vertex_count,
                request.index_count,
                wire::MAX_COMPOUND_PARTS
            ),
        ));
    }
    check_payload_len(request.vertex_count, request.index_count, payload_len)?;
    Ok(ShapeRequest::Geometry(GeometryRequest {
        kind: GeometryKind::Compound,
        vertex_count: request.vertex_count,
        index_count: request.index_count,
    }))
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
        kind: GeometryKind::Convex,
        vertex_count: request.vertex_count,
        index_count: 0,
    }))
}

/// A mesh registration (of `kind`, a mesh or a decomposed one): index triples, vertex and
/// triangle counts within `limits`.
fn mesh_request(
    request: &ControlRequest,
    payload_len: usize,
    limits: &MeshLimits,
    kind: GeometryKind,
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
        kind,
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
/// with its BVHs, a compound of its parts' hulls, or a closed mesh's decomposition. O(n log
/// n) and more (a decomposition: seconds to a minute): the builder thread's work.
pub fn geometry_shape(
    geometry: GeometryRequest,
    payload: &[u8],
    mesh_limits: &MeshLimits,
) -> Result<Shape, Rejection> {
    let (points, indices) = decode(geometry, payload)?;
    match geometry.kind {
        GeometryKind::Convex => convex(&points).map(|hull| Shape::Convex(Arc::new(hull))),
        GeometryKind::Mesh => {
            trimesh(points, &indices, mesh_limits).map(|m| Shape::Mesh(Arc::new(MeshShape::new(m))))
        }
        GeometryKind::Compound => compound(&points, &indices),
        GeometryKind::Decomposed(options) => decomposed(points, &indices, mesh_limits, &options),
    }
}

/// The compound of the hulls of consecutive runs of `points`, `sizes[i]` points each.
fn compound(points: &[DVec3], sizes: &[u32]) -> Result<Shape, Rejection> {
    let total: u64 = sizes.iter().map(|&n| u64::from(n)).sum();
    if total != points.len() as u64 || sizes.contains(&0) {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            format!(
                "the part sizes sum to {total} for {} points, or a part has none",
                points.len()
            ),
        ));
    }
    let mut rest = points;
    let mut hulls = Vec::with_capacity(sizes.len());
    for &n in sizes {
        let (part, after) = rest.split_at(n as usize);
        rest = after;
        hulls.push(convex(part)?);
    }
    CompoundShape::from_hulls(hulls)
        .map(|c| Shape::Compound(Arc::new(c)))
        .map_err(|e| Rejection::new(ErrorCode::EmptyGeometry, e.to_string()))
}

/// The compound of the convex decomposition of a closed mesh.
fn decomposed(
    vertices: Vec<DVec3>,
    indices: &[u32],
    limits: &MeshLimits,
    options: &decompose::Options,
) -> Result<Shape, Rejection> {
    let mesh = trimesh(vertices, indices, limits)?;
    let parts = decompose::decompose(&mesh, options)
        .map_err(|e| Rejection::new(ErrorCode::InvalidShape, e.to_string()))?;
    CompoundShape::from_decomposition(&parts)
        .map(|c| Shape::Compound(Arc::new(c)))
        .map_err(|e| Rejection::new(ErrorCode::InvalidShape, e.to_string()))
}

/// The convex hull of `points`.
fn convex(points: &[DVec3]) -> Result<ConvexPolyhedron, Rejection> {
    ConvexPolyhedron::try_from_points(points).map_err(|e| {
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

/// A triangle mesh of `vertices` and index triples `indices`.
fn trimesh(
    vertices: Vec<DVec3>,
    indices: &[u32],
    limits: &MeshLimits,
) -> Result<TriMesh, Rejection> {
    let triangles = indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    TriMesh::try_new_with_limits(vertices, triangles, limits).map_err(|e| {
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
