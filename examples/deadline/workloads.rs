//! The scene classes the bench drives ([`CLASSES`]): how each is built on the daemon and in
//! the in-process mirror the oracle runs, which query its frames ask, and how its bodies
//! move from frame to frame ([`Workload`]).

use crate::coincident_meshes::CoincidentMeshes;
use crate::compound_pile::{compound_parts, compound_pile_scene};
use crate::demo_scene::DemoScene;
use crate::falling::{falling_scene, falling_world};
use crate::pile::{PILE_RATE_HZ, pile_scene, pile_world, primitive_pile_scene};
use crate::point_mass::World;
use crate::robot_chain::RobotChain;
use crate::spec::{BodyPlan, SceneSpec, ShapeSpec};
use crate::sphere_swarm::SphereSwarm;
use glam::{DQuat, DVec3};
use iceoryx2::prelude::ipc;
use proxima::geometry::TriMesh;
use proxima::scene::Scene;
use proxima_ipc::client::{Client, Motion, Primitive};
use proxima_ipc::wire::{PoseRecord, ResultRecord, query};
use std::error::Error;
use std::path::Path;
use std::sync::Arc;

/// A scene's bodies from one frame to the next, as its client moves them.
pub trait Workload {
    /// Number of pose records each frame carries.
    fn pose_count(&self) -> usize;
    /// Pose record `i` of the current frame.
    fn pose(&self, i: usize) -> PoseRecord;
    /// Moves the bodies to the next frame's poses.
    fn advance(&mut self);
    /// Takes the frame's answer: simulations bounce their bodies with the contacts,
    /// kinematic scenes ignore it.
    fn respond(&mut self, _pairs: &[ResultRecord], _contacts: &[ResultRecord]) {}
    /// A word on the scene's state for the table (simulations: how many bodies rest).
    fn state(&self) -> Option<String> {
        None
    }
}

/// A scene built on the daemon, its in-process mirror (body ids equal on both sides) and
/// its motion.
pub struct Built {
    /// The mirror: the same shapes, bodies and margins, for the oracle.
    pub mirror: Scene,
    /// How its bodies move.
    pub workload: Box<dyn Workload>,
}

/// How a class is built: in daemon scene `scene` of the client, with the data folder.
pub type BuildFn = fn(&Client<ipc::Service>, u32, Option<&Path>) -> Result<Built, Box<dyn Error>>;

/// A scene class.
pub struct Class {
    /// Its `--scene` name.
    pub name: &'static str,
    /// What it is, one line.
    pub about: &'static str,
    /// The query of its frames ([`query`] bits).
    pub query_flags: u32,
    /// Frames per budget unless `--frames` says otherwise.
    pub default_frames: usize,
    /// The oracle checks every this many frames (1: all).
    pub check_every: usize,
    /// Builds it in daemon scene `scene`; `data` is the data folder (`None` when absent).
    pub build: BuildFn,
    /// Whether it needs the data folder (FCL's meshes).
    pub needs_data: bool,
}

/// Every class, in the order they run.
pub const CLASSES: [Class; 8] = [
    Class {
        name: "demo",
        about: "proximad demo's scene: 300 bouncing spheres, 4 tumbling tori (768 triangles each), 200 Hz",
        query_flags: query::CLOSE | query::CONTACTS,
        default_frames: 500,
        check_every: 1,
        build: build_demo,
        needs_data: false,
    },
    Class {
        name: "falling",
        about: "falling_bodies' scene: 300 spheres, capsules, boxes and tori (256 triangles) into a bin, 120 Hz",
        query_flags: query::CLOSE | query::CONTACTS,
        default_frames: 500,
        check_every: 1,
        build: build_falling,
        needs_data: false,
    },
    Class {
        name: "pile",
        about: "100 spheres, capsules, boxes, cylinders and hulls of 2-7 cm settling in a box, 240 Hz",
        query_flags: query::CLOSE | query::CONTACTS,
        default_frames: 500,
        check_every: 1,
        build: build_pile,
        needs_data: false,
    },
    Class {
        name: "pile-primitives",
        about: "the pile with spheres, capsules and boxes only (100 bodies, 2-7 cm), 240 Hz",
        query_flags: query::CLOSE | query::CONTACTS,
        default_frames: 500,
        check_every: 1,
        build: build_primitive_pile,
        needs_data: false,
    },
    Class {
        name: "compound-pile",
        about: "50 spots (5,856 triangles) as compounds of their convex decomposition, 7 cm, settling in a box, 240 Hz",
        query_flags: query::CLOSE | query::CONTACTS,
        default_frames: 500,
        check_every: 1,
        build: build_compound_pile,
        needs_data: true,
    },
    Class {
        name: "robot-chain",
        about: "6 links of FCL's rob.obj swinging through env.obj",
        query_flags: query::CLOSE,
        default_frames: 500,
        check_every: 1,
        build: build_robot_chain,
        needs_data: true,
    },
    Class {
        name: "coincident-meshes",
        about: "two 2,000-triangle blobs at nearly the same pose, one moving slightly",
        query_flags: query::CONTACTS,
        default_frames: 200,
        check_every: 1,
        build: build_coincident,
        needs_data: false,
    },
    Class {
        name: "sphere-swarm",
        about: "2,000 spheres overlapping nearly pairwise (~2 million pairs a frame)",
        query_flags: query::CLOSE,
        default_frames: 20,
        check_every: 5,
        build: build_swarm,
        needs_data: false,
    },
];

/// Registers `spec` on the daemon and builds its mirror; checks the ids agree.
fn register(
    client: &Client<ipc::Service>,
    scene: u32,
    spec: &SceneSpec,
) -> Result<(Vec<u32>, Scene), Box<dyn Error>> {
    let ids = spec.register(client, scene)?;
    let mirror = spec.local_scene()?;
    if ids.iter().enumerate().any(|(i, &id)| id as usize != i) {
        return Err("the daemon's body ids are not 0, 1, 2, … in a fresh scene".into());
    }
    Ok((ids, mirror))
}

/// A point-mass simulation at a fixed step.
struct Simulation {
    world: World,
    dt_s: f64,
}

impl Workload for Simulation {
    fn pose_count(&self) -> usize {
        self.world.moving_count()
    }
    fn pose(&self, i: usize) -> PoseRecord {
        self.world.pose(i)
    }
    fn advance(&mut self) {
        self.world.integrate(self.dt_s);
    }
    fn respond(&mut self, pairs: &[ResultRecord], contacts: &[ResultRecord]) {
        self.world.resolve(pairs, contacts);
    }
    fn state(&self) -> Option<String> {
        Some(format!(
            "at rest {}/{}",
            self.world.resting(),
            self.world.moving_count()
        ))
    }
}

/// The demo's own rate, Hz.
const DEMO_RATE_HZ: f64 = 200.0;

impl Workload for DemoScene {
    fn pose_count(&self) -> usize {
        self.body_count()
    }
    fn pose(&self, i: usize) -> PoseRecord {
        DemoScene::pose(self, i)
    }
    fn advance(&mut self) {
        DemoScene::advance(self, 1.0 / DEMO_RATE_HZ);
    }
    fn respond(&mut self, pairs: &[ResultRecord], contacts: &[ResultRecord]) {
        self.bounce(pairs, contacts);
    }
}

fn build_demo(
    client: &Client<ipc::Service>,
    scene: u32,
    _: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    const SPHERES: usize = 300;
    let demo = DemoScene::build(client, scene, SPHERES)?;
    if (0..demo.body_count()).any(|i| DemoScene::pose(&demo, i).body as usize != i) {
        return Err("the demo's body ids are not 0, 1, 2, … in pose order".into());
    }
    let mirror = demo_mirror(&demo, SPHERES).local_scene()?;
    Ok(Built {
        mirror,
        workload: Box::new(demo),
    })
}

/// The demo scene as `src/demo/scene.rs` registers it (its shapes and margins repeated
/// here: the demo lives in the binary, which exports nothing), at its first poses. The
/// bench's first frame of every row compares the daemon's exact answer with this mirror's,
/// so a change to the demo that this copy misses stops the bench.
fn demo_mirror(demo: &DemoScene, spheres: usize) -> SceneSpec {
    let mut spec = SceneSpec::default();
    let torus = spec.add_shape(ShapeSpec::Mesh(Arc::new(TriMesh::torus(0.8, 0.2, 32, 12))));
    let balls = [0.1, 0.15, 0.2]
        .map(|radius| spec.add_shape(ShapeSpec::Primitive(Primitive::Sphere { radius })));
    for i in 0..demo.body_count() {
        let pose = DemoScene::pose(demo, i);
        let [x, y, z, w] = pose.orientation;
        let (shape, margin_m) = if i < spheres {
            (balls[i % balls.len()], 0.05)
        } else {
            (torus, 0.1)
        };
        spec.add_body(BodyPlan {
            shape,
            position: DVec3::from_array(pose.position),
            orientation: DQuat::from_xyzw(x, y, z, w),
            motion: Motion::Kinematic,
            margin_m,
        });
    }
    spec
}

fn build_falling(
    client: &Client<ipc::Service>,
    scene: u32,
    _: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    let spec = falling_scene(300);
    let (ids, mirror) = register(client, scene, &spec)?;
    Ok(Built {
        mirror,
        workload: Box::new(Simulation {
            world: falling_world(&spec, &ids),
            dt_s: 1.0 / 120.0,
        }),
    })
}

/// Seed of the pile the bench drops.
const PILE_SEED: u64 = 29;

fn build_pile(
    client: &Client<ipc::Service>,
    scene: u32,
    _: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    settling_in_the_pile_box(client, scene, &pile_scene(PILE_SEED))
}

fn build_primitive_pile(
    client: &Client<ipc::Service>,
    scene: u32,
    _: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    settling_in_the_pile_box(client, scene, &primitive_pile_scene(PILE_SEED))
}

/// `spec` (a scene in the pile's box) registered, its bodies falling as the pile's do.
fn settling_in_the_pile_box(
    client: &Client<ipc::Service>,
    scene: u32,
    spec: &SceneSpec,
) -> Result<Built, Box<dyn Error>> {
    let (ids, mirror) = register(client, scene, spec)?;
    Ok(Built {
        mirror,
        workload: Box::new(Simulation {
            world: pile_world(spec, &ids, PILE_SEED),
            dt_s: 1.0 / PILE_RATE_HZ,
        }),
    })
}

/// Parts a spot of the compound pile is decomposed into, at most.
const SPOT_PARTS: usize = 16;

/// The spot's decomposition, made once per run (about 20 s) and shared by every row.
static SPOT_PARTS_CACHE: std::sync::OnceLock<Vec<Vec<DVec3>>> = std::sync::OnceLock::new();

fn build_compound_pile(
    client: &Client<ipc::Service>,
    scene: u32,
    data: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    let data = data.ok_or("compound-pile needs the data folder")?;
    let parts = match SPOT_PARTS_CACHE.get() {
        Some(parts) => parts.clone(),
        None => {
            let mesh = TriMesh::load(data.join("meshes").join("spot.obj"))?;
            let (decomposition, parts) = compound_parts(&mesh, SPOT_PARTS)?;
            let diagonal = mesh_diagonal(&mesh);
            println!(
                "compound-pile: spot in {} parts, concavity {:.4} of its {diagonal:.3} m diagonal",
                decomposition.parts.len(),
                decomposition.concavity / diagonal,
            );
            SPOT_PARTS_CACHE.get_or_init(|| parts).clone()
        }
    };
    settling_in_the_pile_box(client, scene, &compound_pile_scene(parts, PILE_SEED))
}

/// The diagonal of a mesh's bounding box, metres.
fn mesh_diagonal(mesh: &TriMesh) -> f64 {
    let (min, max) = mesh.bounds();
    (max - min).length()
}

impl Workload for RobotChain {
    fn pose_count(&self) -> usize {
        self.link_count()
    }
    fn pose(&self, i: usize) -> PoseRecord {
        RobotChain::pose(self, i)
    }
    fn advance(&mut self) {
        RobotChain::advance(self);
    }
}

fn build_robot_chain(
    client: &Client<ipc::Service>,
    scene: u32,
    data: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    let data = data.ok_or("robot-chain needs the data folder")?;
    let (spec, chain) = RobotChain::build(&data.join("meshes"))?;
    let (ids, mirror) = register(client, scene, &spec)?;
    Ok(Built {
        mirror,
        workload: Box::new(chain.with_ids(&ids)),
    })
}

impl Workload for CoincidentMeshes {
    fn pose_count(&self) -> usize {
        1
    }
    fn pose(&self, _: usize) -> PoseRecord {
        CoincidentMeshes::pose(self)
    }
    fn advance(&mut self) {
        CoincidentMeshes::advance(self);
    }
}

fn build_coincident(
    client: &Client<ipc::Service>,
    scene: u32,
    _: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    let (spec, motion) = CoincidentMeshes::build()?;
    let (ids, mirror) = register(client, scene, &spec)?;
    Ok(Built {
        mirror,
        workload: Box::new(motion.with_ids(&ids)),
    })
}

impl Workload for SphereSwarm {
    fn pose_count(&self) -> usize {
        self.sphere_count()
    }
    fn pose(&self, i: usize) -> PoseRecord {
        SphereSwarm::pose(self, i)
    }
    fn advance(&mut self) {
        SphereSwarm::advance(self);
    }
}

/// Seed of the swarm.
const SWARM_SEED: u64 = 2_000;

fn build_swarm(
    client: &Client<ipc::Service>,
    scene: u32,
    _: Option<&Path>,
) -> Result<Built, Box<dyn Error>> {
    let (spec, swarm) = SphereSwarm::build(SWARM_SEED);
    let (ids, mirror) = register(client, scene, &spec)?;
    Ok(Built {
        mirror,
        workload: Box::new(swarm.with_ids(&ids)),
    })
}
