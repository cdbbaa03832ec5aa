//! The triangles of two meshes at one pose, both in A's frame, with their axis-aligned
//! boxes: what the brute-force mesh–mesh oracles of the tests run over.

use super::meshes;
use proxima::geometry::{TriMesh, Triangle};
use proxima::math::{DVec3, Pose};

/// Axis-aligned box of one triangle.
#[derive(Debug, Clone, Copy)]
pub struct TriangleBox {
    pub lo: DVec3,
    pub hi: DVec3,
}

impl TriangleBox {
    pub fn of(t: &Triangle) -> Self {
        Self {
            lo: t.a.min(t.b).min(t.c),
            hi: t.a.max(t.b).max(t.c),
        }
    }

    /// Length of the shortest vector between the two boxes (0 when they overlap): a lower
    /// bound of the distance of anything inside them, up to rounding.
    pub fn gap(&self, other: &Self) -> f64 {
        (other.lo - self.hi)
            .max(self.lo - other.hi)
            .max(DVec3::ZERO)
            .length()
    }
}

/// Every triangle of A and of B placed at one pose, both in A's frame.
pub struct TrianglePairs {
    pub a: Vec<Triangle>,
    pub a_boxes: Vec<TriangleBox>,
    /// B's triangles mapped into A's frame exactly as the queries map them.
    pub b: Vec<Triangle>,
    pub b_boxes: Vec<TriangleBox>,
    /// Largest coordinate magnitude of either mesh in A's frame: the scale of rounding.
    pub scale: f64,
}

impl TrianglePairs {
    pub fn new(a: &TriMesh, b: &TriMesh, pose_ab: &Pose) -> Self {
        let iso = pose_ab.to_isometry();
        let a = meshes::triangles(a);
        let b: Vec<Triangle> = meshes::triangles(b)
            .iter()
            .map(|t| t.transformed(&iso))
            .collect();
        let scale = a
            .iter()
            .chain(&b)
            .flat_map(Triangle::vertices)
            .map(|v| v.abs().max_element())
            .fold(0.0, f64::max);
        Self {
            a_boxes: a.iter().map(TriangleBox::of).collect(),
            b_boxes: b.iter().map(TriangleBox::of).collect(),
            a,
            b,
            scale,
        }
    }
}
