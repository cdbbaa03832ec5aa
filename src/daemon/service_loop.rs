//! The service loop: the daemon's iceoryx2 node, its control server, and the cycle that
//! serves them until a termination signal.
//!
//! Each cycle answers the control requests, then every scene's waiting pose frames
//! ([`SceneFrames`]). A scene's ports are opened when the scene is created and closed when
//! it is dropped.
//!
//! # Waiting (hybrid)
//! After the last piece of work the loop keeps polling for [`DaemonConfig::spin`], then
//! blocks in a WaitSet on the control event listener (clients notify it after each request)
//! and every scene's poses-ready listener, until a notification, the next sweep, or a
//! termination signal. Zero events is not a timeout: the loop always polls again. The
//! WaitSet lives as long as the daemon; its attachments (guards borrowing the listeners)
//! exist only for the duration of one blocking wait, so the listeners stay owned by their
//! scenes and a scene dropped between two waits simply is not attached at the next one.
//!
//! # Sweeps
//! Every [`DaemonConfig::sweep_interval`] termination signals are checked (a loop that
//! never runs out of work never blocks). About as often, at the next idle moment (the
//! cleanup takes hundreds of µs, too long to slip in between a frame's arrival and its
//! answer; at most [`MAX_SWEEP_DELAY`] late), the nodes of crashed processes are cleaned
//! up, and scenes whose creating control client is gone are orphaned and, after
//! [`DaemonConfig::dead_client_grace`], dropped ([`Liveness`]).

use super::build_gate::BuildGate;
use super::builder::{self, BuildJob, BuildQueue};
use super::config::DaemonConfig;
use super::control::ControlState;
use super::error::{DaemonRunError, DaemonStartError};
use super::frame_loop::SceneFrames;
use super::liveness::{Liveness, OwnerId};
use super::log::{Cause, Level, Logger, Subject};
use super::schedule::most_urgent;
use super::shared_scene::lock;
use crate::geometry::MeshLimits;
use crate::pipeline::WorkerPool;
use crossbeam::channel::Receiver;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::request_response::PortFactory as RequestResponseFactory;
use iceoryx2::waitset::WaitSetRunResult;
use proxima_ipc::wire::{Command, ControlReply, ControlRequest, ErrorCode};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How late a due sweep may be postponed while frames keep the loop busy.
const MAX_SWEEP_DELAY: Duration = Duration::from_secs(1);

/// Whether the loop goes on after a blocking wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Wake {
    Serve,
    Stop,
}

/// A running `proximad`: node, control server and the scenes' state.
pub struct Daemon<S: Service> {
    // Fields drop in order: ports before their services, all before the node.
    control: Server<S, [u8], ControlRequest, ControlReply, ()>,
    control_events: Listener<S>,
    /// Scene id → its frame path (`None` for dropped scenes).
    scenes: Vec<Option<SceneFrames<S>>>,
    waitset: WaitSet<S>,
    control_service: RequestResponseFactory<S, [u8], ControlRequest, ControlReply, ()>,
    node: Node<S>,
    state: ControlState,
    liveness: Liveness,
    log: Logger,
    /// Answers the mesh–mesh pairs of every scene's frames alongside the service loop.
    workers: Arc<WorkerPool>,
    /// The builder thread's end of the build queue, until `run` starts it.
    build_jobs: Option<Receiver<BuildJob>>,
    build_gate: Option<BuildGate>,
    mesh_limits: MeshLimits,
    log_level: Level,
    root: String,
    spin: Duration,
    sweep_interval: Duration,
    /// Scratch list of the connected control clients, refilled at each sweep.
    connected: Vec<OwnerId>,
    stop: StopHandle,
}

/// Stops a running daemon from another thread of the same process (SIGINT and SIGTERM stop
/// the process's daemon the same way); clones stop the same daemon.
#[derive(Debug, Clone, Default)]
pub struct StopHandle(Arc<AtomicBool>);

impl StopHandle {
    /// Asks the daemon to stop; it does within about one sweep interval.
    pub fn stop(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`stop`](Self::stop) was called.
    #[must_use]
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

impl<S: Service> Daemon<S>
where
    // Listeners of services whose events travel over file descriptors (`ipc` and `local`)
    // can join a WaitSet.
    Listener<S>: SynchronousMultiplexing,
{
    /// Creates the node (with `config.iceoryx_prefix` when set), the control service and the
    /// control event listener; logs to stderr at `config.log_level`.
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
        let bad_root =
            |e| DaemonStartError::Config(format!("service root {:?}: {e:?}", config.root));
        let control_service = proxima_ipc::control_service_builder(&node, &config.root)
            .map_err(bad_root)?
            .open_or_create()
            .map_err(|e| DaemonStartError::Ipc(format!("control service: {e:?}")))?;
        let control = control_service
            .server_builder()
            .create()
            .map_err(|e| DaemonStartError::Ipc(format!("control server: {e:?}")))?;
        let control_events = proxima_ipc::control_events_service_builder(&node, &config.root)
            .map_err(bad_root)?
            .open_or_create()
            .map_err(|e| DaemonStartError::Ipc(format!("control event service: {e:?}")))?
            .listener_builder()
            .create()
            .map_err(|e| DaemonStartError::Ipc(format!("control event listener: {e:?}")))?;
        let (builds, build_jobs) = BuildQueue::bounded(config.max_queued_builds);
        let waitset = WaitSetBuilder::new()
            .create::<S>()
            .map_err(|e| DaemonStartError::Ipc(format!("wait set: {e:?}")))?;
        Ok(Self {
            control,
            control_events,
            scenes: Vec::new(),
            waitset,
            control_service,
            node,
            liveness: Liveness::new(config.dead_client_grace),
            log: Logger::new(config.log_level),
            workers: Arc::new(WorkerPool::new(config.workers)),
            build_jobs: Some(build_jobs),
            build_gate: None,
            mesh_limits: config.mesh_limits,
            log_level: config.log_level,
            root: config.root.clone(),
            spin: config.spin,
            sweep_interval: config.sweep_interval,
            connected: Vec::new(),
            stop: StopHandle::default(),
            state: ControlState::new(config, builds),
        })
    }

    /// Serves until SIGINT/SIGTERM: polls while there is work and for the configured spin
    /// after it, then blocks until a client notifies or the next sweep is due.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a request or frame, or to wait.
    pub fn run(&mut self) -> Result<(), DaemonRunError> {
        // The first check installs iceoryx2's SIGINT/SIGTERM handler.
        if self.termination_requested() {
            return Ok(());
        }
        if let Some(jobs) = self.build_jobs.take() {
            let gate = self.build_gate.clone();
            builder::spawn(jobs, self.mesh_limits, gate, self.log_level)
                .map_err(|e| DaemonRunError::Ipc(format!("starting the builder thread: {e}")))?;
        }
        self.log.info(format_args!(
            "root {:?}, spin {:?}, sweep every {:?}, dead-client grace {:?}",
            self.root,
            self.spin,
            self.sweep_interval,
            self.liveness.grace()
        ));
        let start = Instant::now();
        let (mut next_sweep, mut next_signal_check) =
            (start + self.sweep_interval, start + self.sweep_interval);
        let mut last_work = start;
        loop {
            let served = self.serve_control()? + self.serve_frames()?;
            let now = Instant::now();
            if served > 0 {
                last_work = now;
            }
            let idle = now.duration_since(last_work) >= self.spin;
            // A loop that never runs out of work never blocks, so it checks for signals
            // itself (about 2 µs).
            if now >= next_signal_check {
                if self.termination_requested() {
                    break;
                }
                next_signal_check = now + self.sweep_interval;
            }
            // The dead-node cleanup costs hundreds of µs: it waits for an idle moment
            // between frames, unless it is overdue by more than `MAX_SWEEP_DELAY`.
            if now >= next_sweep && (idle || now >= next_sweep + MAX_SWEEP_DELAY) {
                self.sweep(now);
                next_sweep = Instant::now() + self.sweep_interval;
                continue;
            }
            if !idle {
                std::hint::spin_loop();
                continue;
            }
            let wake_at = next_sweep.min(next_signal_check);
            if self.block(wake_at.saturating_duration_since(now))? == Wake::Stop {
                break;
            }
            last_work = Instant::now();
        }
        self.log.info(format_args!("stopping"));
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
            let origin = active.origin().value();
            let mut reply = self.state.handle(&request, active.payload());
            if reply.status == ErrorCode::Ok as u32 {
                reply = self.follow_scene_changes(&request, reply, origin);
            }
            if reply.status != ErrorCode::Ok as u32 {
                let cause = Cause {
                    what: "refused control request",
                    code: reply.status,
                };
                self.log
                    .once(Level::Warn, Subject::Client(origin), cause, || {
                        let name = Command::from_u32(request.command).map_or_else(
                            || format!("command {}", request.command),
                            |c| format!("{c:?}"),
                        );
                        format!("refused {name}: {}", reply.reason())
                    });
            }
            // A client that went away no longer wants the reply: not an error of the daemon.
            let _ = active.send_copy(reply);
            served += 1;
        }
        Ok(served)
    }

    /// Answers every scene's waiting pose frames, the most urgent first
    /// ([`schedule`](super::schedule)); returns how many.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a frame.
    pub fn serve_frames(&mut self) -> Result<usize, DaemonRunError> {
        let mut served = 0;
        loop {
            for frames in self.scenes.iter_mut().flatten() {
                frames.take_next().map_err(DaemonRunError::Ipc)?;
            }
            let waiting = self.scenes.iter().enumerate();
            let next =
                most_urgent(waiting.filter_map(|(id, f)| Some((id, f.as_ref()?.waiting()?))));
            let Some(id) = next else {
                return Ok(served);
            };
            let Some(frames) = self.scenes[id].as_mut() else {
                continue;
            };
            let Some(shared) = self.state.scene(id as u32) else {
                frames.discard_waiting();
                continue;
            };
            let mut cell = lock(shared);
            if cell.dropped {
                frames.discard_waiting();
                continue;
            }
            frames
                .answer_waiting(id as u32, &mut cell.scene, &mut self.log)
                .map_err(DaemonRunError::Ipc)?;
            served += 1;
        }
    }

    /// Whether SIGINT or SIGTERM arrived (checked without sleeping), or the daemon was
    /// stopped through a [`StopHandle`].
    fn termination_requested(&self) -> bool {
        self.node.wait(Duration::ZERO).is_err() || self.stop.is_stopped()
    }

    /// A handle that stops [`run`](Self::run) from another thread, as SIGTERM does, within
    /// about one [`DaemonConfig::sweep_interval`].
    #[must_use]
    pub fn stop_handle(&self) -> StopHandle {
        self.stop.clone()
    }

    /// Blocks until a client notifies the control or a poses-ready event, `timeout` passes
    /// or a termination signal arrives; consumes the notifications that woke it.
    fn block(&self, timeout: Duration) -> Result<Wake, DaemonRunError> {
        if timeout.is_zero() {
            return Ok(Wake::Serve);
        }
        let attach_error = |e| DaemonRunError::Ipc(format!("wait set attach: {e:?}"));
        let listeners = || {
            std::iter::once(&self.control_events)
                .chain(self.scenes.iter().flatten().map(SceneFrames::poses_ready))
        };
        // One small allocation per blocking wait, never on the polled path.
        let guards = listeners()
            .map(|listener| self.waitset.attach_notification(listener))
            .collect::<Result<Vec<_>, _>>()
            .map_err(attach_error)?;
        let mut drain_error = None;
        let result = self
            .waitset
            .wait_and_process_once_with_timeout(
                |id| {
                    for (listener, guard) in listeners().zip(&guards) {
                        if id.has_event_from(guard)
                            && let Err(e) = listener.try_wait(|_| {})
                        {
                            drain_error = Some(e);
                        }
                    }
                    CallbackProgression::Continue
                },
                timeout,
            )
            .map_err(|e| DaemonRunError::Ipc(format!("wait set wait: {e:?}")))?;
        if let Some(e) = drain_error {
            return Err(DaemonRunError::Ipc(format!("event listener: {e:?}")));
        }
        Ok(match result {
            WaitSetRunResult::TerminationRequest => Wake::Stop,
            // Any signal interrupts the wait; only SIGINT and SIGTERM stop the daemon.
            WaitSetRunResult::Interrupt if self.termination_requested() => Wake::Stop,
            _ => Wake::Serve,
        })
    }

    /// Cleans up crashed processes' nodes, then orphans the scenes whose creating client is
    /// gone and drops those orphaned for the grace period.
    fn sweep(&mut self, now: Instant) {
        let cleanup = self.node.try_cleanup_dead_nodes();
        if cleanup.cleanups > 0 || cleanup.failed_cleanups > 0 {
            self.log.debug(format_args!(
                "cleaned up {} dead nodes ({} failed)",
                cleanup.cleanups, cleanup.failed_cleanups
            ));
        }
        self.connected.clear();
        let connected = &mut self.connected;
        self.control_service
            .dynamic_config()
            .list_clients(|client| {
                connected.push(client.client_id.value());
                CallbackProgression::Continue
            });
        let connected = &self.connected;
        let outcome = self.liveness.sweep(now, |owner| connected.contains(&owner));
        self.log.release_if(|subject| match subject {
            Subject::Client(id) => !connected.contains(&id),
            Subject::Scene(_) => false,
        });
        for &id in &outcome.orphaned {
            self.log.warn(format_args!(
                "scene {id}: the client that created it is gone; the scene is dropped after a \
                 grace period of {:?}",
                self.liveness.grace()
            ));
        }
        for &id in &outcome.expired {
            self.release_scene(id);
            self.log.info(format_args!(
                "scene {id} released: its client has been gone for {:?}",
                self.liveness.grace()
            ));
        }
    }

    /// Drops scene `id`'s state and closes its ports (if it still lives).
    fn release_scene(&mut self, id: u32) {
        // A scene already dropped by request has nothing left to release.
        let _ = self.state.drop_scene(id);
        if let Some(slot) = self.scenes.get_mut(id as usize) {
            *slot = None;
        }
        self.liveness.forget(id);
        self.log.release(Subject::Scene(id));
    }

    /// Opens a created scene's ports and records its owner; closes a dropped one's. A scene
    /// whose ports cannot be opened is dropped again and the reply becomes an error.
    fn follow_scene_changes(
        &mut self,
        request: &ControlRequest,
        reply: ControlReply,
        origin: OwnerId,
    ) -> ControlReply {
        if request.command == Command::CreateScene as u32 {
            match self.open_scene(reply.id) {
                Ok(ports) => {
                    let id = reply.id as usize;
                    if self.scenes.len() <= id {
                        self.scenes.resize_with(id + 1, || None);
                    }
                    self.scenes[id] = Some(ports);
                    self.liveness.adopt(reply.id, origin);
                    self.log.info(format_args!(
                        "scene {} created by client {origin:x}",
                        reply.id
                    ));
                }
                Err(why) => {
                    // The scene was just created, so dropping it cannot fail.
                    let _ = self.state.drop_scene(reply.id);
                    self.log.error(format_args!(
                        "scene {}: opening its services failed: {why}",
                        reply.id
                    ));
                    return ControlReply::error(
                        ErrorCode::Internal,
                        &format!("scene services: {why}"),
                    );
                }
            }
        } else if request.command == Command::DropScene as u32 {
            self.release_scene(request.scene);
            self.log.info(format_args!(
                "scene {} dropped by its client",
                request.scene
            ));
        }
        reply
    }

    /// Opens scene `id`'s frame ports and poses-ready listener.
    fn open_scene(&self, id: u32) -> Result<SceneFrames<S>, String> {
        SceneFrames::open(&self.node, &self.root, id, &self.workers)
    }

    /// Holds every shape build at `gate` until it is opened (a test hook: a registration
    /// in progress for as long as a test likes). Takes effect when [`run`](Self::run)
    /// starts the builder thread.
    pub fn set_build_gate(&mut self, gate: BuildGate) {
        self.build_gate = Some(gate);
    }
}
