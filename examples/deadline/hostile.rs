//! The hostile client: a second control connection (a thread of this process with a node
//! of its own) that keeps the daemon's control path busy while the victim's frames run.
//! Round after round it creates a scene of its own, registers the hull of 32,768 points on
//! a sphere and a 1,000,000-triangle mesh (a flat 1,000 × 500 grid of quads, 2 m × 1 m),
//! and drops the scene again (so the daemon's memory stays bounded). DESIGN §8:
//! the frame path never waits for control work, so the victim's deadlines should not move.

use iceoryx2::prelude::ipc;
use proxima_ipc::client::ClientBuilder;
use proxima_ipc::tools::latency::{LatencyRecorder, LatencySummary};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, mpsc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Quads of the grid mesh along X and Y (two triangles each: 1,000,000 triangles).
const GRID_QUADS: (u32, u32) = (1_000, 500);
/// Points of the convex shape.
const CONVEX_POINTS: usize = 32_768;
/// How long one registration may take before the client gives up on it.
const REPLY_TIMEOUT: Duration = Duration::from_secs(300);

/// What the hostile client did.
#[derive(Debug, Clone, Copy)]
pub struct HostileReport {
    /// Rounds begun (each registers one convex, then one mesh).
    pub rounds: u32,
    /// Round trips (request to reply) of the convex registrations that finished.
    pub convex: Option<LatencySummary>,
    /// Round trips of the mesh registrations that finished.
    pub mesh: Option<LatencySummary>,
    /// Requests the daemon refused or that timed out.
    pub failures: u32,
}

/// The running hostile client.
pub struct Hostile {
    stop: Arc<AtomicBool>,
    thread: JoinHandle<Result<HostileReport, String>>,
}

impl Hostile {
    /// Starts the client against the daemon at `root` and iceoryx2 `prefix`, and returns
    /// once it has connected and made its shapes, as it sends its first registration.
    ///
    /// # Errors
    /// It could not connect.
    pub fn start(root: &str, prefix: &str) -> Result<Self, String> {
        let stop = Arc::new(AtomicBool::new(false));
        let (root, prefix, flag) = (root.to_owned(), prefix.to_owned(), Arc::clone(&stop));
        let (ready, started) = mpsc::channel();
        let thread = std::thread::spawn(move || run(&root, &prefix, &flag, &ready));
        let hostile = Self { stop, thread };
        if started.recv_timeout(REPLY_TIMEOUT).is_err() {
            return Err(hostile
                .stop()
                .err()
                .unwrap_or_else(|| "never started".to_owned()));
        }
        Ok(hostile)
    }

    /// Asks the client to stop after its current request and waits for it.
    ///
    /// # Errors
    /// It could not connect, or its thread panicked.
    pub fn stop(self) -> Result<HostileReport, String> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread
            .join()
            .map_err(|_| "the hostile client panicked".to_owned())?
    }
}

fn run(
    root: &str,
    prefix: &str,
    stop: &AtomicBool,
    ready: &mpsc::Sender<()>,
) -> Result<HostileReport, String> {
    let client = ClientBuilder::new()
        .root(root)
        .iceoryx_prefix(prefix)
        .reply_timeout(REPLY_TIMEOUT)
        .connect::<ipc::Service>()
        .map_err(|e| format!("hostile client: {e}"))?;
    let (vertices, triangles) = grid_mesh();
    let points = sphere_points();
    let (mut rounds, mut failures) = (0, 0);
    let mut convex_times = LatencyRecorder::with_capacity(64);
    let mut mesh_times = LatencyRecorder::with_capacity(64);
    // The receiver may have given up waiting: then nobody needs to know.
    let _ = ready.send(());
    while !stop.load(Ordering::Relaxed) {
        rounds += 1;
        let Ok(scene) = client.create_scene() else {
            failures += 1;
            std::thread::sleep(Duration::from_millis(100));
            continue;
        };
        let started = Instant::now();
        match client.register_convex(scene, &points) {
            Ok(_) => convex_times.record(started.elapsed()),
            Err(_) => failures += 1,
        }
        if !stop.load(Ordering::Relaxed) {
            let started = Instant::now();
            match client.register_mesh(scene, &vertices, &triangles) {
                Ok(_) => mesh_times.record(started.elapsed()),
                Err(_) => failures += 1,
            }
        }
        failures += u32::from(client.drop_scene(scene).is_err());
    }
    Ok(HostileReport {
        rounds,
        convex: convex_times.summary(),
        mesh: mesh_times.summary(),
        failures,
    })
}

/// The flat grid: `(X + 1) · (Y + 1)` vertices on z = 0, two triangles per quad.
fn grid_mesh() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let (nx, ny) = GRID_QUADS;
    let step = 2.0 / f64::from(nx);
    let vertices = (0..=ny)
        .flat_map(|j| (0..=nx).map(move |i| [f64::from(i) * step, f64::from(j) * step, 0.0]))
        .collect();
    let at = |i: u32, j: u32| j * (nx + 1) + i;
    let triangles = (0..ny)
        .flat_map(|j| {
            (0..nx).flat_map(move |i| {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                [[a, b, c], [a, c, d]]
            })
        })
        .collect();
    (vertices, triangles)
}

/// Points spread evenly over a sphere of radius 0.5 m (a Fibonacci lattice): every one is
/// a hull vertex.
fn sphere_points() -> Vec<[f64; 3]> {
    crate::support::sphere_directions(CONVEX_POINTS)
        .into_iter()
        .map(|d| (d * 0.5).to_array())
        .collect()
}
