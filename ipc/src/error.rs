//! Errors of the client library, one enum per operation (STYLE §3).
//!
//! - [`ClientConnectError`] for `ClientBuilder::connect`;
//! - [`ControlError`] for every control request of a `Client`;
//! - [`SceneOpenError`] for `Client::open_scene` and `SceneLink::open`;
//! - [`FrameSendError`] for publishing a pose frame on a `SceneLink`;
//! - [`FrameReceiveError`] for receiving a result frame on a `SceneLink`.
//!
//! iceoryx2 failures keep the iceoryx2 error's text in a `Transport` variant, so the enums
//! stay `Clone + Eq` and do not expose iceoryx2's error types in this crate's API.

use crate::wire::ErrorCode;

/// Why [`ClientBuilder::connect`](crate::client::ClientBuilder::connect) failed.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ClientConnectError {
    /// The root does not make a valid iceoryx2 service name; carries the root.
    InvalidRoot(String),
    /// The iceoryx2 prefix is not a valid file name; carries the prefix.
    InvalidPrefix(String),
    /// No daemon serves the control service, or it did not answer `Hello` within the reply
    /// timeout.
    NoDaemon,
    /// The daemon speaks another protocol version.
    ProtocolMismatch {
        /// The daemon's [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION).
        daemon: u32,
    },
    /// The daemon that answered is not the one expected
    /// (`ClientBuilder::expect_instance`): another process serves the control service.
    UnexpectedDaemon {
        /// The instance id the answering daemon gave.
        instance: u64,
    },
    /// The daemon refused `Hello` for another reason.
    Rejected {
        /// The daemon's error code (`Internal` when the status value is unknown).
        code: ErrorCode,
        /// The daemon's reason text.
        reason: String,
    },
    /// iceoryx2 failed to create the node, open the service or send; carries its error text.
    Transport(String),
}

impl std::fmt::Display for ClientConnectError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::InvalidRoot(root) => write!(f, "invalid service root {root:?}"),
            Self::InvalidPrefix(prefix) => write!(f, "invalid iceoryx2 prefix {prefix:?}"),
            Self::NoDaemon => f.write_str("no proxima daemon answered on the control service"),
            Self::ProtocolMismatch { daemon } => write!(
                f,
                "the daemon speaks protocol version {daemon}, this client {}",
                crate::PROTOCOL_VERSION
            ),
            Self::UnexpectedDaemon { instance } => write!(
                f,
                "the process serving the control service (instance {instance:#018x}) is not the \
                 daemon expected"
            ),
            Self::Rejected { code, reason } => {
                write!(f, "the daemon refused the connection: {code}: {reason}")
            }
            Self::Transport(text) => write!(f, "iceoryx2 failure while connecting: {text}"),
        }
    }
}

impl std::error::Error for ClientConnectError {}

/// Why a control request (create a scene, register a shape, add a body…) failed.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ControlError {
    /// The daemon refused the request.
    Rejected {
        /// What was wrong.
        code: ErrorCode,
        /// The daemon's reason text.
        reason: String,
    },
    /// The reply's status is a value this protocol version does not define.
    UnknownStatus(u32),
    /// No reply arrived within the client's reply timeout, though the daemon still serves.
    Timeout,
    /// The daemon this client connected to is gone (it crashed, or a restarted daemon now
    /// serves the root): its scenes, shapes and bodies went with it. Connect again and
    /// register everything anew.
    DaemonLost,
    /// The geometry has more points or indices than a `u32` count can carry; carries the
    /// offending count.
    TooLarge(usize),
    /// The shape was still being built when the client's build timeout passed (it may
    /// still become usable: wait again with `Client::wait_shape`).
    BuildTimeout {
        /// The shape's id.
        shape: u32,
    },
    /// iceoryx2 failed to loan, send or receive; carries its error text.
    Transport(String),
}

impl std::fmt::Display for ControlError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Rejected { code, reason } => {
                write!(f, "rejected by the daemon: {code}: {reason}")
            }
            Self::UnknownStatus(status) => {
                write!(f, "the daemon replied with unknown status {status}")
            }
            Self::Timeout => f.write_str("no reply from the daemon within the timeout"),
            Self::DaemonLost => f.write_str(
                "the daemon this client connected to is gone (crashed or restarted): reconnect",
            ),
            Self::TooLarge(count) => {
                write!(f, "{count} points or indices exceed the u32 wire count")
            }
            Self::BuildTimeout { shape } => {
                write!(
                    f,
                    "shape {shape} was still being built at the build timeout"
                )
            }
            Self::Transport(text) => write!(f, "iceoryx2 failure on the control service: {text}"),
        }
    }
}

impl std::error::Error for ControlError {}

/// Why [`Client::open_scene`](crate::client::Client::open_scene) or
/// [`SceneLink::open`](crate::scene_link::SceneLink::open) failed.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum SceneOpenError {
    /// The root does not make valid iceoryx2 service names; carries the root.
    InvalidRoot(String),
    /// No daemon serves a scene with this token (it was dropped, or never created).
    NoSuchScene,
    /// This client did not create the scene (or dropped it): only its creator holds the
    /// keys to drive it; carries the scene id. A monitor opens a scene's results with the
    /// token its owner shares (`ResultFeed::open`).
    NotOwned(u32),
    /// iceoryx2 failed to open or create a scene service or one of its ports (e.g. the
    /// services exist with incompatible settings, or too many ports); carries its error text.
    Transport(String),
}

impl std::fmt::Display for SceneOpenError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::InvalidRoot(root) => {
                write!(
                    f,
                    "service root {root:?} does not make valid scene service names"
                )
            }
            Self::NoSuchScene => f.write_str("no daemon serves a scene with this token"),
            Self::NotOwned(scene) => write!(
                f,
                "scene {scene} was not created by this client, which holds no keys to it"
            ),
            Self::Transport(text) => write!(f, "iceoryx2 failure while opening a scene: {text}"),
        }
    }
}

impl std::error::Error for SceneOpenError {}

/// Why publishing a pose frame failed.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum FrameSendError {
    /// The frame has more poses than the header's `u32` count can carry; carries the count.
    TooLarge(usize),
    /// iceoryx2 failed to loan the sample, send it or notify the daemon; carries its error
    /// text.
    Transport(String),
}

impl std::fmt::Display for FrameSendError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::TooLarge(count) => write!(f, "{count} poses exceed the u32 wire count"),
            Self::Transport(text) => {
                write!(f, "iceoryx2 failure while publishing a pose frame: {text}")
            }
        }
    }
}

impl std::error::Error for FrameSendError {}

/// Why receiving a result frame failed. Not receiving one in time is not an error: the
/// receive calls return `Ok(None)`.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum FrameReceiveError {
    /// No daemon serves the scene any more, found when a wait ended without a frame: the
    /// daemon is gone (its result publisher's process died), or it let go of the scene
    /// (dropped, released or quarantined; the control reply for the scene says which); or a
    /// frame came from another daemon instance. Either way the scene is gone: create it
    /// again (after connecting again when `Client` calls fail with `DaemonLost` too).
    DaemonLost,
    /// The daemon let go of the scene and said so in the scene's last result frame: its
    /// owner dropped it, or (`owner_gone`) its owner had been gone for the daemon's grace
    /// period. A monitor holding the scene's token learns here that it is over.
    SceneReleased {
        /// The owner's absence was why (its control client closed or its process died).
        owner_gone: bool,
    },
    /// iceoryx2 failed to receive a sample (e.g. the caller holds more result frames than
    /// the subscriber may borrow) or to wait on the event listener; carries its error text.
    Transport(String),
}

impl std::fmt::Display for FrameReceiveError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::DaemonLost => f.write_str(
                "the daemon serving the scene is gone (crashed or restarted): reconnect",
            ),
            Self::SceneReleased { owner_gone: true } => {
                f.write_str("the daemon released the scene: its owner is gone")
            }
            Self::SceneReleased { owner_gone: false } => {
                f.write_str("the daemon released the scene: its owner dropped it")
            }
            Self::Transport(text) => {
                write!(f, "iceoryx2 failure while receiving a result frame: {text}")
            }
        }
    }
}

impl std::error::Error for FrameReceiveError {}
