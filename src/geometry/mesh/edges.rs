//! Edge adjacency of a triangle mesh: for each triangle edge, the triangle across it and
//! whether the surface bends there (convex, flat or concave), computed once when a mesh is
//! registered.
//!
//! The narrow phase uses it to remove *ghost normals*: a shape sliding over a flat,
//! triangulated floor meets the floor's internal edges, and a per-triangle query answers
//! with the normal of the edge it reaches (tilted, pointing out of that triangle's side),
//! although the surface has no edge there. Only edges where the surface really bends may
//! produce such normals ([`crate::pipeline`]'s convex–mesh contacts read the kinds below).
//!
//! # Orientation
//! Kinds are stated for the *front* side of a triangle, the side its counter-clockwise
//! normal `(b − a) × (c − a)` points to. Meshes are two-sided surfaces: seen from the back,
//! a convex edge is concave and vice versa ([`EdgeKind::seen_from_back`]). A neighbour
//! wound the other way (the shared edge traversed in the same direction by both triangles)
//! is compared through its reversed normal, so inconsistent winding does not change kinds.

use super::TriMesh;
use crate::math::DVec3;

/// Two faces whose normals differ by at most this angle (radians) meet at a
/// [`EdgeKind::Flat`] edge: coplanar to the rounding of meshes written in f32 (about
/// `1e-7` relative) with room to spare. A bend below it is treated as no bend.
pub const FLAT_EDGE_ANGLE: f64 = 1e-5;

/// Marks an edge without a single neighbour in [`TriangleEdges::neighbours`].
pub const NO_NEIGHBOUR: u32 = u32::MAX;

/// How the surface bends across an edge, seen from a triangle's front side (the side its
/// normal `(b − a) × (c − a)` points to); from the back, convex and concave swap.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// No single neighbour with a normal: a boundary edge, an edge shared by three or more
    /// triangles, an edge of a zero-area triangle, or a fold back onto itself. Every
    /// normal of the edge's region is real.
    Open,
    /// The neighbour bends away from the front side (a ridge): normals between the two
    /// face normals are real.
    Convex,
    /// The neighbour is coplanar within [`FLAT_EDGE_ANGLE`]: only the face normal is real.
    Flat,
    /// The neighbour bends towards the front side (a valley): only the face normals are
    /// real.
    Concave,
}

impl EdgeKind {
    /// The kind seen from the triangle's back side (convex and concave swap).
    #[must_use]
    pub const fn seen_from_back(self) -> Self {
        match self {
            Self::Convex => Self::Concave,
            Self::Concave => Self::Convex,
            other => other,
        }
    }

    /// Whether a vertex on an edge of this kind can expose normals other than its faces'.
    const fn exposes(self) -> bool {
        matches!(self, Self::Open | Self::Convex)
    }
}

/// The three edges of one triangle; edge `k` joins its vertices `k` and `k + 1 (mod 3)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleEdges {
    /// The triangle across each edge, or [`NO_NEIGHBOUR`] for an [`EdgeKind::Open`] edge.
    pub neighbours: [u32; 3],
    /// How the surface bends across each edge (front side).
    pub kinds: [EdgeKind; 3],
    /// The neighbour's unit normal, reversed when it is wound against this triangle (so it
    /// points to the same side as this triangle's front); zero for an open edge. Mesh frame.
    pub neighbour_normals: [DVec3; 3],
}

/// Edge adjacency and bends of a whole mesh: for each triangle its [`TriangleEdges`], and
/// for each vertex whether an edge at it is bent or open. Kinds are seen from each
/// triangle's front (counter-clockwise) side; neighbours wound the other way are compared
/// through their reversed normals. The narrow phase uses it to remove ghost normals: a
/// per-triangle contact's edge or vertex normal across a flat or concave edge is not a
/// normal of the surface.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshEdges {
    triangles: Vec<TriangleEdges>,
    /// Per vertex: bit 0 set when some edge at it exposes normals on the front side, bit 1
    /// on the back side.
    vertex_exposure: Vec<u8>,
}

impl MeshEdges {
    /// Adjacency of `mesh` (allocates; `O(n log n)` for `n` triangles).
    #[must_use]
    pub fn new(mesh: &TriMesh) -> Self {
        let normals: Vec<Option<DVec3>> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle(i).normal())
            .collect();
        // Every directed edge as (smaller index, larger index, triangle, slot), grouped by
        // its undirected key.
        let mut directed: Vec<(u32, u32, u32, u8)> = mesh
            .triangles()
            .iter()
            .enumerate()
            .flat_map(|(t, tri)| {
                (0..3u8).map(move |k| {
                    let (a, b) = (tri[k as usize], tri[(k as usize + 1) % 3]);
                    (a.min(b), a.max(b), t as u32, k)
                })
            })
            .collect();
        directed.sort_unstable();
        let open = TriangleEdges {
            neighbours: [NO_NEIGHBOUR; 3],
            kinds: [EdgeKind::Open; 3],
            neighbour_normals: [DVec3::ZERO; 3],
        };
        let mut triangles = vec![open; mesh.triangle_count()];
        for group in directed.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let &[(lo, hi, t, k), (_, _, u, l)] = group else {
                continue;
            };
            if lo == hi {
                continue;
            }
            let (Some(nt), Some(nu)) = (normals[t as usize], normals[u as usize]) else {
                continue;
            };
            for (me, slot, other, n, n_other) in [(t, k, u, nt, nu), (u, l, t, nu, nt)] {
                let tri = mesh.triangles()[me as usize];
                let (a, b) = (tri[slot as usize], tri[(slot as usize + 1) % 3]);
                let other_tri = mesh.triangles()[other as usize];
                // Wound consistently, the neighbour runs the edge from b to a.
                let consistent = (0..3).any(|m| other_tri[m] == b && other_tri[(m + 1) % 3] == a);
                let aligned = if consistent { n_other } else { -n_other };
                let Some(kind) = classify(
                    n,
                    aligned,
                    mesh.vertices()[b as usize] - mesh.vertices()[a as usize],
                ) else {
                    continue;
                };
                let entry = &mut triangles[me as usize];
                entry.neighbours[slot as usize] = other;
                entry.kinds[slot as usize] = kind;
                entry.neighbour_normals[slot as usize] = aligned;
            }
        }
        let mut vertex_exposure = vec![0u8; mesh.vertex_count()];
        for (tri, edges) in mesh.triangles().iter().zip(&triangles) {
            for k in 0..3 {
                let kind = edges.kinds[k];
                let bits =
                    u8::from(kind.exposes()) | (u8::from(kind.seen_from_back().exposes()) << 1);
                vertex_exposure[tri[k] as usize] |= bits;
                vertex_exposure[tri[(k + 1) % 3] as usize] |= bits;
            }
        }
        Self {
            triangles,
            vertex_exposure,
        }
    }

    /// The edges of triangle `i`.
    ///
    /// # Panics
    /// When `i` is not a triangle index of the mesh.
    #[must_use]
    #[inline]
    pub fn triangle(&self, i: usize) -> &TriangleEdges {
        &self.triangles[i]
    }

    /// Number of triangles described.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Whether some edge at `vertex` is [`EdgeKind::Open`] or [`EdgeKind::Convex`] seen from
    /// the front side (`front`) or the back side of its triangle: then the vertex itself may
    /// expose normals other than its faces'. A vertex of no triangle exposes nothing.
    ///
    /// # Panics
    /// When `vertex` is not a vertex index of the mesh.
    #[must_use]
    #[inline]
    pub fn vertex_exposed(&self, vertex: u32, front: bool) -> bool {
        self.vertex_exposure[vertex as usize] & if front { 1 } else { 2 } != 0
    }
}

/// The kind of the edge `edge` (a to b, counter-clockwise around `n`) between a face of unit
/// normal `n` and a neighbour of aligned unit normal `aligned`; `None` for a fold (the
/// neighbour turned back onto the face).
fn classify(n: DVec3, aligned: DVec3, edge: DVec3) -> Option<EdgeKind> {
    let angle = n.cross(aligned).length().atan2(n.dot(aligned));
    if angle <= FLAT_EDGE_ANGLE {
        return Some(EdgeKind::Flat);
    }
    if angle >= std::f64::consts::PI - FLAT_EDGE_ANGLE {
        return None;
    }
    // Out of the face, in its plane, across the edge.
    let outward = edge.cross(n);
    Some(if aligned.dot(outward) > 0.0 {
        EdgeKind::Convex
    } else {
        EdgeKind::Concave
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::meshes;

    fn count(edges: &MeshEdges, kind: EdgeKind) -> usize {
        (0..edges.triangle_count())
            .flat_map(|i| edges.triangle(i).kinds)
            .filter(|&k| k == kind)
            .count()
    }

    /// Neighbours are mutual, and each edge's kind is the same seen from both triangles.
    fn assert_symmetric(edges: &MeshEdges) {
        for t in 0..edges.triangle_count() {
            let e = edges.triangle(t);
            for k in 0..3 {
                let n = e.neighbours[k];
                if n == NO_NEIGHBOUR {
                    assert_eq!(e.kinds[k], EdgeKind::Open);
                    continue;
                }
                let back = edges.triangle(n as usize);
                let slot = back.neighbours.iter().position(|&x| x == t as u32).unwrap();
                assert_eq!(back.kinds[slot], e.kinds[k], "triangle {t} edge {k}");
            }
        }
    }

    #[test]
    fn a_flat_grid_has_only_flat_internal_edges_and_open_borders() {
        let n = 6;
        let mesh = meshes::grid(2.0, n);
        let edges = MeshEdges::new(&mesh);
        assert_symmetric(&edges);
        // 4n border edges; every other edge is internal and seen twice.
        assert_eq!(count(&edges, EdgeKind::Open), 4 * n as usize);
        assert_eq!(
            count(&edges, EdgeKind::Flat),
            3 * mesh.triangle_count() - 4 * n as usize
        );
        // Interior vertices expose nothing; border vertices do (open edges).
        let interior = (n + 1) + 1;
        assert!(!edges.vertex_exposed(interior, true) && !edges.vertex_exposed(interior, false));
        assert!(edges.vertex_exposed(0, true) && edges.vertex_exposed(0, false));
    }

    #[test]
    fn a_cube_is_convex_at_its_edges_and_flat_across_its_face_diagonals() {
        let mesh = meshes::cuboid(DVec3::new(1.0, 2.0, 3.0));
        let edges = MeshEdges::new(&mesh);
        assert_symmetric(&edges);
        // 12 box edges (seen twice) and 6 face diagonals (seen twice).
        assert_eq!(count(&edges, EdgeKind::Convex), 24);
        assert_eq!(count(&edges, EdgeKind::Flat), 12);
        assert_eq!(
            count(&edges, EdgeKind::Open) + count(&edges, EdgeKind::Concave),
            0
        );
        for v in 0..mesh.vertex_count() as u32 {
            assert!(edges.vertex_exposed(v, true) && !edges.vertex_exposed(v, false));
        }
        // Seen from inside, the box is a room: every edge concave.
        assert_eq!(EdgeKind::Convex.seen_from_back(), EdgeKind::Concave);
    }

    #[test]
    fn a_tetrahedron_is_convex_everywhere_even_with_a_face_wound_backwards() {
        let v = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let outward = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let edges = MeshEdges::new(&meshes::mesh(v.clone(), outward));
        assert_eq!(count(&edges, EdgeKind::Convex), 12);
        // The first face wound inwards: its own front is the inside, so it sees its edges
        // as concave, and its neighbours still see convex edges.
        let mixed = vec![[0, 1, 2], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let edges = MeshEdges::new(&meshes::mesh(v, mixed));
        assert_eq!(edges.triangle(0).kinds, [EdgeKind::Concave; 3]);
        assert_eq!(count(&edges, EdgeKind::Convex), 9);
    }

    #[test]
    fn a_torus_has_convex_and_concave_edges_and_every_edge_a_neighbour() {
        let mesh = meshes::torus(1.0, 0.3, 24, 10);
        let edges = MeshEdges::new(&mesh);
        assert_symmetric(&edges);
        let (convex, concave) = (
            count(&edges, EdgeKind::Convex),
            count(&edges, EdgeKind::Concave),
        );
        assert!(convex > 0 && concave > 0, "{convex} / {concave}");
        assert_eq!(count(&edges, EdgeKind::Open), 0);
        // The outer equator ring (vertices at tube angle 0) is convex along the tube.
        assert!(edges.vertex_exposed(0, true));
    }

    #[test]
    fn zero_area_and_non_manifold_edges_are_open() {
        let v = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::new(0.5, -1.0, 0.0),
            DVec3::new(0.5, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 0.0),
        ];
        // Three triangles on edge 0–1 (non-manifold); a sliver (0, 1, 5) with zero area.
        let mesh = meshes::mesh(v, vec![[0, 1, 2], [1, 0, 3], [0, 1, 4], [0, 5, 1]]);
        let edges = MeshEdges::new(&mesh);
        assert_eq!(edges.triangle(0).kinds[0], EdgeKind::Open);
        assert_eq!(edges.triangle(3).kinds, [EdgeKind::Open; 3]);
    }
}
