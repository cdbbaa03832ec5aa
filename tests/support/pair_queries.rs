//! The library's own pair dispatch, for tests whose shapes include lone triangles: a pair
//! of registered shapes goes through `proxima::narrow::dispatch` (exactly as the pipeline
//! sends it), a shape against a triangle through the query a mesh's walk runs on each
//! triangle. Tests keep their own shape model only for their oracles.

use proxima::geometry::Triangle;
use proxima::math::Isometry;
use proxima::narrow::convex_mesh::{shape_triangle_distance, shape_triangle_manifold};
use proxima::narrow::dispatch::{self, NarrowScratch};
use proxima::narrow::gjk::EpaWorkspace;
use proxima::narrow::{Manifold, Shape, ShapeDistance};

/// One side of a pair: a registered convex shape (not a mesh), or one triangle of a mesh.
pub enum Piece {
    Shape(Shape),
    Triangle(Triangle),
}

/// The signed distance of `a` and `b` placed by `pose_ab`, A's frame, as the library
/// answers it; `None` for two triangles (no penetration depth between surfaces).
pub fn distance(a: &Piece, b: &Piece, pose_ab: &Isometry) -> Option<ShapeDistance> {
    let epa = &mut EpaWorkspace::new();
    Some(match (a, b) {
        (Piece::Shape(x), Piece::Shape(y)) => {
            let scratch = &mut NarrowScratch::default();
            dispatch::distance_convex(x, y, pose_ab, f64::INFINITY, scratch)
        }
        (Piece::Shape(x), Piece::Triangle(t)) => {
            shape_triangle_distance(x, &t.transformed(pose_ab), epa)
        }
        (Piece::Triangle(_), Piece::Shape(_)) => {
            distance(b, a, &pose_ab.inverse())?.flipped(pose_ab)
        }
        (Piece::Triangle(_), Piece::Triangle(_)) => return None,
    })
}

/// The contact manifold of `a` and `b` placed by `pose_ab`, A's frame, as the library
/// answers it; `None` for two triangles.
pub fn manifold(a: &Piece, b: &Piece, pose_ab: &Isometry) -> Option<Manifold> {
    let mut out = Manifold::new();
    match (a, b) {
        (Piece::Shape(x), Piece::Shape(y)) => {
            let scratch = &mut NarrowScratch::default();
            let d = dispatch::distance_convex(x, y, pose_ab, f64::INFINITY, scratch);
            dispatch::manifold_convex(x, y, pose_ab, &d, scratch, &mut out);
        }
        (Piece::Shape(x), Piece::Triangle(t)) => {
            let epa = &mut EpaWorkspace::new();
            shape_triangle_manifold(x, &t.transformed(pose_ab), epa, &mut out);
        }
        (Piece::Triangle(_), Piece::Shape(_)) => {
            out = manifold(b, a, &pose_ab.inverse())?;
            out.flip(pose_ab);
        }
        (Piece::Triangle(_), Piece::Triangle(_)) => return None,
    }
    Some(out)
}
