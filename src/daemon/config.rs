//! The daemon's configuration: service names, limits and defaults.

use crate::geometry::MeshLimits;
use crate::scene::SceneLimits;

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
    /// Limits of each scene.
    pub scene_limits: SceneLimits,
    /// Limits of each registered mesh.
    pub mesh_limits: MeshLimits,
    /// Most points of a registered convex shape.
    pub max_convex_points: u32,
    /// Close-pair margin of bodies that do not set one, metres.
    pub default_margin: f64,
}

impl Default for DaemonConfig {
    fn default() -> Self {
        Self {
            root: proxima_ipc::DEFAULT_ROOT.to_string(),
            iceoryx_prefix: None,
            max_scenes: 64,
            scene_limits: SceneLimits::STANDARD,
            mesh_limits: MeshLimits {
                max_vertices: 1 << 22,
                max_triangles: 1 << 22,
            },
            max_convex_points: 1 << 16,
            default_margin: 0.0,
        }
    }
}
