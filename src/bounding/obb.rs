//! Oriented bounding box: PCA fit (Gottschalk), 15-axis separating-axis overlap test.
//!
//! **Fit.** The axes are the principal axes of the area-weighted facets of the points'
//! convex hull (triangle fits use the triangles themselves); the extents are the min/max
//! projections on those axes, padded by the conservative slack. Where the covariance leaves
//! the orientation open (repeated eigenvalues: cubes, square plates, cylinders), candidate
//! frames from the minimum-area rectangle about the fixed axis (and, when all three
//! eigenvalues coincide, about the normals of the largest facets) are tried too, and the box
//! of least volume is kept.
//!
//! **Overlap.** The 15 separating axes (3 + 3 face normals, 9 edge cross products) in A's
//! box frame, with `|R| + SAT_PARALLEL` so that near-parallel edges never give a false
//! separating axis, and a slack scaled to the coordinates involved. The relative rotation
//! and translation are computed inside the call; every axis exits early.
//!
//! **Distance bound.** The largest gap over all 15 axes, each normalised: any axis gives a
//! lower bound. The 9 edge axes are kept because they pay: over 20,000 random separated
//! pairs they raised the bound by more than 1% in about half the cases (the 6 face axes
//! alone gave 92% of it on average), and a gap is normalised (one square root) only when
//! it beats the best so far, so they cost about the edge part of the overlap test. They
//! are skipped when the face axes already show a deep overlap ([`DEEP_FACE_OVERLAP`]).
//!
//! Citation: S. Gottschalk, M. C. Lin, D. Manocha, "OBBTree: A Hierarchical Structure for
//! Rapid Interference Detection", SIGGRAPH 1996; Gottschalk's thesis (2000) §4 for the
//! facet covariance.

use super::fit::{
    Moments, frame_about, point_moments, principal_axes, principal_frame, triangle_moments,
};
use super::{Aabb, BoundingVolume};
use crate::geometry::{ConvexPolyhedron, Triangle};
use crate::math::{DMat3, DVec3, Isometry, conservative_slack, tolerance};

/// An oriented box: `center + axes · x` for `|x_k| ≤ half_extents_k`.
///
/// # Invariants
/// `axes` is a rotation (orthonormal columns, determinant +1); `half_extents ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obb {
    /// Centre, metres.
    pub center: DVec3,
    /// The box axes as columns (a rotation matrix: box frame to the volume's frame).
    pub axes: DMat3,
    /// Half side lengths along each axis, metres.
    pub half_extents: DVec3,
}

/// Two adjacent eigenvalues closer than this fraction of the largest count as equal: the
/// orientation about the remaining axis is then settled by the minimum-area rectangle.
const AMBIGUOUS_EIGENVALUES: f64 = 0.05;

/// Facet normals tried when all three eigenvalues coincide.
const MAX_FACET_NORMALS: usize = 12;

impl Obb {
    /// From trusted parts.
    #[must_use]
    pub fn new(center: DVec3, axes: DMat3, half_extents: DVec3) -> Self {
        debug_assert!(
            (axes.transpose() * axes).abs_diff_eq(DMat3::IDENTITY, 1e-9),
            "axes not orthonormal: {axes}"
        );
        debug_assert!(half_extents.cmpge(DVec3::ZERO).all());
        Self {
            center,
            axes,
            half_extents,
        }
    }

    /// The axis-aligned box `aabb` as an OBB of the same frame (no padding).
    #[must_use]
    pub fn from_aabb(aabb: &Aabb) -> Self {
        Self::new(aabb.center(), DMat3::IDENTITY, aabb.half_extents())
    }

    /// The smallest box with the given `axes` containing `points` (non-empty), padded.
    #[must_use]
    pub fn enclosing(points: &[DVec3], axes: DMat3) -> Self {
        Self::enclosing_all(points.iter().copied(), axes)
    }

    /// [`enclosing`](Self::enclosing) over any re-iterable point sequence (non-empty),
    /// measured from its first point and padded for its coordinate scale.
    fn enclosing_all(points: impl Iterator<Item = DVec3> + Clone, axes: DMat3) -> Self {
        let reference = points.clone().next().expect("at least one point");
        let scale = points
            .clone()
            .fold(0.0f64, |s, p| s.max(p.abs().max_element()));
        Self::enclosing_padded(points, axes, reference, conservative_slack(scale))
    }

    /// The 16 corners of two boxes.
    fn corners_of(a: &Self, b: &Self) -> [DVec3; 16] {
        let (ca, cb) = (a.corners(), b.corners());
        std::array::from_fn(|k| if k < 8 { ca[k] } else { cb[k - 8] })
    }

    /// The eight corners.
    #[must_use]
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|k| {
            let sign = DVec3::new(
                if k & 1 == 0 { -1.0 } else { 1.0 },
                if k & 2 == 0 { -1.0 } else { 1.0 },
                if k & 4 == 0 { -1.0 } else { 1.0 },
            );
            self.center + self.axes * (sign * self.half_extents)
        })
    }

    /// Tight box in the frame `axes`, extents measured from `reference` (a point near the
    /// set, for precision), padded by `pad`.
    fn enclosing_padded(
        points: impl IntoIterator<Item = DVec3>,
        axes: DMat3,
        reference: DVec3,
        pad: f64,
    ) -> Self {
        let to_box = axes.transpose();
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in points {
            let q = to_box * (p - reference);
            lo = lo.min(q);
            hi = hi.max(q);
        }
        Self {
            center: reference + axes * ((lo + hi) * 0.5),
            axes,
            half_extents: (hi - lo) * 0.5 + DVec3::splat(pad),
        }
    }

    /// Volume, with tie-breakers for flat boxes: area, then length, so that among boxes of a
    /// planar or linear set the tightest one still wins.
    fn cost(&self) -> f64 {
        let e = self.half_extents;
        let diagonal = e.length();
        e.x * e.y * e.z
            + 1e-9 * diagonal * (e.x * e.y + e.y * e.z + e.z * e.x)
            + 1e-18 * diagonal * diagonal * e.element_sum()
    }

    /// Gottschalk's fit: PCA frame from `moments`, extents over `points`, with candidate
    /// frames from `facets` where the eigenvalues leave the orientation open.
    fn fit_with(points: &[DVec3], moments: &Moments, facets: &[Triangle]) -> Self {
        let scale = points
            .iter()
            .fold(0.0f64, |s, p| s.max(p.abs().max_element()));
        let pad = conservative_slack(scale);
        let reference = moments.mean;
        let (axes, values) = principal_frame(&moments.covariance);
        let mut best = Self::enclosing_padded(points.iter().copied(), axes, reference, pad);
        let mut consider = |normal: DVec3| {
            let frame = frame_about(normal, points, reference);
            let candidate = Self::enclosing_padded(points.iter().copied(), frame, reference, pad);
            if candidate.cost() < best.cost() {
                best = candidate;
            }
        };
        let tolerance = AMBIGUOUS_EIGENVALUES * values.x;
        let (close01, close12) = (
            values.x - values.y <= tolerance,
            values.y - values.z <= tolerance,
        );
        if close01 && close12 {
            for normal in facet_normals(facets) {
                consider(normal);
            }
            for k in 0..3 {
                consider(axes.col(k));
            }
        } else if close01 {
            consider(axes.z_axis);
        } else if close12 {
            consider(axes.x_axis);
        }
        best
    }

    /// `self` (frame B) placed in frame A by `pose_ab`, unpadded, with the magnitude its
    /// placing rounds at: the first half of [`SeparatingAxes::new`], done once
    /// when one box is tested against several ([`BoundingVolume::distance_lower_bounds_within`]).
    #[inline]
    fn placed(&self, pose_ab: &Isometry) -> PlacedObb {
        PlacedObb {
            center: pose_ab.rotation * self.center + pose_ab.translation,
            axes: pose_ab.rotation * self.axes,
            half_extents: self.half_extents,
            scale: self.center.abs().max_element()
                + pose_ab.translation.abs().max_element()
                + self.half_extents.element_sum(),
        }
    }

    /// The distance bound of [`BoundingVolume::distance_lower_bound_within`] against a box
    /// already placed in `self`'s frame.
    fn distance_lower_bound_to(&self, other: &PlacedObb, limit: f64) -> f64 {
        let axes = SeparatingAxes::new(self, other);
        // The largest face-axis gap, negative while the boxes overlap along all six.
        let faces = (0..3)
            .map(|i| axes.face_of_a(i))
            .chain((0..3).map(|j| axes.face_of_b(j)))
            .fold(f64::NEG_INFINITY, |most, (extent, reach)| {
                most.max(extent - reach - axes.slack)
            });
        let mut best = faces.max(0.0);
        let smaller = self
            .half_extents
            .max_element()
            .min(other.half_extents.max_element());
        if best >= limit || -faces >= DEEP_FACE_OVERLAP * smaller {
            return best;
        }
        for i in 0..3 {
            for j in 0..3 {
                let (extent, reach) = axes.edge(i, j);
                let gap = extent - reach - axes.slack;
                let length_squared = axes.edge_length_squared(i, j);
                if gap > 0.0
                    && length_squared > MIN_EDGE_AXIS_SQUARED
                    && gap * gap > best * best * length_squared
                {
                    best = gap / length_squared.sqrt();
                }
            }
        }
        best
    }
}

/// The 15 separating axes of two boxes (Gottschalk), B placed in A's frame: along each,
/// the extent of the centres' offset and the two boxes' summed reach, unnormalised. The
/// boxes are apart along an axis when the extent exceeds the reach plus `slack`.
struct SeparatingAxes {
    /// `R = Aᵀ·R_ab·B`, by rows.
    r: [[f64; 3]; 3],
    /// `|R|` plus [`tolerance::SAT_PARALLEL`], so near-parallel edges never separate falsely.
    abs: [[f64; 3]; 3],
    /// B's centre in A's box frame.
    t: [f64; 3],
    /// Half extents of A, of B.
    a: [f64; 3],
    b: [f64; 3],
    /// Covers the rounding at the magnitudes involved.
    slack: f64,
}

impl SeparatingAxes {
    #[inline]
    fn new(box_a: &Obb, placed_b: &PlacedObb) -> Self {
        let to_a = box_a.axes.transpose();
        let c = (to_a * placed_b.axes).to_cols_array_2d();
        let r = [
            [c[0][0], c[1][0], c[2][0]],
            [c[0][1], c[1][1], c[2][1]],
            [c[0][2], c[1][2], c[2][2]],
        ];
        let scale =
            box_a.center.abs().max_element() + box_a.half_extents.element_sum() + placed_b.scale;
        Self {
            r,
            abs: r.map(|row| row.map(|x| x.abs() + tolerance::SAT_PARALLEL)),
            t: (to_a * (placed_b.center - box_a.center)).to_array(),
            a: box_a.half_extents.to_array(),
            b: placed_b.half_extents.to_array(),
            slack: conservative_slack(scale),
        }
    }

    /// A's face axis `i`: (extent, reach).
    #[inline]
    fn face_of_a(&self, i: usize) -> (f64, f64) {
        let (abs, b) = (&self.abs, &self.b);
        let rb = b[0] * abs[i][0] + b[1] * abs[i][1] + b[2] * abs[i][2];
        (self.t[i].abs(), self.a[i] + rb)
    }

    /// B's face axis `j`: (extent, reach).
    #[inline]
    fn face_of_b(&self, j: usize) -> (f64, f64) {
        let (r, abs, t, a) = (&self.r, &self.abs, &self.t, &self.a);
        let tj = t[0] * r[0][j] + t[1] * r[1][j] + t[2] * r[2][j];
        let ra = a[0] * abs[0][j] + a[1] * abs[1][j] + a[2] * abs[2][j];
        (tj.abs(), ra + self.b[j])
    }

    /// The edge axis `A_i × B_j`: (extent, reach), both scaled by the axis's length.
    #[inline]
    fn edge(&self, i: usize, j: usize) -> (f64, f64) {
        let (r, abs, t, a, b) = (&self.r, &self.abs, &self.t, &self.a, &self.b);
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        let extent = (t[i2] * r[i1][j] - t[i1] * r[i2][j]).abs();
        let ra = a[i1] * abs[i2][j] + a[i2] * abs[i1][j];
        let rb = b[j1] * abs[i][j2] + b[j2] * abs[i][j1];
        (extent, ra + rb)
    }

    /// `|A_i × B_j|²`, computed from the two entries of `R` it is made of.
    #[inline]
    fn edge_length_squared(&self, i: usize, j: usize) -> f64 {
        let (r, i1, i2) = (&self.r, (i + 1) % 3, (i + 2) % 3);
        r[i1][j] * r[i1][j] + r[i2][j] * r[i2][j]
    }

    /// Whether some axis separates the boxes (each test exits early).
    #[inline]
    fn any_separates(&self) -> bool {
        let apart = |(extent, reach): (f64, f64)| extent > reach + self.slack;
        (0..3).any(|i| apart(self.face_of_a(i)))
            || (0..3).any(|j| apart(self.face_of_b(j)))
            || (0..9).any(|k| apart(self.edge(k / 3, k % 3)))
    }
}

/// A box of frame B placed in frame A ([`Obb::placed`]): its centre and axes moved, not
/// padded; `scale` is the magnitude the move rounds at (B's centre, the translation and
/// the half extents), which the tests' slack covers.
#[derive(Debug, Clone, Copy)]
struct PlacedObb {
    center: DVec3,
    axes: DMat3,
    half_extents: DVec3,
    scale: f64,
}

/// Distinct normals of the largest facets, at most [`MAX_FACET_NORMALS`].
fn facet_normals(facets: &[Triangle]) -> Vec<DVec3> {
    let mut order: Vec<(f64, DVec3)> = facets
        .iter()
        .filter_map(|t| {
            let n = t.scaled_normal();
            n.try_normalize().map(|unit| (n.length(), unit))
        })
        .collect();
    order.sort_by(|a, b| b.0.total_cmp(&a.0));
    let mut normals: Vec<DVec3> = Vec::new();
    for (_, n) in order {
        if normals.len() == MAX_FACET_NORMALS {
            break;
        }
        if normals.iter().all(|m| m.dot(n).abs() < 1.0 - 1e-9) {
            normals.push(n);
        }
    }
    normals
}

impl BoundingVolume for Obb {
    const NAME: &'static str = "obb";

    /// Gottschalk's fit over the area-weighted facets of the points' convex hull.
    fn fit_points(points: &[DVec3]) -> Self {
        debug_assert!(!points.is_empty());
        // Hull facets; a flat hull's two-sided triangles still give the planar covariance.
        // Dimension 0 or 1 (or a rejected cloud) falls back to the point covariance.
        let facets: Vec<Triangle> = match ConvexPolyhedron::try_from_points(points) {
            Ok(hull) if hull.dimension() >= 2 => {
                let v = hull.vertices();
                hull.triangles()
                    .iter()
                    .map(|t| Triangle::new(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]))
                    .collect()
            }
            _ => Vec::new(),
        };
        let moments = triangle_moments(&facets).unwrap_or_else(|| point_moments(points));
        // Extents over the input itself: every point must be contained, hull or not.
        Self::fit_with(points, &moments, &facets)
    }

    fn fit_triangles(triangles: &[Triangle]) -> Self {
        debug_assert!(!triangles.is_empty());
        let vertices: Vec<DVec3> = triangles.iter().flat_map(|t| t.vertices()).collect();
        let moments = triangle_moments(triangles).unwrap_or_else(|| point_moments(&vertices));
        Self::fit_with(&vertices, &moments, triangles)
    }

    fn fit_triangles_in_frame(&self, triangles: &[Triangle]) -> Self {
        Self::enclosing_all(triangles.iter().flat_map(Triangle::vertices), self.axes)
    }

    fn merged_in_frame(&self, a: &Self, b: &Self) -> Self {
        Self::enclosing_all(Self::corners_of(a, b).into_iter(), self.axes)
    }

    /// The least-volume box, over the frames of both inputs and the PCA frame of their 16
    /// corners, that encloses all 16 corners (hence both boxes).
    fn merged(&self, other: &Self) -> Self {
        let corners = Self::corners_of(self, other);
        let scale = corners
            .iter()
            .fold(0.0f64, |s, p| s.max(p.abs().max_element()));
        let pad = conservative_slack(scale);
        let pca = principal_axes(&point_moments(&corners).covariance);
        [self.axes, other.axes, pca]
            .into_iter()
            .map(|axes| Self::enclosing_padded(corners, axes, self.center, pad))
            .min_by(|a, b| a.cost().total_cmp(&b.cost()))
            .unwrap_or(*self)
    }

    #[inline]
    fn transformed(&self, pose: &Isometry) -> Self {
        let pad = super::transform_slack(self.center, pose, self.size());
        Self {
            center: pose.transform_point(self.center),
            axes: pose.rotation * self.axes,
            half_extents: self.half_extents + DVec3::splat(pad),
        }
    }

    #[inline]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool {
        !SeparatingAxes::new(self, &other.placed(pose_ab)).any_separates()
    }

    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64 {
        self.distance_lower_bound_within(other, pose_ab, f64::INFINITY)
    }

    /// The face axes first; their gap is returned as soon as it reaches `limit` (the nine
    /// edge axes, each needing a square root, are then skipped).
    fn distance_lower_bound_within(&self, other: &Self, pose_ab: &Isometry, limit: f64) -> f64 {
        self.distance_lower_bound_to(&other.placed(pose_ab), limit)
    }

    /// `other` is placed in frame A once, for both: half of the work of a bound.
    #[inline]
    fn distance_lower_bounds_within(
        pair: [&Self; 2],
        other: &Self,
        pose_ab: &Isometry,
        limit: f64,
    ) -> [f64; 2] {
        let placed = other.placed(pose_ab);
        pair.map(|x| x.distance_lower_bound_to(&placed, limit))
    }

    #[inline]
    fn contains_point(&self, point: DVec3) -> bool {
        let local = self.axes.transpose() * (point - self.center);
        local.abs().cmple(self.half_extents).all()
    }

    #[inline]
    fn center(&self) -> DVec3 {
        self.center
    }

    #[inline]
    fn volume(&self) -> f64 {
        8.0 * self.half_extents.element_product()
    }

    #[inline]
    fn size(&self) -> f64 {
        2.0 * self.half_extents.length()
    }

    #[inline]
    fn stand_off(&self) -> f64 {
        2.0 * self.half_extents.length()
    }
}

/// Overlap along every face axis, as a fraction of the smaller box's largest half extent,
/// beyond which the distance bound does not try the edge axes (the bound stays a bound,
/// only looser where an edge axis would have separated such boxes).
///
/// Measured on `benches/frontier.rs`'s scene (128 frames at 250 visits): of the bounds
/// whose face axes all overlap, the edge axes separated 476 pairs; the overlap was at
/// least half the extent for 4 of them and for 8,024 of the 17,318 that stayed
/// overlapping (at a fifth: 88 and 12,900). Cost per visit 89.8 → 87.0 ns (medians of
/// five alternating runs), the same precision at every counted budget on robot-chain, and
/// 0.7 % more visits for the exact answers.
const DEEP_FACE_OVERLAP: f64 = 0.5;

/// Edge axes shorter than this (squared; edges parallel to within 1e-6 rad) are skipped by
/// the distance bound: a face axis bounds that direction as well, and dividing by the
/// length would magnify rounding.
const MIN_EDGE_AXIS_SQUARED: f64 = 1e-12;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DQuat;
    use crate::test_support::*;
    use rand::Rng;

    /// Eight corners of the box `center + rot · (±half)`.
    fn box_corners(center: DVec3, rot: DQuat, half: DVec3) -> Vec<DVec3> {
        (0..8)
            .map(|k| {
                let s = DVec3::new(
                    if k & 1 == 0 { -1.0 } else { 1.0 },
                    if k & 2 == 0 { -1.0 } else { 1.0 },
                    if k & 4 == 0 { -1.0 } else { 1.0 },
                );
                center + rot * (s * half)
            })
            .collect()
    }

    /// The 12 triangles of a box's surface.
    fn box_mesh(center: DVec3, rot: DQuat, half: DVec3) -> Vec<Triangle> {
        let c = box_corners(center, rot, half);
        // Faces as corner-index quads (bit 0 = x, bit 1 = y, bit 2 = z).
        let quads = [
            [0, 2, 6, 4],
            [1, 5, 7, 3],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 1, 3, 2],
            [4, 6, 7, 5],
        ];
        quads
            .iter()
            .flat_map(|q| {
                [
                    Triangle::new(c[q[0]], c[q[1]], c[q[2]]),
                    Triangle::new(c[q[0]], c[q[2]], c[q[3]]),
                ]
            })
            .collect()
    }

    /// Proportions of the recovery test: random, cubes, flat and needle-like boxes.
    fn box_half(rng: &mut TestRng, case: usize, scale: f64) -> DVec3 {
        let mut h = DVec3::new(
            rng.random_range(0.05..1.0),
            rng.random_range(0.05..1.0),
            rng.random_range(0.05..1.0),
        );
        match case % 5 {
            0 => h = DVec3::splat(h.x),
            1 => h.z = h.x * 1e-3,
            2 => h.y = h.x,
            _ => {}
        }
        h * scale
    }

    /// The true box's volume once padded by the fit's slack (1e-6 at 1e6 from the origin is
    /// 1% of a 1e-4 box: the padding, not the orientation, is then what costs volume).
    fn padded_volume(center: DVec3, half: DVec3) -> f64 {
        let pad = conservative_slack(center.abs().max_element() + half.length());
        8.0 * (half + DVec3::splat(pad)).element_product()
    }

    fn surface_samples(
        rng: &mut TestRng,
        center: DVec3,
        rot: DQuat,
        half: DVec3,
        n: usize,
    ) -> Vec<DVec3> {
        (0..n)
            .map(|_| {
                let mut p = point_in_cube(rng, 1.0);
                let k = rng.random_range(0..3);
                p[k] = if rng.random::<bool>() { 1.0 } else { -1.0 };
                center + rot * (p * half)
            })
            .collect()
    }

    #[test]
    fn triangle_fits_of_a_rotated_box_recover_the_box() {
        let mut rng = rng(21);
        for case in 0..3000 {
            let center = DVec3::splat(CENTERS[case % 4]) + point_in_cube(&mut rng, 1.0);
            let scale = SCALES[case % 5];
            let rot = rotation(&mut rng);
            let half = box_half(&mut rng, case / 5, scale);
            let obb = Obb::fit_triangles(&box_mesh(center, rot, half));
            let truth = padded_volume(center, half);
            assert!(
                obb.volume() <= truth * 1.01 && obb.volume() >= truth * 0.99,
                "case {case}: {} vs {truth}, half {half}",
                obb.volume()
            );
        }
    }

    #[test]
    fn point_fits_of_a_rotated_box_recover_the_box() {
        let mut rng = rng(22);
        for case in 0..3000 {
            let center = DVec3::splat(CENTERS[case % 4]) + point_in_cube(&mut rng, 1.0);
            let scale = SCALES[case % 5];
            let rot = rotation(&mut rng);
            let half = box_half(&mut rng, case / 5, scale);
            let mut points = box_corners(center, rot, half);
            points.extend(surface_samples(&mut rng, center, rot, half, 40));
            let obb = Obb::fit_points(&points);
            let truth = padded_volume(center, half);
            assert!(
                obb.volume() <= truth * 1.01,
                "case {case}: {} vs {truth}, half {half}",
                obb.volume()
            );
            assert!(points.iter().all(|&p| obb.contains_point(p)), "case {case}");
        }
    }

    #[test]
    fn fits_contain_every_point_and_vertex() {
        let mut rng = rng(23);
        for case in 0..4000 {
            let center = DVec3::splat(CENTERS[case % 4]);
            let scale = SCALES[(case / 4) % 5];
            let kind = CloudKind::ALL[(case / 20) % CloudKind::ALL.len()];
            let points = cloud(&mut rng, kind, 1 + case % 37, center, scale);
            let obb = Obb::fit_points(&points);
            assert!(
                obb.half_extents.is_finite() && obb.axes.is_finite(),
                "case {case}"
            );
            for p in &points {
                assert!(obb.contains_point(*p), "case {case}: {p} outside {obb:?}");
            }
            let tris: Vec<Triangle> = points
                .chunks(3)
                .map(|c| Triangle::new(c[0], c[c.len() / 2], c[c.len() - 1]))
                .collect();
            let obb = Obb::fit_triangles(&tris);
            for t in &tris {
                for v in t.vertices() {
                    assert!(obb.contains_point(v), "case {case}: {v} outside {obb:?}");
                }
            }
        }
    }

    /// A random box of size about `scale` near `center`.
    fn random_obb(rng: &mut TestRng, center: f64, scale: f64) -> Obb {
        let c = DVec3::splat(center) + point_in_cube(rng, scale);
        let half = DVec3::new(
            rng.random_range(0.01..1.0),
            rng.random_range(0.01..1.0),
            rng.random_range(0.01..1.0),
        ) * scale;
        Obb::new(c, DMat3::from_quat(rotation(rng)), half)
    }

    fn inside(rng: &mut TestRng, b: &Obb) -> DVec3 {
        // Corners, surface points and interior points.
        let mut u = point_in_cube(rng, 1.0);
        if rng.random::<bool>() {
            let k = rng.random_range(0..3);
            u[k] = u[k].signum();
        }
        b.center + b.axes * (u * b.half_extents)
    }

    #[test]
    fn merged_boxes_contain_both_inputs() {
        let mut rng = rng(24);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let a = random_obb(&mut rng, center, scale);
            let factor = rng.random_range(0.1..3.0);
            let b = random_obb(&mut rng, center, scale * factor);
            let m = a.merged(&b);
            for p in a.corners().into_iter().chain(b.corners()) {
                assert!(m.contains_point(p), "case {case}");
            }
            for _ in 0..20 {
                let which = if rng.random::<bool>() { &a } else { &b };
                let p = inside(&mut rng, which);
                assert!(m.contains_point(p), "case {case}");
            }
            // Never worse than the boxes in either input's frame (both are candidates).
            for axes in [a.axes, b.axes] {
                let framed = Obb::enclosing(&[a.corners(), b.corners()].concat(), axes);
                assert!(m.volume() <= framed.volume() * (1.0 + 1e-6), "case {case}");
            }
        }
    }

    #[test]
    fn transformed_boxes_move_their_points_and_keep_overlap() {
        let mut rng = rng(25);
        let mut mismatches = 0;
        for case in 0..3000 {
            let scale = SCALES[case % 5];
            let a = random_obb(&mut rng, 0.0, scale);
            let b = random_obb(&mut rng, 0.0, scale);
            let pose = isometry(&mut rng, scale);
            let moved = b.transformed(&pose);
            for _ in 0..10 {
                let p = inside(&mut rng, &b) * (1.0 - 1e-9) + b.center * 1e-9;
                assert!(moved.contains_point(pose.transform_point(p)), "case {case}");
            }
            if a.overlaps(&b, &pose) != a.overlaps(&moved, &Isometry::IDENTITY) {
                mismatches += 1;
            }
            let (d1, d2) = (
                a.distance_lower_bound(&b, &pose),
                a.distance_lower_bound(&moved, &Isometry::IDENTITY),
            );
            assert!((d1 - d2).abs() <= 1e-9 * scale, "case {case}: {d1} vs {d2}");
        }
        assert_eq!(mismatches, 0);
    }

    /// The frontier bounds a split of B's node from B's side (`pose_ab` inverted): the same
    /// 15 separating axes, so the same bound to rounding, at every scale and offset.
    #[test]
    fn the_bound_is_the_same_seen_from_either_box() {
        let mut rng = rng(27);
        let mut positive = 0;
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let a = random_obb(&mut rng, center, scale);
            let b = random_obb(&mut rng, 0.0, scale);
            let mut pose = isometry(&mut rng, 2.0 * scale);
            pose.translation += DVec3::splat(center);
            let (forward, reverse) = (
                a.distance_lower_bound(&b, &pose),
                b.distance_lower_bound(&a, &pose.inverse()),
            );
            let magnitude = center.abs() + scale;
            assert!(
                (forward - reverse).abs() <= 1e-9 * magnitude,
                "case {case}: {forward} from A, {reverse} from B"
            );
            positive += usize::from(forward > 0.0);
        }
        assert!((300..2700).contains(&positive), "{positive} of 3000 apart");
    }

    #[test]
    fn overlap_and_distance_are_conservative_against_sampled_points() {
        let mut rng = rng(26);
        let (mut overlapping, mut apart) = (0, 0);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let a = random_obb(&mut rng, center, scale);
            let b = random_obb(&mut rng, 0.0, scale);
            let mut pose = isometry(&mut rng, 1.5 * scale);
            pose.translation += DVec3::splat(center);
            let overlaps = a.overlaps(&b, &pose);
            let bound = a.distance_lower_bound(&b, &pose);
            assert!(bound >= 0.0);
            if overlaps {
                overlapping += 1;
            } else {
                apart += 1;
                assert!(bound > 0.0, "case {case}: apart but bound 0");
            }
            let pa: Vec<DVec3> = (0..300).map(|_| inside(&mut rng, &a)).collect();
            let pb: Vec<DVec3> = (0..300)
                .map(|_| pose.transform_point(inside(&mut rng, &b)))
                .collect();
            // Points of B inside A prove an overlap.
            if pb.iter().any(|p| a.contains_point(*p)) {
                assert!(overlaps, "case {case}: false negative");
                assert_eq!(bound, 0.0, "case {case}");
            }
            let sampled = pa
                .iter()
                .flat_map(|p| pb.iter().map(move |q| p.distance(*q)))
                .fold(f64::INFINITY, f64::min);
            assert!(bound <= sampled, "case {case}: {bound} > {sampled}");
        }
        assert!(overlapping > 300 && apart > 300, "{overlapping} / {apart}");
    }

    #[test]
    fn touching_boxes_overlap_and_have_zero_distance() {
        let mut rng = rng(27);
        for case in 0..3000 {
            let (center, scale) = (CENTERS[case % 4], SCALES[case % 5]);
            let a = random_obb(&mut rng, center, scale);
            let b = random_obb(&mut rng, 0.0, scale);
            // Put B's corner k exactly on A's face point.
            let target = inside(&mut rng, &a);
            let target = a.center
                + a.axes * {
                    let mut u = a.axes.transpose() * (target - a.center);
                    u.x = a.half_extents.x;
                    u
                };
            let rot = DMat3::from_quat(rotation(&mut rng));
            let corner = b.corners()[case % 8];
            let pose = Isometry::new(rot, target - rot * corner);
            assert!(a.overlaps(&b, &pose), "case {case}");
            assert_eq!(a.distance_lower_bound(&b, &pose), 0.0, "case {case}");
        }
    }

    #[test]
    fn separated_axis_aligned_boxes_have_the_exact_gap() {
        let a = Obb::new(DVec3::ZERO, DMat3::IDENTITY, DVec3::ONE);
        let b = Obb::new(DVec3::ZERO, DMat3::IDENTITY, DVec3::splat(0.5));
        let pose = Isometry::from_translation(DVec3::new(4.0, 0.2, -0.3));
        assert!(!a.overlaps(&b, &pose));
        // Exact up to the SAT_PARALLEL inflation of |R| (1e-9 of the extents).
        assert!((a.distance_lower_bound(&b, &pose) - 2.5).abs() < 1e-8);
        // Edge–edge: B rotated 45° about Z and X, placed along the diagonal.
        let rot = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_4);
        let pose = Isometry::new(rot, DVec3::new(3.0, 3.0, 0.0));
        let d = a.distance_lower_bound(&b, &pose);
        let exact = (DVec3::new(3.0, 3.0, 0.0) - DVec3::new(1.0, 1.0, 0.0)).length() - 0.5;
        assert!(d <= exact && d > 0.5 * exact, "{d} vs {exact}");
    }

    #[test]
    fn single_points_give_tiny_boxes_that_contain_them() {
        for center in CENTERS {
            let p = DVec3::new(center, -center, 0.5 * center);
            let obb = Obb::fit_points(&[p, p, p]);
            assert!(obb.contains_point(p));
            assert!(obb.size() <= 1e-9 * (1.0 + center));
            assert!(obb.volume() >= 0.0 && obb.stand_off() == obb.size());
        }
    }
}
