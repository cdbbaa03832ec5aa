//! How far a piece is from its convex hull: the concavity the methods drive down.
//!
//! The concavity of a piece (metres) is the larger of two one-sided distances, as in
//! CoACD's boundary Hausdorff distance:
//! - **surface below hull:** the greatest depth of a surface sample below the hull's
//!   boundary (a pocket the hull bridges);
//! - **hull above surface:** the greatest distance from a point of the hull's boundary to
//!   the piece's boundary (the bridge itself, which a thin part's pocket can leave far
//!   from any surface even when the pocket is shallow): to the nearest surface sample, or 0
//!   for a point of a hull face on a cut plane that lies on that cut's cap.
//!
//! Both are sampled, the second on a lattice of the hull's triangles about `spacing` apart.
//! Distances to the nearest surface sample carry the samples' spacing as a floor: a convex
//! piece measures up to about that, never 0 (the options' limit is twice the spacing).

use super::nearest::SampleGrid;
use super::piece::{Piece, Plane, lattice_samples};
use crate::geometry::HullTriangle;
use crate::math::DVec3;

/// What a hull is measured against.
pub(super) struct Surface<'a> {
    /// The surface samples, in a grid.
    pub grid: &'a SampleGrid<'a>,
    /// Which grid samples belong to this piece (a candidate half uses part of a grid).
    pub member: &'a dyn Fn(usize) -> bool,
    /// Further surface points not in the grid (a candidate cut's section outline).
    pub extra: &'a [DVec3],
    /// The piece (its cut planes and caps).
    pub piece: &'a Piece,
    /// A cut being weighed, not made yet: hull faces on it are left out (its cap is not
    /// known; the cut's own result is measured in full once made).
    pub pending: Option<Plane>,
    /// Hull lattice spacing, metres.
    pub spacing: f64,
}

/// The concavity of a piece whose hull is `hull` and whose surface samples below the hull are
/// `samples` (module docs), metres.
pub(super) fn concavity(hull: &[HullTriangle], samples: &[DVec3], surface: &Surface) -> f64 {
    let mut deepest: f64 = 0.0;
    for &p in samples {
        // The sample's depth is its least height below a plane: once one plane shows it no
        // deeper than the deepest so far, the rest cannot raise the maximum.
        let depth =
            hull.iter()
                .map(|t| t.offset - t.normal.dot(p))
                .try_fold(f64::INFINITY, |least, d| {
                    let least = least.min(d);
                    if least <= deepest { None } else { Some(least) }
                });
        if let Some(depth) = depth {
            deepest = depth;
        }
    }
    deepest.max(bridge_height(hull, surface))
}

/// The greatest distance from the hull's boundary (off the cut planes) to the surface.
fn bridge_height(hull: &[HullTriangle], surface: &Surface) -> f64 {
    let reach = hull
        .iter()
        .flat_map(|t| t.corners)
        .map(|c| c.abs().max_element())
        .fold(0.0, f64::max);
    let on_plane = ON_CUT_RELATIVE * reach.max(f64::MIN_POSITIVE);
    let mut lattice = Vec::new();
    let mut highest: f64 = 0.0;
    for t in hull {
        let on = |c: &Plane| {
            c.normal.dot(t.normal) > 0.0
                && t.corners
                    .iter()
                    .all(|&p| c.signed_distance(p).abs() <= on_plane)
        };
        if surface.pending.as_ref().is_some_and(on) {
            continue;
        }
        // Merged pieces can hold caps of one plane under several cut indices.
        let caps: Vec<usize> = (0..surface.piece.cuts.len())
            .filter(|&k| on(&surface.piece.cuts[k]))
            .collect();
        lattice.clear();
        lattice.extend_from_slice(&t.corners);
        let [a, b, c] = t.corners;
        lattice_samples(a, b, c, surface.spacing, MAX_HULL_DIVISIONS, &mut lattice);
        for &p in &lattice {
            let near_extra = surface
                .extra
                .iter()
                .map(|&q| (q - p).length())
                .fold(f64::INFINITY, f64::min);
            if near_extra <= highest {
                continue;
            }
            let Some(near) = surface.grid.nearest_above(p, highest, surface.member) else {
                continue;
            };
            let near = near.min(near_extra);
            // Last, as the dearest test: a point on a cut's cap is on the piece.
            let on_cap = !caps.is_empty() && surface.piece.on_caps(p, &caps);
            if near.is_finite() && !on_cap {
                highest = highest.max(near);
            }
        }
    }
    highest
}

/// Most divisions of a hull triangle's edge when sampling the hull.
const MAX_HULL_DIVISIONS: usize = 16;

/// A hull triangle within this fraction of the coordinates' magnitude of a cut plane lies on it.
const ON_CUT_RELATIVE: f64 = 1e-9;
