//! Robust orientation predicates: the sign of a small determinant, always exact.
//!
//! These wrap Shewchuk's adaptive-precision predicates (the `robust` crate): a fast
//! floating-point evaluation with a forward error bound (inlined here, the same operations
//! as the crate's), refined in exact expansion arithmetic by the crate only when the bound
//! cannot certify the sign. The **sign** of every result is
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
    -robust_orient3d(a, b, c, d)
}

/// `robust::orient3d(a, b, c, d)`, bit for bit, with its floating-point stage inlined here.
///
/// PERF(examples/fcl_peer, collide_all): the crate's function holds its exact stage too,
/// whose 6 KB stack frame every call paid for (a page-touching probe) even when the first
/// stage settles the sign, which it nearly always does: 42 % of the exact triangle test's
/// time on env × rob. The crate is called only when this stage cannot certify the sign,
/// and repeats the same stage first, so the value returned is the crate's in every case.
#[inline]
fn robust_orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    orient3d_first_stage(a, b, c, d)
        .unwrap_or_else(|| robust::orient3d(coord3(a), coord3(b), coord3(c), coord3(d)))
}

/// The `robust` crate's `orient3d` floating-point stage, operation for operation
/// (Shewchuk's first stage): its value when its error bound certifies the sign, else
/// `None`.
#[inline]
fn orient3d_first_stage(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<f64> {
    let (adx, bdx, cdx) = (a.x - d.x, b.x - d.x, c.x - d.x);
    let (ady, bdy, cdy) = (a.y - d.y, b.y - d.y, c.y - d.y);
    let (adz, bdz, cdz) = (a.z - d.z, b.z - d.z, c.z - d.z);
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    let errbound = O3D_ERRBOUND_A * permanent;
    (det > errbound || -det > errbound).then_some(det)
}

/// Half an ulp of 1.0 (Shewchuk's `epsilon`), as the `robust` crate defines it.
const EPSILON: f64 = 0.000_000_000_000_000_111_022_302_462_515_65;

/// Shewchuk's `o3derrboundA`: the first stage's relative error bound.
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * EPSILON) * EPSILON;

/// The `robust` crate's first-stage bound for `orient2d` (Ozaki et al., 2016).
const O2D_THETA: f64 = 3.330_669_062_177_372_2e-16;

/// Orientation of `c` relative to the directed line `a → b` in the plane.
///
/// Returns a value with the exact sign of `(b - a) × (c - a)` (the z component): positive
/// when `a, b, c` turn counter-clockwise (`c` left of `a → b`), negative when clockwise,
/// exactly `0.0` when collinear. The magnitude approximates twice the signed area.
#[must_use]
#[inline]
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    // PERF: the crate's first stage inlined, as in `robust_orient3d` (same reason, same
    // value in every case).
    orient2d_first_stage(a, b, c)
        .unwrap_or_else(|| robust::orient2d(coord2(a), coord2(b), coord2(c)))
}

/// The `robust` crate's `orient2d` floating-point stage, operation for operation: its
/// value when its error bound certifies the sign, else `None`.
#[inline]
fn orient2d_first_stage(a: DVec2, b: DVec2, c: DVec2) -> Option<f64> {
    let detleft = (a.x - c.x) * (b.y - c.y);
    let detright = (a.y - c.y) * (b.x - c.x);
    let det = detleft - detright;
    let errbound = O2D_THETA * (detleft + detright).abs();
    (det >= errbound || -det >= errbound).then_some(det)
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

    /// The inlined first stages return the crate's value bit for bit, on random points
    /// and on points a few ulps from coplanar or collinear (where the exact stage runs).
    #[test]
    fn the_inlined_first_stages_return_the_crates_values() {
        use crate::test_support::{point_in_cube, rng};
        let mut r = rng(31);
        // How often the first stage could not decide a near point, so that the crate's
        // exact stage ran.
        let (mut exact_stage_3d, mut exact_stage_2d) = (0, 0);
        for k in 0..20_000 {
            let scale = [1e-3, 1.0, 1e3][k % 3];
            let (a, b, c) = (
                point_in_cube(&mut r, scale),
                point_in_cube(&mut r, scale),
                point_in_cube(&mut r, scale),
            );
            let free = point_in_cube(&mut r, scale);
            // Near-coplanar: an affine mix of the three, nudged by a few ulps.
            let (s, t) = (
                rand::Rng::random::<f64>(&mut r),
                rand::Rng::random::<f64>(&mut r),
            );
            let on = a + (b - a) * s + (c - a) * t;
            let nudge = |x: f64, n: i64| f64::from_bits((x.to_bits() as i64 + n) as u64);
            let near = DVec3::new(on.x, on.y, nudge(on.z, (k % 7) as i64 - 3));
            for d in [free, near, a] {
                let crate_value = robust::orient3d(coord3(a), coord3(b), coord3(c), coord3(d));
                assert_eq!(robust_orient3d(a, b, c, d).to_bits(), crate_value.to_bits());
            }
            exact_stage_3d += usize::from(orient3d_first_stage(a, b, c, near).is_none());
            let flat = |p: DVec3| DVec2::new(p.x, p.y);
            let line = flat(a) + (flat(b) - flat(a)) * s;
            let near2 = DVec2::new(line.x, nudge(line.y, (k % 5) as i64 - 2));
            for p in [flat(c), near2, flat(a)] {
                let crate_value = robust::orient2d(coord2(flat(a)), coord2(flat(b)), coord2(p));
                assert_eq!(
                    orient2d(flat(a), flat(b), p).to_bits(),
                    crate_value.to_bits()
                );
            }
            exact_stage_2d += usize::from(orient2d_first_stage(flat(a), flat(b), near2).is_none());
        }
        assert!(
            exact_stage_3d > 1_000 && exact_stage_2d > 1_000,
            "{exact_stage_3d} {exact_stage_2d}"
        );
    }

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
