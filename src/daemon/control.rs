//! The control service's logic: one request in, one reply out, against the daemon's scenes.
//!
//! Pure state handling, no IPC: the service loop in [`super`] receives a request, calls
//! [`ControlState::handle`] and sends the reply. A refused request changes nothing and gets
//! the error code and reason; it is logged once by the caller.

use super::config::DaemonConfig;
use super::convert::{self, Rejection};
use crate::broad::{BroadPhaseChoice, BroadPhaseKind};
use crate::scene::{BodyDesc, BodyId, Scene, ShapeId};
use proxima_ipc::PROTOCOL_VERSION;
use proxima_ipc::wire::{BroadPhaseCode, Command, ControlReply, ControlRequest, ErrorCode};

/// The scenes a daemon serves, by id (ids are not reused while the daemon runs).
#[derive(Debug)]
pub struct ControlState {
    config: DaemonConfig,
    scenes: Vec<Option<Scene>>,
    live_scenes: u32,
}

impl ControlState {
    /// No scenes yet.
    #[must_use]
    pub fn new(config: DaemonConfig) -> Self {
        Self {
            config,
            scenes: Vec::new(),
            live_scenes: 0,
        }
    }

    /// Scene `id`, if it lives.
    #[must_use]
    pub fn scene(&self, id: u32) -> Option<&Scene> {
        self.scenes.get(id as usize).and_then(Option::as_ref)
    }

    /// Scene `id`, mutable, if it lives.
    pub fn scene_mut(&mut self, id: u32) -> Option<&mut Scene> {
        self.scenes.get_mut(id as usize).and_then(Option::as_mut)
    }

    /// Answers one request; the state changes only when the reply is a success.
    pub fn handle(&mut self, request: &ControlRequest, payload: &[u8]) -> ControlReply {
        match self.try_handle(request, payload) {
            Ok(id) => ControlReply::ok(id),
            Err(r) => ControlReply::error(r.code, &r.reason),
        }
    }

    fn try_handle(&mut self, request: &ControlRequest, payload: &[u8]) -> Result<u32, Rejection> {
        if request.protocol_version != PROTOCOL_VERSION {
            return Err(Rejection::new(
                ErrorCode::ProtocolMismatch,
                format!(
                    "client speaks protocol {}, the daemon {PROTOCOL_VERSION}",
                    request.protocol_version
                ),
            ));
        }
        let Some(command) = Command::from_u32(request.command) else {
            return Err(Rejection::new(
                ErrorCode::MalformedMessage,
                format!("unknown command {}", request.command),
            ));
        };
        if !payload.is_empty() && command != Command::RegisterShape {
            return Err(Rejection::new(
                ErrorCode::MalformedMessage,
                "only RegisterShape carries a payload",
            ));
        }
        match command {
            Command::Hello => Ok(PROTOCOL_VERSION),
            Command::CreateScene => self.create_scene(),
            Command::DropScene => self.drop_scene(request.scene).map(|()| request.scene),
            Command::RegisterShape => {
                let shape = convert::shape(
                    request,
                    payload,
                    &self.config.mesh_limits,
                    self.config.max_convex_points,
                )?;
                let scene = self.live_scene(request.scene)?;
                Ok(scene.register_shape(shape).map_err(scene_rejection)?.0)
            }
            Command::AddBody => {
                let desc = BodyDesc {
                    shape: ShapeId(request.target),
                    pose: convert::pose(request.position, request.orientation)?,
                    motion: convert::motion(request.motion)?,
                    filter: convert::filter(request),
                    margin: convert::margin(request.margin),
                };
                let scene = self.live_scene(request.scene)?;
                Ok(scene.add_body(&desc).map_err(scene_rejection)?.0)
            }
            Command::RemoveBody => {
                let scene = self.live_scene(request.scene)?;
                scene
                    .remove_body(BodyId(request.target))
                    .map_err(scene_rejection)?;
                Ok(request.target)
            }
            Command::UpdateBody => {
                let motion = convert::motion(request.motion)?;
                let (filter, margin) = (convert::filter(request), convert::margin(request.margin));
                let scene = self.live_scene(request.scene)?;
                scene
                    .update_body(BodyId(request.target), motion, filter, margin)
                    .map_err(scene_rejection)?;
                Ok(request.target)
            }
            Command::SetSceneParams => {
                let choice = broad_phase(request.broad_phase)?;
                self.live_scene(request.scene)?.set_broad_phase(choice);
                Ok(request.scene)
            }
        }
    }

    /// Drops scene `id` with all its shapes and bodies.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownScene`] when no such scene lives.
    pub fn drop_scene(&mut self, id: u32) -> Result<(), Rejection> {
        self.live_scene(id)?;
        self.scenes[id as usize] = None;
        self.live_scenes -= 1;
        Ok(())
    }

    fn create_scene(&mut self) -> Result<u32, Rejection> {
        if self.live_scenes >= self.config.max_scenes {
            return Err(Rejection::new(
                ErrorCode::LimitExceeded,
                format!(
                    "the daemon's limit of {} scenes is reached",
                    self.config.max_scenes
                ),
            ));
        }
        let scene = Scene::try_new(self.config.default_margin, self.config.scene_limits)
            .map_err(scene_rejection)?;
        self.scenes.push(Some(scene));
        self.live_scenes += 1;
        Ok(self.scenes.len() as u32 - 1)
    }

    fn live_scene(&mut self, id: u32) -> Result<&mut Scene, Rejection> {
        self.scene_mut(id)
            .ok_or_else(|| Rejection::new(ErrorCode::UnknownScene, format!("no scene {id}")))
    }
}

/// The broad-phase choice of a wire code.
fn broad_phase(code: u32) -> Result<BroadPhaseChoice, Rejection> {
    let code = BroadPhaseCode::from_u32(code).ok_or_else(|| {
        Rejection::new(
            ErrorCode::MalformedMessage,
            format!("unknown broad phase {code} (0 auto, 1 sort and sweep, 2 incremental SAP, 3 hash grid, 4 column grid, 5 skin grid)"),
        )
    })?;
    Ok(match code {
        BroadPhaseCode::Auto => BroadPhaseChoice::Auto,
        BroadPhaseCode::SortAndSweep => BroadPhaseChoice::Fixed(BroadPhaseKind::SortAndSweep),
        BroadPhaseCode::IncrementalSap => BroadPhaseChoice::Fixed(BroadPhaseKind::IncrementalSap),
        BroadPhaseCode::HashGrid => BroadPhaseChoice::Fixed(BroadPhaseKind::HashGrid),
        BroadPhaseCode::ColumnGrid => BroadPhaseChoice::Fixed(BroadPhaseKind::ColumnGrid),
        BroadPhaseCode::SkinGrid => BroadPhaseChoice::Fixed(BroadPhaseKind::SkinGrid),
    })
}

fn scene_rejection(e: crate::scene::SceneError) -> Rejection {
    use crate::scene::SceneError as E;
    let code = match e {
        E::UnknownShape(_) => ErrorCode::UnknownShape,
        E::UnknownBody(_) => ErrorCode::UnknownBody,
        E::TooManyShapes(_) | E::TooManyBodies(_) => ErrorCode::LimitExceeded,
        _ => ErrorCode::MalformedMessage,
    };
    Rejection::new(code, e.to_string())
}

#[cfg(test)]
#[path = "control_tests.rs"]
mod tests;
