//! A triangle sunk into one face of a box: its depth without the separating-axis test, the
//! hot case of a box against a mesh lying on it (a torus on the floor) or pressed into it.
//!
//! # Why the depth is exact
//! Let face `f` be the box's face axis of least overlap, `o` that overlap, and `v` the
//! triangle's vertex deepest past `f`. Moving the triangle out along `f`'s normal by `o`
//! separates it (every vertex is then on or beyond the face's plane), so the depth is at
//! most `o`. Every separating motion must carry `v`, a point inside the box, out of it, so
//! it is at least `v`'s distance to the box's surface; when `v` lies nearer `f` (at `o`)
//! than any other face, that is `o`. The depth is then `o`, exactly, and `f`'s normal is the
//! separating-axis test's own answer: the face axes come first in its order and keep ties
//! (Ericson, *Real-Time Collision Detection*, §5.2.1). The witnesses are found as that
//! test's caller finds them ([`super::query`]'s step 3: the support features along the
//! normal, B moved out by the depth), so the answer is the test's to rounding.
//!
//! Any other pair (apart or touching along a face, a flat box, a vertex as near another
//! face, an edge sunk across an edge of the box) is left to the separating-axis test.

use super::placed_core::Polygon;
use super::query::{FEATURE_RELATIVE, closest_pair};
use crate::geometry::Triangle;
use crate::math::DVec3;
use crate::narrow::contact::ShapeDistance;

/// The box `[-half, half]` (A's frame, axis-aligned at A's origin, every half extent
/// positive) against `triangle` sunk into one face (module docs): the signed distance
/// (minus the depth), witnesses and normal A→B, else `None`.
#[must_use]
pub(super) fn face_depth_box_triangle(half: DVec3, triangle: &Triangle) -> Option<ShapeDistance> {
    if half.min_element() <= 0.0 {
        return None;
    }
    let vertices = triangle.vertices();
    let (low, high) = (
        triangle.a.min(triangle.b).min(triangle.c),
        triangle.a.max(triangle.b).max(triangle.c),
    );
    // The face axes as the separating-axis test tries them: per axis the side of larger
    // separation (`+` on ties), the first axis of the largest.
    let (mut separation, mut axis, mut plus) = (f64::NEG_INFINITY, 0, true);
    for k in 0..3 {
        let (over_plus, over_minus) = (low[k] - half[k], -half[k] - high[k]);
        let (side, gap) = if over_plus >= over_minus {
            (true, over_plus)
        } else {
            (false, over_minus)
        };
        if gap > separation {
            (separation, axis, plus) = (gap, k, side);
        }
    }
    if separation >= 0.0 {
        return None;
    }
    let depth = -separation;
    let sign = if plus { 1.0 } else { -1.0 };
    // The deepest vertex past the face: the least far out along the outward normal.
    let deepest = (vertices.iter())
        .min_by(|p, q| (sign * p[axis]).total_cmp(&(sign * q[axis])))
        .copied()?;
    let scale = half
        .max_element()
        .max(low.abs().max(high.abs()).max_element());
    let tiny = FEATURE_RELATIVE * scale;
    let to_other_faces = (0..3)
        .filter(|&i| i != axis)
        .map(|i| half[i] - deepest[i].abs())
        .fold(half[axis] + sign * deepest[axis], f64::min);
    if depth + tiny >= to_other_faces {
        return None;
    }
    let mut normal = DVec3::ZERO;
    normal[axis] = sign;
    // Support features, as the separating-axis path builds them: the box's face along the
    // normal, the triangle's vertices within `tiny` of its extreme against it, moved out.
    let shift = normal * depth;
    let extreme = vertices
        .iter()
        .map(|v| -v.dot(normal))
        .fold(f64::NEG_INFINITY, f64::max);
    let mut on_triangle = Polygon::default();
    for v in vertices {
        if -v.dot(normal) >= extreme - tiny {
            on_triangle.push(v + shift);
        }
    }
    let mut face = Polygon::default();
    let (j, l) = if axis == 0 {
        (1, 2)
    } else if axis == 1 {
        (0, 2)
    } else {
        (0, 1)
    };
    for (sj, sl) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
        let mut corner = DVec3::ZERO;
        (corner[axis], corner[j], corner[l]) = (sign * half[axis], sj * half[j], sl * half[l]);
        face.push(corner);
    }
    let (point_a, point_b) = closest_pair(&face, &on_triangle);
    Some(ShapeDistance {
        distance: -depth,
        point_a,
        point_b: point_b - shift,
        normal,
    })
}

#[cfg(test)]
mod tests {
    use super::super::placed_core::PlacedCore;
    use super::super::query;
    use super::*;
    use crate::geometry::Cuboid;
    use crate::math::Isometry;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    /// A triangle near a box of half extents `half`: a vertex just inside one of its faces
    /// (sometimes near an edge or corner of the box), the others around it, from slivers
    /// to triangles larger than the box.
    fn sunk_triangle(rng: &mut TestRng, half: DVec3) -> Triangle {
        let axis = rng.random_range(0..3);
        let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
        let mut inside = DVec3::new(
            rng.random_range(-1.0..1.0) * half.x,
            rng.random_range(-1.0..1.0) * half.y,
            rng.random_range(-1.0..1.0) * half.z,
        );
        inside[axis] = sign * (half[axis] - rng.random_range(0.0..0.3) * half.min_element());
        let size = [0.02, 0.3, 2.0][rng.random_range(0..3)];
        let out = |rng: &mut TestRng| {
            let mut p = inside + point_in_cube(rng, size);
            p[axis] = inside[axis] + sign * rng.random_range(0.0..size);
            p
        };
        let (b, c) = (out(rng), out(rng));
        Triangle::new(inside, b, c)
    }

    /// Boxes against triangles sunk into their faces: every depth this path answers is the
    /// separating-axis path's, with the same witnesses and normal; both outcomes occur.
    #[test]
    fn a_triangle_sunk_into_a_face_gets_the_separating_axis_answer() {
        let mut rng = rng(2718);
        let identity = Isometry::IDENTITY;
        let (mut taken, mut declined) = (0, 0);
        for case in 0..20_000 {
            let half = DVec3::new(
                rng.random_range(0.05..2.0),
                rng.random_range(0.05..2.0),
                rng.random_range(0.05..2.0),
            );
            let t = sunk_triangle(&mut rng, half);
            let axes = query::distance(
                &PlacedCore::cuboid(&Cuboid::new(half), &identity),
                &PlacedCore::triangle(&t, &identity),
            );
            let Some(fast) = face_depth_box_triangle(half, &t) else {
                declined += 1;
                continue;
            };
            taken += 1;
            let scale =
                1.0 + half.max_element() + t.a.abs().max(t.b.abs()).max(t.c.abs()).max_element();
            assert!(
                (fast.distance - axes.distance).abs() <= 1e-12 * scale
                    && fast.normal.distance(axes.normal) <= 1e-12
                    && fast.point_a.distance(axes.point_a) <= 1e-9 * scale
                    && fast.point_b.distance(axes.point_b) <= 1e-9 * scale,
                "case {case}: {fast:?} against {axes:?}"
            );
            assert!(fast.distance < 0.0, "case {case}: a sunk triangle overlaps");
        }
        assert!(
            taken > 8_000 && declined > 2_000,
            "{taken} taken, {declined} declined"
        );
    }
}
