//! The daemon as a whole: its iceoryx2 node, its threads and the links between them,
//! started by [`Daemon::new`] and served by [`Daemon::run`] until a termination signal.
//!
//! [`run`](Daemon::run) serves the frames on the calling thread ([`FrameThread`]), the
//! control service on a thread of its own ([`ControlThread`], `proximad-control`), and
//! starts the builder thread ([`builder`], `proximad-builder`); the worker pool was started
//! by `new`. When any of the first two ends (a signal, a [`StopHandle`], an error, a
//! panic) the other follows within a sweep interval, and `run` returns the first error.
//!
//! The daemon's ports live on one node of the thread-safe iceoryx2 service type, so the
//! control thread can open a scene's ports and hand them to the frame thread; on the wire
//! it is the same shared memory as `ipc::Service`, which clients use.

use super::Ipc;
use super::builder::{self, BuildJob, BuildQueue};
use super::claim::{self, EventSettings};
use super::config::DaemonConfig;
use super::control::ControlState;
use super::control_thread::{ControlThread, FrameLinks};
use super::error::{DaemonRunError, DaemonStartError};
use super::frame_thread::{ControlLinks, FrameThread};
use super::gate::Gate;
use super::log::{Level, Logger};
use super::node_counter;
use super::secrets;
use super::stop::{StopHandle, StopOnDrop};
use crate::geometry::MeshLimits;
use crate::pipeline::WorkerPool;
use crossbeam::channel::{self, Receiver};
use iceoryx2::prelude::*;
use std::sync::Arc;

/// Commands the control thread may have sent before the frame thread reads them (it reads
/// them between frames); a full queue makes the control thread wait for one frame.
const FRAME_COMMANDS: usize = 64;

/// A `proximad` ready to serve: its threads' state, the build queue and the settings the
/// threads start with (see the module docs).
pub struct Daemon {
    /// This run's instance id: random, in every reply and result header.
    instance: u64,
    control: ControlThread,
    frames: FrameThread,
    /// The builder thread's end of the build queue, until `run` starts it.
    build_jobs: Option<Receiver<BuildJob>>,
    build_gate: Option<Gate>,
    mesh_limits: MeshLimits,
    log_level: Level,
    root: String,
    config_line: String,
    stop: StopHandle,
}

impl Daemon {
    /// Creates the node (with `config.iceoryx_prefix` when set), the control service, the
    /// event listeners, the build queue and the worker pool; logs to stderr at
    /// `config.log_level`.
    ///
    /// # Errors
    /// [`DaemonStartError`] when the configuration is invalid or iceoryx2 fails.
    pub fn new(config: DaemonConfig) -> Result<Self, DaemonStartError> {
        let instance = secrets::random_u64().map_err(|e| {
            DaemonStartError::Ipc(format!("no randomness for the instance id: {e}"))
        })?;
        let ipc_config = iceoryx_config(&config)?;
        // Before the node (a counter another user set up stops it with an unclear error)
        // and after (the node may have made the counter).
        secure_node_counter(&ipc_config, &config)?;
        let node = NodeBuilder::new()
            .config(&ipc_config)
            .create::<Ipc>()
            .map_err(|e| DaemonStartError::Ipc(format!("node: {e:?}")))?;
        secure_node_counter(&ipc_config, &config)?;
        let wake = frame_wake(&node, &config.root)?;
        let (commands, incoming) = channel::bounded(FRAME_COMMANDS);
        let (retire, retired) = channel::bounded(FRAME_COMMANDS);
        let (builds, build_jobs) = BuildQueue::bounded(config.max_queued_builds);
        let workers = Arc::new(WorkerPool::new(config.workers));
        let frames = FrameThread::new(
            &config,
            ControlLinks {
                commands: incoming,
                wake: wake.listener,
                retire,
            },
            wake.lane,
        );
        let links = FrameLinks {
            commands,
            wake: wake.control,
            retired,
        };
        let state = ControlState::new(config.clone(), builds, instance);
        let control = ControlThread::new(node, &config, state, links, workers)?;
        let config_line = format!(
            "spin {:?}, sweep every {:?}, dead-client grace {:?}",
            config.spin, config.sweep_interval, config.dead_client_grace
        );
        Ok(Self {
            instance,
            control,
            frames,
            build_jobs: Some(build_jobs),
            build_gate: None,
            mesh_limits: config.mesh_limits,
            log_level: config.log_level,
            root: config.root,
            config_line,
            stop: StopHandle::default(),
        })
    }

    /// Serves until SIGINT/SIGTERM or [`StopHandle::stop`]: frames on this thread, control
    /// requests on the control thread, shape builds on the builder thread.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a request or frame, or to wait, or a
    /// thread cannot start or panics.
    pub fn run(&mut self) -> Result<(), DaemonRunError> {
        // The first check installs iceoryx2's SIGINT/SIGTERM handler.
        if self.control.termination_requested() {
            return Ok(());
        }
        let mut log = Logger::new(self.log_level);
        log.info(format_args!(
            "root {:?}, instance {:#018x}, {}",
            self.root, self.instance, self.config_line
        ));
        if let Some(jobs) = self.build_jobs.take() {
            builder::spawn(
                jobs,
                self.mesh_limits,
                self.build_gate.clone(),
                self.log_level,
            )
            .map_err(|e| DaemonRunError::Ipc(format!("starting the builder: {e}")))?;
        }
        let (control, frames, stop) = (&mut self.control, &mut self.frames, &self.stop);
        let result = std::thread::scope(|s| {
            let control_thread = std::thread::Builder::new()
                .name("proximad-control".to_owned())
                .spawn_scoped(s, || {
                    let _stop = StopOnDrop(stop);
                    control.run(stop)
                })
                .map_err(|e| DaemonRunError::Ipc(format!("starting the control thread: {e}")));
            let served = match &control_thread {
                Ok(_) => {
                    let _stop = StopOnDrop(stop);
                    frames.run(stop)
                }
                Err(_) => Ok(()),
            };
            let controlled = control_thread.and_then(|thread| {
                thread.join().unwrap_or_else(|_| {
                    Err(DaemonRunError::Ipc(
                        "the control thread panicked".to_owned(),
                    ))
                })
            });
            served.and(controlled)
        });
        log.info(format_args!("stopping"));
        result
    }

    /// This run's instance id (random per start, never 0): every control reply and result
    /// header carries it, so clients can tell this daemon from another
    /// (`ClientBuilder::expect_instance`).
    #[must_use]
    pub fn instance(&self) -> u64 {
        self.instance
    }

    /// A handle that stops [`run`](Self::run) from another thread, as SIGTERM does, within
    /// about one [`DaemonConfig::sweep_interval`].
    #[must_use]
    pub fn stop_handle(&self) -> StopHandle {
        self.stop.clone()
    }

    /// Holds every shape build at `gate` while it is closed (a test hook: a registration
    /// in progress for as long as a test likes). Takes effect when [`run`](Self::run)
    /// starts the builder thread.
    pub fn set_build_gate(&mut self, gate: Gate) {
        self.build_gate = Some(gate);
    }

    /// Holds every control request at `gate` while it is closed, before it is handled (a
    /// test hook: control work in progress for as long as a test likes).
    pub fn set_control_gate(&mut self, gate: Gate) {
        self.control.set_gate(gate);
    }
}

/// The iceoryx2 configuration of the daemon's node: the global one, under
/// `config.iceoryx_prefix` when set.
fn iceoryx_config(config: &DaemonConfig) -> Result<iceoryx2::config::Config, DaemonStartError> {
    let mut ipc_config = iceoryx2::config::Config::global_config().clone();
    if let Some(prefix) = &config.iceoryx_prefix {
        ipc_config.global.prefix = FileName::new(prefix.as_bytes())
            .map_err(|e| DaemonStartError::Config(format!("iceoryx2 prefix {prefix:?}: {e:?}")))?;
    }
    Ok(ipc_config)
}

/// Makes the node counter of `ipc_config`'s prefix private, logging it, or refuses a
/// counter another user owns ([`node_counter`]).
fn secure_node_counter(
    ipc_config: &iceoryx2::config::Config,
    config: &DaemonConfig,
) -> Result<(), DaemonStartError> {
    let prefix = ipc_config.global.prefix.to_string();
    for counter in node_counter::secure(&prefix)?.restricted {
        Logger::new(config.log_level).info(format_args!(
            "made iceoryx2's node counter {} private (mode 0600): other users could stop \
             new clients from connecting",
            counter.display()
        ));
    }
    Ok(())
}

/// Notifiers of `<root>/frame-wake`: the control thread's and the lane's, twice over, so that
/// a second daemon started on the same root by mistake gets as far as the control service
/// and says why it refuses to start (`claim`).
const FRAME_WAKE_NOTIFIERS: usize = 2 * 2;

/// The ports of the frame thread's wake-up event.
struct FrameWake {
    /// The control thread's notifier.
    control: iceoryx2::port::notifier::Notifier<Ipc>,
    /// The lane's notifier.
    lane: iceoryx2::port::notifier::Notifier<Ipc>,
    /// The frame thread's listener.
    listener: iceoryx2::port::listener::Listener<Ipc>,
}

/// The ports of the frame thread's wake-up event (`<root>/frame-wake`, the daemon's own: no
/// client opens it).
fn frame_wake(node: &Node<Ipc>, root: &str) -> Result<FrameWake, DaemonStartError> {
    let text = format!("{root}/frame-wake");
    let name = ServiceName::new(&text)
        .map_err(|e| DaemonStartError::Config(format!("service root {root:?}: {e:?}")))?;
    let ports = proxima_ipc::DAEMON_EVENT_PORTS;
    let builder = node
        .service_builder(&name)
        .event()
        .max_notifiers(FRAME_WAKE_NOTIFIERS)
        .max_listeners(ports);
    let expected = EventSettings {
        notifiers: FRAME_WAKE_NOTIFIERS,
        listeners: ports,
        nodes: None,
    };
    let service = claim::event_service(builder, &text, expected)?;
    let notifier = service
        .notifier_builder()
        .create()
        .map_err(DaemonStartError::ipc("frame wake-up notifier"))?;
    let lane_notifier = service
        .notifier_builder()
        .create()
        .map_err(DaemonStartError::ipc("the lane's frame wake-up notifier"))?;
    let listener = service
        .listener_builder()
        .create()
        .map_err(DaemonStartError::ipc("frame wake-up listener"))?;
    Ok(FrameWake {
        control: notifier,
        lane: lane_notifier,
        listener,
    })
}
