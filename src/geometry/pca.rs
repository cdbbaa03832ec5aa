//! Principal component analysis of point sets and triangle surfaces.
//!
//! The covariance of a point set, or of a triangle surface with area weighting (each triangle
//! integrated continuously over its area), and its eigenvectors as a right-handed frame. Both
//! covariances are computed in *normalised* coordinates: the mean is subtracted first and the
//! result divided by the spread (largest coordinate offset from the mean), so that sets 1e6
//! from the origin and sizes from 1e-4 to 1e4 are conditioned alike. Eigenvectors do not
//! depend on that scaling.
//!
//! The eigen-decomposition is faer's self-adjoint solver; its output is sorted by decreasing
//! eigenvalue, re-orthonormalised (Gram–Schmidt, then a cross product for a right-handed
//! third axis). Degenerate covariances (zero, rank 1 or 2, repeated eigenvalues) give some
//! orthonormal completion, never NaN.
//!
//! Citation: S. Gottschalk, M. C. Lin, D. Manocha, "OBBTree: A Hierarchical Structure for
//! Rapid Interference Detection", SIGGRAPH 1996, §4 (continuous triangle covariance).

use crate::geometry::Triangle;
use crate::math::{DMat3, DVec3};
use faer::{Mat, Side};

/// Mean and normalised covariance of a point set or surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    /// Centroid, metres (same frame as the input).
    pub mean: DVec3,
    /// Covariance of `(x - mean) / spread`: dimensionless, symmetric, positive semi-definite.
    pub covariance: DMat3,
    /// The normalising length, metres: the largest `|x_k - mean_k|` over the input (1 when
    /// every input point coincides with the mean, so the covariance is then zero).
    pub spread: f64,
}

/// Mean and covariance of `points` (each weighted equally). `points` must be non-empty and
/// finite.
#[must_use]
pub fn point_moments(points: &[DVec3]) -> Moments {
    debug_assert!(!points.is_empty());
    let origin = points[0];
    let sum = points.iter().fold(DVec3::ZERO, |s, &p| s + (p - origin));
    let mean = origin + sum / points.len() as f64;
    let spread = spread_about(mean, points.iter().copied());
    let inv = 1.0 / spread;
    let mut c = [0.0f64; 6];
    for &p in points {
        accumulate(&mut c, (p - mean) * inv, 1.0);
    }
    Moments {
        mean,
        covariance: symmetric(c, 1.0 / points.len() as f64),
        spread,
    }
}

/// Area-weighted mean and covariance of the surface made of `triangles` (Gottschalk's
/// continuous formula: a triangle `p, q, r` of area `A` and centroid `m` contributes
/// `A/12 (9 m mᵀ + p pᵀ + q qᵀ + r rᵀ)` to the second moment).
///
/// Returns `None` when the total area is zero to rounding (all triangles degenerate); the
/// caller then falls back to [`point_moments`] of the vertices.
#[must_use]
pub fn triangle_moments(triangles: &[Triangle]) -> Option<Moments> {
    let origin = triangles.first()?.a;
    // Pass 1: area-weighted centroid, relative to `origin` for precision far from zero.
    let (mut total_area, mut weighted) = (0.0, DVec3::ZERO);
    for t in triangles {
        let (a, b, c) = (t.a - origin, t.b - origin, t.c - origin);
        let area = 0.5 * (b - a).cross(c - a).length();
        total_area += area;
        weighted += area * (a + b + c) / 3.0;
    }
    let vertices = triangles.iter().flat_map(|t| t.vertices());
    let extent = spread_about(origin, vertices.clone());
    if total_area <= DEGENERATE_AREA * extent * extent || !total_area.is_finite() {
        return None;
    }
    let mean = origin + weighted / total_area;
    let spread = spread_about(mean, vertices);
    let inv = 1.0 / spread;
    // Pass 2: second moments of the normalised surface about the mean.
    let (mut c, mut area_sum, mut first) = ([0.0f64; 6], 0.0, DVec3::ZERO);
    for t in triangles {
        let [a, b, cc] = t.vertices().map(|v| (v - mean) * inv);
        let area = 0.5 * (b - a).cross(cc - a).length();
        let m = (a + b + cc) / 3.0;
        accumulate(&mut c, m, 9.0 * area / 12.0);
        for v in [a, b, cc] {
            accumulate(&mut c, v, area / 12.0);
        }
        area_sum += area;
        first += area * m;
    }
    let centroid = first / area_sum;
    let second = symmetric(c, 1.0 / area_sum);
    let covariance = second - outer(centroid, centroid);
    Some(Moments {
        mean,
        covariance,
        spread,
    })
}

/// Below this fraction of `extent²`, a surface's total area counts as zero.
const DEGENERATE_AREA: f64 = 1e-24;

/// The principal axes of a covariance: a right-handed orthonormal frame whose columns are
/// eigenvectors sorted by decreasing eigenvalue.
///
/// Degenerate input (zero, rank-deficient, repeated eigenvalues, even non-finite entries)
/// gives some orthonormal frame, never NaN.
#[must_use]
pub fn principal_axes(covariance: &DMat3) -> DMat3 {
    principal_frame(covariance).0
}

/// [`principal_axes`] together with the eigenvalue along each axis (the Rayleigh quotient
/// `axisᵀ C axis`, so it matches the returned, re-orthonormalised axes), in decreasing order.
#[must_use]
pub fn principal_frame(covariance: &DMat3) -> (DMat3, DVec3) {
    let sym = (*covariance + covariance.transpose()) * 0.5;
    let cols = sym.to_cols_array_2d();
    if !sym.is_finite() {
        return (DMat3::IDENTITY, DVec3::ZERO);
    }
    let matrix = Mat::<f64>::from_fn(3, 3, |i, j| cols[j][i]);
    let axes = match matrix.self_adjoint_eigen(Side::Lower) {
        Ok(eigen) => {
            let u = eigen.U();
            // faer sorts eigenvalues increasing: take the columns in reverse order.
            let column = |j: usize| DVec3::new(u[(0, j)], u[(1, j)], u[(2, j)]);
            orthonormalise(column(2), column(1))
        }
        Err(_) => DMat3::IDENTITY,
    };
    let values = DVec3::new(
        axes.x_axis.dot(sym * axes.x_axis),
        axes.y_axis.dot(sym * axes.y_axis),
        axes.z_axis.dot(sym * axes.z_axis),
    );
    (axes, values)
}

/// A right-handed orthonormal frame whose first column is `first` (normalised) and whose
/// second lies in the plane of `first` and `second`. Any completion when either is zero or
/// they are parallel.
#[must_use]
pub fn orthonormalise(first: DVec3, second: DVec3) -> DMat3 {
    let x = first.try_normalize().unwrap_or(DVec3::X);
    let y = (second - x * x.dot(second))
        .try_normalize()
        .filter(|y| y.dot(x).abs() < 1e-6)
        .unwrap_or_else(|| x.any_orthonormal_vector());
    // A second Gram–Schmidt pass removes what rounding left of `x` in `y`.
    let y = (y - x * x.dot(y)).normalize();
    DMat3::from_cols(x, y, x.cross(y))
}

/// The largest `|x_k - center_k|` over `points`, or 1 when that is zero.
fn spread_about(center: DVec3, points: impl Iterator<Item = DVec3>) -> f64 {
    let spread = points.fold(0.0f64, |s, p| s.max((p - center).abs().max_element()));
    if spread > 0.0 { spread } else { 1.0 }
}

/// Adds `weight · v vᵀ` to the packed upper triangle `[xx, xy, xz, yy, yz, zz]`.
#[inline]
fn accumulate(c: &mut [f64; 6], v: DVec3, weight: f64) {
    let w = v * weight;
    c[0] += w.x * v.x;
    c[1] += w.x * v.y;
    c[2] += w.x * v.z;
    c[3] += w.y * v.y;
    c[4] += w.y * v.z;
    c[5] += w.z * v.z;
}

/// The symmetric matrix of a packed upper triangle, times `scale`.
fn symmetric(c: [f64; 6], scale: f64) -> DMat3 {
    let c = c.map(|x| x * scale);
    DMat3::from_cols(
        DVec3::new(c[0], c[1], c[2]),
        DVec3::new(c[1], c[3], c[4]),
        DVec3::new(c[2], c[4], c[5]),
    )
}

/// `a bᵀ`.
fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{rng, rotation};
    use rand::Rng;

    fn assert_frame(axes: &DMat3) {
        assert!(axes.is_finite(), "{axes}");
        assert!(
            (axes.transpose() * *axes).abs_diff_eq(DMat3::IDENTITY, 1e-12),
            "not orthonormal: {axes}"
        );
        assert!(
            (axes.determinant() - 1.0).abs() < 1e-12,
            "left-handed: {axes}"
        );
    }

    #[test]
    fn axes_of_an_anisotropic_cloud_follow_its_rotation() {
        let mut rng = rng(1);
        for case in 0..1000 {
            let rot = rotation(&mut rng);
            let offset = [0.0, 1e3, 1e6][case % 3];
            let scale = [1e-4, 1.0, 1e4][case % 3];
            let half = DVec3::new(3.0, 2.0, 1.0) * scale;
            let points: Vec<DVec3> = (0..200)
                .flat_map(|_| {
                    let p = DVec3::new(
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                        rng.random_range(-1.0..1.0),
                    ) * half;
                    // Symmetric pairs make the true axes exact eigenvectors.
                    [
                        p,
                        -p,
                        p * DVec3::new(-1.0, 1.0, 1.0),
                        p * DVec3::new(1.0, -1.0, 1.0),
                    ]
                })
                .map(|p| DVec3::splat(offset) + rot * p)
                .collect();
            let m = point_moments(&points);
            let axes = principal_axes(&m.covariance);
            assert_frame(&axes);
            for (k, expected) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                let cos = axes.col(k).dot(rot * expected).abs();
                assert!(cos > 0.99, "case {case}: axis {k} off by cos {cos}");
            }
        }
    }

    #[test]
    fn degenerate_covariances_give_orthonormal_frames() {
        let mut rng = rng(2);
        let mut inputs = vec![
            DMat3::ZERO,
            DMat3::IDENTITY,
            DMat3::from_diagonal(DVec3::new(1.0, 1.0, 0.0)),
            DMat3::from_diagonal(DVec3::new(0.0, 0.0, 1.0)),
            DMat3::from_diagonal(DVec3::new(1e-300, 0.0, 0.0)),
            DMat3::from_diagonal(DVec3::new(f64::NAN, 0.0, 0.0)),
        ];
        for _ in 0..1000 {
            let r = DMat3::from_quat(rotation(&mut rng));
            let d = DVec3::new(
                [0.0, 1.0][rng.random_range(0..2)],
                [0.0, 1.0][rng.random_range(0..2)],
                [0.0, 1.0, 1e-17][rng.random_range(0..3)],
            );
            inputs.push(r * DMat3::from_diagonal(d) * r.transpose());
        }
        for c in &inputs {
            let (axes, values) = principal_frame(c);
            assert_frame(&axes);
            assert!(values.is_finite() || !c.is_finite());
            if c.is_finite() {
                assert!(values.x >= values.y - 1e-12 && values.y >= values.z - 1e-12);
            }
        }
    }

    #[test]
    fn rank_one_covariance_gives_the_line_as_first_axis() {
        let dir = DVec3::new(1.0, 2.0, -0.5).normalize();
        let points: Vec<DVec3> = (0..50)
            .map(|i| DVec3::splat(1e6) + dir * (i as f64 * 1e-3))
            .collect();
        let m = point_moments(&points);
        let axes = principal_axes(&m.covariance);
        assert_frame(&axes);
        assert!(axes.x_axis.dot(dir).abs() > 1.0 - 1e-9);
    }

    #[test]
    fn triangle_moments_match_dense_sampling() {
        let mut rng = rng(3);
        for case in 0..50 {
            let tris: Vec<Triangle> = (0..4)
                .map(|_| {
                    let mut p = || {
                        DVec3::new(
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                            rng.random_range(-1.0..1.0),
                        ) + DVec3::splat(1e3)
                    };
                    Triangle::new(p(), p(), p())
                })
                .collect();
            let m = triangle_moments(&tris).unwrap();
            // Monte Carlo over the surface: uniform barycentric samples weighted by area.
            let (mut samples, mut weights) = (Vec::new(), Vec::new());
            for t in &tris {
                for _ in 0..4000 {
                    let (mut u, mut v) = (rng.random::<f64>(), rng.random::<f64>());
                    if u + v > 1.0 {
                        (u, v) = (1.0 - u, 1.0 - v);
                    }
                    samples.push(t.a + (t.b - t.a) * u + (t.c - t.a) * v);
                    weights.push(t.area());
                }
            }
            let total: f64 = weights.iter().sum();
            let mean = samples
                .iter()
                .zip(&weights)
                .fold(DVec3::ZERO, |s, (p, w)| s + (*p - DVec3::splat(1e3)) * *w)
                / total
                + DVec3::splat(1e3);
            assert!(
                m.mean.distance(mean) < 0.05,
                "case {case}: mean {} vs {mean}",
                m.mean
            );
            let mut cov = DMat3::ZERO;
            for (p, w) in samples.iter().zip(&weights) {
                let d = (*p - mean) / m.spread;
                cov += outer(d, d) * (*w / total);
            }
            assert!(
                (cov - m.covariance)
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|e| *e < 0.03),
                "case {case}: {cov} vs {}",
                m.covariance
            );
        }
    }

    #[test]
    fn zero_area_triangles_have_no_surface_moments() {
        let p = DVec3::new(1e6, 2.0, 3.0);
        let tris = [
            Triangle::new(p, p, p),
            Triangle::new(p, p + DVec3::X, p + 2.0 * DVec3::X),
        ];
        assert!(triangle_moments(&tris).is_none());
        assert!(triangle_moments(&[]).is_none());
    }

    #[test]
    fn a_single_point_has_zero_covariance_and_a_frame() {
        let m = point_moments(&[DVec3::splat(-1e6); 5]);
        assert_eq!(m.mean, DVec3::splat(-1e6));
        assert_eq!(m.covariance, DMat3::ZERO);
        assert_frame(&principal_axes(&m.covariance));
    }
}
