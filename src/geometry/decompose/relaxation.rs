//! The baseline: the relaxation strategy of the lectures.
//!
//! 1. Split top-down by each piece's oriented box: through the box's middle, across its
//!    longest axis, largest piece first, until there are [`LEAVES_PER_PART`] leaves per
//!    allowed part (at most [`MAX_LEAVES`]); a piece already within half the allowed
//!    concavity is a leaf as it is.
//! 2. Merge by volume ([`super::merge::merge_by_volume`]): the smallest piece with the
//!    neighbour whose union fills the most of its hull, while the hull's empty fraction
//!    stays within the threshold; then down to the part count.

use super::cut_search::{cut_fitted, extent_along};
use super::fitted::Fitted;
use super::merge::merge_by_volume;
use super::piece::Plane;
use crate::geometry::pca::{point_moments, principal_axes};

/// Leaves the split aims for, per allowed part.
const LEAVES_PER_PART: usize = 4;
/// Most leaves the split makes, whatever the part count.
const MAX_LEAVES: usize = 256;

/// Splits `root` into small leaves and merges them back (module docs); unions are weighed
/// on up to `threads` threads.
pub(super) fn relax(
    root: Fitted,
    limit: f64,
    max_parts: usize,
    max_empty: f64,
    slack: f64,
    threads: usize,
) -> Vec<Fitted> {
    let target = max_parts
        .saturating_mul(LEAVES_PER_PART)
        .clamp(1, MAX_LEAVES);
    let mut open = vec![root];
    let mut leaves = Vec::new();
    while open.len() + leaves.len() < target {
        let Some(largest) =
            (0..open.len()).max_by(|&a, &b| open[a].volume.total_cmp(&open[b].volume))
        else {
            break;
        };
        let piece = open.swap_remove(largest);
        if piece.concavity <= 0.5 * limit {
            leaves.push(piece);
            continue;
        }
        match box_split(&piece).and_then(|plane| cut_fitted(&piece, &plane)) {
            Some((a, b)) => open.extend([a, b]),
            None => leaves.push(piece),
        }
    }
    leaves.extend(open);
    merge_by_volume(leaves, max_empty, max_parts, slack, threads)
}

/// The plane through the middle of the piece's oriented box, across its longest axis.
fn box_split(piece: &Fitted) -> Option<Plane> {
    let points = &piece.hull.points;
    let axes = principal_axes(&point_moments(points).covariance);
    let (axis, (lo, hi)) = [axes.x_axis, axes.y_axis, axes.z_axis]
        .into_iter()
        .map(|a| (a, extent_along(points, a)))
        .max_by(|a, b| (a.1.1 - a.1.0).total_cmp(&(b.1.1 - b.1.0)))?;
    (hi > lo).then_some(Plane {
        normal: axis,
        offset: 0.5 * (lo + hi),
    })
}
