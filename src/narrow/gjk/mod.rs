//! GJK distance and EPA penetration between any two convex shapes given by support maps.
//!
//! - [`gjk_distance`]: the distance between two convex sets, with witnesses, by the
//!   Gilbert–Johnson–Keerthi algorithm (van den Bergen's formulation with a relative
//!   termination test), the signed-volume sub-distance of [`simplex`], an optional
//!   warm start ([`GjkCache`]) and an optional Nesterov-accelerated search direction
//!   (Montaut, Le Lidec, Petrik, Sivic and Carpentier, "Collision detection accelerated: an
//!   optimization perspective", RSS 2022).
//! - [`epa::penetration`]: the penetration depth of two overlapping sets from GJK's final
//!   simplex (expanding polytope algorithm, van den Bergen 2001).
//! - [`signed_distance_convex`]: both together for shapes seen as a core plus a radius
//!   ([`Rounded`]), answering with a [`ShapeDistance`] under its contract.
//!
//! # Frames
//! Shape A is at the origin of the query frame; B is placed by `pose_ab`. Every point and
//! direction in and out is in A's frame. The Minkowski difference is `A − B`; its point
//! closest to the origin is `v`, and the normal A→B of a separated pair is `−v / |v|`.
//!
//! # Rounded shapes
//! The support map of a sphere (or of a capsule's caps) is curved everywhere, so GJK on it
//! only converges to its tolerance. [`Rounded`] views a sphere as a point plus a radius and
//! a capsule as a segment plus a radius; GJK and EPA then run on the cores (polytopes, on
//! which GJK terminates exactly) and the radii are subtracted at the end.

pub mod epa;
pub mod simplex;

use crate::budget::WorkClock;
use crate::geometry::{Capsule, Segment, Sphere, SupportMap};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{DistanceBound, Reached, ShapeDistance};
pub use epa::{EpaOutcome, EpaResult, EpaWorkspace};
pub use simplex::{Simplex, SupportPoint};

/// Multiple of `f64::EPSILON × scale` (scale: the largest support point seen) under which
/// the distance is rounding noise: GJK then answers [`GjkOutcome::Touching`].
pub(crate) const ROUNDING_ULPS: f64 = 64.0;

/// Parameters of [`gjk_distance`] and [`epa::penetration`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GjkParams {
    /// Relative tolerance: stop when the upper bound `|v|` and the lower bound of the
    /// distance differ by at most `rel_tol · |v| + abs_tol`.
    pub rel_tol: f64,
    /// EPA's relative tolerance on the depth: stop when the support value along the
    /// nearest face's normal exceeds the face's distance by at most `epa_rel_tol · depth`
    /// (+ the absolute floor). On polytopes a loose value stops early on nearly coplanar
    /// faces (1e-7 gave depths 4e-9 short for two identical boxes offset by 1e-7); on curved
    /// shapes a tight one can exhaust the polytope's capacity (then EPA falls back).
    pub epa_rel_tol: f64,
    /// Absolute tolerance, metres, added to the rounding floor `ROUNDING_ULPS · ε · scale`.
    pub abs_tol: f64,
    /// Iteration cap for GJK and (separately) for EPA.
    pub max_iterations: u32,
    /// Use the Nesterov-accelerated search direction; the final iterations always run plain
    /// GJK so that the stopping test certifies the answer.
    pub accelerated: bool,
}

impl Default for GjkParams {
    fn default() -> Self {
        Self {
            rel_tol: 1e-10,
            epa_rel_tol: 1e-10,
            abs_tol: 0.0,
            max_iterations: 128,
            accelerated: false,
        }
    }
}

/// Warm start kept between frames for one pair: the last separating direction (A's frame)
/// and where the shapes' support searches ended.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GjkCache {
    /// The last `v` (closest point of `A − B` to the origin), or zero for none.
    pub direction: DVec3,
    /// The support search hints of A and B ([`SupportMap::support_from`]).
    pub support_hints: [u32; 2],
}

/// How GJK stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GjkOutcome {
    /// The sets are apart by [`GjkResult::distance`] > rounding, converged to tolerance: a
    /// support plane within `rel_tol` (plus rounding) of it, and its witnesses that far
    /// apart to the same tolerance.
    Separated,
    /// The distance is below the rounding floor (or `abs_tol`): the sets touch, or the
    /// origin lies on GJK's simplex to rounding — they may then overlap deeply; only EPA
    /// can tell. Witnesses are valid; the normal is certified only by
    /// [`signed_distance_convex`], which checks it against the support functions.
    Touching,
    /// The origin is exactly inside GJK's simplex: the sets overlap (or touch exactly); the
    /// distance is 0 and the depth is EPA's job.
    Penetrating,
    /// The iteration cap was hit, or rounding stopped the descent (no step made the
    /// simplex closer, or its witnesses parted from `|v|`) short of the tolerance: the
    /// distance lies between [`GjkResult::lower_bound`] and `distance`, an upper bound (a
    /// real distance between the witnesses).
    ///
    /// Rounding stops it on curved shapes: near a rim the last simplex holds nearly equal
    /// points, whose step gains less than an ulp of `|v|²` while the support plane is still
    /// 1e-10–1e-7 (relative) short; on 3 % of the apart cylinder–box and cylinder–cylinder
    /// pairs placed around a rim (`tests.rs`).
    DidNotConverge,
    /// A support plane proved the sets farther apart than the caller's stop distance
    /// ([`gjk_distance_until`]): [`GjkResult::lower_bound`] exceeds it, and `distance` is an
    /// upper bound (a real distance between points of the two sets).
    Beyond,
}

/// The answer of [`gjk_distance`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GjkResult {
    /// How it stopped.
    pub outcome: GjkOutcome,
    /// Distance, metres, ≥ 0 (0 when penetrating).
    pub distance: f64,
    /// Witness on A (A's frame).
    pub point_a: DVec3,
    /// Witness on B (A's frame); `point_a − point_b = v`.
    pub point_b: DVec3,
    /// Iterations (support calls after the first).
    pub iterations: u32,
    /// The final simplex (EPA's start when penetrating).
    pub simplex: Simplex,
    /// `point_a − point_b`, the point of `A − B` closest to the origin (A's frame).
    pub v: DVec3,
    /// A lower bound of the distance, metres, rounding included: the farthest support
    /// plane found (for [`GjkOutcome::Beyond`], above the stop distance), or 0 when none
    /// lay beyond the origin.
    pub lower_bound: f64,
}

impl GjkResult {
    /// Unit normal A→B: `−v / |v|`, from the plane of the final simplex when it is a
    /// triangle (accurate even when `|v|` is rounding-sized); zero when penetrating.
    ///
    /// PERF: computed on demand, since distance-only callers (BVH bounds, broad culling)
    /// would otherwise pay a cross product, a square root and a division on the query's
    /// critical path (about 30 ns of a 380 ns query on 8-vertex hulls).
    #[must_use]
    pub fn normal(&self) -> DVec3 {
        if self.outcome == GjkOutcome::Penetrating {
            DVec3::ZERO
        } else {
            separating_normal(&self.simplex, self.v)
        }
    }
}

/// The support point of `A − B` along `d` (A's frame); `hints` are A's and B's support
/// search hints.
// PERF: inlined so that `d` stays in registers; through a call it was stored as scalars
// and reloaded as a pair, stalling store forwarding (a fifth of the support time).
#[inline(always)]
fn support<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    d: DVec3,
    hints: &mut [u32; 2],
) -> SupportPoint {
    let pa = a.support_from(d, &mut hints[0]);
    let pb = pose_ab
        .transform_point(b.support_from(pose_ab.inverse_transform_vector(-d), &mut hints[1]));
    SupportPoint {
        w: pa - pb,
        a: pa,
        b: pb,
    }
}

/// The smallest offset that counts at coordinates of magnitude `scale`: the absolute
/// tolerance plus the rounding of `ROUNDING_ULPS` ulps (GJK's and EPA's).
#[inline]
fn floor(params: &GjkParams, scale: f64) -> f64 {
    params.abs_tol + ROUNDING_ULPS * f64::EPSILON * scale
}

/// How a converged search ends: touching when the distance is rounding noise, else apart.
fn settled(distance: f64, floor: f64) -> GjkOutcome {
    if distance <= floor {
        GjkOutcome::Touching
    } else {
        GjkOutcome::Separated
    }
}

/// A unit normal A→B to try when the descent stalls: the normal of the triangle the last
/// segment made with the rejected support point `w` when that is well shaped, else
/// [`separating_normal`]'s.
fn stall_normal(simplex: &Simplex, w: DVec3, v: DVec3) -> DVec3 {
    let p = simplex.points();
    if p.len() == 2
        && let Some(n) = triangle_normal([p[0].w, p[1].w, w], v)
    {
        return n;
    }
    separating_normal(simplex, v)
}

/// The unit normal of triangle `w` facing away from `v` (A→B when `v` is GJK's point),
/// `None` when the triangle is too thin for its normal to be trusted (sine of its angle at
/// `w[0]` below 1e-3).
#[inline(always)]
fn triangle_normal(w: [DVec3; 3], v: DVec3) -> Option<DVec3> {
    let (e1, e2) = (w[1] - w[0], w[2] - w[0]);
    let n = e1.cross(e2);
    let nn = n.length_squared();
    if nn > 1e-6 * e1.length_squared() * e2.length_squared() {
        let n = if n.dot(v) > 0.0 { -n } else { n };
        return Some(n * (1.0 / nn.sqrt()));
    }
    None
}

fn magnitude(p: &SupportPoint) -> f64 {
    p.a.abs().max_element().max(p.b.abs().max_element())
}

/// The distance between convex shapes `a` (at the origin) and `b` (placed by `pose_ab`).
///
/// Never NaN for finite input: the sub-distance never divides by a vanishing determinant,
/// and every exit is labelled by [`GjkOutcome`]. `cache` is read for the start direction and
/// updated with the final one.
#[must_use]
pub fn gjk_distance<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    params: &GjkParams,
    cache: &mut GjkCache,
) -> GjkResult {
    gjk_distance_until(a, b, pose_ab, params, cache, f64::INFINITY)
}

/// [`gjk_distance`] that stops as soon as a support plane proves the sets more than
/// `stop_above` metres apart: the outcome is then [`GjkOutcome::Beyond`], with a lower
/// bound above `stop_above` (rounding included) and the distance of the points found so
/// far as an upper bound. Otherwise exactly [`gjk_distance`]'s answer.
#[must_use]
pub fn gjk_distance_until<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    params: &GjkParams,
    cache: &mut GjkCache,
    stop_above: f64,
) -> GjkResult {
    let guess = if cache.direction.is_finite() && cache.direction != DVec3::ZERO {
        cache.direction
    } else if pose_ab.translation != DVec3::ZERO {
        -pose_ab.translation
    } else {
        DVec3::X
    };
    let mut hints = cache.support_hints;
    let result = descend(
        params,
        guess,
        stop_above,
        #[inline(always)]
        |d| support(a, b, pose_ab, d, &mut hints),
    );
    if result.v != DVec3::ZERO {
        cache.direction = result.v;
    }
    cache.support_hints = hints;
    result
}

/// GJK's descent from `guess` (the start direction is `−guess`), with `support(d)` the
/// support point of `A − B` along `d` in A's frame; stops with [`GjkOutcome::Beyond`] once a
/// support plane is more than `stop_above` metres from the origin.
#[inline(always)]
fn descend(
    params: &GjkParams,
    guess: DVec3,
    stop_above: f64,
    mut support: impl FnMut(DVec3) -> SupportPoint,
) -> GjkResult {
    let first = support(-guess);
    let mut simplex = Simplex::single(first);
    let mut v = first.w;
    let mut scale = magnitude(&first);
    let mut accelerated = params.accelerated;
    let mut dir = v;
    let mut last_w = first.w;
    let mut outcome = GjkOutcome::DidNotConverge;
    let mut lower_bound = 0.0;
    let mut iterations = 0;
    while iterations < params.max_iterations {
        let dist2 = v.length_squared();
        let floor = floor(params, scale);
        if dist2 == 0.0 {
            outcome = GjkOutcome::Penetrating;
            break;
        }
        if dist2 <= floor * floor {
            outcome = GjkOutcome::Touching;
            break;
        }
        if accelerated {
            let k = f64::from(iterations);
            let momentum = (k + 1.0) / (k + 3.0);
            let y = v * momentum + last_w * (1.0 - momentum);
            dir = dir * momentum + y * (1.0 - momentum);
            if dir.length_squared() == 0.0 || !dir.is_finite() {
                accelerated = false;
                dir = v;
            }
        } else {
            dir = v;
        }
        iterations += 1;
        let p = support(-dir);
        if !p.w.is_finite() {
            break;
        }
        scale = scale.max(magnitude(&p));
        let dist = dist2.sqrt();
        // `p.w` minimises `x · dir` over `A − B`, so every point lies beyond the plane ⟂
        // `dir` through it: the distance is at least `p.w · dir / |dir|`, less the rounding
        // floor.
        let along = p.w.dot(dir);
        if along > 0.0 {
            let dir_length = if accelerated { dir.length() } else { dist };
            let plane = along / dir_length - floor;
            lower_bound = f64::max(lower_bound, plane);
            if plane > stop_above {
                outcome = GjkOutcome::Beyond;
                break;
            }
        }
        let gap = dist2 - v.dot(p.w);
        let converged = gap <= params.rel_tol * dist2 + floor * dist;
        if converged || simplex.contains(p.w) {
            if accelerated {
                // The test only certifies the plain direction: switch to it and re-check.
                accelerated = false;
                continue;
            }
            // A support point already in the simplex: the simplex holds the answer, and
            // what is left of the gap is the sub-distance's rounding of `v`'s direction
            // (first order in the plane, second order in `|v|`).
            outcome = settled(dist, floor);
            break;
        }
        last_w = p.w;
        simplex.push(p);
        let Some(v_new) = simplex.reduce_if_closer(dist2) else {
            // No progress: rounding limit, short of the tolerance (`converged` is false).
            // The previous (better) simplex is kept.
            if accelerated {
                accelerated = false;
                continue;
            }
            // The plane across the stalled step's triangle (or the simplex's own) is
            // often the true normal where `v`'s direction is not: on a flat contact `v`
            // tilts by rounding, and a wide face then leaves `v`'s plane 1e-8 short.
            iterations += 1;
            let n = stall_normal(&simplex, p.w, v);
            let plane = -n.dot(support(n).w) - floor;
            lower_bound = f64::max(lower_bound, plane);
            let certified = dist - lower_bound <= params.rel_tol * dist + floor;
            // Without a plane beyond the origin (not seen in the suites: 20,000 rim pairs,
            // the oracle suite) the answer is the one from before this check existed.
            outcome = if certified || lower_bound <= 0.0 {
                settled(dist, floor)
            } else {
                GjkOutcome::DidNotConverge
            };
            break;
        };
        v = v_new;
    }
    if v.length_squared() == 0.0 {
        outcome = GjkOutcome::Penetrating;
    }
    let c = simplex.closest();
    let dist = v.length();
    let witnessed2 = (c.a - c.b).length_squared();
    // `v` is the sub-distance's projection, the witnesses its weights applied to the
    // support points; on a simplex of nearly equal points the two part (by 1e-8 relative
    // near a rim), and `|v|` is then no bound at all. Compared squared: `|w − d| > tol`.
    let tol = floor(params, scale) + params.rel_tol * dist;
    let parted = witnessed2 > (dist + tol) * (dist + tol)
        || (dist > tol && witnessed2 < (dist - tol) * (dist - tol));
    if outcome == GjkOutcome::Separated && parted {
        outcome = GjkOutcome::DidNotConverge;
    }
    GjkResult {
        outcome,
        distance: match outcome {
            GjkOutcome::Penetrating => 0.0,
            GjkOutcome::Separated | GjkOutcome::Touching => dist,
            GjkOutcome::DidNotConverge | GjkOutcome::Beyond => witnessed2.sqrt(),
        },
        point_a: c.a,
        point_b: c.b,
        iterations,
        simplex,
        v,
        lower_bound,
    }
}

/// `−v / |v|`; for a triangle simplex holding `v` inside, the triangle's unit normal
/// (the same direction in exact arithmetic, since `v` is then the origin's projection on its
/// plane, but computed from edges of the shapes' size instead of the rounding-sized `v`).
///
/// For a segment simplex `v` is recomputed from its endpoint nearer the origin, `p`, as
/// `p − (p·e / e·e) e` (`e` the segment): the convex combination `λ₀ w₀ + λ₁ w₁` carries an
/// error of `ε · |w_far|`, which tilted the normal of a point 5e-10 off a 2e4-wide box by
/// 3e-3 rad; from the near endpoint the error is `ε · |p|`.
// PERF: one normalisation per call, of the direction returned (each costs a square root
// and a division on the query's critical path).
fn separating_normal(simplex: &Simplex, v: DVec3) -> DVec3 {
    let p = simplex.points();
    if p.len() == 2 {
        let w = simplex.weights();
        let (near, far) = if w[0] >= w[1] {
            (p[0].w, p[1].w)
        } else {
            (p[1].w, p[0].w)
        };
        let e = far - near;
        let ee = e.length_squared();
        if ee > 0.0 {
            let n = e * (near.dot(e) / ee) - near;
            if n.dot(v) < 0.0 {
                return n.normalize_or_zero();
            }
        }
    }
    if p.len() == 3
        && let Some(n) = triangle_normal([p[0].w, p[1].w, p[2].w], v)
    {
        return n;
    }
    -v.normalize_or_zero()
}

/// Whether `n` is an outward normal of `A − B` at the origin, to rounding: the support
/// value `h(n)` is within the rounding floor of 0 (or below).
fn certifies_touching<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    params: &GjkParams,
    n: DVec3,
) -> bool {
    let p = support(a, b, pose_ab, n, &mut [0; 2]);
    let floor = params.abs_tol + ROUNDING_ULPS * f64::EPSILON * magnitude(&p);
    p.w.dot(n) <= floor
}

/// A convex shape seen as a core (a support map) swept by a ball of `radius` metres.
#[derive(Debug, Clone, Copy)]
pub struct Rounded<'s, S: ?Sized> {
    /// The core, local frame.
    pub core: &'s S,
    /// Radius, metres, ≥ 0.
    pub radius: f64,
}

/// The core of a sphere: its centre.
pub static POINT: Sphere = Sphere { radius: 0.0 };

impl<'s, S: SupportMap + ?Sized> Rounded<'s, S> {
    /// A core with a radius.
    #[must_use]
    pub fn new(core: &'s S, radius: f64) -> Self {
        debug_assert!(radius >= 0.0 && radius.is_finite());
        Self { core, radius }
    }

    /// A shape with no radius.
    #[must_use]
    pub fn plain(core: &'s S) -> Self {
        Self::new(core, 0.0)
    }
}

impl Rounded<'static, Sphere> {
    /// A sphere as its centre ([`POINT`]) plus its radius.
    #[must_use]
    pub fn sphere(sphere: &Sphere) -> Self {
        Rounded::new(&POINT, sphere.radius)
    }
}

/// The core segment of a capsule (pass it to [`Rounded::new`] with the capsule's radius).
#[must_use]
pub fn capsule_core(capsule: &Capsule) -> Segment {
    capsule.segment()
}

/// What [`signed_distance_convex`] ran and how each part ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ConvexOutcome {
    /// GJK's outcome on the cores.
    pub gjk: GjkOutcome,
    /// EPA's, when it ran (cores penetrating or touching).
    pub epa: Option<EpaOutcome>,
}

/// The signed distance between two rounded convex shapes, under the contract of
/// [`crate::narrow::contact`]: GJK on the cores; when they overlap or touch, EPA on the
/// cores; then the radii are subtracted along the normal.
///
/// When no normal is defined (both shapes reduce to the same point), the normal is `+X`,
/// as the closed forms of [`crate::narrow::pairs`] choose.
#[must_use]
pub fn signed_distance_convex<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &Rounded<'_, A>,
    b: &Rounded<'_, B>,
    pose_ab: &Isometry,
    params: &GjkParams,
    cache: &mut GjkCache,
    workspace: &mut EpaWorkspace,
) -> (ShapeDistance, ConvexOutcome) {
    let clock = &mut WorkClock::default();
    let (reached, outcome) = signed_distance_convex_within(
        a,
        b,
        pose_ab,
        params,
        cache,
        workspace,
        clock,
        f64::INFINITY,
    );
    // An unlimited clock never stops EPA; a fallback's answer is its lower end.
    (reached.at_lower(), outcome)
}

/// [`signed_distance_convex`] with EPA polling `clock` ([`epa::penetration`]): exact, or,
/// when EPA ended short of its tolerance ([`EpaResult::depth_lower`] below the depth),
/// bounds between its fallback's depth (the lower bound of the signed distance, with its
/// normal and witnesses) and its polytope's (the upper bound): [`Reached::Resolved`] when
/// rounding broke the polytope, [`Reached::Bounded`] when the clock stopped it or it ran
/// out of room. GJK stopped short of its tolerance ([`GjkOutcome::DidNotConverge`]) with a
/// separating plane gives [`Reached::Resolved`] between that plane and its witnesses'
/// distance; without one, EPA decides as for touching shapes.
///
/// Shapes proven more than `limit` metres apart (signed distance) get
/// [`Reached::Exact`] with a lower bound above `limit` as their distance instead of the
/// exact value ([`gjk_distance_until`]), GJK's normal and its witnesses of the points found
/// so far; `f64::INFINITY` asks the exact distance whatever it is.
#[allow(clippy::too_many_arguments)]
pub fn signed_distance_convex_within<A: SupportMap + ?Sized, B: SupportMap + ?Sized>(
    a: &Rounded<'_, A>,
    b: &Rounded<'_, B>,
    pose_ab: &Isometry,
    params: &GjkParams,
    cache: &mut GjkCache,
    workspace: &mut EpaWorkspace,
    clock: &mut WorkClock,
    limit: f64,
) -> (Reached, ConvexOutcome) {
    let radii = a.radius + b.radius;
    let g = gjk_distance_until(a.core, b.core, pose_ab, params, cache, limit + radii);
    let g_normal = g.normal();
    let gjk_only = ConvexOutcome {
        gjk: g.outcome,
        epa: None,
    };
    if g.outcome == GjkOutcome::Beyond {
        let normal = g_normal.try_normalize().unwrap_or(DVec3::X);
        let answer = ShapeDistance {
            distance: g.lower_bound - radii,
            point_a: g.point_a + normal * a.radius,
            point_b: g.point_b - normal * b.radius,
            normal,
        };
        return (Reached::Exact(answer), gjk_only);
    }
    // Stopped short of its tolerance with a separating plane: the distance lies between
    // the plane and the witnesses' distance, stated as rounding-limited bounds.
    if g.outcome == GjkOutcome::DidNotConverge && g.lower_bound > 0.0 {
        let normal = g_normal.try_normalize().unwrap_or(DVec3::X);
        let bound = DistanceBound::new(
            g.lower_bound.min(g.distance) - radii,
            g.distance - radii,
            normal,
            g.point_b - normal * b.radius,
        );
        return (Reached::Resolved(bound), gjk_only);
    }
    // The depth's lower bound when EPA left a gap.
    let mut depth_lower = None;
    let (core, normal, epa) = match g.outcome {
        GjkOutcome::Separated | GjkOutcome::Beyond => (
            (g.distance, g.point_a, g.point_b),
            g_normal,
            None::<EpaOutcome>,
        ),
        GjkOutcome::Touching
            if g_normal != DVec3::ZERO
                && certifies_touching(a.core, b.core, pose_ab, params, g_normal) =>
        {
            ((g.distance, g.point_a, g.point_b), g_normal, None)
        }
        // No plane proved the shapes apart: they may overlap, which only EPA can tell.
        GjkOutcome::Touching | GjkOutcome::Penetrating | GjkOutcome::DidNotConverge => {
            let e = epa::penetration(
                a.core, b.core, pose_ab, &g.simplex, params, workspace, clock,
            );
            // Stopped, or a fallback whose polytope left a gap: the depth is bounded.
            if e.outcome == EpaOutcome::Stopped || e.depth_lower < e.depth {
                depth_lower = Some(e.depth_lower);
            }
            if g.outcome == GjkOutcome::Touching && e.depth <= 0.0 {
                (
                    (g.distance, g.point_a, g.point_b),
                    e.normal,
                    Some(e.outcome),
                )
            } else {
                (
                    (-e.depth.max(0.0), e.point_a, e.point_b),
                    e.normal,
                    Some(e.outcome),
                )
            }
        }
    };
    let normal = if normal.is_finite() && normal != DVec3::ZERO {
        normal.normalize()
    } else {
        DVec3::X
    };
    let (d, pa, pb) = core;
    let answer = ShapeDistance {
        distance: d - radii,
        point_a: pa + normal * a.radius,
        point_b: pb - normal * b.radius,
        normal,
    };
    let reached = match depth_lower {
        None => Reached::Exact(answer),
        Some(lower) => {
            let bound = DistanceBound {
                lower: answer.distance,
                upper: (-lower - radii).max(answer.distance),
                normal,
                point_a: answer.point_a,
                point_b: answer.point_b,
            };
            // Rounding, not the clock or the polytope's room, left the gap.
            if epa == Some(EpaOutcome::RoundingLimited) {
                Reached::Resolved(bound)
            } else {
                Reached::Bounded(bound)
            }
        }
    };
    (
        reached,
        ConvexOutcome {
            gjk: g.outcome,
            epa,
        },
    )
}

#[cfg(test)]
mod tests;
