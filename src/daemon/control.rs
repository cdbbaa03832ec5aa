//! The control service's logic: one request in, one reply out, against the daemon's scenes.
//!
//! State handling, no IPC: the control thread receives a request, calls
//! [`ControlState::handle`] and sends the reply. A refused request changes nothing and gets
//! the error code and reason; it is logged once by the caller.
//!
//! Every request is O(1) or a copy: scene edits take the scene's lock
//! ([`shared_scene`]) for one edit; a convex or mesh registration is
//! checked ([`convert::shape_request`]), gets its shape id, and its payload is copied into a
//! [`BuildJob`] for the builder thread; the reply says the shape is being built.

use super::builder::{BuildJob, BuildQueue};
use super::config::DaemonConfig;
use super::convert::{self, Rejection, ShapeRequest};
use super::shape_table::ShapeState;
use super::shared_scene::{self, SharedScene, lock};
use crate::broad::{BroadPhaseChoice, BroadPhaseKind};
use crate::scene::{BodyDesc, BodyId, Scene};
use proxima_ipc::PROTOCOL_VERSION;
use proxima_ipc::wire::{
    BroadPhaseCode, Command, ControlReply, ControlRequest, ErrorCode, reply_flags,
};
use std::sync::Arc;

/// The scenes a daemon serves, by id (ids are not reused while the daemon runs), and the
/// queue of shapes to build.
#[derive(Debug)]
pub struct ControlState {
    config: DaemonConfig,
    scenes: Vec<Option<SharedScene>>,
    live_scenes: u32,
    builds: BuildQueue,
}

/// A successful request's reply: the id and the [`reply_flags`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Answer {
    id: u32,
    flags: u32,
}

impl From<u32> for Answer {
    fn from(id: u32) -> Self {
        Self { id, flags: 0 }
    }
}

impl ControlState {
    /// No scenes yet; convex and mesh shapes go to `builds`.
    #[must_use]
    pub fn new(config: DaemonConfig, builds: BuildQueue) -> Self {
        Self {
            config,
            scenes: Vec::new(),
            live_scenes: 0,
            builds,
        }
    }

    /// Scene `id`, if it lives.
    #[must_use]
    pub fn scene(&self, id: u32) -> Option<&SharedScene> {
        self.scenes.get(id as usize).and_then(Option::as_ref)
    }

    /// Answers one request; the state changes only when the reply is a success.
    pub fn handle(&mut self, request: &ControlRequest, payload: &[u8]) -> ControlReply {
        match self.try_handle(request, payload) {
            Ok(Answer { id, flags }) => ControlReply::ok_with(id, flags),
            Err(r) => ControlReply::error(r.code, &r.reason),
        }
    }

    fn try_handle(
        &mut self,
        request: &ControlRequest,
        payload: &[u8],
    ) -> Result<Answer, Rejection> {
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
            Command::Hello => Ok(PROTOCOL_VERSION.into()),
            Command::CreateScene => self.create_scene().map(Answer::from),
            Command::DropScene => self
                .drop_scene(request.scene)
                .map(|()| request.scene.into()),
            Command::RegisterShape => self.register_shape(request, payload),
            Command::ShapeState => {
                let building = match lock(self.live_scene(request.scene)?)
                    .shapes
                    .state(request.target)?
                {
                    ShapeState::Building => reply_flags::SHAPE_BUILDING,
                    ShapeState::Ready => 0,
                };
                Ok(Answer {
                    id: request.target,
                    flags: building,
                })
            }
            Command::AddBody => self.add_body(request).map(Answer::from),
            Command::RemoveBody => {
                let body = BodyId(request.target);
                let mut cell = lock(self.live_scene(request.scene)?);
                cell.scene.remove_body(body).map_err(scene_rejection)?;
                Ok(request.target.into())
            }
            Command::UpdateBody => {
                let motion = convert::motion(request.motion)?;
                let (filter, margin) = (convert::filter(request), convert::margin(request.margin));
                let mut cell = lock(self.live_scene(request.scene)?);
                cell.scene
                    .update_body(BodyId(request.target), motion, filter, margin)
                    .map_err(scene_rejection)?;
                Ok(request.target.into())
            }
            Command::SetSceneParams => {
                let choice = broad_phase(request.broad_phase)?;
                lock(self.live_scene(request.scene)?)
                    .scene
                    .set_broad_phase(choice);
                Ok(request.scene.into())
            }
        }
    }

    /// Adds a body of a built shape: the request is checked before the scene is locked.
    fn add_body(&self, request: &ControlRequest) -> Result<u32, Rejection> {
        let pose = convert::pose(request.position, request.orientation)?;
        let motion = convert::motion(request.motion)?;
        let mut cell = lock(self.live_scene(request.scene)?);
        let desc = BodyDesc {
            shape: cell.shapes.usable(request.target)?,
            pose,
            motion,
            filter: convert::filter(request),
            margin: convert::margin(request.margin),
        };
        Ok(cell.scene.add_body(&desc).map_err(scene_rejection)?.0)
    }

    /// A primitive is registered at once; a convex or mesh shape gets its id and goes to
    /// the builder with a copy of its payload (the reply says it is being built).
    fn register_shape(
        &self,
        request: &ControlRequest,
        payload: &[u8],
    ) -> Result<Answer, Rejection> {
        let config = &self.config;
        let max_shapes = config.scene_limits.max_shapes;
        let shape = convert::shape_request(
            request,
            payload.len(),
            &config.mesh_limits,
            config.max_convex_points,
        )?;
        let shared = self.live_scene(request.scene)?;
        let geometry = match shape {
            ShapeRequest::Primitive(shape) => {
                let mut cell = lock(shared);
                // The table hands out no more ids than the scene takes shapes, so the
                // scene has room for this one.
                let id = cell.shapes.reserve(max_shapes)?;
                let registered = cell.scene.register_shape(shape).map_err(scene_rejection);
                cell.shapes.finish(id, registered.clone());
                return registered.map(|_| id.into());
            }
            ShapeRequest::Geometry(geometry) => geometry,
        };
        // Before an id is handed out for nothing: only this thread queues, so the room
        // found here is still there below.
        self.builds.check_room()?;
        let shape = lock(shared).shapes.reserve(max_shapes)?;
        let job = BuildJob {
            scene_id: request.scene,
            shape,
            scene: Arc::downgrade(shared),
            geometry,
            payload: payload.to_vec(),
        };
        if let Err(refused) = self.builds.submit(job) {
            lock(shared).shapes.finish(shape, Err(refused.clone()));
            return Err(refused);
        }
        Ok(Answer {
            id: shape,
            flags: reply_flags::SHAPE_BUILDING,
        })
    }

    /// Drops scene `id` with all its shapes and bodies (a frame or build still holding it
    /// leaves it alone, see [`shared_scene`]).
    ///
    /// # Errors
    /// [`ErrorCode::UnknownScene`] when no such scene lives.
    pub fn drop_scene(&mut self, id: u32) -> Result<(), Rejection> {
        lock(self.live_scene(id)?).dropped = true;
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
        self.scenes.push(Some(shared_scene::share(scene)));
        self.live_scenes += 1;
        Ok(self.scenes.len() as u32 - 1)
    }

    fn live_scene(&self, id: u32) -> Result<&SharedScene, Rejection> {
        self.scene(id)
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
