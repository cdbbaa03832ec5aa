//! `ipc/PROTOCOL.md` §7 against the daemon: the limits a client is told are the defaults
//! `proximad` runs with. (The rest of the document is checked in `ipc/tests/protocol_doc.rs`.)

#[path = "../ipc/tests/support/protocol_doc.rs"]
mod protocol_doc;

use proxima::daemon::DaemonConfig;
use proxima::math::tolerance::MAX_COORDINATE;

#[test]
fn the_documented_limits_are_the_daemons_defaults() {
    let limits = protocol_doc::map_under(protocol_doc::document(), "## 7. Limits", 1);
    let config = DaemonConfig::default();
    let coded = [
        ("scenes alive at once", f64::from(config.max_scenes)),
        (
            "scenes alive at once per client process",
            f64::from(config.client_quota.scenes),
        ),
        (
            "shapes per client process (all its scenes)",
            f64::from(config.client_quota.shapes),
        ),
        (
            "bodies per client process (all its scenes)",
            f64::from(config.client_quota.bodies),
        ),
        (
            "memory of shapes and bodies per client process, MiB",
            (config.client_quota.memory_bytes >> 20) as f64,
        ),
        (
            "shapes per scene",
            f64::from(config.scene_limits.max_shapes),
        ),
        (
            "bodies per scene",
            f64::from(config.scene_limits.max_bodies),
        ),
        ("mesh vertices", config.mesh_limits.max_vertices as f64),
        ("mesh triangles", config.mesh_limits.max_triangles as f64),
        ("convex points", f64::from(config.max_convex_points)),
        (
            "queued shape builds (all clients)",
            config.max_queued_builds as f64,
        ),
        (
            "memory of shapes and bodies, MiB (all scenes)",
            (config.max_memory_bytes >> 20) as f64,
        ),
        (
            "candidate pairs answered per frame",
            f64::from(config.scene_limits.max_pairs_per_frame),
        ),
        ("coordinate magnitude", MAX_COORDINATE),
    ];
    assert_eq!(
        limits.len(),
        coded.len(),
        "every documented limit is checked"
    );
    for (name, value) in coded {
        let documented = limits
            .get(name)
            .unwrap_or_else(|| panic!("PROTOCOL.md §7 does not list `{name}`"));
        assert_eq!(protocol_doc::number(documented), value, "{name}");
    }
}
