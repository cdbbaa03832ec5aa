//! Convex decomposition metrics (issue #33, deliverable 2): every `proxima::decompose`
//! method and parry's V-HACD on the same meshes, one table per mesh, one row per method.
//!
//! ```text
//! cargo run --release --example decompose -- MESH... [--max-concavity C] [--max-parts N] [--threads T] [--out DIR]
//! cargo run --release --example decompose -- --all
//! ```
//!
//! `MESH` is a mesh file (`.obj`, `.stl`), a shared mesh by name (`bunny`, `spot`,
//! `fandisk`, `env`, `rob`, found in the data folder by `tests/support/data.rs`'s rule), or a
//! procedural solid (`torus`, `u-block`); `--all` takes all seven. Columns:
//!
//! - `method`: ours by `Method::name`, then `parry-vhacd` (V-HACD at its defaults) and
//!   `parry-vhacd-equal` (as near as V-HACD gets to `cut-search`'s part count, or to
//!   `--max-parts` when `cut-search` does not run: its `max_convex_hulls` set to that count
//!   and its `concavity` bisected); `--method NAME` (repeatable) picks rows;
//! - `parts`: number of convex parts;
//! - `hausdorff_rel`: symmetric Hausdorff distance between the mesh surface and the boundary
//!   of the union of the parts' hulls, sampled, over the bounding-box diagonal;
//! - `volume_overshoot`: the hulls' total volume over the mesh's enclosed volume, minus 1;
//! - `seconds`: wall time of the decomposition alone (V-HACD's includes its hulls; for
//!   `parry-vhacd-equal`, the kept run's, not the search's).
//!
//! `decompose/metrics.rs` defines both metrics exactly, with their sampling error;
//! `decompose/methods.rs` says how each method is run. `--out DIR` writes
//! `DIR/<mesh>-<method>.obj`, one object `part_N` per hull. A mesh that cannot be found or
//! loaded ends the program before any work with exit code 2.

// The data folder's rule and the procedural prisms (the rest is the tests').
#[path = "decompose/meshes.rs"]
mod meshes;
#[path = "decompose/methods.rs"]
mod methods;
#[path = "decompose/metrics.rs"]
mod metrics;
#[path = "../benches/common/parry_convert.rs"]
mod parry_convert;
#[path = "../tests/support/mod.rs"]
mod support;

use clap::Parser;
use methods::{Limits, Run};
use metrics::Reference;
use proxima::geometry::TriMesh;
use std::error::Error;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Parser)]
#[command(about = "Convex decomposition metrics: Proxima's methods and parry's V-HACD")]
struct Args {
    /// Mesh files, shared mesh names or procedural solid names.
    #[arg(required_unless_present = "all")]
    meshes: Vec<String>,
    /// Every shared mesh and both procedural solids.
    #[arg(long)]
    all: bool,
    /// Largest concavity allowed, relative to the bounding-box diagonal (> 0).
    #[arg(long, value_name = "C", value_parser = positive)]
    max_concavity: Option<f64>,
    /// Most parts allowed (≥ 1).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    max_parts: Option<u32>,
    /// Threads our cut search may use (default: every available core; parry's V-HACD
    /// uses one). The parts are the same for any count.
    #[arg(long, value_name = "T", value_parser = clap::value_parser!(u32).range(1..))]
    threads: Option<u32>,
    /// Folder to write every method's parts to, as OBJ.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Only this method's row (repeatable; default: every row).
    #[arg(long = "method", value_name = "NAME",
          value_parser = clap::builder::PossibleValuesParser::new(methods::row_names()))]
    only: Vec<String>,
    /// Two more columns: the Hausdorff distance's directions, hulls to mesh and mesh to
    /// hulls, each over the diagonal.
    #[arg(long)]
    directions: bool,
}

fn main() -> ExitCode {
    let args = Args::parse();
    let mut names = args.meshes.clone();
    if args.all {
        names.extend(meshes::SHARED.map(|(name, _)| name.to_owned()));
        names.extend(meshes::PROCEDURAL.map(str::to_owned));
    }
    let loaded: Result<Vec<_>, _> = names.iter().map(|n| meshes::load(n)).collect();
    let loaded = match loaded {
        Ok(loaded) => loaded,
        Err(e) => {
            eprintln!("decompose: {e}");
            return ExitCode::from(2);
        }
    };
    match run(&args, &loaded) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("decompose: {e}");
            ExitCode::FAILURE
        }
    }
}

/// A positive finite number, for clap.
fn positive(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a positive finite number")),
    }
}

/// One table per mesh, and the parts' OBJ files when asked.
fn run(args: &Args, loaded: &[(String, TriMesh)]) -> Result<(), Box<dyn Error>> {
    let limits = Limits {
        max_concavity: args.max_concavity,
        max_parts: args.max_parts.map(|n| n as usize),
        threads: args.threads.map(|n| n as usize),
    };
    if let Some(dir) = &args.out {
        std::fs::create_dir_all(dir)?;
    }
    for (label, mesh) in loaded {
        let reference = Reference::new(mesh);
        print_header(label, mesh, &reference, args.directions);
        for run in methods::run_all(mesh, &limits, &args.only) {
            print_row(&run, &reference, args.directions);
            if let Some(dir) = &args.out {
                run.write_obj(&dir.join(format!("{label}-{}.obj", run.method)))?;
            }
        }
        println!();
    }
    Ok(())
}

/// The mesh's line (size, volume, whether it is closed) and the column names.
fn print_header(label: &str, mesh: &TriMesh, reference: &Reference, directions: bool) {
    let closed = match reference.open_edges() {
        0 => "closed".to_owned(),
        n => format!(
            "NOT closed ({n} edges not shared by exactly two triangles): its volume is the \
             divergence theorem's all the same"
        ),
    };
    println!(
        "# {label}: {} triangles, bounding-box diagonal {:.4} m, volume {:.4e} m³, {closed}",
        mesh.triangle_count(),
        reference.diagonal(),
        reference.volume(),
    );
    print!(
        "{:<18} {:>5} {:>13} {:>16} {:>9}",
        "method", "parts", "hausdorff_rel", "volume_overshoot", "seconds"
    );
    if directions {
        print!(" {:>16} {:>17}", "hull_to_mesh_rel", "mesh_to_hulls_rel");
    }
    println!();
}

/// One method's row.
fn print_row(run: &Run, reference: &Reference, directions: bool) {
    let m = reference.measure(&run.hulls);
    print!(
        "{:<18} {:>5} {:>13.5} {:>16.4} {:>9.3}",
        run.method,
        run.hulls.len(),
        m.hausdorff_rel,
        m.volume_overshoot,
        run.seconds
    );
    if directions {
        print!(
            " {:>16.5} {:>17.5}",
            m.hull_to_mesh_rel, m.mesh_to_hulls_rel
        );
    }
    println!();
}
