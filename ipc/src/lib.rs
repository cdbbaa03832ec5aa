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
pub const PROTOCOL_VERSION: u32 = 8;

/// The default root prefix of every service name (`<root>/control`, `<root>/<scene>/poses`…).
pub const DEFAULT_ROOT: &str = "proxima";

/// The name of the control service under `root`.
#[must_use]
pub fn control_service_name(root: &str) -> String {
    format!("{root}/control")
}

/// The builder of the control service (`<root>/control`), with every setting the daemon and
/// its clients must agree on. Both sides call this and then `open_or_create()`, so whichever
/// comes first creates the service with these settings and the other opens it.
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
        .max_response_buffer_size(CONTROL_MAX_RESPONSE_BUFFER_SIZE))
}

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

/// The builder of scene `scene`'s pose service (`<root>/<scene>/poses`): `[PoseRecord]`
/// slices with a [`wire::PoseFrameHeader`], up to [`POSES_MAX_PUBLISHERS`] client
/// publishers, the daemon's one subscriber keeping the newest [`FRAME_BUFFER`] frames
/// (older ones are overwritten: the newest frame wins under a deadline). Both sides call it,
/// then `open_or_create()`.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn poses_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    scene: u32,
) -> Result<PosesServiceBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&poses_service_name(root, scene))?;
    Ok(node
        .service_builder(&name)
        .publish_subscribe::<[wire::PoseRecord]>()
        .user_header::<wire::PoseFrameHeader>()
        .max_publishers(POSES_MAX_PUBLISHERS)
        .max_subscribers(1)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0))
}

/// The builder of scene `scene`'s result service (`<root>/<scene>/results`): `[ResultRecord]`
/// slices with a [`wire::ResultFrameHeader`], the daemon's one publisher, up to
/// [`RESULTS_MAX_SUBSCRIBERS`] subscribers (the simulation, monitors).
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn results_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    scene: u32,
) -> Result<ResultsServiceBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&results_service_name(root, scene))?;
    Ok(node
        .service_builder(&name)
        .publish_subscribe::<[wire::ResultRecord]>()
        .user_header::<wire::ResultFrameHeader>()
        .max_publishers(1)
        .max_subscribers(RESULTS_MAX_SUBSCRIBERS)
        .subscriber_max_buffer_size(FRAME_BUFFER)
        .history_size(0))
}

/// The builder of scene `scene`'s poses-ready event service (`<root>/<scene>/poses-ready`):
/// clients notify [`EVENT_POSES_SENT`] after publishing a pose frame; the daemon's one
/// listener blocks on it (in its WaitSet) between frames. One service per direction, so
/// neither side is woken by its own notifications.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn poses_ready_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    scene: u32,
) -> Result<EventBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&format!("{root}/{scene}/poses-ready"))?;
    Ok(node
        .service_builder(&name)
        .event()
        .max_notifiers(POSES_MAX_PUBLISHERS)
        .max_listeners(DAEMON_EVENT_PORTS))
}

/// The builder of scene `scene`'s results-ready event service (`<root>/<scene>/results-ready`):
/// the daemon notifies [`EVENT_RESULTS_READY`] after publishing a result frame; clients
/// block on it instead of spinning.
///
/// # Errors
/// `root` does not make a valid iceoryx2 service name.
pub fn results_ready_service_builder<S: iceoryx2::service::Service>(
    node: &Node<S>,
    root: &str,
    scene: u32,
) -> Result<EventBuilder<S>, ServiceNameError> {
    let name = ServiceName::new(&format!("{root}/{scene}/results-ready"))?;
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
    scene: u32,
) -> Result<EventBuilder<S>, ServiceNameError> {
    results_ready_service_builder(node, root, scene)
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
        .max_nodes(CONTROL_MAX_CLIENTS + DAEMON_EVENT_PORTS))
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

/// The name of scene `scene`'s pose service under `root`.
#[must_use]
pub fn poses_service_name(root: &str, scene: u32) -> String {
    format!("{root}/{scene}/poses")
}

/// The name of scene `scene`'s result service under `root`.
#[must_use]
pub fn results_service_name(root: &str, scene: u32) -> String {
    format!("{root}/{scene}/results")
}

#[cfg(test)]
mod tests;
