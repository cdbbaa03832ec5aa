//! The service loop: the daemon's iceoryx2 node, its control server, and the cycle that
//! serves them until a termination signal.
//!
//! Each cycle answers the control requests, then every scene's waiting pose frames
//! ([`SceneFrames`]). A scene's ports are opened when the scene is created and closed when
//! it is dropped. TODO(#4): blocking on the scenes' events between frames (hybrid wait),
//! the worker pool, dead-client cleanup.

use super::config::DaemonConfig;
use super::control::ControlState;
use super::error::{DaemonRunError, DaemonStartError};
use super::frame_loop::SceneFrames;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use proxima_ipc::wire::{Command, ControlReply, ControlRequest, ErrorCode};
use std::time::Duration;

/// A running `proximad`: node, control server and the scenes' state.
pub struct Daemon<S: Service> {
    node: Node<S>,
    control: Server<S, [u8], ControlRequest, ControlReply, ()>,
    state: ControlState,
    root: String,
    /// Scene id → its frame ports (`None` for dropped scenes).
    frames: Vec<Option<SceneFrames<S>>>,
}

impl<S: Service> Daemon<S> {
    /// Creates the node (with `config.iceoryx_prefix` when set) and the control service.
    ///
    /// # Errors
    /// [`DaemonStartError`] when the configuration is invalid or iceoryx2 fails.
    pub fn new(config: DaemonConfig) -> Result<Self, DaemonStartError> {
        let mut ipc_config = iceoryx2::config::Config::global_config().clone();
        if let Some(prefix) = &config.iceoryx_prefix {
            ipc_config.global.prefix = FileName::new(prefix.as_bytes()).map_err(|e| {
                DaemonStartError::Config(format!("iceoryx2 prefix {prefix:?}: {e:?}"))
            })?;
        }
        let node = NodeBuilder::new()
            .config(&ipc_config)
            .create::<S>()
            .map_err(|e| DaemonStartError::Ipc(format!("node: {e:?}")))?;
        let control = proxima_ipc::control_service_builder(&node, &config.root)
            .map_err(|e| {
                DaemonStartError::Config(format!("service root {:?}: {e:?}", config.root))
            })?
            .open_or_create()
            .map_err(|e| DaemonStartError::Ipc(format!("control service: {e:?}")))?
            .server_builder()
            .create()
            .map_err(|e| DaemonStartError::Ipc(format!("control server: {e:?}")))?;
        Ok(Self {
            node,
            control,
            root: config.root.clone(),
            state: ControlState::new(config),
            frames: Vec::new(),
        })
    }

    /// Serves until SIGINT/SIGTERM, waking every `cycle`.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a request or reply.
    pub fn run(&mut self, cycle: Duration) -> Result<(), DaemonRunError> {
        while self.node.wait(cycle).is_ok() {
            self.serve_control()?;
            self.serve_frames()?;
        }
        Ok(())
    }

    /// Answers every waiting control request; returns how many.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a request or reply.
    pub fn serve_control(&mut self) -> Result<usize, DaemonRunError> {
        let mut served = 0;
        while let Some(active) = self
            .control
            .receive()
            .map_err(|e| DaemonRunError::Ipc(format!("control receive: {e:?}")))?
        {
            let request = *active.user_header();
            let mut reply = self.state.handle(&request, active.payload());
            if reply.status == ErrorCode::Ok as u32 {
                reply = self.follow_scene_changes(&request, reply);
            } else {
                eprintln!(
                    "proximad: refused control request {}: {}",
                    request.command,
                    reply.reason()
                );
            }
            // A client that went away no longer wants the reply: not an error of the daemon.
            let _ = active.send_copy(reply);
            served += 1;
        }
        Ok(served)
    }

    /// Answers every scene's waiting pose frames; returns how many.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a frame.
    pub fn serve_frames(&mut self) -> Result<usize, DaemonRunError> {
        let mut served = 0;
        for (id, frames) in self.frames.iter_mut().enumerate() {
            let (Some(frames), Some(scene)) = (frames.as_mut(), self.state.scene_mut(id as u32))
            else {
                continue;
            };
            served += frames
                .serve(id as u32, scene)
                .map_err(DaemonRunError::Ipc)?;
        }
        Ok(served)
    }

    /// Opens a created scene's frame ports, closes a dropped one's. A scene whose ports
    /// cannot be opened is dropped again and the reply becomes an error.
    fn follow_scene_changes(
        &mut self,
        request: &ControlRequest,
        reply: ControlReply,
    ) -> ControlReply {
        let id = reply.id as usize;
        if request.command == Command::CreateScene as u32 {
            match SceneFrames::open(&self.node, &self.root, reply.id) {
                Ok(frames) => {
                    if self.frames.len() <= id {
                        self.frames.resize_with(id + 1, || None);
                    }
                    self.frames[id] = Some(frames);
                }
                Err(why) => {
                    // The scene was just created, so dropping it cannot fail.
                    let _ = self.state.drop_scene(reply.id);
                    return ControlReply::error(
                        ErrorCode::Internal,
                        &format!("scene services: {why}"),
                    );
                }
            }
        } else if request.command == Command::DropScene as u32
            && let Some(slot) = self.frames.get_mut(id)
        {
            *slot = None;
        }
        reply
    }

    /// The scenes' state (for tests and tools in the same process).
    #[must_use]
    pub fn state(&self) -> &ControlState {
        &self.state
    }
}
