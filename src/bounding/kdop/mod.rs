//! k-DOP: the intersection of `N` slabs along fixed directions (k = 2N discrete orientations).
//!
//! Directions are fixed, integer and unnormalised (see [`directions`]): the 14-DOP uses the 3
//! axes and the 4 corner diagonals, the 18-DOP the axes and the 6 edge diagonals, the 26-DOP
//! all 13 (Klosowski et al. 1998, "Efficient collision detection using bounding volume
//! hierarchies of k-DOPs"). Fit, merge and same-frame overlap are exact interval work.
//!
//! # Refit after rotation
//! A k-DOP does not stay a k-DOP when rotated, so [`BoundingVolume::transformed`] encloses the
//! moved one. For each target direction `d` of the parent frame, the largest `d · x` over the
//! moved DOP is `h(Rᵀd) + d · t`, with `h` the support function of the original DOP. `h` is
//! sublinear, so writing `u = Rᵀd = Σ λ_i v_i` with `λ_i >= 0` over the DOP's own signed
//! directions `v_i` gives `h(u) <= Σ λ_i h(v_i)`, and `h(v_i)` is a slab maximum (or minus a
//! slab minimum): a valid upper bound for any such combination (the dual of the LP
//! `max u · x` over the slabs). The combination used is the simplicial cone of the octant
//! that contains `u` (components sorted `A >= B >= C`):
//! - 26-DOP: `(A−B)·e_a + (B−C)·(e_a+e_b) + C·(e_a+e_b+e_c)`;
//! - 14-DOP: `C·corner + (A−C)·e_a + (B−C)·e_b`;
//! - 18-DOP: `(A−B−C)·e_a + B·(e_a+e_b) + C·(e_a+e_c)` when `A >= B + C`, else
//!   `(e_a+e_b)(A+B−C)/2 + (e_a+e_c)(A+C−B)/2 + (e_b+e_c)(B+C−A)/2`;
//!
//! and the result is also clipped by the axis-only bound `Σ |u_i| h(±e_i)`. Minima use the
//! same combination with every direction negated. The answer is padded by a relative slack.
//! Overlap under a pose tests A against B refitted into A's frame, slab by slab.

mod directions;
mod polytope;

use self::directions::{Layout, Signed};
use super::BoundingVolume;
use crate::geometry::Triangle;
use crate::math::{DMat3, DVec3, Isometry, conservative_slack};

/// A k-DOP with `N` slab directions: `{x : min[k] <= d_k · x <= max[k] for every k}`, local
/// frame, slab values in metres times `|d_k|` (directions are unnormalised integers).
///
/// Only `N` = 7, 9 and 13 exist ([`Kdop14`], [`Kdop18`], [`Kdop26`]); any other `N` fails to
/// compile as soon as a method is used:
///
/// ```compile_fail
/// use proxima::bounding::{BoundingVolume, Kdop};
/// use proxima::math::DVec3;
/// let _ = Kdop::<8>::fit_points(&[DVec3::ZERO]);
/// ```
///
/// # Invariants
/// `min[k] <= max[k]` for every slot, all finite; slots 0..3 are the x, y, z axes, so the
/// first three slabs are the DOP's AABB (which contains it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kdop<const N: usize> {
    /// Lower slab values, `min over the volume of d_k · x`.
    pub min: [f64; N],
    /// Upper slab values, `max over the volume of d_k · x`.
    pub max: [f64; N],
}

/// 14-DOP: axes and corner diagonals.
pub type Kdop14 = Kdop<7>;
/// 18-DOP: axes and edge diagonals.
pub type Kdop18 = Kdop<9>;
/// 26-DOP: axes, corner and edge diagonals.
pub type Kdop26 = Kdop<13>;

impl<const N: usize> Kdop<N> {
    /// The slab directions in slot order. Evaluating it for `N` other than 7, 9 or 13 is a
    /// compile-time error, which is what makes invalid `N` unusable.
    pub const DIRECTIONS: [DVec3; N] = directions::directions::<N>();
    const INVERSE_NORMS: [f64; N] = directions::inverse_norms::<N>();
    const LAYOUT: Layout = Layout::of(N);

    /// The slab values of `point`, `d_k · point` for each slot.
    #[must_use]
    #[inline]
    pub fn slab_values(point: DVec3) -> [f64; N] {
        let mut out = [0.0; N];
        for (value, d) in out.iter_mut().zip(Self::DIRECTIONS) {
            *value = d.dot(point);
        }
        out
    }

    /// The AABB part (slots 0..3), lower corner.
    #[must_use]
    #[inline]
    pub fn aabb_min(&self) -> DVec3 {
        DVec3::new(self.min[0], self.min[1], self.min[2])
    }

    /// The AABB part (slots 0..3), upper corner.
    #[must_use]
    #[inline]
    pub fn aabb_max(&self) -> DVec3 {
        DVec3::new(self.max[0], self.max[1], self.max[2])
    }

    /// Centre of the AABB part (not always inside the k-DOP; see
    /// [`center`](BoundingVolume::center)).
    #[must_use]
    #[inline]
    pub fn aabb_center(&self) -> DVec3 {
        (self.aabb_min() + self.aabb_max()) * 0.5
    }

    /// Diagonal length of the AABB part, metres.
    #[must_use]
    #[inline]
    pub fn aabb_diagonal(&self) -> f64 {
        (self.aabb_max() - self.aabb_min()).length()
    }

    /// Largest magnitude of any slab value.
    #[inline]
    fn magnitude(&self) -> f64 {
        let mut m = 0.0_f64;
        for k in 0..N {
            m = m.max(self.min[k].abs()).max(self.max[k].abs());
        }
        m
    }

    /// The interval of `s · (d · x)` over the DOP for a signed direction `s · d`, as bounded
    /// by its slab.
    #[inline]
    fn signed_interval(&self, s: Signed) -> (f64, f64) {
        if s.negated {
            (-self.max[s.slot], -self.min[s.slot])
        } else {
            (self.min[s.slot], self.max[s.slot])
        }
    }

    /// Bounds `(lo, hi)` with `lo <= min u · x` and `hi >= max u · x` over the DOP (up to
    /// rounding): the better of the cone combination and the axis-only bound.
    #[inline]
    fn support_interval(&self, u: DVec3) -> (f64, f64) {
        let signs = [u.x < 0.0, u.y < 0.0, u.z < 0.0];
        let (mut lo_axes, mut hi_axes) = (0.0, 0.0);
        for (a, weight) in u.abs().to_array().into_iter().enumerate() {
            let (lo, hi) = self.signed_interval(directions::axis(a, signs));
            lo_axes += weight * lo;
            hi_axes += weight * hi;
        }
        let (mut lo_cone, mut hi_cone) = (0.0, 0.0);
        for (weight, s) in directions::cone_combination(Self::LAYOUT, u) {
            let (lo, hi) = self.signed_interval(s);
            lo_cone += weight * lo;
            hi_cone += weight * hi;
        }
        (lo_axes.max(lo_cone), hi_axes.min(hi_cone))
    }

    /// The slack of a refit of `self` under a pose with translation `t`: every term of the
    /// refit is at most `|d|_1 <= 3` times a slab value or a translation component.
    #[inline]
    fn refit_pad(&self, t: DVec3) -> f64 {
        conservative_slack(4.0 * (3.0 * self.magnitude() + t.abs().max_element()))
    }

    /// Slot `k` of the refit of `self` under the pose `(Rᵀ = r_t, t)`: bounds on `d_k · x`
    /// over the moved DOP, padded by `pad`.
    #[inline]
    fn refit_slab(&self, k: usize, r_t: &DMat3, t: DVec3, pad: f64) -> (f64, f64) {
        let d = Self::DIRECTIONS[k];
        let (lo, hi) = self.support_interval(*r_t * d);
        let offset = d.dot(t);
        (lo + offset - pad, hi + offset + pad)
    }

    /// The fitted DOP of `points`, padded.
    fn fit_iter(points: impl Iterator<Item = DVec3>) -> Self {
        let mut min = [f64::INFINITY; N];
        let mut max = [f64::NEG_INFINITY; N];
        let mut largest = 0.0_f64;
        for p in points {
            largest = largest.max(p.abs().max_element());
            for k in 0..N {
                let v = Self::DIRECTIONS[k].dot(p);
                min[k] = min[k].min(v);
                max[k] = max[k].max(v);
            }
        }
        debug_assert!(min[0].is_finite(), "fit of an empty or non-finite set");
        // Slab values are sums of up to 3 coordinates.
        let pad = conservative_slack(3.0 * largest);
        for k in 0..N {
            min[k] -= pad;
            max[k] += pad;
        }
        Self { min, max }
    }
}

impl<const N: usize> BoundingVolume for Kdop<N> {
    const NAME: &'static str = match N {
        7 => "kdop14",
        9 => "kdop18",
        13 => "kdop26",
        _ => panic!("a k-DOP has 7, 9 or 13 slab directions"),
    };

    fn fit_points(points: &[DVec3]) -> Self {
        debug_assert!(!points.is_empty(), "fit of an empty point set");
        Self::fit_iter(points.iter().copied())
    }

    fn fit_triangles(triangles: &[Triangle]) -> Self {
        debug_assert!(!triangles.is_empty(), "fit of an empty triangle set");
        Self::fit_iter(triangles.iter().flat_map(Triangle::vertices))
    }

    #[inline]
    fn merged(&self, other: &Self) -> Self {
        let mut out = *self;
        for k in 0..N {
            out.min[k] = out.min[k].min(other.min[k]);
            out.max[k] = out.max[k].max(other.max[k]);
        }
        out
    }

    /// A conservative k-DOP (parent frame) of the moved one: see the module doc.
    #[inline]
    fn transformed(&self, pose: &Isometry) -> Self {
        let r_t = pose.rotation.transpose();
        let pad = self.refit_pad(pose.translation);
        let mut out = *self;
        for k in 0..N {
            (out.min[k], out.max[k]) = self.refit_slab(k, &r_t, pose.translation, pad);
        }
        out
    }

    /// Whether two k-DOPs of the same frame share a point as far as the slabs tell (closed
    /// intervals, no slack): false only when some slab separates them.
    #[inline]
    fn intersects(&self, other: &Self) -> bool {
        let mut overlap = true;
        for k in 0..N {
            overlap &= self.min[k] <= other.max[k] && other.min[k] <= self.max[k];
        }
        overlap
    }

    /// `other` refitted into A's frame, then the slab interval test; stops at the first
    /// separating slab (same answer as `self.intersects(&other.transformed(pose_ab))`).
    #[inline]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool {
        let r_t = pose_ab.rotation.transpose();
        let pad = other.refit_pad(pose_ab.translation);
        for k in 0..N {
            let (lo, hi) = other.refit_slab(k, &r_t, pose_ab.translation, pad);
            if lo > self.max[k] || hi < self.min[k] {
                return false;
            }
        }
        true
    }

    /// The widest slab gap between A and B refitted into A's frame, over `|d_k|`, less a
    /// rounding slack. Each slab is a pair of parallel planes, so its gap bounds the distance
    /// from below.
    #[inline]
    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64 {
        let b = other.transformed(pose_ab);
        let mut gap = 0.0_f64;
        for k in 0..N {
            let slab_gap = (self.min[k] - b.max[k]).max(b.min[k] - self.max[k]);
            gap = gap.max(slab_gap * Self::INVERSE_NORMS[k]);
        }
        (gap - conservative_slack(self.magnitude() + b.magnitude())).max(0.0)
    }

    #[inline]
    fn contains_point(&self, point: DVec3) -> bool {
        let mut inside = true;
        for k in 0..N {
            let v = Self::DIRECTIONS[k].dot(point);
            inside &= self.min[k] <= v && v <= self.max[k];
        }
        inside
    }

    /// The AABB part's centre when the DOP contains it (the common case), else the mean of
    /// the polytope's face vertices (a point inside; not a hot path).
    fn center(&self) -> DVec3 {
        let c = self.aabb_center();
        if self.contains_point(c) {
            return c;
        }
        polytope::vertex_mean(self).unwrap_or(c)
    }

    /// The exact volume of the polytope (faces clipped from the slab planes). Not a hot path.
    fn volume(&self) -> f64 {
        polytope::volume(self)
    }

    /// The diagonal of the AABB part, which contains the k-DOP: within a factor √3 of the
    /// k-DOP's own diameter and never below it.
    #[inline]
    fn size(&self) -> f64 {
        self.aabb_diagonal()
    }

    /// The diagonal of the AABB part: the k-DOP lies inside that box, so any of its points is
    /// within the box diagonal of any point of the (non-empty) geometry it bounds.
    #[inline]
    fn stand_off(&self) -> f64 {
        self.aabb_diagonal()
    }
}

#[cfg(test)]
mod tests;
