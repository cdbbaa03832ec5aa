//! The demo's embedded scene and its motion: a gas of spheres bouncing in a box off the
//! walls and off each other (using the contacts the daemon returns), and four tori tumbling
//! on circles through the box's centre so that they meet and interlock.
//!
//! The client integrates the motion itself, as a simulation would: the daemon only answers
//! which bodies are close and where they touch. Spheres bounce off each other and off the
//! tori (sphere–mesh contacts through the tori's BVHs); the tori follow their paths.

use glam::{DQuat, DVec3};
use proxima::geometry::TriMesh;
use proxima_ipc::client::{BodySpec, Client, Motion, Primitive};
use proxima_ipc::error::ControlError;
use proxima_ipc::wire::{PoseRecord, ResultRecord};
use std::f64::consts::TAU;

/// Half the side of the box the spheres bounce in, metres.
const BOX_HALF: f64 = 3.0;
/// Close-pair margins, metres.
const SPHERE_MARGIN: f64 = 0.05;
const TORUS_MARGIN: f64 = 0.1;
/// Collision groups: everything pairs with everything.
const SPHERES: u32 = u32::MAX;
const TORI: u32 = u32::MAX;
/// Tori: tube centre-line radius, tube radius (metres), path radius (metres), count.
const TORUS_MAJOR: f64 = 0.8;
const TORUS_MINOR: f64 = 0.2;
const TORUS_PATH: f64 = 1.2;
const TORI_COUNT: usize = 4;

/// A body the client moves.
#[derive(Debug, Clone, Copy)]
struct Moving {
    id: u32,
    position: DVec3,
    orientation: DQuat,
    velocity: DVec3,
    radius: f64,
}

/// The demo scene: its bodies' ids and the state the client integrates.
#[derive(Debug)]
pub struct DemoScene {
    spheres: Vec<Moving>,
    tori: Vec<Moving>,
    /// Body id → index into `spheres` (`usize::MAX` for tori).
    sphere_of_body: Vec<usize>,
    time: f64,
}

impl DemoScene {
    /// Registers the shapes and adds `sphere_count` spheres and the tori to `scene`.
    /// Positions and velocities come from a fixed-seed generator: every run is the same.
    ///
    /// # Errors
    /// The daemon refused a request.
    pub fn build(
        client: &Client<iceoryx2::prelude::ipc::Service>,
        scene: u32,
        sphere_count: usize,
    ) -> Result<Self, ControlError> {
        let torus = TriMesh::torus(TORUS_MAJOR, TORUS_MINOR, 32, 12);
        let vertices: Vec<[f64; 3]> = torus.vertices().iter().map(|v| v.to_array()).collect();
        let torus_shape = client.register_mesh(scene, &vertices, torus.triangles())?;
        let radii = [0.1, 0.15, 0.2];
        let mut sphere_shapes = Vec::new();
        for radius in radii {
            sphere_shapes.push(client.register_primitive(scene, Primitive::Sphere { radius })?);
        }
        let mut random = SplitMix(0x5eed);
        let mut demo = Self {
            spheres: Vec::with_capacity(sphere_count),
            tori: Vec::with_capacity(TORI_COUNT),
            sphere_of_body: Vec::new(),
            time: 0.0,
        };
        for i in 0..sphere_count {
            let kind = i % radii.len();
            let radius = radii[kind];
            let reach = BOX_HALF - radius;
            let position = DVec3::new(
                random.between(-reach, reach),
                random.between(-reach, reach),
                random.between(-reach, reach),
            );
            let velocity = DVec3::new(
                random.between(-1.0, 1.0),
                random.between(-1.0, 1.0),
                random.between(-1.0, 1.0),
            ) * 1.5;
            let id = client.add_body(
                scene,
                &spec(
                    sphere_shapes[kind],
                    position,
                    DQuat::IDENTITY,
                    SPHERES,
                    SPHERE_MARGIN,
                ),
            )?;
            demo.note_sphere(id, demo.spheres.len());
            demo.spheres.push(Moving {
                id,
                position,
                orientation: DQuat::IDENTITY,
                velocity,
                radius,
            });
        }
        for k in 0..TORI_COUNT {
            let (position, orientation) = torus_pose(k, 0.0);
            let id = client.add_body(
                scene,
                &spec(torus_shape, position, orientation, TORI, TORUS_MARGIN),
            )?;
            demo.tori.push(Moving {
                id,
                position,
                orientation,
                velocity: DVec3::ZERO,
                radius: TORUS_MAJOR + TORUS_MINOR,
            });
        }
        Ok(demo)
    }

    fn note_sphere(&mut self, body: u32, index: usize) {
        let body = body as usize;
        if self.sphere_of_body.len() <= body {
            self.sphere_of_body.resize(body + 1, usize::MAX);
        }
        self.sphere_of_body[body] = index;
    }

    /// Number of bodies whose poses each frame carries.
    #[must_use]
    pub fn body_count(&self) -> usize {
        self.spheres.len() + self.tori.len()
    }

    /// The pose record of moving body `i` (spheres first, then tori).
    #[must_use]
    pub fn pose(&self, i: usize) -> PoseRecord {
        let body = if i < self.spheres.len() {
            &self.spheres[i]
        } else {
            &self.tori[i - self.spheres.len()]
        };
        PoseRecord {
            body: body.id,
            reserved: 0,
            position: body.position.to_array(),
            orientation: body.orientation.to_array(),
        }
    }

    /// Advances the motion by `dt` seconds: spheres fly straight and bounce off the walls,
    /// tori follow their paths.
    pub fn advance(&mut self, dt: f64) {
        self.time += dt;
        for s in &mut self.spheres {
            s.position += s.velocity * dt;
            let reach = BOX_HALF - s.radius;
            for axis in 0..3 {
                if s.position[axis].abs() > reach {
                    s.position[axis] = s.position[axis].clamp(-reach, reach);
                    s.velocity[axis] = -s.velocity[axis];
                }
            }
        }
        for (k, t) in self.tori.iter_mut().enumerate() {
            (t.position, t.orientation) = torus_pose(k, self.time);
        }
    }

    /// Bounces what the contact records say touch: two spheres approaching each other
    /// collide elastically (equal masses) along the contact normal (A→B) and are pushed
    /// apart by half the depth each; a sphere approaching a torus is reflected off it (the
    /// torus, moved by its path, is immovable) and pushed out by the depth. Returns how many
    /// pairs bounced. Each pair acts once, at its deepest contact.
    pub fn bounce(&mut self, pairs: &[ResultRecord], contacts: &[ResultRecord]) -> usize {
        let mut bounced = 0;
        for pair in pairs {
            let first = (pair.index as usize).min(contacts.len());
            let end = (first + pair.count as usize).min(contacts.len());
            let Some(c) = contacts[first..end]
                .iter()
                .min_by(|x, y| x.distance.total_cmp(&y.distance))
            else {
                continue;
            };
            let sphere = |body: u32| {
                self.sphere_of_body
                    .get(body as usize)
                    .copied()
                    .filter(|&i| i != usize::MAX)
            };
            let n = DVec3::from_array(c.normal);
            let depth = (-c.distance).max(0.0);
            match (sphere(c.body_a), sphere(c.body_b)) {
                (Some(i), Some(j)) => {
                    let approach = (self.spheres[i].velocity - self.spheres[j].velocity).dot(n);
                    self.spheres[i].position -= n * (depth / 2.0);
                    self.spheres[j].position += n * (depth / 2.0);
                    if approach > 0.0 {
                        self.spheres[i].velocity -= n * approach;
                        self.spheres[j].velocity += n * approach;
                        bounced += 1;
                    }
                }
                // One sphere and a torus: `out` points from the torus to the sphere.
                (Some(i), None) | (None, Some(i)) => {
                    let out = if sphere(c.body_b) == Some(i) { n } else { -n };
                    let s = &mut self.spheres[i];
                    s.position += out * depth;
                    let into = s.velocity.dot(out);
                    if into < 0.0 {
                        s.velocity -= out * (2.0 * into);
                        bounced += 1;
                    }
                }
                (None, None) => {}
            }
        }
        bounced
    }
}

/// Torus `k`'s pose at time `t`: its centre on a circle of radius [`TORUS_PATH`] about the
/// box centre (a quarter turn apart, one revolution per 8 s), tumbling about a tilted axis.
fn torus_pose(k: usize, t: f64) -> (DVec3, DQuat) {
    let phase = TAU * (k as f64 / TORI_COUNT as f64 + t / 8.0);
    let position = DVec3::new(phase.cos(), phase.sin(), 0.3 * (2.0 * phase).sin()) * TORUS_PATH;
    let axis = DVec3::new(1.0, k as f64 * 0.5, 0.3).normalize();
    (position, DQuat::from_axis_angle(axis, 0.9 * t + k as f64))
}

fn spec(shape: u32, position: DVec3, orientation: DQuat, group: u32, margin: f64) -> BodySpec {
    BodySpec {
        shape,
        position: position.to_array(),
        orientation: orientation.to_array(),
        motion: Motion::Kinematic,
        group,
        mask: group,
        margin: Some(margin),
    }
}

/// SplitMix64: a tiny fixed-seed generator, so the demo is the same on every run without
/// pulling a random-number crate into the daemon binary.
struct SplitMix(u64);

impl SplitMix {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[low, high)`.
    fn between(&mut self, low: f64, high: f64) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        low + (high - low) * unit
    }
}
