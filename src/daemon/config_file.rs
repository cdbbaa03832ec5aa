//! `proximad --config FILE`: the daemon's configuration as TOML.
//!
//! Every key is optional; a key that is absent keeps the default, and command-line flags
//! override the file. Unknown keys and out-of-range values are errors naming the key, so a
//! misspelt limit never silently falls back to the default.
//!
//! ```toml
//! root = "proxima"                # service root prefix
//! iceoryx_prefix = "iox2_"        # iceoryx2 file-name prefix (omit: iceoryx2's default)
//! log_level = "info"              # error, warn, info or debug
//!
//! [limits]
//! max_scenes = 64
//! max_scenes_per_client = 16      # what one client process may hold, over all its ports:
//! max_shapes_per_client = 16384   #   scenes, shapes, bodies
//! max_bodies_per_client = 262144
//! max_memory_mib_per_client = 2048  #   and the memory of its shapes and bodies
//! max_shapes_per_scene = 4096
//! max_bodies_per_scene = 100000
//! max_pairs_per_frame = 16384     # candidate pairs a frame answers; more are dropped and counted
//! max_mesh_vertices = 4194304
//! max_mesh_triangles = 4194304
//! max_convex_points = 65536
//! max_queued_builds = 4           # convex and mesh shapes waiting for the builder
//! max_memory_mib = 8192           # memory of all shapes and bodies, estimated up front
//!
//! [scene]
//! default_margin_m = 0.0          # close-pair margin of bodies that set none, metres
//!
//! [service_loop]
//! spin_us = 50                    # polling after the last work before blocking
//! sweep_interval_ms = 100         # dead-client and signal checks, longest blocking wait
//! dead_client_grace_ms = 2000     # a dead client's scenes live this long
//! workers = 1                     # threads answering mesh pairs (default: cores − 1)
//! realtime_priority = 10          # frame thread under SCHED_FIFO at this priority (default: off)
//! ```

use super::config::DaemonConfig;
use super::realtime;
use serde::Deserialize;
use std::fmt;
use std::path::Path;
use std::time::Duration;

/// The parsed file: every key optional.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConfigFile {
    /// Root prefix of every service name.
    pub root: Option<String>,
    /// iceoryx2 file-name prefix.
    pub iceoryx_prefix: Option<String>,
    /// `error`, `warn`, `info` or `debug`.
    pub log_level: Option<String>,
    /// `[limits]`.
    #[serde(default)]
    pub limits: LimitsSection,
    /// `[scene]`.
    #[serde(default)]
    pub scene: SceneSection,
    /// `[service_loop]`.
    #[serde(default)]
    pub service_loop: ServiceLoopSection,
}

/// `[service_loop]`: waiting and dead-client handling.
#[derive(Debug, Clone, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ServiceLoopSection {
    /// Polling after the last piece of work before blocking, microseconds.
    pub spin_us: Option<u64>,
    /// Period of the dead-client and signal checks, milliseconds, `≥ 1`.
    pub sweep_interval_ms: Option<u64>,
    /// How long a dead client's scenes live on, milliseconds.
    pub dead_client_grace_ms: Option<u64>,
    /// Worker threads answering mesh–mesh pairs and tree walks beside the loop (0: none).
    pub workers: Option<usize>,
    /// `SCHED_FIFO` priority of the frame thread, 1–99.
    pub realtime_priority: Option<u8>,
}

/// `[limits]`: what one client may ask of the daemon.
#[derive(Debug, Clone, Default, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSection {
    /// Most scenes alive at once.
    pub max_scenes: Option<u32>,
    /// Most scenes one client process may hold.
    pub max_scenes_per_client: Option<u32>,
    /// Most shapes one client process may hold, over its scenes.
    pub max_shapes_per_client: Option<u32>,
    /// Most live bodies one client process may hold, over its scenes.
    pub max_bodies_per_client: Option<u32>,
    /// Memory of the shapes and bodies one client process may hold, MiB.
    pub max_memory_mib_per_client: Option<u64>,
    /// Most shapes registered in one scene.
    pub max_shapes_per_scene: Option<u32>,
    /// Most live bodies in one scene.
    pub max_bodies_per_scene: Option<u32>,
    /// Most candidate pairs one frame answers.
    pub max_pairs_per_frame: Option<u32>,
    /// Largest vertex count of a registered mesh.
    pub max_mesh_vertices: Option<usize>,
    /// Largest triangle count of a registered mesh.
    pub max_mesh_triangles: Option<usize>,
    /// Most points of a registered convex shape.
    pub max_convex_points: Option<u32>,
    /// Most convex and mesh shapes waiting to be built.
    pub max_queued_builds: Option<usize>,
    /// Memory of all shapes and bodies, MiB.
    pub max_memory_mib: Option<u64>,
}

/// `[scene]`: defaults of every scene.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSection {
    /// Close-pair margin of bodies that set none, metres, finite and `≥ 0`.
    pub default_margin_m: Option<f64>,
}

/// Why a configuration file was refused.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ConfigFileError {
    /// The file could not be read.
    Read(String),
    /// Not valid TOML, an unknown key or a value of the wrong type (toml's message, with
    /// the line).
    Parse(String),
    /// A value outside its range: the key and why.
    Invalid {
        /// The key, dotted (`limits.max_scenes`).
        key: &'static str,
        /// What is wrong with its value.
        reason: String,
    },
}

impl fmt::Display for ConfigFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Read(why) => write!(f, "cannot read the configuration file: {why}"),
            Self::Parse(why) => write!(f, "invalid configuration file: {why}"),
            Self::Invalid { key, reason } => write!(f, "configuration key {key}: {reason}"),
        }
    }
}

impl std::error::Error for ConfigFileError {}

impl ConfigFile {
    /// Parses TOML text.
    ///
    /// # Errors
    /// [`ConfigFileError::Parse`] for bad TOML, unknown keys or wrong types.
    pub fn parse(text: &str) -> Result<Self, ConfigFileError> {
        toml::from_str(text).map_err(|e| ConfigFileError::Parse(e.to_string()))
    }

    /// Reads and parses the file at `path`.
    ///
    /// # Errors
    /// [`ConfigFileError::Read`] or those of [`parse`](Self::parse).
    pub fn load(path: &Path) -> Result<Self, ConfigFileError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ConfigFileError::Read(format!("{}: {e}", path.display())))?;
        Self::parse(&text)
    }

    /// `config` with every key this file sets replaced; `config` is unchanged on error.
    ///
    /// # Errors
    /// [`ConfigFileError::Invalid`] for a value out of range (zero limits, a negative or
    /// non-finite margin, an empty root).
    pub fn apply(&self, config: &DaemonConfig) -> Result<DaemonConfig, ConfigFileError> {
        let mut out = config.clone();
        if let Some(root) = &self.root {
            out.root = non_empty("root", root)?;
        }
        if let Some(prefix) = &self.iceoryx_prefix {
            out.iceoryx_prefix = Some(non_empty("iceoryx_prefix", prefix)?);
        }
        if let Some(level) = &self.log_level {
            out.log_level = level.parse().map_err(|reason| ConfigFileError::Invalid {
                key: "log_level",
                reason,
            })?;
        }
        let l = &self.service_loop;
        if let Some(us) = l.spin_us {
            out.spin = Duration::from_micros(us);
        }
        if let Some(priority) = l.realtime_priority {
            let priority = realtime::checked_priority(priority).map_err(|reason| {
                ConfigFileError::Invalid {
                    key: "service_loop.realtime_priority",
                    reason,
                }
            })?;
            out.realtime_priority = Some(priority);
        }
        let mut sweep_ms = out.sweep_interval.as_millis() as u64;
        set_positive(
            &mut sweep_ms,
            l.sweep_interval_ms,
            "service_loop.sweep_interval_ms",
        )?;
        out.sweep_interval = Duration::from_millis(sweep_ms);
        if let Some(ms) = l.dead_client_grace_ms {
            out.dead_client_grace = Duration::from_millis(ms);
        }
        if let Some(workers) = l.workers {
            out.workers = workers;
        }
        self.limits.apply_to(&mut out)?;
        if let Some(margin) = self.scene.default_margin_m {
            if !(margin.is_finite() && margin >= 0.0) {
                return Err(ConfigFileError::Invalid {
                    key: "scene.default_margin_m",
                    reason: format!("{margin} is not a finite distance ≥ 0"),
                });
            }
            out.default_margin = margin;
        }
        Ok(out)
    }
}

impl LimitsSection {
    /// Sets the limits this section gives in `out`.
    fn apply_to(&self, out: &mut DaemonConfig) -> Result<(), ConfigFileError> {
        let l = self;
        set_positive(&mut out.max_scenes, l.max_scenes, "limits.max_scenes")?;
        let quota = &mut out.client_quota;
        set_positive(
            &mut quota.scenes,
            l.max_scenes_per_client,
            "limits.max_scenes_per_client",
        )?;
        set_positive(
            &mut quota.shapes,
            l.max_shapes_per_client,
            "limits.max_shapes_per_client",
        )?;
        set_positive(
            &mut quota.bodies,
            l.max_bodies_per_client,
            "limits.max_bodies_per_client",
        )?;
        let mut client_mib = quota.memory_bytes >> 20;
        set_positive(
            &mut client_mib,
            l.max_memory_mib_per_client,
            "limits.max_memory_mib_per_client",
        )?;
        quota.memory_bytes = client_mib.saturating_mul(1 << 20);
        set_positive(
            &mut out.scene_limits.max_shapes,
            l.max_shapes_per_scene,
            "limits.max_shapes_per_scene",
        )?;
        set_positive(
            &mut out.scene_limits.max_bodies,
            l.max_bodies_per_scene,
            "limits.max_bodies_per_scene",
        )?;
        set_positive(
            &mut out.scene_limits.max_pairs_per_frame,
            l.max_pairs_per_frame,
            "limits.max_pairs_per_frame",
        )?;
        set_positive(
            &mut out.mesh_limits.max_vertices,
            l.max_mesh_vertices,
            "limits.max_mesh_vertices",
        )?;
        set_positive(
            &mut out.mesh_limits.max_triangles,
            l.max_mesh_triangles,
            "limits.max_mesh_triangles",
        )?;
        set_positive(
            &mut out.max_convex_points,
            l.max_convex_points,
            "limits.max_convex_points",
        )?;
        set_positive(
            &mut out.max_queued_builds,
            l.max_queued_builds,
            "limits.max_queued_builds",
        )?;
        let mut memory_mib = out.max_memory_bytes >> 20;
        set_positive(&mut memory_mib, l.max_memory_mib, "limits.max_memory_mib")?;
        out.max_memory_bytes = memory_mib.saturating_mul(1 << 20);
        Ok(())
    }
}

fn non_empty(key: &'static str, value: &str) -> Result<String, ConfigFileError> {
    if value.is_empty() {
        return Err(ConfigFileError::Invalid {
            key,
            reason: "must not be empty".to_owned(),
        });
    }
    Ok(value.to_owned())
}

/// Sets `target` to `value` when given; zero is refused (a limit of zero serves nothing).
fn set_positive<T: Copy + PartialEq + Default + fmt::Display>(
    target: &mut T,
    value: Option<T>,
    key: &'static str,
) -> Result<(), ConfigFileError> {
    match value {
        Some(v) if v == T::default() => Err(ConfigFileError::Invalid {
            key,
            reason: "must be at least 1".to_owned(),
        }),
        Some(v) => {
            *target = v;
            Ok(())
        }
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_empty_file_keeps_every_default() {
        let file = ConfigFile::parse("").unwrap();
        assert_eq!(
            file.apply(&DaemonConfig::default()).unwrap(),
            DaemonConfig::default()
        );
    }

    #[test]
    fn every_key_reaches_its_field() {
        let file = ConfigFile::parse(
            r#"
            root = "lab"
            iceoryx_prefix = "iox2_lab_"
            log_level = "debug"
            [limits]
            max_scenes = 3
            max_shapes_per_scene = 10
            max_bodies_per_scene = 20
            max_mesh_vertices = 30
            max_mesh_triangles = 40
            max_convex_points = 50
            max_queued_builds = 60
            max_memory_mib = 70
            max_scenes_per_client = 80
            max_shapes_per_client = 81
            max_bodies_per_client = 82
            max_memory_mib_per_client = 83
            [scene]
            default_margin_m = 0.25
            [service_loop]
            spin_us = 7
            sweep_interval_ms = 9
            dead_client_grace_ms = 11
            workers = 13
            realtime_priority = 17
            "#,
        )
        .unwrap();
        let c = file.apply(&DaemonConfig::default()).unwrap();
        assert_eq!(c.root, "lab");
        assert_eq!(c.iceoryx_prefix.as_deref(), Some("iox2_lab_"));
        assert_eq!(c.max_scenes, 3);
        assert_eq!(
            (c.scene_limits.max_shapes, c.scene_limits.max_bodies),
            (10, 20)
        );
        assert_eq!(
            (c.mesh_limits.max_vertices, c.mesh_limits.max_triangles),
            (30, 40)
        );
        assert_eq!((c.max_convex_points, c.default_margin), (50, 0.25));
        assert_eq!(c.max_queued_builds, 60);
        assert_eq!(c.max_memory_bytes, 70 << 20);
        let quota = c.client_quota;
        assert_eq!(
            (quota.scenes, quota.shapes, quota.bodies, quota.memory_bytes),
            (80, 81, 82, 83 << 20)
        );
        assert_eq!(
            (c.log_level, c.workers, c.realtime_priority),
            (super::super::log::Level::Debug, 13, Some(17))
        );
        assert_eq!(
            (c.spin, c.sweep_interval, c.dead_client_grace),
            (
                Duration::from_micros(7),
                Duration::from_millis(9),
                Duration::from_millis(11)
            )
        );
    }

    #[test]
    fn unknown_keys_wrong_types_and_bad_values_are_refused_by_name() {
        let parse_error = |text: &str| match ConfigFile::parse(text) {
            Err(ConfigFileError::Parse(why)) => why,
            other => panic!("{text:?}: expected a parse error, got {other:?}"),
        };
        assert!(parse_error("max_scene = 3").contains("max_scene"));
        assert!(parse_error("[limits]\nmax_scenes = -1").contains("max_scenes"));
        assert!(parse_error("[limits]\nmax_scenes = \"many\"").contains("max_scenes"));
        assert!(parse_error("root = ").contains("line 1"));
        let invalid = |text: &str| {
            ConfigFile::parse(text)
                .unwrap()
                .apply(&DaemonConfig::default())
                .unwrap_err()
        };
        for (text, key) in [
            ("[limits]\nmax_scenes = 0", "limits.max_scenes"),
            (
                "[limits]\nmax_mesh_triangles = 0",
                "limits.max_mesh_triangles",
            ),
            (
                "[limits]\nmax_queued_builds = 0",
                "limits.max_queued_builds",
            ),
            ("[limits]\nmax_memory_mib = 0", "limits.max_memory_mib"),
            ("[scene]\ndefault_margin_m = -0.1", "scene.default_margin_m"),
            ("[scene]\ndefault_margin_m = nan", "scene.default_margin_m"),
            ("[scene]\ndefault_margin_m = inf", "scene.default_margin_m"),
            ("root = \"\"", "root"),
            ("log_level = \"loud\"", "log_level"),
            (
                "[service_loop]\nsweep_interval_ms = 0",
                "service_loop.sweep_interval_ms",
            ),
            (
                "[service_loop]\nrealtime_priority = 0",
                "service_loop.realtime_priority",
            ),
        ] {
            assert!(
                matches!(invalid(text), ConfigFileError::Invalid { key: k, .. } if k == key),
                "{text:?}"
            );
        }
    }

    #[test]
    fn a_missing_file_is_a_read_error_naming_it() {
        let err = ConfigFile::load(Path::new("/nonexistent/proximad.toml")).unwrap_err();
        assert!(matches!(&err, ConfigFileError::Read(why) if why.contains("/nonexistent")));
    }
}
