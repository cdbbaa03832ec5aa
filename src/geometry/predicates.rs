//! Robust orientation predicates: the sign of a small determinant, always exact.
//!
//! These wrap Shewchuk's adaptive-precision predicates (the `robust` crate): a fast
//! floating-point evaluation with a forward error bound, refined in exact expansion
//! arithmetic only when the bound cannot certify the sign. The **sign** of every result is
//! exactly the sign of the real determinant of the (floating-point) inputs; the magnitude is
//! an approximation of that determinant. Inputs must be finite and must not overflow or
//! underflow when multiplied (coordinates below about `1e100` in magnitude).
//!
//! Citation: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and Fast Robust
//! Geometric Predicates", Discrete & Computational Geometry 18(3), 1997.

use crate::math::DVec3;
use glam::DVec2;
use robust::{Coord, Coord3D};

/// Orientation of `d` relative to the plane through `a, b, c`.
///
/// Returns a value with the exact sign of `((b - a) × (c - a)) · (d - a)`: positive when `d`
/// lies on the side the normal of the counter-clockwise triangle `a, b, c` points to
/// ("above"), negative below, and exactly `0.0` when the four points are coplanar (also when
/// `a, b, c` are collinear). The magnitude approximates six times the signed volume of the
/// tetrahedron `a b c d`, cubic metres.
#[must_use]
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    // NOTE: `robust::orient3d` is positive when `d` is *below*; we negate to follow the
    // right-hand normal of `a, b, c`, like `Triangle::scaled_normal`.
    -robust::orient3d(coord3(a), coord3(b), coord3(c), coord3(d))
}

/// Orientation of `c` relative to the directed line `a → b` in the plane.
///
/// Returns a value with the exact sign of `(b - a) × (c - a)` (the z component): positive
/// when `a, b, c` turn counter-clockwise (`c` left of `a → b`), negative when clockwise,
/// exactly `0.0` when collinear. The magnitude approximates twice the signed area.
#[must_use]
#[inline]
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    robust::orient2d(coord2(a), coord2(b), coord2(c))
}

/// [`orient2d`] of the projections of `a, b, c` onto the coordinate plane orthogonal to
/// axis `drop_axis` (0 = x, 1 = y, 2 = z).
///
/// The kept coordinates are taken in cyclic order — `(y, z)`, `(z, x)`, `(x, y)` — so the
/// sign is exactly the sign of component `drop_axis` of `(b - a) × (c - a)`.
///
/// # Panics
/// In debug builds, when `drop_axis > 2`.
#[must_use]
#[inline]
pub fn orient2d_projected(drop_axis: usize, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    debug_assert!(drop_axis < 3);
    orient2d(
        project(drop_axis, a),
        project(drop_axis, b),
        project(drop_axis, c),
    )
}

/// The projection of `p` used by [`orient2d_projected`]: the two coordinates other than
/// `drop_axis`, in cyclic order.
#[must_use]
#[inline]
pub fn project(drop_axis: usize, p: DVec3) -> DVec2 {
    match drop_axis {
        0 => DVec2::new(p.y, p.z),
        1 => DVec2::new(p.z, p.x),
        _ => DVec2::new(p.x, p.y),
    }
}

#[inline]
fn coord3(p: DVec3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

#[inline]
fn coord2(p: DVec2) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient3d_is_positive_above_a_counter_clockwise_triangle() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        assert!(orient3d(a, b, c, DVec3::Z) > 0.0);
        assert!(orient3d(a, b, c, -DVec3::Z) < 0.0);
        assert_eq!(orient3d(a, b, c, DVec3::new(5.0, -3.0, 0.0)), 0.0);
        assert!((orient3d(a, b, c, DVec3::Z * 2.0) - 2.0).abs() < 1e-15);
    }

    #[test]
    fn orient3d_sign_is_exact_where_naive_evaluation_fails() {
        // d is 1 ulp above the plane z = 1e8 spanned by large coordinates: the naive
        // determinant cancels catastrophically, the predicate must not.
        let z = 1e8;
        let (a, b, c) = (
            DVec3::new(1e8, 3e7, z),
            DVec3::new(-7e7, 1e8 + 1.0, z),
            DVec3::new(0.1, -9e7, z),
        );
        let above = DVec3::new(0.3, 0.7, f64::from_bits(z.to_bits() + 1));
        let below = DVec3::new(0.3, 0.7, f64::from_bits(z.to_bits() - 1));
        let on = DVec3::new(0.3, 0.7, z);
        let s = orient3d(a, b, c, DVec3::new(0.0, 0.0, z + 1.0)).signum();
        assert_eq!(orient3d(a, b, c, above).signum(), s);
        assert_eq!(orient3d(a, b, c, below).signum(), -s);
        assert_eq!(orient3d(a, b, c, on), 0.0);
    }

    #[test]
    fn orient2d_projected_sign_matches_the_normal_component() {
        let (a, b, c) = (
            DVec3::new(0.2, -1.0, 3.0),
            DVec3::new(1.5, 0.5, -2.0),
            DVec3::new(-0.7, 2.0, 1.0),
        );
        let n = (b - a).cross(c - a);
        for axis in 0..3 {
            assert_eq!(orient2d_projected(axis, a, b, c).signum(), n[axis].signum());
        }
        let p = DVec3::new(1.0, -2.0, 3.0);
        assert_eq!(orient2d_projected(2, p, p * 3.0, p * -2.0), 0.0);
    }

    #[test]
    fn orient2d_decides_nearly_collinear_points_exactly() {
        let a = DVec2::new(0.5, 0.5);
        let b = DVec2::new(12.0, 12.0);
        let on = DVec2::new(24.0, 24.0);
        let left = DVec2::new(24.0, f64::from_bits(24f64.to_bits() + 1));
        assert_eq!(orient2d(a, b, on), 0.0);
        assert!(orient2d(a, b, left) > 0.0);
    }
}
