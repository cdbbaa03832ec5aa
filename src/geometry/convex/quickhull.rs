//! Quickhull in 3D with a plane tolerance (Barber, Dobkin & Huhdanpaa 1996, "The Quickhull
//! Algorithm for Convex Hulls"; tolerance handling after D. Gregorius, GDC 2014).
//!
//! Works on points already moved near the origin (see [`super::ConvexPolyhedron`]), so that
//! the tolerance `eps` is relative to the cloud's extent. Edge cases handled:
//! - points within `eps` of the current hull are discarded (coplanar and duplicate points);
//! - a visible set whose boundary is not one simple loop (possible when rounding makes the
//!   hull slightly non-convex) is retried with a looser visibility threshold, and the eye
//!   point is dropped only if every threshold fails;
//! - a face the eye sees by less than `eps` is still made visible when the new cone face
//!   next to it would fold inward by more than `eps` at its far vertex (a small cone face
//!   beside a long sliver), unless the eye is within the input's rounding of its plane;
//! - vertices swallowed by a new cone go back into the pool, so they are re-added if they
//!   still lie outside.

use crate::math::DVec3;
use std::collections::HashMap;

/// One triangle of the hull under construction.
struct HullFace {
    /// Vertices (indices into the points), counter-clockwise seen from outside.
    v: [usize; 3],
    /// `adj[k]` is the face across the edge `v[k] → v[(k + 1) % 3]`.
    adj: [usize; 3],
    /// Outward unit normal.
    normal: DVec3,
    /// Plane offset: `normal · x = offset` on the plane.
    offset: f64,
    /// Points strictly outside this face (by more than `eps`), assigned to it.
    outside: Vec<usize>,
    /// False once the face has been replaced.
    alive: bool,
    /// Epoch of the last visibility search that marked this face visible.
    visible_epoch: u32,
}

/// Unit normal and offset of the triangle `v`, computed from its two shortest edges (the
/// cross product of the shortest edges has the smallest rounding error).
pub(super) fn triangle_plane(pts: &[DVec3], v: [usize; 3]) -> (DVec3, f64) {
    let (a, b, c) = (pts[v[0]], pts[v[1]], pts[v[2]]);
    let (e0, e1, e2) = (b - a, c - b, a - c);
    let (l0, l1, l2) = (
        e0.length_squared(),
        e1.length_squared(),
        e2.length_squared(),
    );
    let n = if l0 >= l1 && l0 >= l2 {
        e1.cross(e2)
    } else if l1 >= l2 {
        e2.cross(e0)
    } else {
        e0.cross(e1)
    };
    let n = n.normalize_or_zero();
    (n, (n.dot(a) + n.dot(b) + n.dot(c)) / 3.0)
}

/// The hull triangles (indices into `pts`, outward counter-clockwise) of the points, started
/// from the non-degenerate tetrahedron `simplex`.
pub(super) fn quickhull(
    pts: &[DVec3],
    simplex: [usize; 4],
    eps: f64,
    noise: f64,
) -> Vec<[usize; 3]> {
    let mut hull = Builder {
        pts,
        eps,
        noise,
        faces: Vec::new(),
        epoch: 0,
        scratch: Scratch::default(),
    };
    hull.start(simplex);
    let mut stack: Vec<usize> = (0..hull.faces.len()).collect();
    // NOTE: every step adds one vertex; a vertex can only be re-added after being swallowed,
    // which needs rounding-level non-convexity, so this cap is never reached in practice.
    let mut budget = 8 * pts.len() + 64;
    while let Some(fi) = stack.pop() {
        if !hull.faces[fi].alive || hull.faces[fi].outside.is_empty() {
            continue;
        }
        if budget == 0 {
            break; // the caller's containment check catches what is left
        }
        budget -= 1;
        hull.add_eye(fi, &mut stack);
    }
    hull.faces.iter().filter(|f| f.alive).map(|f| f.v).collect()
}

struct Builder<'a> {
    pts: &'a [DVec3],
    eps: f64,
    /// Rounding level of the input coordinates, metres: heights above a plane below this
    /// are noise, not geometry.
    noise: f64,
    faces: Vec<HullFace>,
    epoch: u32,
    /// Buffers each eye reuses, so adding a vertex allocates nothing once they have grown.
    scratch: Scratch,
}

/// The per-eye working sets of [`Builder::add_eye`], kept between eyes.
#[derive(Default)]
struct Scratch {
    /// Faces that see the eye.
    visible: Vec<usize>,
    /// The visible set's boundary edges `(a, b, face beyond)`, unordered.
    edges: Vec<(usize, usize, usize)>,
    /// The same edges as one loop.
    horizon: Vec<(usize, usize, usize)>,
    /// Points to reassign to the new cone's faces.
    pool: Vec<usize>,
    /// Corners of visible faces off the horizon.
    swallowed: Vec<usize>,
}

impl Builder<'_> {
    fn distance(&self, face: usize, p: usize) -> f64 {
        let f = &self.faces[face];
        f.normal.dot(self.pts[p]) - f.offset
    }

    fn push_face(&mut self, v: [usize; 3], adj: [usize; 3]) -> usize {
        let (normal, offset) = triangle_plane(self.pts, v);
        self.faces.push(HullFace {
            v,
            adj,
            normal,
            offset,
            outside: Vec::new(),
            alive: true,
            visible_epoch: 0,
        });
        self.faces.len() - 1
    }

    /// The initial tetrahedron, oriented outward, with every other point assigned.
    fn start(&mut self, simplex: [usize; 4]) {
        let [a, mut b, mut c, d] = simplex;
        let (n, off) = triangle_plane(self.pts, [a, b, c]);
        if n.dot(self.pts[d]) - off > 0.0 {
            std::mem::swap(&mut b, &mut c);
        }
        let tris = [[a, b, c], [a, d, b], [b, d, c], [c, d, a]];
        let mut edge_owner: HashMap<(usize, usize), (usize, usize)> = HashMap::new();
        for (fi, t) in tris.iter().enumerate() {
            self.push_face(*t, [usize::MAX; 3]);
            for k in 0..3 {
                edge_owner.insert((t[k], t[(k + 1) % 3]), (fi, k));
            }
        }
        for (fi, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (g, _) = edge_owner[&(t[(k + 1) % 3], t[k])];
                self.faces[fi].adj[k] = g;
            }
        }
        let pool: Vec<usize> = (0..self.pts.len())
            .filter(|i| !simplex.contains(i))
            .collect();
        self.assign(&pool, 0..4);
    }

    /// Gives each pool point to the face (among `faces`) it is farthest outside of, or drops
    /// it when it is within `eps` of all of them.
    fn assign(&mut self, pool: &[usize], faces: impl Iterator<Item = usize> + Clone) {
        for &p in pool {
            let mut best = (self.eps, usize::MAX);
            for f in faces.clone() {
                let d = self.distance(f, p);
                if d > best.0 {
                    best = (d, f);
                }
            }
            if best.1 != usize::MAX {
                self.faces[best.1].outside.push(p);
            }
        }
    }

    /// Adds the farthest outside point of face `fi` to the hull.
    fn add_eye(&mut self, fi: usize, stack: &mut Vec<usize>) {
        let eye = {
            let f = &self.faces[fi];
            let mut best = (f64::NEG_INFINITY, 0);
            for (slot, &p) in f.outside.iter().enumerate() {
                let d = f.normal.dot(self.pts[p]) - f.offset;
                if d > best.0 {
                    best = (d, slot);
                }
            }
            self.faces[fi].outside.swap_remove(best.1)
        };
        let mut scratch = std::mem::take(&mut self.scratch);
        let found = [self.eps, 0.0, -self.eps].into_iter().any(|threshold| {
            self.visible_set(fi, eye, threshold, &mut scratch.visible);
            self.horizon(&scratch.visible, &mut scratch.edges, &mut scratch.horizon)
        });
        if !found {
            // NOTE: no consistent cone exists for this eye; dropping it keeps the surface a
            // manifold. The caller checks containment and retries with a coarser tolerance.
            self.scratch = scratch;
            stack.push(fi);
            return;
        }
        let Scratch {
            visible,
            horizon,
            pool,
            swallowed,
            ..
        } = &mut scratch;
        pool.clear();
        // Corners of visible faces off the horizon, each once. (A hull vertex is in no
        // outside set, so these are the only repeats the pool could get.)
        swallowed.clear();
        for &f in visible.iter() {
            let face = &mut self.faces[f];
            face.alive = false;
            pool.append(&mut face.outside);
            for v in face.v {
                if !horizon.iter().any(|e| e.0 == v) && !swallowed.contains(&v) {
                    swallowed.push(v);
                    pool.push(v);
                }
            }
        }
        let first = self.faces.len();
        let m = horizon.len();
        for (i, &(a, b, g)) in horizon.iter().enumerate() {
            let next = first + (i + 1) % m;
            let prev = first + (i + m - 1) % m;
            let nf = self.push_face([a, b, eye], [g, next, prev]);
            let gk = (0..3)
                .find(|&k| self.faces[g].v[k] == b && self.faces[g].v[(k + 1) % 3] == a)
                .expect("horizon neighbour shares the edge");
            self.faces[g].adj[gk] = nf;
        }
        let new_faces = first..first + m;
        self.assign(pool, new_faces.clone());
        stack.extend(new_faces.filter(|&f| !self.faces[f].outside.is_empty()));
        self.scratch = scratch;
    }

    /// Fills `visible` with the faces connected to `start` that see `eye` by more than
    /// `threshold`.
    fn visible_set(&mut self, start: usize, eye: usize, threshold: f64, visible: &mut Vec<usize>) {
        self.epoch += 1;
        let epoch = self.epoch;
        visible.clear();
        visible.push(start);
        self.faces[start].visible_epoch = epoch;
        let mut i = 0;
        while i < visible.len() {
            let f = visible[i];
            i += 1;
            for k in 0..3 {
                let g = self.faces[f].adj[k];
                if self.faces[g].visible_epoch != epoch
                    && (self.distance(g, eye) > threshold || self.folds_in(f, k, g, eye))
                {
                    self.faces[g].visible_epoch = epoch;
                    visible.push(g);
                }
            }
        }
    }

    /// Whether the cone face `[a, b, eye]` over the edge `a → b` (edge `k` of face `f`) would
    /// leave the far vertex of `g` (the face across that edge) more than `eps` in front of
    /// it: a concave fold that must not be built.
    ///
    /// The eye may be up to `eps` in front of `g` and still not see it; the fold's angle is
    /// then about `eps / h`, `h` the eye's distance from the edge, and the far vertex of a
    /// long sliver `g` ends up `eps · L / h` in front of the new face (`L` its distance
    /// from the edge), far beyond tolerance. Measuring at the far vertex catches this,
    /// while a coplanar neighbour (far vertex on the new plane) is left alone.
    fn folds_in(&self, f: usize, k: usize, g: usize, eye: usize) -> bool {
        // Only an eye truly in front of `g` makes a concave fold. Within the input's rounding
        // of `g`'s plane the eye is coplanar with it: a far vertex in front of the new plane
        // then comes from that rounding (amplified when the eye is near the edge's line),
        // and making `g` visible would fold a coplanar cone over it instead.
        if self.distance(g, eye) <= self.noise {
            return false;
        }
        let (a, b) = (self.faces[f].v[k], self.faces[f].v[(k + 1) % 3]);
        let Some(&far) = self.faces[g].v.iter().find(|&&v| v != a && v != b) else {
            return false;
        };
        let (normal, offset) = triangle_plane(self.pts, [a, b, eye]);
        normal.dot(self.pts[far]) - offset > self.eps
    }

    /// The boundary of the visible set as one loop of edges `(a, b, face beyond)` in
    /// `horizon`, in the visible faces' orientation (`edges` is working space); `false` when
    /// it is not a single simple loop.
    fn horizon(
        &self,
        visible: &[usize],
        edges: &mut Vec<(usize, usize, usize)>,
        horizon: &mut Vec<(usize, usize, usize)>,
    ) -> bool {
        let epoch = self.epoch;
        edges.clear();
        for &f in visible {
            let face = &self.faces[f];
            for k in 0..3 {
                let g = face.adj[k];
                if self.faces[g].visible_epoch != epoch {
                    edges.push((face.v[k], face.v[(k + 1) % 3], g));
                }
            }
        }
        if edges.is_empty() {
            return false;
        }
        // A horizon has a handful of edges: a linear search finds the next one sooner than
        // a hash map is built.
        let starting_at = |v: usize| edges.iter().position(|e| e.0 == v);
        for (i, e) in edges.iter().enumerate() {
            if edges[..i].iter().any(|d| d.0 == e.0) {
                return false; // a vertex where the loop touches itself
            }
        }
        horizon.clear();
        let mut cur = 0;
        loop {
            horizon.push(edges[cur]);
            let Some(next) = starting_at(edges[cur].1) else {
                return false;
            };
            cur = next;
            if cur == 0 {
                break;
            }
            if horizon.len() > edges.len() {
                return false;
            }
        }
        // Fewer edges in the loop than on the boundary: the visible set has a hole.
        horizon.len() == edges.len() && horizon.len() >= 3
    }
}
