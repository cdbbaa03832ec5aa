//! The answer for one candidate pair, doing only what the frame's [`Query`] asks:
//! mesh–mesh by exact BVH queries (warm starts, contact sets), every other pair through the
//! [`dispatch`](super::dispatch)er. Conservative answers ([`conservative`]: separating-axis
//! bounds, or world boxes) go to pairs left no time for their exact one, and the box answer
//! is also the worker pool's fallback when answering a pair panicked (a bug, never client
//! input).
//!
//! Each function returns the pair's [`Answer`] and, when the query asks for contacts and the
//! pair touches, appends its manifold (at most [`MANIFOLD_POINTS`] points) to
//! `contacts`. Whether the pair is *reported* is decided by the caller from the answer.

use super::{ContactPoint, PairResult, Query};
use crate::bounding::Aabb;
use crate::broad::CandidatePair;
use crate::budget::WorkClock;
use crate::math::{DVec3, Pose, conservative_slack};
use crate::narrow::contact::{DistanceBound, Manifold, Reached, ShapeDistance};
use crate::narrow::dispatch::{self, NarrowScratch};
use crate::narrow::mesh_mesh::frontier::FrontierAnswer;
use crate::narrow::mesh_mesh::{
    DistanceCache, MeshDistance, MeshMeshWorkspace, Proximity, contacts_mesh_mesh_within,
    intersects_mesh_mesh_within,
};
use crate::narrow::{MANIFOLD_POINTS, reduce_manifold};
use crate::narrow::{MeshShape, Shape};
use crate::scene::Body;
use std::ops::ControlFlow;

/// One pair's answer before the report decision.
#[derive(Debug, Clone, Copy)]
pub(super) struct Answer {
    /// The pair record (contacts not yet linked).
    pub result: PairResult,
    /// Whether the shapes touch or intersect (for a box answer: may touch).
    pub touching: bool,
    /// When the pair was proven farther apart than its margins: a lower bound of its true
    /// distance, metres (rounding included), which later frames keep as a
    /// [`Separation`](super::separation::Separation); `None` otherwise.
    pub apart_by: Option<f64>,
}

/// Mesh–mesh scratch of one thread, reused across pairs and frames.
#[derive(Debug, Default)]
pub(super) struct MeshScratch {
    pub traversal: MeshMeshWorkspace,
    /// Every intersection segment end of the pair being answered, A's frame.
    points: Vec<DVec3>,
    /// The contact normal (A's triangle normal) of each entry of `points`.
    normals: Vec<DVec3>,
    /// Indices into `points` kept by the manifold reduction.
    kept: Vec<usize>,
}

impl MeshScratch {
    /// Capacities of the manifold scratch vectors (tests check they stop growing).
    #[cfg(test)]
    pub fn capacities(&self) -> [usize; 3] {
        [
            self.points.capacity(),
            self.normals.capacity(),
            self.kept.capacity(),
        ]
    }
}

/// Every pair but mesh–mesh, through the [`dispatch`](super::dispatch)er: the exact signed
/// distance (closed forms, GJK/EPA, or a convex shape against a mesh's triangles) when the
/// query needs a distance or a touching decision, and the manifold when it asks contacts
/// and the shapes touch. Everything in world frame; exact to the methods' tolerance (error
/// bound: GJK's relative tolerance times the distance plus 64 ulps of the coordinates, plus
/// the gap of a [`Reached::Resolved`] answer, which rounding kept from its tolerance).
pub(super) fn direct(
    pair: &CandidatePair,
    (a, sa): (&Body, &Shape),
    (b, sb): (&Body, &Shape),
    query: Query,
    scratch: &mut NarrowScratch,
    manifold: &mut Manifold,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let pose_ab = Pose::relative(&a.pose, &b.pose);
    let limit = reporting_limit(query, a, b);
    let reached = dispatch::distance_within(sa, sb, &pose_ab, limit, scratch);
    match reached {
        Reached::Bounded(bound) if bound.upper.is_finite() => {
            return from_bound(pair, (a, b), &bound, query, contacts);
        }
        // Stopped before it found anything: the world boxes say more.
        Reached::Bounded(_) => {
            let grown = |body: &Body| body.world_bounds.grown(body.margin);
            return boxes(pair, &grown(a), &grown(b), query, contacts);
        }
        Reached::Exact(_) | Reached::Resolved(_) => {}
    }
    // Finished: exact, or short of the tolerance by the rounding gap `width()`.
    let d = reached.at_lower();
    let scale = d
        .point_a
        .abs()
        .max_element()
        .max(d.point_b.abs().max_element())
        + a.pose.position.abs().max_element();
    let error_bound = 1e-10 * d.distance.abs() + 64.0 * f64::EPSILON * scale + reached.width();
    let mut result = in_world(pair, a, &d, error_bound, true);
    let touching = d.distance <= 0.0;
    if query.contacts && touching {
        scratch.manifold_cut_short = false;
        dispatch::manifold(sa, sb, &pose_ab, &d, scratch, manifold);
        // The frame's clock stopped the manifold (a compound's): fewer points than exact.
        result.exact = !scratch.manifold_cut_short;
        let normal = a.pose.transform_vector(manifold.normal);
        for p in manifold.points() {
            contacts.push(ContactPoint {
                pair: 0,
                point_a: a.pose.transform_point(p.point_a),
                point_b: a.pose.transform_point(p.point_b),
                normal,
                distance: p.distance,
                error_bound: result.error_bound,
            });
        }
    }
    Answer {
        result,
        touching,
        apart_by: None,
    }
}

/// How far apart a pair's answer must be exact, metres: without `DISTANCE` nothing beyond
/// the margins is reported (and touching is within them), so a query may stop there.
fn reporting_limit(query: Query, a: &Body, b: &Body) -> f64 {
    if query.distance {
        f64::INFINITY
    } else {
        a.margin + b.margin
    }
}

/// The record of `pair` from its answer `d` in A's frame, mapped to world frame by A's
/// pose, with `error_bound` and whether it is `exact`.
fn in_world(
    pair: &CandidatePair,
    a: &Body,
    d: &ShapeDistance,
    error_bound: f64,
    exact: bool,
) -> PairResult {
    PairResult {
        a: pair.a,
        b: pair.b,
        distance: d.distance,
        error_bound,
        point_a: a.pose.transform_point(d.point_a),
        point_b: a.pose.transform_point(d.point_b),
        normal: a.pose.transform_vector(d.normal),
        exact,
        first_contact: 0,
        contact_count: 0,
    }
}

/// A one-point manifold from a pair record: its witnesses and normal, `distance` (−depth)
/// and the record's error bound.
fn witness_contact(result: &PairResult, distance: f64) -> ContactPoint {
    ContactPoint {
        pair: 0,
        point_a: result.point_a,
        point_b: result.point_b,
        normal: result.normal,
        distance,
        error_bound: result.error_bound,
    }
}

/// Mesh–mesh (meshes are surfaces): the exact distance when the query needs one (`CLOSE`
/// for pairs within their margins, `DISTANCE` for all; warm-started from the pair's `cache`), the reduced intersection set when it asks `CONTACTS`,
/// else (`OVERLAP` alone) an intersection test, which stops at the first proof. Every
/// step polls `clock` (leaf pair by leaf pair); a pair it stopped is answered
/// conservatively, from what it found so far or from its world boxes.
///
/// A `CLOSE` pair beyond its margins (and no `DISTANCE` asked) says distance `+∞`: it is
/// not reported, and it touches nothing; its [`Answer::apart_by`] is the lower bound the
/// search proved on the way
/// ([`proximity_mesh_mesh`](crate::narrow::mesh_mesh::proximity_mesh_mesh)). Without a distance, a touching pair's record says distance 0 (intersecting surfaces),
/// error bound 0, and takes its witnesses and normal from the first contact when contacts
/// were asked; with `OVERLAP` alone it has none (points and normal all zero).
pub(super) fn mesh_mesh(
    pair: &CandidatePair,
    (a, ma): (&Body, &MeshShape),
    (b, mb): (&Body, &MeshShape),
    query: Query,
    cache: &mut DistanceCache,
    (scratch, clock): (&mut MeshScratch, &mut WorkClock),
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let pose_ab = Pose::relative(&a.pose, &b.pose);
    // `CLOSE` without `DISTANCE` needs the distance only of pairs within their margins: a
    // tolerance query, which stops at the first triangle pair close enough, rules the
    // others out (its lower bounds prune far pairs near the roots). Its float distances
    // could call a grazing contact apart, so when touching matters (`OVERLAP`,
    // `CONTACTS`) the exact predicates confirm before the pair is dismissed.
    let margins = a.margin + b.margin;
    // PERF: a pair whose last closest triangle pair is still within the margins needs no
    // proximity search (it would answer "within"): resting and sliding pairs.
    if query.close && !query.distance && !ma.cached_pair_within(mb, &pose_ab, cache, margins) {
        let traversal = &mut scratch.traversal;
        let Some(proximity) = ma.proximity_within(mb, &pose_ab, margins, traversal, clock) else {
            return mesh_unsearched(pair, (a, b), query, contacts);
        };
        if let Proximity::Apart { lower_bound } = proximity {
            let touching = if query.overlap || query.contacts {
                let (ta, tb) = (&ma.overlap_tree, &mb.overlap_tree);
                intersects_mesh_mesh_within(ta, tb, &pose_ab, traversal, clock)
            } else {
                Some(false)
            };
            match touching {
                Some(false) => return apart(pair, Some(lower_bound)),
                Some(true) => {}
                None => return mesh_unsearched(pair, (a, b), query, contacts),
            }
        }
    }
    let mut known = None;
    if query.close || query.distance {
        let d = ma.distance_to_within(mb, &pose_ab, cache, &mut scratch.traversal, clock);
        if clock.stopped() {
            return mesh_distance_stopped(pair, (a, b), query, &d, contacts);
        }
        known = Some(KnownDistance {
            distance: d.distance,
            error_bound: d.error_bound,
            point_a: d.point_a,
            point_b: d.point_b,
        });
    }
    mesh_mesh_tail(
        pair,
        (a, ma),
        (b, mb),
        &pose_ab,
        query,
        known,
        (scratch, clock),
        contacts,
    )
}

/// A mesh pair whose distance search the clock stopped (the frame's slice ended, or its
/// client is gone): [`mesh_bounded`] with the search's lower bound (`d.distance −
/// d.error_bound`; the truth is at most the closest pair found, `d.distance`) and that
/// pair's witnesses, as [`mesh_mesh_truncated`] answers the frontier's.
fn mesh_distance_stopped(
    pair: &CandidatePair,
    (a, b): (&Body, &Body),
    query: Query,
    d: &MeshDistance,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let bounds = (d.distance - d.error_bound, d.error_bound);
    let witnesses = Some((d.point_a, d.point_b));
    mesh_bounded(pair, (a, b), query, bounds, witnesses, contacts)
}

/// A mesh pair whose first test the clock stopped (the frame's deadline came near or its
/// slice ended, or its client is gone): known only by its world boxes ([`mesh_bounded`]
/// between their bounds).
fn mesh_unsearched(
    pair: &CandidatePair,
    (a, b): (&Body, &Body),
    query: Query,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let boxes = world_boxes(pair, a, b);
    let bounds = (boxes.distance, boxes.error_bound);
    mesh_bounded(pair, (a, b), query, bounds, None, contacts)
}

/// The exact distance of a mesh pair, witnesses in A's frame.
#[derive(Debug, Clone, Copy)]
struct KnownDistance {
    distance: f64,
    error_bound: f64,
    point_a: DVec3,
    point_b: DVec3,
}

/// What [`mesh_mesh`] does once the distance is known (when the query needs it): the
/// record's distance, witnesses and normal, the manifold when contacts are asked, and the
/// touching decision.
#[allow(clippy::too_many_arguments)]
fn mesh_mesh_tail(
    pair: &CandidatePair,
    (a, ma): (&Body, &MeshShape),
    (b, mb): (&Body, &MeshShape),
    pose_ab: &Pose,
    query: Query,
    known: Option<KnownDistance>,
    (scratch, clock): (&mut MeshScratch, &mut WorkClock),
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let mut result = empty_record(pair);
    let mut touching = None;
    if let Some(d) = known {
        result.distance = d.distance;
        result.error_bound = d.error_bound;
        result.point_a = a.pose.transform_point(d.point_a);
        result.point_b = a.pose.transform_point(d.point_b);
        result.normal = (result.point_b - result.point_a)
            .try_normalize()
            .unwrap_or(DVec3::X);
        touching = Some(d.distance <= 0.0);
    }
    if query.contacts && touching != Some(false) {
        let first = contacts.len();
        let finished = mesh_manifold(a, (ma, mb), pose_ab, (scratch, clock), contacts);
        if let Some(c) = contacts.get(first) {
            touching = Some(true);
            if !(query.close || query.distance) {
                (result.point_a, result.point_b, result.normal) = (c.point_a, c.point_b, c.normal);
            }
        } else if !finished {
            // Stopped before any intersection was found: the pair may touch; its one
            // contact is the record's witnesses (its distance's, or its boxes').
            touching = Some(true);
            if result.normal == DVec3::ZERO {
                let boxes = world_boxes(pair, a, b);
                (result.point_a, result.point_b, result.normal) =
                    (boxes.point_a, boxes.point_b, boxes.normal);
                result.error_bound = result.error_bound.max(boxes.error_bound);
            }
            contacts.push(witness_contact(&result, 0.0));
        } else if touching.is_none() {
            touching = Some(false);
        }
        // Stopped, the contacts found are real but perhaps not all of them.
        result.exact &= finished;
    }
    let touching = match touching {
        Some(known) => known,
        None => {
            let (ta, tb) = (&ma.overlap_tree, &mb.overlap_tree);
            let found = intersects_mesh_mesh_within(ta, tb, pose_ab, &mut scratch.traversal, clock);
            // Stopped before it found an intersection: the pair may touch.
            result.exact &= found.is_some();
            found.unwrap_or(true)
        }
    };
    Answer {
        result,
        touching,
        apart_by: None,
    }
}

/// A mesh pair whose budgeted frontier traversal finished (`frontier` is
/// [`Exact`](crate::budget::Completeness::Exact)): the record [`mesh_mesh`] gives,
/// with the distance and witnesses taken from the frontier instead of a second traversal
/// (the same minimum over all triangle pairs, with the same rounding bound; when several
/// triangle pairs share the minimum, as intersecting meshes do at 0, the witnesses may name
/// another of them). Contacts, overlap tests and everything else run as in [`mesh_mesh`].
/// The frontier's threshold must have been the margin sum, or with `DISTANCE` an upper
/// bound of the pair's distance (so a finished pair is always `maybe_close` then).
#[allow(clippy::too_many_arguments)]
pub(super) fn mesh_mesh_finished(
    pair: &CandidatePair,
    (a, ma): (&Body, &MeshShape),
    (b, mb): (&Body, &MeshShape),
    query: Query,
    frontier: &FrontierAnswer,
    cache: &mut DistanceCache,
    (scratch, clock): (&mut MeshScratch, &mut WorkClock),
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    debug_assert!(frontier.is_exact());
    let wants_distance = query.close || query.distance;
    let pose_ab = Pose::relative(&a.pose, &b.pose);
    let known = frontier
        .witnesses
        .filter(|_| frontier.maybe_close)
        .map(|w| KnownDistance {
            distance: frontier.distance_lower,
            // The exact query's rounding bound, whichever trees the frontier refined, so
            // that an unlimited budget gives its record bit for bit.
            error_bound: ma.rounding_with(mb, &pose_ab.to_isometry()),
            point_a: w.point_a,
            point_b: w.point_b,
        });
    if wants_distance && known.is_none() {
        // Proven beyond the margins: every triangle pair's distance exceeds them, which is
        // what [`mesh_mesh`]'s tolerance query would find. It then answers "far" unless
        // touching matters and the exact predicates find an intersection (a grazing
        // contact the float distances miss, or an upper bound under `DISTANCE` that
        // rounding undercut), where it computes the exact distance: so does this.
        let grazing = if query.overlap || query.contacts {
            let (ta, tb) = (&ma.overlap_tree, &mb.overlap_tree);
            match intersects_mesh_mesh_within(ta, tb, &pose_ab, &mut scratch.traversal, clock) {
                Some(found) => found,
                None => return mesh_unsearched(pair, (a, b), query, contacts),
            }
        } else {
            false
        };
        if query.distance || grazing {
            let mesh = (scratch, clock);
            return mesh_mesh(pair, (a, ma), (b, mb), query, cache, mesh, contacts);
        }
        // The frontier's lower bound may be a triangle distance, which rounding can put
        // above the truth.
        let rounding = ma.rounding_with(mb, &pose_ab.to_isometry());
        return apart(pair, Some(frontier.distance_lower - rounding));
    }
    mesh_mesh_tail(
        pair,
        (a, ma),
        (b, mb),
        &pose_ab,
        query,
        known.filter(|_| wants_distance),
        (scratch, clock),
        contacts,
    )
}

/// A mesh pair whose budgeted frontier traversal was cut short (`frontier` is
/// [`Truncated`](crate::budget::Completeness::Truncated), hence `maybe_close`):
/// [`mesh_bounded`] with the frontier's lower bound and error bound, and the closest
/// triangle pair it found so far (`distance_upper` apart) as witnesses.
pub(super) fn mesh_mesh_truncated(
    pair: &CandidatePair,
    (a, b): (&Body, &Body),
    query: Query,
    frontier: &FrontierAnswer,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    debug_assert!(!frontier.is_exact() && frontier.maybe_close);
    let bounds = (frontier.distance_lower, frontier.error_bound);
    let witnesses = frontier.witnesses.map(|w| (w.point_a, w.point_b));
    mesh_bounded(pair, (a, b), query, bounds, witnesses, contacts)
}

/// The conservative answer DESIGN §4 asks for of a mesh pair known only between bounds:
/// distance `lower` (never above the truth) with `error_bound` (`true ≤ distance +
/// error_bound`), `exact` false. The pair *may touch* when `lower ≤ 0`; its contact (when
/// asked) is then one point, the record's witnesses and normal, distance 0 (meshes have no
/// depth) with the record's error bound. Witnesses: the closest triangle pair found so far
/// (A's frame), else the points of the two world boxes nearest each other, with the box
/// normal.
fn mesh_bounded(
    pair: &CandidatePair,
    (a, b): (&Body, &Body),
    query: Query,
    (lower, error_bound): (f64, f64),
    witnesses: Option<(DVec3, DVec3)>,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let mut result = world_boxes(pair, a, b);
    if let Some((point_a, point_b)) = witnesses {
        let (point_a, point_b) = (
            a.pose.transform_point(point_a),
            a.pose.transform_point(point_b),
        );
        if let Some(normal) = (point_b - point_a).try_normalize() {
            (result.point_a, result.point_b, result.normal) = (point_a, point_b, normal);
        }
    }
    result.distance = lower;
    result.error_bound = error_bound;
    result.exact = false;
    let touching = result.distance <= 0.0;
    if query.contacts && touching {
        contacts.push(witness_contact(&result, 0.0));
    }
    Answer {
        result,
        touching,
        apart_by: None,
    }
}

/// The record of `pair` from its bodies' world boxes alone ([`boxes`]): their witnesses,
/// normal and error bound, for a mesh pair whose own search left none.
fn world_boxes(pair: &CandidatePair, a: &Body, b: &Body) -> PairResult {
    boxes(
        pair,
        &a.world_bounds,
        &b.world_bounds,
        Query::NONE,
        &mut Vec::new(),
    )
    .result
}

/// The answer for a pair beyond its margins under a query that does not ask the distance:
/// distance `+∞` (never reported), touching nothing; `apart_by` as [`Answer::apart_by`].
pub(super) fn apart(pair: &CandidatePair, apart_by: Option<f64>) -> Answer {
    let mut result = empty_record(pair);
    result.distance = f64::INFINITY;
    Answer {
        result,
        touching: false,
        apart_by,
    }
}

/// A mesh pair's record before anything is known: distance 0, no witnesses, exact.
fn empty_record(pair: &CandidatePair) -> PairResult {
    PairResult {
        a: pair.a,
        b: pair.b,
        distance: 0.0,
        error_bound: 0.0,
        point_a: DVec3::ZERO,
        point_b: DVec3::ZERO,
        normal: DVec3::ZERO,
        exact: true,
        first_contact: 0,
        contact_count: 0,
    }
}

/// Appends the manifold of two meshes (nothing when they do not intersect): the segment ends
/// of every intersecting triangle pair ([`contacts_mesh_mesh`]), reduced by
/// [`reduce_manifold`]. Depth is 0 (surfaces have no inside): `distance` 0 with the rounding
/// of the coordinates as error bound. One normal for the manifold: the sum of the contacts'
/// normals (A's triangle normals, A→B), each counted once per segment end, normalised; when
/// they cancel, the normal of the first kept point's contact.
fn mesh_manifold(
    a: &Body,
    (ma, mb): (&MeshShape, &MeshShape),
    pose_ab: &Pose,
    (scratch, clock): (&mut MeshScratch, &mut WorkClock),
    contacts: &mut Vec<ContactPoint>,
) -> bool {
    let MeshScratch {
        traversal,
        points,
        normals,
        kept,
    } = scratch;
    points.clear();
    normals.clear();
    let finished = contacts_mesh_mesh_within(
        &ma.overlap_tree,
        &mb.overlap_tree,
        pose_ab,
        traversal,
        clock,
        |c| {
            for end in c.segment {
                points.push(end);
                normals.push(c.normal);
            }
            ControlFlow::Continue(())
        },
    );
    reduce_manifold(points, kept);
    let Some(&first) = kept.first() else {
        return finished;
    };
    debug_assert!(kept.len() <= MANIFOLD_POINTS);
    let normal_a = normals
        .iter()
        .sum::<DVec3>()
        .try_normalize()
        .unwrap_or(normals[first]);
    let normal = a.pose.transform_vector(normal_a);
    for &i in kept.iter() {
        let point = a.pose.transform_point(points[i]);
        contacts.push(ContactPoint {
            pair: 0,
            point_a: point,
            point_b: point,
            normal,
            distance: 0.0,
            error_bound: conservative_slack(point.abs().max_element()),
        });
    }
    finished
}

/// The conservative answer of a pair left no time for its exact one (not a mesh–mesh pair):
/// the bounds of [`dispatch::distance_bound`] for capsules and cuboids among themselves
/// (exact to rounding for a capsule apart from the other core, and for two boxes apart
/// but within `enough`), else their margin-grown world boxes' answer ([`boxes`]).
///
/// From the bounds: the distance is their lower bound less the rounding of the relative
/// pose (a pair is reported close whenever the truth may be), the error bound reaches their
/// upper bound, the normal is their axis. It may touch when the lower bound is `≤ 0`; its
/// contact (when asked) is one point at that bound. Where the axes meet the depth (cores
/// overlapping, a box in the pair) the answer is the exact one's to rounding, but without
/// its witnesses or manifold, so it stays marked inexact.
pub(super) fn conservative(
    pair: &CandidatePair,
    (a, sa): (&Body, &Shape),
    (b, sb): (&Body, &Shape),
    query: Query,
    scratch: &mut NarrowScratch,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let pose_ab = Pose::relative(&a.pose, &b.pose).to_isometry();
    let enough = reporting_limit(query, a, b);
    let Some(bound) = dispatch::distance_bound(sa, sb, &pose_ab, enough) else {
        let grown = |body: &Body| body.world_bounds.grown(body.margin);
        return boxes(pair, &grown(a), &grown(b), query, contacts);
    };
    scratch.paths.separating_axes += 1;
    from_bound(pair, (a, b), &bound, query, contacts)
}

/// The conservative answer from bounds on a pair's signed distance (A's frame): the
/// distance is the lower bound less the rounding of the relative pose (a pair is reported
/// close whenever the truth may be), the error bound reaches the upper bound, the normal
/// and witnesses are the bounds'. It may touch when the lower bound is `≤ 0`; its contact
/// (when asked) is one point at that bound.
fn from_bound(
    pair: &CandidatePair,
    (a, b): (&Body, &Body),
    bound: &DistanceBound,
    query: Query,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let slack = conservative_slack(
        a.pose.position.abs().max_element() + b.pose.position.abs().max_element(),
    );
    let at_lower = ShapeDistance {
        distance: bound.lower - slack,
        ..bound.at_lower()
    };
    let error_bound = bound.upper - bound.lower + 2.0 * slack;
    let result = in_world(pair, a, &at_lower, error_bound, false);
    let touching = result.distance <= 0.0;
    if query.contacts && touching {
        contacts.push(witness_contact(&result, result.distance));
    }
    Answer {
        result,
        touching,
        apart_by: None,
    }
}

/// The conservative answer from two world boxes: their distance when apart, minus their
/// smallest overlap when they overlap (either way a lower bound of the shapes' signed
/// distance), with the sum of their diagonals (plus that overlap) as error bound, and
/// [`box_normal`];
/// the pair *may* touch when the boxes do. Its contact (when asked and the boxes touch) is one point: the box
/// witnesses, the box normal, distance 0 (the depth is unknown) with the box answer's error
/// bound, which covers the true depth.
pub(super) fn boxes(
    pair: &CandidatePair,
    a: &Aabb,
    b: &Aabb,
    query: Query,
    contacts: &mut Vec<ContactPoint>,
) -> Answer {
    let point_a = b.center().clamp(a.min, a.max);
    let point_b = point_a.clamp(b.min, b.max);
    let gap = (a.min - b.max).max(b.min - a.max).max(DVec3::ZERO);
    // Overlapping boxes: moving one by their smallest overlap along its axis separates the
    // boxes, hence the shapes, so the signed distance is at least minus that overlap (solid
    // shapes can penetrate; 0 would not be a lower bound).
    let overlap = (a.max.min(b.max) - a.min.max(b.min)).min_element().max(0.0);
    let distance = if gap == DVec3::ZERO {
        -overlap
    } else {
        gap.length()
    };
    let result = PairResult {
        a: pair.a,
        b: pair.b,
        distance,
        error_bound: (a.max - a.min).length() + (b.max - b.min).length() + overlap,
        point_a,
        point_b,
        normal: box_normal(a, b, gap),
        exact: false,
        first_contact: 0,
        contact_count: 0,
    };
    let touching = result.distance <= 0.0;
    if query.contacts && touching {
        contacts.push(witness_contact(&result, 0.0));
    }
    Answer {
        result,
        touching,
        apart_by: None,
    }
}

/// The normal A→B of two world boxes: along their gap when they are apart, else along the
/// axis on which they overlap least (the direction that separates them soonest), pointing
/// from A's centre towards B's. `gap` is the per-axis separation (zero where they overlap).
fn box_normal(a: &Aabb, b: &Aabb, gap: DVec3) -> DVec3 {
    let towards_b = b.center() - a.center();
    let sign = |axis: usize| if towards_b[axis] < 0.0 { -1.0 } else { 1.0 };
    if gap != DVec3::ZERO {
        let signed = DVec3::new(gap.x * sign(0), gap.y * sign(1), gap.z * sign(2));
        return signed.normalize();
    }
    let overlap = a.max.min(b.max) - a.min.max(b.min);
    let axis = if overlap.x <= overlap.y && overlap.x <= overlap.z {
        0
    } else if overlap.y <= overlap.z {
        1
    } else {
        2
    };
    let mut normal = DVec3::ZERO;
    normal[axis] = sign(axis);
    normal
}
