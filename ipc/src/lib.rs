//! # proxima-ipc
//!
//! Proxima's wire protocol over iceoryx2 shared memory: the `#[repr(C)]` records, the service
//! names and the protocol version a client checks on connect. Depends only on iceoryx2 and
//! std; records use plain arrays (`[f64; 3]`), never glam, so clients in any language that
//! iceoryx2 binds can speak it. `ipc/PROTOCOL.md` describes the protocol without Rust
//! (names, settings, type names, byte layouts, codes, sequences); `ipc/tests/protocol_doc.rs`
//! keeps it equal to this crate.
//!
//! The protocol, in the order a client meets it:
//! - [`wire`]: the records and headers that cross shared memory, their codes and query flags;
//! - this crate's root: [`PROTOCOL_VERSION`], the service names and the builders both sides
//!   open every service with ([`control_service_builder`], [`poses_service_builder`],
//!   [`results_service_builder`], the event services), and the event ids;
//! - [`client`]: [`ClientBuilder`](client::ClientBuilder) → [`Client`](client::Client), one
//!   control request and its reply per call (a convex or mesh registration that waits for
//!   its build asks again until the shape is built);
//! - [`scene_link`]: a scene's pose frames out and its result frames back;
//!   [`result_feed`] is the receiving half alone, for monitors;
//! - [`error`]: one error enum per operation.
//!
//! [`transport`] holds how the client waits on iceoryx2 (its spins and sleeps).
//! [`tools`] is **not part of the protocol**: helpers for tools and tests (child-process
//! isolation, latency summaries).

pub mod client;
pub mod error;
pub mod result_feed;
pub mod scene_link;
pub mod wire;

pub mod transport;

pub mod tools;

use iceoryx2::node::Node;
use iceoryx2::service::builder::event::Builder as EventBuilder;
use iceoryx2::service::builder::publish_subscribe::Builder as PublishSubscribeBuilder;
use iceoryx2::service::builder::request_response::Builder as RequestResponseBuilder;
use iceoryx2::service::service_name::{ServiceName, ServiceNameError};

/// The protocol version. A client and a daemon whose versions differ refuse to talk; bump it
/// on any change to a wire record's layout or meaning.
pub const PROTOCOL_VERSION: u32 = 11;

/// The default root prefix of every service name (`<root>/control`, `<root>/scene-<token>/poses`…).
pub const DEFAULT_ROOT: &str = "proxima";

/// The name of the control service under `root`.
#[must_use]
pub fn control_service_name(root: &str) -> String {
    format!("{root}/control")
}

/// The builder of the control service (`<root>/control`), with every setting the daemon and
/// its clients must agree on. The daemon creates the service (or, when clients of an
/// earlier run still hold it, opens it after checking that no one serves it and that its
/// client, server, request, buffer and node counts are these); clients only `open()`.
///
/// Settings: request `[u8]` (geometry) with a [`wire::ControlRequest`] user header, response
/// [`wire::ControlReply`]; at most [`CONTROL_MAX_CLIENTS`] clients, [`CONTROL_MAX_SERVERS`]
/// server, [`CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT`] requests in flight per client and
/// [`CONTROL_MAX_RESPONSE_BUFFER_SIZE`] buffered responses. A client port additionally uses
/// [`CONTROL_INITIAL_MAX_SLICE_LEN`] and `AllocationStrategy::PowerOfTwo`, so meshes of any
/// size fit.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name (empty, too long, or bad characters).
pub fn control_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
) -> Result<ControlServiceBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&control_service_name(root))?;
    Ok(node
        .service_builder(&name)
        .request_response::<[u8], wire::ControlReply>()
        .request_user_header::<wire::ControlRequest>()
        .max_clients(CONTROL_MAX_CLIENTS)
        .max_servers(CONTROL_MAX_SERVERS)
        .max_active_requests_per_client(CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT)
        .max_response_buffer_size(CONTROL_MAX_RESPONSE_BUFFER_SIZE)
        .max_nodes(CONTROL_MAX_NODES))
}

/// Nodes that may hold the control service (and the control event service) at once: one
/// per client, plus the daemon's ports ([`DAEMON_EVENT_PORTS`]).
pub const CONTROL_MAX_NODES: usize = CONTROL_MAX_CLIENTS + DAEMON_EVENT_PORTS;

/// The iceoryx2 builder type [`control_service_builder`] returns.
pub type ControlServiceBuilder<S> =
    RequestResponseBuilder<[u8], wire::ControlRequest, wire::ControlReply, (), S>;

/// Most clients the control service admits at once.
pub const CONTROL_MAX_CLIENTS: usize = 64;
/// Servers of the control service: the one daemon.
pub const CONTROL_MAX_SERVERS: usize = 1;
/// Control requests one client may have in flight.
pub const CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT: usize = 4;
/// Responses buffered per control request.
pub const CONTROL_MAX_RESPONSE_BUFFER_SIZE: usize = 4;
/// Initial byte capacity of a client's request slice (grows by powers of two).
pub const CONTROL_INITIAL_MAX_SLICE_LEN: usize = 4096;

/// A scene's token: 128 random bits, handed to the scene's owner in the `CreateScene`
/// reply ([`wire::ControlReply::scene_token`]), that name the scene's services
/// ([`scene_services_name`]). Whoever holds it can open them, so it is the capability to
/// read the scene's results; sending it frames needs the frame key as well. `Debug` does not
/// print it, so it stays out of logs.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SceneToken(pub [u64; 2]);

impl std::fmt::Display for SceneToken {
    /// 32 lowercase hex digits: `self.0[0]`, then `self.0[1]`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:016x}{:016x}", self.0[0], self.0[1])
    }
}

impl std::str::FromStr for SceneToken {
    type Err = String;

    /// Parses the 32 hex digits [`Display`](std::fmt::Display) writes.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let bad = || format!("a scene token is 32 hex digits, not {text:?}");
        if text.len() != 32 || !text.is_ascii() {
            return Err(bad());
        }
        let half = |digits: &str| u64::from_str_radix(digits, 16).map_err(|_| bad());
        Ok(Self([half(&text[..16])?, half(&text[16..])?]))
    }
}

impl std::fmt::Debug for SceneToken {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("SceneToken(…)")
    }
}

/// The common prefix of the services of the scene with token `token` under `root`:
/// `<root>/scene-<token as 32 hex digits>`.
#[must_use]
pub fn scene_services_name(root: &str, token: SceneToken) -> String {
    format!("{root}/scene-{token}")
}

/// The builder of a scene's pose service (`<scene services>/poses`): `[PoseRecord]`
/// slices with a [`wire::PoseFrameHeader`], up to [`POSES_MAX_PUBLISHERS`] client
/// publishers, the daemon's one subscriber keeping the newest [`FRAME_BUFFER`] frames
/// (older ones are overwritten: the newest frame wins under a deadline). The daemon creates
/// it; clients open it.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn poses_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    token: SceneToken,
) -> Result<PosesServiceBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&poses_service_name(root, token))?;
    Ok(node
        .service_builder(&name)
        .publish_subscribe::<[wire::PoseRecord]>()
        .user_header::<wire::PoseFrameHeader>()
        .max_publishers(POSES_MAX_PUBLISHERS)
        .max_subscribers(1)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0))
}

/// The builder of a scene's result service (`<scene services>/results`): `[ResultRecord]`
/// slices with a [`wire::ResultFrameHeader`], the daemon's one publisher, up to
/// [`RESULTS_MAX_SUBSCRIBERS`] subscribers (the simulation, monitors). Safe overflow is on
/// (the default, stated): a subscriber that does not read loses its oldest frames and never
/// holds the daemon up.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn results_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    token: SceneToken,
) -> Result<ResultsServiceBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&results_service_name(root, token))?;
    Ok(node
        .service_builder(&name)
        .publish_subscribe::<[wire::ResultRecord]>()
        .user_header::<wire::ResultFrameHeader>()
        .max_publishers(1)
        .max_subscribers(RESULTS_MAX_SUBSCRIBERS)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0)
        .enable_safe_overflow(true))
}

/// The builder of a scene's poses-ready event service (`<scene services>/poses-ready`):
/// clients notify [`EVENT_POSES_SENT`] after publishing a pose frame; the daemon's one
/// listener blocks on it (in its WaitSet) between frames. One service per direction, so
/// neither side is woken by its own notifications.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn poses_ready_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    token: SceneToken,
) -> Result<EventBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&format!("{}/poses-ready", scene_services_name(root, token)))?;
    Ok(node
        .service_builder(&name)
        .event()
        .max_notifiers(POSES_MAX_PUBLISHERS)
        .max_listeners(DAEMON_EVENT_PORTS))
}

/// The builder of a scene's results-ready event service (`<scene services>/results-ready`):
/// the daemon notifies [`EVENT_RESULTS_READY`] after publishing a result frame; clients
/// block on it instead of spinning.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn results_ready_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    token: SceneToken,
) -> Result<EventBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&format!(
        "{}/results-ready",
        scene_services_name(root, token)
    ))?;
    Ok(node
        .service_builder(&name)
        .event()
        .max_notifiers(DAEMON_EVENT_PORTS)
        .max_listeners(RESULTS_MAX_SUBSCRIBERS))
}

/// The daemon's side of the result events: the same service as
/// [`results_ready_service_builder`], under the name the daemon's frame path uses.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn events_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    token: SceneToken,
) -> Result<EventBuilder<S>, ServiceNameError> {
    results_ready_service_builder(node, root, token)
}

/// The builder of the control event service (`<root>/control-events`): a client notifies
/// [`EVENT_CONTROL_SENT`] after each control request, so the daemon, blocked in its WaitSet,
/// wakes for it (request–response ports cannot join a WaitSet). Up to
/// [`CONTROL_MAX_CLIENTS`] notifiers; the daemon's one listener.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn control_events_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
) -> Result<EventBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&format!("{root}/control-events"))?;
    Ok(node
        .service_builder(&name)
        .event()
        .max_notifiers(CONTROL_MAX_CLIENTS)
        .max_listeners(DAEMON_EVENT_PORTS)
        .max_nodes(CONTROL_MAX_NODES))
}

/// The iceoryx2 builder type [`poses_service_builder`] returns.
pub type PosesServiceBuilder<S> =
    PublishSubscribeBuilder<[wire::PoseRecord], wire::PoseFrameHeader, S>;
/// The iceoryx2 builder type [`results_service_builder`] returns.
pub type ResultsServiceBuilder<S> =
    PublishSubscribeBuilder<[wire::ResultRecord], wire::ResultFrameHeader, S>;

/// Client processes that may publish poses to one scene.
pub const POSES_MAX_PUBLISHERS: usize = 4;
/// Processes that may subscribe to one scene's results.
pub const RESULTS_MAX_SUBSCRIBERS: usize = 8;
/// Frames a subscriber keeps before the oldest is overwritten.
pub const FRAME_BUFFER: usize = 2;
/// Event id a client sends after publishing a pose frame.
pub const EVENT_POSES_SENT: usize = 1;
/// Event id the daemon sends after publishing a result frame.
pub const EVENT_RESULTS_READY: usize = 2;
/// Event id a client sends after sending a control request.
pub const EVENT_CONTROL_SENT: usize = 3;
/// Daemon ports on a daemon-side event service: the running daemon, plus one slot for a
/// crashed predecessor whose node has not been cleaned up yet when a new daemon starts.
pub const DAEMON_EVENT_PORTS: usize = 2;

/// The name of the pose service of the scene with token `token` under `root`.
#[must_use]
pub fn poses_service_name(root: &str, token: SceneToken) -> String {
    format!("{}/poses", scene_services_name(root, token))
}

/// The name of the result service of the scene with token `token` under `root`.
#[must_use]
pub fn results_service_name(root: &str, token: SceneToken) -> String {
    format!("{}/results", scene_services_name(root, token))
}

#[cfg(test)]
mod tests;
