//! Run time against error: one scene, many frames, a list of frame budgets; each budgeted
//! frame is compared with the exact answer of the same poses.
//!
//! ```text
//! cargo run --release --example time_vs_error -- --scene mesh-pile --budgets-us inf,2000,1000,500,200,100,50 --frames 300 --out target/time_vs_error
//! cargo run --release --example time_vs_error -- --list-scenes
//! cargo run --release --example time_vs_error -- --mesh1 a.obj --mesh2 b.obj --budgets-us inf,200 --out DIR
//! ```
//!
//! Each frame the scene's bodies move (the same motion for every budget); the exact answer
//! comes from [`step`] with `DISTANCE` (every candidate's exact distance) on a workspace of
//! its own, in a pass over all frames before the timed rows (`--oracle-inline`: just
//! before each timed frame, as before 2026-11-24, when the oracle's work evicted the timed
//! frame's caches: robot-chain frames with no traversal took 9.7 µs at the median that
//! way and 4.7 µs without it). Each budgeted frame runs
//! [`step_within`] with a [`Deadline`] of the budget from its start (`inf`: [`Unlimited`];
//! `--depths` adds rows with a fixed number of traversal visits instead, [`VisitBudget`]).
//! The query is `CLOSE`: every pair within the sum of its margins, with signed distance and
//! normal.
//!
//! Measured per row against the exact frame:
//! - `missed_collisions`: pairs touching in the exact answer (distance ≤ 0) that the frame
//!   does not report as possibly touching (must be 0: truncated answers are conservative);
//! - `false_positive_pairs`: reported pairs whose exact distance is beyond their margins,
//!   with the largest such exact distance (`false_positive_max_distance`); `precision`: the share of reported pairs that
//!   are truly close;
//! - `dist_abs_err_max` / `dist_rel_err_max`: over pairs both report, `|d − d_exact|` and
//!   that over the smaller body's size; `depth_err_max`: the same over touching pairs;
//! - `normal_err_deg_max`: angle between the reported and exact normals of pairs both
//!   report exactly;
//! - latency of `step_within`: p50, p99, p99.9, max; `deadline_misses`: frames over budget;
//! - `truncated_pairs_per_frame`, and `separated_pairs_per_frame`: mesh pairs answered
//!   "apart" with no traversal, by a separation kept from an earlier frame or by their
//!   convex hulls; `hull_tests_per_frame`: the hull tests run;
//! - `broad_us_mean`, `frontier_us_mean`, `narrow_us_mean`: the frame's stage times
//!   ([`StepReport`]'s `broad_ns`, `mid_ns`, `narrow_ns`), mean µs.
//!
//! `--volume obb|rss|sphere|sphere-medial|sphere-octree` refines every mesh pair with that tree instead
//! of each mesh's measured choice (`auto`), to compare the trees on one scene.
//!
//! `--speed F` moves the bodies along the same paths at `F` times the scene's motion per
//! frame (a faster control loop sees less motion per frame, and kept separations last
//! longer). `--workers N` gives the stepping workspace a pool of `N` worker threads, which
//! the exact rows use for their mesh pairs.
//!
//! Writes `DIR/curve.csv` (one row per scene and budget), `DIR/error_vs_time.svg` (distance
//! error and precision against median frame time) and `DIR/latency.svg` (each budget's
//! latency distribution with its deadline marked), and prints the table. `--order bound`
//! (or `pair`, `largest`) runs the frontier in plain breadth-first rounds instead of its
//! default stages by width, to measure what the order buys.

#[path = "../tests/support/data.rs"]
#[allow(dead_code)]
mod data;

use clap::Parser;
use plotters::prelude::*;
use proxima::bvh::BuildParams;
use proxima::geometry::{Capsule, Cuboid, Sphere, TriMesh};
use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::mesh_mesh::frontier::RoundOrder;
use proxima::narrow::{MeshShape, QueryVolume, Shape};
use proxima::pipeline::{
    Budget, Deadline, FrameResults, PairResult, PipelineWorkspace, Query, StepReport, Unlimited,
    VisitBudget, WorkerPool, step, step_within,
};
use proxima::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits};
use std::collections::BTreeMap;
use std::error::Error;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

#[derive(Debug, Parser)]
#[command(about = "Frame time against error, budget by budget, on one scene")]
struct Args {
    /// Built-in scene (see --list-scenes); ignored with --mesh1/--mesh2.
    #[arg(long, default_value = "mesh-pile")]
    scene: String,
    /// Frame budgets in microseconds, comma-separated; `inf` for the exact run.
    #[arg(long, default_value = "inf,2000,1000,500,200,100,50")]
    budgets_us: String,
    /// Extra rows with a fixed number of traversal visits per frame, comma-separated.
    #[arg(long, default_value = "")]
    depths: String,
    /// Frames per budget.
    #[arg(long, default_value_t = 200)]
    frames: usize,
    /// Output directory for curve.csv and the plots.
    #[arg(long, default_value = "target/time_vs_error")]
    out: PathBuf,
    /// Order of the frontier's entries: `stages` (the default: rounds in stages by width,
    /// cheapest pairs first), `bound` (plain rounds, smallest lower bound first), `pair` or
    /// `largest` (plain rounds by pair, or largest bound first), to measure what the
    /// order buys.
    #[arg(long, default_value = "stages")]
    order: String,
    /// Motion per frame, as a multiple of the scene's own (`0.1`: the same paths at a tenth
    /// of the speed, as a faster control loop sees them).
    #[arg(long, default_value_t = 1.0)]
    speed: f64,
    /// Worker threads beside the stepping thread (0: none): the exact (`inf`) rows answer
    /// their mesh pairs on them too; budgeted frames refine the frontier on the stepping
    /// thread either way.
    #[arg(long, default_value_t = 0)]
    workers: usize,
    /// Compute each frame's exact answer just before the timed frame instead of in a pass
    /// of its own: the oracle's work then evicts the timed frame's caches, a pessimistic
    /// measure for a daemon whose process does other work between frames.
    #[arg(long)]
    oracle_inline: bool,
    /// Print the built-in scenes and exit.
    #[arg(long)]
    list_scenes: bool,
    /// First mesh of a two-mesh scene (OBJ or STL).
    #[arg(long)]
    mesh1: Option<PathBuf>,
    /// Second mesh of a two-mesh scene.
    #[arg(long)]
    mesh2: Option<PathBuf>,
    /// The trees mesh pairs are refined with: `auto` (each mesh's measured choice,
    /// `QueryVolume::measure`), `obb`, `rss`, `sphere` (the tighter of each mesh's two
    /// sphere trees), `sphere-medial` or `sphere-octree`, forced for every mesh.
    #[arg(long, default_value = "auto")]
    volume: String,
}

/// The trees every mesh of the scene is refined with (`--volume`).
#[derive(Debug, Clone, Copy)]
enum VolumeChoice {
    Auto,
    Forced(QueryVolume),
    /// Sphere trees of one construction (`None`: the tighter, as the mesh would keep).
    Spheres(Option<BuildParams>),
}

impl VolumeChoice {
    fn parse(name: &str) -> Result<Self, Box<dyn Error>> {
        Ok(match name {
            "auto" => Self::Auto,
            "obb" => Self::Forced(QueryVolume::Obb),
            "rss" => Self::Forced(QueryVolume::Rss),
            "sphere" => Self::Spheres(None),
            "sphere-medial" => Self::Spheres(Some(BuildParams::MEDIAL_AXIS)),
            "sphere-octree" => Self::Spheres(Some(BuildParams::OCTREE)),
            other => {
                return Err(format!(
                    "--volume {other:?}: auto, obb, rss, sphere, sphere-medial or sphere-octree"
                )
                .into());
            }
        })
    }

    /// The mesh with its trees, refined as chosen; prints the mesh's own measured choice.
    fn shape(self, name: &str, mesh: TriMesh) -> Arc<MeshShape> {
        let mut shape = MeshShape::new(mesh);
        println!(
            "mesh {name}: {} triangles, measured choice {:?}",
            shape.mesh.triangle_count(),
            shape.query_volume
        );
        match self {
            Self::Auto => {}
            Self::Forced(volume) => shape.query_volume = volume,
            Self::Spheres(params) => {
                shape = shape.with_sphere_tree(params.as_ref());
                shape.query_volume = QueryVolume::Sphere;
            }
        }
        Arc::new(shape)
    }
}

/// The built-in scenes.
const SCENES: [(&str, &str); 3] = [
    (
        "mesh-pile",
        "12 tori and 4 mesh spheres (1,024 and 960 triangles) tumbling in a 2.4 m box: many touching and near mesh pairs",
    ),
    (
        "robot-chain",
        "a chain of 6 links of FCL's rob.obj swinging through FCL's env.obj (scaled to metres; needs the data folder, PROXIMA_DATA)",
    ),
    (
        "primitives",
        "150 spheres, capsules and boxes: no meshes, so no BVH; exact while time lasts; the capsule and box pairs left at the deadline get their distance bounds (exact where apart within their margins)",
    ),
];

/// A scene and how its bodies move: `poses(frame)` gives every moving body's pose.
struct Workload {
    name: String,
    scene: Scene,
    movers: Vec<Mover>,
    /// Each body's size (largest extent of its shape's box), metres, by body id.
    sizes: BTreeMap<u32, f64>,
}

/// A body on a smooth periodic path.
struct Mover {
    id: BodyId,
    centre: DVec3,
    amplitude: DVec3,
    phase: f64,
    /// Angular speed of its tumble, rad per frame, about `axis`.
    spin: f64,
    axis: DVec3,
    /// For chain links: the previous link's id and the offset along it.
    parent: Option<(usize, DVec3)>,
}

impl Workload {
    /// Adds a body of `shape` at `pose` and records its size.
    fn add(&mut self, shape: Shape, pose: Pose, motion: Motion, margin: f64) -> BodyId {
        let shape = self.scene.register_shape(shape).expect("a valid shape");
        let body = self
            .scene
            .add_body(&BodyDesc {
                shape,
                pose,
                motion,
                filter: CollisionFilter::ALL,
                margin: Some(margin),
            })
            .expect("room for the body");
        let b = self.scene.body(body).expect("just added").world_bounds;
        self.sizes.insert(body.0, (b.max - b.min).max_element());
        body
    }

    /// Moves every mover to its pose at `frame`.
    /// Places the movers at frame `frame` of motion at `speed` times the scene's own.
    fn pose_at(&mut self, frame: usize, speed: f64) {
        let t = frame as f64 * speed;
        let mut placed: Vec<Pose> = Vec::with_capacity(self.movers.len());
        for m in &self.movers {
            let wobble = DVec3::new(
                (0.013 * t + m.phase).sin(),
                (0.017 * t + 2.0 * m.phase).sin(),
                (0.011 * t + 3.0 * m.phase).cos(),
            );
            let rotation = DQuat::from_axis_angle(m.axis, m.spin * t + m.phase);
            let pose = match m.parent {
                None => Pose::new(m.centre + m.amplitude * wobble, rotation),
                Some((parent, offset)) => {
                    let p = placed[parent];
                    Pose::new(p.position + p.rotation * offset, p.rotation * rotation)
                }
            };
            placed.push(pose);
            self.scene.set_pose(m.id, pose).expect("a live body");
        }
    }
}

fn new_workload(name: &str) -> Workload {
    Workload {
        name: name.to_string(),
        scene: Scene::try_new(0.01, SceneLimits::STANDARD).expect("valid defaults"),
        movers: Vec::new(),
        sizes: BTreeMap::new(),
    }
}

/// A small deterministic generator for layouts (the same scene every run).
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
    fn vector(&mut self, half: f64) -> DVec3 {
        DVec3::new(
            self.range(-half, half),
            self.range(-half, half),
            self.range(-half, half),
        )
    }
}

fn mesh_pile(volume: VolumeChoice) -> Workload {
    let mut w = new_workload("mesh-pile");
    let mut rng = Lcg(7);
    let torus = volume.shape("torus", TriMesh::torus(0.4, 0.12, 32, 16));
    let ball = volume.shape("ball", TriMesh::uv_sphere(0.35, 24, 20));
    for i in 0..16 {
        let shape = if i < 12 {
            Shape::Mesh(Arc::clone(&torus))
        } else {
            Shape::Mesh(Arc::clone(&ball))
        };
        let centre = rng.vector(0.8);
        let id = w.add(shape, Pose::from_translation(centre), Motion::Dynamic, 0.02);
        w.movers.push(Mover {
            id,
            centre,
            amplitude: DVec3::splat(0.35),
            phase: rng.range(0.0, std::f64::consts::TAU),
            spin: rng.range(0.005, 0.02),
            axis: rng.vector(1.0).normalize_or(DVec3::Z),
            parent: None,
        });
    }
    w
}

/// The data folder's `meshes/` (`PROXIMA_DATA`, see `tests/support/data.rs`).
fn meshes_dir() -> Result<PathBuf, Box<dyn Error>> {
    let dir = data::data_dir().ok_or(
        "the robot-chain scene needs the data folder: set PROXIMA_DATA \
         (a folder with meshes/env.obj and meshes/rob.obj)",
    )?;
    Ok(dir.join("meshes"))
}

fn robot_chain(volume: VolumeChoice) -> Result<Workload, Box<dyn Error>> {
    let mut w = new_workload("robot-chain");
    let meshes = meshes_dir()?;
    let env = TriMesh::load(meshes.join("env.obj"))?
        .scaled(0.001)
        .centered_on_bounds();
    let rob = TriMesh::load(meshes.join("rob.obj"))?
        .scaled(0.001)
        .centered_on_bounds();
    let link = volume.shape("rob", rob);
    w.add(
        Shape::Mesh(volume.shape("env", env)),
        Pose::IDENTITY,
        Motion::Static,
        0.02,
    );
    let mut rng = Lcg(11);
    for i in 0..6 {
        let id = w.add(
            Shape::Mesh(Arc::clone(&link)),
            Pose::IDENTITY,
            Motion::Dynamic,
            0.02,
        );
        w.movers.push(Mover {
            id,
            centre: DVec3::new(-1.5, 0.0, 0.2),
            amplitude: DVec3::new(1.2, 1.0, 0.4),
            phase: rng.range(0.0, std::f64::consts::TAU),
            spin: 0.01 * (1.0 + i as f64 * 0.3),
            axis: DVec3::new(0.2, 0.3, 1.0).normalize(),
            parent: (i > 0).then(|| (i - 1, DVec3::new(0.9, 0.0, 0.0))),
        });
    }
    Ok(w)
}

fn primitives() -> Workload {
    let mut w = new_workload("primitives");
    let mut rng = Lcg(5);
    for i in 0..150 {
        let shape = match i % 3 {
            0 => Shape::Sphere(Sphere::new(rng.range(0.1, 0.3))),
            1 => Shape::Capsule(Capsule::new(rng.range(0.1, 0.3), rng.range(0.05, 0.2))),
            _ => Shape::Cuboid(Cuboid::new(rng.vector(0.25).abs() + DVec3::splat(0.05))),
        };
        let centre = rng.vector(2.0);
        let id = w.add(shape, Pose::from_translation(centre), Motion::Dynamic, 0.02);
        w.movers.push(Mover {
            id,
            centre,
            amplitude: DVec3::splat(0.4),
            phase: rng.range(0.0, std::f64::consts::TAU),
            spin: rng.range(0.005, 0.03),
            axis: rng.vector(1.0).normalize_or(DVec3::Z),
            parent: None,
        });
    }
    w
}

fn two_meshes(a: &Path, b: &Path, volume: VolumeChoice) -> Result<Workload, Box<dyn Error>> {
    let mut w = new_workload("two-meshes");
    let (ma, mb) = (
        TriMesh::load(a)?.centered_on_bounds(),
        TriMesh::load(b)?.centered_on_bounds(),
    );
    let size = |m: &TriMesh| {
        let (lo, hi) = m.bounds();
        (hi - lo).max_element()
    };
    let reach = 0.5 * (size(&ma) + size(&mb));
    let margin = 0.01 * reach;
    w.add(
        Shape::Mesh(volume.shape("mesh1", ma)),
        Pose::IDENTITY,
        Motion::Static,
        margin,
    );
    let id = w.add(
        Shape::Mesh(volume.shape("mesh2", mb)),
        Pose::from_translation(DVec3::X * reach),
        Motion::Dynamic,
        margin,
    );
    w.movers.push(Mover {
        id,
        centre: DVec3::ZERO,
        amplitude: DVec3::splat(0.6 * reach),
        phase: 0.3,
        spin: 0.02,
        axis: DVec3::new(1.0, 2.0, 3.0).normalize(),
        parent: None,
    });
    Ok(w)
}

/// One row of the curve.
#[derive(Debug, Default, Clone)]
struct Row {
    budget: String,
    budget_us: Option<f64>,
    frames: usize,
    missed_collisions: usize,
    false_positive_pairs: usize,
    false_positive_max_distance: f64,
    reported: usize,
    truly_close: usize,
    dist_abs_err_max: f64,
    dist_rel_err_max: f64,
    depth_err_max: f64,
    depth_err_rel_max: f64,
    normal_err_deg_max: f64,
    truncated_frames: usize,
    /// Frontier visits and truncated pairs, summed over the frames.
    visits: u64,
    truncated_pairs: u64,
    /// Mesh pairs answered apart with no traversal, summed over frames.
    separated_pairs: u64,
    /// Hull tests, summed over the frames.
    hull_tests: u64,
    /// Stage times of `step_within` (broad phase, budgeted frontier, narrow phase), summed
    /// over frames, nanoseconds.
    stage_ns: [u64; 3],
    latencies_us: Vec<f64>,
    deadline_misses: usize,
}

impl Row {
    fn precision(&self) -> f64 {
        if self.reported == 0 {
            1.0
        } else {
            self.truly_close as f64 / self.reported as f64
        }
    }

    fn percentile(&self, q: f64) -> f64 {
        let mut v = self.latencies_us.clone();
        v.sort_by(f64::total_cmp);
        if v.is_empty() {
            return 0.0;
        }
        let at = ((v.len() as f64 * q).ceil() as usize).clamp(1, v.len());
        v[at - 1]
    }
}

/// The frame's budget kind for one row.
#[derive(Debug, Clone, Copy)]
enum RowBudget {
    Unlimited,
    Time(Duration),
    Visits(u64),
}

fn parse_budgets(args: &Args) -> Result<Vec<(String, RowBudget)>, String> {
    let mut rows = Vec::new();
    for b in args
        .budgets_us
        .split(',')
        .map(str::trim)
        .filter(|b| !b.is_empty())
    {
        if b == "inf" {
            rows.push(("inf".to_string(), RowBudget::Unlimited));
        } else {
            let us: f64 = b
                .parse()
                .map_err(|_| format!("budget {b:?} is not a number of µs"))?;
            rows.push((
                b.to_string(),
                RowBudget::Time(Duration::from_secs_f64(us * 1e-6)),
            ));
        }
    }
    for d in args
        .depths
        .split(',')
        .map(str::trim)
        .filter(|d| !d.is_empty())
    {
        let visits: u64 = d
            .parse()
            .map_err(|_| format!("depth {d:?} is not a visit count"))?;
        rows.push((format!("visits:{visits}"), RowBudget::Visits(visits)));
    }
    Ok(rows)
}

/// Compares one budgeted frame with the exact one, into `row`. `exact` holds the exact
/// distance of every candidate pair (a `DISTANCE` frame); the exact `CLOSE` answer is those
/// within their margins.
fn compare(row: &mut Row, got: &[PairResult], exact: &[PairResult], w: &Workload) {
    let margins = |p: &PairResult| {
        let m = |id: u32| w.scene.body(BodyId(id)).map_or(0.0, |b| b.margin);
        m(p.a) + m(p.b)
    };
    let size = |p: &PairResult| w.sizes[&p.a].min(w.sizes[&p.b]);
    let distance_of: BTreeMap<(u32, u32), f64> =
        exact.iter().map(|p| ((p.a, p.b), p.distance)).collect();
    let exact_of: BTreeMap<(u32, u32), &PairResult> = exact
        .iter()
        .filter(|p| p.distance <= margins(p))
        .map(|p| ((p.a, p.b), p))
        .collect();
    let got_of: BTreeMap<(u32, u32), &PairResult> = got.iter().map(|p| ((p.a, p.b), p)).collect();
    for e in exact_of.values().filter(|e| e.distance <= 0.0) {
        if got_of.get(&(e.a, e.b)).is_none_or(|g| g.distance > 0.0) {
            row.missed_collisions += 1;
        }
    }
    for g in got {
        row.reported += 1;
        match exact_of.get(&(g.a, g.b)) {
            Some(e) => {
                row.truly_close += 1;
                let err = (g.distance - e.distance).abs();
                row.dist_abs_err_max = row.dist_abs_err_max.max(err);
                row.dist_rel_err_max = row.dist_rel_err_max.max(err / size(e));
                if e.distance < 0.0 {
                    row.depth_err_max = row.depth_err_max.max(err);
                    row.depth_err_rel_max = row.depth_err_rel_max.max(err / size(e));
                }
                let (n1, n2) = (g.normal, e.normal);
                if g.exact && n1.length_squared() > 0.0 && n2.length_squared() > 0.0 {
                    let angle = n1.normalize().dot(n2.normalize()).clamp(-1.0, 1.0).acos();
                    row.normal_err_deg_max = row.normal_err_deg_max.max(angle.to_degrees());
                }
            }
            None => {
                // Reported but beyond its margins in truth: a false positive (conservative),
                // and how far apart it really is.
                row.false_positive_pairs += 1;
                let truth = distance_of
                    .get(&(g.a, g.b))
                    .copied()
                    .unwrap_or(f64::INFINITY);
                row.false_positive_max_distance = row.false_positive_max_distance.max(truth);
            }
        }
    }
}

/// Every frame's exact answer: a `DISTANCE` frame on a workspace of its own, for the poses
/// of frames `0..frames`.
fn exact_frames(w: &mut Workload, frames: usize, speed: f64) -> Vec<Vec<PairResult>> {
    let (mut ws, mut exact) = (PipelineWorkspace::default(), FrameResults::default());
    (0..frames)
        .map(|frame| {
            w.pose_at(frame, speed);
            step(&w.scene, Query::DISTANCE, &mut ws, &mut exact);
            w.scene.end_frame();
            exact.pairs.clone()
        })
        .collect()
}

/// Where a row's exact answers come from.
enum Oracle<'a> {
    /// Computed before the rows, one per frame.
    Before(&'a [Vec<PairResult>]),
    /// Computed just before each timed frame.
    Inline,
}

fn run_row(
    w: &mut Workload,
    oracle: &Oracle<'_>,
    (frames, speed): (usize, f64),
    (order, pool): (RoundOrder, Option<&Arc<WorkerPool>>),
    (label, budget): &(String, RowBudget),
) -> Row {
    let mut row = Row {
        budget: label.clone(),
        budget_us: match budget {
            RowBudget::Time(d) => Some(d.as_secs_f64() * 1e6),
            _ => None,
        },
        ..Row::default()
    };
    let mut exact_ws = PipelineWorkspace::default();
    let mut kept_ws = match pool {
        Some(pool) => PipelineWorkspace::with_workers(Arc::clone(pool)),
        None => PipelineWorkspace::default(),
    }
    .with_frontier_order(order);
    let (mut exact, mut got) = (FrameResults::default(), FrameResults::default());
    for frame in 0..frames {
        w.pose_at(frame, speed);
        let exact_pairs = match oracle {
            Oracle::Before(frames) => &frames[frame],
            Oracle::Inline => {
                step(&w.scene, Query::DISTANCE, &mut exact_ws, &mut exact);
                &exact.pairs
            }
        };
        let started = Instant::now();
        let report: StepReport = match *budget {
            RowBudget::Unlimited => step_within(
                &w.scene,
                Query::CLOSE,
                &mut Unlimited,
                &mut kept_ws,
                &mut got,
            ),
            RowBudget::Time(d) => {
                let mut deadline = Deadline(started + d);
                step_within(
                    &w.scene,
                    Query::CLOSE,
                    &mut deadline as &mut dyn Budget,
                    &mut kept_ws,
                    &mut got,
                )
            }
            RowBudget::Visits(v) => step_within(
                &w.scene,
                Query::CLOSE,
                &mut VisitBudget(v),
                &mut kept_ws,
                &mut got,
            ),
        };
        let elapsed = started.elapsed();
        row.latencies_us.push(elapsed.as_secs_f64() * 1e6);
        if let RowBudget::Time(d) = budget
            && elapsed > *d
        {
            row.deadline_misses += 1;
        }
        row.truncated_frames += usize::from(report.truncated_pairs > 0);
        row.visits += report.frontier.visits;
        row.truncated_pairs += u64::from(report.truncated_pairs);
        row.separated_pairs += u64::from(report.separated_pairs);
        row.hull_tests += u64::from(report.hull_tests);
        for (sum, ns) in
            row.stage_ns
                .iter_mut()
                .zip([report.broad_ns, report.mid_ns, report.narrow_ns])
        {
            *sum += ns;
        }
        compare(&mut row, &got.pairs, exact_pairs, w);
        row.frames += 1;
        w.scene.end_frame();
    }
    row
}

fn csv(scene: &str, rows: &[Row]) -> String {
    let mut out = String::from(
        "scene,budget_us,frames,missed_collisions,false_positive_pairs,false_positive_max_distance,precision,dist_abs_err_max,dist_rel_err_max,depth_err_max,depth_err_rel_max,normal_err_deg_max,truncated_frames,truncated_pairs_per_frame,visits_per_frame,latency_p50_us,latency_p99_us,latency_p999_us,latency_max_us,deadline_misses,separated_pairs_per_frame,hull_tests_per_frame,broad_us_mean,frontier_us_mean,narrow_us_mean\n",
    );
    for r in rows {
        let _ = writeln!(
            out,
            "{scene},{},{},{},{},{:e},{:.6},{:e},{:e},{:e},{:e},{:.6},{},{:.2},{:.0},{:.1},{:.1},{:.1},{:.1},{},{:.2},{:.2},{:.2},{:.2},{:.2}",
            r.budget,
            r.frames,
            r.missed_collisions,
            r.false_positive_pairs,
            r.false_positive_max_distance,
            r.precision(),
            r.dist_abs_err_max,
            r.dist_rel_err_max,
            r.depth_err_max,
            r.depth_err_rel_max,
            r.normal_err_deg_max,
            r.truncated_frames,
            r.truncated_pairs as f64 / r.frames.max(1) as f64,
            r.visits as f64 / r.frames.max(1) as f64,
            r.percentile(0.5),
            r.percentile(0.99),
            r.percentile(0.999),
            r.percentile(1.0),
            r.deadline_misses,
            r.separated_pairs as f64 / r.frames.max(1) as f64,
            r.hull_tests as f64 / r.frames.max(1) as f64,
            r.stage_ns[0] as f64 / 1e3 / r.frames.max(1) as f64,
            r.stage_ns[1] as f64 / 1e3 / r.frames.max(1) as f64,
            r.stage_ns[2] as f64 / 1e3 / r.frames.max(1) as f64,
        );
    }
    out
}

fn plot_error_vs_time(path: &Path, scene: &str, rows: &[Row]) -> Result<(), Box<dyn Error>> {
    let points: Vec<(f64, f64, f64)> = rows
        .iter()
        .map(|r| {
            (
                r.percentile(0.5).max(1.0),
                r.dist_abs_err_max.max(1e-9),
                r.precision(),
            )
        })
        .collect();
    let x_max = points.iter().map(|p| p.0).fold(1.0, f64::max) * 1.5;
    let y_max = points.iter().map(|p| p.1).fold(1e-6, f64::max) * 2.0;
    let root = SVGBackend::new(path, (900, 560)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(300);
    let mut chart = ChartBuilder::on(&top)
        .caption(
            format!("{scene}: max distance error against median frame time"),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d((1.0..x_max).log_scale(), (1e-9..y_max).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("median frame time, µs")
        .y_desc("max |d − d_exact|, m")
        .draw()?;
    chart.draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.1)), &BLUE))?;
    chart.draw_series(
        points
            .iter()
            .map(|p| Circle::new((p.0, p.1), 4, BLUE.filled())),
    )?;
    let mut precision = ChartBuilder::on(&bottom)
        .caption("precision of the reported close pairs", ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d((1.0..x_max).log_scale(), 0.0..1.05)?;
    precision
        .configure_mesh()
        .x_desc("median frame time, µs")
        .y_desc("precision")
        .draw()?;
    precision.draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.2)), &RED))?;
    precision.draw_series(
        points
            .iter()
            .map(|p| Circle::new((p.0, p.2), 4, RED.filled())),
    )?;
    root.present()?;
    Ok(())
}

fn plot_latency(path: &Path, scene: &str, rows: &[Row]) -> Result<(), Box<dyn Error>> {
    let x_max = rows
        .iter()
        .map(|r| r.percentile(1.0).max(r.budget_us.unwrap_or(0.0)))
        .fold(1.0, f64::max)
        * 1.2;
    let root = SVGBackend::new(path, (900, 480)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!("{scene}: frame latency distribution (dashed: each budget's deadline)"),
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d((1.0..x_max).log_scale(), 0.0..1.0)?;
    chart
        .configure_mesh()
        .x_desc("frame latency, µs")
        .y_desc("fraction of frames ≤ latency")
        .draw()?;
    for (i, r) in rows.iter().enumerate() {
        let colour = Palette99::pick(i).to_rgba();
        let mut v = r.latencies_us.clone();
        v.sort_by(f64::total_cmp);
        let n = v.len().max(1) as f64;
        chart
            .draw_series(LineSeries::new(
                v.iter()
                    .enumerate()
                    .map(|(k, &x)| (x.max(1.0), (k + 1) as f64 / n)),
                colour,
            ))?
            .label(format!("budget {}", r.budget))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        if let Some(deadline) = r.budget_us {
            chart.draw_series(DashedLineSeries::new(
                [(deadline, 0.0), (deadline, 1.0)],
                6,
                4,
                colour.into(),
            ))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()?;
    root.present()?;
    Ok(())
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    if args.list_scenes {
        for (name, what) in SCENES {
            println!("{name:<12} {what}");
        }
        return Ok(());
    }
    let budgets = parse_budgets(&args)?;
    let order = match args.order.as_str() {
        "stages" => RoundOrder::CheapestPairsFirst,
        "bound" => RoundOrder::SmallestBound,
        "pair" => RoundOrder::Pair,
        "largest" => RoundOrder::LargestBound,
        other => {
            return Err(format!("--order {other:?}: stages, bound, pair or largest").into());
        }
    };
    let volume = VolumeChoice::parse(&args.volume)?;
    let mut workload = match (&args.mesh1, &args.mesh2) {
        (Some(a), Some(b)) => two_meshes(a, b, volume)?,
        (None, None) => match args.scene.as_str() {
            "mesh-pile" => mesh_pile(volume),
            "robot-chain" => robot_chain(volume)?,
            "primitives" => primitives(),
            other => return Err(format!("unknown scene {other:?}: see --list-scenes").into()),
        },
        _ => return Err("--mesh1 and --mesh2 go together".into()),
    };
    std::fs::create_dir_all(&args.out)?;
    let pool = (args.workers > 0).then(|| Arc::new(WorkerPool::new(args.workers)));
    let exact = (!args.oracle_inline).then(|| exact_frames(&mut workload, args.frames, args.speed));
    let oracle = exact.as_deref().map_or(Oracle::Inline, Oracle::Before);
    let mut rows = Vec::new();
    for budget in &budgets {
        rows.push(run_row(
            &mut workload,
            &oracle,
            (args.frames, args.speed),
            (order, pool.as_ref()),
            budget,
        ));
    }
    let exact_p50 = rows
        .iter()
        .find(|r| r.budget == "inf")
        .map(|r| r.percentile(0.5));
    println!(
        "scene {} ({} bodies), {} frames per budget, query CLOSE, frontier order {}",
        workload.name,
        workload.scene.body_count(),
        args.frames,
        args.order
    );
    println!(
        "{:>12} {:>9} {:>7} {:>6} {:>9} {:>11} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>7}",
        "budget µs",
        "of exact",
        "missed",
        "FP",
        "precision",
        "dist err m",
        "depth rel",
        "trunc/fr",
        "sep/fr",
        "p50 µs",
        "p99 µs",
        "p99.9 µs",
        "max µs",
        "misses"
    );
    for r in &rows {
        let share = match (r.budget_us, exact_p50) {
            (Some(b), Some(e)) if e > 0.0 => format!("{:.2}", b / e),
            _ => "-".into(),
        };
        println!(
            "{:>12} {:>9} {:>7} {:>6} {:>9.3} {:>11.3e} {:>10.3e} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>7}",
            r.budget,
            share,
            r.missed_collisions,
            r.false_positive_pairs,
            r.precision(),
            r.dist_abs_err_max,
            r.depth_err_rel_max,
            r.truncated_pairs as f64 / r.frames.max(1) as f64,
            r.separated_pairs as f64 / r.frames.max(1) as f64,
            r.percentile(0.5),
            r.percentile(0.99),
            r.percentile(0.999),
            r.percentile(1.0),
            r.deadline_misses
        );
    }
    std::fs::write(args.out.join("curve.csv"), csv(&workload.name, &rows))?;
    plot_error_vs_time(&args.out.join("error_vs_time.svg"), &workload.name, &rows)?;
    plot_latency(&args.out.join("latency.svg"), &workload.name, &rows)?;
    println!(
        "wrote {}/curve.csv, error_vs_time.svg, latency.svg",
        args.out.display()
    );
    if rows.iter().any(|r| r.missed_collisions > 0) {
        return Err("a budgeted frame missed a collision".into());
    }
    Ok(())
}
