//! Procedural closed meshes: a UV sphere and a torus, welded (neighbouring triangles share
//! vertex indices) and oriented counter-clockwise seen from outside. Used by the demo scene,
//! the examples and the tests.

use super::TriMesh;
use crate::math::DVec3;
use std::f64::consts::{PI, TAU};

impl TriMesh {
    /// Closed UV sphere of `radius` about the origin: `segments ≥ 3` around the z axis,
    /// `rings ≥ 2` bands from pole to pole; `2 · segments · (rings − 1)` triangles.
    ///
    /// # Panics
    /// When `segments < 3` or `rings < 2`.
    #[must_use]
    pub fn uv_sphere(radius: f64, segments: u32, rings: u32) -> Self {
        assert!(segments >= 3 && rings >= 2);
        let mut vertices = vec![DVec3::new(0.0, 0.0, radius)];
        for k in 1..rings {
            let theta = PI * f64::from(k) / f64::from(rings);
            for j in 0..segments {
                let phi = TAU * f64::from(j) / f64::from(segments);
                vertices.push(
                    radius
                        * DVec3::new(
                            theta.sin() * phi.cos(),
                            theta.sin() * phi.sin(),
                            theta.cos(),
                        ),
                );
            }
        }
        let south = vertices.len() as u32;
        vertices.push(DVec3::new(0.0, 0.0, -radius));
        let ring = |k: u32, j: u32| 1 + (k - 1) * segments + j % segments;
        let mut tris = Vec::new();
        for j in 0..segments {
            tris.push([0, ring(1, j), ring(1, j + 1)]);
        }
        for k in 1..rings - 1 {
            for j in 0..segments {
                let (a, b) = (ring(k, j), ring(k + 1, j));
                let (c, d) = (ring(k + 1, j + 1), ring(k, j + 1));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        for j in 0..segments {
            tris.push([ring(rings - 1, j), south, ring(rings - 1, j + 1)]);
        }
        Self::try_new(vertices, tris).expect("procedural meshes are valid by construction")
    }

    /// Closed torus about the z axis: tube centre line of radius `major`, tube radius
    /// `minor < major`; `around` steps along the centre line, `across` around the tube;
    /// `2 · around · across` triangles.
    ///
    /// # Panics
    /// When `minor ≥ major`, `around < 3` or `across < 3`.
    #[must_use]
    pub fn torus(major: f64, minor: f64, around: u32, across: u32) -> Self {
        assert!(minor < major && around >= 3 && across >= 3);
        let mut vertices = Vec::new();
        for i in 0..around {
            let u = TAU * f64::from(i) / f64::from(around);
            for j in 0..across {
                let v = TAU * f64::from(j) / f64::from(across);
                let r = major + minor * v.cos();
                vertices.push(DVec3::new(r * u.cos(), r * u.sin(), minor * v.sin()));
            }
        }
        let at = |i: u32, j: u32| (i % around) * across + j % across;
        let mut tris = Vec::new();
        for i in 0..around {
            for j in 0..across {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                tris.push([a, b, c]);
                tris.push([a, c, d]);
            }
        }
        Self::try_new(vertices, tris).expect("procedural meshes are valid by construction")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_meshes_have_the_documented_counts_and_an_outward_orientation() {
        let sphere = TriMesh::uv_sphere(2.0, 16, 8);
        let torus = TriMesh::torus(1.0, 0.25, 24, 12);
        assert_eq!(sphere.triangle_count(), 2 * 16 * 7);
        assert_eq!(torus.triangle_count(), 2 * 24 * 12);
        for (mesh, inside) in [(&sphere, DVec3::ZERO), (&torus, DVec3::X)] {
            let report = mesh.report();
            assert!(report.closed && report.degenerate_triangles.is_empty());
            // Outward orientation: every face's normal points away from an interior point
            // of the solid near it (the centre, or the tube's centre line).
            for i in 0..mesh.triangle_count() {
                let t = mesh.triangle(i);
                let centroid = (t.a + t.b + t.c) / 3.0;
                let core = if inside == DVec3::ZERO {
                    DVec3::ZERO
                } else {
                    DVec3::new(centroid.x, centroid.y, 0.0).normalize()
                };
                assert!(
                    (t.b - t.a).cross(t.c - t.a).dot(centroid - core) > 0.0,
                    "face {i}"
                );
            }
        }
        let r = sphere
            .vertices()
            .iter()
            .map(|v| v.length())
            .fold(0.0, f64::max);
        assert!((r - 2.0).abs() < 1e-12);
    }
}
