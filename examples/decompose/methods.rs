//! The decompositions `decompose` compares, each timed alone: every
//! [`proxima::decompose::Method`], then parry's V-HACD twice, at its defaults and as near
//! as it gets to the part count of our quality method (`Method::CutSearch`, or
//! `--max-parts` when that does not run), so that one row compares at an equal number of
//! parts ([`run_vhacd_equal`] says how).
//!
//! V-HACD keeps its voxel-to-triangle map and takes `compute_exact_convex_hulls`, the hulls
//! parry documents as the accurate ones (of the mesh's triangles clipped to each part's
//! voxels); its time includes them. Their vertices become [`ConvexPolyhedron`]s after the
//! clock stops, so both libraries' parts are measured by the same code.

use crate::parry_convert::parry_vector;
use parry3d_f64::transformation::vhacd::{VHACD, VHACDParameters};
use proxima::decompose::{Method, Options, decompose};
use proxima::geometry::{ConvexHullError, ConvexPolyhedron, TriMesh};
use proxima::math::DVec3;
use std::error::Error;
use std::io::{BufWriter, Write};
use std::path::Path;
use std::time::Instant;

/// Whether `method` is the quality method, whose part count the second V-HACD row matches.
fn is_quality(method: Method) -> bool {
    matches!(method, Method::CutSearch)
}

/// The command line's bounds on our methods; `None` keeps [`Options::default`]'s.
#[derive(Debug, Clone, Copy, Default)]
pub struct Limits {
    /// Largest concavity, relative to the bounding-box diagonal.
    pub max_concavity: Option<f64>,
    /// Most parts.
    pub max_parts: Option<usize>,
    /// Threads of our cut search.
    pub threads: Option<usize>,
}

impl Limits {
    /// The options of `method` under these bounds.
    fn options(&self, method: Method) -> Options {
        let defaults = Options::default();
        Options {
            method,
            max_concavity: self.max_concavity.unwrap_or(defaults.max_concavity),
            max_parts: self.max_parts.unwrap_or(defaults.max_parts),
            threads: self.threads.unwrap_or(defaults.threads),
            ..defaults
        }
    }
}

/// Row name of V-HACD at its defaults.
pub const VHACD_ROW: &str = "parry-vhacd";
/// Row name of V-HACD with `max_convex_hulls` set to the quality method's part count.
pub const VHACD_EQUAL_ROW: &str = "parry-vhacd-equal";

/// One method's parts and the wall time of its decomposition alone, seconds.
pub struct Run {
    /// Row name.
    pub method: String,
    /// The parts' hulls, mesh frame.
    pub hulls: Vec<ConvexPolyhedron>,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Every row name, in table order: ours by [`Method::name`], then [`VHACD_ROW`] and
/// [`VHACD_EQUAL_ROW`].
pub fn row_names() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = Method::ALL.iter().map(|m| m.name()).collect();
    names.extend([VHACD_ROW, VHACD_EQUAL_ROW]);
    names
}

/// The methods named in `only` (all when empty) on `mesh`, in [`row_names`] order, ours
/// under `limits`. [`VHACD_EQUAL_ROW`] takes the quality method's part count when that method
/// ran, else `limits.max_parts`, else it has no row. A method that fails is reported on
/// stderr and has no row.
pub fn run_all(mesh: &TriMesh, limits: &Limits, only: &[String]) -> Vec<Run> {
    let wanted = |name: &str| only.is_empty() || only.iter().any(|o| o == name);
    let mut runs = Vec::new();
    let mut quality_parts = None;
    for method in Method::ALL.into_iter().filter(|m| wanted(m.name())) {
        match run_proxima(mesh, &limits.options(method)) {
            Ok(run) => {
                if is_quality(method) {
                    quality_parts = Some(run.hulls.len());
                }
                runs.push(run);
            }
            Err(e) => eprintln!("{}: {e}", method.name()),
        }
    }
    let equal_parts = quality_parts.or(limits.max_parts);
    if wanted(VHACD_ROW) {
        match run_vhacd_default(mesh) {
            Ok(run) => runs.push(run),
            Err(e) => eprintln!("{VHACD_ROW}: {e}"),
        }
    }
    if wanted(VHACD_EQUAL_ROW) {
        match equal_parts.map(|n| run_vhacd_equal(mesh, n)) {
            Some(Ok(run)) => runs.push(run),
            Some(Err(e)) => eprintln!("{VHACD_EQUAL_ROW}: {e}"),
            None => eprintln!(
                "{VHACD_EQUAL_ROW}: no part count to match (run cut-search or give --max-parts)"
            ),
        }
    }
    runs
}

/// Our decomposition of `mesh` under `options`.
///
/// # Errors
/// The decomposition's error.
pub fn run_proxima(mesh: &TriMesh, options: &Options) -> Result<Run, Box<dyn Error>> {
    let start = Instant::now();
    let decomposition = decompose(mesh, options)?;
    let seconds = start.elapsed().as_secs_f64();
    Ok(Run {
        method: options.method.name().to_owned(),
        hulls: decomposition.parts.into_iter().map(|p| p.hull).collect(),
        seconds,
    })
}

/// parry's V-HACD of `mesh` at [`VHACDParameters::default`]: the [`VHACD_ROW`] row.
///
/// # Errors
/// A hull vertex our hull construction rejects (non-finite or too large).
pub fn run_vhacd_default(mesh: &TriMesh) -> Result<Run, ConvexHullError> {
    let (run, left_out) = run_vhacd(mesh, VHACD_ROW, &VHACDParameters::default())?;
    note_left_out(&run, left_out);
    Ok(run)
}

/// V-HACD's `concavity` range the equal-parts search covers (its default is 0.01).
const CONCAVITY_RANGE: [f64; 2] = [1e-5, 1.0];
/// Steps of the equal-parts search (bisections of `ln concavity`).
const CONCAVITY_STEPS: usize = 12;

/// parry's V-HACD of `mesh` with as close to `parts` parts as it gives: the
/// [`VHACD_EQUAL_ROW`].
///
/// `max_convex_hulls = parts` alone does not get there: it only bounds V-HACD's split depth
/// (up to `2^(⌈log₂ parts⌉ + 1)` parts, parry has no merge step), and V-HACD stops splitting
/// a part once its concavity is below `concavity` (0.01 by default), often well before.
/// So `concavity` is bisected (log scale, [`CONCAVITY_RANGE`], at most [`CONCAVITY_STEPS`]
/// runs) and the run whose part count is nearest `parts` kept, ties to the larger count.
/// Its time is that one run's; the search is not counted.
///
/// # Errors
/// A hull vertex our hull construction rejects (non-finite or too large).
pub fn run_vhacd_equal(mesh: &TriMesh, parts: usize) -> Result<Run, ConvexHullError> {
    let mut params = VHACDParameters {
        max_convex_hulls: u32::try_from(parts.max(1)).unwrap_or(u32::MAX),
        ..VHACDParameters::default()
    };
    let [mut low, mut high] = CONCAVITY_RANGE.map(f64::ln);
    let mut best: Option<(Run, usize, f64)> = None;
    for _ in 0..CONCAVITY_STEPS {
        let middle = 0.5 * (low + high);
        params.concavity = middle.exp();
        let (run, left_out) = run_vhacd(mesh, VHACD_EQUAL_ROW, &params)?;
        let n = run.hulls.len();
        // More parts than wanted: allow more concavity.
        if n > parts {
            low = middle;
        } else {
            high = middle;
        }
        let key = |n: usize| (n.abs_diff(parts), usize::MAX - n);
        if best
            .as_ref()
            .is_none_or(|(b, ..)| key(n) < key(b.hulls.len()))
        {
            best = Some((run, left_out, params.concavity));
        }
        if n == parts {
            break;
        }
    }
    let (run, left_out, concavity) = best.expect("the search runs at least once");
    eprintln!(
        "{VHACD_EQUAL_ROW}: concavity {concavity:.3e} gives {} parts (wanted {parts})",
        run.hulls.len()
    );
    note_left_out(&run, left_out);
    Ok(run)
}

/// Says on stderr how many V-HACD parts had no hull vertex, if any.
fn note_left_out(run: &Run, left_out: usize) {
    if left_out > 0 {
        eprintln!(
            "{}: {left_out} parts without a hull vertex left out",
            run.method
        );
    }
}

/// parry's V-HACD of `mesh` under `params`, hulls by `compute_exact_convex_hulls`, timed
/// together; then the hulls as ours. Parts whose hull has no vertex (V-HACD's exact hulls
/// come from the mesh's triangles, and a part of interior voxels meets none) are left out
/// and counted in the second value.
fn run_vhacd(
    mesh: &TriMesh,
    name: &str,
    params: &VHACDParameters,
) -> Result<(Run, usize), ConvexHullError> {
    let points: Vec<_> = mesh.vertices().iter().map(|&v| parry_vector(v)).collect();
    let start = Instant::now();
    let vhacd = VHACD::decompose(params, &points, mesh.triangles(), true);
    let hulls = vhacd.compute_exact_convex_hulls(&points, mesh.triangles());
    let seconds = start.elapsed().as_secs_f64();
    let left_out = hulls.iter().filter(|(v, _)| v.is_empty()).count();
    let hulls = hulls
        .iter()
        .filter(|(vertices, _)| !vertices.is_empty())
        .map(|(vertices, _)| {
            let ours: Vec<DVec3> = vertices.iter().map(|v| DVec3::new(v.x, v.y, v.z)).collect();
            ConvexPolyhedron::try_from_points(&ours)
        })
        .collect::<Result<_, _>>()?;
    let run = Run {
        method: name.to_owned(),
        hulls,
        seconds,
    };
    Ok((run, left_out))
}

impl Run {
    /// Writes the parts to `path` as OBJ: one object `part_N` per hull (N from 0) with its
    /// vertices and triangles (faces counter-clockwise seen from outside).
    ///
    /// # Errors
    /// The file's I/O errors.
    pub fn write_obj(&self, path: &Path) -> std::io::Result<()> {
        let mut out = BufWriter::new(std::fs::File::create(path)?);
        writeln!(out, "# {}: {} convex parts", self.method, self.hulls.len())?;
        let mut first = 1; // OBJ indices are 1-based and count every vertex before.
        for (i, hull) in self.hulls.iter().enumerate() {
            writeln!(out, "o part_{i}")?;
            for v in hull.vertices() {
                writeln!(out, "v {} {} {}", v.x, v.y, v.z)?;
            }
            for t in hull.triangles() {
                let [a, b, c] = t.map(|k| k as usize + first);
                writeln!(out, "f {a} {b} {c}")?;
            }
            first += hull.vertices().len();
        }
        out.flush()
    }
}
