//! Benchmarks one mesh pair the way FCL's own mesh-pair test does (issue #3).
//!
//! ```text
//! cargo run --release --example pair_queries -- MESH1.obj MESH2.obj TRANSFORMS.txt \
//!     [--scale1 S] [--scale2 S] [--center] [--dump DIR] [--repeats K]
//!     [--collide-bv obb] [--distance-bv rss] [--build sah] [--leaf-size 2]
//! ```
//!
//! Mesh 1 takes each transform of TRANSFORMS.txt (`#` comment lines, then the count N, then
//! N lines of a row-major 3×3 rotation and a translation); mesh 2 stays at identity.
//! `--scale1/--scale2` multiply a mesh's vertices; `--center` then moves each mesh's
//! bounding-box centre to the origin. BVHs are built once, outside the timing: by default
//! as the daemon builds them ([`MESH_TREE_PARAMS`]: binned SAH, up to two triangles a leaf),
//! OBBs for the collision queries and RSSs for distance (the fastest combination measured;
//! other volume types, builders and leaf sizes by option). Per transform, each query runs
//! twice to warm up and is then timed over K runs (default 5); its time is the mean of
//! those runs.
//!
//! stdout: one TSV row per query, `query n mean_us median_us p95_us max_us colliding tri_pairs
//! mean_dist`. `distance` starts every run cold (a fresh cache); `distance_warm` keeps the
//! pair's cache between runs, as a simulation querying the same pair every frame would.
//! `--dump DIR` writes `DIR/proxima.tsv`: `i collide_bool collide_all contacts tri_pairs distance`,
//! and `DIR/proxima_times.tsv`: each pose's µs per query (`i collide_bool_us collide_all_us
//! distance_us`), to find the poses behind a mean.

use proxima::bounding::{Aabb, BoundingSphere, BoundingVolume, Kdop18, Lss, Obb, Rss};
use proxima::bvh::{BuildParams, Bvh};
use proxima::geometry::TriMesh;
use proxima::math::{DMat3, DQuat, DVec3, Pose};
use proxima::narrow::MESH_TREE_PARAMS;
use proxima::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshMeshWorkspace, contacts_mesh_mesh, distance_mesh_mesh,
    intersects_mesh_mesh,
};
use std::error::Error;
use std::fmt::Write as _;
use std::hint::black_box;
use std::ops::ControlFlow;
use std::time::Instant;

const WARM_UP_RUNS: usize = 2;

struct Args {
    meshes: [String; 2],
    transforms: String,
    scales: [f64; 2],
    center: bool,
    dump: Option<String>,
    repeats: usize,
    /// Volume types of the collision trees and of the distance trees.
    volumes: [String; 2],
    build: BuildParams,
}

fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut positional = Vec::new();
    let (mut scales, mut center, mut dump, mut repeats) = ([1.0, 1.0], false, None, 5);
    let mut volumes = ["obb".to_string(), "rss".to_string()];
    let (mut build, mut leaf_size) = (MESH_TREE_PARAMS, MESH_TREE_PARAMS.leaf_size);
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{arg} needs a value"));
        match arg.as_str() {
            "--scale1" => scales[0] = value()?.parse()?,
            "--scale2" => scales[1] = value()?.parse()?,
            "--center" => center = true,
            "--dump" => dump = Some(value()?),
            "--repeats" => repeats = value()?.parse::<usize>()?.max(1),
            "--collide-bv" => volumes[0] = value()?,
            "--distance-bv" => volumes[1] = value()?,
            "--build" => {
                build = match value()?.as_str() {
                    "sah" => BuildParams::BINNED_SAH,
                    "mean" => BuildParams::MEAN_VARIANCE,
                    "median" => BuildParams::MEDIAN,
                    "agglomerative" => BuildParams::AGGLOMERATIVE,
                    other => {
                        return Err(format!(
                            "unknown builder {other} (sah, mean, median, agglomerative)"
                        )
                        .into());
                    }
                }
            }
            "--leaf-size" => leaf_size = value()?.parse()?,
            _ if arg.starts_with("--") => return Err(format!("unknown option {arg}").into()),
            _ => positional.push(arg),
        }
    }
    let [m1, m2, transforms]: [String; 3] = positional
        .try_into()
        .map_err(|_| "usage: pair_queries MESH1 MESH2 TRANSFORMS [--scale1 S] [--scale2 S] [--center] [--dump DIR]")?;
    Ok(Args {
        meshes: [m1, m2],
        transforms,
        scales,
        center,
        dump,
        repeats,
        volumes,
        build: build.with_leaf_size(leaf_size),
    })
}

/// Reads the transforms file: the pose of mesh 1 for each line.
fn read_transforms(path: &str) -> Result<Vec<Pose>, Box<dyn Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with('#'));
    let count: usize = lines.next().ok_or("empty transforms file")?.parse()?;
    let poses = lines
        .take(count)
        .map(|line| {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(str::parse)
                .collect::<Result<_, _>>()?;
            let [r @ .., tx, ty, tz]: [f64; 12] =
                v.try_into().map_err(|_| "a transform needs 12 numbers")?;
            let rotation = DMat3::from_cols_array(&r).transpose(); // row-major in the file
            Ok(Pose::try_new(
                DVec3::new(tx, ty, tz),
                DQuat::from_mat3(&rotation).normalize(),
            )?)
        })
        .collect::<Result<Vec<_>, Box<dyn Error>>>()?;
    if poses.len() != count {
        return Err(format!("expected {count} transforms, found {}", poses.len()).into());
    }
    Ok(poses)
}

fn load(path: &str, scale: f64, center: bool) -> Result<TriMesh, Box<dyn Error>> {
    let mesh = TriMesh::load(path)?.scaled(scale);
    Ok(if center {
        mesh.centered_on_bounds()
    } else {
        mesh
    })
}

/// Mean time of `repeats` runs of `query`, microseconds, after a warm-up.
fn time_us<T>(repeats: usize, mut query: impl FnMut() -> T) -> (f64, T) {
    for _ in 0..WARM_UP_RUNS {
        black_box(query());
    }
    let start = Instant::now();
    for _ in 1..repeats {
        black_box(query());
    }
    let last = query();
    (start.elapsed().as_secs_f64() * 1e6 / repeats as f64, last)
}

fn summary(
    name: &str,
    mut times: Vec<f64>,
    colliding: usize,
    pairs: String,
    dist: String,
) -> String {
    times.sort_by(f64::total_cmp);
    let n = times.len();
    let mean = times.iter().sum::<f64>() / n as f64;
    let median = if n % 2 == 1 {
        times[n / 2]
    } else {
        0.5 * (times[n / 2 - 1] + times[n / 2])
    };
    let p95 = times[((0.95 * n as f64).ceil() as usize).clamp(1, n) - 1];
    format!(
        "{name}\t{n}\t{mean:.2}\t{median:.2}\t{p95:.2}\t{:.2}\t{colliding}\t{pairs}\t{dist}",
        times[n - 1]
    )
}

/// Per-pose results of the two collision queries.
#[derive(Default)]
struct CollideRuns {
    time_bool: Vec<f64>,
    time_all: Vec<f64>,
    hit: Vec<bool>,
    pairs: Vec<usize>,
}

fn collide_runs<C: BoundingVolume>(
    meshes: [&TriMesh; 2],
    build: &BuildParams,
    poses: &[Pose],
    repeats: usize,
) -> CollideRuns {
    let (a, b) = (
        Bvh::<C>::from_mesh(meshes[0], build),
        Bvh::<C>::from_mesh(meshes[1], build),
    );
    let mut ws = MeshMeshWorkspace::new();
    let mut runs = CollideRuns::default();
    for pose_ab in poses {
        let (t, hit) = time_us(repeats, || intersects_mesh_mesh(&a, &b, pose_ab, &mut ws));
        runs.time_bool.push(t);
        runs.hit.push(hit);
        let (t, pairs) = time_us(repeats, || {
            let mut count = 0usize;
            contacts_mesh_mesh(&a, &b, pose_ab, &mut ws, |_| {
                count += 1;
                ControlFlow::Continue(())
            });
            count
        });
        runs.time_all.push(t);
        runs.pairs.push(pairs);
    }
    runs
}

/// Per-pose results of the distance query, cold and warm.
#[derive(Default)]
struct DistanceRuns {
    time_cold: Vec<f64>,
    time_warm: Vec<f64>,
    distance: Vec<f64>,
}

fn distance_runs<D: BoundingVolume>(
    meshes: [&TriMesh; 2],
    build: &BuildParams,
    poses: &[Pose],
    repeats: usize,
) -> DistanceRuns {
    let (a, b) = (
        Bvh::<D>::from_mesh(meshes[0], build),
        Bvh::<D>::from_mesh(meshes[1], build),
    );
    let mut ws = MeshMeshWorkspace::new();
    let mut runs = DistanceRuns::default();
    let exact = DistanceParams::EXACT;
    for pose_ab in poses {
        let (t, d) = time_us(repeats, || {
            distance_mesh_mesh(&a, &b, pose_ab, &exact, &mut DistanceCache::new(), &mut ws)
        });
        runs.time_cold.push(t);
        runs.distance.push(d.distance);
        let mut cache = DistanceCache::new();
        let (t, _) = time_us(repeats, || {
            distance_mesh_mesh(&a, &b, pose_ab, &exact, &mut cache, &mut ws)
        });
        runs.time_warm.push(t);
    }
    runs
}

/// Calls `$run::<T>($args)` with the volume type named by `$name`.
macro_rules! with_volume {
    ($name:expr, $run:ident($($args:expr),*)) => {
        match $name {
            "obb" => $run::<Obb>($($args),*),
            "rss" => $run::<Rss>($($args),*),
            "aabb" => $run::<Aabb>($($args),*),
            "sphere" => $run::<BoundingSphere>($($args),*),
            "kdop18" => $run::<Kdop18>($($args),*),
            "lss" => $run::<Lss>($($args),*),
            other => return Err(format!("unknown volume type {other} (obb, rss, aabb, sphere, kdop18, lss)").into()),
        }
    };
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse_args()?;
    let transforms = read_transforms(&args.transforms)?;
    let m1 = load(&args.meshes[0], args.scales[0], args.center)?;
    let m2 = load(&args.meshes[1], args.scales[1], args.center)?;
    // Mesh 2 (at identity) in mesh 1's frame.
    let poses: Vec<Pose> = transforms.iter().map(Pose::inverse).collect();
    let meshes = [&m1, &m2];
    let started = Instant::now();
    let collide = with_volume!(
        args.volumes[0].as_str(),
        collide_runs(meshes, &args.build, &poses, args.repeats)
    );
    let distance = with_volume!(
        args.volumes[1].as_str(),
        distance_runs(meshes, &args.build, &poses, args.repeats)
    );
    eprintln!(
        "{} + {} triangles; {} / {} trees, {:?}; {:.1} s in all",
        m1.triangle_count(),
        m2.triangle_count(),
        args.volumes[0],
        args.volumes[1],
        args.build.strategy,
        started.elapsed().as_secs_f64()
    );
    let colliding = collide.hit.iter().filter(|&&h| h).count();
    let touching = collide.pairs.iter().filter(|&&p| p > 0).count();
    let total_pairs: usize = collide.pairs.iter().sum();
    let zero = distance.distance.iter().filter(|&&d| d == 0.0).count();
    let mean_dist = format!(
        "{:.6}",
        distance.distance.iter().sum::<f64>() / poses.len() as f64
    );
    println!("query\tn\tmean_us\tmedian_us\tp95_us\tmax_us\tcolliding\ttri_pairs\tmean_dist");
    println!(
        "{}",
        summary(
            "collide_bool",
            collide.time_bool.clone(),
            colliding,
            "-".into(),
            "-".into()
        )
    );
    println!(
        "{}",
        summary(
            "collide_all",
            collide.time_all.clone(),
            touching,
            total_pairs.to_string(),
            "-".into()
        )
    );
    println!(
        "{}",
        summary(
            "distance",
            distance.time_cold.clone(),
            zero,
            "-".into(),
            mean_dist.clone()
        )
    );
    println!(
        "{}",
        summary(
            "distance_warm",
            distance.time_warm,
            zero,
            "-".into(),
            mean_dist
        )
    );
    if let Some(dir) = args.dump {
        let mut dump =
            String::from("i\tcollide_bool\tcollide_all\tcontacts\ttri_pairs\tdistance\n");
        for i in 0..poses.len() {
            let pairs = collide.pairs[i];
            writeln!(
                dump,
                "{i}\t{}\t{}\t{pairs}\t{pairs}\t{:.16e}",
                u8::from(collide.hit[i]),
                u8::from(pairs > 0),
                distance.distance[i]
            )?;
        }
        let mut times = String::from("i\tcollide_bool_us\tcollide_all_us\tdistance_us\n");
        for i in 0..poses.len() {
            writeln!(
                times,
                "{i}\t{:.3}\t{:.3}\t{:.3}",
                collide.time_bool[i], collide.time_all[i], distance.time_cold[i]
            )?;
        }
        std::fs::create_dir_all(&dir)?;
        std::fs::write(format!("{dir}/proxima.tsv"), dump)?;
        std::fs::write(format!("{dir}/proxima_times.tsv"), times)?;
    }
    Ok(())
}
