//! Whether a point on a cut plane lies on a piece's caps there: the test that spares a
//! hull point on a cap its dearest nearest-sample search (see `concavity.rs`).
//!
//! A cap outline can have thousands of edges (a cut through a fine mesh), and one hull is
//! tested at many points, and one piece against a hundred candidate hulls. So the outline
//! is put in the plane's coordinates once, its edges binned in bands across the plane
//! (a point's crossing count needs only the edges of its band), and [`CapOutlines`] keeps
//! every outline a piece has given for the next hull.

use super::buckets::Buckets;
use super::piece::Piece;
use crate::math::DVec3;
use glam::DVec2;
use std::ops::RangeInclusive;
use std::sync::{Arc, Mutex, PoisonError};

/// The outlines of a piece's caps on one cut plane, to test many points against.
pub(super) struct CapOutline {
    /// The plane's axes.
    u: DVec3,
    v: DVec3,
    /// Every directed outline edge, in the plane's coordinates `(p·u, p·v)`, metres.
    edges: Vec<[DVec2; 2]>,
    /// Bands across the plane, along `v`.
    bands: Bands,
    /// The edges of each band: those whose `v` range meets it.
    members: Buckets,
}

/// Outline edges per band, on average (about; long edges sit in several bands).
const EDGES_PER_BAND: usize = 4;

/// Most bands of one outline.
const MAX_BANDS: usize = 4096;

/// `count` bands of equal height from `v_low` up, metres.
#[derive(Debug, Clone, Copy)]
struct Bands {
    v_low: f64,
    height: f64,
    count: usize,
}

impl Bands {
    /// The band `v` falls in, if any.
    fn of(self, v: f64) -> Option<usize> {
        let at = (v - self.v_low) / self.height;
        if at.is_nan() {
            // A flat outline (every edge at one v): one band holds it.
            return (v == self.v_low).then_some(0);
        }
        (0.0..=self.count as f64)
            .contains(&at)
            .then(|| (at as usize).min(self.count - 1))
    }

    /// The bands the edge `a b` meets.
    fn met_by(self, [a, b]: [DVec2; 2]) -> RangeInclusive<usize> {
        let low = self.of(a.y.min(b.y)).unwrap_or(0);
        let high = self.of(a.y.max(b.y)).unwrap_or(0);
        low..=high
    }
}

impl CapOutline {
    /// The outline made of the directed `edges` (ends in space, on a plane of unit normal
    /// `normal`).
    pub fn new(normal: DVec3, edges: &[[DVec3; 2]]) -> Self {
        let u = normal.any_orthonormal_vector();
        let v = normal.cross(u);
        let edges: Vec<[DVec2; 2]> = edges
            .iter()
            .map(|e| e.map(|q| DVec2::new(q.dot(u), q.dot(v))))
            .collect();
        let (v_low, v_high) = edges
            .iter()
            .flatten()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), q| {
                (lo.min(q.y), hi.max(q.y))
            });
        let count = (edges.len() / EDGES_PER_BAND).clamp(1, MAX_BANDS);
        let bands = Bands {
            v_low,
            height: (v_high - v_low) / count as f64,
            count,
        };
        let members = Buckets::new(count, edges.len(), |k| bands.met_by(edges[k]));
        Self {
            u,
            v,
            edges,
            bands,
            members,
        }
    }

    /// Whether `p`, a point on the plane, lies on the caps: the winding number of their
    /// outlines about it, seen along the plane's normal, is not zero (Sunday's crossings
    /// of the ray from `p` along `+u`). Only the edges of `p`'s band can cross that ray.
    pub fn contains(&self, p: DVec3) -> bool {
        let (x, y) = (p.dot(self.u), p.dot(self.v));
        let Some(band) = self.bands.of(y) else {
            return false;
        };
        let mut winding = 0i32;
        for &k in self.members.get(band) {
            let [a, b] = self.edges[k as usize];
            let left = (b.x - a.x) * (y - a.y) - (x - a.x) * (b.y - a.y);
            if a.y <= y && b.y > y && left > 0.0 {
                winding += 1;
            } else if a.y > y && b.y <= y && left < 0.0 {
                winding -= 1;
            }
        }
        winding != 0
    }
}

/// A piece's cap outlines, gathered the first time a hull asks for them, by the cuts whose
/// plane a hull face lies on (a merged piece can hold caps of one plane under several cut
/// indices). Shared by the threads that score one piece's candidates.
pub(super) struct CapOutlines<'a> {
    pub piece: &'a Piece,
    gathered: Mutex<Vec<(Vec<usize>, Arc<CapOutline>)>>,
}

impl<'a> CapOutlines<'a> {
    /// None gathered yet.
    pub fn new(piece: &'a Piece) -> Self {
        Self {
            piece,
            gathered: Mutex::new(Vec::new()),
        }
    }

    /// The outline of the caps of the cuts `cuts` (indices into the piece's cuts, one plane).
    pub fn of(&self, cuts: &[usize]) -> Arc<CapOutline> {
        // A thread that panicked holding the lock left the list whole (a push is the only
        // change), so the list is still good to read.
        let mut gathered = self.gathered.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some((_, outline)) = gathered.iter().find(|(c, _)| c == cuts) {
            return Arc::clone(outline);
        }
        let outline = Arc::new(self.piece.cap_outline(cuts));
        gathered.push((cuts.to_vec(), Arc::clone(&outline)));
        outline
    }
}

#[cfg(test)]
mod tests {
    use super::CapOutline;
    use crate::math::{DVec3, orthonormal_basis};
    use crate::test_support::{point_in_cube, rng};
    use rand::Rng;
    use std::f64::consts::TAU;

    /// A star-shaped loop of `n` corners at random radii in `radii` about the origin of the
    /// plane spanned by `u` and `v`, counter-clockwise (clockwise when `reversed`), as edges.
    fn star(
        r: &mut crate::test_support::TestRng,
        n: usize,
        radii: (f64, f64),
        (u, v): (DVec3, DVec3),
        reversed: bool,
    ) -> Vec<[DVec3; 2]> {
        let corners: Vec<DVec3> = (0..n)
            .map(|k| {
                let angle = TAU * k as f64 / n as f64;
                let radius = r.random_range(radii.0..radii.1);
                (u * angle.cos() + v * angle.sin()) * radius
            })
            .collect();
        let mut edges: Vec<[DVec3; 2]> =
            (0..n).map(|k| [corners[k], corners[(k + 1) % n]]).collect();
        if reversed {
            edges = edges.into_iter().map(|[a, b]| [b, a]).collect();
        }
        edges
    }

    /// The winding number of the edges about `p`, by summing the angles they subtend (an
    /// algorithm independent of the crossing count under test).
    fn winding_by_angles(edges: &[[DVec3; 2]], p: DVec3, normal: DVec3) -> i32 {
        let turned: f64 = edges
            .iter()
            .map(|&[a, b]| {
                let (a, b) = (a - p, b - p);
                a.cross(b).dot(normal).atan2(a.dot(b))
            })
            .sum();
        (turned / TAU).round() as i32
    }

    #[test]
    fn banded_crossings_agree_with_the_angle_sum_over_a_star_with_a_hole() {
        let mut r = rng(3901);
        let (mut inside, mut outside) = (0, 0);
        for _ in 0..20 {
            let normal = point_in_cube(&mut r, 1.0).normalize_or(DVec3::Z);
            let (u, v) = orthonormal_basis(normal);
            let offset = normal * r.random_range(-2.0..2.0);
            let mut edges = star(&mut r, 300, (0.8, 1.0), (u, v), false);
            edges.extend(star(&mut r, 40, (0.2, 0.4), (u, v), true));
            let edges: Vec<[DVec3; 2]> = edges.iter().map(|e| e.map(|q| q + offset)).collect();
            let outline = CapOutline::new(normal, &edges);
            for _ in 0..500 {
                let p = offset + u * r.random_range(-1.1..1.1) + v * r.random_range(-1.1..1.1);
                let expected = winding_by_angles(&edges, p, normal) != 0;
                assert_eq!(outline.contains(p), expected, "at {p}");
                if expected {
                    inside += 1;
                } else {
                    outside += 1;
                }
            }
        }
        assert!(
            inside > 1000 && outside > 1000,
            "{inside} in, {outside} out"
        );
    }

    #[test]
    fn an_outline_with_no_edges_contains_nothing() {
        let outline = CapOutline::new(DVec3::Z, &[]);
        assert!(!outline.contains(DVec3::ZERO));
    }
}
