//! The daemon-wide services (`<root>/control`, `<root>/control-events`, `<root>/frame-wake`),
//! claimed at start so no one else's stand in for them (DESIGN §10).
//!
//! Each is created with the shared builders' settings. One that already exists is opened
//! only when nobody serves it and its settings are exactly the daemon's: clients of an
//! earlier run that still hold it are fine; a service set up by another process with other
//! settings (a second server allowed, a deadline on the events, too few ids) is refused, and
//! so is a control service another process already serves. Both refusals stop the start
//! with a message that says which, so `proximad` exits non-zero instead of serving beside an
//! impostor.

use super::Ipc;
use super::error::DaemonStartError;
use iceoryx2::prelude::*;
use iceoryx2::service::builder::event::{
    Builder as EventBuilder, EventCreateError, EventOpenError,
};
use iceoryx2::service::builder::request_response::{
    RequestResponseCreateError, RequestResponseOpenError,
};
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;
use proxima_ipc::wire::{ControlReply, ControlRequest};
use proxima_ipc::{
    CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT, CONTROL_MAX_CLIENTS, CONTROL_MAX_NODES,
    CONTROL_MAX_RESPONSE_BUFFER_SIZE, CONTROL_MAX_SERVERS, ControlServiceBuilder,
    EVENT_CONTROL_SENT,
};

/// The control service's port factory.
pub type ControlFactory = iceoryx2::service::port_factory::request_response::PortFactory<
    Ipc,
    [u8],
    ControlRequest,
    ControlReply,
    (),
>;

/// Creates `<root>/control`, or opens one that nobody serves with exactly its settings.
///
/// # Errors
/// [`DaemonStartError::Occupied`] when another process serves it or set it up otherwise;
/// [`DaemonStartError::Ipc`] when iceoryx2 fails.
pub fn control_service(
    builder: ControlServiceBuilder<Ipc>,
    name: &str,
) -> Result<ControlFactory, DaemonStartError> {
    let service = create_or_open(name, || match builder.clone().create() {
        Ok(service) => Attempt::Done(Ok(service)),
        Err(RequestResponseCreateError::AlreadyExists) => match builder.clone().open() {
            Ok(service) => Attempt::Done(Ok(service)),
            Err(RequestResponseOpenError::DoesNotExist) => Attempt::Vanished,
            Err(e) => Attempt::Done(Err(cannot_open(name, &e))),
        },
        Err(e) => Attempt::Done(Err(DaemonStartError::Ipc(format!("{name}: {e:?}")))),
    })?;
    let servers = service.dynamic_config().number_of_servers();
    if servers > 0 {
        return Err(occupied(
            name,
            &format!("{servers} other server(s) already serve it: is another proximad running?"),
        ));
    }
    let config = service.static_config();
    let found = [
        ("max_clients", config.max_clients(), CONTROL_MAX_CLIENTS),
        ("max_servers", config.max_servers(), CONTROL_MAX_SERVERS),
        (
            "max_active_requests_per_client",
            config.max_active_requests_per_client(),
            CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT,
        ),
        (
            "max_response_buffer_size",
            config.max_response_buffer_size(),
            CONTROL_MAX_RESPONSE_BUFFER_SIZE,
        ),
        ("max_nodes", config.max_nodes(), CONTROL_MAX_NODES),
    ];
    check_settings(name, &found)?;
    Ok(service)
}

/// Creates the event service `builder` describes (named `name`), or opens one with exactly
/// `max_notifiers`, `max_listeners` and `max_nodes`, no deadline and room for every event
/// id; `max_nodes` `None` = iceoryx2's default, not checked.
///
/// # Errors
/// [`DaemonStartError::Occupied`] when it exists with other settings;
/// [`DaemonStartError::Ipc`] when iceoryx2 fails.
pub fn event_service(
    builder: EventBuilder<Ipc>,
    name: &str,
    expected: EventSettings,
) -> Result<EventFactory<Ipc>, DaemonStartError> {
    let service = create_or_open(name, || match builder.clone().create() {
        Ok(service) => Attempt::Done(Ok(service)),
        Err(EventCreateError::AlreadyExists) => match builder.clone().open() {
            Ok(service) => Attempt::Done(Ok(service)),
            Err(EventOpenError::DoesNotExist) => Attempt::Vanished,
            Err(e) => Attempt::Done(Err(cannot_open(name, &e))),
        },
        Err(e) => Attempt::Done(Err(DaemonStartError::Ipc(format!("{name}: {e:?}")))),
    })?;
    let config = service.static_config();
    if config.deadline().is_some() {
        return Err(occupied(name, "it was set up with a deadline"));
    }
    if config.event_id_max_value() < EVENT_CONTROL_SENT {
        return Err(occupied(name, "it was set up with too few event ids"));
    }
    let mut found = vec![
        ("max_notifiers", config.max_notifiers(), expected.notifiers),
        ("max_listeners", config.max_listeners(), expected.listeners),
    ];
    if let Some(nodes) = expected.nodes {
        found.push(("max_nodes", config.max_nodes(), nodes));
    }
    check_settings(name, &found)?;
    Ok(service)
}

/// The settings an existing event service must have.
#[derive(Debug, Clone, Copy)]
pub struct EventSettings {
    /// Its `max_notifiers`.
    pub notifiers: usize,
    /// Its `max_listeners`.
    pub listeners: usize,
    /// Its `max_nodes`, when the builder sets it.
    pub nodes: Option<usize>,
}

/// Refuses the service when a setting found differs from the one expected.
fn check_settings(name: &str, found: &[(&str, usize, usize)]) -> Result<(), DaemonStartError> {
    match found.iter().find(|(_, value, expected)| value != expected) {
        Some((setting, value, expected)) => Err(occupied(
            name,
            &format!("it was set up by another process with {setting} {value}, not {expected}"),
        )),
        None => Ok(()),
    }
}

/// One try at creating or opening a service.
enum Attempt<T> {
    /// Created, opened, or refused.
    Done(Result<T, DaemonStartError>),
    /// It existed when created and was gone when opened: a crashed process's service being
    /// cleaned up meanwhile. Try again.
    Vanished,
}

/// Tries `attempt` until it is done, or [`ATTEMPTS`] times.
fn create_or_open<T>(
    name: &str,
    mut attempt: impl FnMut() -> Attempt<T>,
) -> Result<T, DaemonStartError> {
    for _ in 0..ATTEMPTS {
        match attempt() {
            Attempt::Done(result) => return result,
            Attempt::Vanished => std::thread::sleep(std::time::Duration::from_millis(10)),
        }
    }
    Err(DaemonStartError::Ipc(format!(
        "{name}: it kept appearing and vanishing ({ATTEMPTS} attempts)"
    )))
}

/// How often [`create_or_open`] tries a service that vanishes between create and open.
const ATTEMPTS: usize = 50;

fn cannot_open(name: &str, e: &dyn std::fmt::Debug) -> DaemonStartError {
    occupied(
        name,
        &format!("it exists and cannot be opened as ours ({e:?})"),
    )
}

fn occupied(name: &str, why: &str) -> DaemonStartError {
    DaemonStartError::Occupied(format!("{name}: {why}"))
}
