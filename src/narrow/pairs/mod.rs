//! Closed-form pair queries between the primitives sphere, capsule, cuboid and triangle,
//! one file per pair in canonical order (STYLE.md §4).
//!
//! Each pair file gives, with B placed by `pose_ab` (B's frame in A's) and every answer in
//! A's frame, following the contract of [`crate::narrow::contact`]:
//! - `distance_X_Y(a, b, pose_ab) -> ShapeDistance`: exact signed distance (minus the
//!   penetration depth when they overlap), witnesses, unit normal A→B;
//! - `manifold_X_Y(a, b, pose_ab, &mut Manifold)`: up to 4 contact points with one normal
//!   A→B when they touch or overlap, empty when apart.
//!
//! All of them share one engine: every primitive is a convex polytope *core* swept by a ball
//! (a sphere a point, a capsule a segment, cuboid and triangle radius 0; `placed_core`); the
//! distance is the separating-axis test over the complete axis set of the two cores plus
//! closed-form vertex/edge closest points (`query`); manifolds clip an incident feature
//! against a reference face (`clip`). A ball, capsule or box apart from a triangle (the
//! convex–mesh walk's usual case) skips the axis test: its closest pair comes straight from
//! the features, certified by the separation along it (`triangle_apart`). Exact to
//! rounding, except the documented skip of near-parallel cross axes (`≤ 1e-12` × extent).
//!
//! Cylinders and hulls are not polytope cores; for them this module holds the proofs the
//! dispatcher tries before GJK/EPA, each answering exactly (to GJK's tolerance) or not at
//! all:
//! - `sphere_cylinder`: a closed form;
//! - `capsule_cylinder`: a certified search along the capsule's core while it stays out of
//!   the cylinder;
//! - `face_certificate`: a box's faces against any convex shape;
//! - `cylinder_certificate`: a cylinder's caps and side against any convex shape;
//! - `cylinder_rim`: a cylinder's rim apart from a box or a cylinder.
//!
//! # Degenerate input, documented choices
//! - Coincident sphere centres (and any pair whose cores touch in a point, segment or
//!   flat set with no defined direction): the normal is the first of `+X, +Y, +Z` of A's
//!   frame (or an edge direction crossed with one) that gives the least overlap — `+X` for
//!   two spheres.
//! - Zero-length capsules are spheres; zero-size boxes are points, segments or rectangles;
//!   zero-area triangles are the segment or point they span. None yields NaN.
//! - Triangles are two-sided and have no thickness.

mod box_face_depth;
mod clip;
mod placed_core;
mod query;
mod triangle_apart;

mod capsule_capsule;
mod capsule_cuboid;
mod capsule_cylinder;
mod capsule_triangle;
mod cuboid_cuboid;
mod cuboid_triangle;
mod cylinder_certificate;
mod cylinder_rim;
mod face_certificate;
mod sphere_capsule;
mod sphere_cuboid;
mod sphere_cylinder;
mod sphere_solid;
mod sphere_sphere;
mod sphere_triangle;

pub use capsule_capsule::{
    distance_bound_capsule_capsule, distance_capsule_capsule, manifold_capsule_capsule,
    manifold_capsule_capsule_from,
};
pub use capsule_cuboid::{
    distance_bound_capsule_cuboid, distance_capsule_cuboid, manifold_capsule_cuboid,
    manifold_capsule_cuboid_from,
};
pub use capsule_cylinder::distance_capsule_cylinder;
pub use capsule_triangle::{
    distance_capsule_triangle, manifold_capsule_triangle, manifold_capsule_triangle_from,
};
pub(crate) use cuboid_cuboid::distance_cuboid_cuboid_within;
pub use cuboid_cuboid::{
    distance_bound_cuboid_cuboid, distance_cuboid_cuboid, manifold_cuboid_cuboid,
};
pub use cuboid_triangle::{
    distance_cuboid_triangle, manifold_cuboid_triangle, manifold_cuboid_triangle_from,
};
pub use cylinder_certificate::certified_distance_cylinder_convex;
pub use cylinder_rim::{NearestPoint, certified_rim_distance};
pub use face_certificate::{FaceCertificate, face_distance_cuboid_convex};
pub use sphere_capsule::{distance_sphere_capsule, manifold_sphere_capsule};
pub use sphere_cuboid::{distance_sphere_cuboid, manifold_sphere_cuboid};
pub use sphere_cylinder::{distance_sphere_cylinder, manifold_sphere_cylinder};
pub use sphere_sphere::{distance_sphere_sphere, manifold_sphere_sphere};
pub use sphere_triangle::{distance_sphere_triangle, manifold_sphere_triangle};

/// Shared by the pair files' unit tests: checks the [`crate::narrow::contact`] contract.
#[cfg(test)]
pub(super) mod check {
    use crate::narrow::contact::{Manifold, ShapeDistance};

    /// Unit normal, `point_b − point_a = distance · normal`, no NaN.
    pub fn contract(d: &ShapeDistance, tol: f64) {
        assert!(d.distance.is_finite() && d.point_a.is_finite() && d.point_b.is_finite());
        assert!((d.normal.length() - 1.0).abs() < 1e-12, "{d:?}");
        let r = d.point_b - d.point_a - d.normal * d.distance;
        assert!(r.length() <= tol, "{d:?}: residual {r}");
    }

    /// Points count and every point's distance `≤ 0 + tol`.
    pub fn manifold(m: &Manifold, count: usize, tol: f64) {
        assert_eq!(m.len(), count, "{m:?}");
        for p in m.points() {
            assert!(p.distance <= tol, "{m:?}");
            let r = p.point_b - p.point_a - m.normal * p.distance;
            assert!(r.length() <= 1e-6 + tol, "{m:?}");
        }
    }
}
