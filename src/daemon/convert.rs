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

/// The shape a `RegisterShape` request describes, its geometry decoded from `payload`.
pub fn shape(
    request: &ControlRequest,
    payload: &[u8],
    mesh_limits: &MeshLimits,
    max_convex_points: u32,
) -> Result<Shape, Rejection> {
    let Some(kind) = ShapeKindCode::from_u32(request.shape_kind) else {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            format!("unknown shape kind {}", request.shape_kind),
        ));
    };
    let [d0, d1, d2, _] = request.dimensions;
    let primitive = |result: Result<Shape, crate::geometry::ShapeError>| {
        let has_geometry =
            !payload.is_empty() || request.vertex_count != 0 || request.index_count != 0;
        if has_geometry {
            return Err(Rejection::new(
                ErrorCode::MalformedMessage,
                "a primitive shape carries no geometry payload",
            ));
        }
        result.map_err(|e| Rejection::new(ErrorCode::InvalidShape, e.to_string()))
    };
    match kind {
        ShapeKindCode::Sphere => primitive(Sphere::try_new(d0).map(Shape::Sphere)),
        ShapeKindCode::Capsule => primitive(Capsule::try_new(d1, d0).map(Shape::Capsule)),
        ShapeKindCode::Cuboid => {
            primitive(Cuboid::try_new(DVec3::new(d0, d1, d2)).map(Shape::Cuboid))
        }
        ShapeKindCode::Cylinder => primitive(Cylinder::try_new(d1, d0).map(Shape::Cylinder)),
        ShapeKindCode::Cone => primitive(Cone::try_new(d1, d0).map(Shape::Cone)),
        ShapeKindCode::Convex => convex(request, payload, max_convex_points),
        ShapeKindCode::Mesh => mesh(request, payload, mesh_limits),
    }
}

/// A convex shape: the hull of the payload's points (no indices allowed).
fn convex(request: &ControlRequest, payload: &[u8], max_points: u32) -> Result<Shape, Rejection> {
    if request.vertex_count > max_points {
        return Err(Rejection::new(
            ErrorCode::LimitExceeded,
            format!("{} points, the limit is {max_points}", request.vertex_count),
        ));
    }
    let (points, indices) = geometry(request, payload)?;
    if !indices.is_empty() {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            "a convex shape carries no indices",
        ));
    }
    ConvexPolyhedron::try_from_points(&points)
        .map(|hull| Shape::Convex(Arc::new(hull)))
        .map_err(|e| {
            let code = match e {
                ConvexHullError::Empty => ErrorCode::EmptyGeometry,
                ConvexHullError::TooLarge { .. } => ErrorCode::LimitExceeded,
                _ => ErrorCode::InvalidShape,
            };
            Rejection::new(code, e.to_string())
        })
}

/// A triangle mesh from the payload's points and index triples, with its BVHs.
fn mesh(request: &ControlRequest, payload: &[u8], limits: &MeshLimits) -> Result<Shape, Rejection> {
    let (vertices, indices) = geometry(request, payload)?;
    if indices.len() % 3 != 0 {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            "mesh indices are not a multiple of 3",
        ));
    }
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
fn geometry(request: &ControlRequest, payload: &[u8]) -> Result<(Vec<DVec3>, Vec<u32>), Rejection> {
    let (points, indices) = (request.vertex_count as usize, request.index_count as usize);
    let expected = points
        .checked_mul(24)
        .and_then(|v| indices.checked_mul(4).and_then(|i| v.checked_add(i)));
    if expected != Some(payload.len()) {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            format!(
                "{points} points and {indices} indices need {expected:?} bytes, the payload has {}",
                payload.len()
            ),
        ));
    }
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
