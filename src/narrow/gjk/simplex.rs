//! The GJK simplex and its sub-distance algorithm: the point of a simplex (1 to 4 points of
//! the Minkowski difference) closest to the origin, and the smallest face that realises it.
//!
//! Signed-volume sub-distance after Montanari, Petrinic and Barbieri, "Improving the GJK
//! algorithm for faster and more reliable distance queries between convex objects", ACM TOG
//! 36(3), 2017: the barycentric coordinates of the origin's projection are ratios of signed
//! volumes (tetrahedron) or of signed areas (triangle); a vertex whose coordinate has the wrong sign sends the
//! search to the faces that leave it out. Flat tetrahedra and needle triangles, whose
//! determinants vanish, are replaced by the best of their faces, so no division by a zero
//! (or rounding-sized) determinant ever happens and the result is never NaN.

use crate::math::DVec3;

/// A point of the Minkowski difference `A − B` with the support points that made it, all in
/// A's frame: `w = a − b`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SupportPoint {
    /// `a − b`, metres.
    pub w: DVec3,
    /// Point of A, metres.
    pub a: DVec3,
    /// Point of B, metres.
    pub b: DVec3,
}

/// Up to four support points with the barycentric weights of the point closest to the origin.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Simplex {
    points: [SupportPoint; 4],
    /// `points[k].w`, contiguous for the sub-distance.
    ws: [DVec3; 4],
    lambda: [f64; 4],
    len: usize,
}

/// Below this `sin²` of the angle between two edges a triangle counts as a needle.
const FLAT_TRIANGLE: f64 = 1e-24;
/// Below this multiple of `|e1| |e2| |e3|` a tetrahedron's volume counts as flat.
const FLAT_TETRAHEDRON: f64 = 1e-13;

/// The outcome of the sub-distance on some of the simplex's points.
#[derive(Debug, Clone, Copy)]
struct Reduced {
    /// Indices into the simplex of the points kept, increasing (every sub-feature is named
    /// by increasing indices: `EDGE_OPPOSITE`, `FACE_OPPOSITE`).
    idx: [usize; 4],
    lambda: [f64; 4],
    len: usize,
    v: DVec3,
}

impl Reduced {
    fn point(i: usize, p: &[DVec3; 4]) -> Self {
        Self {
            idx: [i, 0, 0, 0],
            lambda: [1.0, 0.0, 0.0, 0.0],
            len: 1,
            v: p[i],
        }
    }

    fn better(self, other: Self) -> Self {
        if other.v.length_squared() < self.v.length_squared() {
            other
        } else {
            self
        }
    }
}

impl Simplex {
    /// The simplex of one point.
    #[must_use]
    pub fn single(p: SupportPoint) -> Self {
        let mut s = Self::default();
        s.points[0] = p;
        s.ws[0] = p.w;
        s.lambda[0] = 1.0;
        s.len = 1;
        s
    }

    /// The points.
    #[must_use]
    pub fn points(&self) -> &[SupportPoint] {
        &self.points[..self.len]
    }

    /// The barycentric weights of the closest point (same order as [`points`](Self::points)).
    #[must_use]
    pub fn weights(&self) -> &[f64] {
        &self.lambda[..self.len]
    }

    /// Number of points (1 to 4).
    #[must_use]
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it holds no point (only for `Default`).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether `w` is already one of the points (exactly).
    #[must_use]
    pub fn contains(&self, w: DVec3) -> bool {
        self.ws[..self.len].contains(&w)
    }

    /// Adds a point (the simplex must hold fewer than 4).
    pub fn push(&mut self, p: SupportPoint) {
        debug_assert!(self.len < 4);
        self.points[self.len] = p;
        self.ws[self.len] = p.w;
        self.len += 1;
    }

    /// The closest point to the origin as the weighted sum of the points' `(w, a, b)`.
    #[must_use]
    pub fn closest(&self) -> SupportPoint {
        let mut r = SupportPoint::default();
        for (p, &l) in self.points().iter().zip(self.weights()) {
            r.w += p.w * l;
            r.a += p.a * l;
            r.b += p.b * l;
        }
        r
    }

    /// Removes the last point [`push`](Self::push)ed, giving back the simplex as it was
    /// (weights included) when [`reduce_if_closer`](Self::reduce_if_closer) refused it.
    fn pop(&mut self) {
        debug_assert!(self.len > 1);
        self.len -= 1;
    }

    /// [`reduce`](Self::reduce) when the new closest point is closer to the origin than
    /// `dist2` (squared metres); otherwise drops the last pushed point and keeps the simplex
    /// as it was. Returns the new closest point, or `None` when there was no progress.
    ///
    /// The last point pushed must be a new support point that made progress (GJK's step):
    /// the closer point then lies on a face holding it, and faces without it are searched
    /// only when no other face is left (to rounding they can still win; the progress test
    /// then rejects them).
    #[inline(always)]
    pub fn reduce_if_closer(&mut self, dist2: f64) -> Option<DVec3> {
        let r = self.sub_distance(Newest::Last);
        if r.v.length_squared() >= dist2 {
            self.pop();
            return None;
        }
        self.apply(&r);
        Some(r.v)
    }

    /// Replaces the simplex by the smallest sub-simplex containing its point closest to the
    /// origin, stores that point's weights and returns it (`w` part). A full tetrahedron is
    /// kept only when it contains the origin; the result is then exactly zero.
    pub fn reduce(&mut self) -> DVec3 {
        let r = self.sub_distance(Newest::Unknown);
        self.apply(&r);
        r.v
    }

    /// The sub-distance of the current points (Montanari's signed volumes).
    fn sub_distance(&self, newest: Newest) -> Reduced {
        let p = &self.ws;
        match self.len {
            1 => Reduced::point(0, p),
            2 => segment(p, 0, 1),
            3 => triangle(p, [0, 1, 2], newest),
            _ => tetrahedron(p, newest),
        }
    }

    /// Keeps the points and weights `r` selects.
    fn apply(&mut self, r: &Reduced) {
        // `r.idx` is increasing (see `Reduced`), so moving the points down in place never
        // overwrites one still to be moved, and a kept prefix does not move at all.
        for slot in 0..r.len {
            let from = r.idx[slot];
            debug_assert!(from >= slot && (slot == 0 || from > r.idx[slot - 1]));
            if from != slot {
                self.points[slot] = self.points[from];
                self.ws[slot] = self.ws[from];
            }
            self.lambda[slot] = r.lambda[slot];
        }
        self.len = r.len;
    }
}

/// Whether the last point of a simplex (or face) is the new support point of a GJK step,
/// which lets the sub-distance skip the old face opposite it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Newest {
    Last,
    Unknown,
}

/// The sub-features to search, opposite the vertices whose barycentric sign is `wrong`:
/// with [`Newest::Last`], the one opposite the last vertex (the old simplex, which cannot
/// be closer) only when no other is named. PERF: spares a triangle (or segment) solve.
fn to_search<const N: usize>(mut wrong: [bool; N], newest: Newest) -> [bool; N] {
    if newest == Newest::Last && wrong[..N - 1].contains(&true) {
        wrong[N - 1] = false;
    }
    wrong
}

/// The edges of a triangle `[0, 1, 2]` opposite each vertex, in increasing order.
const EDGE_OPPOSITE: [[usize; 2]; 3] = [[1, 2], [0, 2], [0, 1]];
/// The faces of a tetrahedron `[0, 1, 2, 3]` opposite each vertex, in increasing order.
const FACE_OPPOSITE: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

#[inline(always)]
fn segment(p: &[DVec3; 4], i: usize, j: usize) -> Reduced {
    let (a, b) = (p[i], p[j]);
    let e = b - a;
    let ee = e.length_squared();
    if ee == 0.0 {
        return Reduced::point(i, p);
    }
    let t = -a.dot(e) / ee;
    if t <= 0.0 {
        return Reduced::point(i, p);
    }
    if t >= 1.0 {
        return Reduced::point(j, p);
    }
    Reduced {
        idx: [i, j, 0, 0],
        lambda: [1.0 - t, t, 0.0, 0.0],
        len: 2,
        v: a * (1.0 - t) + b * t,
    }
}

fn same_sign(a: f64, b: f64) -> bool {
    (a > 0.0 && b > 0.0) || (a < 0.0 && b < 0.0)
}

#[inline(always)]
fn triangle(p: &[DVec3; 4], t: [usize; 3], newest: Newest) -> Reduced {
    let (a, b, c) = (p[t[0]], p[t[1]], p[t[2]]);
    let (e1, e2) = (b - a, c - a);
    let n = e1.cross(e2);
    let nn = n.length_squared();
    if nn <= FLAT_TRIANGLE * e1.length_squared() * e2.length_squared() || nn.is_nan() {
        return best_edge(p, t, [true; 3]);
    }
    // Projection of the origin on the plane, then the signed areas of the three
    // sub-triangles it makes, measured along `n` from vertex-relative vectors (Montanari
    // projects on the coordinate plane of largest area instead; both have the same signs,
    // and this form needs no data-dependent choice of plane).
    // PERF: the areas are taken on the plane scaled by `nn` (`nn · x − P`, `P = nn · p0`):
    // all three scale by `nn³`, and the division for `p0` is off the path to the signs.
    // They grow as the 12th power of the edge length: no overflow below 1e25 m, and an
    // underflow (edges under 1e-25 m) zeroes them, which sends the search to the edges.
    let big_p = n * a.dot(n);
    let (ra, rb, rc) = (a * nn - big_p, b * nn - big_p, c * nn - big_p);
    let c_ = [
        n.dot(rb.cross(rc)),
        n.dot(rc.cross(ra)),
        n.dot(ra.cross(rb)),
    ];
    let total = c_[0] + c_[1] + c_[2];
    let wrong = [
        !same_sign(c_[0], total),
        !same_sign(c_[1], total),
        !same_sign(c_[2], total),
    ];
    if wrong == [false; 3] {
        let l = [c_[0] / total, c_[1] / total, c_[2] / total];
        return Reduced {
            idx: [t[0], t[1], t[2], 0],
            lambda: [l[0], l[1], l[2], 0.0],
            len: 3,
            v: big_p / nn,
        };
    }
    best_edge(p, t, to_search(wrong, newest))
}

#[inline(always)]
fn tetrahedron(p: &[DVec3; 4], newest: Newest) -> Reduced {
    let [a, b, c, d] = *p;
    let vol = |x: DVec3, y: DVec3, z: DVec3, w: DVec3| (y - x).dot((z - x).cross(w - x));
    let o = DVec3::ZERO;
    let c_ = [
        vol(o, b, c, d),
        vol(a, o, c, d),
        vol(a, b, o, d),
        vol(a, b, c, o),
    ];
    let total = c_.iter().sum::<f64>();
    // Squared, to spare three square roots: `|total| ≤ FLAT · |e1| |e2| |e3|`.
    let size2 = (b - a).length_squared() * (c - a).length_squared() * (d - a).length_squared();
    if total * total <= FLAT_TETRAHEDRON * FLAT_TETRAHEDRON * size2 || total.is_nan() {
        return best_face(p, [true; 4], newest);
    }
    let wrong = c_.map(|x| !same_sign(x, total));
    if wrong == [false; 4] {
        return Reduced {
            idx: [0, 1, 2, 3],
            lambda: c_.map(|x| x / total),
            len: 4,
            v: DVec3::ZERO,
        };
    }
    best_face(p, to_search(wrong, newest), newest)
}

/// The closest to the origin of triangle `t`'s edges opposite the vertices `skip` marks
/// (at least one).
// PERF: a function rather than a closure so that it can be forced inline (about 3 % of a
// query on 8-vertex hulls went to the call and the returned value).
#[inline(always)]
fn best_edge(p: &[DVec3; 4], t: [usize; 3], skip: [bool; 3]) -> Reduced {
    let mut best: Option<Reduced> = None;
    for (k, &s) in skip.iter().enumerate() {
        if s {
            let [i, j] = EDGE_OPPOSITE[k];
            let r = segment(p, t[i], t[j]);
            best = Some(best.map_or(r, |b| b.better(r)));
        }
    }
    best.expect("a marked vertex names an edge")
}

/// The closest to the origin of the tetrahedron's faces opposite the vertices `skip` marks
/// (at least one); `newest` as for the tetrahedron.
#[inline(always)]
fn best_face(p: &[DVec3; 4], skip: [bool; 4], newest: Newest) -> Reduced {
    let mut best: Option<Reduced> = None;
    for (k, &s) in skip.iter().enumerate() {
        if s {
            // Faces 0 to 2 hold vertex 3, last in each; face 3 does not.
            let face_newest = if k < 3 { newest } else { Newest::Unknown };
            let r = triangle(p, FACE_OPPOSITE[k], face_newest);
            best = Some(best.map_or(r, |b| b.better(r)));
        }
    }
    best.expect("a marked vertex names a face")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn simplex(ws: &[DVec3]) -> Simplex {
        let mut s = Simplex::single(SupportPoint {
            w: ws[0],
            ..Default::default()
        });
        for &w in &ws[1..] {
            s.push(SupportPoint {
                w,
                ..Default::default()
            });
        }
        s
    }

    #[test]
    fn a_segment_across_the_origin_reduces_to_its_foot() {
        let mut s = simplex(&[DVec3::new(-1.0, 1.0, 0.0), DVec3::new(1.0, 1.0, 0.0)]);
        assert_eq!(s.reduce(), DVec3::new(0.0, 1.0, 0.0));
        assert_eq!(s.len(), 2);
    }

    #[test]
    fn a_triangle_above_the_origin_keeps_all_three_points() {
        let mut s = simplex(&[
            DVec3::new(-1.0, -1.0, 2.0),
            DVec3::new(1.0, -1.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
        ]);
        let v = s.reduce();
        assert!((v - DVec3::new(0.0, 0.0, 2.0)).length() < 1e-15);
        assert_eq!(s.len(), 3);
        assert!((s.weights().iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_tetrahedron_around_the_origin_gives_zero_and_one_beside_gives_a_vertex() {
        let around = [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, -1.0, 1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(1.0, -1.0, -1.0),
        ];
        let mut s = simplex(&around);
        assert_eq!(s.reduce(), DVec3::ZERO);
        assert_eq!(s.len(), 4);
        let beside: Vec<DVec3> = around.iter().map(|&p| p + DVec3::splat(3.0)).collect();
        let mut s = simplex(&beside);
        let v = s.reduce();
        // Nearest: the face on the plane x + y + z = 8.
        assert_eq!(s.len(), 3);
        assert!((v - DVec3::splat(8.0 / 3.0)).length() < 1e-14, "{v}");
    }

    #[test]
    fn flat_and_repeated_simplices_give_finite_answers() {
        // Four coplanar points, a repeated point, a needle triangle.
        let cases: [&[DVec3]; 3] = [
            &[
                DVec3::new(-1.0, -1.0, 1.0),
                DVec3::new(1.0, -1.0, 1.0),
                DVec3::new(1.0, 1.0, 1.0),
                DVec3::new(-1.0, 1.0, 1.0),
            ],
            &[DVec3::new(1.0, 2.0, 3.0), DVec3::new(1.0, 2.0, 3.0)],
            &[
                DVec3::new(1.0, 0.0, 1.0),
                DVec3::new(2.0, 0.0, 1.0),
                DVec3::new(3.0, 1e-30, 1.0),
            ],
        ];
        for ws in cases {
            let mut s = simplex(ws);
            let v = s.reduce();
            assert!(v.is_finite(), "{ws:?} → {v}");
            let best = ws.iter().map(|p| p.length()).fold(f64::INFINITY, f64::min);
            assert!(v.length() <= best + 1e-15);
        }
    }
}
