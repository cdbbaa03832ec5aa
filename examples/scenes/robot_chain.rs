//! Robot chain: six links of FCL's `rob.obj` (216 triangles) in a chain swinging through
//! FCL's `env.obj` (2,180 triangles), both scaled from millimetres to metres: the
//! `robot-chain` scene of `examples/time_vs_error.rs`, with the same paths (the first link
//! wobbles about a point and tumbles, each next one hangs 0.9 m along the previous one's
//! X axis and tumbles on its own), the same seed and margins (2 cm).

use super::spec::{BodyPlan, SceneSpec, ShapeSpec};
use glam::{DQuat, DVec3};
use proxima::geometry::TriMesh;
use proxima_ipc::client::Motion;
use proxima_ipc::wire::PoseRecord;
use std::error::Error;
use std::f64::consts::TAU;
use std::path::Path;
use std::sync::Arc;

/// Links in the chain.
const LINKS: usize = 6;
/// Close-pair margin of every body, metres.
const MARGIN_M: f64 = 0.02;

/// A link's path (see the module docs).
#[derive(Debug, Clone, Copy)]
struct Link {
    centre: DVec3,
    amplitude: DVec3,
    phase: f64,
    /// Angular speed of its tumble about `axis`, rad per frame.
    spin: f64,
    axis: DVec3,
    /// The previous link and the offset along it (all links but the first).
    parent: Option<(usize, DVec3)>,
}

/// The chain's links and their daemon ids; [`RobotChain::pose`] gives each link's pose at
/// the current frame.
#[derive(Debug, Clone)]
pub struct RobotChain {
    links: Vec<Link>,
    ids: Vec<u32>,
    frame: usize,
    poses: Vec<(DVec3, DQuat)>,
}

impl RobotChain {
    /// The scene, from `meshes` (the folder holding `env.obj` and `rob.obj`): the
    /// environment first (static), then the links at their frame-0 poses; and the chain,
    /// whose link ids are to be set by [`with_ids`](Self::with_ids).
    ///
    /// # Errors
    /// A mesh could not be read.
    pub fn build(meshes: &Path) -> Result<(SceneSpec, Self), Box<dyn Error>> {
        let load = |name: &str| -> Result<TriMesh, Box<dyn Error>> {
            Ok(TriMesh::load(meshes.join(name))?
                .scaled(0.001)
                .centered_on_bounds())
        };
        let mut spec = SceneSpec::default();
        let env = spec.add_shape(ShapeSpec::Mesh(Arc::new(load("env.obj")?)));
        let rob = spec.add_shape(ShapeSpec::Mesh(Arc::new(load("rob.obj")?)));
        spec.add_body(plan(env, (DVec3::ZERO, DQuat::IDENTITY), Motion::Static));
        let mut rng = Lcg(11);
        let links = (0..LINKS)
            .map(|i| Link {
                centre: DVec3::new(-1.5, 0.0, 0.2),
                amplitude: DVec3::new(1.2, 1.0, 0.4),
                phase: rng.range(0.0, TAU),
                spin: 0.01 * (1.0 + i as f64 * 0.3),
                axis: DVec3::new(0.2, 0.3, 1.0).normalize(),
                parent: (i > 0).then(|| (i - 1, DVec3::new(0.9, 0.0, 0.0))),
            })
            .collect();
        let mut chain = Self {
            links,
            ids: Vec::new(),
            frame: 0,
            poses: Vec::new(),
        };
        chain.place();
        for &pose in &chain.poses {
            spec.add_body(plan(rob, pose, Motion::Dynamic));
        }
        Ok((spec, chain))
    }

    /// This chain moving the bodies `ids` of its scene (the registered ids, in list order:
    /// the environment first).
    #[must_use]
    pub fn with_ids(mut self, ids: &[u32]) -> Self {
        self.ids = ids[1..].to_vec();
        self
    }

    /// Number of links (the poses each frame carries).
    #[must_use]
    pub fn link_count(&self) -> usize {
        self.links.len()
    }

    /// Link `i`'s pose record at the current frame.
    #[must_use]
    pub fn pose(&self, i: usize) -> PoseRecord {
        let (position, orientation) = self.poses[i];
        PoseRecord {
            body: self.ids[i],
            reserved: 0,
            position: position.to_array(),
            orientation: orientation.to_array(),
        }
    }

    /// Moves every link to the next frame's pose.
    pub fn advance(&mut self) {
        self.frame += 1;
        self.place();
    }

    /// Places the links at `self.frame`.
    fn place(&mut self) {
        let t = self.frame as f64;
        self.poses.clear();
        for link in &self.links {
            let wobble = DVec3::new(
                (0.013 * t + link.phase).sin(),
                (0.017 * t + 2.0 * link.phase).sin(),
                (0.011 * t + 3.0 * link.phase).cos(),
            );
            let rotation = DQuat::from_axis_angle(link.axis, link.spin * t + link.phase);
            let pose = match link.parent {
                None => (link.centre + link.amplitude * wobble, rotation),
                Some((parent, offset)) => {
                    let (position, turn) = self.poses[parent];
                    (position + turn * offset, turn * rotation)
                }
            };
            self.poses.push(pose);
        }
    }
}

fn plan(shape: usize, (position, orientation): (DVec3, DQuat), motion: Motion) -> BodyPlan {
    BodyPlan {
        shape,
        position,
        orientation,
        motion,
        margin_m: MARGIN_M,
    }
}

/// `time_vs_error`'s layout generator, so the paths are the same.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
}
