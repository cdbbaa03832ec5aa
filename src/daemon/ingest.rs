//! Stage 1 of a frame: check a pose frame and apply its poses to the scene.
//!
//! A frame is applied whole or not at all: the header is checked (protocol, scene, count,
//! query flags, see [`convert::query`]), then every record (known body, finite position
//! within range, unit quaternion — renormalised within 1e-6), and only then are the poses
//! written. A rejected frame leaves the scene as it was and names the first
//! offending body, so a client's bad frame never corrupts the state other frames rely on.

use super::convert::{self, Rejection};
use crate::math::Pose;
use crate::pipeline::Query;
use crate::scene::{BodyId, Scene};
use proxima_ipc::PROTOCOL_VERSION;
use proxima_ipc::wire::{ErrorCode, PoseFrameHeader, PoseRecord};

/// A frame the scene refused: why, and which body (`None` for a header problem).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameRejection {
    /// Code and reason.
    pub rejection: Rejection,
    /// The body whose record was refused.
    pub body: Option<u32>,
}

/// Checks `header` and `records` against `scene` (id `scene_id`) and applies the poses;
/// returns the frame's query. `validated` is scratch space for the checked poses (cleared,
/// reused across frames).
///
/// # Errors
/// The first problem found; the scene is then unchanged.
pub fn apply_pose_frame(
    scene_id: u32,
    scene: &mut Scene,
    header: &PoseFrameHeader,
    records: &[PoseRecord],
    validated: &mut Vec<(BodyId, Pose)>,
) -> Result<Query, FrameRejection> {
    let refuse = |code, reason: String, body| {
        Err(FrameRejection {
            rejection: Rejection::new(code, reason),
            body,
        })
    };
    if header.protocol_version != PROTOCOL_VERSION {
        return refuse(
            ErrorCode::ProtocolMismatch,
            format!(
                "frame speaks protocol {}, the daemon {PROTOCOL_VERSION}",
                header.protocol_version
            ),
            None,
        );
    }
    if header.scene != scene_id {
        return refuse(
            ErrorCode::UnknownScene,
            format!(
                "frame for scene {} on scene {scene_id}'s service",
                header.scene
            ),
            None,
        );
    }
    if header.count as usize != records.len() {
        return refuse(
            ErrorCode::MalformedMessage,
            format!(
                "header counts {} poses, the payload holds {}",
                header.count,
                records.len()
            ),
            None,
        );
    }
    let query = convert::query(header.query_flags).map_err(|rejection| FrameRejection {
        rejection,
        body: None,
    })?;
    validated.clear();
    for record in records {
        let id = BodyId(record.body);
        if record.reserved != 0 {
            return refuse(
                ErrorCode::MalformedMessage,
                format!("pose of body {}: reserved field is not 0", record.body),
                Some(record.body),
            );
        }
        if scene.body(id).is_none() {
            return refuse(
                ErrorCode::UnknownBody,
                format!("no body {} in scene {scene_id}", record.body),
                Some(record.body),
            );
        }
        match convert::pose(record.position, record.orientation) {
            Ok(pose) => validated.push((id, pose)),
            Err(rejection) => {
                return Err(FrameRejection {
                    rejection,
                    body: Some(record.body),
                });
            }
        }
    }
    for &(id, pose) in validated.iter() {
        scene
            .set_pose(id, pose)
            .expect("checked above: the body lives");
    }
    Ok(query)
}

#[cfg(test)]
#[path = "ingest_tests.rs"]
mod tests;
