//! Tightness of every bounding-volume type on real meshes: mean volume relative to the OBB.
//!
//! Each mesh's triangles are split top-down at the median centroid along the longest axis,
//! down to single triangles, as a BVH builder would. Every volume type is fitted to the
//! triangles of every group, and groups are bucketed by size. A bucket's figure is
//! Σ volume(type) / Σ volume(OBB) over its groups (a ratio of means, so flat groups of zero
//! OBB volume do not divide by zero). Fit time per triangle is printed too.
//!
//! ```text
//! cargo run --release --example bv_tightness                  # meshes in the data folder (PROXIMA_DATA)
//! cargo run --release --example bv_tightness -- A.obj B.stl   # meshes of your own
//! ```

#[path = "../tests/support/data.rs"]
#[allow(dead_code)]
mod data;

use proxima::bounding::{
    Aabb, BoundingSphere, BoundingVolume, Kdop14, Kdop18, Kdop26, Lss, Obb, Rss,
};
use proxima::geometry::{TriMesh, Triangle};
use std::error::Error;
use std::path::PathBuf;
use std::time::Instant;

/// Group-size buckets: a group with n triangles goes to the first bucket with n < bound.
const BUCKETS: [(usize, &str); 5] = [
    (2, "1"),
    (16, "2-15"),
    (256, "16-255"),
    (4096, "256-4095"),
    (usize::MAX, "4096+"),
];

fn main() -> Result<(), Box<dyn Error>> {
    let mut paths: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if paths.is_empty() {
        let dir = data::data_dir()
            .ok_or("no meshes given and no data folder: set PROXIMA_DATA or name OBJ files")?
            .join("meshes");
        paths = std::fs::read_dir(&dir)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        paths.sort();
    }
    println!("mesh\tgroup_tris\tgroups\tsphere\taabb\tobb\tkdop14\tkdop18\tkdop26\tlss\trss");
    for path in &paths {
        let mesh = TriMesh::load(path)?;
        let triangles: Vec<Triangle> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle(i))
            .collect();
        let groups = median_split_groups(&triangles);
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("?");
        let obb = volumes::<Obb>(&groups);
        let columns = [
            volumes::<BoundingSphere>(&groups),
            volumes::<Aabb>(&groups),
            obb.clone(),
            volumes::<Kdop14>(&groups),
            volumes::<Kdop18>(&groups),
            volumes::<Kdop26>(&groups),
            volumes::<Lss>(&groups),
            volumes::<Rss>(&groups),
        ];
        for (bucket, (_, label)) in BUCKETS.iter().enumerate() {
            let members: Vec<usize> = (0..groups.len())
                .filter(|&g| bucket_of(groups[g].len()) == bucket)
                .collect();
            if members.is_empty() {
                continue;
            }
            let obb_sum: f64 = members.iter().map(|&g| obb[g]).sum();
            print!("{name}\t{label}\t{}", members.len());
            for column in &columns {
                let sum: f64 = members.iter().map(|&g| column[g]).sum();
                print!("\t{:.3}", sum / obb_sum);
            }
            println!();
        }
        print_fit_times(name, &triangles);
    }
    Ok(())
}

fn bucket_of(n: usize) -> usize {
    BUCKETS
        .iter()
        .position(|&(bound, _)| n < bound)
        .unwrap_or(BUCKETS.len() - 1)
}

/// Every group of a top-down median split (the whole mesh, its halves, … single triangles).
fn median_split_groups(triangles: &[Triangle]) -> Vec<Vec<Triangle>> {
    let mut groups = Vec::new();
    let mut stack = vec![triangles.to_vec()];
    while let Some(mut group) = stack.pop() {
        if group.len() > 1 {
            let (lo, hi) = group
                .iter()
                .fold((group[0].centroid(), group[0].centroid()), |(lo, hi), t| {
                    (lo.min(t.centroid()), hi.max(t.centroid()))
                });
            let axis = (hi - lo).max_position();
            let mid = group.len() / 2;
            group.select_nth_unstable_by(mid, |a, b| {
                a.centroid()[axis].total_cmp(&b.centroid()[axis])
            });
            stack.push(group[..mid].to_vec());
            stack.push(group[mid..].to_vec());
        }
        groups.push(group);
    }
    groups
}

fn volumes<B: BoundingVolume>(groups: &[Vec<Triangle>]) -> Vec<f64> {
    groups
        .iter()
        .map(|g| B::fit_triangles(g).volume())
        .collect()
}

fn print_fit_times(name: &str, triangles: &[Triangle]) {
    fn per_triangle_ns<B: BoundingVolume>(triangles: &[Triangle]) -> f64 {
        let start = Instant::now();
        std::hint::black_box(B::fit_triangles(std::hint::black_box(triangles)));
        start.elapsed().as_nanos() as f64 / triangles.len() as f64
    }
    println!(
        "# {name}: whole-mesh fit, ns per triangle: sphere {:.0}, aabb {:.1}, obb {:.0}, kdop14 {:.1}, kdop18 {:.1}, kdop26 {:.1}, lss {:.0}, rss {:.0}",
        per_triangle_ns::<BoundingSphere>(triangles),
        per_triangle_ns::<Aabb>(triangles),
        per_triangle_ns::<Obb>(triangles),
        per_triangle_ns::<Kdop14>(triangles),
        per_triangle_ns::<Kdop18>(triangles),
        per_triangle_ns::<Kdop26>(triangles),
        per_triangle_ns::<Lss>(triangles),
        per_triangle_ns::<Rss>(triangles),
    );
}
