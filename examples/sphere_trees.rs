//! Tightness per level of sphere trees over closed meshes: how much of the space a cut of N
//! spheres claims that lies outside the solid, for the octree, medial-axis and binned-SAH
//! sphere trees.
//!
//! ```text
//! cargo run --release --example sphere_trees                      # shared meshes + torus + L prism
//! cargo run --release --example sphere_trees -- A.obj B.obj       # closed meshes of your own
//! cargo run --release --example sphere_trees -- --grid 96 --counts 1,8,64 --out target/sphere_trees
//! ```
//!
//! Meshes: the files named, else `spot`, `fandisk` and `stanford-bunny` from the data folder
//! (`PROXIMA_DATA`, else `../shared/data`; the bunny has a few holes and is reported anyway,
//! marked `closed=no`) plus a torus (major radius 1 m, minor 0.3 m) and the L prism of
//! `tests/support/meshes.rs` (volume 3 m³). Any other open mesh is skipped with one line.
//!
//! Each mesh gets three `Bvh<BoundingSphere>` trees, `octree` (`BuildParams::OCTREE`),
//! `medial` (`BuildParams::MEDIAL_AXIS`) and `sah` (`BuildParams::BINNED_SAH`), each build
//! timed (`build_s`, seconds). For every N of `--counts` the **cut of N nodes** starts at the
//! root and repeatedly opens (replaces by its two children) the internal node of largest
//! volume in the cut, until the cut holds N nodes or only leaves (then `spheres` < N and the
//! row says so). The rule is the same for every tree, so rows of one N compare equal counts.
//!
//! Tightness, `outside_over_volume`, is the volume of the union of the cut's spheres outside
//! the mesh over the mesh's volume (divergence theorem, |Σ a·(b×c)|/6). It is sampled on a
//! regular grid of G³ points (`--grid G`, default 128) over one box per mesh that holds the
//! mesh and every sphere of every cut, offset by irrational fractions of a cell so that no
//! row of samples runs exactly through a vertex or an edge. A sample is inside the mesh by
//! ray parity along +x: each (y, z) row of samples collects the x of its line's crossings
//! with the triangles whose y-z bounding box it meets, and a sample is inside when an odd
//! number of them lie below it. Inside flags are computed once per mesh; a sphere marks only
//! the samples of its own bounding box. `covered_inside` is the fraction of inside samples
//! the union covers: informative only, since the spheres bound the surface's triangles, not
//! the interior, so it need not be 1. Each mesh's header gives the grid's inside volume over
//! the exact volume as a check of the sampling.
//!
//! The box depends on the cuts reported, so figures move by grid effects when `--counts`
//! changes. Outside volume need not fall as N grows: a child sphere bounds its triangles,
//! not its parent's ball, and may poke out of it; a `note` line names every such growth.
//!
//! Prints one table per mesh and a summary line (tightest tree per N, octree/medial ratio);
//! `--out DIR` also writes `DIR/sphere_trees.csv`
//! (`mesh,tree,count,spheres,outside_over_volume,covered_inside,build_s`).

// The data folder's rule (`support::data`) and the L prism (`support::meshes`).
#[path = "../tests/support/mod.rs"]
mod support;

use clap::Parser;
use proxima::bounding::{BoundingSphere, BoundingVolume};
use proxima::bvh::{BuildParams, Bvh, BvhNode};
use proxima::geometry::{TriMesh, Triangle};
use proxima::math::DVec3;
use std::collections::BinaryHeap;
use std::error::Error;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// The three trees compared, by row name.
const TREES: [(&str, BuildParams); 3] = [
    ("octree", BuildParams::OCTREE),
    ("medial", BuildParams::MEDIAL_AXIS),
    ("sah", BuildParams::BINNED_SAH),
];

/// Shared meshes of the default run, and whether each is reported even when open.
const SHARED: [(&str, bool); 3] = [
    ("spot", false),
    ("fandisk", false),
    ("stanford-bunny", true),
];

/// Where a sample sits in its cell along x, y, z, in cells: √5 − 2, √2 − 1, √3 − 1
/// (irrational, so rows of samples miss the vertices and edges of meshes with round
/// coordinates).
const OFFSET: [f64; 3] = [0.236_067_977_5, 0.414_213_562_4, 0.732_050_807_6];

#[derive(Debug, Parser)]
#[command(about = "Tightness per level of sphere trees: union volume outside the mesh")]
struct Args {
    /// Closed mesh files (OBJ); default: the shared meshes, a torus and an L prism.
    meshes: Vec<PathBuf>,
    /// Samples per axis of the grid (G³ samples per mesh).
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(2..=1024))]
    grid: u32,
    /// Sphere counts N of the cuts, comma-separated (each ≥ 1).
    #[arg(long, value_delimiter = ',', default_value = "1,8,64,512,4096",
          value_parser = clap::value_parser!(u64).range(1..))]
    counts: Vec<u64>,
    /// Folder to write sphere_trees.csv to.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

/// A mesh to measure.
struct Named {
    name: String,
    mesh: TriMesh,
    /// Reported even when not closed (the bunny).
    keep_open: bool,
}

/// One cut of a tree: the spheres of N nodes (fewer when only leaves were left).
struct Cut {
    requested: usize,
    spheres: Vec<BoundingSphere>,
}

/// One tree of one mesh: its build time (s) and its cuts, in ascending count.
struct TreeRun {
    name: &'static str,
    build_s: f64,
    cuts: Vec<Cut>,
}

/// One printed and CSV row.
struct Row {
    tree: &'static str,
    count: usize,
    spheres: usize,
    outside_over_volume: f64,
    covered_inside: f64,
    build_s: f64,
}

fn main() -> Result<(), Box<dyn Error>> {
    let args = Args::parse();
    let started = Instant::now();
    let mut counts: Vec<usize> = args.counts.iter().map(|&n| n as usize).collect();
    counts.sort_unstable();
    counts.dedup();
    let meshes = load_meshes(&args.meshes)?;
    let mut csv =
        String::from("mesh,tree,count,spheres,outside_over_volume,covered_inside,build_s\n");
    for named in &meshes {
        let closed = named.mesh.report().closed;
        if !closed && !named.keep_open {
            println!("skipped {}: not closed", named.name);
            continue;
        }
        let rows = measure(named, closed, &counts, args.grid as usize);
        print_summary(&named.name, &rows, &counts);
        for r in &rows {
            writeln!(
                csv,
                "{},{},{},{},{:.6},{:.6},{:.6}",
                named.name,
                r.tree,
                r.count,
                r.spheres,
                r.outside_over_volume,
                r.covered_inside,
                r.build_s
            )?;
        }
    }
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
        std::fs::write(dir.join("sphere_trees.csv"), csv)?;
    }
    println!("total {:.1} s", started.elapsed().as_secs_f64());
    Ok(())
}

/// The meshes named on the command line (errors end the program), else the default set.
fn load_meshes(paths: &[PathBuf]) -> Result<Vec<Named>, Box<dyn Error>> {
    let mut meshes = Vec::new();
    for path in paths {
        let mesh = TriMesh::load(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("?");
        meshes.push(Named {
            name: name.to_owned(),
            mesh,
            keep_open: false,
        });
    }
    if !paths.is_empty() {
        return Ok(meshes);
    }
    match support::data::data_dir() {
        Some(dir) => {
            for (name, keep_open) in SHARED {
                let path = dir.join("meshes").join(format!("{name}.obj"));
                match TriMesh::load(&path) {
                    Ok(mesh) => meshes.push(Named {
                        name: name.to_owned(),
                        mesh,
                        keep_open,
                    }),
                    Err(e) => println!("skipped {name}: {}: {e}", path.display()),
                }
            }
        }
        None => println!("skipped the shared meshes: no data folder (set PROXIMA_DATA)"),
    }
    let torus = TriMesh::torus(1.0, 0.3, 96, 48);
    meshes.push(Named {
        name: "torus".to_owned(),
        mesh: torus,
        keep_open: false,
    });
    let l_prism = support::meshes::l_prism();
    meshes.push(Named {
        name: "l-prism".to_owned(),
        mesh: l_prism,
        keep_open: false,
    });
    Ok(meshes)
}

/// Builds the three trees of one mesh, samples every cut, prints the table; returns its rows.
fn measure(named: &Named, closed: bool, counts: &[usize], g: usize) -> Vec<Row> {
    let triangles: Vec<Triangle> = (0..named.mesh.triangle_count())
        .map(|i| named.mesh.triangle(i))
        .collect();
    let volume = mesh_volume(&triangles);
    let trees: Vec<TreeRun> = TREES
        .iter()
        .map(|&(name, params)| {
            let start = Instant::now();
            let bvh = Bvh::<BoundingSphere>::from_mesh(&named.mesh, &params);
            let build_s = start.elapsed().as_secs_f64();
            TreeRun {
                name,
                build_s,
                cuts: cuts(&bvh, counts),
            }
        })
        .collect();
    let grid = Grid::new(named.mesh.bounds(), &trees, g);
    let inside = inside_flags(&grid, &triangles);
    let inside_count = inside.iter().filter(|&&b| b).count();
    let size = grid.h * g as f64;
    println!(
        "\n== {}: {} triangles, closed={}, volume {:.5} m³, grid {g}³ over {:.3} × {:.3} × {:.3} m, \
         grid inside volume / volume = {:.4}",
        named.name,
        triangles.len(),
        if closed { "yes" } else { "no" },
        volume,
        size.x,
        size.y,
        size.z,
        inside_count as f64 * grid.cell_volume() / volume
    );
    println!(
        "{:<7} {:>6} {:>8} {:>20} {:>15} {:>9}",
        "tree", "count", "spheres", "outside_over_volume", "covered_inside", "build_s"
    );
    let mut covered = vec![false; inside.len()];
    let mut rows = Vec::new();
    for tree in &trees {
        for cut in &tree.cuts {
            let (outside, covered_in) = union_counts(&grid, &cut.spheres, &inside, &mut covered);
            let row = Row {
                tree: tree.name,
                count: cut.requested,
                spheres: cut.spheres.len(),
                outside_over_volume: outside as f64 * grid.cell_volume() / volume,
                covered_inside: covered_in as f64 / inside_count as f64,
                build_s: tree.build_s,
            };
            print_row(&row);
            rows.push(row);
        }
    }
    rows
}

/// Prints one table row; a cut that ran out of internal nodes says so.
fn print_row(r: &Row) {
    let note = if r.spheres < r.count {
        "  (only leaves left)"
    } else {
        ""
    };
    println!(
        "{:<7} {:>6} {:>8} {:>20.4} {:>15.4} {:>9.4}{note}",
        r.tree, r.count, r.spheres, r.outside_over_volume, r.covered_inside, r.build_s
    );
}

/// Per count: the tightest tree and octree/medial; then any tree whose outside volume grows
/// with N (a child sphere may poke out of its parent, so small growth is possible).
fn print_summary(mesh: &str, rows: &[Row], counts: &[usize]) {
    let of = |tree: &str, n: usize| {
        rows.iter()
            .find(|r| r.tree == tree && r.count == n)
            .map_or(f64::NAN, |r| r.outside_over_volume)
    };
    let mut line = format!("summary {mesh}:");
    for &n in counts {
        // Every tree at the least value: `octree=medial=sah` when they tie (same spheres).
        let least = TREES
            .iter()
            .map(|&(tree, _)| of(tree, n))
            .fold(f64::INFINITY, f64::min);
        let best: Vec<&str> = TREES
            .iter()
            .map(|&(tree, _)| tree)
            .filter(|&tree| of(tree, n) == least)
            .collect();
        let best = best.join("=");
        let ratio = of("octree", n) / of("medial", n);
        let _ = write!(line, "  N={n} tightest={best} octree/medial={ratio:.2};");
    }
    println!("{line}");
    for (tree, _) in TREES {
        for pair in counts.windows(2) {
            let (a, b) = (of(tree, pair[0]), of(tree, pair[1]));
            if b > a {
                println!(
                    "note {mesh}: {tree} outside grows from N={} ({a:.4}) to N={} ({b:.4})",
                    pair[0], pair[1]
                );
            }
        }
    }
}

/// A cut being grown: its internal nodes keyed by volume (m³) and its leaves. The bits of a
/// non-negative finite f64 order as the number does; ties go to the larger node index, the
/// same rule for every tree.
#[derive(Default)]
struct Frontier {
    open: BinaryHeap<(u64, usize)>,
    leaves: Vec<usize>,
}

impl Frontier {
    fn add(&mut self, nodes: &[BvhNode<BoundingSphere>], i: usize) {
        if nodes[i].is_leaf() {
            self.leaves.push(i);
        } else {
            self.open.push((nodes[i].bv.volume().to_bits(), i));
        }
    }

    fn len(&self) -> usize {
        self.open.len() + self.leaves.len()
    }
}

/// The cuts of `bvh` for each of `counts` (ascending), grown one opening at a time.
fn cuts(bvh: &Bvh<BoundingSphere>, counts: &[usize]) -> Vec<Cut> {
    let nodes = bvh.nodes();
    let mut cut = Frontier::default();
    cut.add(nodes, 0);
    let mut result = Vec::new();
    for &n in counts {
        while cut.len() < n {
            let Some((_, i)) = cut.open.pop() else { break };
            for child in nodes[i].children() {
                cut.add(nodes, child);
            }
        }
        let members = cut
            .open
            .iter()
            .map(|&(_, i)| i)
            .chain(cut.leaves.iter().copied());
        let spheres = members.map(|i| nodes[i].bv).collect();
        result.push(Cut {
            requested: n,
            spheres,
        });
    }
    result
}

/// The sampling grid: `n` samples per axis, sample (i, j, k) at
/// `lo + ((i, j, k) + OFFSET) · h`, all inside the box `[lo, lo + n·h]` (m).
struct Grid {
    lo: DVec3,
    h: DVec3,
    n: usize,
}

impl Grid {
    /// The grid over the box of the mesh's `bounds` and of every sphere of every cut.
    fn new(bounds: (DVec3, DVec3), trees: &[TreeRun], n: usize) -> Self {
        let (mut lo, mut hi) = bounds;
        let spheres = trees.iter().flat_map(|t| &t.cuts).flat_map(|c| &c.spheres);
        for s in spheres {
            lo = lo.min(s.center - DVec3::splat(s.radius));
            hi = hi.max(s.center + DVec3::splat(s.radius));
        }
        Self {
            lo,
            h: (hi - lo) / n as f64,
            n,
        }
    }

    /// Volume of one cell, m³.
    fn cell_volume(&self) -> f64 {
        self.h.x * self.h.y * self.h.z
    }

    /// Coordinate (m) of the samples of index `i` along `axis`.
    fn coord(&self, axis: usize, i: usize) -> f64 {
        self.lo[axis] + (i as f64 + OFFSET[axis]) * self.h[axis]
    }

    /// The indices along `axis` of the samples with coordinate in `[a, b]` (m), if any.
    fn range(&self, axis: usize, a: f64, b: f64) -> Option<std::ops::RangeInclusive<usize>> {
        let first = ((a - self.lo[axis]) / self.h[axis] - OFFSET[axis])
            .ceil()
            .max(0.0);
        let last = ((b - self.lo[axis]) / self.h[axis] - OFFSET[axis])
            .floor()
            .min((self.n - 1) as f64);
        (first <= last).then_some(first as usize..=last as usize)
    }

    /// Flat index of sample (i, j, k); x varies fastest, so a (y, z) row is contiguous.
    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.n + j) * self.n + i
    }
}

/// Whether each sample is inside the mesh, by the parity of +x ray crossings.
fn inside_flags(grid: &Grid, triangles: &[Triangle]) -> Vec<bool> {
    let n = grid.n;
    let mut rows: Vec<Vec<f64>> = vec![Vec::new(); n * n];
    for t in triangles {
        let (lo, hi) = (t.a.min(t.b).min(t.c), t.a.max(t.b).max(t.c));
        let (Some(js), Some(ks)) = (grid.range(1, lo.y, hi.y), grid.range(2, lo.z, hi.z)) else {
            continue;
        };
        for k in ks {
            for j in js.clone() {
                if let Some(x) = crossing(t, grid.coord(1, j), grid.coord(2, k)) {
                    rows[k * n + j].push(x);
                }
            }
        }
    }
    let mut inside = vec![false; n * n * n];
    for (row, xs) in rows.iter_mut().enumerate() {
        xs.sort_unstable_by(f64::total_cmp);
        let mut below = 0;
        for i in 0..n {
            let x = grid.coord(0, i);
            while below < xs.len() && xs[below] < x {
                below += 1;
            }
            inside[row * n + i] = below % 2 == 1;
        }
    }
    inside
}

/// The x (m) where the line {(·, y, z)} crosses triangle `t`, if it passes strictly inside
/// the triangle's y-z projection (an edge-on or degenerate projection gives none).
fn crossing(t: &Triangle, y: f64, z: f64) -> Option<f64> {
    // Twice the signed y-z area of (u, v, p): the barycentric weight of the third vertex.
    let edge = |u: DVec3, v: DVec3| (v.y - u.y) * (z - u.z) - (v.z - u.z) * (y - u.y);
    let (wa, wb, wc) = (edge(t.b, t.c), edge(t.c, t.a), edge(t.a, t.b));
    let all_positive = wa > 0.0 && wb > 0.0 && wc > 0.0;
    let all_negative = wa < 0.0 && wb < 0.0 && wc < 0.0;
    (all_positive || all_negative).then(|| (wa * t.a.x + wb * t.b.x + wc * t.c.x) / (wa + wb + wc))
}

/// Samples covered by the union of `spheres`: (outside the mesh, inside the mesh).
/// `covered` is scratch of the grid's size.
fn union_counts(
    grid: &Grid,
    spheres: &[BoundingSphere],
    inside: &[bool],
    covered: &mut [bool],
) -> (usize, usize) {
    covered.fill(false);
    let (mut outside_count, mut inside_count) = (0, 0);
    for s in spheres {
        let (c, r) = (s.center, s.radius);
        let (Some(js), Some(ks)) = (
            grid.range(1, c.y - r, c.y + r),
            grid.range(2, c.z - r, c.z + r),
        ) else {
            continue;
        };
        for k in ks {
            let dz = grid.coord(2, k) - c.z;
            for j in js.clone() {
                let dy = grid.coord(1, j) - c.y;
                let rest = r * r - dy * dy - dz * dz;
                if rest < 0.0 {
                    continue;
                }
                let w = rest.sqrt();
                let Some(is) = grid.range(0, c.x - w, c.x + w) else {
                    continue;
                };
                for i in is {
                    let at = grid.index(i, j, k);
                    if !covered[at] {
                        covered[at] = true;
                        if inside[at] {
                            inside_count += 1
                        } else {
                            outside_count += 1
                        }
                    }
                }
            }
        }
    }
    (outside_count, inside_count)
}

/// Volume enclosed by a closed mesh (m³), by the divergence theorem: |Σ a·(b×c)| / 6.
fn mesh_volume(triangles: &[Triangle]) -> f64 {
    triangles
        .iter()
        .map(|t| t.a.dot(t.b.cross(t.c)))
        .sum::<f64>()
        .abs()
        / 6.0
}
