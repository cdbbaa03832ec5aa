//! Convex polyhedra: the hull of a point cloud, built robustly.
//!
//! [`ConvexPolyhedron::try_from_points`] computes the hull with quickhull and a plane
//! tolerance relative to the cloud's size; duplicate, collinear and coplanar inputs are not
//! errors but give a hull of lower [`dimension`](ConvexPolyhedron::dimension). The hull is
//! built twice when needed: the first pass finds the corners (vertices of the merged
//! coplanar faces that are not on a straight edge), the second builds the hull of the
//! corners alone, so no vertex lies in the middle of a face or an edge.

mod build;
mod faces;
mod flat;
mod quickhull;
mod scan;
mod validate;

use build::build_with_corners;
use scan::VertexLanes;

use super::{PointTree, SupportMap};
use crate::math::{DVec3, bounds_of, tolerance};
use std::collections::HashSet;
use std::fmt;

/// Why [`ConvexPolyhedron::try_from_points`] rejected a point cloud.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum ConvexHullError {
    /// The point list is empty.
    Empty,
    /// The point at this index has a NaN or infinite coordinate.
    NonFinite {
        /// Index of the offending point in the input.
        index: usize,
    },
    /// The point at this index has a coordinate above
    /// [`tolerance::MAX_COORDINATE`].
    TooLarge {
        /// Index of the offending point in the input.
        index: usize,
    },
}

impl fmt::Display for ConvexHullError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => f.write_str("convex hull of an empty point set"),
            Self::NonFinite { index } => {
                write!(
                    f,
                    "hull input point {index} has a NaN or infinite coordinate"
                )
            }
            Self::TooLarge { index } => write!(
                f,
                "hull input point {index} exceeds the largest accepted coordinate ({:e} m)",
                tolerance::MAX_COORDINATE
            ),
        }
    }
}

impl std::error::Error for ConvexHullError {}

/// A planar face of a hull: a polygon of coplanar hull triangles merged together.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// Outward unit normal (local frame).
    pub normal: DVec3,
    /// Plane offset, metres: `normal · x ≤ offset` for every hull vertex (to
    /// [`ConvexPolyhedron::tolerance`]), equality on the face.
    pub offset: f64,
    /// Outline as indices into [`ConvexPolyhedron::vertices`], counter-clockwise seen from
    /// outside (from the side `normal` points to).
    pub vertices: Vec<u32>,
}

/// The hull construction's plane tolerance for a cloud with bounds `lo`, `hi`, metres:
/// relative to its extent plus the rounding of its distance from the origin.
fn plane_tolerance(lo: DVec3, hi: DVec3) -> f64 {
    let extent = (hi - lo).max_element() * 0.5;
    let magnitude = lo.abs().max(hi.abs()).max_element();
    tolerance::PLANE_RELATIVE * extent
        + ROUNDING_ULPS * f64::EPSILON * magnitude
        + f64::MIN_POSITIVE
}

/// One triangle of [`ConvexPolyhedron::quick_hull_triangles`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HullTriangle {
    /// Corners, counter-clockwise seen from outside, metres.
    pub corners: [DVec3; 3],
    /// Outward unit normal.
    pub normal: DVec3,
    /// Plane offset, metres: `normal · x ≤ offset` inside the hull.
    pub offset: f64,
}

/// Multiple of `f64::EPSILON × magnitude` added to the plane tolerance: covers the rounding
/// of coordinates far from the origin (a flat cloud at 1e6 m is flat only to ~1e-10 m).
const ROUNDING_ULPS: f64 = 8.0;

/// How many tolerances [`ConvexPolyhedron::try_from_points`] tries, each [`RETRY_FACTOR`]
/// times the previous, before it keeps the last hull.
const RETRIES: usize = 6;
/// See [`RETRIES`].
const RETRY_FACTOR: f64 = 4.0;

/// Containment tolerance as a multiple of the construction tolerance: discarded points are
/// within one tolerance of a plane that later steps and face merging may move by a few more.
const CONTAINMENT_FACTOR: f64 = 8.0;

/// The convex hull of a finite point set, in the points' (local) frame.
///
/// # Invariants
/// - [`vertices`](Self::vertices) is a non-empty subset of the input points, without
///   duplicates; for dimension 3 each is a corner (not inside a face or an edge, to
///   tolerance).
/// - Every vertex (and every input point) lies on or behind every face plane, within
///   [`tolerance`](Self::tolerance).
/// - Dimension 3: the triangles form a closed 2-manifold with `V − E + F = 2`; each is
///   non-degenerate and counter-clockwise seen from outside.
/// - Dimension 2: the polygon is triangulated on both sides (closed, zero volume).
/// - Dimensions 0 and 1: no triangles and no faces.
/// - Dimensions 2 and 3: the vertex adjacency (used by the support map) is symmetric and
///   every vertex has a neighbour.
///
/// [`validate`](Self::validate) checks all of these.
#[derive(Debug, Clone)]
pub struct ConvexPolyhedron {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    faces: Vec<Face>,
    dimension: u8,
    /// Representable point near the cloud; planes below are relative to it.
    origin: DVec3,
    /// Containment planes `(unit normal, offset)` relative to `origin`.
    planes: Vec<(DVec3, f64)>,
    /// Construction tolerance, metres.
    eps: f64,
    /// `vertices − origin`, the support search's copy (as the hull was built on it).
    centred: Vec<DVec3>,
    /// `centred` in lanes, for the linear search of small hulls (empty for large ones).
    lanes: VertexLanes,
    /// Vertex adjacency in compressed rows: the neighbours of vertex `i` are
    /// `neighbours[neighbour_start[i]..neighbour_start[i + 1]]`. Empty below dimension 2.
    neighbour_start: Vec<u32>,
    /// See `neighbour_start`.
    neighbours: Vec<u32>,
}

/// Below this many vertices [`SupportMap::support`] scans them all; above, it climbs the
/// vertex graph.
const HILL_CLIMB_MIN_VERTICES: usize = 32;

impl ConvexPolyhedron {
    /// The convex hull of `points` (local frame, metres).
    ///
    /// Duplicate, collinear and coplanar points give a hull of lower dimension, not an
    /// error. Points within [`tolerance`](Self::tolerance) of the hull of the others are not
    /// vertices.
    ///
    /// # Errors
    /// [`ConvexHullError::Empty`] for no points, [`ConvexHullError::NonFinite`] and
    /// [`ConvexHullError::TooLarge`] with the index of the first bad point.
    pub fn try_from_points(points: &[DVec3]) -> Result<Self, ConvexHullError> {
        if points.is_empty() {
            return Err(ConvexHullError::Empty);
        }
        for (index, p) in points.iter().enumerate() {
            if !p.is_finite() {
                return Err(ConvexHullError::NonFinite { index });
            }
            if p.abs().max_element() > tolerance::MAX_COORDINATE {
                return Err(ConvexHullError::TooLarge { index });
            }
        }
        let mut unique: Vec<DVec3> = Vec::with_capacity(points.len());
        let mut seen = HashSet::with_capacity(points.len());
        for p in points {
            // `+ 0.0` folds -0.0 into 0.0 so equal points hash equally.
            let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
            if seen.insert(key) {
                unique.push(*p);
            }
        }
        let (lo, hi) = bounds_of(unique.iter().copied());
        let origin = (lo + hi) * 0.5;
        let local: Vec<DVec3> = unique.iter().map(|p| *p - origin).collect();
        let mut eps = plane_tolerance(lo, hi);
        let mut attempt = 0;
        loop {
            let hull = build_with_corners(&unique, &local, origin, eps);
            attempt += 1;
            // NOTE: thin slivers can leave a hull non-convex by more than its tolerance far
            // from the sliver (their planes are ill-conditioned). A coarser tolerance merges
            // them away; the hull reports the tolerance it was finally built with.
            if attempt == RETRIES || (hull.validate().is_ok() && hull.contains_all(&unique)) {
                debug_assert!(hull.validate().is_ok(), "{:?}", hull.validate());
                return Ok(hull);
            }
            eps *= RETRY_FACTOR;
        }
    }

    /// The triangles of the hull of `points` (counter-clockwise seen from outside) with
    /// their planes `(unit normal, offset)`, `normal · x ≤ offset` inside; coplanar
    /// triangles are not merged.
    ///
    /// A fast, unchecked measure for searches that weigh many candidate hulls (convex
    /// decomposition's cut search): no corner pass, no face merging, no validation or retry.
    /// `None` when a point is not finite or the points do not span a solid.
    #[must_use]
    pub fn quick_hull_triangles(points: &[DVec3]) -> Option<Vec<HullTriangle>> {
        if points.is_empty() || !points.iter().all(|p| p.is_finite()) {
            return None;
        }
        let (lo, hi) = bounds_of(points.iter().copied());
        let origin = (lo + hi) * 0.5;
        let local: Vec<DVec3> = points.iter().map(|p| *p - origin).collect();
        let eps = plane_tolerance(lo, hi);
        let build::Start::Solid(simplex) = build::start(&local, eps) else {
            return None;
        };
        let triangles = quickhull::quickhull(&local, simplex, eps, build::rounding_noise(points));
        Some(
            triangles
                .iter()
                .map(|&t| {
                    let (normal, offset) = quickhull::triangle_plane(&local, t);
                    HullTriangle {
                        corners: t.map(|i| points[i]),
                        normal,
                        offset: offset + normal.dot(origin),
                    }
                })
                .collect(),
        )
    }

    /// Whether every point is within tolerance of the hull (the construction contract):
    /// passes [`contains_point`](Self::contains_point). Solid and flat hulls ask, per
    /// plane, for the point farthest along its normal (the same dot products,
    /// `O(F log n)` rather than `O(F n)`).
    fn contains_all(&self, points: &[DVec3]) -> bool {
        if self.dimension < 2 {
            return points.iter().all(|p| self.contains_point(*p));
        }
        let tol = self.tolerance();
        let local: Vec<DVec3> = points.iter().map(|p| *p - self.origin).collect();
        let tree = PointTree::new(&local);
        self.planes
            .iter()
            .all(|(n, d)| tree.max_dot(*n).is_none_or(|(_, top)| top - d <= tol))
    }

    /// Hull vertices (local frame): a subset of the input points, without duplicates.
    #[must_use]
    #[inline]
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// Hull triangles, indices into [`vertices`](Self::vertices), counter-clockwise seen from
    /// outside: `(b − a) × (c − a)` points outward. For a flat hull the polygon appears
    /// twice, once per side; empty for dimensions 0 and 1.
    #[must_use]
    #[inline]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Merged planar faces with outward unit normals. Dimension 3: the polygon faces;
    /// dimension 2: the polygon once per side; empty for dimensions 0 and 1.
    #[must_use]
    #[inline]
    pub fn faces(&self) -> &[Face] {
        &self.faces
    }

    /// 0 for a point, 1 for a segment, 2 for a flat polygon, 3 for a solid.
    #[must_use]
    #[inline]
    pub fn dimension(&self) -> u8 {
        self.dimension
    }

    /// Distance (metres) within which a point counts as on a face plane: relative to the
    /// cloud's extent plus the rounding of its distance from the origin.
    #[must_use]
    #[inline]
    pub fn tolerance(&self) -> f64 {
        CONTAINMENT_FACTOR * self.eps
    }

    /// Volume, cubic metres; 0 below dimension 3.
    #[must_use]
    pub fn volume(&self) -> f64 {
        if self.dimension < 3 {
            return 0.0;
        }
        self.local_triangles()
            .map(|[a, b, c]| a.dot(b.cross(c)))
            .sum::<f64>()
            / 6.0
    }

    /// Area of the closed surface, square metres. A flat hull counts both sides (twice the
    /// polygon's area); 0 for dimensions 0 and 1.
    #[must_use]
    pub fn surface_area(&self) -> f64 {
        self.local_triangles()
            .map(|[a, b, c]| 0.5 * (b - a).cross(c - a).length())
            .sum()
    }

    /// Centroid: of the solid for dimension 3, of the polygon, the segment or the point below.
    #[must_use]
    pub fn centroid(&self) -> DVec3 {
        let local = match self.dimension {
            3 => {
                let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
                for [a, b, c] in self.local_triangles() {
                    let w = a.dot(b.cross(c));
                    sum += (a + b + c) * (w / 4.0);
                    weight += w;
                }
                sum / weight
            }
            2 => {
                let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
                for [a, b, c] in self.local_triangles() {
                    let w = (b - a).cross(c - a).length();
                    sum += (a + b + c) * (w / 3.0);
                    weight += w;
                }
                sum / weight
            }
            _ => {
                let n = self.vertices.len() as f64;
                self.vertices
                    .iter()
                    .map(|v| *v - self.origin)
                    .sum::<DVec3>()
                    / n
            }
        };
        local + self.origin
    }

    /// Whether `p` (local frame) lies in the hull, within [`tolerance`](Self::tolerance).
    #[must_use]
    pub fn contains_point(&self, p: DVec3) -> bool {
        let q = p - self.origin;
        let tol = self.tolerance();
        match self.dimension {
            0 => (q - (self.vertices[0] - self.origin)).length() <= tol,
            1 => {
                let (a, b) = (
                    self.vertices[0] - self.origin,
                    self.vertices[1] - self.origin,
                );
                let ab = b - a;
                let t = ((q - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
                (q - (a + ab * t)).length() <= tol
            }
            _ => self.planes.iter().all(|(n, d)| n.dot(q) - d <= tol),
        }
    }

    /// The largest signed distance (metres) of `p` (local frame) from the hull's face
    /// planes, positive outside; for a flat hull the polygon's edges count as planes too.
    /// `None` below dimension 2.
    #[must_use]
    pub fn max_plane_distance(&self, p: DVec3) -> Option<f64> {
        let q = p - self.origin;
        (self.dimension >= 2).then(|| {
            self.planes
                .iter()
                .map(|(n, d)| n.dot(q) - d)
                .fold(f64::NEG_INFINITY, f64::max)
        })
    }

    fn local_triangles(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.triangles
            .iter()
            .map(|t| t.map(|i| self.vertices[i as usize] - self.origin))
    }
}

impl ConvexPolyhedron {
    /// Whether the support search scans every vertex (small hulls, and hulls without a
    /// vertex graph) rather than climbing the graph.
    fn uses_linear_search(&self) -> bool {
        self.centred.len() < HILL_CLIMB_MIN_VERTICES || self.neighbours.is_empty()
    }
}

impl SupportMap for ConvexPolyhedron {
    /// Hill climbing over the vertex graph (a local maximum of a linear function on a convex
    /// polytope is global), or a linear scan for small hulls. On a hull that is convex only
    /// to tolerance, the result's `p · d` is within `tolerance() · |d|` of the maximum.
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        self.support_from(direction, &mut 0)
    }

    /// The climb starts at vertex `*hint` (any out-of-range value: vertex 0) and stores the
    /// vertex it ends at: successive GJK directions move little, so the climb is short.
    // PERF: inlined into GJK, the direction stays in registers (through a call its (y, z)
    // half was reloaded across two stores, stalling store forwarding).
    #[inline(always)]
    fn support_from(&self, direction: DVec3, hint: &mut u32) -> DVec3 {
        let centred = &self.centred;
        let score = |i: usize| centred[i].dot(direction);
        if self.uses_linear_search() {
            return self.vertices[self.lanes.argmax(direction)];
        }
        let start = if (*hint as usize) < centred.len() {
            *hint as usize
        } else {
            0
        };
        let mut best = (score(start), start);
        loop {
            let (from, to) = (
                self.neighbour_start[best.1] as usize,
                self.neighbour_start[best.1 + 1] as usize,
            );
            let before = best.1;
            for &n in &self.neighbours[from..to] {
                let s = score(n as usize);
                if s > best.0 {
                    best = (s, n as usize);
                }
            }
            if best.1 == before {
                *hint = best.1 as u32;
                return self.vertices[best.1];
            }
        }
    }
}

impl ConvexPolyhedron {
    /// Fills the vertex adjacency from the triangles.
    fn build_adjacency(&mut self) {
        let n = self.vertices.len();
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                for (x, y) in [(a, b), (b, a)] {
                    if !lists[x as usize].contains(&y) {
                        lists[x as usize].push(y);
                    }
                }
            }
        }
        self.neighbour_start = Vec::with_capacity(n + 1);
        self.neighbours.clear();
        for list in lists {
            self.neighbour_start.push(self.neighbours.len() as u32);
            self.neighbours.extend(list);
        }
        self.neighbour_start.push(self.neighbours.len() as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube_corners() -> Vec<DVec3> {
        (0..8)
            .map(|i| {
                DVec3::new(
                    (i & 1) as f64 * 2.0 - 1.0,
                    ((i >> 1) & 1) as f64 * 2.0 - 1.0,
                    ((i >> 2) & 1) as f64 * 2.0 - 1.0,
                )
            })
            .collect()
    }

    #[test]
    fn cube_hull_has_six_square_faces_and_volume_eight() {
        let h = ConvexPolyhedron::try_from_points(&cube_corners()).unwrap();
        h.validate().unwrap();
        assert_eq!(h.dimension(), 3);
        assert_eq!(h.vertices().len(), 8);
        assert_eq!(h.triangles().len(), 12);
        assert_eq!(h.faces().len(), 6);
        assert!(h.faces().iter().all(|f| f.vertices.len() == 4));
        assert!((h.volume() - 8.0).abs() < 1e-12);
        assert!((h.surface_area() - 24.0).abs() < 1e-12);
        assert!(h.centroid().length() < 1e-12);
    }

    #[test]
    fn the_same_points_give_the_same_faces_every_time() {
        // Face outlines once started at a `HashMap`'s first key, random per build, which
        // changed contact depths in the last bit between two registrations of one shape.
        let first = ConvexPolyhedron::try_from_points(&cube_corners()).unwrap();
        for _ in 0..16 {
            let again = ConvexPolyhedron::try_from_points(&cube_corners()).unwrap();
            assert_eq!(again.faces(), first.faces());
        }
    }

    #[test]
    fn errors_name_the_first_bad_point() {
        assert_eq!(
            ConvexPolyhedron::try_from_points(&[]).unwrap_err(),
            ConvexHullError::Empty
        );
        let bad = [DVec3::ZERO, DVec3::new(0.0, f64::NAN, 0.0)];
        assert_eq!(
            ConvexPolyhedron::try_from_points(&bad).unwrap_err(),
            ConvexHullError::NonFinite { index: 1 }
        );
        let huge = [DVec3::new(2e9, 0.0, 0.0)];
        assert_eq!(
            ConvexPolyhedron::try_from_points(&huge).unwrap_err(),
            ConvexHullError::TooLarge { index: 0 }
        );
        assert!(ConvexHullError::Empty.to_string().contains("empty"));
    }

    #[test]
    fn a_square_is_flat_and_closed_on_both_sides() {
        let pts: Vec<DVec3> = cube_corners().into_iter().filter(|p| p.z > 0.0).collect();
        let h = ConvexPolyhedron::try_from_points(&pts).unwrap();
        h.validate().unwrap();
        assert_eq!(h.dimension(), 2);
        assert_eq!(h.triangles().len(), 4);
        assert_eq!(h.volume(), 0.0);
        assert!((h.surface_area() - 8.0).abs() < 1e-12);
        assert!(h.contains_point(DVec3::new(0.5, 0.5, 1.0)));
        assert!(!h.contains_point(DVec3::new(0.5, 0.5, 1.1)));
    }
}
