//! The quality-first method: concavity-driven cut search (in the manner of CoACD, greedy).
//!
//! The most concave piece is cut next, by the plane that leaves the least concavity in its
//! two halves; cutting stops when every piece is within the allowed concavity or the part
//! count is reached. Neighbouring pieces whose union stays within the allowed concavity are
//! then merged back ([`super::merge::merge_within`]), so no cut survives that was not needed.
//!
//! A candidate plane is scored on a thinned copy of the piece (at most [`SCORE_SAMPLES`]
//! surface samples and [`SCORE_EDGES`] edges): each half is the samples on its side plus the
//! points where edges cross the plane (the section's outline), its concavity measured as in
//! `concavity.rs` on those. Candidates are the three coordinate axes and the piece's
//! principal axes, each at [`OFFSETS`] evenly spaced offsets and through the
//! [`DEEPEST_SAMPLES`] surface samples deepest below the hull; the best few are
//! refined by halving the step around them, then cut exactly, and the best exact cut is kept
//! (the thinned score cannot tell apart cuts closer than its samples).
//!
//! Only the finalists' scores are needed in full: once [`EXACT_FINALISTS`] scores are known,
//! a candidate is measured only until it is known to score worse than all of them (its
//! halves' concavity measured up to a bar, see `concavity.rs`). The finalists are the same
//! as with every score in full, for any thread count. Likewise an exact cut is measured
//! only until it is known to score worse than the best exact cut so far.
//!
//! Citation: X. Wei, M. Liu, Z. Ling, H. Su, "Approximate Convex Decomposition for 3D Meshes
//! with Collision-Aware Concavity and Tree Search", SIGGRAPH 2022 (CoACD).

use super::cap_outline::CapOutlines;
use super::concavity::{Surface, concavity, deepest_samples};
use super::fitted::Fitted;
use super::nearest::SampleGrid;
use super::parallel::map_in_order;
use super::piece::Plane;
use crate::geometry::ConvexPolyhedron;
use crate::geometry::pca::{point_moments, principal_axes};
use crate::math::{DVec3, bounds_of};
use std::sync::{Mutex, PoisonError};

/// Most surface samples a candidate is scored on.
const SCORE_SAMPLES: usize = 1200;
/// Most edges whose crossings outline a candidate's section.
const SCORE_EDGES: usize = 3000;
/// A candidate's hull is sampled at least this fraction of the piece's extent apart.
const SCORE_LATTICE_DIVISIONS: f64 = 8.0;
/// Offsets tried along each axis.
const OFFSETS: usize = 9;
/// Refinement rounds around the best candidate (each halves the step).
const REFINE_ROUNDS: usize = 3;
/// Cosine above which a principal axis counts as along a coordinate axis (about 8°).
const NEAR_PARALLEL: f64 = 0.99;
/// Samples deepest below the piece's hull that candidate planes are also put through: a
/// concave edge is where a cut through it may remove the concavity whole.
const DEEPEST_SAMPLES: usize = 3;
/// Candidates cut exactly after the thinned scoring, best first.
const EXACT_FINALISTS: usize = 4;
/// Weight of the lesser half's concavity in a candidate's score (the greater half's is 1):
/// among cuts that leave the same worst half, prefer the one that also flattens the other.
const LESSER_HALF_WEIGHT: f64 = 0.25;

/// Cuts the most concave piece until all are within `limit` metres or there are
/// `max_parts`; returns the pieces (not yet merged). Each cut's candidates are weighed on up
/// to `threads` threads; the pieces are the same for any count.
pub(super) fn cut_until(root: Fitted, limit: f64, max_parts: usize, threads: usize) -> Vec<Fitted> {
    let mut pieces = vec![root];
    // Pieces no plane could cut, set aside with their concavity.
    let mut uncuttable = Vec::new();
    while pieces.len() + uncuttable.len() < max_parts {
        let Some(worst) = most_concave(&pieces) else {
            break;
        };
        if pieces[worst].concavity <= limit {
            break;
        }
        let piece = pieces.swap_remove(worst);
        match best_cut(&piece, limit, threads) {
            Some((a, b)) => pieces.extend([a, b]),
            None => uncuttable.push(piece),
        }
    }
    pieces.extend(uncuttable);
    pieces
}

fn most_concave(pieces: &[Fitted]) -> Option<usize> {
    (0..pieces.len()).max_by(|&a, &b| pieces[a].concavity.total_cmp(&pieces[b].concavity))
}

/// Cuts a measured piece exactly and measures both halves.
pub(super) fn cut_fitted(piece: &Fitted, plane: &Plane) -> Option<(Fitted, Fitted)> {
    let (below, above) = piece.piece.cut(plane)?;
    Some((
        Fitted::new(below, piece.spacing)?,
        Fitted::new(above, piece.spacing)?,
    ))
}

/// The cut that leaves the least concavity in the halves of `piece` (see the module docs):
/// the [`EXACT_FINALISTS`] best candidates by the thinned score, each refined, are cut
/// exactly and the best exact result is kept. Each stage's candidates are weighed on up to
/// `threads` threads.
fn best_cut(piece: &Fitted, limit: f64, threads: usize) -> Option<(Fitted, Fitted)> {
    let samples = thinned(&piece.samples, SCORE_SAMPLES);
    let scorer = Scorer::new(piece, &samples);
    let deepest: Vec<DVec3> =
        deepest_samples(&piece.hull.triangles, &piece.samples, DEEPEST_SAMPLES)
            .into_iter()
            .map(|(_, p)| p)
            .collect();
    let axes = candidate_axes(scorer.samples);
    let mut candidates: Vec<(Plane, f64)> = Vec::new(); // (plane, step)
    for &axis in &axes {
        let (lo, hi) = extent_along(scorer.samples, axis);
        let step = (hi - lo) / (OFFSETS + 1) as f64;
        if !step.is_finite() || step <= 0.0 {
            continue;
        }
        let even = (1..=OFFSETS).map(|k| lo + step * k as f64);
        let through_deepest = deepest.iter().map(|p| p.dot(axis));
        for offset in even.chain(through_deepest) {
            candidates.push((
                Plane {
                    normal: axis,
                    offset,
                },
                step,
            ));
        }
    }
    // Only the best few scores matter: once that many are known, a candidate is measured
    // only until it is known to score worse than all of them.
    let leaders = Leaders::new(EXACT_FINALISTS);
    let mut scored: Vec<(f64, Plane, f64)> =
        map_in_order(&candidates, threads, |&(plane, step)| {
            let bar = leaders.bar();
            let score = scorer.score(&plane, bar)?;
            if score <= bar {
                leaders.offer(score);
            }
            Some((score, plane, step))
        })
        .into_iter()
        .flatten()
        .collect();
    // The scores above their bar are only known to be above it, but so are they above the
    // finalists' scores: the finalists are the same as if every score were measured whole.
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    scored.truncate(EXACT_FINALISTS);
    let finalists = map_in_order(&scored, threads, |&(score, plane, step)| {
        refined(&scorer, score, plane, step)
    });
    // Near convex halves score alike up to the thinned samples' noise: the planes through
    // the deepest sample, which a concave edge calls for, are always cut exactly too.
    let through_deepest = deepest.first().into_iter().flat_map(|p| {
        axes.iter().map(move |&normal| Plane {
            normal,
            offset: normal.dot(*p),
        })
    });
    // A finalist that refining did not move can be a plane through the deepest sample
    // too (about one cut in twenty): each plane is cut once.
    let mut planes: Vec<Plane> = Vec::with_capacity(EXACT_FINALISTS + 6);
    for plane in finalists.into_iter().chain(through_deepest) {
        if !planes.contains(&plane) {
            planes.push(plane);
        }
    }
    // Only the best exact cut is kept: once one is known, a cut is measured only until it
    // is known to score worse.
    let best_exact = Leaders::new(1);
    map_in_order(&planes, threads, |plane| {
        let (score, a, b) = exact_cut(piece, plane, limit, best_exact.bar())?;
        best_exact.offer(score);
        Some((score, a, b))
    })
    .into_iter()
    .flatten()
    .min_by(|x, y| x.0.total_cmp(&y.0))
    .map(|(_, a, b)| (a, b))
}

/// The lowest scores the jobs of one stage have measured in full so far, shared across the
/// stage's threads: a job measured only up to [`Leaders::bar`] still knows whether it is
/// among them.
struct Leaders {
    /// How many lowest scores are kept.
    kept: usize,
    /// They, ascending.
    scores: Mutex<Vec<f64>>,
}

impl Leaders {
    fn new(kept: usize) -> Self {
        Self {
            kept,
            scores: Mutex::new(Vec::with_capacity(kept + 1)),
        }
    }

    /// The highest of the kept scores, or infinity while fewer are known: a score above it
    /// is among them no more.
    fn bar(&self) -> f64 {
        let scores = self.scores.lock().unwrap_or_else(PoisonError::into_inner);
        if scores.len() < self.kept {
            f64::INFINITY
        } else {
            scores[self.kept - 1]
        }
    }

    /// Keeps `score`, measured in full, if it is among the lowest.
    fn offer(&self, score: f64) {
        let mut scores = self.scores.lock().unwrap_or_else(PoisonError::into_inner);
        let at = scores.partition_point(|&s| s <= score);
        scores.insert(at, score);
        scores.truncate(self.kept);
    }
}

/// Cuts `piece` by `plane` and measures both halves, with the cut's [`exact_score`]; `None`
/// when the cut leaves a side empty or scores above `bar` (then the halves are measured
/// only as far as it takes to know).
fn exact_cut(piece: &Fitted, plane: &Plane, limit: f64, bar: f64) -> Option<(f64, Fitted, Fitted)> {
    let (below, above) = piece.piece.cut(plane)?;
    // The score is at least either half's concavity less `limit`.
    let bar_a = raised(bar + limit);
    let a = Fitted::new_up_to(below, piece.spacing, bar_a)?;
    if a.concavity > bar_a {
        return None;
    }
    // Above `limit`, the other half adds no finished share, and the score rises with it.
    let finished = finished_share(&[&a], piece.volume, limit);
    let bar_b = limit.max(other_half_bar(a.concavity, bar + limit * finished));
    let b = Fitted::new_up_to(above, piece.spacing, bar_b)?;
    if b.concavity > bar_b {
        return None;
    }
    Some((exact_score(&a, &b, piece.volume, limit), a, b))
}

/// Moves `plane` by halving steps while the thinned score improves.
fn refined(scorer: &Scorer, mut score: f64, mut plane: Plane, mut step: f64) -> Plane {
    for _ in 0..REFINE_ROUNDS {
        step *= 0.5;
        for offset in [plane.offset - step, plane.offset + step] {
            let moved = Plane { offset, ..plane };
            if let Some(s) = scorer.score(&moved, score)
                && s < score
            {
                (score, plane) = (s, moved);
            }
        }
    }
    plane
}

/// The exact score of a cut into `a` and `b`, metres (lower is better): the worse half's
/// concavity, a quarter of the other's, less up to `limit` for the share of the piece's
/// volume the cut finishes (halves within the limit). The last term settles near ties, as
/// a U's first cut: taking off a large finished part leaves less to cut.
fn exact_score(a: &Fitted, b: &Fitted, volume: f64, limit: f64) -> f64 {
    a.concavity.max(b.concavity) + LESSER_HALF_WEIGHT * a.concavity.min(b.concavity)
        - limit * finished_share(&[a, b], volume, limit)
}

/// The share of a piece's `volume` (m³) that those of `halves` within `limit` finish, 0 to 1.
fn finished_share(halves: &[&Fitted], volume: f64, limit: f64) -> f64 {
    let finished: f64 = halves
        .iter()
        .filter(|h| h.concavity <= limit)
        .map(|h| h.volume)
        .sum();
    if volume > 0.0 {
        (finished / volume).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The coordinate axes and the piece's principal axes, a principal axis within a few
/// degrees of a coordinate axis left out (a model's flat faces and creases usually follow
/// its coordinate axes; a principal axis just off one cuts them into slivers).
fn candidate_axes(samples: &[DVec3]) -> Vec<DVec3> {
    let axes = principal_axes(&point_moments(samples).covariance);
    let mut candidates = vec![DVec3::X, DVec3::Y, DVec3::Z];
    for axis in [axes.x_axis, axes.y_axis, axes.z_axis] {
        if candidates.iter().all(|c| c.dot(axis).abs() < NEAR_PARALLEL) {
            candidates.push(axis);
        }
    }
    candidates
}

/// The least and greatest of `points` along `axis`, metres.
pub(super) fn extent_along(points: &[DVec3], axis: DVec3) -> (f64, f64) {
    points
        .iter()
        .map(|p| p.dot(axis))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), d| {
            (lo.min(d), hi.max(d))
        })
}

/// A thinned copy of a piece that candidate planes are scored on.
struct Scorer<'a> {
    samples: &'a [DVec3],
    grid: SampleGrid<'a>,
    edges: Vec<[DVec3; 2]>,
    /// The piece's cap outlines, gathered once for every candidate.
    caps: CapOutlines<'a>,
    /// Hull lattice spacing, metres: coarser than the piece's for speed.
    spacing: f64,
}

impl<'a> Scorer<'a> {
    fn new(piece: &'a Fitted, samples: &'a [DVec3]) -> Self {
        let (lo, hi) = bounds_of(samples.iter().copied());
        Self {
            samples,
            grid: SampleGrid::new(samples),
            edges: thinned(&piece.piece.surface_edges(), SCORE_EDGES),
            caps: CapOutlines::new(&piece.piece),
            spacing: piece
                .spacing
                .max((hi - lo).max_element() / SCORE_LATTICE_DIVISIONS),
        }
    }

    /// The candidate's score, metres (lower is better), when at most `bar`; above `bar`,
    /// some value between `bar` and the score. `None` when a side is empty (or, for a
    /// score above `bar`, may be).
    fn score(&self, plane: &Plane, bar: f64) -> Option<f64> {
        let section: Vec<DVec3> = self
            .edges
            .iter()
            .filter_map(|&[p, q]| {
                let (sp, sq) = (plane.signed_distance(p), plane.signed_distance(q));
                ((sp <= 0.0) != (sq <= 0.0)).then(|| p + (q - p) * (sp / (sp - sq)))
            })
            .collect();
        let below: Vec<bool> = self
            .samples
            .iter()
            .map(|&p| plane.signed_distance(p) <= 0.0)
            .collect();
        let flipped = Plane {
            normal: -plane.normal,
            offset: -plane.offset,
        };
        let a = self.half_concavity(&below, true, *plane, &section, bar)?;
        if a > bar {
            return Some(a);
        }
        let b = self.half_concavity(&below, false, flipped, &section, other_half_bar(a, bar))?;
        Some(a.max(b) + LESSER_HALF_WEIGHT * a.min(b))
    }

    /// The concavity of the half on side `side` (per sample in `below`), cut off by `cut`,
    /// up to `bar` (see [`concavity`]).
    fn half_concavity(
        &self,
        below: &[bool],
        side: bool,
        cut: Plane,
        section: &[DVec3],
        bar: f64,
    ) -> Option<f64> {
        // The half's samples, then the section outline: the hull's input.
        let mut points: Vec<DVec3> = Vec::with_capacity(self.samples.len() + section.len());
        points.extend(
            (0..self.samples.len())
                .filter(|&i| below[i] == side)
                .map(|i| self.samples[i]),
        );
        let half = points.len();
        if half == 0 {
            return None;
        }
        points.extend_from_slice(section);
        // A half that spans no solid (a sliver) holds no concavity.
        let Some(hull) = ConvexPolyhedron::quick_hull_triangles(&points) else {
            return Some(0.0);
        };
        let surface = Surface {
            grid: &self.grid,
            member: &|i| below[i] == side,
            extra: section,
            caps: &self.caps,
            pending: Some(cut),
            spacing: self.spacing,
        };
        Some(concavity(&hull, &points[..half], &surface, bar))
    }
}

/// The concavity `b` of one half above which a score `max(a, b) + w·min(a, b)` is above
/// `bar`, the other half's concavity being `a` (at most `bar`), raised by a relative
/// [`BAR_MARGIN`] so that rounding cannot put a score just over `bar` at or under it.
fn other_half_bar(a: f64, bar: f64) -> f64 {
    let w = LESSER_HALF_WEIGHT;
    let b = if bar - w * a >= a {
        bar - w * a
    } else {
        (bar - a) / w
    };
    b + BAR_MARGIN * bar.abs().max(a)
}

/// `bar` raised by the relative [`BAR_MARGIN`].
fn raised(bar: f64) -> f64 {
    bar + BAR_MARGIN * bar.abs()
}

/// Relative margin by which a derived bar is raised ([`other_half_bar`], [`raised`]): far
/// above the rounding of a score, so a measure cut short at the bar always scores above
/// the bar it was derived from.
const BAR_MARGIN: f64 = 1e-9;

/// Every `len / most`-th item, so at most about `most` remain, spread over the input.
fn thinned<T: Copy>(items: &[T], most: usize) -> Vec<T> {
    let stride = items.len().div_ceil(most.max(1)).max(1);
    items.iter().step_by(stride).copied().collect()
}

#[cfg(test)]
mod tests {
    use super::{SCORE_SAMPLES, Scorer, thinned};
    use crate::geometry::decompose::fitted::Fitted;
    use crate::geometry::decompose::piece::Plane;
    use crate::geometry::decompose::solid::prepare;
    use crate::geometry::decompose::tests::{BAR_FRACTIONS, check_barred};
    use crate::math::DVec3;
    use crate::test_support::meshes::{comb_prism, torus};
    use crate::test_support::{point_in_cube, rng};

    /// A candidate scored up to a bar scores as in full when that is within the bar, and
    /// otherwise above the bar and no more than in full: on planes through a torus and a
    /// comb, at bars below, at and above each score.
    #[test]
    fn a_score_up_to_a_bar_is_exact_within_it_and_bounded_above_it() {
        let mut r = rng(5302);
        let mut counts = (0, 0);
        for (mesh, half) in [(torus(1.0, 0.3, 24, 12), 1.3), (comb_prism(3), 2.0)] {
            let solid = prepare(&mesh).expect("closed test mesh").piece;
            let piece = Fitted::new(solid, 0.05).expect("solid");
            let samples = thinned(&piece.samples, SCORE_SAMPLES);
            let scorer = Scorer::new(&piece, &samples);
            let centre = (piece.bounds.0 + piece.bounds.1) * 0.5;
            for round in 0..40 {
                let normal = point_in_cube(&mut r, 1.0).normalize_or(DVec3::X);
                let plane = Plane {
                    normal,
                    offset: normal.dot(centre + point_in_cube(&mut r, 0.5 * half)),
                };
                let Some(full) = scorer.score(&plane, f64::INFINITY) else {
                    continue;
                };
                for bar in BAR_FRACTIONS.map(|f| f * full) {
                    // A side is empty only when the full score says so.
                    let barred = scorer.score(&plane, bar).expect("both sides hold samples");
                    check_barred(full, bar, barred, &mut counts, &format!("round {round}"));
                }
            }
        }
        assert!(
            counts.0 > 150 && counts.1 > 150,
            "{counts:?} (within, above)"
        );
    }
}
