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

use super::cap_outline::CapOutlines;
use super::nearest::SampleGrid;
use super::piece::{Plane, lattice_samples};
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
    /// The piece's cut planes and caps.
    pub caps: &'a CapOutlines<'a>,
    /// A cut being weighed, not made yet: hull faces on it are left out (its cap is not
    /// known; the cut's own result is measured in full once made).
    pub pending: Option<Plane>,
    /// Hull lattice spacing, metres.
    pub spacing: f64,
}

/// The concavity of a piece whose hull is `hull` and whose surface samples below the hull are
/// `samples` (module docs), metres, when it is at most `bar`; above `bar`, some value
/// between `bar` and the concavity (the measure stops as soon as it knows it is above).
/// `f64::INFINITY` asks for the concavity whatever it is.
pub(super) fn concavity(
    hull: &[HullTriangle],
    samples: &[DVec3],
    surface: &Surface,
    bar: f64,
) -> f64 {
    let depth = deepest_samples(hull, samples, 1)
        .first()
        .map_or(0.0, |&(depth, _)| depth)
        .max(0.0);
    if depth > bar {
        return depth;
    }
    bridge_height(hull, surface, depth, bar)
}

/// The `k` samples deepest below the hull's boundary, with their depths (metres, negative
/// outside), deepest first; fewer when there are fewer samples, none when the hull has no
/// triangles.
///
/// A sample's depth is its least height below a face plane: once one plane shows it no
/// deeper than the `k`-th deepest so far, the rest cannot put it among the `k`.
pub(super) fn deepest_samples(
    hull: &[HullTriangle],
    samples: &[DVec3],
    k: usize,
) -> Vec<(f64, DVec3)> {
    let mut deepest: Vec<(f64, DVec3)> = Vec::with_capacity(k + 1);
    if hull.is_empty() || k == 0 {
        return deepest;
    }
    // The faces that dismissed the latest samples, most recent first: samples come
    // triangle by triangle, so the next one is most often dismissed by one of them, in a
    // few tests rather than a scan of the hull.
    let mut recent = [0; RECENT_FACES];
    'samples: for &p in samples {
        let bar = if deepest.len() < k {
            f64::NEG_INFINITY
        } else {
            deepest[k - 1].0
        };
        let height = |t: &HullTriangle| t.offset - t.normal.dot(p);
        if let Some(r) = recent.iter().position(|&f| height(&hull[f]) <= bar) {
            recent[..=r].rotate_right(1);
            continue;
        }
        let mut least = f64::INFINITY;
        for (i, t) in hull.iter().enumerate() {
            least = least.min(height(t));
            if least <= bar {
                recent.rotate_right(1);
                recent[0] = i;
                continue 'samples;
            }
        }
        let at = deepest.partition_point(|&(d, _)| d >= least);
        deepest.insert(at, (least, p));
        deepest.truncate(k);
    }
    deepest
}

/// How many of the faces that dismissed the latest samples [`deepest_samples`] tries first.
const RECENT_FACES: usize = 8;

/// The greatest distance from the hull's boundary (off the cut planes) to the surface, or
/// `floor` when that is greater; once above `bar`, some value between `bar` and that.
///
/// A maximum of nearest distances: a point with a sample within the greatest so far cannot
/// raise it, so each point is first dismissed by the cheapest test that can (the samples
/// next to it, then the section outline), then by whether it lies on a cap, and only then
/// pays for a whole nearest-sample search. The largest triangles, where a bridge is most
/// likely, go first: the sooner the greatest so far is high, the more points the cheap
/// tests dismiss (the maximum is the same in any order).
fn bridge_height(hull: &[HullTriangle], surface: &Surface, floor: f64, bar: f64) -> f64 {
    let reach = hull
        .iter()
        .flat_map(|t| t.corners)
        .map(|c| c.abs().max_element())
        .fold(0.0, f64::max);
    let on_plane = ON_CUT_RELATIVE * reach.max(f64::MIN_POSITIVE);
    let mut lattice = Vec::new();
    let mut highest: f64 = floor;
    let mut hint = 0;
    let cuts = &surface.caps.piece.cuts;
    let mut largest_first: Vec<(f64, &HullTriangle)> = hull
        .iter()
        .map(|t| {
            let [a, b, c] = t.corners;
            ((b - a).cross(c - a).length_squared(), t)
        })
        .collect();
    largest_first.sort_unstable_by(|x, y| y.0.total_cmp(&x.0));
    for &(_, t) in &largest_first {
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
        let on_caps: Vec<usize> = (0..cuts.len()).filter(|&k| on(&cuts[k])).collect();
        let outline = (!on_caps.is_empty()).then(|| surface.caps.of(&on_caps));
        lattice.clear();
        lattice.extend_from_slice(&t.corners);
        let [a, b, c] = t.corners;
        lattice_samples(a, b, c, surface.spacing, MAX_HULL_DIVISIONS, &mut lattice);
        for &p in &lattice {
            let within = |q: &DVec3| (*q - p).length_squared() <= highest * highest;
            if surface
                .grid
                .near_within(p, highest, surface.member, &mut hint)
                || surface.extra.iter().any(within)
            {
                continue;
            }
            // Caps are sampled along their outlines only: the nearest sample to a point
            // inside one is far, and its search the dearest of all.
            if outline.as_ref().is_some_and(|o| o.contains(p)) {
                continue;
            }
            let Some(near) = surface.grid.nearest_above(p, highest, surface.member) else {
                continue;
            };
            let near_extra = surface
                .extra
                .iter()
                .map(|&q| (q - p).length())
                .fold(f64::INFINITY, f64::min);
            let near = near.min(near_extra);
            if near.is_finite() {
                highest = highest.max(near);
                if highest > bar {
                    return highest;
                }
            }
        }
    }
    highest
}

/// Most divisions of a hull triangle's edge when sampling the hull.
const MAX_HULL_DIVISIONS: usize = 16;

/// A hull triangle within this fraction of the coordinates' magnitude of a cut plane lies on it.
const ON_CUT_RELATIVE: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::deepest_samples;
    use crate::geometry::ConvexPolyhedron;
    use crate::math::DVec3;
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;

    /// The `k` deepest against every face scanned for every sample, on random hulls with
    /// samples inside and outside, walked both in a spatially coherent order (as a piece's
    /// samples come) and shuffled.
    #[test]
    fn the_deepest_samples_agree_with_a_scan_of_every_face() {
        let mut r = rng(4501);
        let (mut inside, mut outside) = (0, 0);
        for round in 0..200 {
            let corners: Vec<DVec3> = (0..r.random_range(4..60))
                .map(|_| point_in_cube(&mut r, 1.0))
                .collect();
            let Some(hull) = ConvexPolyhedron::quick_hull_triangles(&corners) else {
                continue;
            };
            let mut samples: Vec<DVec3> = (0..r.random_range(1..400))
                .map(|_| point_in_cube(&mut r, 1.1))
                .collect();
            if round % 2 == 0 {
                samples.sort_by(|a, b| a.x.total_cmp(&b.x));
            }
            let depth = |p: DVec3| {
                hull.iter()
                    .map(|t| t.offset - t.normal.dot(p))
                    .fold(f64::INFINITY, f64::min)
            };
            let mut expected: Vec<f64> = samples.iter().map(|&p| depth(p)).collect();
            inside += expected.iter().filter(|&&d| d > 0.0).count();
            outside += expected.iter().filter(|&&d| d < 0.0).count();
            expected.sort_by(|a, b| b.total_cmp(a));
            for k in [1, 3, 7] {
                let found = deepest_samples(&hull, &samples, k);
                assert_eq!(found.len(), k.min(samples.len()));
                for (i, &(d, p)) in found.iter().enumerate() {
                    assert_eq!(d, expected[i], "round {round}, k {k}, rank {i}");
                    assert_eq!(d, depth(p));
                }
            }
        }
        assert!(
            inside > 1000 && outside > 1000,
            "{inside} inside, {outside} outside"
        );
    }
}
