//! Errors of starting and running the daemon (never caused by a client: client mistakes are
//! answered with wire error codes and the daemon keeps serving).

use std::fmt;

/// Why the daemon could not start.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum DaemonStartError {
    /// The iceoryx2 configuration (prefix, service name) is invalid.
    Config(String),
    /// iceoryx2 could not create the node or a service or port.
    Ipc(String),
    /// A service the daemon serves is already served, or was set up with other settings,
    /// by another process: the daemon refuses to serve beside it.
    Occupied(String),
}

impl DaemonStartError {
    /// The error of iceoryx2 failing to create `what`, as a `map_err` argument.
    pub(crate) fn ipc<E: fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> Self {
        move |e| Self::Ipc(format!("{what}: {e:?}"))
    }
}

impl fmt::Display for DaemonStartError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Config(why) => write!(f, "invalid configuration: {why}"),
            Self::Ipc(why) => write!(f, "shared-memory setup failed: {why}"),
            Self::Occupied(why) => write!(f, "refusing to start: {why}"),
        }
    }
}

impl std::error::Error for DaemonStartError {}

/// Why the daemon stopped with an error (a termination signal is not one).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum DaemonRunError {
    /// Receiving a request or sending a reply failed in iceoryx2.
    Ipc(String),
}

impl fmt::Display for DaemonRunError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Ipc(why) => write!(f, "shared-memory transfer failed: {why}"),
        }
    }
}

impl std::error::Error for DaemonRunError {}
