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
//! [`MeshEdges`] (built when the mesh is registered) says for every triangle edge whether the
//! surface is convex, flat or concave there, or open (border, non-manifold). For each
//! triangle contact whose normal is not the triangle's face normal, the closest feature on
//! the triangle (the deepest point's witness, by its barycentric coordinates) decides what
//! is allowed, seen from the side of the triangle the shape is on:
//! - the face's interior, a flat or concave edge, or a vertex whose edges are all flat or
//!   concave: only the face normal;
//! - a convex edge: a normal between the two face normals (its component across the edge
//!   inside the wedge); outside it, the nearer face normal;
//! - an open edge, or a vertex on a convex or open edge: the normal as found.
//!
//! A replaced normal gets new depths: each point of that triangle's manifold measured along
//! it against the plane of the face it came from (points that no longer touch are dropped),
//! plus the shape's deepest point along it when it lies over that face. The triangle
//! contacts are then merged as before: the deepest point's normal for the manifold, at most
//! [`MANIFOLD_POINTS`](crate::narrow::MANIFOLD_POINTS) points by [`reduce_manifold`].
//!
//! # One walk
//! The pipeline asks the distance first (walking the RSS tree, pruned by the best distance),
//! then the manifold of a touching pair with that distance. The distance walk visits every
//! triangle the shape touches (its pruning keeps all subtrees whose lower bound is `≤ 0`)
//! and records them with their per-triangle signed distances; the manifold then answers
//! from that record without walking again, and without a second per-triangle query for
//! shapes whose triangle manifold is one point (spheres and the GJK shapes). A pair beyond
//! contact (distance `> 0`) gets an empty manifold with no walk at all.

use super::super::contacts::reduce_manifold;
use super::{NarrowScratch, ShapeBound, core_of, shape_triangle_distance, shape_triangle_manifold};
use crate::bounding::{Obb, Rss};
use crate::geometry::Triangle;
use crate::geometry::mesh::{EdgeKind, NO_NEIGHBOUR};
use crate::math::{DVec3, Isometry, Pose};
use crate::narrow::contact::{Manifold, ManifoldPoint, ShapeDistance};
use crate::narrow::convex_mesh::{for_each_overlapping_triangle, nearest_triangle};
use crate::scene::{MeshShape, Shape};
use std::ops::ControlFlow;

/// A normal within this angle (radians, as the sine) of a face normal counts as the face
/// normal: no correction.
const FACE_NORMAL_SINE: f64 = 1e-12;

/// A barycentric coordinate at most this small puts a witness on the opposite edge.
const ON_EDGE: f64 = 1e-9;

/// Scratch of the convex–mesh contacts (no allocation once grown).
#[derive(Debug, Default)]
pub(super) struct MeshContactScratch {
    /// The pair the last distance walk answered, when it recorded every touching triangle.
    walked: Option<WalkKey>,
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

/// Which pair a distance walk answered: the shape and mesh (by address; both live in the
/// scene for the whole frame) and the relative pose, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
struct WalkKey {
    shape: usize,
    mesh: usize,
    pose_ab: Pose,
}

impl WalkKey {
    fn new(shape: &Shape, mesh: &MeshShape, pose_ab: &Pose) -> Self {
        Self {
            shape: std::ptr::from_ref(shape) as usize,
            mesh: std::ptr::from_ref(mesh) as usize,
            pose_ab: *pose_ab,
        }
    }
}

/// A convex shape against a mesh's triangles: the nearest (or deepest) triangle's signed
/// distance, exact when at most `limit` (see [`nearest_triangle`]). Records the triangles
/// it finds touching for [`shape_mesh_manifold`].
pub(super) fn shape_mesh_distance(
    shape: &Shape,
    mesh: &MeshShape,
    pose_ab: &Pose,
    limit: f64,
    scratch: &mut NarrowScratch,
) -> ShapeDistance {
    let NarrowScratch {
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
    let found = nearest_triangle(
        &Rss::around(shape),
        &mesh.distance_tree,
        pose_ab,
        limit,
        convex_mesh,
        |id, triangle| {
            *triangle_queries += 1;
            let d = shape_triangle_distance(shape, triangle, epa);
            if d.distance <= 0.0 {
                touching.push((id, *triangle, d));
            }
            (d.distance, d)
        },
    );
    // With a negative limit the walk may skip touching triangles: no record then.
    *walked = (limit >= 0.0).then(|| WalkKey::new(shape, mesh, pose_ab));
    found.map_or(
        // A mesh without triangles, or nothing within the limit.
        ShapeDistance {
            distance: f64::INFINITY,
            point_a: DVec3::ZERO,
            point_b: DVec3::ZERO,
            normal: DVec3::X,
        },
        |(_, d)| d,
    )
}

/// A convex shape against a mesh: the contacts of every triangle the shape touches, ghost
/// normals removed (see the [module docs](self)), reduced to at most 4 points under the
/// normal of the deepest, into `out`. `d` is the pair's signed distance from
/// [`shape_mesh_distance`]: beyond contact the manifold is empty without any walk, and
/// right after that distance walk of the same pair its record of touching triangles is used
/// instead of walking the tree again. Falls back to `d`'s one point when the shape touches
/// but no corrected point does (a graze at rounding level).
pub(super) fn shape_mesh_manifold(
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
    let mut gather = |id: u32, triangle: &Triangle, m: &Manifold| {
        let contact = TriangleContact {
            shape,
            mesh,
            iso_ab: &iso_ab,
            id,
            triangle,
        };
        contact.push_corrected(m, points, normals);
    };
    if *walked == Some(WalkKey::new(shape, mesh, pose_ab)) {
        let one_point = !matches!(shape, Shape::Capsule(_) | Shape::Cuboid(_));
        for (id, triangle, d_t) in touching.iter() {
            if one_point {
                triangle_manifold.set_from_distance(d_t);
            } else {
                *triangle_queries += 1;
                shape_triangle_manifold(shape, triangle, epa, triangle_manifold);
            }
            gather(*id, triangle, triangle_manifold);
        }
    } else {
        for_each_overlapping_triangle(
            &Obb::around(shape),
            &mesh.overlap_tree,
            pose_ab,
            convex_mesh,
            |id, triangle| {
                *triangle_queries += 1;
                shape_triangle_manifold(shape, triangle, epa, triangle_manifold);
                gather(id, triangle, triangle_manifold);
                ControlFlow::Continue(())
            },
        );
    }
    let Some(deepest) =
        (0..points.len()).min_by(|&i, &j| points[i].distance.total_cmp(&points[j].distance))
    else {
        out.set_from_distance(d);
        return;
    };
    let normal = normals[deepest];
    out.reset(normal);
    positions.clear();
    positions.extend(points.iter().map(|p| p.point_a));
    reduce_manifold(positions, kept);
    // The deepest point always stays.
    if !kept.contains(&deepest) {
        kept.pop();
        kept.insert(0, deepest);
    }
    for &i in kept.iter() {
        let p = points[i];
        // Depth along the common normal.
        let distance = (p.point_b - p.point_a).dot(normal).min(0.0);
        out.push(ManifoldPoint { distance, ..p });
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
    /// Replace by `outward` (unit, from the mesh towards the shape), the face normal of
    /// triangle `face` (this one or the neighbour across a convex edge).
    Replace { outward: DVec3, face: u32 },
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
        // The face's plane passes through the witness (on this triangle, and on the shared
        // edge when the face is the neighbour's).
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
        // The shape's deepest point along the new normal, when it lies over that face.
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
    fn verdict(&self, outward: DVec3, witness: DVec3) -> Verdict {
        let Some(n) = self.triangle.normal() else {
            // A zero-area triangle has no face: its edges are open.
            return Verdict::Keep;
        };
        let front = outward.dot(n) >= 0.0;
        let face = if front { n } else { -n };
        if outward.cross(face).length() <= FACE_NORMAL_SINE && outward.dot(face) > 0.0 {
            return Verdict::Keep;
        }
        let to_face = Verdict::Replace {
            outward: face,
            face: self.id,
        };
        let edges = self.mesh.edges.triangle(self.id as usize);
        match feature(self.triangle, witness) {
            Feature::Interior => to_face,
            Feature::Vertex(k) => {
                let vertex = self.mesh.mesh.triangles()[self.id as usize][k];
                if self.mesh.edges.vertex_exposed(vertex, front) {
                    Verdict::Keep
                } else {
                    to_face
                }
            }
            Feature::Edge(k) => {
                let kind = if front {
                    edges.kinds[k]
                } else {
                    edges.kinds[k].seen_from_back()
                };
                match kind {
                    EdgeKind::Open => Verdict::Keep,
                    EdgeKind::Flat | EdgeKind::Concave => to_face,
                    EdgeKind::Convex => {
                        debug_assert_ne!(edges.neighbours[k], NO_NEIGHBOUR);
                        let sign = if front { 1.0 } else { -1.0 };
                        let other = self.iso_ab.transform_vector(edges.neighbour_normals[k]) * sign;
                        let [a, b, c] = self.triangle.vertices();
                        let along = [b - a, c - b, a - c][k].normalize_or_zero();
                        let across = outward - along * outward.dot(along);
                        if within_wedge(across, face, other) {
                            Verdict::Keep
                        } else if outward.dot(face) >= outward.dot(other) {
                            to_face
                        } else {
                            Verdict::Replace {
                                outward: other,
                                face: edges.neighbours[k],
                            }
                        }
                    }
                }
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
