//! Cuboid–cuboid: the 15-axis separating-axis test (3 + 3 faces, 9 edge × edge) gives the
//! exact penetration depth; apart, the exact distance is the best of the 16 corner-to-box
//! clamps and the support edges along the cross axes the boxes are apart on
//! ([`super::query`], step 2). The edges are tried only when the best corner pair does not
//! separate the boxes at its own distance (which proves it the closest pair).
//!
//! Gottschalk, Lin, Manocha, *OBBTree* (1996); Ericson §4.4.1. Near-parallel edge pairs
//! (`|e_a × e_b| ≤ 1e-12`) are skipped, which can change a depth by at most `1e-12` × extent.
//! Manifold: reference/incident face clipping (Sutherland–Hodgman) reduced to the 4 most
//! informative points; edge–edge: 1 point ([`super::clip`]).
//!
//! The test and the apart case run here on the half extents in A's frame, where A is
//! axis-aligned (a box's projection radius is `Σ hₖ |aₖ · u|`, its corners are sign
//! patterns), instead of through the generic placed cores: boxes are the most common pair
//! of a physics scene. Penetration and the manifold then go to the shared engine with this
//! axis; so does the rare apart case whose support along a cross axis is a face.

use super::clip;
use super::placed_core::{AXIS_RELATIVE, PlacedCore};
use super::query::{self, Axis, BOUND_ULPS, FEATURE_RELATIVE};
use crate::geometry::Cuboid;
use crate::math::{DMat3, DVec3, Isometry};
use crate::narrow::contact::{DistanceBound, Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_cuboid_cuboid(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry) -> ShapeDistance {
    distance_cuboid_cuboid_within(a, b, pose_ab, f64::INFINITY).0
}

/// [`distance_cuboid_cuboid`] when it is at most `limit` metres; above the limit the answer
/// may be the separating axes' lower bound instead (`distance > limit` holds, the value is
/// not exact), which the second field then says (`true`). PERF: the first axis the boxes
/// are apart on decides, in the one pass the exact answer needs anyway.
#[must_use]
pub(crate) fn distance_cuboid_cuboid_within(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    limit: f64,
) -> (ShapeDistance, bool) {
    let boxes = Boxes::new(a, b, pose_ab);
    // Apart along any axis is enough to go to the closest pair; overlapping needs the best.
    let axis = boxes.best_axis_or_first_above(0.0);
    if axis.separation > limit {
        return (boxes.bound(&axis).at_lower(), true);
    }
    (exact(&boxes, &axis, (a, b, pose_ab)), false)
}

/// [`Boxes::distance`] with the shared engine on the boxes' cores behind it.
fn exact(
    boxes: &Boxes,
    axis: &Axis,
    (a, b, pose_ab): (&Cuboid, &Cuboid, &Isometry),
) -> ShapeDistance {
    boxes.distance(axis, |axis| {
        let (core_a, core_b) = cores(a, b, pose_ab);
        query::distance_with_axis(&core_a, &core_b, axis)
    })
}

/// Bounds on the signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's),
/// A's frame, as [`DistanceBound`] states. The separating-axis test stops at the first
/// axis the boxes are apart on: apart by more than `enough` metres there, the bounds are
/// that separation and an upper bound; apart by less, their exact distance, a rounding
/// allowance either side (the exact answer costs what the apart case of
/// [`distance_cuboid_cuboid`] costs, and settles a pair the axes leave undecided).
/// Overlapping boxes get the axes' depth.
#[must_use]
pub fn distance_bound_cuboid_cuboid(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    enough: f64,
) -> DistanceBound {
    let boxes = Boxes::new(a, b, pose_ab);
    // The first axis the boxes are apart on: beyond `enough`, that is all the bounds need;
    // within it, the exact distance is what another axis could add, and more.
    let axis = boxes.best_axis_or_first_above(0.0);
    if axis.separation > 0.0 && axis.separation <= enough {
        return DistanceBound::exact(&exact(&boxes, &axis, (a, b, pose_ab)), boxes.slack());
    }
    boxes.bound(&axis)
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_cuboid_cuboid(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry, out: &mut Manifold) {
    let boxes = Boxes::new(a, b, pose_ab);
    let axis = boxes.best_axis_or_first_above(boxes.tiny);
    if axis.separation > boxes.tiny {
        // PERF: apart by more than rounding (the distance is positive too): no closest pair.
        out.reset(axis.normal);
        return;
    }
    let (core_a, core_b) = cores(a, b, pose_ab);
    if axis.separation <= 0.0 {
        // Overlapping: the normal is the axis; the witnesses only if clipping finds nothing.
        let shared = |axis: &Axis| query::distance_with_axis(&core_a, &core_b, axis);
        let distance = || boxes.distance(&axis, shared);
        clip::manifold_along(&core_a, &core_b, axis.normal, distance, out);
    } else {
        let d = boxes.distance(&axis, |axis| {
            query::distance_with_axis(&core_a, &core_b, axis)
        });
        clip::manifold_from_distance(&core_a, &core_b, &d, out);
    }
}

/// The boxes as the shared engine's cores, A's frame.
fn cores(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry) -> (PlacedCore, PlacedCore) {
    (
        PlacedCore::cuboid(a, &Isometry::IDENTITY),
        PlacedCore::cuboid(b, pose_ab),
    )
}

/// Two boxes in A's frame: A axis-aligned about the origin, B's centre `t` and axes `r`
/// (columns).
struct Boxes {
    ha: DVec3,
    hb: DVec3,
    t: DVec3,
    r: DMat3,
    /// `|r|`, entry by entry.
    abs_r: DMat3,
    /// B's half extents' reach along A's axes, `|r| hb`.
    reach_b: DVec3,
    /// The largest corner coordinate, metres.
    scale: f64,
    /// [`FEATURE_RELATIVE`] times `scale`: the tolerance of support features and of
    /// rounding-sized gaps, as the shared engine's.
    tiny: f64,
}

impl Boxes {
    fn new(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry) -> Self {
        let (ha, hb) = (a.half_extents, b.half_extents);
        let (t, r) = (pose_ab.translation, pose_ab.rotation);
        let abs_r = DMat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
        let reach_b = abs_r * hb;
        // The largest coordinate of B's corners: |t| plus B's reach, per axis.
        let scale = ha.max_element().max((t.abs() + reach_b).max_element());
        Self {
            ha,
            hb,
            t,
            r,
            abs_r,
            reach_b,
            scale,
            tiny: FEATURE_RELATIVE * scale,
        }
    }

    // The 15 axes' separations in closed form (Gottschalk et al.; Ericson §4.4.1).
    // PERF: inlined, the axis stays in registers; passed through memory, a `DVec3`'s
    // (y, z) half is reloaded across two stores and stalls store forwarding.

    /// Along A's face normal `i`.
    #[inline(always)]
    fn face_a(&self, i: usize) -> Axis {
        let s = self.t[i];
        let u = DVec3::AXES[i];
        Axis {
            normal: if s >= 0.0 { u } else { -u },
            separation: s.abs() - self.ha[i] - self.reach_b[i],
        }
    }

    /// Along B's face normal `j`.
    #[inline(always)]
    fn face_b(&self, j: usize) -> Axis {
        let u = self.r.col(j);
        let s = self.t.dot(u);
        Axis {
            normal: if s >= 0.0 { u } else { -u },
            separation: s.abs() - self.abs_r.col(j).dot(self.ha) - self.hb[j],
        }
    }

    /// Along A's edge `i` crossed with B's edge `j`; `None` when they are parallel to
    /// [`AXIS_RELATIVE`].
    #[inline(always)]
    fn cross(&self, i: usize, j: usize) -> Option<Axis> {
        let u = DVec3::AXES[i].cross(self.r.col(j));
        let length = u.length();
        if length <= AXIS_RELATIVE {
            return None;
        }
        // B's reach projected directly: the cofactor shortcut (`b_k · u = ±(b_l)ᵢ`) leans
        // on orthonormality, and its rounding divided by a near-parallel pair's short `u`
        // broke the stress suite's certificate by 5e-11 relative.
        let reach_b = (self.r.transpose() * u).abs().dot(self.hb);
        let s = self.t.dot(u);
        let scale = if s >= 0.0 { 1.0 } else { -1.0 } / length;
        Some(Axis {
            normal: u * scale,
            separation: (s.abs() - u.abs().dot(self.ha) - reach_b) / length,
        })
    }

    /// The best of the 15 axes (the shared engine's [`query::best_axis`], on half extents),
    /// or the first found apart by more than `enough` metres (`f64::INFINITY`: the best).
    fn best_axis_or_first_above(&self, enough: f64) -> Axis {
        let mut best = Axis {
            normal: DVec3::X,
            separation: f64::NEG_INFINITY,
        };
        let mut offer = |axis: Axis| {
            if axis.separation > best.separation {
                best = axis;
            }
            best.separation > enough
        };
        for i in 0..3 {
            if offer(self.face_a(i)) {
                return best;
            }
        }
        for j in 0..3 {
            if offer(self.face_b(j)) {
                return best;
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                if let Some(axis) = self.cross(i, j)
                    && offer(axis)
                {
                    return best;
                }
            }
        }
        best
    }

    /// The rounding allowance of a bound, metres.
    fn slack(&self) -> f64 {
        BOUND_ULPS * f64::EPSILON * self.scale
    }

    /// The bounds from `axis`, as [`Self::best_axis_or_first_above`] gives it: the best of
    /// the 15 when the boxes overlap (the test then ran to the end), so the lower bound is
    /// the depth and the upper one meets it; else an axis they are apart on, with an upper
    /// bound from one step of alternating projection. A's corner farthest along the axis
    /// and B's farthest against it are sign patterns, a closest point a clamp.
    fn bound(&self, axis: &Axis) -> DistanceBound {
        let slack = self.slack();
        let n = axis.normal;
        let lower = axis.separation - slack;
        let to_b = |p: DVec3| self.r.transpose() * (p - self.t);
        let from_b = |q: DVec3| self.t + self.r * q;
        let upper = if axis.separation <= 0.0 {
            // The skipped near-parallel cross axes may change the depth by as much.
            let skipped = AXIS_RELATIVE * 2.0 * (self.ha.max_element() + self.hb.max_element());
            lower + 2.0 * slack + skipped
        } else {
            let on_b = from_b(to_b(n.signum() * self.ha).clamp(-self.hb, self.hb));
            on_b.clamp(-self.ha, self.ha).distance(on_b) + slack
        };
        let point_b = from_b(-(self.r.transpose() * n).signum() * self.hb);
        DistanceBound::new(lower, upper, n, point_b)
    }

    /// The signed distance given the best axis, or any axis the boxes are apart on; `shared`
    /// is the shared engine's answer on the boxes' cores with that axis (penetration, and the
    /// rare apart case [`Self::closest_pair_apart`] leaves to it).
    fn distance(&self, axis: &Axis, shared: impl FnOnce(&Axis) -> ShapeDistance) -> ShapeDistance {
        if axis.separation > 0.0
            && let Some((on_a, on_b)) = self.closest_pair_apart()
        {
            return query::apart(0.0, 0.0, on_a, on_b, axis, self.tiny);
        }
        shared(axis)
    }

    /// The closest pair of boxes known to be apart ([`super::query`], step 2), or `None` when
    /// a cross axis they are apart on is (to `tiny`) a face normal of one of them, which the
    /// shared engine handles.
    fn closest_pair_apart(&self) -> Option<(DVec3, DVec3)> {
        let (ha, hb, t, r) = (self.ha, self.hb, self.t, self.r);
        let corner = |i: usize, h: DVec3| {
            DVec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        };
        let mut best = (f64::INFINITY, DVec3::ZERO, DVec3::ZERO);
        // B's corners against A, in A's frame.
        for i in 0..8 {
            let q = t + r * corner(i, hb);
            let p = q.clamp(-ha, ha);
            let d = p.distance_squared(q);
            if d < best.0 {
                best = (d, p, q);
            }
        }
        // A's corners against B, in B's frame (distances are the same); mapped back after.
        let (rt, t_in_b) = (r.transpose(), r.transpose() * -t);
        let mut best_b = (f64::INFINITY, DVec3::ZERO, DVec3::ZERO);
        for i in 0..8 {
            let p = t_in_b + rt * corner(i, ha);
            let q = p.clamp(-hb, hb);
            let d = p.distance_squared(q);
            if d < best_b.0 {
                best_b = (d, p, q);
            }
        }
        if best_b.0 < best.0 {
            best = (best_b.0, r * best_b.1 + t, r * best_b.2 + t);
        }
        if self.separates_at(best.1, best.2) {
            // PERF: the corner pair is the closest pair, no edge pair need be tried (most
            // apart poses: `narrow_phase` cuboid_cuboid separated 323 → 198 ns).
            return Some((best.1, best.2));
        }
        for i in 0..3 {
            for j in 0..3 {
                let Some(axis) = self.cross(i, j) else {
                    continue;
                };
                let sep = axis.separation;
                if sep <= 0.0 || sep * sep >= best.0 {
                    continue;
                }
                let u = axis.normal;
                let centre_a = support_edge_centre(ha, i, u, self.tiny)?;
                let centre_b = t + r * support_edge_centre(hb, j, rt * -u, self.tiny)?;
                // The closest points of the edges' lines (unit directions, Ericson §5.1.8):
                // only a pair inside both edges matters, any other is no closer than a
                // corner pair offered above. Not parallel (`Self::cross`), so `1 − b² > 0`.
                let (dir_a, dir_b) = (DVec3::AXES[i], r.col(j));
                let w = centre_a - centre_b;
                let (b, c, f) = (dir_a.dot(dir_b), dir_a.dot(w), dir_b.dot(w));
                let s = (b * f - c) / (1.0 - b * b);
                let s_b = f + s * b;
                if s.abs() > ha[i] || s_b.abs() > hb[j] {
                    continue;
                }
                let (p, q) = (centre_a + dir_a * s, centre_b + dir_b * s_b);
                let d = p.distance_squared(q);
                if d < best.0 {
                    best = (d, p, q);
                }
            }
        }
        Some((best.1, best.2))
    }

    /// Whether the boxes are apart along `on_b − on_a` by that pair's own distance (to
    /// [`BOUND_ULPS`] of the scale): then no pair of points is closer, since the distance is
    /// at least the separation along any axis, and `(on_a, on_b)` is the closest pair.
    fn separates_at(&self, on_a: DVec3, on_b: DVec3) -> bool {
        let gap = on_b - on_a;
        let length = gap.length();
        if length <= self.tiny {
            return false;
        }
        let u = gap / length;
        let reach_b = (self.r.transpose() * u).abs().dot(self.hb);
        let separation = self.t.dot(u) - u.abs().dot(self.ha) - reach_b;
        separation >= length - self.slack()
    }
}

/// The centre of the edge along axis `i` of the box of half extents `h` (its own frame)
/// that supports direction `u` (`u ⟂` axis `i`); `None` when `u` is within `tiny` of a face
/// normal (the support feature is a face).
fn support_edge_centre(h: DVec3, i: usize, u: DVec3, tiny: f64) -> Option<DVec3> {
    let mut p = DVec3::ZERO;
    for k in 0..3 {
        if k != i {
            if h[k] > 0.0 && 2.0 * h[k] * u[k].abs() <= tiny {
                return None;
            }
            p[k] = if u[k] >= 0.0 { h[k] } else { -h[k] };
        }
    }
    Some(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;

    #[test]
    fn stacked_cubes_give_four_points_over_the_overlap() {
        let c = Cuboid::new(DVec3::splat(0.5));
        let pose = Isometry::from_translation(DVec3::new(0.3, 0.2, 0.9));
        let d = distance_cuboid_cuboid(&c, &c, &pose);
        assert!(
            (d.distance + 0.1).abs() < 1e-15 && d.normal == DVec3::Z,
            "{d:?}"
        );
        check::contract(&d, 1e-15);
        let mut m = Manifold::new();
        manifold_cuboid_cuboid(&c, &c, &pose, &mut m);
        check::manifold(&m, 4, 1e-15);
        for p in m.points() {
            assert!((p.distance + 0.1).abs() < 1e-15);
            assert!(p.point_a.x >= -0.2 - 1e-15 && p.point_a.y >= -0.3 - 1e-15);
        }
    }

    #[test]
    fn crossed_edges_give_one_point_and_the_edge_axis() {
        let c = Cuboid::new(DVec3::splat(0.5));
        // A's edge along Y at x = z = 0.5 faces w = (1, 0, 1)/√2; B's local X edge at
        // y = z = -0.5 is turned along (1, 0, -1)/√2 and faces -w, dipping 0.1 into A's.
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let (w, v) = (DVec3::new(s, 0.0, s), DVec3::Y);
        let rot = DMat3::from_cols(DVec3::new(s, 0.0, -s), (w + v) * s, (w - v) * s);
        let rot = if rot.determinant() > 0.0 {
            rot
        } else {
            DMat3::from_cols(rot.x_axis, (w - v) * s, (w + v) * s)
        };
        let centre = DVec3::new(0.5, 0.0, 0.5) + w * (s - 0.1);
        let pose = Isometry::new(rot, centre);
        let d = distance_cuboid_cuboid(&c, &c, &pose);
        assert!((d.distance + 0.1).abs() < 1e-14, "{d:?}");
        assert!(d.normal.abs_diff_eq(w, 1e-14), "{d:?}");
        check::contract(&d, 1e-14);
        let mut m = Manifold::new();
        manifold_cuboid_cuboid(&c, &c, &pose, &mut m);
        check::manifold(&m, 1, 1e-14);
        assert!(
            m.points()[0]
                .point_a
                .abs_diff_eq(DVec3::new(0.5, 0.0, 0.5), 1e-14)
        );
    }

    #[test]
    fn zero_size_and_flat_boxes_never_give_nan() {
        let flat = Cuboid::new(DVec3::new(1.0, 1.0, 0.0));
        let point = Cuboid::new(DVec3::ZERO);
        for (a, b) in [(flat, flat), (flat, point), (point, point)] {
            for pose in [
                Isometry::IDENTITY,
                Isometry::from_translation(DVec3::new(0.1, 0.2, 0.0)),
            ] {
                let d = distance_cuboid_cuboid(&a, &b, &pose);
                check::contract(&d, 1e-15);
                let mut m = Manifold::new();
                manifold_cuboid_cuboid(&a, &b, &pose, &mut m);
                assert!(m.len() <= 4 && m.points().iter().all(|p| p.point_a.is_finite()));
            }
        }
    }
}
