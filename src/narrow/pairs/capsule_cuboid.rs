//! Capsule–cuboid: the segment–box distance minus the radius; when the core segment meets
//! the box, the separating-axis depth over the 3 box faces and the 3 segment × edge axes
//! plus the radius (exact: those are all face normals of the Minkowski difference).
//!
//! Everything starts in the box's frame ([`InBox`]). The segment's point closest to the box
//! comes first, in closed form: it proves the cores apart in the common case (the shapes
//! touch through the radius) and is then the answer. Cores that meet get their depth from
//! the separating axes, exact for a solid box; the shared engine of [`super::query`] answers
//! what is left (a flat box whose core meets the segment, cores touching to rounding).
//! Manifold: up to 2 points (segment clipped against a box face), 1 for an edge or corner
//! contact ([`super::clip`]).

use super::placed_core::{AXIS_RELATIVE, PlacedCore};
use super::query::FEATURE_RELATIVE;
use super::{clip, query};
use crate::geometry::{Capsule, Cuboid};
use crate::math::{DVec3, Isometry};
use crate::narrow::closest_points::closest_point_segment;
use crate::narrow::contact::{DistanceBound, Manifold, ShapeDistance};

/// Exact signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's), with
/// witnesses and unit normal A→B, all in A's frame, as [`crate::narrow::contact`] states;
/// negative: minus the penetration depth. Never NaN, degenerate sizes included.
#[must_use]
pub fn distance_capsule_cuboid(a: &Capsule, b: &Cuboid, pose_ab: &Isometry) -> ShapeDistance {
    let placed = InBox::new(a, b, pose_ab);
    placed
        .apart(pose_ab)
        .or_else(|| placed.overlapping(pose_ab))
        .unwrap_or_else(|| {
            query::distance(
                &PlacedCore::capsule(a, &Isometry::IDENTITY),
                &PlacedCore::cuboid(b, pose_ab),
            )
        })
}

/// Bounds on the signed distance from `a` to `b` placed by `pose_ab` (B's frame in A's),
/// A's frame, as [`DistanceBound`] states. Cores apart: the exact answer, a rounding
/// allowance either side (it costs what a separating-axis test would, so the bounds need no
/// limit to stop at). Cores that meet: the separating axes, whose depth is exact for a
/// solid box.
#[must_use]
pub fn distance_bound_capsule_cuboid(a: &Capsule, b: &Cuboid, pose_ab: &Isometry) -> DistanceBound {
    let placed = InBox::new(a, b, pose_ab);
    match placed.apart(pose_ab) {
        Some(d) => DistanceBound::exact(&d, placed.slack()),
        None => placed.bound_from_axes(pose_ab),
    }
}

/// The capsule's core segment in the box's frame, where each separating axis costs a few
/// products. PERF: the axes cost a quarter of the shared engine's on placed cores (4,096
/// near pairs: 266–271 → 87 ns a bound).
#[derive(Debug, Clone, Copy)]
struct InBox {
    /// The segment's end points, box frame.
    p0: DVec3,
    p1: DVec3,
    /// The box's half extents, metres.
    half: DVec3,
    radius: f64,
}

/// The best of the separating axes, box frame.
struct Axis {
    /// Unit axis from the box towards the segment.
    away: DVec3,
    /// The cores' separation along it, metres (negative: overlap).
    separation: f64,
}

impl InBox {
    fn new(a: &Capsule, b: &Cuboid, pose_ab: &Isometry) -> Self {
        let to_box = pose_ab.inverse();
        let seg = a.segment();
        Self {
            p0: to_box.transform_point(seg.a),
            p1: to_box.transform_point(seg.b),
            half: b.half_extents,
            radius: a.radius,
        }
    }

    /// The largest coordinate of the pair plus the radius, metres.
    fn scale(&self) -> f64 {
        self.half
            .max_element()
            .max(self.p0.abs().max_element())
            .max(self.p1.abs().max_element())
            + self.radius
    }

    /// The rounding allowance of an answer, metres.
    fn slack(&self) -> f64 {
        query::BOUND_ULPS * f64::EPSILON * self.scale()
    }

    /// The separating-axis test over the box faces and the segment × box edge axes
    /// (near-parallel cross axes skipped, as [`AXIS_RELATIVE`] states).
    fn best_axis(&self) -> Axis {
        let (c, e, h) = (
            (self.p0 + self.p1) * 0.5,
            (self.p1 - self.p0) * 0.5,
            self.half,
        );
        let mut best = Axis {
            away: DVec3::X,
            separation: f64::NEG_INFINITY,
        };
        let mut offer = |u: DVec3, length: f64| {
            let s = (c.dot(u).abs() - e.dot(u).abs() - u.abs().dot(h)) / length;
            if s > best.separation {
                best.separation = s;
                best.away = if c.dot(u) >= 0.0 { u } else { -u } / length;
            }
        };
        for k in 0..3 {
            offer(DVec3::AXES[k], 1.0);
        }
        for k in 0..3 {
            let u = DVec3::AXES[k].cross(e);
            let length = u.length();
            if length > AXIS_RELATIVE * e.length() {
                offer(u, length);
            }
        }
        best
    }

    /// The bounds from the separating axes, A's frame: the separation minus the radius
    /// below; above, the depth itself when the box is solid (the axes are then every face
    /// normal of the cores' Minkowski difference) and the cores overlap, else one step of
    /// alternating projection from the box point nearest the segment's middle.
    fn bound_from_axes(&self, pose_ab: &Isometry) -> DistanceBound {
        let (p0, p1, h) = (self.p0, self.p1, self.half);
        let axis = self.best_axis();
        let slack = self.slack();
        let lower = axis.separation - self.radius - slack;
        let upper = if h.min_element() > 0.0 && axis.separation <= 0.0 {
            // The skipped near-parallel cross axes may change the depth by as much.
            let extent = 0.5 * p0.distance(p1) + h.max_element();
            lower + 2.0 * slack + AXIS_RELATIVE * 2.0 * extent
        } else {
            let on_box = ((p0 + p1) * 0.5).clamp(-h, h);
            let on_segment = closest_point_segment(on_box, p0, p1);
            on_segment.distance(on_segment.clamp(-h, h)) - self.radius + slack
        };
        // A→B is from the segment towards the box; B's point farthest against it is the
        // corner on the segment's side.
        let normal = pose_ab.transform_vector(-axis.away);
        let point_b = pose_ab.transform_point(axis.away.signum() * h);
        DistanceBound::new(lower, upper, normal, point_b)
    }

    /// The exact answer, A's frame, when the cores are apart by more than rounding; `None`
    /// when they meet or nearly do ([`Self::overlapping`] or the shared engine then finds
    /// the depth and its normal).
    ///
    /// The squared distance from the segment's point `p(t) = p₀ + t·d` to the box is convex
    /// and differentiable in `t`, with slope `2 d · (p(t) − clamp(p(t)))`: continuous,
    /// non-decreasing and linear between the (at most 6) parameters where the segment crosses
    /// a face plane. The closest point is where the slope changes sign: at an end, or found
    /// exactly by linear interpolation between the two crossing parameters around the sign
    /// change. PERF: no feature enumeration, no branches on the box's features.
    fn apart(&self, pose_ab: &Isometry) -> Option<ShapeDistance> {
        let on_segment = self.closest_point();
        let on_box = on_segment.clamp(-self.half, self.half);
        let gap = on_segment.distance(on_box);
        (gap > FEATURE_RELATIVE * self.scale()).then(|| {
            let normal = (on_box - on_segment) / gap;
            ShapeDistance {
                distance: gap - self.radius,
                point_a: pose_ab.transform_point(on_segment + normal * self.radius),
                point_b: pose_ab.transform_point(on_box),
                normal: pose_ab.transform_vector(normal),
            }
        })
    }

    /// The exact answer, A's frame, when the cores overlap and the box is solid (its axes
    /// are then complete, so their least overlap is the cores' penetration depth); `None`
    /// otherwise (the shared engine then decides). The witnesses are the closest points of
    /// the segment moved out along the axis by that overlap, where the cores touch, moved
    /// back. PERF: a quarter of the shared engine's cost (129 against 558 ns a pair,
    /// `narrow_phase` penetrating poses), which searches the features as well.
    fn overlapping(&self, pose_ab: &Isometry) -> Option<ShapeDistance> {
        let axis = self.best_axis();
        if !(self.half.min_element() > 0.0 && axis.separation <= 0.0) {
            return None;
        }
        let out = axis.away * -axis.separation;
        let touching = InBox {
            p0: self.p0 + out,
            p1: self.p1 + out,
            ..*self
        };
        let on_touching = touching.closest_point();
        let on_box = on_touching.clamp(-self.half, self.half);
        let normal = -axis.away;
        Some(ShapeDistance {
            distance: axis.separation - self.radius,
            point_a: pose_ab.transform_point(on_touching - out + normal * self.radius),
            point_b: pose_ab.transform_point(on_box),
            normal: pose_ab.transform_vector(normal),
        })
    }

    /// A point of the segment closest to the box (see [`Self::apart`]), box frame.
    fn closest_point(&self) -> DVec3 {
        self.p0 + (self.p1 - self.p0) * self.closest_parameter()
    }

    /// The segment parameter in `[0, 1]` of a point closest to the box (see [`Self::apart`]).
    fn closest_parameter(&self) -> f64 {
        let (p0, d, h) = (self.p0, self.p1 - self.p0, self.half);
        // Half the slope of the squared distance at `t`.
        let slope = |t: f64| {
            let p = p0 + d * t;
            d.dot(p - p.clamp(-h, h))
        };
        let (first, last) = (slope(0.0), slope(1.0));
        if first >= 0.0 {
            return 0.0;
        }
        if last <= 0.0 {
            return 1.0;
        }
        // The face-plane crossings inside the segment, in order, between its ends.
        let mut crossings = [0.0; 8];
        let mut n = 1;
        for k in 0..3 {
            if d[k] != 0.0 {
                for plane in [-h[k], h[k]] {
                    let t = (plane - p0[k]) / d[k];
                    if t > 0.0 && t < 1.0 {
                        crossings[n] = t;
                        n += 1;
                    }
                }
            }
        }
        crossings[n] = 1.0;
        let crossings = &mut crossings[..=n];
        crossings.sort_unstable_by(f64::total_cmp);
        // The slope is negative at the first crossing and positive at the last.
        let (mut t0, mut s0) = (0.0, first);
        for &t1 in &crossings[1..] {
            let s1 = if t1 == 1.0 { last } else { slope(t1) };
            if s1 >= 0.0 {
                return t0 + (t1 - t0) * (-s0 / (s1 - s0));
            }
            (t0, s0) = (t1, s1);
        }
        1.0
    }
}

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab`: at most 4
/// points on both surfaces with one normal A→B, A's frame; empty when apart.
pub fn manifold_capsule_cuboid(a: &Capsule, b: &Cuboid, pose_ab: &Isometry, out: &mut Manifold) {
    clip::manifold(
        &PlacedCore::capsule(a, &Isometry::IDENTITY),
        &PlacedCore::cuboid(b, pose_ab),
        out,
    );
}

/// [`manifold_capsule_cuboid`] from the pair's signed distance `d` (this file's `distance_…`,
/// A's frame), which the dispatcher has already: the manifold is clipped along `d`'s
/// normal without the separating axes and closest points again. PERF: the settling pile's
/// touching pairs (`benches/pile.rs`) spent 7× their distance's time in the manifold.
pub fn manifold_capsule_cuboid_from(
    a: &Capsule,
    b: &Cuboid,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    clip::manifold_from_distance(
        &PlacedCore::capsule(a, &Isometry::IDENTITY),
        &PlacedCore::cuboid(b, pose_ab),
        d,
        out,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DMat3, DVec3};
    use crate::narrow::pairs::check;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    /// The closed form against a golden-section search of the convex distance along the
    /// segment, on segments whose end coordinates snap to quarters of the half extents
    /// (parallel to faces, on face planes, through edges and corners) or fall anywhere.
    #[test]
    fn the_closest_parameter_matches_a_search_of_the_convex_distance() {
        let mut r = rng(41);
        let half = DVec3::new(0.5, 0.75, 1.0);
        let point = |r: &mut TestRng| {
            if r.random_bool(0.5) {
                let quarter =
                    |k: usize, r: &mut TestRng| half[k] * f64::from(r.random_range(-8..=8)) / 4.0;
                DVec3::new(quarter(0, r), quarter(1, r), quarter(2, r))
            } else {
                point_in_cube(r, 2.5)
            }
        };
        let (mut at_an_end, mut inside, mut meeting) = (0, 0, 0);
        for case in 0..5000 {
            let (p0, p1) = (point(&mut r), point(&mut r));
            let placed = InBox {
                p0,
                p1,
                half,
                radius: 0.0,
            };
            let at = |t: f64| {
                let p = p0 + (p1 - p0) * t;
                p.distance(p.clamp(-half, half))
            };
            let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
            for _ in 0..200 {
                let (m1, m2) = (lo + (hi - lo) * 0.382, lo + (hi - lo) * 0.618);
                if at(m1) <= at(m2) {
                    hi = m2;
                } else {
                    lo = m1;
                }
            }
            let want = at(lo).min(at(0.0)).min(at(1.0));
            let t = placed.closest_parameter();
            assert!(
                (0.0..=1.0).contains(&t) && (at(t) - want).abs() <= 1e-12,
                "case {case}: {p0} {p1}: t {t} gives {}, search {want}",
                at(t)
            );
            if want == 0.0 {
                meeting += 1;
            } else if t == 0.0 || t == 1.0 {
                at_an_end += 1;
            } else {
                inside += 1;
            }
        }
        eprintln!("{at_an_end} at an end, {inside} inside, {meeting} meeting");
        assert!(
            at_an_end > 500 && inside > 500 && meeting > 500,
            "{at_an_end} at an end, {inside} inside, {meeting} meeting"
        );
    }

    #[test]
    fn a_capsule_lying_on_a_box_gives_two_points() {
        let c = Capsule::new(1.0, 0.5);
        let b = Cuboid::new(DVec3::new(2.0, 2.0, 1.0));
        // Box below the capsule, the capsule's core along the box's top face (X axis).
        let rot = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let pose = Isometry::new(rot, DVec3::new(0.0, 0.0, -1.4)).inverse();
        let d = distance_capsule_cuboid(&c, &b, &pose);
        assert!((d.distance + 0.1).abs() < 1e-14, "{d:?}");
        check::contract(&d, 1e-14);
        let mut m = Manifold::new();
        manifold_capsule_cuboid(&c, &b, &pose, &mut m);
        check::manifold(&m, 2, 1e-14);
    }

    #[test]
    fn a_core_through_the_box_uses_the_separating_axes() {
        let c = Capsule::new(3.0, 0.5);
        let b = Cuboid::new(DVec3::new(1.0, 2.0, 1.0));
        let pose = Isometry::from_translation(DVec3::new(0.25, 0.0, 0.0));
        let d = distance_capsule_cuboid(&c, &b, &pose);
        // Box spans x ∈ [-0.75, 1.25]: pushing it 0.75 along +X clears the core; plus the
        // radius.
        assert!((d.distance + 1.25).abs() < 1e-14, "{d:?}");
        assert!(d.normal.abs_diff_eq(DVec3::X, 1e-15));
        check::contract(&d, 1e-14);
    }
}
