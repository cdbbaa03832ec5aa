//! Coincident meshes: two copies of one 2,000-triangle blob (a UV sphere of radius 0.5 m,
//! 40 segments × 26 rings, its radius bumped by up to ±8 % with a smooth pattern) at
//! nearly the same pose. The first stays at the origin (static); the second moves a
//! millimetre or so and turns by about half a degree each frame, so the two surfaces cross
//! each other nearly everywhere: the costliest case of a contact query.

use super::spec::{BodyPlan, SceneSpec, ShapeSpec};
use glam::{DQuat, DVec3};
use proxima::geometry::TriMesh;
use proxima_ipc::client::Motion;
use proxima_ipc::wire::PoseRecord;
use std::error::Error;
use std::sync::Arc;

/// Close-pair margin of both bodies, metres.
const MARGIN_M: f64 = 0.005;

/// The moving copy's daemon id and frame count.
#[derive(Debug, Clone, Copy)]
pub struct CoincidentMeshes {
    moving: u32,
    frame: u64,
}

impl CoincidentMeshes {
    /// The scene (the static copy, then the moving one at its frame-0 pose) and its
    /// motion, whose moving id is to be set by [`with_ids`](Self::with_ids).
    ///
    /// # Errors
    /// The blob is not a valid mesh (it is, by construction).
    pub fn build() -> Result<(SceneSpec, Self), Box<dyn Error>> {
        let mut spec = SceneSpec::default();
        let blob = spec.add_shape(ShapeSpec::Mesh(Arc::new(blob()?)));
        let motion = Self {
            moving: 0,
            frame: 0,
        };
        for (motion_kind, pose) in [
            (Motion::Static, (DVec3::ZERO, DQuat::IDENTITY)),
            (Motion::Kinematic, motion.pose_at(0)),
        ] {
            spec.add_body(BodyPlan {
                shape: blob,
                position: pose.0,
                orientation: pose.1,
                motion: motion_kind,
                margin_m: MARGIN_M,
            });
        }
        Ok((spec, motion))
    }

    /// This motion moving body `ids[1]` (the registered ids, in list order).
    #[must_use]
    pub fn with_ids(mut self, ids: &[u32]) -> Self {
        self.moving = ids[1];
        self
    }

    /// The moving copy's pose record at the current frame (the only pose a frame carries).
    #[must_use]
    pub fn pose(&self) -> PoseRecord {
        let (position, orientation) = self.pose_at(self.frame);
        PoseRecord {
            body: self.moving,
            reserved: 0,
            position: position.to_array(),
            orientation: orientation.to_array(),
        }
    }

    /// Moves to the next frame.
    pub fn advance(&mut self) {
        self.frame += 1;
    }

    /// Within 1 mm of the origin, turned by at most 0.01 rad.
    fn pose_at(&self, frame: u64) -> (DVec3, DQuat) {
        let t = frame as f64;
        let offset = DVec3::new((0.05 * t).sin(), (0.07 * t).cos(), (0.03 * t).sin()) * 1e-3;
        let axis = DVec3::new((0.011 * t).cos(), (0.013 * t).sin(), 1.0).normalize();
        (
            offset,
            DQuat::from_axis_angle(axis, 0.01 * (0.02 * t).sin()),
        )
    }
}

/// The blob: 2 · 40 · 25 = 2,000 triangles.
fn blob() -> Result<TriMesh, Box<dyn Error>> {
    let sphere = TriMesh::uv_sphere(0.5, 40, 26);
    let bumped = sphere
        .vertices()
        .iter()
        .map(|v| {
            let u = v.normalize_or_zero();
            let bump = 0.08 * (3.0 * u.x).sin() * (2.0 * u.y + 1.0).cos() * (1.0 + u.z * u.z) / 2.0;
            *v * (1.0 + bump)
        })
        .collect();
    Ok(TriMesh::try_new(bumped, sphere.triangles().to_vec())?)
}
