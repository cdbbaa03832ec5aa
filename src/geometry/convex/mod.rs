//! Convex polyhedra: the hull of a point cloud, built robustly.
//!
//! [`ConvexPolyhedron::try_from_points`] computes the hull with quickhull and a plane
//! tolerance relative to the cloud's size; duplicate, collinear and coplanar inputs are not
//! errors but give a hull of lower [`dimension`](ConvexPolyhedron::dimension). The hull is
//! built twice when needed: the first pass finds the corners (vertices of the merged
//! coplanar faces that are not on a straight edge), the second builds the hull of the
//! corners alone, so no vertex lies in the middle of a face or an edge.

mod faces;
mod flat;
mod quickhull;

use super::SupportMap;
use crate::math::{DVec3, tolerance};
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
    /// [`tolerance::MAX_COORDINATE`](crate::math::tolerance::MAX_COORDINATE).
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
}

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
        let (lo, hi) = bounds(&unique);
        let origin = (lo + hi) * 0.5;
        let local: Vec<DVec3> = unique.iter().map(|p| *p - origin).collect();
        let extent = (hi - lo).max_element() * 0.5;
        let magnitude = lo.abs().max(hi.abs()).max_element();
        let mut eps = tolerance::PLANE_RELATIVE * extent
            + ROUNDING_ULPS * f64::EPSILON * magnitude
            + f64::MIN_POSITIVE;
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

    /// Whether every point is within tolerance of the hull (the construction contract).
    fn contains_all(&self, points: &[DVec3]) -> bool {
        points.iter().all(|p| self.contains_point(*p))
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

    /// Checks every invariant listed under `# Invariants` on the type; `Err` names the first
    /// one broken.
    ///
    /// # Errors
    /// A message describing the broken invariant.
    pub fn validate(&self) -> Result<(), String> {
        let tol = self.tolerance();
        if self.vertices.is_empty() {
            return Err("no vertices".into());
        }
        let mut seen = HashSet::new();
        for v in &self.vertices {
            if !seen.insert(v.to_array().map(f64::to_bits)) {
                return Err(format!("duplicate vertex {v}"));
            }
        }
        let expected_vertices = match self.dimension {
            0 => self.vertices.len() == 1,
            1 => self.vertices.len() == 2,
            2 | 3 => self.vertices.len() > self.dimension as usize,
            _ => false,
        };
        if !expected_vertices {
            return Err(format!(
                "{} vertices for dimension {}",
                self.vertices.len(),
                self.dimension
            ));
        }
        if self.dimension < 2 {
            return if self.triangles.is_empty() && self.faces.is_empty() {
                Ok(())
            } else {
                Err("triangles or faces below dimension 2".into())
            };
        }
        for (i, v) in self.vertices.iter().enumerate() {
            let worst = self.max_plane_distance(*v).unwrap_or(0.0);
            if worst > tol {
                return Err(format!("vertex {i} is {worst:e} m outside a face plane"));
            }
        }
        self.validate_triangles(tol)?;
        self.validate_faces(tol)?;
        validate_closed(&self.triangles, self.vertices.len(), self.dimension == 3)
    }

    fn validate_triangles(&self, tol: f64) -> Result<(), String> {
        let local: Vec<DVec3> = self.vertices.iter().map(|v| *v - self.origin).collect();
        for (ti, t) in self.triangles.iter().enumerate() {
            if t.iter().any(|&i| i as usize >= local.len()) {
                return Err(format!("triangle {ti} indexes past the vertices"));
            }
            let [a, b, c] = t.map(|i| local[i as usize]);
            let n = (b - a).cross(c - a);
            let rounding = 64.0 * f64::EPSILON * (b - a).length() * (c - a).length();
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || n.length() <= rounding {
                return Err(format!("triangle {ti} is degenerate"));
            }
            if self.dimension == 2 {
                // NOTE: a thin fan triangle's own plane is ill-conditioned; a flat hull's
                // triangles are checked against the polygon's normal instead.
                let side = n.dot(self.faces[0].normal);
                let top = ti < self.triangles.len() / 2;
                if (side > 0.0) != top || side.abs() < 0.5 * n.length() {
                    return Err(format!("triangle {ti} is not aligned with its side"));
                }
                continue;
            }
            let (n, d) = quickhull::triangle_plane(&local, t.map(|i| i as usize));
            for (vi, v) in local.iter().enumerate() {
                let dist = n.dot(*v) - d;
                if dist > tol {
                    return Err(format!(
                        "vertex {vi} is {dist:e} m in front of triangle {ti}: not outward"
                    ));
                }
            }
        }
        if self.dimension == 3 && self.volume() <= 0.0 {
            return Err("triangles face inward (volume not positive)".into());
        }
        Ok(())
    }

    fn validate_faces(&self, tol: f64) -> Result<(), String> {
        for (fi, f) in self.faces.iter().enumerate() {
            if (f.normal.length() - 1.0).abs() > 1e-9 || f.vertices.len() < 3 {
                return Err(format!("face {fi} has a bad normal or outline"));
            }
            for &v in &f.vertices {
                let p = *self
                    .vertices
                    .get(v as usize)
                    .ok_or_else(|| format!("face {fi} indexes past the vertices"))?;
                let local_offset = f.offset - f.normal.dot(self.origin);
                let dist = f.normal.dot(p - self.origin) - local_offset;
                if dist.abs() > tol {
                    return Err(format!("face {fi} vertex {v} is {dist:e} m off its plane"));
                }
            }
        }
        Ok(())
    }

    fn local_triangles(&self) -> impl Iterator<Item = [DVec3; 3]> + '_ {
        self.triangles
            .iter()
            .map(|t| t.map(|i| self.vertices[i as usize] - self.origin))
    }

    /// Indices of vertices that are corners of some face outline.
    fn corners(&self) -> Vec<usize> {
        let local: Vec<DVec3> = self.vertices.iter().map(|v| *v - self.origin).collect();
        let mut corner = vec![false; local.len()];
        for f in &self.faces {
            for i in 0..f.vertices.len() {
                if faces::is_corner(&local, &f.vertices, i, self.eps) {
                    corner[f.vertices[i] as usize] = true;
                }
            }
        }
        (0..local.len()).filter(|&i| corner[i]).collect()
    }
}

impl SupportMap for ConvexPolyhedron {
    /// Linear scan over the vertices.
    #[inline]
    fn support(&self, direction: DVec3) -> DVec3 {
        let mut best = (f64::NEG_INFINITY, self.vertices[0]);
        for v in &self.vertices {
            let d = (*v - self.origin).dot(direction);
            if d > best.0 {
                best = (d, *v);
            }
        }
        best.1
    }
}

fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

/// Index of the point maximising `score` (the first on ties).
fn argmax(local: &[DVec3], score: impl Fn(DVec3) -> f64) -> (usize, f64) {
    let mut best = (0, f64::NEG_INFINITY);
    for (i, p) in local.iter().enumerate() {
        let s = score(*p);
        if s > best.1 {
            best = (i, s);
        }
    }
    best
}

/// [`build`], then again on the corners alone when some vertices are not corners.
fn build_with_corners(
    world: &[DVec3],
    local: &[DVec3],
    origin: DVec3,
    eps: f64,
) -> ConvexPolyhedron {
    let hull = build(world, local, origin, eps);
    if hull.dimension == 3 {
        let corners = hull.corners();
        if corners.len() < hull.vertices.len() {
            let world: Vec<DVec3> = corners.iter().map(|&i| hull.vertices[i]).collect();
            let local: Vec<DVec3> = world.iter().map(|p| *p - origin).collect();
            return build(&world, &local, origin, eps);
        }
    }
    hull
}

/// The hull of distinct points `world` (their `local` copies are `world − origin`).
fn build(world: &[DVec3], local: &[DVec3], origin: DVec3, eps: f64) -> ConvexPolyhedron {
    let mut hull = ConvexPolyhedron {
        vertices: Vec::new(),
        triangles: Vec::new(),
        faces: Vec::new(),
        dimension: 0,
        origin,
        planes: Vec::new(),
        eps,
    };
    let centre = local.iter().sum::<DVec3>() / local.len() as f64;
    // The farthest point from the centroid, and the farthest from it, are hull vertices.
    let (i0, _) = argmax(local, |p| (p - centre).length_squared());
    let p0 = local[i0];
    let (i1, d1) = argmax(local, |p| (p - p0).length());
    if d1 <= eps {
        hull.vertices = vec![world[i0]];
        return hull;
    }
    let axis = (local[i1] - p0) / d1;
    let (i2, d2) = argmax(local, |p| (p - p0).cross(axis).length());
    if d2 <= eps {
        hull.dimension = 1;
        hull.vertices = vec![world[i0], world[i1]];
        return hull;
    }
    let normal = (local[i1] - p0).cross(local[i2] - p0).normalize();
    let (i3, d3) = argmax(local, |p| (p - p0).dot(normal).abs());
    if d3 <= eps {
        let outline = flat::polygon(local, normal, eps);
        if outline.len() < 3 {
            hull.dimension = 1;
            hull.vertices = vec![world[i0], world[i1]];
            return hull;
        }
        finish_flat(&mut hull, world, local, &outline, normal);
        return hull;
    }
    let tris = quickhull::quickhull(local, [i0, i1, i2, i3], eps);
    finish_solid(&mut hull, world, local, &tris);
    hull
}

/// Compacts the vertices used by `tris` into the hull and merges its faces.
fn finish_solid(h: &mut ConvexPolyhedron, world: &[DVec3], local: &[DVec3], tris: &[[usize; 3]]) {
    h.dimension = 3;
    let mut remap = vec![u32::MAX; world.len()];
    let mut kept_local = Vec::new();
    for t in tris {
        for &i in t {
            if remap[i] == u32::MAX {
                remap[i] = h.vertices.len() as u32;
                h.vertices.push(world[i]);
                kept_local.push(local[i]);
            }
        }
    }
    h.triangles = tris.iter().map(|t| t.map(|i| remap[i])).collect();
    for f in faces::merge_coplanar(&kept_local, &h.triangles, h.eps) {
        h.planes.push((f.normal, f.offset));
        h.faces.push(Face {
            normal: f.normal,
            offset: f.offset + f.normal.dot(h.origin),
            vertices: f.outline,
        });
    }
}

/// Fills a flat hull from its polygon outline (indices into `world`, counter-clockwise about
/// `normal`).
fn finish_flat(
    h: &mut ConvexPolyhedron,
    world: &[DVec3],
    local: &[DVec3],
    outline: &[usize],
    normal: DVec3,
) {
    h.dimension = 2;
    h.vertices = outline.iter().map(|&i| world[i]).collect();
    let poly: Vec<DVec3> = outline.iter().map(|&i| local[i]).collect();
    let m = poly.len() as u32;
    for i in 1..m - 1 {
        h.triangles.push([0, i, i + 1]);
    }
    for i in 1..m - 1 {
        h.triangles.push([0, i + 1, i]);
    }
    let offset = poly
        .iter()
        .map(|p| normal.dot(*p))
        .fold(f64::NEG_INFINITY, f64::max);
    let back = poly
        .iter()
        .map(|p| -normal.dot(*p))
        .fold(f64::NEG_INFINITY, f64::max);
    h.planes.push((normal, offset));
    h.planes.push((-normal, back));
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let side = (b - a).cross(normal).normalize();
        let d = poly
            .iter()
            .map(|p| side.dot(*p))
            .fold(f64::NEG_INFINITY, f64::max);
        h.planes.push((side, d));
    }
    let ids: Vec<u32> = (0..m).collect();
    h.faces.push(Face {
        normal,
        offset: offset + normal.dot(h.origin),
        vertices: ids.clone(),
    });
    h.faces.push(Face {
        normal: -normal,
        offset: back - normal.dot(h.origin),
        vertices: ids.into_iter().rev().collect(),
    });
}

/// Every directed edge has its reverse as often as itself; for a solid, each exactly once
/// and `V − E + F = 2`.
fn validate_closed(tris: &[[u32; 3]], vertex_count: usize, solid: bool) -> Result<(), String> {
    let mut directed: std::collections::HashMap<(u32, u32), usize> = Default::default();
    for t in tris {
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        if back != count || (solid && count != 1) {
            return Err(format!("edge {a}-{b} used {count} times, reverse {back}"));
        }
    }
    if solid {
        let (v, e, f) = (
            vertex_count as i64,
            directed.len() as i64 / 2,
            tris.len() as i64,
        );
        if v - e + f != 2 {
            return Err(format!("Euler characteristic V - E + F = {}", v - e + f));
        }
    }
    Ok(())
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
