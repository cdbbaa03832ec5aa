//! The control service's logic: one request in, one reply out, against the daemon's scenes.
//!
//! State handling, no IPC: the control thread receives a request, calls
//! [`ControlState::handle`] with the client port it came from and sends the reply. A refused
//! request changes nothing and gets the error code and reason; it is logged once by the
//! caller.
//!
//! # Trust
//! A scene belongs to the client port that created it: every command naming it from
//! another port is refused with `NotOwner` (DESIGN §10). Scene ids are random, so a client
//! cannot name the next scene before it exists; each scene also gets a secret frame key
//! (its pose frames must carry it) and a secret token that names its services. A scene
//! whose services failed is [quarantined](ControlState::quarantine): its state is freed, and
//! its owner is told why until it drops the id.
//!
//! Every request is O(1) or a copy: scene edits take the scene's lock
//! ([`shared_scene`]) for one edit, and never wait for it: while a frame or a build holds it
//! the request is not handled ([`ControlState::handle_unless_busy`]) and the control thread
//! asks again later, so one client's long frame holds up no other client's requests; a convex or mesh registration is
//! checked ([`convert::shape_request`]), gets its shape id, and its payload is copied into a
//! [`BuildJob`] for the builder thread; the reply says the shape is being built.

use super::budget_memory;
use super::builder::{BuildJob, BuildQueue};
use super::config::DaemonConfig;
use super::convert::{self, Rejection, ShapeRequest};
use super::liveness::OwnerId;
use super::quota::{ProcessId, Quotas, Usage};
use super::secrets;
use super::shape_table::ShapeState;
use super::shared_scene::{self, SceneCell, SceneSignals, SharedScene, lock};
use crate::broad::{BroadPhaseChoice, BroadPhaseKind};
use crate::scene::{BodyDesc, BodyId, Scene};
use proxima_ipc::wire::{
    BroadPhaseCode, Command, ControlReply, ControlRequest, ErrorCode, reply_flags,
};
use proxima_ipc::{PROTOCOL_VERSION, SceneToken};
use std::collections::HashMap;
use std::sync::{Arc, MutexGuard, TryLockError};

/// The scenes a daemon serves, by id, and the queue of shapes to build.
#[derive(Debug)]
pub struct ControlState {
    config: DaemonConfig,
    /// This daemon run's instance id, in every reply.
    instance: u64,
    /// Live and quarantined scenes (a quarantined one counts against `max_scenes` until its
    /// owner drops it or is gone).
    scenes: HashMap<u32, SceneEntry>,
    builds: BuildQueue,
    /// Bytes charged to the shapes and bodies of every scene alive
    /// ([`budget_memory`](super::budget_memory)), at most `config.max_memory_bytes`.
    memory_bytes: u64,
    /// What each client process holds, against `config.client_quota`.
    quotas: Quotas,
}

/// Who sent a request: the control client port, which owns the scenes it creates, and the
/// process behind it, which their [quota](super::quota) is charged to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    /// The port (iceoryx2's `UniqueClientId` value).
    pub port: OwnerId,
    /// The process that created the port's node.
    pub process: ProcessId,
}

/// A scene as the control service knows it.
#[derive(Debug)]
pub struct SceneEntry {
    /// The client port that created it, the only one it answers.
    pub owner: OwnerId,
    /// The process of `owner`, which `usage` is charged to.
    pub process: ProcessId,
    /// The secret that names its services.
    pub token: SceneToken,
    /// The secret its pose frames carry.
    pub frame_key: u64,
    /// Its state, or why it was quarantined.
    pub state: Result<SharedScene, String>,
    /// What it holds, charged to `process` (only the scene itself once quarantined).
    pub usage: Usage,
    /// What the control thread tells its frames while one may be in progress.
    pub signals: SceneSignals,
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
    /// No scenes yet; convex and mesh shapes go to `builds`; every reply carries
    /// `instance`.
    #[must_use]
    pub fn new(config: DaemonConfig, builds: BuildQueue, instance: u64) -> Self {
        Self {
            quotas: Quotas::new(config.client_quota),
            config,
            instance,
            scenes: HashMap::new(),
            builds,
            memory_bytes: 0,
        }
    }

    /// This daemon run's instance id, which every reply carries.
    #[must_use]
    pub fn instance(&self) -> u64 {
        self.instance
    }

    /// A failure reply, carrying the instance id like every other (for refusals made
    /// outside [`handle`](Self::handle)).
    #[must_use]
    pub fn refusal(&self, code: ErrorCode, reason: &str) -> ControlReply {
        ControlReply {
            instance: self.instance,
            ..ControlReply::error(code, reason)
        }
    }

    /// Scene `id`, live or quarantined.
    #[must_use]
    pub fn entry(&self, id: u32) -> Option<&SceneEntry> {
        self.scenes.get(&id)
    }

    /// Stops every scene's frame in progress at its next poll (the daemon is stopping).
    pub fn stop_all_frames(&self) {
        for entry in self.scenes.values() {
            entry.signals.releasing();
        }
    }

    /// Scene `id`, if it lives (not quarantined).
    #[must_use]
    pub fn scene(&self, id: u32) -> Option<&SharedScene> {
        self.scenes.get(&id)?.state.as_ref().ok()
    }

    /// Answers one request from `origin`; the state changes only when the
    /// reply is a success. A `CreateScene` reply carries the new scene's keys. `None` when
    /// the request needs its scene's lock and a frame or a build holds it: nothing changed,
    /// ask again later (the control thread never waits for a frame, which may be long).
    pub fn handle_unless_busy(
        &mut self,
        origin: Origin,
        request: &ControlRequest,
        payload: &[u8],
    ) -> Option<ControlReply> {
        let mut reply = match self.try_handle(origin, request, payload) {
            Ok(Answer { id, flags }) => ControlReply {
                instance: self.instance,
                ..ControlReply::ok_with(id, flags)
            },
            Err(Refusal::SceneBusy) => return None,
            Err(Refusal::Rejected(r)) => self.refusal(r.code, &r.reason),
        };
        if request.command == Command::CreateScene as u32
            && let Some(entry) = self.scenes.get(&reply.id)
        {
            reply.frame_key = entry.frame_key;
            reply.scene_token = entry.token.0;
        }
        Some(reply)
    }

    /// [`handle_unless_busy`](Self::handle_unless_busy), asking again until the scene's
    /// lock is free (for callers that may wait: tests, the fuzz suite).
    #[cfg(test)]
    pub fn handle(
        &mut self,
        origin: Origin,
        request: &ControlRequest,
        payload: &[u8],
    ) -> ControlReply {
        loop {
            if let Some(reply) = self.handle_unless_busy(origin, request, payload) {
                return reply;
            }
            std::thread::yield_now();
        }
    }

    /// Whether every charge is where the [quota](super::quota) invariant puts it: each
    /// process's usage is the sum of its scenes', each live scene's bodies are its charged
    /// bodies, and the daemon-wide memory is the sum over all scenes.
    #[cfg(test)]
    pub fn accounts_balance(&self) -> bool {
        let mut sums: HashMap<ProcessId, Usage> = HashMap::new();
        for entry in self.scenes.values() {
            sums.entry(entry.process).or_default().add(entry.usage);
            if let Ok(shared) = &entry.state
                && lock(shared).scene.body_count() != entry.usage.bodies as usize
            {
                return false;
            }
        }
        let memory: u64 = sums.values().map(|u| u.memory_bytes).sum();
        memory == self.memory_bytes
            && sums.len() == self.quotas.processes()
            && sums.iter().all(|(&p, &u)| self.quotas.usage(p) == u)
    }

    /// Stops serving scene `id` after a fault on its services: frees its state and answers
    /// its owner's requests with `SceneQuarantined` and `reason` until it drops the id (its
    /// process's quota keeps only the scene itself). Returns whether the scene was live.
    pub fn quarantine(&mut self, id: u32, reason: String) -> bool {
        let Some(entry) = self.scenes.get_mut(&id).filter(|e| e.state.is_ok()) else {
            return false;
        };
        if let Ok(shared) = std::mem::replace(&mut entry.state, Err(reason)) {
            lock(&shared).dropped = true;
        }
        let freed = Usage {
            scenes: 0,
            ..std::mem::replace(&mut entry.usage, Usage::SCENE)
        };
        self.memory_bytes -= freed.memory_bytes;
        self.quotas.refund(entry.process, freed);
        true
    }

    fn try_handle(
        &mut self,
        origin: Origin,
        request: &ControlRequest,
        payload: &[u8],
    ) -> Result<Answer, Refusal> {
        let command = command_of(request, payload)?;
        match command {
            Command::Hello => Ok(PROTOCOL_VERSION.into()),
            Command::CreateScene => Ok(self.create_scene(origin)?.into()),
            Command::DropScene => {
                self.owned_entry(origin.port, request.scene)?;
                self.drop_scene(request.scene)?;
                Ok(request.scene.into())
            }
            Command::RegisterShape => self.register_shape(origin, request, payload),
            Command::ShapeState => {
                let building = match self
                    .owned_cell(origin.port, request.scene)?
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
            Command::AddBody => {
                self.owned_entry(origin.port, request.scene)?;
                self.check_room(origin.process, Usage::BODY)?;
                let body = self.add_body(origin, request)?;
                self.charge(request.scene, Usage::BODY);
                Ok(body.into())
            }
            Command::RemoveBody => {
                let body = BodyId(request.target);
                let mut cell = self.owned_cell(origin.port, request.scene)?;
                cell.scene.remove_body(body).map_err(scene_rejection)?;
                drop(cell);
                self.refund(request.scene, Usage::BODY);
                Ok(request.target.into())
            }
            Command::UpdateBody => {
                let motion = convert::motion(request.motion)?;
                let (filter, margin) = (convert::filter(request), convert::margin(request.margin));
                let mut cell = self.owned_cell(origin.port, request.scene)?;
                cell.scene
                    .update_body(BodyId(request.target), motion, filter, margin)
                    .map_err(scene_rejection)?;
                Ok(request.target.into())
            }
            Command::SetSceneParams => {
                let choice = broad_phase(request.broad_phase)?;
                self.owned_cell(origin.port, request.scene)?
                    .scene
                    .set_broad_phase(choice);
                Ok(request.scene.into())
            }
        }
    }

    /// Adds a body of a built shape: the request is checked before the scene is locked.
    fn add_body(&self, origin: Origin, request: &ControlRequest) -> Result<u32, Refusal> {
        let pose = convert::pose(request.position, request.orientation)?;
        let motion = convert::motion(request.motion)?;
        let mut cell = self.owned_cell(origin.port, request.scene)?;
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
        &mut self,
        origin: Origin,
        request: &ControlRequest,
        payload: &[u8],
    ) -> Result<Answer, Refusal> {
        let config = &self.config;
        let max_shapes = config.scene_limits.max_shapes;
        let shape = convert::shape_request(
            request,
            payload.len(),
            &config.mesh_limits,
            config.max_convex_points,
        )?;
        let shared = self.owned_scene(origin.port, request.scene)?;
        let geometry = match shape {
            ShapeRequest::Primitive(shape) => {
                self.check_room(origin.process, Usage::shape(0))?;
                let mut cell = try_lock(shared)?;
                // The table hands out no more ids than the scene takes shapes, so the
                // scene has room for this one.
                let id = cell.shapes.reserve(max_shapes)?;
                let registered = cell.scene.register_shape(shape).map_err(scene_rejection);
                cell.shapes.finish(id, registered.clone());
                // A refused primitive keeps its id (refused), so it is charged too.
                drop(cell);
                self.charge(request.scene, Usage::shape(0));
                return Ok(registered.map(|_| id.into())?);
            }
            ShapeRequest::Geometry(geometry) => geometry,
        };
        // Before an id is handed out for nothing: only this thread queues, so the room
        // found here is still there below.
        self.builds.check_room()?;
        let charge = budget_memory::geometry_estimate(&geometry);
        self.check_room(origin.process, Usage::shape(charge))?;
        // The last point where the request may wait for the scene: nothing changed yet.
        let shape = try_lock(shared)?.shapes.reserve(max_shapes)?;
        let job = BuildJob {
            scene_id: request.scene,
            shape,
            scene: Arc::downgrade(shared),
            geometry,
            payload: payload.to_vec(),
        };
        if let Err(refused) = self.builds.submit(job) {
            lock(shared).shapes.finish(shape, Err(refused.clone()));
            return Err(refused.into());
        }
        self.charge(request.scene, Usage::shape(charge));
        Ok(Answer {
            id: shape,
            flags: reply_flags::SHAPE_BUILDING,
        })
    }

    /// Drops scene `id` with all its shapes and bodies (a frame or build still holding it
    /// leaves it alone, see [`shared_scene`]), or lets go of a quarantined id.
    ///
    /// # Errors
    /// [`ErrorCode::UnknownScene`] when no such scene lives.
    pub fn drop_scene(&mut self, id: u32) -> Result<(), Rejection> {
        let entry = self.scenes.remove(&id).ok_or_else(|| unknown(id))?;
        if let Ok(shared) = entry.state {
            lock(&shared).dropped = true;
        }
        self.memory_bytes -= entry.usage.memory_bytes;
        self.quotas.refund(entry.process, entry.usage);
        Ok(())
    }

    /// Whether the daemon's memory budget and `process`'s quota have room for `more`.
    fn check_room(&self, process: ProcessId, more: Usage) -> Result<(), Rejection> {
        let (in_use, budget) = (self.memory_bytes, self.config.max_memory_bytes);
        if in_use.saturating_add(more.memory_bytes) > budget {
            return Err(Rejection::new(
                ErrorCode::LimitExceeded,
                format!(
                    "it needs about {}; the daemon's {} for shapes and bodies has {} left",
                    budget_memory::readable(more.memory_bytes),
                    budget_memory::readable(budget),
                    budget_memory::readable(budget.saturating_sub(in_use))
                ),
            ));
        }
        self.quotas.check(process, more)
    }

    /// Charges `more` to scene `id` and its process (the daemon-wide memory too).
    fn charge(&mut self, id: u32, more: Usage) {
        if let Some(entry) = self.scenes.get_mut(&id) {
            entry.usage.add(more);
            self.quotas.charge(entry.process, more);
            self.memory_bytes += more.memory_bytes;
        }
    }

    /// Gives `back` (charged to scene `id` before) back.
    fn refund(&mut self, id: u32, back: Usage) {
        if let Some(entry) = self.scenes.get_mut(&id) {
            entry.usage.remove(back);
            self.quotas.refund(entry.process, back);
            self.memory_bytes -= back.memory_bytes;
        }
    }

    fn create_scene(&mut self, origin: Origin) -> Result<u32, Rejection> {
        if self.scenes.len() >= self.config.max_scenes as usize {
            return Err(Rejection::new(
                ErrorCode::LimitExceeded,
                format!(
                    "the daemon's limit of {} scenes is reached",
                    self.config.max_scenes
                ),
            ));
        }
        self.check_room(origin.process, Usage::SCENE)?;
        let scene = Scene::try_new(self.config.default_margin, self.config.scene_limits)
            .map_err(scene_rejection)?;
        let secret = |what| {
            secrets::random_u64().map_err(|e| {
                Rejection::new(
                    ErrorCode::Internal,
                    format!("no randomness for {what}: {e}"),
                )
            })
        };
        // Random ids: a client cannot name (or set up services for) a scene before it exists.
        let id = loop {
            let id = secret("a scene id")? as u32;
            if id != u32::MAX && !self.scenes.contains_key(&id) {
                break id;
            }
        };
        let entry = SceneEntry {
            owner: origin.port,
            process: origin.process,
            token: SceneToken([secret("a scene token")?, secret("a scene token")?]),
            frame_key: secret("a frame key")?,
            state: Ok(shared_scene::share(scene)),
            usage: Usage::NOTHING,
            signals: SceneSignals::new(),
        };
        self.scenes.insert(id, entry);
        self.charge(id, Usage::SCENE);
        Ok(id)
    }

    /// Scene `id`, if it exists and belongs to client port `origin`.
    fn owned_entry(&self, origin: OwnerId, id: u32) -> Result<&SceneEntry, Rejection> {
        let entry = self.scenes.get(&id).ok_or_else(|| unknown(id))?;
        if entry.owner != origin {
            return Err(Rejection::new(
                ErrorCode::NotOwner,
                format!("scene {id} belongs to another client"),
            ));
        }
        Ok(entry)
    }

    /// Scene `id`'s cell, locked, if it belongs to client port `origin`, is not
    /// quarantined and nobody else holds its lock ([`Refusal::SceneBusy`] then).
    fn owned_cell(&self, origin: OwnerId, id: u32) -> Result<MutexGuard<'_, SceneCell>, Refusal> {
        try_lock(self.owned_scene(origin, id)?)
    }

    /// Scene `id`'s state, if it belongs to client port `origin` and is not quarantined.
    fn owned_scene(&self, origin: OwnerId, id: u32) -> Result<&SharedScene, Rejection> {
        self.owned_entry(origin, id)?
            .state
            .as_ref()
            .map_err(|reason| {
                Rejection::new(ErrorCode::SceneQuarantined, format!("scene {id}: {reason}"))
            })
    }
}

/// The command of `request`, once its header is one this daemon answers: its protocol
/// version, a zero `reserved` field, a known command, a payload only with RegisterShape.
fn command_of(request: &ControlRequest, payload: &[u8]) -> Result<Command, Rejection> {
    if request.protocol_version != PROTOCOL_VERSION {
        return Err(Rejection::new(
            ErrorCode::ProtocolMismatch,
            format!(
                "client speaks protocol {}, the daemon {PROTOCOL_VERSION}",
                request.protocol_version
            ),
        ));
    }
    if request.reserved != 0 {
        return Err(Rejection::new(
            ErrorCode::MalformedMessage,
            "the reserved field is not 0",
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
    Ok(command)
}

/// Why a request got no answer: refused (its reply says why), or its scene's lock was
/// held by a frame or a build (asked again later; nothing changed).
#[derive(Debug)]
enum Refusal {
    Rejected(Rejection),
    SceneBusy,
}

impl From<Rejection> for Refusal {
    fn from(rejection: Rejection) -> Self {
        Self::Rejected(rejection)
    }
}

/// `scene`'s lock, unless another thread holds it. A lock poisoned by a thread that
/// panicked is taken over, as [`lock`] does.
fn try_lock(scene: &SharedScene) -> Result<MutexGuard<'_, SceneCell>, Refusal> {
    match scene.try_lock() {
        Ok(guard) => Ok(guard),
        Err(TryLockError::Poisoned(poisoned)) => Ok(poisoned.into_inner()),
        Err(TryLockError::WouldBlock) => Err(Refusal::SceneBusy),
    }
}

/// The refusal of a request naming scene `id`, which does not exist.
fn unknown(id: u32) -> Rejection {
    Rejection::new(ErrorCode::UnknownScene, format!("no scene {id}"))
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
