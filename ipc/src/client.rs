//! The control half of the client: connect to a `proximad` daemon, create scenes, register
//! shapes, and add, remove and update bodies. Each call is one request on the control
//! service (`<root>/control`) and one reply, waited for up to the client's reply timeout
//! (a registration that waits for its shape's build asks again until it is built, see below).
//!
//! ```no_run
//! use proxima_ipc::client::{BodySpec, ClientBuilder, Motion, Primitive};
//! use std::time::Duration;
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let client = ClientBuilder::new()
//!     .root("proxima")
//!     .reply_timeout(Duration::from_secs(1))
//!     .connect::<iceoryx2::service::ipc::Service>()?;
//! let scene = client.create_scene()?;
//! let ball = client.register_primitive(scene, Primitive::Sphere { radius: 0.1 })?;
//! let body = client.add_body(
//!     scene,
//!     &BodySpec {
//!         shape: ball,
//!         position: [0.0, 0.0, 1.0],
//!         orientation: [0.0, 0.0, 0.0, 1.0],
//!         motion: Motion::Dynamic,
//!         group: 1,
//!         mask: u32::MAX,
//!         margin: None,
//!     },
//! )?;
//! client.update_body(scene, body, Motion::Kinematic, 1, u32::MAX, Some(0.01))?;
//! client.remove_body(scene, body)?;
//! client.drop_scene(scene)?;
//! # Ok(())
//! # }
//! ```
//!
//! # Shapes that take time to build
//! The daemon builds convex and mesh shapes apart from the frames: their registration is
//! answered at once, and the shape becomes usable once built (seconds for a few hundred
//! thousand triangles). [`Client::register_convex`] and [`Client::register_mesh`] wait for
//! that, up to the build timeout ([`ClientBuilder::build_timeout`]), so the id they return
//! takes bodies at once. [`Client::register_mesh_no_wait`] and
//! [`Client::register_convex_no_wait`] return as soon as the daemon has accepted the
//! geometry; [`Client::shape_state`] and [`Client::wait_shape`] follow the build, and
//! [`Client::add_body`] on a shape not built yet is refused with
//! [`ErrorCode::ShapeNotReady`].
//!
//! Request–response ports cannot join a WaitSet, so a reply is awaited by polling with a
//! short back-off: a spin of [`CONTROL_REPLY_SPIN`], then sleeps of [`CONTROL_REPLY_SLEEP`].
//! After each request the client notifies the control event service, which wakes a daemon
//! blocked in its WaitSet.
//!
//! # When the daemon goes away
//! A client is bound to the daemon that answered its `Hello` (its server port). When that
//! daemon has crashed or was replaced by a restart, every request fails with
//! [`ControlError::DaemonLost`], at once if the daemon's port is already gone and otherwise
//! once the reply timeout has passed: the daemon's scenes, shapes and bodies are gone with
//! it, so connect again ([`ClientBuilder::connect`]) and register everything anew.

use std::collections::HashMap;
use std::sync::{Mutex, PoisonError};
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::identifiers::UniqueServerId;
use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::port::client::Client as ClientPort;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::{
    AllocationStrategy, CallbackProgression, EventId, FileName, PortFactory as _,
    SemanticString as _,
};
use iceoryx2::service::Service;
use iceoryx2::service::builder::event::EventOpenError;
use iceoryx2::service::builder::request_response::RequestResponseOpenError;
use iceoryx2::service::port_factory::event::PortFactory as EventPortFactory;
use iceoryx2::service::port_factory::request_response::PortFactory;

use crate::SceneToken;
use crate::error::{ClientConnectError, ControlError, SceneOpenError};
use crate::scene_link::{SceneAccess, SceneLink};
use crate::transport::{CONTROL_REPLY_SLEEP, CONTROL_REPLY_SPIN, SHAPE_POLL_FIRST, SHAPE_POLL_MAX};
use crate::wire::{
    BroadPhaseCode, Command, ControlReply, ControlRequest, ErrorCode, MotionCode, ShapeKindCode,
    reply_flags,
};
use crate::{CONTROL_INITIAL_MAX_SLICE_LEN, DEFAULT_ROOT, EVENT_CONTROL_SENT, PROTOCOL_VERSION};

/// The default reply timeout of [`ClientBuilder`].
pub const DEFAULT_REPLY_TIMEOUT: Duration = Duration::from_secs(2);
/// The default build timeout of [`ClientBuilder`]: long enough for the largest mesh the
/// daemon's default limits admit.
pub const DEFAULT_BUILD_TIMEOUT: Duration = Duration::from_secs(600);

/// A convex or mesh shape the daemon has accepted, built or not
/// ([`Client::register_mesh_no_wait`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Registration {
    /// The shape's id.
    pub shape: u32,
    /// Whether bodies may use it already; if not, see [`Client::wait_shape`].
    pub ready: bool,
}

/// Whether a registered shape may take bodies yet ([`Client::shape_state`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShapeState {
    /// The daemon is still building it.
    Building,
    /// Built: bodies may use it.
    Ready,
}

/// How the daemon decomposes a mesh registered with
/// [`Client::register_decomposed_mesh`] ([`ShapeKindCode::DecomposedMesh`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decomposition {
    /// Largest concavity of a part, relative to the mesh's bounding-box diagonal; 0 for
    /// the daemon's default (0.02).
    pub max_concavity: f64,
    /// Most parts, up to [`MAX_COMPOUND_PARTS`](crate::wire::MAX_COMPOUND_PARTS); 0 for
    /// the daemon's default (64).
    pub max_parts: u32,
    /// `false`: the concavity-driven cut search (quality first); `true`: relaxation
    /// (faster, looser).
    pub fast: bool,
}

impl Default for Decomposition {
    /// The daemon's defaults, quality first.
    fn default() -> Self {
        Self {
            max_concavity: 0.0,
            max_parts: 0,
            fast: false,
        }
    }
}

impl Decomposition {
    /// The request's `dimensions`: `[max_concavity, max_parts, method, 0]`.
    #[must_use]
    pub fn to_wire(self) -> [f64; 4] {
        let method = if self.fast { 1.0 } else { 0.0 };
        [self.max_concavity, f64::from(self.max_parts), method, 0.0]
    }
}

/// A primitive shape, dimensions in metres in the shape's local frame; round shapes' axes
/// run along local Z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Primitive {
    /// A ball about the origin.
    Sphere {
        /// Radius, metres.
        radius: f64,
    },
    /// A segment from `−half_height` to `+half_height` on Z, swept by a ball.
    Capsule {
        /// Radius, metres.
        radius: f64,
        /// Half the segment's length, metres.
        half_height: f64,
    },
    /// A box centred on the origin.
    Cuboid {
        /// Half extents along X, Y, Z, metres.
        half_extents: [f64; 3],
    },
    /// A cylinder from `−half_height` to `+half_height` on Z.
    Cylinder {
        /// Radius, metres.
        radius: f64,
        /// Half the height, metres.
        half_height: f64,
    },
    /// A cone with its base at `−half_height` and apex at `+half_height` on Z.
    Cone {
        /// Base radius, metres.
        radius: f64,
        /// Half the height, metres.
        half_height: f64,
    },
}

impl Primitive {
    /// The wire kind and `dimensions` of this primitive (see [`ShapeKindCode`]).
    #[must_use]
    pub const fn to_wire(self) -> (ShapeKindCode, [f64; 4]) {
        match self {
            Self::Sphere { radius } => (ShapeKindCode::Sphere, [radius, 0.0, 0.0, 0.0]),
            Self::Capsule {
                radius,
                half_height,
            } => (ShapeKindCode::Capsule, [radius, half_height, 0.0, 0.0]),
            Self::Cuboid {
                half_extents: [x, y, z],
            } => (ShapeKindCode::Cuboid, [x, y, z, 0.0]),
            Self::Cylinder {
                radius,
                half_height,
            } => (ShapeKindCode::Cylinder, [radius, half_height, 0.0, 0.0]),
            Self::Cone {
                radius,
                half_height,
            } => (ShapeKindCode::Cone, [radius, half_height, 0.0, 0.0]),
        }
    }
}

/// How a body moves (static bodies never pair with each other).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Motion {
    /// Never moves after it is added.
    Static,
    /// Moved by the client, not by physics.
    Kinematic,
    /// Moved by the client's physics.
    Dynamic,
}

impl Motion {
    /// The wire code of this motion kind.
    #[must_use]
    pub const fn to_wire(self) -> MotionCode {
        match self {
            Self::Static => MotionCode::Static,
            Self::Kinematic => MotionCode::Kinematic,
            Self::Dynamic => MotionCode::Dynamic,
        }
    }
}

/// A body to add to a scene.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySpec {
    /// The shape id (from a `register_*` call).
    pub shape: u32,
    /// Initial position of the body's local origin, metres, world frame.
    pub position: [f64; 3],
    /// Initial orientation, unit quaternion `[x, y, z, w]`, world frame.
    pub orientation: [f64; 4],
    /// How the body moves.
    pub motion: Motion,
    /// Collision group bits: a pair is tested when each body's group meets the other's mask.
    pub group: u32,
    /// Collision mask bits.
    pub mask: u32,
    /// Close-pair margin, metres, `≥ 0`; `None` = the scene's default.
    pub margin: Option<f64>,
}

/// The wire value of an optional margin: negative means "the scene's default".
const fn margin_to_wire(margin: Option<f64>) -> f64 {
    match margin {
        Some(m) => m,
        None => -1.0,
    }
}

/// Settings of a [`Client`]; [`ClientBuilder::connect`] makes one.
#[derive(Debug, Clone)]
pub struct ClientBuilder {
    root: String,
    prefix: Option<String>,
    reply_timeout: Duration,
    build_timeout: Duration,
    expected_instance: Option<u64>,
}

impl Default for ClientBuilder {
    fn default() -> Self {
        Self::new()
    }
}

impl ClientBuilder {
    /// Root [`DEFAULT_ROOT`], iceoryx2's global config, reply timeout
    /// [`DEFAULT_REPLY_TIMEOUT`], build timeout [`DEFAULT_BUILD_TIMEOUT`].
    #[must_use]
    pub fn new() -> Self {
        Self {
            root: DEFAULT_ROOT.to_owned(),
            prefix: None,
            reply_timeout: DEFAULT_REPLY_TIMEOUT,
            build_timeout: DEFAULT_BUILD_TIMEOUT,
            expected_instance: None,
        }
    }

    /// Connect only to the daemon run with instance id `instance` (as `proximad` logs it at
    /// start and writes it with `--instance-file`): another process serving the control
    /// service is refused with [`ClientConnectError::UnexpectedDaemon`].
    #[must_use]
    pub fn expect_instance(mut self, instance: u64) -> Self {
        self.expected_instance = Some(instance);
        self
    }

    /// The root prefix of the daemon's service names (its `--root`).
    #[must_use]
    pub fn root(mut self, root: &str) -> Self {
        self.root = root.to_owned();
        self
    }

    /// The iceoryx2 `global.prefix` of every shared-memory file (isolates test instances);
    /// by default iceoryx2's global config decides.
    #[must_use]
    pub fn iceoryx_prefix(mut self, prefix: &str) -> Self {
        self.prefix = Some(prefix.to_owned());
        self
    }

    /// How long each request waits for its reply, and connect for the daemon.
    #[must_use]
    pub fn reply_timeout(mut self, timeout: Duration) -> Self {
        self.reply_timeout = timeout;
        self
    }

    /// How long [`Client::register_mesh`], [`Client::register_convex`] and
    /// [`Client::wait_shape`] wait for a shape to be built.
    #[must_use]
    pub fn build_timeout(mut self, timeout: Duration) -> Self {
        self.build_timeout = timeout;
        self
    }

    /// Creates the node, opens the control service and checks the daemon's protocol version
    /// with `Hello`. Waits up to the reply timeout for a daemon to serve the service.
    ///
    /// # Errors
    /// [`ClientConnectError::NoDaemon`] when no daemon answers in time,
    /// [`ClientConnectError::ProtocolMismatch`] when it speaks another version, and the other
    /// variants for bad settings and iceoryx2 failures.
    pub fn connect<S: Service>(self) -> Result<Client<S>, ClientConnectError> {
        let deadline = Instant::now() + self.reply_timeout;
        let mut config = Config::global_config().clone();
        if let Some(prefix) = &self.prefix {
            config.global.prefix = FileName::new(prefix.as_bytes())
                .map_err(|_| ClientConnectError::InvalidPrefix(prefix.clone()))?;
        }
        let node = NodeBuilder::new()
            .config(&config)
            .create::<S>()
            .map_err(|e| ClientConnectError::Transport(format!("creating the node: {e}")))?;
        // The daemon creates both services; until it has, there is no daemon to talk to.
        let invalid_root = |_| ClientConnectError::InvalidRoot(self.root.clone());
        let control = crate::control_service_builder(&node, &self.root).map_err(invalid_root)?;
        let service = open_when_created(
            deadline,
            "control service",
            || control.clone().open(),
            |e| matches!(e, RequestResponseOpenError::DoesNotExist),
        )?;
        let port = control_port(&service)?;
        let control_events =
            crate::control_events_service_builder(&node, &self.root).map_err(invalid_root)?;
        let events = open_when_created(
            deadline,
            "control event service",
            || control_events.clone().open(),
            |e| matches!(e, EventOpenError::DoesNotExist),
        )?;
        let notifier = events.notifier_builder().create().map_err(|e| {
            ClientConnectError::Transport(format!("creating the control notifier: {e}"))
        })?;
        // A request sent before the daemon's server port exists is lost: wait for it first.
        poll_until(deadline, || {
            Ok::<_, ()>((service.dynamic_config().number_of_servers() > 0).then_some(()))
        })
        .ok()
        .flatten()
        .ok_or(ClientConnectError::NoDaemon)?;
        let mut client = Client {
            root: self.root,
            reply_timeout: self.reply_timeout,
            build_timeout: self.build_timeout,
            daemon: None,
            instance: 0,
            scenes: Mutex::default(),
            port,
            notifier,
            service,
            _events: events,
            node,
        };
        let hello = ControlRequest {
            protocol_version: PROTOCOL_VERSION,
            command: Command::Hello as u32,
            ..ControlRequest::default()
        };
        // iceoryx2 makes a port's connections once, when the other side's port list changes:
        // one that fails (its creation timed out on a loaded host) leaves this client unheard
        // for good. An unanswered Hello is therefore sent again from a fresh port, whose
        // arrival makes the daemon connect anew; Hello changes nothing, so a late reply to
        // the first is harmless.
        let mut wait = FIRST_HELLO_WAIT;
        let reply = loop {
            let attempt_deadline = deadline.min(Instant::now() + wait);
            match client.request_until(&hello, 0, |_| {}, attempt_deadline) {
                Ok((reply, daemon)) => {
                    client.daemon = Some(daemon);
                    break reply;
                }
                Err(ControlError::Timeout) if Instant::now() < deadline => {
                    client.port = control_port(&client.service)?;
                    wait *= 2;
                }
                Err(ControlError::Timeout) => return Err(ClientConnectError::NoDaemon),
                Err(e) => return Err(ClientConnectError::Transport(e.to_string())),
            }
        };
        check_hello(&reply)?;
        if self
            .expected_instance
            .is_some_and(|expected| expected != reply.instance)
        {
            return Err(ClientConnectError::UnexpectedDaemon {
                instance: reply.instance,
            });
        }
        client.instance = reply.instance;
        Ok(client)
    }
}

/// Opens a service the daemon creates (`what`, for the error text), polling until it
/// exists (`is_missing` tells the open error that says it does not yet) or `deadline`
/// passes ([`ClientConnectError::NoDaemon`]).
fn open_when_created<T, E: std::fmt::Display>(
    deadline: Instant,
    what: &str,
    mut open: impl FnMut() -> Result<T, E>,
    is_missing: impl Fn(&E) -> bool,
) -> Result<T, ClientConnectError> {
    poll_until(deadline, || match open() {
        Ok(service) => Ok(Some(service)),
        Err(e) if is_missing(&e) => Ok(None),
        Err(e) => Err(ClientConnectError::Transport(format!(
            "opening the {what}: {e}"
        ))),
    })?
    .ok_or(ClientConnectError::NoDaemon)
}

/// How long connect waits for the first `Hello`'s reply before it sends `Hello` again from
/// a fresh port; each further wait is twice the last.
const FIRST_HELLO_WAIT: Duration = Duration::from_millis(250);

/// A new client port of the control service.
fn control_port<S: Service>(
    service: &PortFactory<S, [u8], ControlRequest, ControlReply, ()>,
) -> Result<ClientPort<S, [u8], ControlRequest, ControlReply, ()>, ClientConnectError> {
    service
        .client_builder()
        .initial_max_slice_len(CONTROL_INITIAL_MAX_SLICE_LEN)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| ClientConnectError::Transport(format!("creating the client port: {e}")))
}

/// The daemon's answer to `Hello`: success with our version, or why not.
fn check_hello(reply: &ControlReply) -> Result<(), ClientConnectError> {
    match ErrorCode::from_u32(reply.status) {
        Some(ErrorCode::Ok) if reply.id == PROTOCOL_VERSION => Ok(()),
        Some(ErrorCode::Ok) => Err(ClientConnectError::ProtocolMismatch { daemon: reply.id }),
        Some(ErrorCode::ProtocolMismatch) => Err(ClientConnectError::ProtocolMismatch {
            daemon: reply.protocol_version,
        }),
        code => Err(ClientConnectError::Rejected {
            code: code.unwrap_or(ErrorCode::Internal),
            reason: reply.reason(),
        }),
    }
}

/// A connection to a daemon's control service. Not shareable between threads with
/// `ipc::Service` (iceoryx2's ports are single-threaded there).
pub struct Client<S: Service> {
    root: String,
    reply_timeout: Duration,
    build_timeout: Duration,
    /// The server port of the daemon that answered `Hello` (`None` only during connect).
    daemon: Option<UniqueServerId>,
    /// The instance id of that daemon (0 only during connect).
    instance: u64,
    /// The scenes this client created and has not dropped, with their keys.
    scenes: Mutex<HashMap<u32, SceneAccess>>,
    // Fields drop in order: the ports before their services, all before the node.
    port: ClientPort<S, [u8], ControlRequest, ControlReply, ()>,
    notifier: Notifier<S>,
    service: PortFactory<S, [u8], ControlRequest, ControlReply, ()>,
    _events: EventPortFactory<S>,
    node: Node<S>,
}

impl<S: Service> std::fmt::Debug for Client<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Client")
            .field("root", &self.root)
            .field("reply_timeout", &self.reply_timeout)
            .field("service", &self.service.name())
            .finish_non_exhaustive()
    }
}

impl<S: Service> Client<S> {
    /// The root prefix of the daemon's service names.
    #[must_use]
    pub fn root(&self) -> &str {
        &self.root
    }

    /// How long each request waits for its reply.
    #[must_use]
    pub fn reply_timeout(&self) -> Duration {
        self.reply_timeout
    }

    /// How long a registration waits for its shape to be built.
    #[must_use]
    pub fn build_timeout(&self) -> Duration {
        self.build_timeout
    }

    /// The iceoryx2 node that owns this client's ports (for opening scene services).
    #[must_use]
    pub fn node(&self) -> &Node<S> {
        &self.node
    }

    /// The instance id of the daemon this client is connected to (random per daemon run).
    #[must_use]
    pub fn daemon_instance(&self) -> u64 {
        self.instance
    }

    /// Opens the frame link to scene `scene`, which this client created (its pose, result
    /// and event services) on this client's node and root.
    ///
    /// # Errors
    /// [`SceneOpenError::NotOwned`] when this client did not create `scene` (or dropped
    /// it); otherwise see [`SceneOpenError`].
    pub fn open_scene(&self, scene: u32) -> Result<SceneLink<S>, SceneOpenError> {
        let access = self
            .scene_access(scene)
            .ok_or(SceneOpenError::NotOwned(scene))?;
        SceneLink::open(&self.node, &self.root, &access)
    }

    /// The keys of scene `scene`, if this client created it and has not dropped it. Its
    /// [`token`](SceneAccess::token) is the capability to read its results: give it to a
    /// monitor that may ([`ResultFeed::open`](crate::result_feed::ResultFeed::open)).
    #[must_use]
    pub fn scene_access(&self, scene: u32) -> Option<SceneAccess> {
        self.owned_scenes().get(&scene).copied()
    }

    /// Creates a scene owned by this client; returns its id (the client keeps its keys, see
    /// [`scene_access`](Self::scene_access)).
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn create_scene(&self) -> Result<u32, ControlError> {
        let reply = self.request(&self.header(Command::CreateScene, 0), &[])?;
        let scene = reply_id(&reply)?;
        let access = SceneAccess {
            scene,
            token: SceneToken(reply.scene_token),
            frame_key: reply.frame_key,
            instance: reply.instance,
        };
        self.owned_scenes().insert(scene, access);
        Ok(scene)
    }

    /// Drops scene `scene` with all its bodies.
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn drop_scene(&self, scene: u32) -> Result<(), ControlError> {
        self.call(&self.header(Command::DropScene, scene))?;
        self.owned_scenes().remove(&scene);
        Ok(())
    }

    /// The scenes this client owns (a poisoned lock is taken over: the map is always whole).
    fn owned_scenes(&self) -> std::sync::MutexGuard<'_, HashMap<u32, SceneAccess>> {
        self.scenes.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Registers a primitive shape for scene `scene`; returns the shape id.
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn register_primitive(&self, scene: u32, shape: Primitive) -> Result<u32, ControlError> {
        let (kind, dimensions) = shape.to_wire();
        self.call(&ControlRequest {
            shape_kind: kind as u32,
            dimensions,
            ..self.header(Command::RegisterShape, scene)
        })
    }

    /// Registers the convex hull of `points` (metres, the shape's local frame) for scene
    /// `scene` and waits until the daemon has built it; returns the shape id.
    ///
    /// # Errors
    /// See [`ControlError`]; [`ControlError::TooLarge`] beyond `u32::MAX` points;
    /// [`ControlError::BuildTimeout`] when it is not built within the build timeout.
    pub fn register_convex(&self, scene: u32, points: &[[f64; 3]]) -> Result<u32, ControlError> {
        let registration = self.register_convex_no_wait(scene, points)?;
        self.wait_registered(scene, registration)
    }

    /// Registers the convex hull of `points` like [`register_convex`](Self::register_convex),
    /// returning once the daemon has accepted the points, before the hull is built.
    ///
    /// # Errors
    /// As [`register_convex`](Self::register_convex), except that a geometry refused while
    /// building is told by [`shape_state`](Self::shape_state) instead.
    pub fn register_convex_no_wait(
        &self,
        scene: u32,
        points: &[[f64; 3]],
    ) -> Result<Registration, ControlError> {
        self.register_geometry(scene, ShapeKindCode::Convex, [0.0; 4], points, &[])
    }

    /// Registers a solid made of convex parts, each the hull of its points (metres, the
    /// shape's local frame), and waits until the daemon has built it; returns the shape id.
    /// Its contacts report true penetration depth, part pair by part pair.
    ///
    /// # Errors
    /// See [`ControlError`]; [`ControlError::TooLarge`] beyond `u32::MAX` points or parts
    /// (the daemon takes at most
    /// [`MAX_COMPOUND_PARTS`](crate::wire::MAX_COMPOUND_PARTS) parts);
    /// [`ControlError::BuildTimeout`] when it is not built within the build timeout.
    pub fn register_compound(
        &self,
        scene: u32,
        parts: &[&[[f64; 3]]],
    ) -> Result<u32, ControlError> {
        let points: Vec<[f64; 3]> = parts.iter().flat_map(|p| p.iter().copied()).collect();
        let sizes = parts
            .iter()
            .map(|p| u32::try_from(p.len()).map_err(|_| ControlError::TooLarge(p.len())))
            .collect::<Result<Vec<u32>, _>>()?;
        let kind = ShapeKindCode::Compound;
        let registration = self.register_geometry(scene, kind, [0.0; 4], &points, &sizes)?;
        self.wait_registered(scene, registration)
    }

    /// Registers a closed triangle mesh (as [`register_mesh`](Self::register_mesh)) that
    /// the daemon decomposes into convex parts as `how` says, answered as that compound
    /// (true penetration depth); waits until it is built (a decomposition takes seconds to
    /// a minute: set the build timeout accordingly) and returns the shape id.
    ///
    /// # Errors
    /// As [`register_mesh`](Self::register_mesh); a mesh that encloses no volume is
    /// [`ControlError::Rejected`] with `InvalidShape`.
    pub fn register_decomposed_mesh(
        &self,
        scene: u32,
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
        how: Decomposition,
    ) -> Result<u32, ControlError> {
        let kind = ShapeKindCode::DecomposedMesh;
        let indices = triangles.as_flattened();
        let registration = self.register_geometry(scene, kind, how.to_wire(), vertices, indices)?;
        self.wait_registered(scene, registration)
    }

    /// Registers a triangle mesh (vertices in metres, the shape's local frame; triangles as
    /// vertex indices) for scene `scene` and waits until the daemon has built it; returns
    /// the shape id.
    ///
    /// # Errors
    /// See [`ControlError`]; [`ControlError::TooLarge`] beyond `u32::MAX` vertices or
    /// indices; [`ControlError::BuildTimeout`] when it is not built within the build
    /// timeout.
    pub fn register_mesh(
        &self,
        scene: u32,
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<u32, ControlError> {
        let registration = self.register_mesh_no_wait(scene, vertices, triangles)?;
        self.wait_registered(scene, registration)
    }

    /// Registers a triangle mesh like [`register_mesh`](Self::register_mesh), returning once
    /// the daemon has accepted the geometry, before its BVHs are built.
    ///
    /// # Errors
    /// As [`register_mesh`](Self::register_mesh), except that a geometry refused while
    /// building (an index out of range, no triangles) is told by
    /// [`shape_state`](Self::shape_state) instead.
    pub fn register_mesh_no_wait(
        &self,
        scene: u32,
        vertices: &[[f64; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<Registration, ControlError> {
        let indices = triangles.as_flattened();
        self.register_geometry(scene, ShapeKindCode::Mesh, [0.0; 4], vertices, indices)
    }

    /// Whether shape `shape` of scene `scene` is built.
    ///
    /// # Errors
    /// See [`ControlError`]: a build that failed is [`ControlError::Rejected`] with its
    /// code and reason.
    pub fn shape_state(&self, scene: u32, shape: u32) -> Result<ShapeState, ControlError> {
        let reply = self.request(
            &ControlRequest {
                target: shape,
                ..self.header(Command::ShapeState, scene)
            },
            &[],
        )?;
        let (_, flags) = accepted(&reply)?;
        Ok(if flags & reply_flags::SHAPE_BUILDING == 0 {
            ShapeState::Ready
        } else {
            ShapeState::Building
        })
    }

    /// Waits until shape `shape` of scene `scene` is built, up to the build timeout, asking
    /// after pauses from [`SHAPE_POLL_FIRST`] doubling to [`SHAPE_POLL_MAX`].
    ///
    /// # Errors
    /// As [`shape_state`](Self::shape_state); [`ControlError::BuildTimeout`] when it is
    /// still being built at the timeout.
    pub fn wait_shape(&self, scene: u32, shape: u32) -> Result<(), ControlError> {
        let deadline = Instant::now() + self.build_timeout;
        let mut pause = SHAPE_POLL_FIRST;
        while self.shape_state(scene, shape)? == ShapeState::Building {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                return Err(ControlError::BuildTimeout { shape });
            }
            std::thread::sleep(pause.min(left));
            pause = (pause * 2).min(SHAPE_POLL_MAX);
        }
        Ok(())
    }

    /// Adds a body to scene `scene`; returns the body id.
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn add_body(&self, scene: u32, body: &BodySpec) -> Result<u32, ControlError> {
        self.call(&ControlRequest {
            target: body.shape,
            motion: body.motion.to_wire() as u32,
            group: body.group,
            mask: body.mask,
            margin: margin_to_wire(body.margin),
            position: body.position,
            orientation: body.orientation,
            ..self.header(Command::AddBody, scene)
        })
    }

    /// Removes body `body` from scene `scene`.
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn remove_body(&self, scene: u32, body: u32) -> Result<(), ControlError> {
        self.call(&ControlRequest {
            target: body,
            ..self.header(Command::RemoveBody, scene)
        })
        .map(drop)
    }

    /// Changes body `body`'s motion kind, collision group and mask, and margin (metres;
    /// `None` = the scene's default).
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn update_body(
        &self,
        scene: u32,
        body: u32,
        motion: Motion,
        group: u32,
        mask: u32,
        margin: Option<f64>,
    ) -> Result<(), ControlError> {
        self.call(&ControlRequest {
            target: body,
            motion: motion.to_wire() as u32,
            group,
            mask,
            margin: margin_to_wire(margin),
            ..self.header(Command::UpdateBody, scene)
        })
        .map(drop)
    }

    /// Sets which broad phase scene `scene`'s frames run, from its next frame on
    /// ([`BroadPhaseCode::Auto`], the default, lets the daemon choose). Results do not
    /// depend on it, only their cost.
    ///
    /// # Errors
    /// See [`ControlError`].
    pub fn set_broad_phase(
        &self,
        scene: u32,
        broad_phase: BroadPhaseCode,
    ) -> Result<(), ControlError> {
        self.call(&ControlRequest {
            broad_phase: broad_phase as u32,
            ..self.header(Command::SetSceneParams, scene)
        })
        .map(drop)
    }

    /// Sends one raw request and returns the raw reply, its status not interpreted. For
    /// tests and tools; the typed methods above are built on it.
    ///
    /// # Errors
    /// [`ControlError::Timeout`], [`ControlError::DaemonLost`] and
    /// [`ControlError::Transport`] only.
    pub fn request(
        &self,
        header: &ControlRequest,
        payload: &[u8],
    ) -> Result<ControlReply, ControlError> {
        self.request_until(
            header,
            payload.len(),
            |out| out.copy_from_slice(payload),
            Instant::now() + self.reply_timeout,
        )
        .map(|(reply, _)| reply)
    }

    /// Whether the daemon this client said `Hello` to still serves the control service.
    /// Removes the ports of crashed processes first, so a daemon killed without a chance to
    /// clean up counts as gone.
    #[must_use]
    pub fn daemon_is_alive(&self) -> bool {
        let _ = self.node.try_cleanup_dead_nodes();
        self.daemon_is_listed()
    }

    /// Whether the daemon's server port is listed on the control service (a crashed
    /// daemon's port stays listed until some process cleans up its node).
    fn daemon_is_listed(&self) -> bool {
        let Some(daemon) = self.daemon else {
            return true;
        };
        let mut listed = false;
        self.service.dynamic_config().list_servers(|server| {
            listed = server.server_id == daemon;
            if listed {
                CallbackProgression::Stop
            } else {
                CallbackProgression::Continue
            }
        });
        listed
    }

    /// A request header for `command` on `scene`, every other field zero.
    fn header(&self, command: Command, scene: u32) -> ControlRequest {
        ControlRequest {
            protocol_version: PROTOCOL_VERSION,
            command: command as u32,
            scene,
            ..ControlRequest::default()
        }
    }

    /// Registers a shape with a geometry payload: `vertices`, then `indices` (a mesh's
    /// vertex indices, a compound's part sizes).
    fn register_geometry(
        &self,
        scene: u32,
        kind: ShapeKindCode,
        dimensions: [f64; 4],
        vertices: &[[f64; 3]],
        indices: &[u32],
    ) -> Result<Registration, ControlError> {
        let count = |n: usize| u32::try_from(n).map_err(|_| ControlError::TooLarge(n));
        let header = ControlRequest {
            shape_kind: kind as u32,
            dimensions,
            vertex_count: count(vertices.len())?,
            index_count: count(indices.len())?,
            ..self.header(Command::RegisterShape, scene)
        };
        let len = geometry_len(vertices.len(), indices.len());
        let fill = |out: &mut [u8]| encode_geometry(out, vertices, indices);
        let (reply, _) =
            self.request_until(&header, len, fill, Instant::now() + self.reply_timeout)?;
        let (shape, flags) = accepted(&reply)?;
        Ok(Registration {
            shape,
            ready: flags & reply_flags::SHAPE_BUILDING == 0,
        })
    }

    /// The id of an accepted registration, once its shape is built.
    fn wait_registered(&self, scene: u32, registration: Registration) -> Result<u32, ControlError> {
        if !registration.ready {
            self.wait_shape(scene, registration.shape)?;
        }
        Ok(registration.shape)
    }

    /// One request with an empty payload; the reply's id on success.
    fn call(&self, header: &ControlRequest) -> Result<u32, ControlError> {
        reply_id(&self.request(header, &[])?)
    }

    /// Loans a `len`-byte request, lets `fill` write it, sends it, wakes the daemon and waits
    /// for the reply until `deadline`; returns the reply and the server port that sent it.
    ///
    /// [`ControlError::DaemonLost`] before sending when the daemon's port is gone, when a
    /// reply comes from another daemon, and at the deadline when the daemon has died.
    fn request_until(
        &self,
        header: &ControlRequest,
        len: usize,
        fill: impl FnOnce(&mut [u8]),
        deadline: Instant,
    ) -> Result<(ControlReply, UniqueServerId), ControlError> {
        if !self.daemon_is_listed() {
            return Err(ControlError::DaemonLost);
        }
        let mut request = self
            .port
            .loan_slice(len)
            .map_err(|e| ControlError::Transport(format!("loaning a {len}-byte request: {e}")))?;
        *request.user_header_mut() = *header;
        fill(request.payload_mut());
        let pending = request
            .send()
            .map_err(|e| ControlError::Transport(format!("sending a request: {e}")))?;
        // No listener (a daemon that never blocks, or none at all) is not an error here: the
        // reply wait below decides.
        let _ = self
            .notifier
            .notify_with_custom_event_id(EventId::new(EVENT_CONTROL_SENT));
        let answer = poll_until(deadline, || {
            pending
                .receive()
                .map(|reply| reply.map(|r| (*r.payload(), r.origin())))
                .map_err(|e| ControlError::Transport(format!("receiving a reply: {e}")))
        })?;
        match answer {
            Some((_, origin)) if self.daemon.is_some_and(|daemon| daemon != origin) => {
                Err(ControlError::DaemonLost)
            }
            Some((reply, _)) if self.instance != 0 && reply.instance != self.instance => {
                Err(ControlError::DaemonLost)
            }
            Some(answer) => Ok(answer),
            None if !self.daemon_is_alive() => Err(ControlError::DaemonLost),
            None => Err(ControlError::Timeout),
        }
    }
}

/// The id of a success reply, or the reply's error.
fn reply_id(reply: &ControlReply) -> Result<u32, ControlError> {
    accepted(reply).map(|(id, _)| id)
}

/// The id and [`reply_flags`] of a success reply, or the reply's error.
fn accepted(reply: &ControlReply) -> Result<(u32, u32), ControlError> {
    match ErrorCode::from_u32(reply.status) {
        Some(ErrorCode::Ok) => Ok((reply.id, reply.flags)),
        Some(code) => Err(ControlError::Rejected {
            code,
            reason: reply.reason(),
        }),
        None => Err(ControlError::UnknownStatus(reply.status)),
    }
}

/// Bytes of a geometry payload with `vertices` points and `indices` indices.
const fn geometry_len(vertices: usize, indices: usize) -> usize {
    vertices * 24 + indices * 4
}

/// Writes the geometry payload (see [`ControlRequest`]) into `out`, which is exactly
/// [`geometry_len`] bytes long.
fn encode_geometry(out: &mut [u8], vertices: &[[f64; 3]], indices: &[u32]) {
    debug_assert_eq!(out.len(), geometry_len(vertices.len(), indices.len()));
    let (points, index_bytes) = out.split_at_mut(vertices.len() * 24);
    let coordinates = vertices.iter().flatten();
    for (dst, x) in points.chunks_exact_mut(8).zip(coordinates) {
        dst.copy_from_slice(&x.to_ne_bytes());
    }
    for (dst, i) in index_bytes.chunks_exact_mut(4).zip(indices) {
        dst.copy_from_slice(&i.to_ne_bytes());
    }
}

/// Polls `poll` until it yields a value or `deadline` passes (`Ok(None)`): spins for
/// [`CONTROL_REPLY_SPIN`], then sleeps [`CONTROL_REPLY_SLEEP`] between polls. Polls at least once.
fn poll_until<T, E>(
    deadline: Instant,
    mut poll: impl FnMut() -> Result<Option<T>, E>,
) -> Result<Option<T>, E> {
    let start = Instant::now();
    loop {
        if let Some(value) = poll()? {
            return Ok(Some(value));
        }
        let now = Instant::now();
        if now >= deadline {
            return Ok(None);
        }
        if now - start < CONTROL_REPLY_SPIN {
            std::hint::spin_loop();
        } else {
            std::thread::sleep(CONTROL_REPLY_SLEEP.min(deadline - now));
        }
    }
}

#[cfg(test)]
#[path = "client_tests.rs"]
mod tests;
