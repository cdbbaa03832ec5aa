//! Axis-aligned bounding box.
//!
//! Stored as `min`/`max` corners; the tests under a relative pose work in centre/half-extent
//! form. B's box, moved into A's frame, is enclosed in the AABB of A's frame with centre
//! `R c_b + t` and half-extents `|R| h_b` (Arvo 1990, "Transforming axis-aligned bounding
//! boxes", Graphics Gems), so overlap is three interval tests and the distance bound is the
//! length of the per-axis gaps. Both are conservative: the enclosing box contains B's box,
//! and a relative slack covers rounding.

use super::BoundingVolume;
use crate::geometry::Triangle;
use crate::math::{DMat3, DVec3, Isometry, conservative_slack, tolerance};

/// A box `{x : min <= x <= max}` (componentwise, local frame, metres).
///
/// # Invariants
/// `min <= max` componentwise, both finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    /// Lower corner, metres.
    pub min: DVec3,
    /// Upper corner, metres.
    pub max: DVec3,
}

impl Aabb {
    /// A box from trusted corners (`min <= max`).
    #[must_use]
    #[inline]
    pub fn new(min: DVec3, max: DVec3) -> Self {
        debug_assert!(min.cmple(max).all(), "inverted box {min} {max}");
        Self { min, max }
    }

    /// The box with the given centre and half-extents (`half_extents >= 0`).
    #[must_use]
    #[inline]
    pub fn from_center_half_extents(center: DVec3, half_extents: DVec3) -> Self {
        debug_assert!(half_extents.cmpge(DVec3::ZERO).all());
        Self {
            min: center - half_extents,
            max: center + half_extents,
        }
    }

    /// The box grown by `margin` metres (`≥ 0`) on every side.
    #[must_use]
    #[inline]
    pub fn grown(&self, margin: f64) -> Self {
        debug_assert!(margin >= 0.0);
        Self {
            min: self.min - DVec3::splat(margin),
            max: self.max + DVec3::splat(margin),
        }
    }

    /// The box's centre, `(min + max) / 2`.
    #[must_use]
    #[inline]
    pub fn center(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// Half the side lengths, `(max - min) / 2`.
    #[must_use]
    #[inline]
    pub fn half_extents(&self) -> DVec3 {
        (self.max - self.min) * 0.5
    }

    /// The side lengths, `max - min`.
    #[must_use]
    #[inline]
    pub fn extents(&self) -> DVec3 {
        self.max - self.min
    }

    /// The box grown by `margin >= 0` on every side (metres).
    #[must_use]
    #[inline]
    pub fn loosened(&self, margin: f64) -> Self {
        debug_assert!(margin >= 0.0);
        Self {
            min: self.min - DVec3::splat(margin),
            max: self.max + DVec3::splat(margin),
        }
    }

    /// The smallest box containing `self` and `point` (no padding).
    #[must_use]
    #[inline]
    pub fn union_point(&self, point: DVec3) -> Self {
        Self {
            min: self.min.min(point),
            max: self.max.max(point),
        }
    }

    /// The eight corners; corner `i` takes `max` on axis `k` when bit `k` of `i` is set.
    #[must_use]
    pub fn corners(&self) -> [DVec3; 8] {
        std::array::from_fn(|i| {
            DVec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            )
        })
    }

    /// The enclosing box of `points`, padded by the slack of their largest coordinate.
    fn fit_iter(points: impl Iterator<Item = DVec3>) -> Self {
        let mut min = DVec3::INFINITY;
        let mut max = DVec3::NEG_INFINITY;
        for p in points {
            min = min.min(p);
            max = max.max(p);
        }
        debug_assert!(
            min.is_finite() && max.is_finite(),
            "fit of an empty or non-finite set"
        );
        let pad = conservative_slack(min.abs().max(max.abs()).max_element());
        Self {
            min: min - DVec3::splat(pad),
            max: max + DVec3::splat(pad),
        }
    }

    /// Per axis of A: the signed gap between A and the AABB (A's axes) enclosing `other`
    /// (frame B), negative when the intervals overlap; and the magnitude of the quantities
    /// involved, whose `BV_RELATIVE` multiple covers the rounding of the whole comparison.
    #[inline]
    fn enclose_in_a(&self, other: &Self, pose_ab: &Isometry) -> (DVec3, DVec3) {
        let (ca, ha) = (self.center(), self.half_extents());
        let (cb, hb) = (other.center(), other.half_extents());
        let r = &pose_ab.rotation;
        let abs_r = DMat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
        let cb_in_a = pose_ab.transform_point(cb);
        let hb_in_a = abs_r * hb;
        let gap = (ca - cb_in_a).abs() - (ha + hb_in_a);
        // Rounding is a few ulps of the largest magnitude in play on each axis;
        // |R c_b| <= |c_b|_1 on every axis.
        let magnitude = ca.abs()
            + ha
            + hb_in_a
            + pose_ab.translation.abs()
            + DVec3::splat(cb.abs().element_sum());
        (gap, magnitude)
    }
}

impl BoundingVolume for Aabb {
    const NAME: &'static str = "aabb";

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
        Self {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The enclosing AABB (parent axes) of the moved box, padded by the rounding slack.
    #[inline]
    fn transformed(&self, pose: &Isometry) -> Self {
        let r = &pose.rotation;
        let abs_r = DMat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
        let center = pose.transform_point(self.center());
        let half = abs_r * self.half_extents();
        let magnitude = (center.abs() + half + pose.translation.abs()).max_element()
            + self.min.abs().max(self.max.abs()).max_element();
        Self::from_center_half_extents(center, half + DVec3::splat(conservative_slack(magnitude)))
    }

    /// Whether two boxes of the same frame share a point (closed intervals, no slack).
    #[inline]
    fn intersects(&self, other: &Self) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// A against the AABB (A's axes) enclosing B: three interval tests with slack.
    // PERF: benches/bounding.rs `overlap/aabb`; no branch before the final compare.
    #[inline]
    fn overlaps(&self, other: &Self, pose_ab: &Isometry) -> bool {
        let (gap, magnitude) = self.enclose_in_a(other, pose_ab);
        gap.cmple(magnitude * tolerance::BV_RELATIVE).all()
    }

    /// Length of the per-axis gaps between A and the AABB (A's axes) enclosing B, reduced
    /// by the rounding slack. The enclosing box contains B, so this never exceeds the
    /// distance between A and B.
    #[inline]
    fn distance_lower_bound(&self, other: &Self, pose_ab: &Isometry) -> f64 {
        let (gap, magnitude) = self.enclose_in_a(other, pose_ab);
        (gap - magnitude * tolerance::BV_RELATIVE)
            .max(DVec3::ZERO)
            .length()
    }

    #[inline]
    fn contains_point(&self, point: DVec3) -> bool {
        self.min.cmple(point).all() && point.cmple(self.max).all()
    }

    #[inline]
    fn center(&self) -> DVec3 {
        Aabb::center(self)
    }

    #[inline]
    fn volume(&self) -> f64 {
        self.extents().max(DVec3::ZERO).element_product()
    }

    /// The diagonal length.
    #[inline]
    fn size(&self) -> f64 {
        self.extents().length()
    }

    /// The diagonal length: any point of the box is within the diagonal of any other point
    /// of the box, in particular of any point of the (non-empty) geometry it contains.
    #[inline]
    fn stand_off(&self) -> f64 {
        self.extents().length()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{self as support, CloudKind};
    use rand::Rng;

    /// Random point in the box (corners and faces included now and then).
    fn point_in(rng: &mut support::TestRng, b: &Aabb) -> DVec3 {
        let t = DVec3::new(
            rng.random_range(-0.2..1.2_f64).clamp(0.0, 1.0),
            rng.random_range(-0.2..1.2_f64).clamp(0.0, 1.0),
            rng.random_range(-0.2..1.2_f64).clamp(0.0, 1.0),
        );
        // Clamped: at mixed magnitudes `min + (max - min) * t` can round past `max`.
        (b.min + (b.max - b.min) * t).clamp(b.min, b.max)
    }

    #[test]
    fn fitted_boxes_contain_every_point_and_triangle_vertex() {
        let mut rng = support::rng(11);
        for case in 0..3000 {
            let (points, _) = support::random_cloud(&mut rng, 50);
            let b = Aabb::fit_points(&points);
            assert!(points.iter().all(|p| b.contains_point(*p)), "case {case}");
            let tris: Vec<Triangle> = points
                .windows(3)
                .map(|w| Triangle::new(w[0], w[1], w[2]))
                .collect();
            if !tris.is_empty() {
                let t = Aabb::fit_triangles(&tris);
                assert!(
                    tris.iter()
                        .flat_map(Triangle::vertices)
                        .all(|p| t.contains_point(p))
                );
            }
        }
    }

    #[test]
    fn fit_is_tight_up_to_the_padding() {
        let points = [DVec3::new(1.0, -2.0, 3.0), DVec3::new(-1.0, 5.0, 0.0)];
        let b = Aabb::fit_points(&points);
        assert!(b.min.abs_diff_eq(DVec3::new(-1.0, -2.0, 0.0), 1e-10));
        assert!(b.max.abs_diff_eq(DVec3::new(1.0, 5.0, 3.0), 1e-10));
        assert!((b.volume() - 42.0).abs() < 1e-8);
        assert!((b.size() - (4.0_f64 + 49.0 + 9.0).sqrt()).abs() < 1e-9);
        let single = Aabb::fit_points(&[DVec3::splat(1e6)]);
        assert!(single.contains_point(DVec3::splat(1e6)) && single.size() < 1e-5);
    }

    #[test]
    fn merged_contains_both() {
        let mut rng = support::rng(12);
        for case in 0..2000 {
            let (p, _) = support::random_cloud(&mut rng, 10);
            let (q, _) = support::random_cloud(&mut rng, 10);
            let (a, b) = (Aabb::fit_points(&p), Aabb::fit_points(&q));
            let m = a.merged(&b);
            let mut grown = a;
            grown.merge(&b);
            assert_eq!(m, grown);
            for s in [a, b] {
                for _ in 0..8 {
                    assert!(m.contains_point(point_in(&mut rng, &s)), "case {case}");
                }
            }
        }
    }

    #[test]
    fn transformed_contains_the_moved_points_and_the_moved_box() {
        let mut rng = support::rng(13);
        for case in 0..3000 {
            let (points, scale) = support::random_cloud(&mut rng, 30);
            let pose = support::isometry(&mut rng, 100.0 * scale);
            let b = Aabb::fit_points(&points);
            let moved = b.transformed(&pose);
            for p in &points {
                assert!(
                    moved.contains_point(pose.transform_point(*p)),
                    "case {case}"
                );
            }
            for _ in 0..8 {
                let p = point_in(&mut rng, &b);
                assert!(moved.contains_point(pose.transform_point(p)), "case {case}");
            }
        }
    }

    #[test]
    fn overlap_and_distance_bound_are_conservative_against_brute_force() {
        let mut rng = support::rng(14);
        let (mut overlapping, mut apart) = (0, 0);
        for case in 0..4000 {
            let (a_points, scale) = support::random_cloud(&mut rng, 20);
            let (mut b_points, _) = support::random_cloud(&mut rng, 20);
            let pose_ab = support::isometry(&mut rng, 2.0 * scale);
            let shared = case % 3 == 0;
            if shared {
                b_points.push(pose_ab.inverse_transform_point(a_points[0]));
            }
            let a = Aabb::fit_points(&a_points);
            let b = Aabb::fit_points(&b_points);
            let b_in_a: Vec<DVec3> = b_points
                .iter()
                .map(|p| pose_ab.transform_point(*p))
                .collect();
            let truth = support::min_distance(&a_points, &b_in_a);
            let bound = a.distance_lower_bound(&b, &pose_ab);
            let overlap = a.overlaps(&b, &pose_ab);
            assert!(bound <= truth, "case {case}: bound {bound} > truth {truth}");
            assert!(
                !shared || (overlap && bound == 0.0),
                "case {case}: shared point missed"
            );
            // A sampled point inside both boxes forces an overlap.
            for _ in 0..4 {
                let x = point_in(&mut rng, &a);
                if b.contains_point(pose_ab.inverse_transform_point(x)) {
                    assert!(overlap, "case {case}: common point {x} missed");
                }
            }
            if overlap {
                overlapping += 1;
                assert_eq!(bound, 0.0, "case {case}");
            } else {
                apart += 1;
                assert!(bound > 0.0, "case {case}");
            }
        }
        assert!(overlapping > 400 && apart > 400, "{overlapping} / {apart}");
    }

    #[test]
    fn touching_boxes_overlap_at_every_offset_and_scale() {
        let mut rng = support::rng(15);
        for &offset in &support::CENTERS {
            for &scale in &support::SCALES {
                for case in 0..200 {
                    let h = DVec3::splat(scale);
                    let a = Aabb::from_center_half_extents(DVec3::splat(offset), h);
                    // B's box touches A's +x face exactly, under a pure translation; every
                    // other case puts B's box far from B's origin too, so its centre in A's
                    // frame comes out of a cancellation of two large numbers.
                    let b_center = if case % 2 == 0 {
                        DVec3::ZERO
                    } else {
                        DVec3::splat(-offset)
                    };
                    let b = Aabb::from_center_half_extents(b_center, h);
                    let lateral =
                        support::point_in_cube(&mut rng, scale) * DVec3::new(0.0, 1.0, 1.0);
                    let pose = Isometry::from_translation(
                        DVec3::splat(offset) - b_center + DVec3::X * (2.0 * scale) + lateral,
                    );
                    assert!(a.overlaps(&b, &pose), "offset {offset} scale {scale}");
                    assert_eq!(a.distance_lower_bound(&b, &pose), 0.0);
                    // Apart by more than the slack (1e-12 of the coordinates, 1e-6 at 1e6).
                    let gap = 0.01 * scale + 1e-10 * offset;
                    let apart = Isometry::from_translation(pose.translation + DVec3::X * gap);
                    assert!(!a.overlaps(&b, &apart), "offset {offset} scale {scale}");
                    let d = a.distance_lower_bound(&b, &apart);
                    assert!(d <= gap && d > 0.8 * gap, "{d} vs {gap}");
                }
            }
        }
    }

    #[test]
    fn transform_then_overlap_agrees_with_overlap_under_the_pose() {
        let mut rng = support::rng(16);
        let mut agree = 0;
        for case in 0..3000 {
            let a = Aabb::from_center_half_extents(
                support::point_in_cube(&mut rng, 1.5),
                support::point_in_cube(&mut rng, 1.0).abs(),
            );
            let b = Aabb::from_center_half_extents(
                support::point_in_cube(&mut rng, 1.5),
                support::point_in_cube(&mut rng, 1.0).abs(),
            );
            let pose = support::isometry(&mut rng, 1.5);
            let moved = b.transformed(&pose);
            let direct = a.overlaps(&b, &pose);
            let via_moved = a.overlaps(&moved, &Isometry::IDENTITY);
            let (d1, d2) = (
                a.distance_lower_bound(&b, &pose),
                a.distance_lower_bound(&moved, &Isometry::IDENTITY),
            );
            assert!((d1 - d2).abs() < 1e-9, "case {case}: {d1} vs {d2}");
            // They may differ only when the boxes just touch (within rounding).
            assert!(direct == via_moved || d1.max(d2) < 1e-9, "case {case}");
            agree += usize::from(direct);
        }
        assert!(agree > 300 && agree < 2700, "{agree}");
    }

    #[test]
    fn helpers_round_trip() {
        let b =
            Aabb::from_center_half_extents(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.5, 1.0, 2.0));
        assert_eq!(b.center(), DVec3::new(1.0, 2.0, 3.0));
        assert_eq!(b.half_extents(), DVec3::new(0.5, 1.0, 2.0));
        assert_eq!(b.volume(), 8.0);
        assert_eq!(b.stand_off(), b.size());
        let l = b.loosened(0.25);
        assert_eq!(l.half_extents(), DVec3::new(0.75, 1.25, 2.25));
        assert!(b.intersects(&l) && l.intersects(&b));
        let far = Aabb::new(DVec3::splat(10.0), DVec3::splat(11.0));
        assert!(!b.intersects(&far));
        let u = b.union_point(DVec3::splat(20.0));
        assert!(u.contains_point(DVec3::splat(20.0)) && u.contains_point(b.min));
        assert_eq!(Aabb::NAME, "aabb");
        let flat = Aabb::fit_points(&support::cloud(
            &mut support::rng(0),
            CloudKind::Single,
            1,
            DVec3::ZERO,
            1.0,
        ));
        assert!(flat.volume() < 1e-30);
    }
}
