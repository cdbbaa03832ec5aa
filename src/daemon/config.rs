//! The daemon's configuration: service names, limits and defaults.

use super::log::Level;
use super::quota::ClientQuota;
use crate::geometry::MeshLimits;
use crate::scene::SceneLimits;
use std::time::Duration;

/// Everything `proximad` can be told at start-up.
#[derive(Debug, Clone, PartialEq)]
pub struct DaemonConfig {
    /// Root prefix of every service name (`<root>/control`, `<root>/<scene>/poses`, …).
    pub root: String,
    /// iceoryx2 file-name prefix (`Config::global.prefix`), so several daemons and test
    /// runs stay apart; `None` = iceoryx2's global configuration.
    pub iceoryx_prefix: Option<String>,
    /// Most scenes alive at once.
    pub max_scenes: u32,
    /// The most one client process may hold: scenes, shapes, bodies and memory (so
    /// one client cannot take what the others need, however many ports it opens).
    pub client_quota: ClientQuota,
    /// Limits of each scene.
    pub scene_limits: SceneLimits,
    /// Limits of each registered mesh.
    pub mesh_limits: MeshLimits,
    /// Most points of a registered convex shape.
    pub max_convex_points: u32,
    /// Most convex and mesh shapes waiting to be built, besides the one being built (of all
    /// clients together); a registration beyond is refused with `LimitExceeded`. Each holds
    /// a copy of its geometry payload.
    pub max_queued_builds: usize,
    /// Memory the shapes and bodies of all scenes may take, bytes, as estimated before
    /// anything is copied, built or added (1,500 B per mesh triangle plus 64 B per mesh
    /// vertex, 1,100 B per convex point, 4,096 B per body: measured upper bounds, see
    /// `budget_memory`); a registration or body beyond is refused with `LimitExceeded`. A
    /// removed body or dropped scene gives its share back.
    pub max_memory_bytes: u64,
    /// Close-pair margin of bodies that do not set one, metres.
    pub default_margin: f64,
    /// How long the frame thread (after its last frame) and the control thread (after its
    /// last request) keep polling before they block on their event listeners (the hybrid
    /// wait: a spin of tens of µs catches the next frame or request without the 60–120 µs
    /// cost of waking a halted vCPU).
    pub spin: Duration,
    /// How often the control thread checks for dead clients and termination signals; it
    /// also bounds each blocking wait of the frame and control threads (how soon they see a
    /// stop).
    pub sweep_interval: Duration,
    /// How long a scene outlives the control client that created it (its process died or
    /// it disconnected) before the daemon drops it; a client port that comes back within it
    /// keeps the scene.
    pub dead_client_grace: Duration,
    /// The least important messages written to stderr.
    pub log_level: Level,
    /// Worker threads answering the mesh–mesh pairs and tree walks of unbudgeted frames
    /// beside the thread that runs the frame (0: it answers everything itself). Default:
    /// one fewer than the cores, at least one.
    pub workers: usize,
    /// `SCHED_FIFO` priority (1–99) of the frame thread, so that no thread under the fair
    /// scheduler takes its CPU mid-frame ([`realtime`](super::realtime)); `None` (the
    /// default): normal priority.
    pub realtime_priority: Option<u8>,
}

impl Default for DaemonConfig {
    fn default() -> Self {
        Self {
            root: proxima_ipc::DEFAULT_ROOT.to_string(),
            iceoryx_prefix: None,
            max_scenes: 64,
            client_quota: ClientQuota::STANDARD,
            scene_limits: SceneLimits::STANDARD,
            mesh_limits: MeshLimits {
                max_vertices: 1 << 22,
                max_triangles: 1 << 22,
            },
            max_convex_points: 1 << 16,
            max_queued_builds: 4,
            max_memory_bytes: 8 << 30,
            default_margin: 0.0,
            spin: Duration::from_micros(50),
            sweep_interval: Duration::from_millis(100),
            dead_client_grace: Duration::from_millis(2000),
            log_level: Level::Info,
            workers: std::thread::available_parallelism()
                .map_or(1, |n| n.get().saturating_sub(1).max(1)),
            realtime_priority: None,
        }
    }
}
