//! Benchmarks one mesh pair the way FCL's own mesh-pair test does (issue #3).
//!
//! ```text
//! cargo run --release --example pair_queries -- MESH1.obj MESH2.obj TRANSFORMS.txt \
//!     [--scale1 S] [--scale2 S] [--center] [--dump DIR] [--repeats K]
//! ```
//!
//! Mesh 1 takes each transform of TRANSFORMS.txt (`#` comment lines, then the count N, then
//! N lines of a row-major 3×3 rotation and a translation); mesh 2 stays at identity.
//! `--scale1/--scale2` multiply a mesh's vertices; `--center` then moves each mesh's
//! bounding-box centre to the origin. BVHs are built once, outside the timing: OBB trees for
//! the collision queries, RSS trees for distance. Per transform, each query runs twice to warm
//! up and is then timed over K runs (default 5); its time is the mean of those runs.
//!
//! stdout: one TSV row per query, `query n mean_us median_us p95_us max_us colliding tri_pairs
//! mean_dist`. `distance` starts every run cold (a fresh cache); `distance_warm` keeps the
//! pair's cache between runs, as a simulation querying the same pair every frame would.
//! `--dump DIR` writes `DIR/proxima.tsv`: `i collide_bool collide_all contacts tri_pairs distance`.

use proxima::bounding::{Obb, Rss};
use proxima::bvh::{BuildParams, Bvh};
use proxima::geometry::TriMesh;
use proxima::math::{DMat3, DQuat, DVec3, Pose};
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
}

fn parse_args() -> Result<Args, Box<dyn Error>> {
    let mut positional = Vec::new();
    let (mut scales, mut center, mut dump, mut repeats) = ([1.0, 1.0], false, None, 5);
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or_else(|| format!("{arg} needs a value"));
        match arg.as_str() {
            "--scale1" => scales[0] = value()?.parse()?,
            "--scale2" => scales[1] = value()?.parse()?,
            "--center" => center = true,
            "--dump" => dump = Some(value()?),
            "--repeats" => repeats = value()?.parse::<usize>()?.max(1),
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

fn main() -> Result<(), Box<dyn Error>> {
    let args = parse_args()?;
    let transforms = read_transforms(&args.transforms)?;
    let m1 = load(&args.meshes[0], args.scales[0], args.center)?;
    let m2 = load(&args.meshes[1], args.scales[1], args.center)?;
    let build = Instant::now();
    let (obb1, obb2) = (
        Bvh::<Obb>::from_mesh(&m1, &BuildParams::MEAN_VARIANCE),
        Bvh::<Obb>::from_mesh(&m2, &BuildParams::MEAN_VARIANCE),
    );
    let (rss1, rss2) = (
        Bvh::<Rss>::from_mesh(&m1, &BuildParams::MEAN_VARIANCE),
        Bvh::<Rss>::from_mesh(&m2, &BuildParams::MEAN_VARIANCE),
    );
    eprintln!(
        "built 4 BVHs over {} + {} triangles in {:.2} s",
        m1.triangle_count(),
        m2.triangle_count(),
        build.elapsed().as_secs_f64()
    );

    let mut ws = MeshMeshWorkspace::new();
    let (mut t_bool, mut t_all, mut t_dist, mut t_warm) = (vec![], vec![], vec![], vec![]);
    let (mut n_bool, mut n_all, mut n_dist, mut total_pairs, mut dist_sum) = (0, 0, 0, 0usize, 0.0);
    let mut dump = String::from("i\tcollide_bool\tcollide_all\tcontacts\ttri_pairs\tdistance\n");
    for (i, transform) in transforms.iter().enumerate() {
        let pose_ab = transform.inverse(); // mesh 2 (at identity) in mesh 1's frame
        let (t, hit) = time_us(args.repeats, || {
            intersects_mesh_mesh(&obb1, &obb2, &pose_ab, &mut ws)
        });
        t_bool.push(t);
        let (t, pairs) = time_us(args.repeats, || {
            let mut count = 0usize;
            contacts_mesh_mesh(&obb1, &obb2, &pose_ab, &mut ws, |_| {
                count += 1;
                ControlFlow::Continue(())
            });
            count
        });
        t_all.push(t);
        let (t, d) = time_us(args.repeats, || {
            distance_mesh_mesh(
                &rss1,
                &rss2,
                &pose_ab,
                &DistanceParams::EXACT,
                &mut DistanceCache::new(),
                &mut ws,
            )
        });
        t_dist.push(t);
        let mut cache = DistanceCache::new();
        let (t, _) = time_us(args.repeats, || {
            distance_mesh_mesh(
                &rss1,
                &rss2,
                &pose_ab,
                &DistanceParams::EXACT,
                &mut cache,
                &mut ws,
            )
        });
        t_warm.push(t);
        n_bool += usize::from(hit);
        n_all += usize::from(pairs > 0);
        n_dist += usize::from(d.distance == 0.0);
        total_pairs += pairs;
        dist_sum += d.distance;
        writeln!(
            dump,
            "{i}\t{}\t{}\t{pairs}\t{pairs}\t{:.16e}",
            u8::from(hit),
            u8::from(pairs > 0),
            d.distance
        )?;
    }
    let n = transforms.len() as f64;
    println!("query\tn\tmean_us\tmedian_us\tp95_us\tmax_us\tcolliding\ttri_pairs\tmean_dist");
    println!(
        "{}",
        summary("collide_bool", t_bool, n_bool, "-".into(), "-".into())
    );
    println!(
        "{}",
        summary(
            "collide_all",
            t_all,
            n_all,
            total_pairs.to_string(),
            "-".into()
        )
    );
    println!(
        "{}",
        summary(
            "distance",
            t_dist,
            n_dist,
            "-".into(),
            format!("{:.6}", dist_sum / n)
        )
    );
    println!(
        "{}",
        summary(
            "distance_warm",
            t_warm,
            n_dist,
            "-".into(),
            format!("{:.6}", dist_sum / n)
        )
    );
    if let Some(dir) = args.dump {
        std::fs::create_dir_all(&dir)?;
        std::fs::write(format!("{dir}/proxima.tsv"), dump)?;
    }
    Ok(())
}
