//! Approximate convex decomposition: a closed mesh as a few nearly convex parts, once,
//! before simulation.
//!
//! [`decompose`] repairs the mesh into a closed solid (welds a triangle soup, orients
//! flipped triangles, closes holes: [`Repairs`] says what it did), then cuts it into pieces
//! with planes and gives each piece's convex hull as a [`Part`]. Two [`Method`]s:
//!
//! - [`Method::CutSearch`], quality first: the most concave piece is cut by the plane that
//!   leaves the least concavity, until every piece is within [`Options::max_concavity`] or
//!   there are [`Options::max_parts`]; needless cuts are then merged back.
//! - [`Method::Relaxation`], the lectures' baseline: split top-down by oriented boxes into
//!   small leaves, then merge the smallest with a neighbour while the union fills its hull
//!   to within [`Options::max_empty_fraction`].
//!
//! Pieces are exact: each is the solid cut by half-spaces, its boundary the input's
//! triangles clipped plus flat caps where the cuts went through (`piece.rs`). Its hull
//! therefore contains it, and the hulls together contain the whole solid.
//!
//! **Concavity** of a part (metres) is the greatest depth of the mesh surface inside the part
//! below its hull's boundary: how far an object touching the hull may still be from the mesh.

mod buckets;
mod cap_outline;
mod concavity;
mod cut_search;
mod fitted;
mod merge;
mod nearest;
mod parallel;
mod piece;
mod relaxation;
mod solid;
#[cfg(test)]
mod tests;

use super::{ConvexHullError, ConvexPolyhedron, TriMesh};
use fitted::Fitted;
use std::fmt;

/// How the pieces are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Method {
    /// The lectures' relaxation: top-down box splits into small leaves, merged by volume.
    Relaxation,
    /// Quality first: concavity-driven plane cut search (in the manner of CoACD), then merge.
    CutSearch,
}

impl Method {
    /// Every method, baseline first.
    pub const ALL: [Method; 2] = [Method::Relaxation, Method::CutSearch];

    /// A short name for tables and command lines.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Method::Relaxation => "relaxation",
            Method::CutSearch => "cut-search",
        }
    }
}

/// What a decomposition may do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Which method.
    pub method: Method,
    /// Largest allowed concavity of a part, relative to the mesh's bounding-box diagonal
    /// (default 0.02: 2 cm on a 1 m part).
    pub max_concavity: f64,
    /// Most parts (default 64).
    pub max_parts: usize,
    /// [`Method::Relaxation`] only: the largest fraction of a merged part's hull it may leave
    /// empty (default 0.05).
    pub max_empty_fraction: f64,
    /// Threads the search and the merging may use, the caller's among them (default: the
    /// machine's available parallelism; 0 counts as 1). The parts are the same for any
    /// count.
    pub threads: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            method: Method::CutSearch,
            max_concavity: 0.02,
            max_parts: 64,
            max_empty_fraction: 0.05,
            threads: std::thread::available_parallelism().map_or(1, usize::from),
        }
    }
}

/// One convex part.
#[derive(Debug, Clone)]
pub struct Part {
    /// The part's convex hull, in the mesh's frame.
    pub hull: ConvexPolyhedron,
    /// Volume of the solid inside this part, m³ (at most the hull's).
    pub volume: f64,
    /// The part's concavity, metres (module docs).
    pub concavity: f64,
}

/// What [`decompose`] did to make the input a closed solid.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Repairs {
    /// Vertices merged into another at the same position.
    pub welded_vertices: usize,
    /// Triangles dropped for naming a vertex twice (after welding).
    pub dropped_triangles: usize,
    /// Triangles turned to agree with their neighbours and face outward.
    pub flipped_triangles: usize,
    /// Holes closed, each by a fan about its outline's centroid.
    pub holes_closed: usize,
    /// Parts with a cut whose section outline did not close (edges shared by more than two
    /// triangles can leave one), closed by a straight edge; 0 on a closed manifold input.
    pub parts_with_forced_caps: usize,
}

/// A decomposition: the parts and how well they fit.
#[derive(Debug, Clone)]
pub struct Decomposition {
    /// The parts; their hulls together contain the (repaired) solid.
    pub parts: Vec<Part>,
    /// Volume enclosed by the repaired mesh, m³.
    pub mesh_volume: f64,
    /// The largest part concavity, metres.
    pub concavity: f64,
    /// What was repaired first.
    pub repairs: Repairs,
}

/// Why a mesh could not be decomposed.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum DecomposeError {
    /// The mesh encloses no volume once repaired (flat, or every triangle degenerate).
    NotSolid {
        /// The enclosed volume found, m³.
        volume: f64,
    },
    /// An option is out of range: concavity not positive and finite, or zero parts.
    BadOptions,
    /// A part's hull could not be built (not expected: a part's corners lie in the mesh's
    /// bounds, which [`TriMesh`] keeps finite and in range).
    Hull(ConvexHullError),
}

impl fmt::Display for DecomposeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotSolid { volume } => write!(
                f,
                "the mesh encloses no volume to decompose ({volume:e} m³ once welded, oriented and closed)"
            ),
            Self::BadOptions => f.write_str(
                "decomposition options out of range: max_concavity must be positive and finite, max_parts at least 1",
            ),
            Self::Hull(e) => write!(f, "a part's convex hull could not be built: {e}"),
        }
    }
}

impl std::error::Error for DecomposeError {}

/// Surface samples for concavity lie at most this fraction of the allowed concavity apart
/// on large triangles: a pocket between samples is missed by at most about half of it.
const SAMPLE_SPACING_OF_LIMIT: f64 = 0.5;

/// Decomposes the solid bounded by `mesh` into nearly convex parts (module docs).
///
/// # Errors
/// [`DecomposeError::NotSolid`] when the repaired mesh encloses no volume;
/// [`DecomposeError::BadOptions`] for options out of range.
pub fn decompose(mesh: &TriMesh, options: &Options) -> Result<Decomposition, DecomposeError> {
    let concavity_ok = options.max_concavity.is_finite() && options.max_concavity > 0.0;
    let empty_ok = (0.0..=1.0).contains(&options.max_empty_fraction);
    if !concavity_ok || !empty_ok || options.max_parts == 0 {
        return Err(DecomposeError::BadOptions);
    }
    let solid = solid::prepare(mesh)?;
    let mesh_volume = solid.piece.volume();
    let limit = options.max_concavity * solid.diagonal;
    let spacing = SAMPLE_SPACING_OF_LIMIT * limit;
    let root = Fitted::new(solid.piece, spacing).ok_or(DecomposeError::NotSolid {
        volume: mesh_volume,
    })?;
    // Bounds this close count as touching: far below any concavity worth a part.
    let slack = 1e-6 * solid.diagonal;
    let pieces = match options.method {
        Method::CutSearch => {
            let cut = cut_search::cut_until(root, limit, options.max_parts, options.threads);
            merge::merge_within(cut, limit, options.max_parts, slack, options.threads)
        }
        Method::Relaxation => relaxation::relax(
            root,
            limit,
            options.max_parts,
            options.max_empty_fraction,
            slack,
            options.threads,
        ),
    };
    let mut repairs = solid.repairs;
    repairs.parts_with_forced_caps = pieces.iter().filter(|p| p.piece.forced_caps > 0).count();
    // Each part's checked hull, of every corner of its piece: a few thousand points on a
    // fine mesh, on threads.
    let parts = parallel::map_in_order(&pieces, options.threads, |p| {
        Ok(Part {
            hull: p.polyhedron().map_err(DecomposeError::Hull)?,
            volume: p.volume,
            concavity: p.concavity,
        })
    })
    .into_iter()
    .collect::<Result<Vec<Part>, DecomposeError>>()?;
    let concavity = parts.iter().map(|p| p.concavity).fold(0.0, f64::max);
    Ok(Decomposition {
        parts,
        mesh_volume,
        concavity,
        repairs,
    })
}
