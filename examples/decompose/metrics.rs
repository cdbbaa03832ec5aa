//! How far a set of convex parts is from the mesh it stands for: `hausdorff_rel` and
//! `volume_overshoot`.
//!
//! # Definitions
//! `M` is the mesh surface, `H₁ … H_k` the parts' convex hulls (solids), `U` their union,
//! `D` the mesh's bounding-box diagonal and `τ = INSIDE_RELATIVE · D` (metres).
//!
//! - **Samples.** [`MESH_SAMPLES`] points uniform by area on `M`, plus every mesh vertex;
//!   [`HULL_SAMPLES`] points uniform by area on all hull surfaces together, plus every hull
//!   vertex. The generator is seeded with [`SEED`], so every method is measured on the same
//!   mesh samples.
//! - **Boundary of the union.** A hull sample `p` of `H_i` with outward direction `n` (its
//!   triangle's unit normal; for a vertex, the direction from the hull's centroid) is *kept*
//!   when its probe `p + τ n`, just outside `H_i`, is in no other hull `H_j` deeper than
//!   `τ / 2` (depth: the smallest distance to `H_j`'s face planes). Samples inside another
//!   hull go, and so do samples on a face that another hull covers from the other side: a
//!   cube cut in two keeps only the cube's own faces. A vertex is kept when one of its
//!   probes, its own direction and [`VERTEX_PROBES`] more over the sphere, is in no hull
//!   deeper than `−τ / 2`: where cuts meet inside the solid, the corner they make is a
//!   vertex of every piece but not on `∂U`, whichever way one probe is aimed. Kept samples
//!   sample `∂U`.
//! - **Hull → mesh:** the largest exact distance from a kept sample to `M`.
//! - **Mesh → hulls:** the largest, over mesh samples `m`, of: when `m` is in no hull
//!   deeper than `τ`, its exact distance to `U` (to the nearest hull surface); otherwise `m`
//!   is inside `U`, and its distance to `∂U` is taken as the distance to the nearest kept
//!   sample.
//! - `hausdorff_rel` = the larger of the two, over `D`.
//! - `volume_overshoot` = Σ volume(`H_i`) over the mesh's enclosed volume, minus 1.
//!   Overlaps count twice. The enclosed volume is `|Σ a · (b × c)| / 6` over the triangles
//!   (divergence theorem, about the bounding-box centre), exact for a closed mesh only;
//!   [`open_edges`] says whether it is.
//!
//! # Accuracy
//! Each sample's distance is exact (point–triangle closest points, through an AABB tree)
//! except in the inside branch. A largest distance reached at a vertex is therefore found
//! exactly; one reached elsewhere is under-estimated by at most the distance to the nearest
//! sample (distances are 1-Lipschitz), a few tenths of the sample spacing
//! `√(area / samples)`. The inside branch over-estimates the distance to `∂U` by about
//! `r² / 2d` at depth `d` for kept samples `r` apart. The unit tests measure both on
//! analytic cases.

use proxima::bounding::Aabb;
use proxima::bvh::{BuildParams, Bvh};
use proxima::geometry::{ConvexPolyhedron, TriMesh, Triangle};
use proxima::math::DVec3;
use proxima::narrow::polygon::Polygon;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;
use std::collections::HashMap;

/// Points sampled on the mesh surface (vertices come on top).
pub const MESH_SAMPLES: usize = 50_000;
/// Points sampled on the hull surfaces of one method, all hulls together (vertices on top).
pub const HULL_SAMPLES: usize = 50_000;
/// Seed of the sampling generator.
pub const SEED: u64 = 33;
/// `τ` over the bounding-box diagonal: above the hulls' own plane tolerance (`8e-10` of
/// their half extent, see `ConvexPolyhedron::tolerance`), far below any distance reported.
pub const INSIDE_RELATIVE: f64 = 1e-8;

/// Tree shape for the closest-point searches: median splits stay balanced even over the
/// zero-area "triangles" that stand for points.
const SEARCH_TREE: BuildParams = BuildParams::MEDIAN.with_leaf_size(4);

/// How far a set of convex parts is from its mesh (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Metrics {
    /// The symmetric Hausdorff distance over the diagonal: the larger of the two below.
    pub hausdorff_rel: f64,
    /// Largest distance from the union's boundary to the mesh, over the diagonal.
    pub hull_to_mesh_rel: f64,
    /// Largest distance from the mesh to the union's boundary, over the diagonal.
    pub mesh_to_hulls_rel: f64,
    /// Σ hull volumes over the mesh's enclosed volume, minus 1.
    pub volume_overshoot: f64,
}

/// The mesh's side of the metrics, made once per mesh and shared by every method.
pub struct Reference {
    surface: NearestTriangle,
    samples: Vec<DVec3>,
    diagonal: f64,
    volume: f64,
    open_edges: usize,
}

impl Reference {
    /// Samples `mesh` and builds its closest-point tree.
    #[must_use]
    pub fn new(mesh: &TriMesh) -> Self {
        let triangles: Vec<Triangle> = (0..mesh.triangle_count())
            .map(|i| mesh.triangle(i))
            .collect();
        let mut rng = Pcg64Mcg::seed_from_u64(SEED);
        let mut samples: Vec<DVec3> = sample_by_area(&triangles, MESH_SAMPLES, &mut rng)
            .into_iter()
            .map(|(p, _)| p)
            .collect();
        samples.extend(referenced_vertices(mesh));
        let (lo, hi) = mesh.bounds();
        Self {
            surface: NearestTriangle::new(&triangles).expect("a mesh has a triangle"),
            samples,
            diagonal: lo.distance(hi),
            volume: enclosed_volume(mesh),
            open_edges: open_edges(mesh),
        }
    }

    /// The mesh's bounding-box diagonal, metres.
    #[must_use]
    pub fn diagonal(&self) -> f64 {
        self.diagonal
    }

    /// The mesh's enclosed volume, cubic metres (see [`enclosed_volume`]).
    #[must_use]
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// Edges not shared by exactly two triangles (see [`open_edges`]); 0 for a closed mesh.
    #[must_use]
    pub fn open_edges(&self) -> usize {
        self.open_edges
    }

    /// The metrics of `hulls` (mesh frame). No hulls: infinite distances, overshoot −1.
    #[must_use]
    pub fn measure(&self, hulls: &[ConvexPolyhedron]) -> Metrics {
        let set = HullSet::new(hulls, INSIDE_RELATIVE * self.diagonal);
        let boundary = set.boundary_samples();
        let hull_to_mesh = if boundary.is_empty() {
            f64::INFINITY
        } else {
            boundary
                .iter()
                .map(|p| self.surface.distance(*p))
                .fold(0.0, f64::max)
        };
        let mesh_to_hulls = self.mesh_to_hulls(&set, &boundary);
        let hulls_volume: f64 = hulls.iter().map(ConvexPolyhedron::volume).sum();
        Metrics {
            hausdorff_rel: hull_to_mesh.max(mesh_to_hulls) / self.diagonal,
            hull_to_mesh_rel: hull_to_mesh / self.diagonal,
            mesh_to_hulls_rel: mesh_to_hulls / self.diagonal,
            volume_overshoot: hulls_volume / self.volume - 1.0,
        }
    }

    /// Largest distance (metres) from a mesh sample to the union's boundary: exact outside
    /// the union, to the nearest of `boundary`'s samples inside it.
    fn mesh_to_hulls(&self, set: &HullSet, boundary: &[DVec3]) -> f64 {
        let Some(surfaces) = NearestTriangle::new(&set.surface_triangles()) else {
            return f64::INFINITY;
        };
        let kept = NearestTriangle::from_points(boundary);
        self.samples
            .iter()
            .map(|&m| {
                if set.depth(m, None) <= set.tau {
                    surfaces.distance(m)
                } else {
                    kept.as_ref().map_or(f64::INFINITY, |k| k.distance(m))
                }
            })
            .fold(0.0, f64::max)
    }
}

/// The hulls of one method, with what the boundary rule and the depth tests need.
struct HullSet<'a> {
    hulls: &'a [ConvexPolyhedron],
    /// Each hull's vertex box grown by `tau`: outside it, a point is no deeper than `−tau`.
    boxes: Vec<(DVec3, DVec3)>,
    /// The inside tolerance `τ`, metres.
    tau: f64,
}

impl<'a> HullSet<'a> {
    fn new(hulls: &'a [ConvexPolyhedron], tau: f64) -> Self {
        let boxes = hulls
            .iter()
            .map(|h| {
                let (lo, hi) = h.vertices().iter().fold(
                    (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
                    |(lo, hi), v| (lo.min(*v), hi.max(*v)),
                );
                (lo - DVec3::splat(tau), hi + DVec3::splat(tau))
            })
            .collect();
        Self { hulls, boxes, tau }
    }

    /// How deep `p` lies in hull `i`, metres: its smallest distance to the face planes,
    /// positive inside; −∞ when it is outside the hull's box or the hull is not solid.
    fn depth_in(&self, i: usize, p: DVec3) -> f64 {
        let (lo, hi) = self.boxes[i];
        if p.cmplt(lo).any() || p.cmpgt(hi).any() {
            return f64::NEG_INFINITY;
        }
        self.hulls[i]
            .max_plane_distance(p)
            .map_or(f64::NEG_INFINITY, |d| -d)
    }

    /// The largest depth of `p` in the hulls other than `except`, metres (−∞ for none).
    fn depth(&self, p: DVec3, except: Option<usize>) -> f64 {
        (0..self.hulls.len())
            .filter(|&i| Some(i) != except)
            .map(|i| self.depth_in(i, p))
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether the sample `p` of hull `i`, outward direction `n`, is on the union's
    /// boundary: its probe `p + τ n` is in no other hull deeper than `τ / 2`.
    fn on_boundary(&self, i: usize, p: DVec3, n: DVec3) -> bool {
        self.depth(p + n * self.tau, Some(i)) <= 0.5 * self.tau
    }

    /// Every hull's triangles, and the point or segment of a hull below dimension 2 as a
    /// zero-area triangle: the surfaces whose nearest point is the nearest point of a hull
    /// for any point outside all hulls.
    fn surface_triangles(&self) -> Vec<Triangle> {
        let mut out = Vec::new();
        for h in self.hulls {
            let v = h.vertices();
            match (h.dimension(), v) {
                (0, [a, ..]) => out.push(Triangle::new(*a, *a, *a)),
                (1, [a, b, ..]) => out.push(Triangle::new(*a, *b, *b)),
                _ => out.extend(hull_triangles(h)),
            }
        }
        out
    }

    /// The hull samples the boundary rule keeps (module docs), seeded with [`SEED`].
    fn boundary_samples(&self) -> Vec<DVec3> {
        let (triangles, owners): (Vec<Triangle>, Vec<usize>) = self
            .hulls
            .iter()
            .enumerate()
            .flat_map(|(i, h)| hull_triangles(h).map(move |t| (t, i)))
            .unzip();
        let mut rng = Pcg64Mcg::seed_from_u64(SEED);
        let mut kept = Vec::new();
        for (p, t) in sample_by_area(&triangles, HULL_SAMPLES, &mut rng) {
            let n = triangles[t].normal().unwrap_or(DVec3::ZERO);
            if self.on_boundary(owners[t], p, n) {
                kept.push(p);
            }
        }
        let directions = crate::support::sphere_directions(VERTEX_PROBES);
        for h in self.hulls {
            let centre = h.centroid();
            for &v in h.vertices() {
                if self.vertex_on_boundary(v, (v - centre).normalize_or_zero(), &directions) {
                    kept.push(v);
                }
            }
        }
        kept
    }

    /// Whether the hull vertex `v` is on the union's boundary: one of its probes `v + τ d`
    /// is in no hull, its own included, deeper than `−τ / 2` (first `d` = `outward`, the
    /// direction from its hull's centroid, then [`VERTEX_PROBES`] directions over the
    /// sphere). A face sample needs only its one probe, but a vertex is where faces meet:
    /// where several cuts meet inside the solid, the corner is every piece's vertex, and its
    /// probe lies on or near another piece's face however it is aimed.
    fn vertex_on_boundary(&self, v: DVec3, outward: DVec3, directions: &[DVec3]) -> bool {
        std::iter::once(outward)
            .chain(directions.iter().copied())
            .any(|d| self.depth(v + d * self.tau, None) < -0.5 * self.tau)
    }
}

/// Directions a hull vertex is probed in besides its own: enough that an opening of the
/// union's outside about 30° wide at a vertex meets one.
const VERTEX_PROBES: usize = 64;

/// The triangles of a hull, counter-clockwise seen from outside.
fn hull_triangles(h: &ConvexPolyhedron) -> impl Iterator<Item = Triangle> + '_ {
    let v = h.vertices();
    h.triangles()
        .iter()
        .map(move |t| Triangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
}

/// Exact distances from points to the nearest of a fixed set of triangles, through an AABB
/// tree.
pub struct NearestTriangle {
    bvh: Bvh<Aabb>,
}

impl NearestTriangle {
    /// The search over `triangles` (finite); `None` when there are none.
    #[must_use]
    pub fn new(triangles: &[Triangle]) -> Option<Self> {
        (!triangles.is_empty()).then(|| Self {
            bvh: Bvh::from_triangles(triangles, &SEARCH_TREE),
        })
    }

    /// The search over `points` (finite), each a zero-area triangle; `None` when there are
    /// none.
    #[must_use]
    pub fn from_points(points: &[DVec3]) -> Option<Self> {
        let triangles: Vec<Triangle> = points.iter().map(|&p| Triangle::new(p, p, p)).collect();
        Self::new(&triangles)
    }

    /// Distance from `p` to the nearest triangle, metres: depth first, nearer child first,
    /// skipping subtrees whose box is no nearer than the best triangle so far.
    #[must_use]
    pub fn distance(&self, p: DVec3) -> f64 {
        let nodes = self.bvh.nodes();
        let mut best = f64::INFINITY;
        let mut stack = vec![(0_usize, 0.0_f64)];
        while let Some((i, box_distance)) = stack.pop() {
            if box_distance >= best {
                continue;
            }
            let node = &nodes[i];
            if node.is_leaf() {
                for slot in node.slots() {
                    best = best.min(distance_squared_to_triangle(p, &self.bvh.triangles()[slot]));
                }
                continue;
            }
            let [a, b] = node
                .children()
                .map(|c| (c, distance_squared_to_box(p, &nodes[c].bv)));
            let (near, far) = if a.1 <= b.1 { (a, b) } else { (b, a) };
            stack.push(far);
            stack.push(near);
        }
        best.sqrt()
    }
}

/// Squared distance from `p` to the closed triangle `t`, square metres: the crate's exact
/// closest point on a convex polygon (Ericson §5.1.5, in the frame of the longest edge, so
/// thin and zero-area triangles are handled).
fn distance_squared_to_triangle(p: DVec3, t: &Triangle) -> f64 {
    let mut polygon = Polygon::<3>::new();
    for v in t.vertices() {
        polygon.push(v);
    }
    polygon.closest_point(p).distance_squared(p)
}

/// Squared distance from `p` to the box, square metres (0 inside).
fn distance_squared_to_box(p: DVec3, b: &Aabb) -> f64 {
    (p - p.clamp(b.min, b.max)).length_squared()
}

/// `n` points uniform by area on `triangles`, each with its triangle's index; none when the
/// total area is zero.
fn sample_by_area(triangles: &[Triangle], n: usize, rng: &mut Pcg64Mcg) -> Vec<(DVec3, usize)> {
    let cumulative: Vec<f64> = triangles
        .iter()
        .scan(0.0, |sum, t| {
            *sum += t.area();
            Some(*sum)
        })
        .collect();
    let total = cumulative.last().copied().unwrap_or(0.0);
    if total <= 0.0 {
        return Vec::new();
    }
    (0..n)
        .map(|_| {
            let at = rng.random::<f64>() * total;
            let i = cumulative
                .partition_point(|&c| c <= at)
                .min(triangles.len() - 1);
            (point_in_triangle(&triangles[i], rng), i)
        })
        .collect()
}

/// A point uniform on the triangle `t` (the square-root warp of two uniform numbers).
fn point_in_triangle(t: &Triangle, rng: &mut Pcg64Mcg) -> DVec3 {
    let s = rng.random::<f64>().sqrt();
    let r = rng.random::<f64>();
    t.a * (1.0 - s) + t.b * (s * (1.0 - r)) + t.c * (s * r)
}

/// The vertices some triangle of `mesh` uses, each once.
fn referenced_vertices(mesh: &TriMesh) -> Vec<DVec3> {
    let mut used = vec![false; mesh.vertex_count()];
    for &i in mesh.triangles().iter().flatten() {
        used[i as usize] = true;
    }
    mesh.vertices()
        .iter()
        .zip(used)
        .filter_map(|(v, u)| u.then_some(*v))
        .collect()
}

/// The volume `mesh` encloses, cubic metres, by the divergence theorem:
/// `|Σ (a − o) · ((b − o) × (c − o))| / 6` with `o` the bounding-box centre. Exact for a
/// closed, consistently oriented mesh (either orientation); for an open one, the volume of
/// the surface closed by cones to `o`.
#[must_use]
pub fn enclosed_volume(mesh: &TriMesh) -> f64 {
    let (lo, hi) = mesh.bounds();
    let o = (lo + hi) * 0.5;
    let six: f64 = (0..mesh.triangle_count())
        .map(|i| {
            let t = mesh.triangle(i);
            (t.a - o).dot((t.b - o).cross(t.c - o))
        })
        .sum();
    (six / 6.0).abs()
}

/// Edges of `mesh` not shared by exactly two triangles, after welding vertices at equal
/// positions (so unwelded triangle soups count as closed when they are): 0 for a closed
/// mesh. Edges of a repeated vertex are not counted.
#[must_use]
pub fn open_edges(mesh: &TriMesh) -> usize {
    let mut welded: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.vertex_count());
    let ids: Vec<u32> = mesh
        .vertices()
        .iter()
        .map(|v| {
            // `+ 0.0` folds -0.0 into 0.0 so equal points weld.
            let key = (*v + DVec3::ZERO).to_array().map(f64::to_bits);
            let next = welded.len() as u32;
            *welded.entry(key).or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * mesh.triangle_count());
    for t in mesh.triangles() {
        for k in 0..3 {
            let (a, b) = (ids[t[k] as usize], ids[t[(k + 1) % 3] as usize]);
            if a != b {
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
    }
    edges.values().filter(|&&n| n != 2).count()
}

#[cfg(test)]
#[path = "metrics_tests.rs"]
mod tests;
