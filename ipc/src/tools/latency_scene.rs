//! The scene every round-trip measurement uses, so figures from different clients compare:
//! `bodies` dynamic spheres on a grid, each moving on a small circle, so every pose changes
//! every frame and no two bodies ever come close (`examples/ipc_latency.rs`, the Rust side
//! of `ipc/python/examples/latency.py` in `ipc/examples/frame_dump.rs`; the Python script
//! builds the same scene).

use std::error::Error;

use iceoryx2::service::Service;

use crate::client::{BodySpec, Client, Motion, Primitive};
use crate::scene_link::SceneLink;
use crate::wire::PoseRecord;

/// Sphere radius, metres.
pub const RADIUS: f64 = 0.5;
/// Grid spacing, metres.
pub const SPACING: f64 = 3.0;
/// Each body's close-pair margin, metres.
pub const MARGIN: f64 = 0.1;

/// Body `i`'s position at time `t` seconds: its grid point plus a circle of 0.3 m radius
/// (never closer than 3 − 2·0.3 − 2·0.5 − 2·0.1 = 1.2 m to a neighbour).
#[must_use]
pub fn grid_position(i: usize, bodies: usize, t: f64) -> [f64; 3] {
    let side = (bodies as f64).cbrt().ceil() as usize;
    let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
    let phase = t * 2.0 + i as f64 * 0.37;
    [
        x as f64 * SPACING + 0.3 * phase.cos(),
        y as f64 * SPACING + 0.3 * phase.sin(),
        z as f64 * SPACING,
    ]
}

/// Body `i`'s pose record at time `t` seconds (body ids are `0..bodies`, as
/// [`add_bodies`] adds them to a new scene).
#[must_use]
pub fn pose(i: usize, bodies: usize, t: f64) -> PoseRecord {
    PoseRecord {
        body: i as u32,
        reserved: 0,
        position: grid_position(i, bodies, t),
        orientation: [0.0, 0.0, 0.0, 1.0],
    }
}

/// Registers the sphere in `scene`, adds `bodies` dynamic spheres at their grid points and
/// opens the scene's link.
///
/// # Errors
/// A control request or the link's services failed.
pub fn add_bodies<S: Service>(
    client: &Client<S>,
    scene: u32,
    bodies: usize,
) -> Result<SceneLink<S>, Box<dyn Error>> {
    let shape = client.register_primitive(scene, Primitive::Sphere { radius: RADIUS })?;
    for i in 0..bodies {
        client.add_body(
            scene,
            &BodySpec {
                shape,
                position: grid_position(i, bodies, 0.0),
                orientation: [0.0, 0.0, 0.0, 1.0],
                motion: Motion::Dynamic,
                group: u32::MAX,
                mask: u32::MAX,
                margin: Some(MARGIN),
            },
        )?;
    }
    Ok(client.open_scene(scene)?)
}
