//! The builder thread: decodes the geometry of registered convex and mesh shapes and builds
//! them (hulls, BVHs, edge adjacency), apart from the frames and from the control requests.
//!
//! The control thread checks a registration's header, hands out the shape id, copies the
//! payload and queues a [`BuildJob`] ([`BuildQueue`], bounded: a full queue refuses the
//! registration with `LimitExceeded`). The builder takes the jobs one at a time, in order,
//! at a lower priority than the frame path (nice +[`BUILDER_NICE`] on Linux), and hands each
//! built shape to its scene under the scene's lock for an O(1) registration
//! ([`PreparedShape`]); a geometry it refuses is recorded as the shape's failure. A build is
//! not interrupted, but a job whose scene was dropped before it started is skipped, and one
//! finished after is thrown away.

use super::convert::{self, GeometryRequest, Rejection};
use super::gate::Gate;
use super::log::{Cause, Level, Logger, Subject};
use super::shared_scene::{SceneCell, lock};
use crate::geometry::MeshLimits;
use crate::scene::PreparedShape;
use crossbeam::channel::{self, Receiver, Sender, TrySendError};
use proxima_ipc::wire::ErrorCode;
use std::panic::AssertUnwindSafe;
use std::sync::{Mutex, Weak};
use std::time::Instant;

/// How much nicer than the frame path the builder thread runs (Linux nice values).
pub const BUILDER_NICE: i32 = 10;

/// One shape to build: its scene, its wire id and its geometry.
#[derive(Debug)]
pub struct BuildJob {
    /// The scene's id (for the log).
    pub scene_id: u32,
    /// The shape's wire id in its [`ShapeTable`](super::shape_table::ShapeTable).
    pub shape: u32,
    /// The scene; gone or dropped means the job is skipped.
    pub scene: Weak<Mutex<SceneCell>>,
    /// What the payload holds, checked against the limits already.
    pub geometry: GeometryRequest,
    /// The request's geometry payload, copied out of shared memory.
    pub payload: Vec<u8>,
}

/// The control thread's end of the build queue.
#[derive(Debug, Clone)]
pub struct BuildQueue {
    jobs: Sender<BuildJob>,
}

impl BuildQueue {
    /// A queue of at most `capacity` jobs waiting (besides the one being built), and its
    /// receiving end for the builder.
    #[must_use]
    pub fn bounded(capacity: usize) -> (Self, Receiver<BuildJob>) {
        let (jobs, receiver) = channel::bounded(capacity);
        (Self { jobs }, receiver)
    }

    /// Whether one more job fits.
    ///
    /// # Errors
    /// [`ErrorCode::LimitExceeded`] when the queue is full.
    pub fn check_room(&self) -> Result<(), Rejection> {
        if self.jobs.is_full() {
            return Err(self.full());
        }
        Ok(())
    }

    /// Queues `job`.
    ///
    /// # Errors
    /// [`ErrorCode::LimitExceeded`] when the queue is full, [`ErrorCode::Internal`] when the
    /// builder is gone (the daemon is stopping).
    pub fn submit(&self, job: BuildJob) -> Result<(), Rejection> {
        self.jobs.try_send(job).map_err(|e| match e {
            TrySendError::Full(_) => self.full(),
            TrySendError::Disconnected(_) => {
                Rejection::new(ErrorCode::Internal, "the shape builder has stopped")
            }
        })
    }

    fn full(&self) -> Rejection {
        Rejection::new(
            ErrorCode::LimitExceeded,
            format!(
                "{} shape builds are queued already; register again once one is built",
                self.jobs.capacity().unwrap_or(0)
            ),
        )
    }
}

/// Starts the builder thread: it builds the jobs of `jobs` (meshes checked against
/// `mesh_limits`), each after passing `gate` (if any), until every [`BuildQueue`] is
/// dropped; it logs at `level`.
///
/// # Errors
/// The operating system could not start the thread.
pub fn spawn(
    jobs: Receiver<BuildJob>,
    mesh_limits: MeshLimits,
    gate: Option<Gate>,
    level: Level,
) -> std::io::Result<std::thread::JoinHandle<()>> {
    std::thread::Builder::new()
        .name("proximad-builder".to_owned())
        .spawn(move || {
            lower_priority();
            let mut log = Logger::new(level);
            for job in jobs {
                if let Some(gate) = &gate {
                    gate.pass();
                }
                build(job, &mesh_limits, &mut log);
            }
        })
}

/// Builds `job`'s shape and hands it (or why it failed) to its scene, unless the scene is
/// gone or dropped.
pub fn build(job: BuildJob, mesh_limits: &MeshLimits, log: &mut Logger) {
    if job.scene.upgrade().is_none_or(|scene| lock(&scene).dropped) {
        return;
    }
    let started = Instant::now();
    let BuildJob {
        scene_id,
        shape,
        geometry,
        payload,
        ..
    } = job;
    // A panic in the geometry code is a daemon bug: the shape fails, the daemon goes on.
    let built = std::panic::catch_unwind(AssertUnwindSafe(|| {
        convert::geometry_shape(geometry, &payload, mesh_limits).map(PreparedShape::new)
    }))
    .unwrap_or_else(|_| {
        Err(Rejection::new(
            ErrorCode::Internal,
            "building the shape failed inside the daemon",
        ))
    });
    drop(payload);
    match &built {
        Ok(_) => log.debug(format_args!(
            "scene {scene_id}: shape {shape} built in {:?}",
            started.elapsed()
        )),
        Err(refused) => log.once(
            Level::Warn,
            Subject::Scene(scene_id),
            Cause {
                what: "refused shape geometry",
                code: refused.code as u32,
            },
            || format!("shape {shape} refused: {}", refused.reason),
        ),
    }
    let Some(scene) = job.scene.upgrade() else {
        return;
    };
    let mut cell = lock(&scene);
    if cell.dropped {
        return;
    }
    let outcome = built.and_then(|prepared| {
        cell.scene
            .register_prepared(prepared)
            .map_err(|e| Rejection::new(ErrorCode::LimitExceeded, e.to_string()))
    });
    cell.shapes.finish(shape, outcome);
}

/// Lowers the calling thread's priority by [`BUILDER_NICE`] (Linux: nice values are per
/// thread); elsewhere nothing.
fn lower_priority() {
    #[cfg(target_os = "linux")]
    // SAFETY: `gettid` and `setpriority` on the calling thread's own id change only that
    // thread's nice value; no memory is read or written. A failure leaves the priority as it
    // was, which is harmless.
    unsafe {
        let tid = libc::gettid();
        libc::setpriority(libc::PRIO_PROCESS, tid as libc::id_t, BUILDER_NICE);
    }
}
