//! A box against any convex shape given by its support map: the signed distance of a
//! contact under one face of the box, or of B over one, certified without GJK or EPA, or
//! nothing.
//!
//! # Certificate
//! Let B overlap box A, `n` be the outward normal of one of A's faces and `δ` B's overlap
//! of that face (the face's offset minus B's support value along `−n`). Moving B by `δ·n`
//! puts it beyond the face's plane, out of A: the depth is at most `δ`. A point `p` of B
//! inside A leaves A's interior under a translation `v` only when `|v| ≥ dist(p, ∂A)`, so
//! the depth is at least that. For `n` the face of least overlap and `p` B's deepest point
//! under it, when no other face of A is nearer to `p`, `dist(p, ∂A) = δ` and the depth is
//! exactly `δ`, along `n`: the lower bound EPA's polytope proves, here in six support calls
//! (the resting contacts of a pile: a cylinder or hull standing on the floor or on a box).
//! Otherwise (the deepest point nearer another face, as at edges and corners) there is no
//! answer, and the caller runs GJK/EPA (van den Bergen, *Collision Detection in Interactive
//! 3D Environments*, §4.3.4 on penetration depth as a minimum over directions).
//!
//! # Apart
//! When B lies entirely beyond one face's plane by a gap, the gap is a lower bound of the
//! distance. When B's nearest point to the plane is over the face (its foot on the plane
//! lies in the face), that foot is a point of A the gap away: the distance is exactly the
//! gap (a body hovering over the floor). Otherwise, a gap above `limit` is returned as a
//! bound (the separating axes of cuboid–cuboid do the same): `distance > limit` holds, the
//! value is not exact.
//!
//! # Rounding
//! `δ` and the distances to the other faces are differences of the same rounded coordinates
//! of `p`, so the comparison is exact for the computed `p`; `p` itself carries the rounding
//! of B's support map and pose, as every method's witnesses do.

use crate::geometry::{Cuboid, SupportMap};
use crate::math::{DVec3, Isometry};
use crate::narrow::contact::ShapeDistance;

/// What the face certificate of [`face_distance_cuboid_convex`] found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FaceCertificate {
    /// The exact signed distance (B overlaps A with the depth under one face, or is apart
    /// over one face).
    Exact(ShapeDistance),
    /// B is beyond a face's plane by more than the limit: `distance` is that gap, a lower
    /// bound; `point_b` is B's nearest point to the plane and `point_a` the box's closest
    /// point to it.
    Beyond(ShapeDistance),
    /// Neither: ask GJK/EPA.
    Unknown,
}

impl FaceCertificate {
    /// The same answer with `f` applied to its distance (an exact answer or a bound).
    #[must_use]
    pub fn map(self, f: impl FnOnce(ShapeDistance) -> ShapeDistance) -> Self {
        match self {
            Self::Exact(d) => Self::Exact(f(d)),
            Self::Beyond(d) => Self::Beyond(f(d)),
            Self::Unknown => Self::Unknown,
        }
    }
}

/// The signed distance from box `a` to the convex shape `b` (its support map, B's frame)
/// placed by `pose_ab`, A's frame, when B overlaps A under one face of A or lies over one
/// face (module docs); a lower bound when B is otherwise beyond a face's plane by more than
/// `limit` metres; else
/// [`FaceCertificate::Unknown`]. Six support calls of `b`; never NaN (non-finite input
/// gives `Unknown`).
#[must_use]
pub fn face_distance_cuboid_convex<S: SupportMap + ?Sized>(
    a: &Cuboid,
    b: &S,
    pose_ab: &Isometry,
    limit: f64,
) -> FaceCertificate {
    let h = a.half_extents;
    let to_b = pose_ab.rotation.transpose();
    // The face of least overlap: (overlap, axis, outward sign, B's deepest point).
    let mut least: Option<(f64, usize, f64, DVec3)> = None;
    for k in 0..3 {
        let axis_in_b = to_b.col(k);
        for sign in [1.0, -1.0] {
            let p = pose_ab.transform_point(b.support(axis_in_b * -sign));
            let overlap = h[k] - sign * p[k];
            if least.is_none_or(|(o, ..)| overlap < o) {
                least = Some((overlap, k, sign, p));
            }
        }
    }
    let Some((overlap, k, sign, p)) = least else {
        return FaceCertificate::Unknown;
    };
    let mut n = DVec3::ZERO;
    n[k] = sign;
    if overlap <= 0.0 {
        let gap = -overlap;
        // Over the face: its point under `p` is `gap` away, the plane's lower bound.
        let mut under = p;
        under[k] = sign * h[k];
        if under.abs().cmple(h).all() {
            return FaceCertificate::Exact(ShapeDistance {
                distance: gap,
                point_a: under,
                point_b: p,
                normal: n,
            });
        }
        if gap > limit {
            return FaceCertificate::Beyond(ShapeDistance {
                distance: gap,
                point_a: p.clamp(-h, h),
                point_b: p,
                normal: n,
            });
        }
        return FaceCertificate::Unknown;
    }
    // `room[k]` is `overlap` itself when `p` is on the face's side of the centre.
    let room = h - p.abs();
    if room.min_element() < overlap || !overlap.is_finite() {
        return FaceCertificate::Unknown;
    }
    FaceCertificate::Exact(ShapeDistance {
        distance: -overlap,
        point_a: p + n * overlap,
        point_b: p,
        normal: n,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Cylinder;
    use crate::math::DQuat;
    use crate::narrow::pairs::check;

    fn iso(rotation: DQuat, translation: DVec3) -> Isometry {
        Isometry {
            rotation: crate::math::DMat3::from_quat(rotation),
            translation,
        }
    }

    #[test]
    fn a_cylinder_standing_on_a_slab_sinks_by_its_overlap() {
        let slab = Cuboid::new(DVec3::new(1.0, 1.0, 0.1));
        let c = Cylinder::new(0.2, 0.1);
        let pose = iso(DQuat::IDENTITY, DVec3::new(0.3, -0.2, 0.1 + 0.2 - 1e-3));
        let FaceCertificate::Exact(d) = face_distance_cuboid_convex(&slab, &c, &pose, 0.0) else {
            panic!("a standing cylinder is certified");
        };
        assert!((d.distance + 1e-3).abs() < 1e-15, "{d:?}");
        assert_eq!(d.normal, DVec3::Z);
        check::contract(&d, 1e-15);
    }

    #[test]
    fn a_cylinder_on_the_slabs_corner_is_left_to_gjk() {
        let slab = Cuboid::new(DVec3::new(1.0, 1.0, 0.1));
        let c = Cylinder::new(0.2, 0.1);
        // Centre over the corner: the deepest point is nearer a side than the top.
        let pose = iso(DQuat::IDENTITY, DVec3::new(1.0, 1.0, 0.1 + 0.2 - 0.05));
        let answer = face_distance_cuboid_convex(&slab, &c, &pose, 0.0);
        assert_eq!(answer, FaceCertificate::Unknown);
    }

    #[test]
    fn a_cylinder_over_the_slab_is_exact_and_beside_it_beyond_a_small_limit_only() {
        let slab = Cuboid::new(DVec3::new(1.0, 1.0, 0.1));
        let c = Cylinder::new(0.2, 0.1);
        let over = iso(DQuat::IDENTITY, DVec3::new(0.5, 0.0, 0.1 + 0.2 + 0.05));
        let FaceCertificate::Exact(d) = face_distance_cuboid_convex(&slab, &c, &over, 0.01) else {
            panic!("a cylinder over the slab is certified");
        };
        assert!((d.distance - 0.05).abs() < 1e-15, "{d:?}");
        assert_eq!(d.normal, DVec3::Z);
        check::contract(&d, 1e-15);
        // Up and aside: the cap's nearest point is past the slab's edge.
        let beside = iso(DQuat::IDENTITY, DVec3::new(1.2, 0.0, 0.1 + 0.2 + 0.05));
        let FaceCertificate::Beyond(d) = face_distance_cuboid_convex(&slab, &c, &beside, 0.01)
        else {
            panic!("5 cm above is beyond 1 cm");
        };
        // The cap's rim is 0.1 m beyond the slab's side and 0.05 m above its top.
        let truth = (0.1_f64.powi(2) + 0.05_f64.powi(2)).sqrt();
        assert!(d.distance > 0.01 && d.distance <= truth, "{d:?}");
        let answer = face_distance_cuboid_convex(&slab, &c, &beside, 0.2);
        assert_eq!(answer, FaceCertificate::Unknown);
    }

    #[test]
    fn non_finite_poses_give_no_answer() {
        let slab = Cuboid::new(DVec3::ONE);
        let c = Cylinder::new(0.2, 0.1);
        let pose = iso(DQuat::IDENTITY, DVec3::splat(f64::NAN));
        let answer = face_distance_cuboid_convex(&slab, &c, &pose, 0.0);
        assert_eq!(answer, FaceCertificate::Unknown);
    }
}
