//! How the client waits on iceoryx2 and reports its failures, shared by the control half
//! ([`client`](crate::client)) and the frame half ([`scene_link`](crate::scene_link),
//! [`result_feed`](crate::result_feed)).
//!
//! Each wait polls for a bounded few tens of µs before it gives up the core: waking a
//! blocked process costs 60–120 µs on this machine class against ~7 µs for a polled
//! hand-over (DESIGN §3), and a longer spin would hold a core the daemon may need.
//! `examples/ipc_latency.rs` measures the round trips these waits end.

use std::time::Duration;

use crate::error::SceneOpenError;
use iceoryx2::service::builder::event::EventOpenError;
use iceoryx2::service::builder::publish_subscribe::PublishSubscribeOpenError;

/// How long a control request's reply is awaited by spinning before the wait starts
/// sleeping: request–response ports cannot join a WaitSet, so the reply is polled.
pub const CONTROL_REPLY_SPIN: Duration = Duration::from_micros(20);
/// One sleep of the control reply wait after [`CONTROL_REPLY_SPIN`].
pub const CONTROL_REPLY_SLEEP: Duration = Duration::from_micros(50);
/// The first pause between two `ShapeState` asks while the client waits for a shape to be
/// built; each pause doubles, up to [`SHAPE_POLL_MAX`]. A small shape is ready within a
/// pause or two; a large one costs a request every [`SHAPE_POLL_MAX`].
pub const SHAPE_POLL_FIRST: Duration = Duration::from_micros(200);
/// The longest pause between two `ShapeState` asks.
pub const SHAPE_POLL_MAX: Duration = Duration::from_millis(20);
/// How long a receive polls the result subscriber before it blocks on the scene's
/// results-ready listener: it catches the answers that come sooner than a wake-up.
pub const RESULTS_SPIN: Duration = Duration::from_micros(50);

/// A scene's services or ports could not be opened: `what` failed with iceoryx2's error `e`.
pub(crate) fn open_error(what: &str, e: impl std::fmt::Display) -> SceneOpenError {
    SceneOpenError::Transport(format!("{what}: {e}"))
}

/// A scene's publish–subscribe service could not be opened: no such scene (none, or one
/// being removed: the daemon let the scene go), or `what` failed.
pub(crate) fn pub_sub_open_error(what: &str, e: PublishSubscribeOpenError) -> SceneOpenError {
    match e {
        PublishSubscribeOpenError::DoesNotExist
        | PublishSubscribeOpenError::IsMarkedForDestruction => SceneOpenError::NoSuchScene,
        e => open_error(what, e),
    }
}

/// A scene's event service could not be opened: no such scene (none, or one being
/// removed), or `what` failed.
pub(crate) fn event_open_error(what: &str, e: EventOpenError) -> SceneOpenError {
    match e {
        EventOpenError::DoesNotExist | EventOpenError::IsMarkedForDestruction => {
            SceneOpenError::NoSuchScene
        }
        e => open_error(what, e),
    }
}
