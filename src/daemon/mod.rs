//! The daemon: `proximad`'s service loop and the only code that touches the wire.
//!
//! - [`config`]: start-up configuration (service root, iceoryx2 prefix, limits);
//! - [`config_file`]: the same as a TOML file (`proximad --config FILE`);
//! - `convert`: wire records to validated domain values, once, at the boundary;
//! - `control`: the control service's logic (scenes, shapes, bodies), one request → one reply;
//! - `ingest`: stage 1 of a frame, a pose frame checked whole and applied to its scene;
//! - `frame_loop`: a scene's pose subscriber, result publisher and event notifier, and the
//!   path of one frame through ingest, the pipeline and publication;
//! - `service_loop`: the iceoryx2 node and ports, served until a termination signal, with a
//!   hybrid wait (spin, then block in a WaitSet) and a periodic dead-client sweep;
//! - [`liveness`]: which client owns each scene, and which scenes outlived their owner;
//! - [`log`]: leveled stderr lines, once per (scene or client, cause);
//! - `error`: start-up and run failures (client mistakes are wire error codes instead).

mod build_gate;
mod builder;
pub mod config;
pub mod config_file;
mod control;
mod convert;
mod error;
mod frame_loop;
mod ingest;
pub mod liveness;
pub mod log;
mod schedule;
mod service_loop;
mod shape_table;
mod shared_scene;

pub use build_gate::BuildGate;
pub use config::DaemonConfig;
pub use convert::Rejection;
pub use error::{DaemonRunError, DaemonStartError};
pub use ingest::{FrameRejection, apply_pose_frame};
pub use service_loop::{Daemon, StopHandle};
