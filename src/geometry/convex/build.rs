//! Building a hull: the dimension test, then quickhull (solid) or the polygon (flat), and
//! the corner pass.

use super::{ConvexPolyhedron, Face, ROUNDING_ULPS, VertexLanes, faces, flat, quickhull};
use crate::math::DVec3;

impl ConvexPolyhedron {
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

/// [`build`], then again on the corners alone when some vertices are not corners; fills
/// the support search's centred vertices.
pub(super) fn build_with_corners(
    world: &[DVec3],
    local: &[DVec3],
    origin: DVec3,
    eps: f64,
) -> ConvexPolyhedron {
    let mut hull = build(world, local, origin, eps);
    if hull.dimension == 3 {
        let corners = hull.corners();
        if corners.len() < hull.vertices.len() {
            let world: Vec<DVec3> = corners.iter().map(|&i| hull.vertices[i]).collect();
            let local: Vec<DVec3> = world.iter().map(|p| *p - origin).collect();
            hull = build(&world, &local, origin, eps);
        }
    }
    hull.centred = hull.vertices.iter().map(|v| *v - origin).collect();
    if hull.uses_linear_search() {
        hull.lanes = VertexLanes::new(&hull.centred);
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
        centred: Vec::new(),
        lanes: VertexLanes::default(),
        neighbour_start: Vec::new(),
        neighbours: Vec::new(),
    };
    match start(local, eps) {
        Start::Point(i0) => hull.vertices = vec![world[i0]],
        Start::Segment(i0, i1) => {
            hull.dimension = 1;
            hull.vertices = vec![world[i0], world[i1]];
        }
        Start::Flat(normal, [i0, i1]) => {
            let outline = flat::polygon(local, normal, eps);
            if outline.len() < 3 {
                hull.dimension = 1;
                hull.vertices = vec![world[i0], world[i1]];
            } else {
                finish_flat(&mut hull, world, local, &outline, normal);
                hull.build_adjacency();
            }
        }
        Start::Solid(simplex) => {
            let tris = quickhull::quickhull(local, simplex, eps, rounding_noise(world));
            finish_solid(&mut hull, world, local, &tris);
            hull.build_adjacency();
        }
    }
    hull
}

/// How a hull starts: the first points that span it, or the lower dimension it has.
pub(super) enum Start {
    Point(usize),
    Segment(usize, usize),
    /// Coplanar: the plane's unit normal and two points far apart.
    Flat(DVec3, [usize; 2]),
    /// A tetrahedron of points more than `eps` apart in every dimension.
    Solid([usize; 4]),
}

/// The start of the hull of distinct points `local` (near the origin) at tolerance `eps`.
pub(super) fn start(local: &[DVec3], eps: f64) -> Start {
    let centre = local.iter().sum::<DVec3>() / local.len() as f64;
    // The farthest point from the centroid, and the farthest from it, are hull vertices.
    let (i0, _) = argmax(local, |p| (p - centre).length_squared());
    let p0 = local[i0];
    let (i1, d1) = argmax(local, |p| (p - p0).length());
    if d1 <= eps {
        return Start::Point(i0);
    }
    let axis = (local[i1] - p0) / d1;
    let (i2, d2) = argmax(local, |p| (p - p0).cross(axis).length());
    if d2 <= eps {
        return Start::Segment(i0, i1);
    }
    let normal = (local[i1] - p0).cross(local[i2] - p0).normalize();
    let (i3, d3) = argmax(local, |p| (p - p0).dot(normal).abs());
    if d3 <= eps {
        return Start::Flat(normal, [i0, i1]);
    }
    Start::Solid([i0, i1, i2, i3])
}

/// How far rounding the input coordinates can move a point off a plane: the level below
/// which an eye's height above a face is noise.
pub(super) fn rounding_noise(world: &[DVec3]) -> f64 {
    let magnitude = world
        .iter()
        .map(|p| p.abs().max_element())
        .fold(0.0, f64::max);
    ROUNDING_ULPS * f64::EPSILON * magnitude
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
