//! Sphere swarm: [`SWARM_SPHERES`] spheres of radius 5 cm whose centres wander inside an
//! 8 cm cube, so nearly every pair overlaps (about two million pairs a frame): the most
//! mandatory work a frame of small bodies can carry. Each frame every centre takes a random
//! step of up to 1 mm per axis, reflected at the cube's faces.

use super::spec::{BodyPlan, SceneSpec, ShapeSpec};
use glam::{DQuat, DVec3};
use proxima_ipc::client::{Motion, Primitive};
use proxima_ipc::wire::PoseRecord;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Spheres in the swarm.
pub const SWARM_SPHERES: usize = 2_000;
/// Sphere radius, metres.
const RADIUS_M: f64 = 0.05;
/// Half the side of the cube the centres stay in, metres.
const CUBE_HALF_M: f64 = 0.04;
/// Largest step per axis and frame, metres.
const STEP_M: f64 = 0.001;
/// Close-pair margin of every sphere, metres.
const MARGIN_M: f64 = 0.005;

/// The spheres' centres, their daemon ids and the generator of their steps.
#[derive(Debug, Clone)]
pub struct SphereSwarm {
    centres: Vec<DVec3>,
    ids: Vec<u32>,
    rng: Pcg64Mcg,
}

impl SphereSwarm {
    /// The scene and its motion (same `seed`, same swarm), whose ids are to be set by
    /// [`with_ids`](Self::with_ids).
    #[must_use]
    pub fn build(seed: u64) -> (SceneSpec, Self) {
        let mut rng = Pcg64Mcg::seed_from_u64(seed);
        let mut spec = SceneSpec::default();
        let ball = spec.add_shape(ShapeSpec::Primitive(Primitive::Sphere { radius: RADIUS_M }));
        let centres: Vec<DVec3> = (0..SWARM_SPHERES)
            .map(|_| {
                DVec3::new(
                    rng.random_range(-CUBE_HALF_M..CUBE_HALF_M),
                    rng.random_range(-CUBE_HALF_M..CUBE_HALF_M),
                    rng.random_range(-CUBE_HALF_M..CUBE_HALF_M),
                )
            })
            .collect();
        for &position in &centres {
            spec.add_body(BodyPlan {
                shape: ball,
                position,
                orientation: DQuat::IDENTITY,
                motion: Motion::Kinematic,
                margin_m: MARGIN_M,
            });
        }
        let swarm = Self {
            centres,
            ids: Vec::new(),
            rng,
        };
        (spec, swarm)
    }

    /// This swarm moving the bodies `ids` (the registered ids, in list order).
    #[must_use]
    pub fn with_ids(mut self, ids: &[u32]) -> Self {
        self.ids = ids.to_vec();
        self
    }

    /// Number of spheres (the poses each frame carries).
    #[must_use]
    pub fn sphere_count(&self) -> usize {
        self.centres.len()
    }

    /// Sphere `i`'s pose record.
    #[must_use]
    pub fn pose(&self, i: usize) -> PoseRecord {
        PoseRecord {
            body: self.ids[i],
            reserved: 0,
            position: self.centres[i].to_array(),
            orientation: DQuat::IDENTITY.to_array(),
        }
    }

    /// Every centre takes its random step.
    pub fn advance(&mut self) {
        for c in &mut self.centres {
            for axis in 0..3 {
                let mut x = c[axis] + self.rng.random_range(-STEP_M..STEP_M);
                if x.abs() > CUBE_HALF_M {
                    x = x.signum() * (2.0 * CUBE_HALF_M - x.abs());
                }
                c[axis] = x;
            }
        }
    }
}
