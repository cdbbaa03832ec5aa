//! Capsule–capsule: the distance between the core segments minus both radii.
//!
//! Closest points of two segments in the cross-product form (Ericson §5.1.9), directly
//! when the segments are apart (the common case: rounded shapes touch through their radii),
//! else through [`super::query`]; crossing segments take `d₁ × d₂` as normal, parallel or
//! zero-length ones a fixed axis crossed with the direction. Manifold: 2 points for parallel
//! overlapping cores ([`super::clip`]), else 1.

use super::placed_core::{AXIS_RELATIVE, PlacedCore};
use super::query::FEATURE_RELATIVE;
use super::{clip, query};
use crate::geometry::Capsule;
use crate::math::{DVec3, Isometry};
use crate::narrow::closest_points::closest_points_segment_segment;
use crate::narrow::contact::{DistanceBound, Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_capsule_capsule(a: &Capsule, b: &Capsule, pose_ab: &Isometry) -> ShapeDistance {
    Segments::new(a, b, pose_ab).distance(a, b, pose_ab)
}

/// Bounds on the signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's),
/// A's frame, as [`DistanceBound`] states: the exact answer, a rounding allowance either
/// side. For two capsules the closed form costs what a separating-axis test would (the
/// segments' closest points), so the bounds are exact and need no limit to stop at.
#[must_use]
pub fn distance_bound_capsule_capsule(
    a: &Capsule,
    b: &Capsule,
    pose_ab: &Isometry,
) -> DistanceBound {
    let segments = Segments::new(a, b, pose_ab);
    let d = segments.distance(a, b, pose_ab);
    // Rounding, plus what the shared engine's skip of near-parallel axes may change in a
    // depth when the segments meet.
    let slack = query::BOUND_ULPS * f64::EPSILON * segments.scale
        + AXIS_RELATIVE * 2.0 * (a.half_height + b.half_height);
    DistanceBound::exact(&d, slack)
}

/// The two core segments in A's frame, with their radii.
struct Segments {
    a: (DVec3, DVec3),
    b: (DVec3, DVec3),
    radii: (f64, f64),
    /// The largest end-point coordinate plus the larger radius, metres.
    scale: f64,
}

impl Segments {
    fn new(a: &Capsule, b: &Capsule, pose_ab: &Isometry) -> Self {
        let (sa, sb) = (a.segment(), b.segment());
        let (b0, b1) = (pose_ab.transform_point(sb.a), pose_ab.transform_point(sb.b));
        let scale = [sa.a, sa.b, b0, b1]
            .iter()
            .fold(a.radius.max(b.radius), |m, p| m.max(p.abs().max_element()));
        Self {
            a: (sa.a, sa.b),
            b: (b0, b1),
            radii: (a.radius, b.radius),
            scale,
        }
    }

    /// The exact signed distance: [`Self::apart`], else the shared engine's.
    fn distance(&self, a: &Capsule, b: &Capsule, pose_ab: &Isometry) -> ShapeDistance {
        self.apart().unwrap_or_else(|| {
            query::distance(
                &PlacedCore::capsule(a, &Isometry::IDENTITY),
                &PlacedCore::capsule(b, pose_ab),
            )
        })
    }

    /// The exact answer when the segments are apart by more than rounding: their closest
    /// points (Ericson §5.1.9), the normal along them, both radii taken off. `None` when
    /// they meet or nearly do (the shared engine then finds the depth and its normal).
    /// PERF: a tenth of the shared engine's cost, whose axis search over two segments must
    /// allow for a flat Minkowski difference.
    fn apart(&self) -> Option<ShapeDistance> {
        let (on_a, on_b) = closest_points_segment_segment(self.a.0, self.a.1, self.b.0, self.b.1);
        let gap = on_a.distance(on_b);
        (gap > FEATURE_RELATIVE * self.scale).then(|| {
            let normal = (on_b - on_a) / gap;
            ShapeDistance {
                distance: gap - self.radii.0 - self.radii.1,
                point_a: on_a + normal * self.radii.0,
                point_b: on_b - normal * self.radii.1,
                normal,
            }
        })
    }
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_capsule_capsule(a: &Capsule, b: &Capsule, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &PlacedCore::capsule(a, &Isometry::IDENTITY),
        &PlacedCore::capsule(b, pose_ab),
        out,
    );
}

/// [`manifold_capsule_capsule`] from the pair's signed distance `d` (this file's `distance_…`,
/// A's frame), which the dispatcher has already: the manifold is clipped along `d`'s
/// normal without the separating axes and closest points again. PERF: the settling pile's
/// touching pairs (`benches/pile.rs`) spent 7× their distance's time in the manifold.
pub fn manifold_capsule_capsule_from(
    a: &Capsule,
    b: &Capsule,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    clip::manifold_from_distance(
        &PlacedCore::capsule(a, &Isometry::IDENTITY),
        &PlacedCore::capsule(b, pose_ab),
        d,
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;

    #[test]
    fn crossing_cores_take_the_cross_product_normal() {
        let c = Capsule::new(1.0, 0.25);
        let pose = Isometry::new(
            DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2),
            DVec3::ZERO,
        );
        let d = distance_capsule_capsule(&c, &c, &pose);
        assert!((d.distance + 0.5).abs() < 1e-15, "{d:?}");
        assert!(d.normal.x.abs() > 1.0 - 1e-12);
        check::contract(&d, 1e-15);
        let mut m = Manifold::new();
        manifold_capsule_capsule(&c, &c, &pose, &mut m);
        check::manifold(&m, 1, 1e-15);
    }

    #[test]
    fn parallel_overlapping_capsules_give_two_points() {
        let c = Capsule::new(1.0, 0.25);
        let pose = Isometry::from_translation(DVec3::new(0.4, 0.0, 0.5));
        let d = distance_capsule_capsule(&c, &c, &pose);
        assert!((d.distance + 0.1).abs() < 1e-15 && d.normal.abs_diff_eq(DVec3::X, 1e-15));
        let mut m = Manifold::new();
        manifold_capsule_capsule(&c, &c, &pose, &mut m);
        check::manifold(&m, 2, 1e-14);
        let zs: Vec<f64> = m.points().iter().map(|p| p.point_a.z).collect();
        assert!((zs[0] - zs[1]).abs() > 1.4, "{m:?}");
    }

    #[test]
    fn collinear_and_zero_length_cores_never_give_nan() {
        let c = Capsule::new(1.0, 0.25);
        let dot = Capsule::new(0.0, 0.25);
        let pose = Isometry::from_translation(DVec3::new(0.0, 0.0, 0.5));
        for (a, b) in [(c, c), (c, dot), (dot, dot)] {
            let d = distance_capsule_capsule(&a, &b, &pose);
            check::contract(&d, 1e-15);
            assert!(
                (d.distance + 0.5).abs() < 1e-15 || a == dot && b == dot,
                "{d:?}"
            );
        }
    }
}
