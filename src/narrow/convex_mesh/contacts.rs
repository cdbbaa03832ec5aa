//! A convex shape against a triangle mesh: the signed distance (the nearest or deepest
//! triangle) and the contact manifold (every triangle the shape touches, merged), without
//! ghost normals and with one walk of the mesh's tree when both are asked.
//!
//! # Ghost normals
//! Each triangle is queried on its own (a closed form or GJK/EPA). When the shape's closest
//! feature on a triangle is one of its edges or vertices, the answer's normal points out of
//! that edge or vertex, tilted away from the face. Where the surface really bends (a convex
//! ridge, a mesh border) such normals are real; across an *internal* edge of a flat region,
//! or into a valley, they are "ghosts": a box sliding over a triangulated floor would be
//! pushed sideways at every internal edge it crosses.
//!
//! # How they are removed
//! [`MeshEdges`](crate::geometry::mesh::MeshEdges) (built when the mesh is registered) says for every triangle edge whether the
//! surface is convex, flat or concave there, or open (border, non-manifold). For each
//! triangle contact whose normal is not the triangle's face normal, the closest feature on
//! the triangle (the deepest point's witness, by its barycentric coordinates) decides what
//! is allowed. Meshes are two-sided, so first the side: the shape is on the side of the
//! face where its centre is (for centrally symmetric shapes, the side it leaves by the
//! shorter push); the normal's own sign cannot tell, as a thin triangle lets a
//! per-triangle query push a shape sideways or right through it. Then:
//! - the face's interior, a flat edge, or a vertex whose edges are all flat or bent away
//!   from that side (concave seen from it): only the face normal of that side;
//! - a bent edge (convex or concave): the real normals are the arc between the two face
//!   normals outside the bend and the two reversed face normals inside it. A centre behind
//!   both faces gets the reversed normal of the nearer face; otherwise a normal whose
//!   component across the edge lies in the arc keeps that component, and any other becomes
//!   the face normal on whose side alone the centre is (the nearer by angle if on both);
//! - a vertex bent only as seen from the other side: as its bent edge the normal crosses
//!   most;
//! - an open edge, or a vertex on a convex or open edge (seen from the shape's side): the
//!   normal as found.
//!
//! A replaced normal gets new depths: each point of that triangle's manifold measured along
//! it against the plane through the witness (the face's plane, or the edge) — points that no
//! longer touch are dropped — plus, for a face normal, the shape's deepest point along it
//! when it lies over that face. The triangle contacts are then merged as before: the
//! deepest point's normal for the manifold, at most
//! [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS) points by [`reduce_manifold`](crate::narrow::reduce_manifold); a
//! point of another face keeps its A point and gets its depth along the common normal
//! (its B point then lies on that normal through the A point, as the contract asks).
//!
//! # One walk
//! The pipeline asks the distance first (walking the RSS tree, pruned by the best distance),
//! then the manifold of a touching pair with that distance. The distance walk visits every
//! triangle the shape touches (its pruning keeps all subtrees whose lower bound is `≤ 0`)
//! and records them with their per-triangle signed distances; the manifold then answers
//! from that record without walking again: a capsule's or a box's triangle manifold is
//! clipped along the recorded distance's normal (no second separating-axis test), every
//! other shape's is that distance's one point. A pair beyond contact (distance `> 0`) gets
//! an empty manifold with no walk at all.

use super::node_bound::PlacedShape;
use super::walk::{TRIANGLE_WORK, for_each_overlapping_triangle, nearest_triangle_within};
use crate::bounding::{Aabb, Obb};
use crate::geometry::SupportMap;
use crate::geometry::Triangle;
use crate::geometry::mesh::{EdgeKind, NO_NEIGHBOUR};
use crate::math::{DVec3, Isometry, Pose};
use crate::narrow::contact::{DistanceBound, Manifold, ManifoldPoint, Reached, ShapeDistance};
use crate::narrow::dispatch::{GJK, NarrowScratch};
use crate::narrow::gjk::{EpaWorkspace, GjkCache, Rounded, signed_distance_convex};
use crate::narrow::manifold_reduction::reduce_under_deepest;
use crate::narrow::pair_key::PairKey;
use crate::narrow::pairs;
use crate::narrow::shape::core_of;
use crate::narrow::{MeshShape, Shape};
use std::ops::ControlFlow;

/// A normal within this angle (radians, as the sine) of a face normal counts as the face
/// normal: no correction.
const FACE_NORMAL_SINE: f64 = 1e-12;

/// A barycentric coordinate at most this small puts a witness on the opposite edge.
const ON_EDGE: f64 = 1e-9;

/// Scratch of the convex–mesh contacts (no allocation once grown).
#[derive(Debug, Default)]
pub(crate) struct MeshContactScratch {
    /// The pair the last distance walk answered, when it recorded every touching triangle.
    walked: Option<PairKey>,
    /// The triangles the last distance walk found touching: id, A's frame, signed distance.
    touching: Vec<(u32, Triangle, ShapeDistance)>,
    /// A triangle's manifold, while a mesh manifold is gathered.
    triangle_manifold: Manifold,
    /// Every corrected triangle contact, before reduction, with its normal.
    points: Vec<ManifoldPoint>,
    normals: Vec<DVec3>,
    positions: Vec<DVec3>,
    kept: Vec<usize>,
    /// Per-triangle queries (distance or manifold) run so far, for tests and statistics.
    pub triangle_queries: u64,
}

/// A convex shape against a mesh's triangles: the nearest (or deepest) triangle's signed
/// distance, exact when at most `limit` (see [`nearest_triangle_within`]), or bounds when
/// `scratch.clock` stopped the walk. Records the triangles it finds touching for
/// [`shape_mesh_manifold`] (only when the walk finished).
pub(crate) fn shape_mesh_distance(
    shape: &Shape,
    mesh: &MeshShape,
    pose_ab: &Pose,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> Reached {
    let NarrowScratch {
        clock,
        epa,
        convex_mesh,
        mesh_contacts,
        ..
    } = scratch;
    let MeshContactScratch {
        walked,
        touching,
        triangle_queries,
        ..
    } = mesh_contacts;
    touching.clear();
    let Some((core, radius)) = core_of(shape) else {
        unreachable!("the dispatcher sends only convex shapes here");
    };
    let local = shape.local_bounds();
    let placed = PlacedShape::new(shape, &pose_ab.inverse().to_isometry());
    let walk = nearest_triangle_within(
        |node| placed.lower_bound(node),
        &mesh.distance_tree,
        pose_ab,
        limit,
        clock,
        convex_mesh,
        |id, triangle, threshold| {
            if box_separation(&local, triangle) > threshold
                || plane_separation(core.support_map(), radius, triangle) > threshold
            {
                // PERF: the shape's box or the triangle's plane keeps the triangle beyond
                // anything that could matter.
                return None;
            }
            *triangle_queries += 1;
            let d = shape_triangle_distance(shape, triangle, epa);
            if d.distance <= 0.0 {
                touching.push((id, *triangle, d));
            }
            Some((d.distance, d))
        },
    );
    // With a negative limit the walk may skip touching triangles, and a stopped walk skips
    // some: no record then.
    let finished = walk.unvisited_lower.is_none();
    *walked = (limit >= 0.0 && finished).then(|| PairKey::new(shape, mesh, pose_ab));
    let best = walk.best.map(|(_, d)| d);
    // The volumes' bounds are distances, 0 where they overlap; a triangle left there may
    // be reached through by up to the shape's width along its normal, at most the
    // diagonal of the shape's local box.
    let unvisited_lower = walk.unvisited_lower.map(|left| {
        if left > 0.0 {
            left
        } else {
            let local = shape.local_bounds();
            -(local.max - local.min).length()
        }
    });
    match (unvisited_lower, best) {
        (None, Some(d)) => Reached::Exact(d),
        // A mesh without triangles, or nothing within the limit.
        (None, None) => Reached::Exact(ShapeDistance {
            distance: f64::INFINITY,
            point_a: DVec3::ZERO,
            point_b: DVec3::ZERO,
            normal: DVec3::X,
        }),
        (Some(left), Some(d)) => Reached::Bounded(DistanceBound::new(
            left.min(d.distance),
            d.distance,
            d.normal,
            d.point_b,
        )),
        (Some(left), None) => Reached::Bounded(DistanceBound::new(
            left,
            f64::INFINITY,
            DVec3::X,
            DVec3::ZERO,
        )),
    }
}

/// How far apart the shape's local box `local` (A's frame) and `triangle`'s box (A's
/// frame) are along the axis that separates them most, metres: a lower bound on the
/// distance between the shape and the triangle, as each lies in its box. Negative when the
/// boxes overlap.
fn box_separation(local: &Aabb, triangle: &Triangle) -> f64 {
    let (a, b, c) = (triangle.a, triangle.b, triangle.c);
    let (low, high) = (a.min(b).min(c), a.max(b).max(c));
    (low - local.max).max(local.min - high).max_element()
}

/// How far apart the shape (a core swept by `radius`, at the origin of A's frame) and the
/// plane of `triangle` (A's frame) are, metres: a lower bound on their distance (the plane
/// holds the triangle); `-∞` for a zero-area triangle.
fn plane_separation(core: &dyn SupportMap, radius: f64, triangle: &Triangle) -> f64 {
    let Some(n) = (triangle.b - triangle.a)
        .cross(triangle.c - triangle.a)
        .try_normalize()
    else {
        return f64::NEG_INFINITY;
    };
    // The plane is `n · x = offset`; the shape reaches `h(±n)` towards it.
    let offset = n.dot(triangle.a);
    let toward = if offset >= 0.0 { n } else { -n };
    offset.abs() - core.support(toward).dot(toward) - radius
}

/// A convex shape against a mesh: the contacts of every triangle the shape touches, ghost
/// normals removed (see the [module docs](self)), reduced to at most 4 points under the
/// normal of the deepest, into `out`. `d` is the pair's signed distance from
/// [`shape_mesh_distance`]: beyond contact the manifold is empty without any walk, and
/// right after that distance walk of the same pair its record of touching triangles is used
/// instead of walking the tree again. Falls back to `d`'s one point when the shape touches
/// but no corrected point does (a graze at rounding level).
///
/// Polls `scratch.clock` before each triangle's manifold ([`TRIANGLE_WORK`] units; a
/// one-point triangle costs nothing to poll for): once it stops, the manifold is `d`'s one
/// point (the deepest, with its normal) and `scratch.manifold_cut_short` is set, so the
/// caller marks the answer inexact.
pub(crate) fn shape_mesh_manifold(
    shape: &Shape,
    mesh: &MeshShape,
    pose_ab: &Pose,
    d: &ShapeDistance,
    scratch: &mut NarrowScratch,
    out: &mut Manifold,
) {
    out.reset(DVec3::ZERO);
    if d.distance > 0.0 {
        return;
    }
    let iso_ab = pose_ab.to_isometry();
    let NarrowScratch {
        epa,
        convex_mesh,
        mesh_contacts,
        clock,
        manifold_cut_short,
        ..
    } = scratch;
    let MeshContactScratch {
        walked,
        touching,
        triangle_manifold,
        points,
        normals,
        positions,
        kept,
        triangle_queries,
    } = mesh_contacts;
    points.clear();
    normals.clear();
    let center = shape.local_bounds().center();
    let mut gather = |id: u32, triangle: &Triangle, m: &Manifold| {
        let contact = TriangleContact {
            shape,
            mesh,
            iso_ab: &iso_ab,
            id,
            triangle,
            center,
        };
        contact.push_corrected(m, points, normals);
    };
    let mut stopped = false;
    if *walked == Some(PairKey::new(shape, mesh, pose_ab)) {
        let one_point = !matches!(shape, Shape::Capsule(_) | Shape::Cuboid(_));
        for (id, triangle, d_t) in touching.iter() {
            if !one_point {
                if !clock.allows(TRIANGLE_WORK) {
                    stopped = true;
                    break;
                }
                *triangle_queries += 1;
            }
            shape_triangle_manifold_from(shape, triangle, d_t, triangle_manifold);
            gather(*id, triangle, triangle_manifold);
        }
    } else {
        for_each_overlapping_triangle(
            &Obb::from_aabb(&shape.local_bounds()),
            &mesh.overlap_tree,
            pose_ab,
            convex_mesh,
            |id, triangle| {
                if !clock.allows(TRIANGLE_WORK) {
                    stopped = true;
                    return ControlFlow::Break(());
                }
                *triangle_queries += 1;
                shape_triangle_manifold(shape, triangle, epa, triangle_manifold);
                gather(id, triangle, triangle_manifold);
                ControlFlow::Continue(())
            },
        );
    }
    if stopped {
        // The points gathered so far may miss the deepest: the distance's one point does not.
        *manifold_cut_short = true;
        out.set_from_distance(d);
        return;
    }
    // A ridge's or a valley's points of another face get their depth along the deepest
    // point's normal.
    if !reduce_under_deepest(points, normals, positions, kept, out) {
        out.set_from_distance(d);
    }
}

/// The closest feature of a triangle to a point on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Feature {
    Interior,
    /// Edge `k`: from vertex `k` to vertex `k + 1 (mod 3)`.
    Edge(usize),
    Vertex(usize),
}

/// What a triangle contact's normal becomes.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Verdict {
    /// The normal is real (a face normal, or one the feature exposes).
    Keep,
    /// Replace by `outward` (unit, from the mesh towards the shape): the face normal of
    /// triangle `face` (this one or the neighbour across a convex edge), or with `None` a
    /// normal of a convex edge (the found one without its component along the edge).
    Replace { outward: DVec3, face: Option<u32> },
}

/// One triangle of a mesh, as a convex shape's contact with it sees it.
struct TriangleContact<'a> {
    shape: &'a Shape,
    mesh: &'a MeshShape,
    /// The mesh's frame in the shape's (A's).
    iso_ab: &'a Isometry,
    id: u32,
    /// The triangle, A's frame.
    triangle: &'a Triangle,
    /// The centre of the shape's local box, A's frame: which side of a face it is on.
    center: DVec3,
}

impl TriangleContact<'_> {
    /// Pushes the points of `m` (this triangle's manifold) with their normal, corrected
    /// (see the [module docs](self)).
    fn push_corrected(
        &self,
        m: &Manifold,
        points: &mut Vec<ManifoldPoint>,
        normals: &mut Vec<DVec3>,
    ) {
        let Some(deepest) = m
            .points()
            .iter()
            .min_by(|p, q| p.distance.total_cmp(&q.distance))
        else {
            return;
        };
        let Verdict::Replace { outward, face } = self.verdict(-m.normal, deepest.point_b) else {
            points.extend_from_slice(m.points());
            normals.extend(std::iter::repeat_n(m.normal, m.len()));
            return;
        };
        let normal = -outward;
        // The face's plane (or the edge's) passes through the witness: it is on this
        // triangle, and on the shared edge when the normal is the neighbour's or the edge's.
        let plane = deepest.point_b;
        let mut push = |point_a: DVec3| {
            let distance = (plane - point_a).dot(normal);
            if distance <= 0.0 {
                points.push(ManifoldPoint {
                    point_a,
                    point_b: point_a + distance * normal,
                    distance,
                });
                normals.push(normal);
            }
        };
        for p in m.points() {
            push(p.point_a);
        }
        // For a face normal, the shape's deepest point along it, when it lies over the face.
        let Some(face) = face else {
            return;
        };
        let support = self.support(normal);
        let face_triangle = if face == self.id {
            *self.triangle
        } else {
            self.mesh
                .mesh
                .triangle(face as usize)
                .transformed(self.iso_ab)
        };
        let projected = support + (plane - support).dot(normal) * normal;
        if barycentric(&face_triangle, projected).is_some_and(|l| l.min_element() >= -ON_EDGE) {
            push(support);
        }
    }

    /// What the contact normal `outward` (unit, from the mesh towards the shape) with the
    /// witness `witness` on the triangle becomes.
    ///
    /// The side of a face the shape is on is where its centre is (for the centrally
    /// symmetric shapes, the side that needs the shorter push out along the face normal);
    /// the per-triangle normal's own sign is used only for a centre on the plane. A
    /// triangle alone cannot tell: a thin triangle lets a query push the shape sideways or
    /// through it.
    fn verdict(&self, outward: DVec3, witness: DVec3) -> Verdict {
        let Some(n) = self.triangle.normal() else {
            // A zero-area triangle has no face: its edges are open.
            return Verdict::Keep;
        };
        let height = (self.center - witness).dot(n);
        let front = if height == 0.0 {
            outward.dot(n) >= 0.0
        } else {
            height > 0.0
        };
        let face = if front { n } else { -n };
        if outward.cross(face).length() <= FACE_NORMAL_SINE && outward.dot(face) > 0.0 {
            return Verdict::Keep;
        }
        let to_face = Verdict::Replace {
            outward: face,
            face: Some(self.id),
        };
        let edges = self.mesh.edges.triangle(self.id as usize);
        match feature(self.triangle, witness) {
            Feature::Interior => to_face,
            Feature::Edge(k) if edges.kinds[k] == EdgeKind::Flat => to_face,
            Feature::Edge(k) => self.edge_verdict(k, outward, n, witness),
            Feature::Vertex(k) => {
                let vertex = self.mesh.mesh.triangles()[self.id as usize][k];
                let exposed = |front| self.mesh.edges.vertex_exposed(vertex, front);
                if exposed(front) {
                    Verdict::Keep
                } else if !exposed(!front) {
                    to_face
                } else {
                    // Bent only as seen from the other side (a ridge seen from beside it):
                    // answered as the bent edge at the vertex the normal crosses most.
                    let [a, b, c] = self.triangle.vertices();
                    let along = [b - a, c - b, a - c];
                    [k, (k + 2) % 3]
                        .into_iter()
                        .filter(|&e| !matches!(edges.kinds[e], EdgeKind::Open | EdgeKind::Flat))
                        .max_by(|&e, &f| {
                            let across = |e: usize| outward.cross(along[e].normalize()).length();
                            across(e).total_cmp(&across(f))
                        })
                        .map_or(to_face, |e| self.edge_verdict(e, outward, n, witness))
                }
            }
        }
    }

    /// What the normal `outward` becomes at edge `k` of the triangle (front normal `n`),
    /// a convex, concave or open edge through `witness`.
    ///
    /// Around a bent edge the real normals are the arc between the two faces' normals on
    /// the outside of the bend, and the two faces' reversed normals inside it. A shape whose
    /// centre is behind both faces (inside the bend) gets the reversed normal of the face
    /// nearer its centre. Otherwise a normal whose component across the edge lies in the
    /// arc becomes that component, and any other becomes the face normal on whose side
    /// alone the centre is (the nearer one by angle when it is on both).
    fn edge_verdict(&self, k: usize, outward: DVec3, n: DVec3, witness: DVec3) -> Verdict {
        let edges = self.mesh.edges.triangle(self.id as usize);
        let other = self.iso_ab.transform_vector(edges.neighbour_normals[k]);
        let neighbour = edges.neighbours[k];
        let (p, q) = match edges.kinds[k] {
            EdgeKind::Open => return Verdict::Keep,
            EdgeKind::Convex | EdgeKind::Flat => (n, other),
            EdgeKind::Concave => (-n, -other),
        };
        debug_assert_ne!(neighbour, NO_NEIGHBOUR);
        let (hp, hq) = (
            (self.center - witness).dot(p),
            (self.center - witness).dot(q),
        );
        if hp <= 0.0 && hq <= 0.0 {
            return if hp >= hq {
                Verdict::Replace {
                    outward: -p,
                    face: Some(self.id),
                }
            } else {
                Verdict::Replace {
                    outward: -q,
                    face: Some(neighbour),
                }
            };
        }
        let [a, b, c] = self.triangle.vertices();
        let along = [b - a, c - b, a - c][k].normalize_or_zero();
        // The edge's own normals have no component along it.
        if let Some(across) = (outward - along * outward.dot(along)).try_normalize()
            && within_wedge(across, p, q)
        {
            return if across.dot(outward) >= 1.0 - FACE_NORMAL_SINE {
                Verdict::Keep
            } else {
                Verdict::Replace {
                    outward: across,
                    face: None,
                }
            };
        }
        let toward_p = match (hp > 0.0, hq > 0.0) {
            (true, false) => true,
            (false, true) => false,
            _ => outward.dot(p) >= outward.dot(q),
        };
        if toward_p {
            Verdict::Replace {
                outward: p,
                face: Some(self.id),
            }
        } else {
            Verdict::Replace {
                outward: q,
                face: Some(neighbour),
            }
        }
    }

    /// The shape's farthest point along `direction` (unit), A's frame.
    fn support(&self, direction: DVec3) -> DVec3 {
        let Some((core, radius)) = core_of(self.shape) else {
            unreachable!("only convex shapes meet a mesh here");
        };
        core.support_map().support(direction) + radius * direction
    }
}

/// Whether `v` lies in the wedge spanned by the unit vectors `p` and `q` (less than half a
/// turn apart, all three perpendicular to one axis up to rounding).
fn within_wedge(v: DVec3, p: DVec3, q: DVec3) -> bool {
    let axis = p.cross(q);
    p.cross(v).dot(axis) >= 0.0 && v.cross(q).dot(axis) >= 0.0 && v.dot(p + q) > 0.0
}

/// Barycentric coordinates of `point` (projected onto the triangle's plane) for the vertices
/// `a, b, c`; `None` for a zero-area triangle.
fn barycentric(t: &Triangle, point: DVec3) -> Option<DVec3> {
    let s = t.scaled_normal();
    let area2 = s.length_squared();
    if area2 <= 0.0 {
        return None;
    }
    let la = (t.b - point).cross(t.c - point).dot(s) / area2;
    let lb = (t.c - point).cross(t.a - point).dot(s) / area2;
    Some(DVec3::new(la, lb, 1.0 - la - lb))
}

/// The feature of `t` nearest the point `witness` on it: by which barycentric coordinates
/// are at most [`ON_EDGE`].
fn feature(t: &Triangle, witness: DVec3) -> Feature {
    let Some(l) = barycentric(t, witness) else {
        return Feature::Interior;
    };
    let zero = [l.x <= ON_EDGE, l.y <= ON_EDGE, l.z <= ON_EDGE];
    match zero {
        [false, false, false] => Feature::Interior,
        // Coordinate j zero: the edge opposite vertex j, from vertex j + 1 to j + 2.
        [true, false, false] => Feature::Edge(1),
        [false, true, false] => Feature::Edge(2),
        [false, false, true] => Feature::Edge(0),
        // Two zero: the third vertex.
        [false, true, true] => Feature::Vertex(0),
        [true, false, true] => Feature::Vertex(1),
        [true, true, false] => Feature::Vertex(2),
        [true, true, true] => Feature::Vertex(0),
    }
}

// ---------------------------------------------------------------------------------------
// One convex shape against one triangle, and the shape's volume for the tree walks.

/// The signed distance of a convex shape (A's frame) and one triangle (A's frame): the
/// closed form for a sphere, capsule or cuboid, GJK/EPA for the others. This is the query
/// a mesh's walk runs on each triangle it reaches.
///
/// # Panics
/// If `shape` is a mesh (mesh–triangle pairs are the mesh–mesh queries').
pub fn shape_triangle_distance(
    shape: &Shape,
    triangle: &Triangle,
    epa: &mut EpaWorkspace,
) -> ShapeDistance {
    let identity = Isometry::IDENTITY;
    match shape {
        Shape::Sphere(s) => pairs::distance_sphere_triangle(s, triangle, &identity),
        Shape::Capsule(c) => pairs::distance_capsule_triangle(c, triangle, &identity),
        Shape::Cuboid(b) => pairs::distance_cuboid_triangle(b, triangle, &identity),
        Shape::Cylinder(_)
        | Shape::Cone(_)
        | Shape::Convex(_)
        | Shape::Mesh(_)
        | Shape::Compound(_) => {
            let Some((core, radius)) = core_of(shape) else {
                unreachable!("meshes are not convex shapes");
            };
            signed_distance_convex(
                &Rounded::new(core.support_map(), radius),
                &Rounded::plain(triangle),
                &identity,
                &GJK,
                &mut GjkCache::default(),
                epa,
            )
            .0
        }
    }
}

/// The manifold of a convex shape and one triangle, both in A's frame: the closed form's
/// for a sphere, capsule or cuboid, the one point of the distance for the others.
pub fn shape_triangle_manifold(
    shape: &Shape,
    triangle: &Triangle,
    epa: &mut EpaWorkspace,
    out: &mut Manifold,
) {
    let identity = Isometry::IDENTITY;
    out.reset(DVec3::ZERO);
    match shape {
        Shape::Sphere(s) => pairs::manifold_sphere_triangle(s, triangle, &identity, out),
        Shape::Capsule(c) => pairs::manifold_capsule_triangle(c, triangle, &identity, out),
        Shape::Cuboid(b) => pairs::manifold_cuboid_triangle(b, triangle, &identity, out),
        Shape::Cylinder(_)
        | Shape::Cone(_)
        | Shape::Convex(_)
        | Shape::Mesh(_)
        | Shape::Compound(_) => {
            let d = shape_triangle_distance(shape, triangle, epa);
            out.set_from_distance(&d);
        }
    }
}

/// [`shape_triangle_manifold`] from the pair's signed distance `d` (from
/// [`shape_triangle_distance`] of the same shape and triangle, A's frame): a capsule's or a
/// box's clipped along `d`'s normal without its separating axes again, every other
/// shape's the one point of `d` (as [`shape_triangle_manifold`] gives it).
fn shape_triangle_manifold_from(
    shape: &Shape,
    triangle: &Triangle,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    let identity = Isometry::IDENTITY;
    out.reset(DVec3::ZERO);
    match shape {
        Shape::Capsule(c) => pairs::manifold_capsule_triangle_from(c, triangle, &identity, d, out),
        Shape::Cuboid(b) => pairs::manifold_cuboid_triangle_from(b, triangle, &identity, d, out),
        Shape::Sphere(_)
        | Shape::Cylinder(_)
        | Shape::Cone(_)
        | Shape::Convex(_)
        | Shape::Mesh(_)
        | Shape::Compound(_) => out.set_from_distance(d),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Cuboid, Sphere, TriMesh};
    use crate::math::DQuat;
    use crate::narrow::dispatch::{distance, manifold};
    use crate::test_support::{TestRng, meshes, point_in_cube, random_convex, rng, rotation};
    use rand::Rng;
    use std::sync::Arc;

    fn mesh_shape(mesh: TriMesh) -> Shape {
        Shape::Mesh(Arc::new(MeshShape::new(mesh)))
    }

    /// The pair's exact distance and, when they touch, its manifold, through the dispatcher
    /// as the pipeline asks them (distance first, then the manifold with it).
    fn answer(
        a: &Shape,
        b: &Shape,
        pose_ab: &Pose,
        scratch: &mut NarrowScratch,
    ) -> (ShapeDistance, Manifold) {
        let d = distance(a, b, pose_ab, f64::INFINITY, scratch);
        let mut m = Manifold::new();
        if d.distance <= 0.0 {
            manifold(a, b, pose_ab, &d, scratch, &mut m);
        }
        (d, m)
    }

    /// `max_x∈shape x · dir` for a unit `dir` in the shape's frame, from the shapes'
    /// textbook support functions (independent of the shapes' `SupportMap`s).
    fn support_value(shape: &Shape, dir: DVec3) -> f64 {
        let across = dir.x.hypot(dir.y);
        match shape {
            Shape::Sphere(s) => s.radius,
            Shape::Capsule(c) => dir.z.abs() * c.half_height + c.radius,
            Shape::Cuboid(b) => dir.abs().dot(b.half_extents),
            Shape::Cylinder(c) => dir.z.abs() * c.half_height + across * c.radius,
            _ => unreachable!("not used by the oracles"),
        }
    }

    /// The per-triangle normals of the last distance walk's touching triangles (what the
    /// manifold corrects).
    fn raw_normals(scratch: &NarrowScratch) -> impl Iterator<Item = DVec3> + '_ {
        scratch
            .mesh_contacts
            .touching
            .iter()
            .map(|(_, _, d)| d.normal)
    }

    /// A rotation by at most `max_angle` about a random axis.
    fn small_rotation(rng: &mut TestRng, max_angle: f64) -> DQuat {
        let axis = (rotation(rng) * DVec3::X).normalize();
        DQuat::from_axis_angle(axis, rng.random_range(-max_angle..=max_angle))
    }

    /// The angle between two unit vectors, radians (accurate near 0).
    fn angle(u: DVec3, v: DVec3) -> f64 {
        u.cross(v).length().atan2(u.dot(v))
    }

    /// The contract of [`crate::narrow::contact`] for a manifold: at most 4 points, unit
    /// normal, no NaN, touching distances, `point_b − point_a = distance · normal` (to GJK/EPA's
    /// relative tolerance of `1e-10`, with room).
    fn assert_manifold_contract(m: &Manifold, scale: f64, case: usize) {
        assert!(m.len() <= 4, "case {case}");
        assert!(m.normal.is_finite(), "case {case}: {m:?}");
        assert!(
            (m.normal.length() - 1.0).abs() < 1e-12,
            "case {case}: {m:?}"
        );
        for p in m.points() {
            assert!(p.point_a.is_finite() && p.point_b.is_finite() && p.distance.is_finite());
            assert!(p.distance <= 0.0, "case {case}: {m:?}");
            let residual = p.point_b - p.point_a - m.normal * p.distance;
            assert!(residual.length() <= 1e-9 * scale, "case {case}: {m:?}");
        }
    }

    /// Boxes (and balls, capsules, cylinders) resting on, sunk into or hovering over a
    /// triangulated floor (at its frame's origin, or 1e5 m from it), in many positions with
    /// small tilts: the manifold's normal is the
    /// floor's, and its deepest point is the brute-force deepest penetration along it over
    /// every triangle the shape touches (which is also the sunk depth itself). The raw
    /// per-triangle normals do tilt, even the deepest triangle's (the normal the manifold
    /// took before ghost removal): the ghosts are there to remove.
    #[test]
    fn shapes_on_a_triangulated_floor_only_get_the_floor_normal_and_its_depth() {
        // The same floor at the origin and 1e5 m away in its own frame.
        let far = DVec3::new(1e5, -1e5, 0.0);
        let floors = [DVec3::ZERO, far].map(|offset| {
            let mesh = meshes::grid(5.0, 10).translated(offset);
            (offset, meshes::triangles(&mesh), mesh_shape(mesh))
        });
        let mut rng = rng(501);
        let mut scratch = NarrowScratch::default();
        let (mut touching, mut apart, mut ghosts, mut deepest_ghosts) = (0, 0, 0, 0);
        for case in 0..3000 {
            let shape = random_convex(&mut rng, 0.6, if case % 2 == 0 { 1 } else { 4 });
            // Every 8th case: no tilt, at a grid vertex or on a grid line (degenerate).
            let (xy, tilt) = if case % 8 == 0 {
                let at = |rng: &mut TestRng| f64::from(rng.random_range(-3i32..=3));
                let x = at(&mut rng);
                let y = if case % 16 == 0 {
                    at(&mut rng)
                } else {
                    rng.random_range(-3.0..3.0)
                };
                ((x, y), DQuat::IDENTITY)
            } else {
                (
                    (rng.random_range(-3.5..3.5), rng.random_range(-3.5..3.5)),
                    small_rotation(&mut rng, 0.3),
                )
            };
            let lowest = support_value(&shape, tilt.inverse() * -DVec3::Z);
            let gap = rng.random_range(-0.08..0.02);
            let (offset, triangles, floor) = &floors[usize::from(case % 4 == 3)];
            let shape_pose = Pose::new(*offset + DVec3::new(xy.0, xy.1, lowest + gap), tilt);
            let pose_ab = Pose::relative(&shape_pose, &Pose::IDENTITY);
            let (d, m) = answer(&shape, floor, &pose_ab, &mut scratch);
            let down = pose_ab.transform_vector(-DVec3::Z);
            if d.distance > 0.0 {
                apart += 1;
                assert!(gap > -1e-12, "case {case}: {d:?}");
                continue;
            }
            touching += 1;
            assert!(gap < 1e-12, "case {case}: {d:?}");
            assert_manifold_contract(&m, 10.0, case);
            assert!(!m.is_empty(), "case {case}");
            assert!(angle(m.normal, down) <= 1e-9, "case {case}: {m:?}");
            if raw_normals(&scratch).any(|n| angle(n, down) > 1e-6) {
                ghosts += 1;
            }
            // The deepest triangle's own normal (what the manifold used before): tilted.
            if angle(d.normal, down) > 1e-6 {
                deepest_ghosts += 1;
            }
            // Brute force over every triangle the shape touches: its deepest penetration
            // along the manifold's normal.
            let iso = pose_ab.to_isometry();
            let brute = triangles
                .iter()
                .map(|t| t.transformed(&iso))
                .filter(|t| shape_triangle_distance(&shape, t, &mut scratch.epa).distance <= 0.0)
                .map(|t| {
                    let lowest = t.vertices().map(|v| v.dot(m.normal));
                    support_value(&shape, m.normal)
                        - lowest.into_iter().fold(f64::INFINITY, f64::min)
                })
                .fold(f64::NEG_INFINITY, f64::max);
            let deepest = m.points().iter().map(|p| p.distance).fold(0.0, f64::min);
            assert!(
                (deepest + brute).abs() <= 1e-9,
                "case {case}: {deepest} vs {brute}"
            );
            assert!(
                (deepest - gap).abs() <= 1e-9,
                "case {case}: {deepest} vs {gap}"
            );
        }
        assert!(touching > 1000 && apart > 300, "{touching} / {apart}");
        assert!(
            ghosts > 500 && deepest_ghosts > 50,
            "only {ghosts} / {deepest_ghosts} tilted per-triangle normals"
        );
    }

    /// A ball rolling across the shared diagonal of two coplanar triangles, from above and
    /// from below (meshes are two-sided), with the pair at a random pose: the normal is the
    /// face normal at every position, and the depth is the ball's sunk depth.
    #[test]
    fn a_ball_rolling_over_a_shared_edge_only_gets_the_face_normal() {
        let v = vec![
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ];
        let square = mesh_shape(meshes::mesh(v, vec![[0, 1, 2], [0, 2, 3]]));
        let mut rng = rng(502);
        let mut scratch = NarrowScratch::default();
        let (mut edge_cases, mut ghosts, mut below) = (0, 0, 0);
        for case in 0..3000 {
            let radius = rng.random_range(0.05..0.3);
            // Along the diagonal, within a radius of it.
            let t = rng.random_range(-0.5..0.5);
            let off = rng.random_range(-1.0..1.0) * radius;
            let sunk = rng.random_range(0.0..0.8) * radius;
            let side = if case % 3 == 0 { -1.0 } else { 1.0 };
            let centre_b = DVec3::new(t + off, t - off, side * (radius - sunk));
            // B's frame in A's, with the ball's centre at A's origin.
            let r = rotation(&mut rng);
            let pose_ab = Pose::new(-(r * centre_b), r);
            let (d, m) = answer(
                &Shape::Sphere(Sphere::new(radius)),
                &square,
                &pose_ab,
                &mut scratch,
            );
            assert!(d.distance <= 0.0, "case {case}");
            assert_manifold_contract(&m, 2.0, case);
            let into_mesh = pose_ab.transform_vector(-side * DVec3::Z);
            assert!(angle(m.normal, into_mesh) <= 1e-9, "case {case}: {m:?}");
            let deepest = m.points().iter().map(|p| p.distance).fold(0.0, f64::min);
            assert!(
                (deepest + sunk).abs() <= 1e-12,
                "case {case}: {deepest} vs {sunk}"
            );
            if off.abs() * std::f64::consts::SQRT_2 < radius {
                edge_cases += 1;
            }
            if raw_normals(&scratch).any(|n| angle(n, into_mesh) > 1e-6) {
                ghosts += 1;
            }
            if side < 0.0 {
                below += 1;
            }
        }
        assert!(
            edge_cases > 1000 && below > 500 && ghosts > 100,
            "{edge_cases} {below} {ghosts}"
        );
    }

    /// Whether unit `v` lies in the wedge of the unit normals `n1` and `n2` (both normal to
    /// X): no component along X and non-negative coordinates in the basis (n1, n2).
    fn in_cone(v: DVec3, n1: DVec3, n2: DVec3, tol: f64) -> bool {
        let det = n1.y * n2.z - n1.z * n2.y;
        let a = (v.y * n2.z - v.z * n2.y) / det;
        let b = (n1.y * v.z - n1.z * v.y) / det;
        v.x.abs() <= tol && a >= -tol && b >= -tol
    }

    /// Boxes against a convex ridge (two triangles meeting at a random angle along X), in
    /// random orientations near its middle: the normal always lies in the cone of the two
    /// face normals; both face normals and normals strictly between them (edge contacts)
    /// occur, as do raw per-triangle normals outside the cone.
    #[test]
    fn boxes_on_a_convex_ridge_get_normals_inside_the_face_normal_cone() {
        let mut rng = rng(503);
        let mut scratch = NarrowScratch::default();
        let (mut touching, mut apart, mut faces, mut between, mut ghosts) = (0, 0, 0, 0, 0);
        for case in 0..3000 {
            let (alpha, beta): (f64, f64) =
                (rng.random_range(0.05..1.0), rng.random_range(0.05..1.0));
            let v = vec![
                DVec3::new(-10.0, 0.0, 0.0),
                DVec3::new(10.0, 0.0, 0.0),
                DVec3::new(0.0, 10.0 * alpha.cos(), -10.0 * alpha.sin()),
                DVec3::new(0.0, -10.0 * beta.cos(), -10.0 * beta.sin()),
            ];
            let n1 = DVec3::new(0.0, alpha.sin(), alpha.cos());
            let n2 = DVec3::new(0.0, -beta.sin(), beta.cos());
            let ridge = mesh_shape(meshes::mesh(v, vec![[0, 1, 2], [1, 0, 3]]));
            let half = DVec3::new(
                rng.random_range(0.1..0.5),
                rng.random_range(0.1..0.5),
                rng.random_range(0.1..0.5),
            );
            let shape = Shape::Cuboid(Cuboid::new(half));
            let y = rng.random_range(-1.0..1.0);
            let surface = if y > 0.0 {
                -y * alpha.tan()
            } else {
                y * beta.tan()
            };
            let centre = DVec3::new(
                rng.random_range(-2.0..2.0),
                y,
                surface + rng.random_range(1e-3..0.9),
            );
            let shape_pose = Pose::new(centre, rotation(&mut rng));
            let pose_ab = Pose::relative(&shape_pose, &Pose::IDENTITY);
            let (d, m) = answer(&shape, &ridge, &pose_ab, &mut scratch);
            if d.distance > 0.0 {
                apart += 1;
                continue;
            }
            touching += 1;
            assert_manifold_contract(&m, 20.0, case);
            // The normal from the ridge towards the box, ridge frame.
            let outward = -shape_pose.transform_vector(m.normal);
            assert!(
                in_cone(outward, n1, n2, 1e-9),
                "case {case}: {outward} {m:?}"
            );
            if angle(outward, n1) < 1e-9 || angle(outward, n2) < 1e-9 {
                faces += 1;
            } else {
                between += 1;
            }
            if raw_normals(&scratch)
                .any(|n| !in_cone(-shape_pose.transform_vector(n), n1, n2, 1e-6))
            {
                ghosts += 1;
            }
        }
        assert!(touching > 1000 && apart > 300, "{touching} / {apart}");
        assert!(
            faces > 300 && between > 30 && ghosts > 30,
            "{faces} {between} {ghosts}"
        );
    }

    /// Every convex kind against a torus, a flat grid, a finely cut box, a triangle soup
    /// (open and non-manifold edges, inconsistent winding) and a box with zero-area
    /// triangles mixed in, at random poses: the manifold
    /// keeps the contact contract, is empty exactly when the shapes are apart, and is the
    /// same (to rounding) whether it reuses the distance walk or walks the tree itself.
    #[test]
    fn random_shapes_against_meshes_keep_the_contract_with_and_without_the_walk_record() {
        let mut rng = rng(504);
        let meshes = [
            mesh_shape(meshes::torus(1.0, 0.3, 24, 10)),
            mesh_shape(meshes::grid(1.5, 8)),
            mesh_shape(meshes::subdivided_cuboid(DVec3::new(0.8, 0.6, 0.7), 3)),
            mesh_shape(meshes::triangle_soup(&mut rng, 60, 1.0, 0.5)),
            mesh_shape(meshes::with_zero_area_triangles(
                &mut rng,
                DVec3::splat(0.9),
                30,
            )),
        ];
        let mut scratch = NarrowScratch::default();
        let mut fresh = NarrowScratch::default();
        let (mut touching, mut apart) = (0, 0);
        for case in 0..3000 {
            let mesh = &meshes[case % meshes.len()];
            let shape = random_convex(&mut rng, 0.5, 6);
            let pose_ab = Pose::new(point_in_cube(&mut rng, 1.6), rotation(&mut rng));
            let (d, m) = answer(&shape, mesh, &pose_ab, &mut scratch);
            if d.distance > 0.0 {
                apart += 1;
                assert!(m.is_empty());
                continue;
            }
            touching += 1;
            assert!(!m.is_empty(), "case {case}");
            assert_manifold_contract(&m, 4.0, case);
            // From B's side too: the mirrored manifold keeps the contract.
            let pose_ba = pose_ab.inverse();
            let (d_ba, m_ba) = answer(mesh, &shape, &pose_ba, &mut scratch);
            assert!(
                (d_ba.distance - d.distance).abs() <= 1e-9,
                "case {case}: {} vs {} {shape:?}",
                d_ba.distance,
                d.distance
            );
            assert_manifold_contract(&m_ba, 4.0, case);
            // Without the distance walk's record (a scratch that never walked this pair).
            let mut walked = Manifold::new();
            manifold(&shape, mesh, &pose_ab, &d, &mut fresh, &mut walked);
            assert!(
                angle(walked.normal, m.normal) <= 1e-9,
                "case {case}: {walked:?} {m:?}"
            );
            let deepest = |m: &Manifold| m.points().iter().map(|p| p.distance).fold(0.0, f64::min);
            assert!(
                (deepest(&walked) - deepest(&m)).abs() <= 1e-9,
                "case {case}"
            );
        }
        assert!(touching > 500 && apart > 500, "{touching} / {apart}");
    }

    /// The manifold after the distance walk runs no walk, only the touching triangles'
    /// manifolds for boxes and capsules and no per-triangle query at all for balls and GJK
    /// shapes; a pair beyond contact costs nothing. Walking again would cost every triangle
    /// whose box overlaps the shape's.
    #[test]
    fn the_manifold_reuses_the_distance_walk_and_counts_show_it() {
        let floor = mesh_shape(meshes::grid(2.0, 16));
        let mut rng = rng(505);
        let mut scratch = NarrowScratch::default();
        let mut fresh = NarrowScratch::default();
        let (mut reused, mut rewalked, mut one_point_reused) = (0, 0, 0);
        let mut cases_touching = 0;
        for case in 0..600 {
            let shape = random_convex(&mut rng, 0.4, 6);
            let xy = point_in_cube(&mut rng, 1.0);
            let shape_pose = Pose::new(
                DVec3::new(xy.x, xy.y, rng.random_range(-0.3..0.6)),
                rotation(&mut rng),
            );
            let pose_ab = Pose::relative(&shape_pose, &Pose::IDENTITY);
            let d = distance(&shape, &floor, &pose_ab, f64::INFINITY, &mut scratch);
            let before = scratch.mesh_contacts.triangle_queries;
            let mut m = Manifold::new();
            manifold(&shape, &floor, &pose_ab, &d, &mut scratch, &mut m);
            let cost = scratch.mesh_contacts.triangle_queries - before;
            let touching_triangles = scratch.mesh_contacts.touching.len() as u64;
            if d.distance > 0.0 {
                assert_eq!(cost, 0, "case {case}");
                continue;
            }
            cases_touching += 1;
            let before = fresh.mesh_contacts.triangle_queries;
            let mut again = Manifold::new();
            manifold(&shape, &floor, &pose_ab, &d, &mut fresh, &mut again);
            let walk_cost = fresh.mesh_contacts.triangle_queries - before;
            if matches!(shape, Shape::Capsule(_) | Shape::Cuboid(_)) {
                assert_eq!(cost, touching_triangles, "case {case}");
                assert!(walk_cost >= cost, "case {case}");
                reused += cost;
                rewalked += walk_cost;
            } else {
                assert_eq!(cost, 0, "case {case}");
                one_point_reused += walk_cost;
            }
        }
        assert!(cases_touching > 200, "{cases_touching}");
        assert!(
            reused < rewalked && one_point_reused > 100,
            "{reused} {rewalked} {one_point_reused}"
        );
    }
}
