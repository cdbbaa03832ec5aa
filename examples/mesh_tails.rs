//! Mesh–mesh tails (issue #30, deliverable 3): the distribution of one query's time over
//! many poses, not only its mean, Proxima against parry3d-f64 on the same meshes and poses.
//!
//! ```text
//! cargo run --release --example mesh_tails -- [--poses N] [--laps L] [--slowest K]
//! ```
//!
//! # Scenes
//! - `tray-spot distance`: a flat 60-triangle tray (a 0.4 m × 0.3 m grid of 6 × 5 squares,
//!   open, `z = 0`) against Spot (5,856 triangles, `tests/data/spot.obj`, scaled to 0.15 m)
//!   held over it: uniform rotation, its lowest point 0–3 cm above the tray's plane (a
//!   tenth of the poses dip into it), its centre over a uniform point of the tray. The
//!   exact distance, cold (a fresh `DistanceCache` per query, as for a pair seen for the
//!   first time).
//! - `env-rob contacts`: FCL's `env.obj` (2,180 triangles) and `rob.obj` (216) in
//!   millimetres, rob at a uniform rotation and a uniform point of env's bounding box, kept
//!   so that half the poses intersect: every intersecting triangle pair with its contact
//!   (Proxima's `contacts_mesh_mesh` on the OBB trees; parry's `contact_manifolds` with
//!   prediction 0, counting the manifolds that got points).
//!
//! Each pose is timed `L` times (laps over all poses, so caches are as cold for every
//! pose) and its fastest lap kept, which removes the host's preemptions from a single
//! query; the table gives the mean, median, p95, p99 and maximum over the poses, and the
//! `K` slowest poses of Proxima with parry's time on each.

#[path = "../tests/support/mod.rs"]
mod support;

#[path = "../benches/common/parry_convert.rs"]
mod parry_convert;

use clap::Parser;
use parry_convert::{parry_mesh, parry_pose};
use parry3d_f64::math::Pose as ParryPose;
use parry3d_f64::query::{ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher};
use proxima::geometry::TriMesh;
use proxima::math::{DVec3, Pose};
use proxima::narrow::MeshShape;
use proxima::narrow::mesh_mesh::{
    DistanceCache, MeshMeshWorkspace, contacts_mesh_mesh, intersects_mesh_mesh,
};
use rand::Rng;
use std::hint::black_box;
use std::ops::ControlFlow;
use std::time::Instant;
use support::{meshes, rng, rotation};

#[derive(Debug, Parser)]
#[command(about = "Per-pose time distribution of mesh–mesh queries, Proxima and parry")]
struct Args {
    /// Poses per scene.
    #[arg(long, default_value_t = 2000)]
    poses: usize,
    /// Times each pose is timed; its fastest is kept.
    #[arg(long, default_value_t = 3)]
    laps: usize,
    /// Slowest poses of Proxima listed per scene.
    #[arg(long, default_value_t = 5)]
    slowest: usize,
    /// Seed of the poses.
    #[arg(long, default_value_t = 30)]
    seed: u64,
    /// Only query tray-spot pose N, this many times (for a profiler).
    #[arg(long, num_args = 2, value_names = ["POSE", "TIMES"])]
    profile_pose: Option<Vec<usize>>,
}

/// Each pose's fastest time over `laps` laps, µs, and its answer (a distance or a count).
fn fastest_per_pose(
    poses: usize,
    laps: usize,
    mut query: impl FnMut(usize) -> f64,
) -> (Vec<f64>, Vec<f64>) {
    let (mut best, mut answers) = (vec![f64::INFINITY; poses], vec![0.0; poses]);
    for _ in 0..laps {
        for (i, slot) in best.iter_mut().enumerate() {
            let start = Instant::now();
            answers[i] = black_box(query(i));
            *slot = slot.min(start.elapsed().as_secs_f64() * 1e6);
        }
    }
    (best, answers)
}

/// `mean p50 p95 p99 max` of `times`.
fn summary(times: &[f64]) -> [f64; 5] {
    let mut sorted = times.to_vec();
    sorted.sort_by(f64::total_cmp);
    let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
    let mean = sorted.iter().sum::<f64>() / sorted.len() as f64;
    [mean, at(0.5), at(0.95), at(0.99), sorted[sorted.len() - 1]]
}

/// Prints the time table of `proxima` and `parry` (µs per pose) and Proxima's slowest
/// poses with their `answers` (`what`).
fn report(
    scene: &str,
    (proxima, answers): (&[f64], &[f64]),
    parry: &[f64],
    what: &str,
    slowest: usize,
) {
    let (p, q) = (summary(proxima), summary(parry));
    println!("\n{scene}: {} poses, µs", proxima.len());
    println!(
        "{:<8} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "engine", "mean", "p50", "p95", "p99", "max"
    );
    for (name, s) in [("proxima", p), ("parry", q)] {
        println!(
            "{name:<8} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
            s[0], s[1], s[2], s[3], s[4]
        );
    }
    let ratio: Vec<String> = (0..5).map(|i| format!("{:.2}", q[i] / p[i])).collect();
    println!(
        "parry÷proxima: mean {} p50 {} p95 {} p99 {} max {}",
        ratio[0], ratio[1], ratio[2], ratio[3], ratio[4]
    );
    let mut order: Vec<usize> = (0..proxima.len()).collect();
    order.sort_by(|&i, &j| proxima[j].total_cmp(&proxima[i]));
    for &i in order.iter().take(slowest) {
        println!(
            "  slow pose {i:>5}: proxima {:>9.1} µs, parry {:>9.1} µs, {what} {}",
            proxima[i], parry[i], answers[i]
        );
    }
}

/// The tray and Spot, and Spot's poses over it (see the module docs).
fn tray_spot(args: &Args) -> (TriMesh, TriMesh, Vec<Pose>) {
    // A flat open tray: `[-0.2, 0.2] × [-0.15, 0.15]` at `z = 0`, 6 × 5 rectangles (60
    // triangles).
    let tray = meshes::rectangle_grid([0.2, 0.15], [6, 5]);
    let spot = meshes::data_mesh("spot.obj").centered_on_bounds();
    let (low, high) = spot.bounds();
    let size = (high - low).max_element();
    let spot = spot.scaled(0.15 / size);
    let mut rng = rng(args.seed);
    let poses = (0..args.poses)
        .map(|_| {
            let rotation = rotation(&mut rng);
            let lowest = spot
                .vertices()
                .iter()
                .map(|&v| (rotation * v).z)
                .fold(f64::INFINITY, f64::min);
            let gap = if rng.random_bool(0.1) {
                -rng.random_range(0.0..0.02)
            } else {
                rng.random_range(0.0..0.03)
            };
            let over = DVec3::new(
                rng.random_range(-0.2..0.2),
                rng.random_range(-0.15..0.15),
                gap - lowest,
            );
            Pose::new(over, rotation)
        })
        .collect();
    (tray, spot, poses)
}

fn tray_spot_distance(args: &Args) {
    let (tray, spot, poses) = tray_spot(args);
    if let Some(&[pose, times]) = args.profile_pose.as_deref() {
        let (a, b) = (MeshShape::new(tray), MeshShape::new(spot));
        let mut workspace = MeshMeshWorkspace::new();
        let start = Instant::now();
        for _ in 0..times {
            let mut cache = DistanceCache::default();
            black_box(a.distance_to(&b, &poses[pose], &mut cache, &mut workspace));
        }
        println!(
            "pose {pose}: {:.1} µs per query",
            start.elapsed().as_secs_f64() * 1e6 / times as f64
        );
        std::process::exit(0);
    }
    let (parry_a, parry_b) = (parry_mesh(&tray), parry_mesh(&spot));
    let parry_poses: Vec<ParryPose> = poses.iter().map(parry_pose).collect();
    let (a, b) = (MeshShape::new(tray), MeshShape::new(spot));
    let mut workspace = MeshMeshWorkspace::new();
    let mut largest_gap = 0.0_f64;
    for (pose, parry_pose) in poses.iter().zip(&parry_poses) {
        let d = a.distance_to(&b, pose, &mut DistanceCache::default(), &mut workspace);
        let theirs =
            parry3d_f64::query::distance(&ParryPose::IDENTITY, &parry_a, parry_pose, &parry_b)
                .expect("parry supports trimesh distance")
                .distance;
        largest_gap = largest_gap.max((d.distance.max(0.0) - theirs).abs());
    }
    println!("tray-spot: largest |proxima − parry| distance {largest_gap:.2e} m");
    let proxima = fastest_per_pose(poses.len(), args.laps, |i| {
        let mut cache = DistanceCache::default();
        a.distance_to(&b, &poses[i], &mut cache, &mut workspace)
            .distance
    });
    let parry = fastest_per_pose(poses.len(), args.laps, |i| {
        parry3d_f64::query::distance(&ParryPose::IDENTITY, &parry_a, &parry_poses[i], &parry_b)
            .expect("parry supports trimesh distance")
            .distance
    });
    report(
        "tray-spot distance",
        (&proxima.0, &proxima.1),
        &parry.0,
        "distance (m)",
        args.slowest,
    );
}

fn env_rob_contacts(args: &Args) {
    let Some(env) = meshes::shared_data_mesh("mesh_tails env-rob", "env.obj") else {
        return;
    };
    let rob = meshes::data_mesh("rob.obj");
    let (a, b) = (MeshShape::new(env), MeshShape::new(rob));
    let (low, high) = a.mesh.bounds();
    let mut workspace = MeshMeshWorkspace::new();
    let mut rng = rng(args.seed + 1);
    let (mut hits, mut misses, mut poses) = (0, 0, Vec::new());
    while poses.len() < args.poses {
        let at = DVec3::new(
            rng.random_range(low.x..high.x),
            rng.random_range(low.y..high.y),
            rng.random_range(low.z..high.z),
        );
        let pose = Pose::new(at, rotation(&mut rng));
        let hit = intersects_mesh_mesh(&a.overlap_tree, &b.overlap_tree, &pose, &mut workspace);
        let count = if hit { &mut hits } else { &mut misses };
        if *count < args.poses / 2 {
            *count += 1;
            poses.push(pose);
        }
    }
    let (parry_a, parry_b) = (parry_mesh(&a.mesh), parry_mesh(&b.mesh));
    let parry_poses: Vec<ParryPose> = poses.iter().map(parry_pose).collect();
    let count_proxima = |pose: &Pose, workspace: &mut MeshMeshWorkspace| {
        let mut n = 0usize;
        contacts_mesh_mesh(&a.overlap_tree, &b.overlap_tree, pose, workspace, |_| {
            n += 1;
            ControlFlow::<()>::Continue(())
        });
        n
    };
    let dispatcher = DefaultQueryDispatcher;
    let mut manifolds: Vec<ContactManifold<(), ()>> = Vec::new();
    let mut parry_workspace = None;
    // One workspace and manifold list across queries, as `benches/mesh_pair.rs` and a
    // simulation use them (the poses are unrelated, so nothing is reused).
    let mut count_parry = |pose: &ParryPose| {
        dispatcher
            .contact_manifolds(
                pose,
                &parry_a,
                &parry_b,
                0.0,
                &mut manifolds,
                &mut parry_workspace,
            )
            .expect("parry supports trimesh contact manifolds");
        manifolds.iter().filter(|m| !m.points.is_empty()).count()
    };
    let (mut ours, mut theirs) = (0, 0);
    for (pose, parry_pose) in poses.iter().zip(&parry_poses) {
        ours += count_proxima(pose, &mut workspace);
        theirs += count_parry(parry_pose);
    }
    println!(
        "env-rob: {hits} intersecting poses; contacts proxima {ours}, parry manifolds {theirs}"
    );
    let proxima = fastest_per_pose(poses.len(), args.laps, |i| {
        count_proxima(&poses[i], &mut workspace) as f64
    });
    let parry = fastest_per_pose(poses.len(), args.laps, |i| {
        count_parry(&parry_poses[i]) as f64
    });
    report(
        "env-rob contacts",
        (&proxima.0, &proxima.1),
        &parry.0,
        "contacts",
        args.slowest,
    );
}

fn main() {
    let args = Args::parse();
    tray_spot_distance(&args);
    env_rob_contacts(&args);
}
