//! The daemon: `proximad`'s service loop and the only code that touches the wire.
//!
//! - [`config`]: start-up configuration (service root, iceoryx2 prefix, limits);
//! - `convert`: wire records to validated domain values, once, at the boundary;
//! - `control`: the control service's logic (scenes, shapes, bodies), one request → one reply.

pub mod config;
mod control;
mod convert;

pub use config::DaemonConfig;
pub use control::ControlState;
pub use convert::Rejection;
