//! The daemon: `proximad`'s threads and the only code that touches the wire.
//!
//! # Threads
//! The frame path never waits for control work (DESIGN §8). Four kinds of thread:
//!
//! | thread | owns | does |
//! |---|---|---|
//! | frame (the caller of [`Daemon::run`]; `SCHED_FIFO` with `--realtime-priority`) | every scene's pose, result and event ports | pose frames only, earliest deadline first across scenes |
//! | control (`proximad-control`) | the node, the control server, the scenes by id | control requests, opening and closing scenes' ports, dead-client sweeps, signals |
//! | builder (`proximad-builder`, nice +10) | the queue of shapes to build | decoding and building convex and mesh shapes |
//! | workers (`proxima-worker-*`) | nothing between frames | a frame's mesh–mesh pairs, beside the frame thread |
//!
//! With two cores, the frame thread and one worker share a frame's work; the control thread
//! sleeps between requests; the builder takes what the frames leave. Scenes are shared, one
//! mutex each (`shared_scene`): the frame thread holds it for a frame, the control thread
//! and the builder only for O(1) edits, never for decoding or building. Scenes come to the
//! frame thread, ports opened, over a channel read between frames, and their ports go back to
//! the control thread to be closed. A registration is checked in O(1) on the control thread,
//! its payload copied into a bounded queue, and the shape is usable once the builder has
//! built it (the wire's `ShapeState` tells).
//!
//! # Modules
//! - [`config`]: start-up configuration (service root, iceoryx2 prefix, limits);
//! - [`config_file`]: the same as a TOML file (`proximad --config FILE`);
//! - `service_loop`: [`Daemon`], the node and the threads, started and stopped together;
//! - `control_thread`, `control`: the control service, one request → one reply, against
//!   the scenes; `convert`: wire records to validated domain values, once, at the boundary;
//! - `builder`: the builder thread; `shape_table`: a scene's shape ids, built or not;
//! - `shared_scene`: a scene as the threads share it;
//! - `frame_thread`, `schedule`: which scene's frame is answered next; `frame_loop`: one
//!   scene's frame path through `ingest`, the pipeline and publication;
//! - `wait`, `stop`: how the threads block, and stop together; [`realtime`]: the frame
//!   thread under `SCHED_FIFO`, on request;
//! - [`liveness`]: which client owns each scene, and which scenes outlived their owner;
//! - [`quota`]: what each client process holds, and the most it may;
//! - [`log`]: leveled stderr lines, once per (scene or client, cause);
//! - `gate`: [`Gate`], a test hook that holds builds or control requests;
//! - `error`: start-up and run failures (client mistakes are wire error codes instead).

mod budget_memory;
mod builder;
mod claim;
pub mod config;
pub mod config_file;
mod control;
mod control_thread;
mod convert;
mod error;
mod frame_loop;
mod frame_thread;
mod gate;
mod ingest;
mod lane;
mod lateness;
pub mod liveness;
pub mod log;
pub mod node_counter;
pub mod quota;
pub mod realtime;
pub mod records;
mod schedule;
mod secrets;
mod service_loop;
mod shape_table;
mod shared_scene;
mod stop;
mod wait;

#[cfg(test)]
#[path = "fuzz_tests.rs"]
mod fuzz_tests;

pub use config::DaemonConfig;
pub use convert::Rejection;
pub use error::{DaemonRunError, DaemonStartError};
pub use gate::Gate;
pub use ingest::{FrameRejection, apply_pose_frame};
pub use service_loop::Daemon;
pub use stop::StopHandle;

/// The iceoryx2 service type of the daemon's ports: thread-safe, so the control thread can
/// open a scene's ports and hand them to the frame thread. The same shared memory as
/// `ipc::Service`, which clients use.
type Ipc = iceoryx2::service::ipc_threadsafe::Service;
