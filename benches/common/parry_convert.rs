//! Proxima's values in parry3d-f64's types, for the benches and examples that run parry
//! on the same inputs. Include with `#[path = ".../benches/common/parry_convert.rs"] mod
//! parry_convert;`; items one file does not use are allowed.
#![allow(dead_code)]

use parry3d_f64::math::{Pose as ParryPose, Rotation as ParryRotation, Vector as ParryVector};
use parry3d_f64::shape::TriMesh as ParryMesh;
use proxima::geometry::TriMesh;
use proxima::math::{DQuat, DVec3, Pose};

/// The same vector.
pub fn parry_vector(v: DVec3) -> ParryVector {
    ParryVector::new(v.x, v.y, v.z)
}

/// The same pose: translation and quaternion.
pub fn parry_pose(pose: &Pose) -> ParryPose {
    let q = pose.rotation;
    ParryPose::from_parts(
        parry_vector(pose.position),
        ParryRotation::from_xyzw(q.x, q.y, q.z, q.w),
    )
}

/// The same mesh: the very same `f64` vertices and index triples.
pub fn parry_mesh(mesh: &TriMesh) -> ParryMesh {
    let vertices = mesh.vertices().iter().map(|&p| parry_vector(p)).collect();
    ParryMesh::new(vertices, mesh.triangles().to_vec()).expect("parry accepts the mesh")
}

/// The pose of parry's cylinder (its axis along Y) in Proxima's cylinder frame (axis along
/// Z): a quarter turn about X, which maps Y to Z. A Proxima cylinder at `pose` is parry's
/// at `pose.compose(&parry_cylinder_offset())`.
pub fn parry_cylinder_offset() -> Pose {
    Pose::from_rotation(DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2))
}
