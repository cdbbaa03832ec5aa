//! Merging the hull's coplanar triangles into polygon faces.
//!
//! Triangles are visited by decreasing area; each unassigned one seeds a face whose plane is
//! its own, and grows across shared edges to every neighbour whose three vertices lie within
//! `eps` of that plane (one fixed plane per face, so tolerance cannot drift along a chain of
//! nearly coplanar triangles). The face outline is the loop of its boundary edges; a group
//! whose boundary is not one loop is split back into its triangles.

use super::quickhull::triangle_plane;
use crate::math::DVec3;
use std::collections::HashMap;

/// A merged face in local coordinates: outward unit normal, offset (`normal · x ≤ offset`
/// for every hull vertex, to tolerance) and outline (vertex indices, counter-clockwise).
pub(super) struct LocalFace {
    pub normal: DVec3,
    pub offset: f64,
    pub outline: Vec<u32>,
}

/// Merges the closed triangulated surface `triangles` over `pts` into polygon faces.
pub(super) fn merge_coplanar(pts: &[DVec3], triangles: &[[u32; 3]], eps: f64) -> Vec<LocalFace> {
    let idx = |t: [u32; 3]| t.map(|i| i as usize);
    let mut across: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    for (ti, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            across.insert((t[k], t[(k + 1) % 3]), ti);
        }
    }
    let twice_area = |t: [u32; 3]| {
        let [a, b, c] = idx(t).map(|i| pts[i]);
        (b - a).cross(c - a).length()
    };
    let mut order: Vec<usize> = (0..triangles.len()).collect();
    order.sort_by(|&a, &b| twice_area(triangles[b]).total_cmp(&twice_area(triangles[a])));
    let mut group = vec![usize::MAX; triangles.len()];
    let mut faces = Vec::new();
    for &seed in &order {
        if group[seed] != usize::MAX {
            continue;
        }
        let (normal, offset) = triangle_plane(pts, idx(triangles[seed]));
        let id = faces.len();
        group[seed] = id;
        let mut members = vec![seed];
        let mut i = 0;
        while i < members.len() {
            let t = triangles[members[i]];
            i += 1;
            for k in 0..3 {
                let Some(&n) = across.get(&(t[(k + 1) % 3], t[k])) else {
                    continue;
                };
                let on_plane = idx(triangles[n])
                    .iter()
                    .all(|&v| (normal.dot(pts[v]) - offset).abs() <= eps);
                let (n_normal, _) = triangle_plane(pts, idx(triangles[n]));
                if group[n] == usize::MAX && on_plane && n_normal.dot(normal) > 0.0 {
                    group[n] = id;
                    members.push(n);
                }
            }
        }
        match outline(triangles, &members, &group, &across) {
            Some(loop_) => faces.push(make_face(pts, normal, loop_, &members, triangles)),
            None => {
                for &t in &members {
                    let id = faces.len();
                    group[t] = id;
                    let (own, _) = triangle_plane(pts, idx(triangles[t]));
                    faces.push(make_face(pts, own, triangles[t].to_vec(), &[t], triangles));
                }
            }
        }
    }
    faces
}

/// The boundary loop of a triangle group, or `None` when it is not a single simple loop.
fn outline(
    triangles: &[[u32; 3]],
    members: &[usize],
    group: &[usize],
    across: &HashMap<(u32, u32), usize>,
) -> Option<Vec<u32>> {
    let id = group[members[0]];
    let mut next: HashMap<u32, u32> = HashMap::new();
    for &t in members {
        let tri = triangles[t];
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let inside = across.get(&(b, a)).is_some_and(|&n| group[n] == id);
            if !inside && next.insert(a, b).is_some() {
                return None;
            }
        }
    }
    // NOTE: the smallest vertex, not the map's first key: a `HashMap`'s iteration order is
    // random per map, and the outline's first vertex decides how contacts are clipped
    // against the face (to the last bit), so the same points must give the same outline.
    let start = *next.keys().min()?;
    let mut loop_ = vec![start];
    let mut cur = next[&start];
    while cur != start {
        if loop_.len() > next.len() {
            return None;
        }
        loop_.push(cur);
        cur = *next.get(&cur)?;
    }
    (loop_.len() == next.len()).then_some(loop_)
}

/// A face with the normal of its seed (largest) triangle and the largest offset among its
/// vertices.
///
/// Every member vertex is within `eps` of the seed's plane (that is how the group grew), so
/// with this normal every outline vertex is within `2 eps` of the face plane. A normal fitted
/// to the outline (Newell's) would tilt towards a long sliver member and could leave the
/// small members' vertices farther off.
fn make_face(
    pts: &[DVec3],
    normal: DVec3,
    outline: Vec<u32>,
    members: &[usize],
    tris: &[[u32; 3]],
) -> LocalFace {
    let offset = members
        .iter()
        .flat_map(|&t| tris[t])
        .map(|v| normal.dot(pts[v as usize]))
        .fold(f64::NEG_INFINITY, f64::max);
    LocalFace {
        normal,
        offset,
        outline,
    }
}

/// Whether outline vertex `i` is a corner: farther than `eps` from the line through its
/// outline neighbours.
pub(super) fn is_corner(pts: &[DVec3], outline: &[u32], i: usize, eps: f64) -> bool {
    let m = outline.len();
    let p = |j: usize| pts[outline[j % m] as usize];
    let (a, b, c) = (p(i + m - 1), p(i), p(i + 1));
    let base = c - a;
    let len = base.length();
    if len == 0.0 {
        return (b - a).length() > eps;
    }
    (b - a).cross(base).length() / len > eps
}
