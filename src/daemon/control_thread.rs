//! The control thread: the control server (requests in, replies out), the scenes' frame
//! ports opened and closed, the periodic sweep, termination signals.
//!
//! Each request is answered by [`ControlState`] against the shared scenes (an O(1) edit under
//! a scene's lock, or a registration queued for the builder). A request whose scene's lock a
//! frame holds is kept and asked again every round (at least every 100 µs) behind the
//! frame, its scene's later requests behind it: the thread never waits for a frame, so one
//! client's long frame delays no other client's requests. A created scene's ports are
//! opened here, not on the frame thread, and handed over with [`FrameCommand::Open`]; a
//! dropped scene is marked dropped at once and its ports come back
//! ([`FrameCommand::Close`]) to be closed here too, a sweep later, once readers had time to
//! take its release frame. Each hand-over notifies the frame thread's
//! wake-up listener, so a frame thread blocked without the new scene's listener wakes for it.
//!
//! # Waiting (hybrid)
//! After the last request the thread keeps polling for [`DaemonConfig::spin`] (a client's
//! next request usually follows its reply within µs), then blocks in its WaitSet on the
//! control event listener (clients notify it after each request) until a notification, the
//! next sweep or a termination signal.
//!
//! # Sweeps
//! Every [`DaemonConfig::sweep_interval`]: termination signals are checked (a thread that
//! never runs out of requests never blocks), the nodes of crashed processes are cleaned up
//! (hundreds of µs, off the frame path), and scenes whose creating control client is gone
//! are orphaned and, after [`DaemonConfig::dead_client_grace`], dropped ([`Liveness`]).

use super::Ipc;
use super::claim::{self, ControlFactory, EventSettings};
use super::config::DaemonConfig;
use super::control::{ControlState, Origin};
use super::error::{DaemonRunError, DaemonStartError};
use super::frame_loop::{SceneFrames, SceneKeys};
use super::gate::Gate;
use super::liveness::{Liveness, OwnerId};
use super::log::{Cause, Level, Logger, Subject};
use super::quota::ProcessId;
use super::shared_scene::SharedScene;
use super::stop::StopHandle;
use super::wait::{Wake, wait_for_events};
use crate::pipeline::WorkerPool;
use crossbeam::channel::{Receiver, Sender};
use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use proxima_ipc::wire::{Command, ControlReply, ControlRequest, ErrorCode};
use std::collections::{HashMap, VecDeque};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What the control thread tells the frame thread.
pub enum FrameCommand {
    /// Serve scene `id` from now on, with these ports.
    Open {
        /// The scene's id.
        id: u32,
        /// The scene.
        scene: SharedScene,
        /// Its frame ports, opened by the control thread.
        frames: Box<SceneFrames<Ipc>>,
    },
    /// Stop serving scene `id` and hand it back ([`Retired`]).
    Close(u32),
}

/// A closed scene as the frame thread hands it back: its ports and its share of the scene,
/// so that closing the ports (unmapping shared memory) and freeing the scene (its bodies and
/// shapes, when no one else holds it) happen on the control thread, not between frames.
pub struct Retired {
    /// The scene's id.
    pub id: u32,
    /// The scene.
    pub scene: SharedScene,
    /// Its frame ports.
    pub frames: Box<SceneFrames<Ipc>>,
    /// The fault on its ports that made the frame thread give it up, if that was why.
    pub fault: Option<String>,
}

/// The control thread's ends of its links to the frame thread.
pub struct FrameLinks {
    /// Scenes to serve and to stop serving.
    pub commands: Sender<FrameCommand>,
    /// Wakes the frame thread after a command.
    pub wake: Notifier<Ipc>,
    /// Closed scenes, to let go of here.
    pub retired: Receiver<Retired>,
}

/// The control thread's state: node, control server, scenes (see the module docs).
pub struct ControlThread {
    // Fields drop in order: ports before their services, all before the node.
    server: Server<Ipc, [u8], ControlRequest, ControlReply, ()>,
    requests_sent: Listener<Ipc>,
    frames: FrameLinks,
    control_service: ControlFactory,
    node: Node<Ipc>,
    state: ControlState,
    liveness: Liveness,
    log: Logger,
    /// Answers mesh–mesh pairs for the frame thread; each scene's workspace shares it.
    workers: Arc<WorkerPool>,
    gate: Option<Gate>,
    root: String,
    spin: Duration,
    sweep_interval: Duration,
    /// The connected control client ports and their processes, refilled at each sweep and
    /// when a request comes from a port not in it yet.
    connected: HashMap<OwnerId, ProcessId>,
    /// Requests not answered yet, oldest first: those whose scene's lock was held stay, and
    /// are asked again each round.
    queue: VecDeque<ActiveControlRequest>,
    /// Ports of let-go scenes, each with when it was let go, closed at the first sweep at
    /// least [`LINGER`] later (so readers still get the release frame).
    closing: Vec<(Instant, Box<SceneFrames<Ipc>>)>,
    /// Scratch list of the scenes found busy in one round of answering the queue.
    still_busy: Vec<u32>,
}

/// A control request received and not answered yet.
type ActiveControlRequest = ActiveRequest<Ipc, [u8], ControlRequest, ControlReply, ()>;

/// How long a let-go scene's ports stay open for readers to take its last frames.
const LINGER: Duration = Duration::from_millis(100);

/// How often queued requests whose scene was busy are asked again while the thread would
/// otherwise block.
const ASK_AGAIN_EVERY: Duration = Duration::from_micros(100);

/// The scene a request names, for the commands that take its lock.
fn scene_named(request: &ControlRequest) -> Option<u32> {
    let scene_free = [Command::Hello as u32, Command::CreateScene as u32];
    (!scene_free.contains(&request.command)).then_some(request.scene)
}

impl ControlThread {
    /// Claims the control service ([`claim`]), creates its server and the control event
    /// listener on `node`; replies and scenes' result headers carry `state`'s instance id.
    ///
    /// # Errors
    /// [`DaemonStartError`] when the root is invalid, another process holds the control
    /// service, or iceoryx2 fails.
    pub fn new(
        node: Node<Ipc>,
        config: &DaemonConfig,
        state: ControlState,
        frames: FrameLinks,
        workers: Arc<WorkerPool>,
    ) -> Result<Self, DaemonStartError> {
        let bad_root =
            |e| DaemonStartError::Config(format!("service root {:?}: {e:?}", config.root));
        let root = &config.root;
        let control_service = claim::control_service(
            proxima_ipc::control_service_builder(&node, root).map_err(bad_root)?,
            &proxima_ipc::control_service_name(root),
        )?;
        let server = control_service
            .server_builder()
            .create()
            .map_err(DaemonStartError::ipc("control server"))?;
        let events = EventSettings {
            notifiers: proxima_ipc::CONTROL_MAX_CLIENTS,
            listeners: proxima_ipc::DAEMON_EVENT_PORTS,
            nodes: Some(proxima_ipc::CONTROL_MAX_NODES),
        };
        let requests_sent = claim::event_service(
            proxima_ipc::control_events_service_builder(&node, root).map_err(bad_root)?,
            &format!("{root}/control-events"),
            events,
        )?
        .listener_builder()
        .create()
        .map_err(DaemonStartError::ipc("control event listener"))?;
        Ok(Self {
            server,
            requests_sent,
            frames,
            control_service,
            node,
            state,
            liveness: Liveness::new(config.dead_client_grace),
            log: Logger::new(config.log_level),
            workers,
            gate: None,
            root: config.root.clone(),
            spin: config.spin,
            sweep_interval: config.sweep_interval,
            connected: HashMap::new(),
            queue: VecDeque::new(),
            closing: Vec::new(),
            still_busy: Vec::new(),
        })
    }

    /// Holds every control request at `gate` before it is handled (a test hook).
    pub fn set_gate(&mut self, gate: Gate) {
        self.gate = Some(gate);
    }

    /// Whether SIGINT or SIGTERM arrived (checked without sleeping). The first check
    /// installs iceoryx2's signal handler.
    pub fn termination_requested(&self) -> bool {
        self.node.wait(Duration::ZERO).is_err()
    }

    /// Serves until `stop`, a termination signal or an error; then stops the daemon and
    /// wakes the frame thread so it sees it.
    ///
    /// # Errors
    /// [`DaemonRunError`] when iceoryx2 fails to move a request or to wait.
    pub fn run(&mut self, stop: &StopHandle) -> Result<(), DaemonRunError> {
        let result = WaitSetBuilder::new()
            .create::<Ipc>()
            .map_err(|e| DaemonRunError::Ipc(format!("wait set: {e:?}")))
            .and_then(|waitset| self.serve(stop, &waitset));
        stop.stop();
        // A long frame in progress (on the lane, say) stops at its next poll.
        self.state.stop_all_frames();
        let _ = self.frames.wake.notify();
        result
    }

    fn serve(&mut self, stop: &StopHandle, waitset: &WaitSet<Ipc>) -> Result<(), DaemonRunError> {
        let start = Instant::now();
        let (mut next_sweep, mut last_work) = (start + self.sweep_interval, start);
        loop {
            let served = self.serve_requests();
            // Closing ports and freeing scenes: done here, not between frames.
            while let Ok(retired) = self.frames.retired.try_recv() {
                self.let_go(retired);
            }
            let now = Instant::now();
            if served > 0 {
                last_work = now;
            }
            if now >= next_sweep {
                // About 2 µs; the loop may never block, so it checks itself.
                if self.termination_requested() {
                    return Ok(());
                }
                self.sweep(now);
                self.closing
                    .retain(|(since, _)| now.saturating_duration_since(*since) < LINGER);
                next_sweep = Instant::now() + self.sweep_interval;
            }
            if stop.is_stopped() {
                return Ok(());
            }
            if now.duration_since(last_work) < self.spin {
                std::hint::spin_loop();
                continue;
            }
            let listeners = || std::iter::once(&self.requests_sent);
            let mut timeout = next_sweep.saturating_duration_since(now);
            if !self.queue.is_empty() {
                timeout = timeout.min(ASK_AGAIN_EVERY);
            }
            if wait_for_events(waitset, listeners, timeout)? == Wake::Stop {
                return Ok(());
            }
            last_work = Instant::now();
        }
    }

    /// Takes every waiting control request into the queue, behind those whose scene was
    /// busy, and answers the queue ([`answer_queue`](Self::answer_queue)); returns how many
    /// were answered. A failure to receive (a client's segment that cannot be mapped, say)
    /// is logged and ends the taking; it never ends the daemon.
    fn serve_requests(&mut self) -> usize {
        loop {
            let active = match self.server.receive() {
                Ok(Some(active)) => active,
                Ok(None) => break,
                Err(e) => {
                    let cause = Cause {
                        what: "control receive failure",
                        code: 0,
                    };
                    self.log.once(Level::Error, Subject::Daemon, cause, || {
                        format!("receiving a control request failed: {e:?}")
                    });
                    break;
                }
            };
            if let Some(gate) = &self.gate {
                gate.pass();
            }
            self.queue.push_back(active);
        }
        self.answer_queue()
    }

    /// Answers the queued requests, oldest first; one whose scene is busy stays queued, and
    /// so do its scene's later ones, in order. Returns how many were answered.
    fn answer_queue(&mut self) -> usize {
        let mut served = 0;
        self.still_busy.clear();
        for _ in 0..self.queue.len() {
            let Some(active) = self.queue.pop_front() else {
                break;
            };
            let scene = scene_named(active.user_header());
            if scene.is_some_and(|id| self.still_busy.contains(&id)) {
                self.queue.push_back(active);
                continue;
            }
            match self.answer(active) {
                None => served += 1,
                Some(busy) => {
                    self.still_busy.extend(scene);
                    self.queue.push_back(busy);
                }
            }
        }
        served
    }

    /// Answers `active` and sends the reply, or gives it back when its scene's lock is held
    /// (a frame or a build in progress): it is asked again later, so the control thread
    /// never waits for a frame.
    fn answer(&mut self, active: ActiveControlRequest) -> Option<ActiveControlRequest> {
        let request = *active.user_header();
        let port = active.origin().value();
        let Some(origin) = self.origin_of(port) else {
            let reply = self.state.refusal(
                ErrorCode::Internal,
                "the control service does not list this client port's process",
            );
            self.log_refusal(&request, &reply, port);
            let _ = active.send_copy(reply);
            return None;
        };
        self.stop_frame_before_drop(&request, port);
        let Some(mut reply) = self
            .state
            .handle_unless_busy(origin, &request, active.payload())
        else {
            return Some(active);
        };
        if reply.status == ErrorCode::Ok as u32 {
            reply = self.follow_scene_changes(&request, reply, port);
        } else {
            self.log_refusal(&request, &reply, port);
        }
        // A client that went away no longer wants the reply: not an error of the daemon.
        let _ = active.send_copy(reply);
        None
    }

    /// Who sent a request from client `port`: the port and its process, as the control
    /// service lists them (listed again when the port is new). `None` when the port is not
    /// listed (it has gone) or iceoryx2 does not tell its process.
    fn origin_of(&mut self, port: OwnerId) -> Option<Origin> {
        if !self.connected.contains_key(&port) {
            self.list_connected();
        }
        let process = *self.connected.get(&port)?;
        Some(Origin { port, process })
    }

    /// Refills [`connected`](Self::connected) from the control service's client list.
    fn list_connected(&mut self) {
        self.connected.clear();
        let connected = &mut self.connected;
        self.control_service
            .dynamic_config()
            .list_clients(|client| {
                if let Ok(pid) = client.node_id.pid::<Ipc>() {
                    // A pid is never negative; the cast keeps it as it is.
                    connected.insert(client.client_id.value(), pid.value() as ProcessId);
                }
                CallbackProgression::Continue
            });
    }

    /// Before its owner's DropScene is handled (which takes the scene's lock), stops the
    /// scene's frame in progress at its next poll, so the drop waits for a poll step, not
    /// for the frame's end. Anyone else's DropScene changes nothing, here as in the reply.
    fn stop_frame_before_drop(&self, request: &ControlRequest, origin: OwnerId) {
        if request.command == Command::DropScene as u32
            && let Some(entry) = self.state.entry(request.scene)
            && entry.owner == origin
        {
            entry.signals.releasing();
        }
    }

    /// Logs a refused request once per client and cause.
    fn log_refusal(&mut self, request: &ControlRequest, reply: &ControlReply, origin: OwnerId) {
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
        self.list_connected();
        let connected = &self.connected;
        let outcome = self
            .liveness
            .sweep(now, |owner| connected.contains_key(&owner));
        self.log.release_if(|subject| match subject {
            Subject::Client(id) => !connected.contains_key(&id),
            Subject::Scene(_) | Subject::Daemon => false,
        });
        for &id in &outcome.orphaned {
            if let Some(entry) = self.state.entry(id) {
                entry.signals.owner_gone();
            }
            self.log.warn(format_args!(
                "scene {id}: the client that created it is gone; its frames are abandoned at \
                 their next poll, and the scene is released after a grace period of {:?}",
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

    /// Closes a retired scene's ports, then lets go of it (freed if no build still holds
    /// it); a scene given up for a fault stays quarantined, so its owner learns why.
    fn let_go(&mut self, retired: Retired) {
        let Retired {
            id,
            scene,
            frames,
            fault,
        } = retired;
        drop(scene);
        // Its last frame (the release) may still be unread: a sample in a subscriber's queue
        // is lost with its publisher, so the ports close a sweep later, not now.
        self.closing.push((Instant::now(), frames));
        if let Some(why) = fault
            && self.state.quarantine(id, why)
        {
            self.log.warn(format_args!(
                "{}: quarantined; its owner is told until it drops the scene",
                Subject::Scene(id)
            ));
        }
    }

    /// Drops scene `id`'s state (if it still lives) and takes its ports off the frame thread.
    fn release_scene(&mut self, id: u32) {
        // A frame in progress stops at its next poll, so the lock comes free soon.
        if let Some(entry) = self.state.entry(id) {
            entry.signals.releasing();
        }
        // A scene already dropped by request has nothing left to release.
        let _ = self.state.drop_scene(id);
        self.tell_frames(FrameCommand::Close(id));
        self.liveness.forget(id);
        self.log.release(Subject::Scene(id));
    }

    /// Sends `command` to the frame thread and wakes it. Once the frame thread is gone (the
    /// daemon is stopping) there is no one left to tell.
    fn tell_frames(&self, command: FrameCommand) {
        if self.frames.commands.send(command).is_ok() {
            let _ = self.frames.wake.notify();
        }
    }

    /// Opens a created scene's ports, hands them to the frame thread and records the scene's
    /// owner; closes a dropped one's. A scene whose ports cannot be opened is dropped again
    /// and the reply becomes an error.
    fn follow_scene_changes(
        &mut self,
        request: &ControlRequest,
        reply: ControlReply,
        origin: OwnerId,
    ) -> ControlReply {
        if request.command == Command::DropScene as u32 {
            self.release_scene(request.scene);
            let scene = request.scene;
            self.log
                .info(format_args!("scene {scene} dropped by its client"));
        }
        if request.command != Command::CreateScene as u32 {
            return reply;
        }
        let id = reply.id;
        let Some(entry) = self.state.entry(id) else {
            return self
                .state
                .refusal(ErrorCode::Internal, "the new scene is gone");
        };
        let keys = SceneKeys {
            token: entry.token,
            frame_key: entry.frame_key,
            instance: self.state.instance(),
            signals: entry.signals.clone(),
        };
        let opened = SceneFrames::open(&self.node, &self.root, keys, &self.workers);
        match (opened, self.state.scene(id)) {
            (Ok(frames), Some(scene)) => {
                let scene = Arc::clone(scene);
                let frames = Box::new(frames);
                self.tell_frames(FrameCommand::Open { id, scene, frames });
                self.liveness.adopt(id, origin);
                self.log
                    .info(format_args!("scene {id} created by client {origin:x}"));
                reply
            }
            (opened, _) => {
                let why = opened
                    .err()
                    .unwrap_or_else(|| "the scene is gone".to_owned());
                // The scene was just created, so dropping it cannot fail.
                let _ = self.state.drop_scene(id);
                self.log.error(format_args!(
                    "scene {id}: opening its services failed: {why}"
                ));
                self.state
                    .refusal(ErrorCode::Internal, &format!("scene services: {why}"))
            }
        }
    }
}
