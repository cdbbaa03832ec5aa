//! The service loop: the daemon's iceoryx2 node, its control server, and the cycle that
//! serves them until a termination signal.
//!
//! TODO(#4): per-scene pose subscribers, result publishers and events, the frame loop and
//! the worker pool join here.

use super::config::DaemonConfig;
use super::control::ControlState;
use super::error::{DaemonRunError, DaemonStartError};
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use proxima_ipc::wire::{ControlReply, ControlRequest};
use std::time::Duration;

/// A running `proximad`: node, control server and the scenes' state.
pub struct Daemon<S: Service> {
    node: Node<S>,
    control: Server<S, [u8], ControlRequest, ControlReply, ()>,
    state: ControlState,
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
            state: ControlState::new(config),
        })
    }

    /// Serves until SIGINT/SIGTERM, waking every `cycle`.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a request or reply.
    pub fn run(&mut self, cycle: Duration) -> Result<(), DaemonRunError> {
        while self.node.wait(cycle).is_ok() {
            self.serve_control()?;
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
            let reply = self.state.handle(active.user_header(), active.payload());
            if reply.status != 0 {
                eprintln!(
                    "proximad: refused control request {:?}: {}",
                    active.user_header().command,
                    reply.reason()
                );
            }
            // A client that went away no longer wants the reply: not an error of the daemon.
            let _ = active.send_copy(reply);
            served += 1;
        }
        Ok(served)
    }

    /// The scenes' state (for tests and tools in the same process).
    #[must_use]
    pub fn state(&self) -> &ControlState {
        &self.state
    }
}
