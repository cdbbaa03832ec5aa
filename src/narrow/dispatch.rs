//! The dispatcher: the only place that matches on the *pair* of shape kinds. It picks the
//! query for each pair, flips pairs given in non-canonical order (a closed form exists for
//! one order only) and answers in A's frame; the pipeline converts to world once.
//!
//! | pair | distance | manifold |
//! |---|---|---|
//! | sphere, capsule, cuboid among themselves; sphere–cylinder | closed forms ([`crate::narrow::pairs`]) | closed forms (≤ 4 points, box faces clipped) |
//! | a box with a cylinder, cone or convex hull | the box's face certificate when B overlaps under one face, lies over one, or lies beyond a face's plane by more than the limit ([`pairs::face_distance_cuboid_convex`]), else as the next row | as the next row |
//! | a cylinder with a capsule, box, cylinder, cone or hull | for a capsule whose core is out of the cylinder, the certified search along the core ([`pairs::distance_capsule_cylinder`]); else the cylinder's certificate when the depth under a cap or the side, or the distance over one, is proved by support points ([`pairs::certified_distance_cylinder_convex`]; either cylinder of a pair), after the box's; else as the next row | as the next row |
//! | a cylinder, cone or convex hull with any convex shape | GJK on the cores (stopped once a support plane proves the pair beyond the limit), EPA when they overlap ([`crate::narrow::gjk`]) | one point, the distance's witnesses, against a sphere; else reference-face clipping of the shapes' contact features from the distance's normal, ≤ 4 points ([`crate::narrow::convex_manifold`]) |
//! | a convex shape and a mesh | the nearest triangle through the mesh's RSS tree ([`crate::narrow::convex_mesh`]), each triangle by its closed form or GJK | the manifolds of the triangles the shape reaches, ghost normals removed, reduced to 4 points ([`crate::narrow::convex_mesh`]) |
//! | mesh–mesh | [`Route::MeshMesh`]: the BVH tandem queries with warm starts and the worker pool | intersection segments, reduced |
//! | a compound with anything | the part pairs the part tree cannot rule out, each by its row above, the smallest ([`crate::narrow::compound`]) | every touching part pair's manifold, reduced under the deepest one's normal |
//!
//! Canonical order: sphere < capsule < cuboid < cylinder < cone < convex < mesh < compound,
//! except that a compound is always answered as A (its queries take any B). GJK is
//! symmetric, so its pairs are answered in the order given.
//!
//! # Meshes are surfaces
//! A convex shape against a mesh is answered against the mesh's triangles (two-sided, no
//! thickness): the signed distance is the smallest over the triangles, negative when the
//! shape reaches through some triangle. A shape entirely inside a closed mesh without
//! touching its surface is apart from it, as for mesh–mesh.

use crate::budget::WorkClock;
use crate::geometry::SupportMap;
use crate::math::{DVec3, Isometry, Pose};
use crate::narrow::compound::{self, query::CompoundScratch};
use crate::narrow::contact::{DistanceBound, Manifold, Reached, ShapeDistance};
use crate::narrow::convex_manifold::{ManifoldScratch, manifold_convex_convex_in};
use crate::narrow::convex_mesh::ConvexMeshWorkspace;
use crate::narrow::convex_mesh::{MeshContactScratch, shape_mesh_distance, shape_mesh_manifold};
use crate::narrow::gjk::{
    self, EpaWorkspace, GjkCache, GjkOutcome, GjkParams, Rounded, signed_distance_convex_within,
};
use crate::narrow::mesh_mesh::{DistanceCache, MeshMeshWorkspace};
use crate::narrow::pairs::{self, FaceCertificate};
use crate::narrow::shape::{core_of, features_of};
use crate::narrow::{MeshShape, Shape};
use std::sync::Arc;

/// GJK/EPA settings of the dispatcher: GJK's defaults (relative tolerance 1e-10).
pub const GJK: GjkParams = GjkParams {
    rel_tol: 1e-10,
    epa_rel_tol: 1e-10,
    abs_tol: 0.0,
    max_iterations: 128,
    accelerated: false,
};

/// How many narrow-phase distance queries took each path (counted by the dispatcher, and
/// by the pipeline for mesh–mesh pairs on their own route): which stages a frame really
/// entered. Time-of-impact searches count each of their distance steps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PathCounts {
    /// Closed forms: sphere, capsule and cuboid among themselves, a box's face certificate
    /// against a cylinder, cone or hull, and a cylinder's certificate.
    pub closed_form: u32,
    /// GJK runs: convex pairs without a closed form.
    pub gjk: u32,
    /// Distance bounds ([`DistanceBound`]): the early-outs that prove pairs beyond the
    /// reporting limit (cuboid–cuboid pairs by their separating axes, a box and a cylinder,
    /// cone or hull by a face plane of the box, a cylinder by a plane of its caps or side,
    /// a pair with a cylinder, cone or hull by the support plane across the line between
    /// the shapes' origins, GJK pairs by a support plane, these counted in `gjk` too), and
    /// the conservative answer of capsule and cuboid pairs once the frame's deadline is
    /// near.
    pub separating_axes: u32,
    /// EPA runs: GJK found the cores overlapping.
    pub epa: u32,
    /// Walks of a mesh's BVH for a convex shape against the mesh.
    pub convex_mesh: u32,
    /// Mesh–mesh BVH tandem queries.
    pub mesh_mesh: u32,
    /// Compound queries (their part pairs are counted by their own paths too).
    pub compound: u32,
}

impl PathCounts {
    /// Queries that entered BVH code (convex–mesh walks and mesh–mesh traversals).
    #[must_use]
    pub fn bvh(&self) -> u32 {
        self.convex_mesh + self.mesh_mesh
    }

    /// Adds `other`'s counts (another thread's, for pairs it answered for this frame).
    pub fn add(&mut self, other: &Self) {
        let Self {
            closed_form,
            gjk,
            separating_axes,
            epa,
            convex_mesh,
            mesh_mesh,
            compound,
        } = *other;
        self.closed_form += closed_form;
        self.gjk += gjk;
        self.separating_axes += separating_axes;
        self.epa += epa;
        self.convex_mesh += convex_mesh;
        self.mesh_mesh += mesh_mesh;
        self.compound += compound;
    }
}

/// Scratch of the dispatcher for one thread (no allocation once grown).
#[derive(Debug, Default)]
pub struct NarrowScratch {
    /// The frame's clock, polled by [`distance_within`]'s long steps (unlimited unless the
    /// pipeline sets one for a budgeted frame).
    pub clock: WorkClock,
    /// Paths taken since the pipeline last reset it (once per frame).
    pub(crate) paths: PathCounts,
    pub(crate) epa: EpaWorkspace,
    pub(crate) convex_mesh: ConvexMeshWorkspace,
    mesh_mesh: MeshMeshWorkspace,
    /// Convex–mesh contacts: the distance walk's touching triangles and the manifold's.
    pub(crate) mesh_contacts: MeshContactScratch,
    /// The buffers of the convex pairs' clipped manifolds (boxed: 22 KB).
    manifold: Box<ManifoldScratch>,
    /// The compound queries' candidate part pairs and gathered points.
    pub(crate) compound: CompoundScratch,
    /// Set by a [`manifold`] that `clock` stopped before it gathered every point (a
    /// compound's part pairs, a convex shape's triangles of a mesh; it keeps the deepest
    /// point and the normal): the caller marks the pair's answer inexact. Never cleared
    /// here.
    pub manifold_cut_short: bool,
}

/// Every convex kind, as a pattern (every kind but the mesh and the compound).
macro_rules! convex {
    () => {
        Shape::Sphere(_)
            | Shape::Capsule(_)
            | Shape::Cuboid(_)
            | Shape::Cylinder(_)
            | Shape::Cone(_)
            | Shape::Convex(_)
    };
}

/// How the pipeline answers a pair.
pub enum Route<'s> {
    /// Two meshes: the BVH tandem queries (warm starts, worker pool, manifold of the
    /// intersection set).
    MeshMesh(&'s Arc<MeshShape>, &'s Arc<MeshShape>),
    /// Everything else (a compound's part pairs included): [`distance`] and [`manifold`].
    Direct,
}

/// The route of the pair `(a, b)`.
pub fn route<'s>(a: &'s Shape, b: &'s Shape) -> Route<'s> {
    match (a, b) {
        (Shape::Mesh(ma), Shape::Mesh(mb)) => Route::MeshMesh(ma, mb),
        (convex!(), convex!() | Shape::Mesh(_))
        | (Shape::Mesh(_), convex!())
        | (Shape::Compound(_), _)
        | (_, Shape::Compound(_)) => Route::Direct,
    }
}

/// Whether the pair's exact answer costs about what the conservative answer of its world
/// boxes costs: a sphere against a sphere, capsule or cuboid, whose closed forms take
/// 2.5–14 ns (`benches/narrow_phase.rs`, README). Such a pair is answered exactly even once
/// the frame's deadline is near (`crate::pipeline::FrameCosts::tail_ns`): its box answer would save
/// nothing and, for a sphere whose box corners lie outside it, often report it close.
pub fn exact_costs_no_more_than_boxes(a: &Shape, b: &Shape) -> bool {
    use Shape::{Capsule as C, Cuboid as B, Sphere as S};
    matches!((a, b), (S(_), S(_) | C(_) | B(_)) | (C(_) | B(_), S(_)))
}

/// Bounds on the signed distance of `a` and `b` placed by `pose_ab`, A's frame, cheaper
/// than the exact query ([`DistanceBound`]), for the pairs that have them: capsules and
/// cuboids among themselves. A capsule's are its exact answer while its segment is apart
/// from the other core (as cheap as the separating axes); two boxes' come from the axes,
/// which may stop once the lower bound exceeds `enough` metres, and are exact when the
/// axes find the boxes apart but not beyond it. `None` for every other pair (sphere pairs
/// answer exactly for about the same cost; the others have no such test).
pub fn distance_bound(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    enough: f64,
) -> Option<DistanceBound> {
    use Shape::{Capsule as C, Cuboid as B};
    match (a, b) {
        (C(x), C(y)) => Some(pairs::distance_bound_capsule_capsule(x, y, pose_ab)),
        (C(x), B(y)) => Some(pairs::distance_bound_capsule_cuboid(x, y, pose_ab)),
        (B(x), B(y)) => Some(pairs::distance_bound_cuboid_cuboid(x, y, pose_ab, enough)),
        (B(_), C(_)) => {
            let pose_ba = pose_ab.inverse();
            distance_bound(b, a, &pose_ba, enough).map(|d| d.flipped(pose_ab))
        }
        _ => None,
    }
}

/// The signed distance of `a` and `b` placed by `pose_ab`, A's frame (see the module docs
/// for the query each pair gets), exact when it is at most `limit` metres; above the limit
/// the answer may be only a bound (`distance > limit` holds, the value is not exact): a
/// lower bound from the separating axes of cuboid–cuboid pairs, or an upper bound,
/// possibly `+∞`, from a convex shape's walk of a mesh stopped early. Mesh–mesh pairs get a
/// cold exact distance here; the pipeline sends them down [`Route::MeshMesh`] instead.
/// Runs to the end whatever `scratch.clock` says ([`distance_within`] polls it).
pub fn distance(
    a: &Shape,
    b: &Shape,
    pose_ab: &Pose,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> ShapeDistance {
    unlimited(scratch, |scratch| {
        distance_within(a, b, pose_ab, limit, scratch)
    })
}

/// [`distance`] under the frame's clock `scratch.clock`, polled by the steps that can take
/// long (a convex shape's walk of a mesh, EPA): exact when it finished, else bounds.
pub fn distance_within(
    a: &Shape,
    b: &Shape,
    pose_ab: &Pose,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> Reached {
    use Shape::{Compound as K, Mesh as M};
    match (a, b) {
        (K(compound), _) => {
            scratch.paths.compound += 1;
            compound::query::distance_within(compound, b, pose_ab, limit, scratch)
        }
        (_, K(_)) => distance_within(b, a, &pose_ab.inverse(), limit, scratch)
            .flipped(&pose_ab.to_isometry()),
        (convex!(), convex!()) => convex_reach(a, b, &pose_ab.to_isometry(), limit, scratch),
        (convex!(), M(mesh)) => {
            scratch.paths.convex_mesh += 1;
            shape_mesh_distance(a, mesh, pose_ab, limit, scratch)
        }
        (M(_), convex!()) => distance_within(b, a, &pose_ab.inverse(), limit, scratch)
            .flipped(&pose_ab.to_isometry()),
        (M(x), M(y)) => {
            scratch.paths.mesh_mesh += 1;
            let d = x.distance_to(
                y,
                pose_ab,
                &mut DistanceCache::new(),
                &mut scratch.mesh_mesh,
            );
            Reached::Exact(ShapeDistance {
                distance: d.distance,
                point_a: d.point_a,
                point_b: d.point_b,
                normal: (d.point_b - d.point_a).try_normalize().unwrap_or(DVec3::X),
            })
        }
    }
}

/// [`distance`] for a pair of convex shapes placed by an isometry: the closed forms and
/// GJK/EPA. A pair with a mesh is passed on to [`distance`].
pub fn distance_convex(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> ShapeDistance {
    unlimited(scratch, |scratch| {
        convex_reach(a, b, pose_ab, limit, scratch)
    })
}

/// Runs `query` with `scratch.clock` set aside for an unlimited one, which never stops it,
/// so its answer is exact.
fn unlimited(
    scratch: &mut NarrowScratch,
    query: impl FnOnce(&mut NarrowScratch) -> Reached,
) -> ShapeDistance {
    let clock = std::mem::take(&mut scratch.clock);
    let reached = query(scratch);
    scratch.clock = clock;
    reached.at_lower()
}

/// The convex pairs' arms of [`distance_within`].
fn convex_reach(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> Reached {
    use Shape::{Capsule as C, Compound as K, Cuboid as B, Mesh as M, Sphere as S};
    let paths = &mut scratch.paths;
    let closed = |paths: &mut PathCounts, d| {
        paths.closed_form += 1;
        Reached::Exact(d)
    };
    match (a, b) {
        (S(x), S(y)) => closed(paths, pairs::distance_sphere_sphere(x, y, pose_ab)),
        (S(x), C(y)) => closed(paths, pairs::distance_sphere_capsule(x, y, pose_ab)),
        (S(x), B(y)) => closed(paths, pairs::distance_sphere_cuboid(x, y, pose_ab)),
        (S(x), Shape::Cylinder(y)) => closed(paths, pairs::distance_sphere_cylinder(x, y, pose_ab)),
        // No early-out for a capsule: its closed form costs what the separating axes would.
        (C(x), C(y)) => closed(paths, pairs::distance_capsule_capsule(x, y, pose_ab)),
        (C(x), B(y)) => closed(paths, pairs::distance_capsule_cuboid(x, y, pose_ab)),
        (B(x), B(y)) => {
            let (d, beyond_limit) = pairs::distance_cuboid_cuboid_within(x, y, pose_ab, limit);
            if beyond_limit {
                paths.separating_axes += 1;
            } else {
                paths.closed_form += 1;
            }
            Reached::Exact(d)
        }
        (C(x), Shape::Cylinder(y)) => {
            match pairs::distance_capsule_cylinder(x, y, pose_ab, GJK.rel_tol) {
                Some(d) => closed(paths, d),
                None => certified_or_gjk(a, b, pose_ab, limit, scratch, FaceCertificate::Unknown),
            }
        }
        (C(_) | Shape::Cylinder(_), S(_)) | (B(_), S(_) | C(_)) | (Shape::Cylinder(_), C(_)) => {
            convex_reach(b, a, &pose_ab.inverse(), limit, scratch).flipped(pose_ab)
        }
        (B(x), Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_)) => {
            if let Some(d) = beyond_along_centres(a, b, pose_ab, limit) {
                paths.separating_axes += 1;
                return Reached::Exact(d);
            }
            let Some((core_b, _)) = core_of(b) else {
                unreachable!("the arm holds convex shapes only");
            };
            let face = pairs::face_distance_cuboid_convex(x, &core_b, pose_ab, limit);
            certified_or_gjk(a, b, pose_ab, limit, scratch, face)
        }
        (S(_), Shape::Cone(_) | Shape::Convex(_))
        | (C(_), Shape::Cone(_) | Shape::Convex(_))
        | (Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_), convex!()) => {
            if let Some(d) = beyond_along_centres(a, b, pose_ab, limit) {
                paths.separating_axes += 1;
                return Reached::Exact(d);
            }
            certified_or_gjk(a, b, pose_ab, limit, scratch, FaceCertificate::Unknown)
        }
        (M(_) | K(_), _) | (_, M(_) | K(_)) => {
            distance_within(a, b, &pose_ab.to_pose(), limit, scratch)
        }
    }
}

/// The contact manifold of `a` and `b` placed by `pose_ab`, A's frame, into `out` (emptied
/// first; stays empty when they are apart). `d` is their signed distance from
/// [`distance`] (exact when they touch): pairs whose manifold is one point take it from
/// `d` instead of running their query again. Mesh–mesh pairs go down [`Route::MeshMesh`];
/// here they too get the one point of `d`.
pub fn manifold(
    a: &Shape,
    b: &Shape,
    pose_ab: &Pose,
    d: &ShapeDistance,
    scratch: &mut NarrowScratch,
    out: &mut Manifold,
) {
    use Shape::{Compound as K, Mesh as M};
    match (a, b) {
        (K(compound), _) => compound::query::manifold(compound, b, pose_ab, d, scratch, out),
        (convex!(), convex!()) => manifold_convex(a, b, &pose_ab.to_isometry(), d, scratch, out),
        (M(_), convex!()) | (_, K(_)) => {
            let pose_ba = pose_ab.inverse();
            let d_ba = d.flipped(&pose_ba.to_isometry());
            manifold(b, a, &pose_ba, &d_ba, scratch, out);
            out.flip(&pose_ab.to_isometry());
        }
        // Mesh–mesh off the pipeline's route: the one point of `d`.
        (M(_), M(_)) => out.set_from_distance(d),
        (convex!(), M(mesh)) => shape_mesh_manifold(a, mesh, pose_ab, d, scratch, out),
    }
}

/// [`manifold`] for a pair of convex shapes placed by an isometry (`d` from
/// [`distance_convex`]). A pair with a mesh is passed on to [`manifold`].
pub fn manifold_convex(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    scratch: &mut NarrowScratch,
    out: &mut Manifold,
) {
    use Shape::{Capsule as C, Compound as K, Cuboid as B, Mesh as M, Sphere as S};
    out.reset(DVec3::ZERO);
    match (a, b) {
        (C(x), C(y)) => pairs::manifold_capsule_capsule_from(x, y, pose_ab, d, out),
        (C(x), B(y)) => pairs::manifold_capsule_cuboid_from(x, y, pose_ab, d, out),
        (B(x), B(y)) => pairs::manifold_cuboid_cuboid(x, y, pose_ab, out),
        (B(_), C(_)) => {
            let pose_ba = pose_ab.inverse();
            manifold_convex(b, a, &pose_ba, &d.flipped(&pose_ba), scratch, out);
            out.flip(pose_ab);
        }
        // One point: every pair with a sphere (a sphere touches a convex shape at one
        // point, the distance's witnesses; clipping would find the same point again).
        (S(_), convex!())
        | (C(_) | B(_) | Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_), S(_)) => {
            out.set_from_distance(d);
        }
        // GJK pairs: reference-face clipping from the distance's normal.
        (C(_) | B(_), Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_))
        | (
            Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_),
            C(_) | B(_) | Shape::Cylinder(_) | Shape::Cone(_) | Shape::Convex(_),
        ) => {
            let (fa, fb) = (features_of(a), features_of(b));
            manifold_convex_convex_in(fa, fb, pose_ab, d, &mut scratch.manifold, out);
        }
        (M(_) | K(_), _) | (_, M(_) | K(_)) => {
            manifold(a, b, &pose_ab.to_pose(), d, scratch, out);
        }
    }
}

/// The proof that convex shapes `a` and `b` (B placed by `pose_ab`) are more than `limit`
/// metres apart by one support plane: the plane across the line from A's origin to B's,
/// at A's farthest point along it. B's nearest point along it lies beyond by `gap`, a lower
/// bound of the distance (less the rounding of the two support points); `None` when that
/// does not exceed `limit` (or the origins coincide). The answer is a bound, as every
/// beyond-the-limit answer may be: distance `gap`, witnesses the two support points (real
/// points, farther apart than `gap`), normal along the line.
///
/// PERF: two support calls. GJK proved these pairs too, but after its own start and a
/// second support plane, and the certificates tried before it cost more still:
/// `benches/pile.rs`, alternating runs, `proxima/distance` 192 / 175 → 166 / 165 µs,
/// `proxima/frame-all-pairs` 281 / 276 → 270 / 269 µs.
fn beyond_along_centres(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    limit: f64,
) -> Option<ShapeDistance> {
    if !limit.is_finite() {
        return None;
    }
    let normal = pose_ab.translation.try_normalize()?;
    let (Some((core_a, radius_a)), Some((core_b, radius_b))) = (core_of(a), core_of(b)) else {
        unreachable!("the dispatcher sends only convex pairs here");
    };
    let point_a = core_a.support(normal) + normal * radius_a;
    let point_b = pose_ab
        .transform_point(core_b.support(pose_ab.inverse_transform_vector(-normal)))
        - normal * radius_b;
    let scale = point_a.abs().max_element().max(point_b.abs().max_element());
    // GJK's own allowance for the rounding of support points and pose.
    let gap = normal.dot(point_b - point_a) - gjk::ROUNDING_ULPS * f64::EPSILON * scale;
    (gap > limit).then_some(ShapeDistance {
        distance: gap,
        point_a,
        point_b,
        normal,
    })
}

/// A convex pair's answer from `certificate` when it has one, else from a cylinder's
/// certificate when either shape is a cylinder ([`cylinder_certificate`]), else, for a
/// cylinder apart from a box or cylinder, from its rim ([`rim_certificate`]), else from GJK
/// and EPA.
fn certified_or_gjk(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    limit: f64,
    scratch: &mut NarrowScratch,
    certificate: FaceCertificate,
) -> Reached {
    let certificate = match certificate {
        FaceCertificate::Unknown => cylinder_certificate(a, b, pose_ab, limit),
        known => known,
    };
    match certificate {
        FaceCertificate::Exact(d) => {
            scratch.paths.closed_form += 1;
            Reached::Exact(d)
        }
        FaceCertificate::Beyond(d) => {
            scratch.paths.separating_axes += 1;
            Reached::Exact(d)
        }
        FaceCertificate::Unknown => match rim_certificate(a, b, pose_ab) {
            Some(d) => {
                scratch.paths.closed_form += 1;
                Reached::Exact(d)
            }
            None => convex_distance(a, b, pose_ab, limit, scratch),
        },
    }
}

/// [`pairs::certified_rim_distance`] for a cylinder apart from a box or a cylinder, the
/// rim of either cylinder tried; `None` for other pairs or when no rim certifies.
fn rim_certificate(a: &Shape, b: &Shape, pose_ab: &Isometry) -> Option<ShapeDistance> {
    let rel_tol = GJK.rel_tol;
    let flipped = |d: ShapeDistance| d.flipped(pose_ab);
    match (a, b) {
        (Shape::Cylinder(x), Shape::Cuboid(y)) => {
            pairs::certified_rim_distance(x, y, pose_ab, rel_tol)
        }
        (Shape::Cuboid(x), Shape::Cylinder(y)) => {
            pairs::certified_rim_distance(y, x, &pose_ab.inverse(), rel_tol).map(flipped)
        }
        (Shape::Cylinder(x), Shape::Cylinder(y)) => {
            pairs::certified_rim_distance(x, y, pose_ab, rel_tol).or_else(|| {
                pairs::certified_rim_distance(y, x, &pose_ab.inverse(), rel_tol).map(flipped)
            })
        }
        _ => None,
    }
}

/// [`pairs::certified_distance_cylinder_convex`] for a cylinder on either side of a convex
/// pair, the other shape's core rounded by its radius (a capsule's segment); `Unknown`
/// when neither is a cylinder or the bounds do not meet.
fn cylinder_certificate(a: &Shape, b: &Shape, pose_ab: &Isometry, limit: f64) -> FaceCertificate {
    let certify = |cylinder, other: &Shape, pose: &Isometry| {
        let Some((core, radius)) = core_of(other) else {
            unreachable!("the dispatcher sends only convex pairs here");
        };
        let rel_tol = GJK.rel_tol.max(GJK.epa_rel_tol);
        pairs::certified_distance_cylinder_convex(cylinder, &core, pose, rel_tol, limit + radius)
            .map(|d| ShapeDistance {
                distance: d.distance - radius,
                point_b: d.point_b - d.normal * radius,
                ..d
            })
    };
    let as_a = match a {
        Shape::Cylinder(x) => certify(x, b, pose_ab),
        _ => FaceCertificate::Unknown,
    };
    match (as_a, b) {
        (FaceCertificate::Unknown, Shape::Cylinder(y)) => {
            let pose_ba = pose_ab.inverse();
            certify(y, a, &pose_ba).map(|d| d.flipped(pose_ab))
        }
        (known, _) => known,
    }
}

/// GJK/EPA between two convex shapes (the caller's arm guarantees neither is a mesh):
/// exact up to `limit` metres; beyond, GJK stops at the first support plane that proves it
/// and answers that plane's lower bound.
fn convex_distance(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> Reached {
    let (Some((core_a, radius_a)), Some((core_b, radius_b))) = (core_of(a), core_of(b)) else {
        unreachable!("the dispatcher sends only convex pairs here");
    };
    let (ra, rb) = (
        Rounded::new(&core_a, radius_a),
        Rounded::new(&core_b, radius_b),
    );
    let (reached, outcome) = signed_distance_convex_within(
        &ra,
        &rb,
        pose_ab,
        &GJK,
        &mut GjkCache::default(),
        &mut scratch.epa,
        &mut scratch.clock,
        limit,
    );
    scratch.paths.gjk += 1;
    scratch.paths.separating_axes += u32::from(outcome.gjk == GjkOutcome::Beyond);
    scratch.paths.epa += u32::from(outcome.epa.is_some());
    reached
}

#[cfg(test)]
#[path = "dispatch_tests.rs"]
mod tests;
