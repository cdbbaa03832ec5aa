//! The closed solid a decomposition starts from: the input mesh welded, oriented and with its
//! holes closed, as one [`Piece`].
//!
//! Real meshes arrive as triangle soups (every triangle with its own three vertices),
//! with flipped triangles, holes from a scanner and edges shared by more than two triangles.
//! Each repair here is counted in [`Repairs`]; what cannot be repaired is an error.

use super::piece::Piece;
use super::{DecomposeError, Repairs};
use crate::geometry::TriMesh;
use crate::math::DVec3;
use std::collections::{HashMap, VecDeque};

/// The repaired solid and what was done to it.
pub(super) struct Solid {
    pub piece: Piece,
    pub repairs: Repairs,
    /// Bounding-box diagonal of the input, metres.
    pub diagonal: f64,
}

/// Welds, orients and closes `mesh` (see the module docs).
pub(super) fn prepare(mesh: &TriMesh) -> Result<Solid, DecomposeError> {
    let mut repairs = Repairs::default();
    let (points, mut triangles) = weld(mesh, &mut repairs);
    let (lo, hi) = mesh.bounds();
    let diagonal = (hi - lo).length();
    if triangles.is_empty() || diagonal <= 0.0 {
        return Err(DecomposeError::NotSolid { volume: 0.0 });
    }
    repairs.flipped_triangles = orient(&points, &mut triangles);
    let mut points = points;
    repairs.holes_closed = close_holes(&mut points, &mut triangles);
    let piece = Piece::from_triangles(points, &triangles);
    let volume = piece.volume();
    // A closed surface of a flat or empty solid encloses nothing to decompose.
    if volume.is_nan() || volume <= SOLID_FRACTION * diagonal.powi(3) {
        return Err(DecomposeError::NotSolid { volume });
    }
    Ok(Solid {
        piece,
        repairs,
        diagonal,
    })
}

/// Below this fraction of the bounding-box diagonal cubed, the enclosed volume counts as
/// zero (a flat sheet, or a surface whose orientation could not be settled).
const SOLID_FRACTION: f64 = 1e-12;

/// Merges vertices at the same position and drops triangles that repeat a vertex.
fn weld(mesh: &TriMesh, repairs: &mut Repairs) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut by_position: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.vertex_count());
    let mut points = Vec::with_capacity(mesh.vertex_count());
    let welded: Vec<u32> = mesh
        .vertices()
        .iter()
        .map(|&p| {
            // `+ 0.0` folds -0.0 into 0.0 so equal points weld.
            let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
            *by_position.entry(key).or_insert_with(|| {
                points.push(p);
                points.len() as u32 - 1
            })
        })
        .collect();
    repairs.welded_vertices = mesh.vertex_count() - points.len();
    let mut triangles = Vec::with_capacity(mesh.triangle_count());
    for t in mesh.triangles() {
        let t = t.map(|i| welded[i as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            repairs.dropped_triangles += 1;
        } else {
            triangles.push(t);
        }
    }
    (points, triangles)
}

/// Makes neighbouring triangles agree on orientation (each edge shared by exactly two
/// triangles traversed once each way), then turns each component that was inconsistent, or
/// the whole mesh, outward (positive volume). Returns how many triangles were flipped.
fn orient(points: &[DVec3], triangles: &mut [[u32; 3]]) -> usize {
    let mut by_edge: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(triangles.len() * 2);
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            by_edge
                .entry((a.min(b), a.max(b)))
                .or_default()
                .push(i as u32);
        }
    }
    let mut component = vec![u32::MAX; triangles.len()];
    let mut flipped = 0;
    let mut queue = VecDeque::new();
    for seed in 0..triangles.len() {
        if component[seed] != u32::MAX {
            continue;
        }
        let (mut members, mut flips) = (Vec::new(), 0);
        component[seed] = seed as u32;
        queue.push_back(seed);
        while let Some(i) = queue.pop_front() {
            members.push(i);
            let t = triangles[i];
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let Some(sharing) = by_edge.get(&(a.min(b), a.max(b))) else {
                    continue;
                };
                // Only manifold edges say which way a neighbour should face.
                let [x, y] = sharing[..] else { continue };
                let j = if x as usize == i { y } else { x } as usize;
                if component[j] != u32::MAX {
                    continue;
                }
                component[j] = seed as u32;
                if traverses(triangles[j], a, b) {
                    triangles[j].swap(1, 2);
                    flips += 1;
                }
                queue.push_back(j);
            }
        }
        if flips > 0 && signed_volume(points, triangles, &members) < 0.0 {
            for &i in &members {
                triangles[i].swap(1, 2);
            }
            flips = members.len() - flips;
        }
        flipped += flips;
    }
    let all: Vec<usize> = (0..triangles.len()).collect();
    if signed_volume(points, triangles, &all) < 0.0 {
        for t in triangles.iter_mut() {
            t.swap(1, 2);
        }
        flipped = triangles.len() - flipped;
    }
    flipped
}

/// Whether triangle `t` runs along the directed edge `a → b`.
fn traverses(t: [u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b)
}

fn signed_volume(points: &[DVec3], triangles: &[[u32; 3]], members: &[usize]) -> f64 {
    let o = points[triangles[members[0]][0] as usize];
    members
        .iter()
        .map(|&i| {
            let [a, b, c] = triangles[i].map(|v| points[v as usize] - o);
            a.dot(b.cross(c))
        })
        .sum()
}

/// Closes every hole: each directed edge without its reverse is a border edge; the borders
/// are chained into outlines and each filled with a fan about its centroid. Returns the
/// number of holes closed.
fn close_holes(points: &mut Vec<DVec3>, triangles: &mut Vec<[u32; 3]>) -> usize {
    let mut balance: HashMap<(u32, u32), i32> = HashMap::with_capacity(triangles.len() * 3);
    for t in triangles.iter() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if a < b {
                *balance.entry((a, b)).or_default() += 1;
            } else {
                *balance.entry((b, a)).or_default() -= 1;
            }
        }
    }
    // A fill runs each border edge the other way.
    let mut fill_edges = Vec::new();
    for (&(a, b), &count) in &balance {
        let edge = if count > 0 { [b, a] } else { [a, b] };
        fill_edges.extend(std::iter::repeat_n(edge, count.unsigned_abs() as usize));
    }
    fill_edges.sort_unstable();
    let (outlines, _) = super::piece::chain_outlines(&fill_edges);
    let mut closed = 0;
    for outline in outlines.iter().filter(|o| o.len() >= 3) {
        let centre = outline
            .iter()
            .fold(DVec3::ZERO, |s, &v| s + points[v as usize])
            / outline.len() as f64;
        points.push(centre);
        let c = points.len() as u32 - 1;
        for (k, &a) in outline.iter().enumerate() {
            triangles.push([a, outline[(k + 1) % outline.len()], c]);
        }
        closed += 1;
    }
    closed
}
