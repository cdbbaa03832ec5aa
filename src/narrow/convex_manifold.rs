//! Multi-point contact manifolds of any two convex shapes, from their signed distance.
//!
//! The pairs answered by GJK/EPA (cylinders, cones, convex hulls, against any convex shape)
//! get one normal and one deepest point from [`crate::narrow::gjk`]; a resting contact needs
//! the whole contact patch. [`manifold_convex_convex`] builds it from the pair's
//! [`ShapeDistance`] `d` (normal `n`, A→B), never running the distance query again.
//!
//! # Algorithm (Ericson, *Real-Time Collision Detection*, §8.3.4 (clipping);
//! Gregorius, *Robust Contact Creation for Physics Simulations*, GDC 2015)
//! 1. **Reference face**: A's face whose outward normal is closest to `n` and B's closest to
//!    `−n` ([`ContactFeatures::face_towards`]); one counts when its cosine with the normal is
//!    at least [`FACE_ALIGNMENT`] (about 0.8°, as the closed-form pairs); the better aligned
//!    is the reference (A on ties). None: see *Parallel lines* below, else the single
//!    point of `d` (edge–edge, point contacts).
//! 2. **Incident feature**: the other shape's feature out of which the reference normal
//!    points back ([`ContactFeatures::feature_towards`]): a polytope's best face, a
//!    cylinder's cap or side line, a cone's base or slant line, a capsule's segment, a
//!    sphere's centre. It is clipped (Sutherland–Hodgman) against the reference face's side
//!    planes, which contain the contact direction, so that moving a point along `n` never
//!    leaves the face.
//! 3. **Depth test**: each clipped core point is moved along `n` onto the incident surface
//!    (by the radius for a sphere; for a capsule's segment point, exactly where the ray
//!    leaves the capsule, which is the radius only when the segment is ⟂ `n`), then along
//!    `n` onto the reference face's plane; it is kept when it is at most
//!    [`CONTACT_SLACK_RELATIVE`] × the scale above that plane. Both points lie on the segment along `n`, so every kept point meets
//!    the contract of [`crate::narrow::contact`] (`point_b − point_a = distance · n`).
//! 4. **Deepest point**: when `d`'s witnesses are deeper than every kept point by more than
//!    the slack (a curved reference face's rim, a polytope vertex off the best incident
//!    face), they are added, so the deepest reported depth is `d.distance`. Nothing kept: the
//!    single point of `d`.
//! 5. **Reduction** to [`MANIFOLD_POINTS`](crate::narrow::contact::MANIFOLD_POINTS) by
//!    [`Manifold::push_reduced`]: the deepest, the farthest from it, the one spanning the
//!    largest triangle with those, the one adding the most area outside it.
//!
//! The manifold's normal is `d.normal`, unchanged; apart shapes (`d.distance > 0`) get an
//! empty manifold with it.
//!
//! # Parallel lines
//! Without a reference face, two line features (a cylinder's side, a capsule's segment, a
//! cone's slant) ⟂ `n` and parallel within [`LINE_PARALLEL`] (a pipe lying on a pipe)
//! touch along a segment: the overlap of the two lines, its ends pulled in by the drift of
//! a depth-long column along lines not exactly ⟂ `n` (so no column slips past a line's
//! end), gives up to two points. Each is the pair on one column along `n`: one shape's
//! surface point, and the other's extreme towards it on that column
//! ([`ContactFeatures::column_top`], answered by cylinders and capsules; two cones' slants
//! get the single point).
//!
//! # Tolerances
//! - [`FACE_ALIGNMENT`]: the closed forms' value, so a box given as a hull gets the same
//!   manifold as the box.
//! - [`CONTACT_SLACK_RELATIVE`] = 1e-9: EPA's normal is accurate to its relative tolerance
//!   (1e-10), so points of a face lying flat on another are at the same depth to about
//!   1e-10 × size; ten times that keeps them all without keeping points measurably above.
//! - [`LINE_PARALLEL`] = 1e-2, as the closed forms' parallel edges; the columns make the
//!   points exact whatever the angle, and the depth test drops the ends that do not touch.

mod features;

pub use features::{ContactFeatures, DISC_POINTS, FEATURE_POINTS, Polygon};

use crate::math::{DVec3, Isometry};
use crate::narrow::contact::{Manifold, ManifoldPoint, ShapeDistance};

/// Cosine between a face's normal and the contact normal above which the face is a
/// reference face (about 0.8°), as in the closed-form pairs.
pub const FACE_ALIGNMENT: f64 = 0.9999;

/// How far above the reference plane (times the scale of the coordinates) a clipped point
/// may lie and still be a contact point (module docs).
pub const CONTACT_SLACK_RELATIVE: f64 = 1e-9;

/// Sine of the angle under which two line features count as parallel, and a line as ⟂
/// the normal (about 0.6°, as the closed-form pairs' edges).
pub const LINE_PARALLEL: f64 = 1e-2;

/// Candidate points: every clipped vertex plus the witness.
const CANDIDATES: usize = 2 * FEATURE_POINTS + 1;

/// Fills `out` with the contact manifold of `a` and `b` placed by `pose_ab` (B's frame in
/// A's), A's frame, from their signed distance `d` (the [`crate::narrow::contact`]
/// contract, A's frame): at most [`MANIFOLD_POINTS`](crate::narrow::contact::MANIFOLD_POINTS) points with normal `d.normal`, each
/// `≤ 0` deep to the slack, the deepest at `d.distance`; empty when `d.distance > 0`.
///
/// # Allocation
/// None (fixed-capacity buffers on the stack; [`manifold_convex_convex_in`] reuses a
/// [`ManifoldScratch`] instead).
pub fn manifold_convex_convex<A: ContactFeatures + ?Sized, B: ContactFeatures + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    out: &mut Manifold,
) {
    manifold_convex_convex_in(a, b, pose_ab, d, &mut ManifoldScratch::new(), out);
}

/// The buffers of [`manifold_convex_convex_in`]: five polygons and the candidate points,
/// about 22 KB, kept by the caller so that no query fills them anew.
#[derive(Clone)]
pub struct ManifoldScratch {
    face_a: Polygon,
    face_b: Polygon,
    incident: Polygon,
    clip: [Polygon; 2],
    cands: Candidates,
}

impl ManifoldScratch {
    /// Empty buffers.
    #[must_use]
    pub fn new() -> Self {
        Self {
            face_a: Polygon::new(),
            face_b: Polygon::new(),
            incident: Polygon::new(),
            clip: [Polygon::new(), Polygon::new()],
            cands: Candidates::new(),
        }
    }
}

impl Default for ManifoldScratch {
    fn default() -> Self {
        Self::new()
    }
}

impl std::fmt::Debug for ManifoldScratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ManifoldScratch").finish_non_exhaustive()
    }
}

/// [`manifold_convex_convex`] with its buffers in `scratch`: the same manifold.
///
/// # Allocation
/// None.
// PERF: the buffers are 22 KB; filling them with zeros on every call was a fifth of a
// box–cylinder manifold (`benches/pile.rs`).
pub fn manifold_convex_convex_in<A: ContactFeatures + ?Sized, B: ContactFeatures + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    scratch: &mut ManifoldScratch,
    out: &mut Manifold,
) {
    let n = d.normal;
    out.reset(n);
    if d.distance > 0.0 {
        return;
    }
    let ManifoldScratch {
        face_a,
        face_b,
        incident,
        clip,
        cands,
    } = scratch;
    cands.clear();
    let fa = a.face_towards(n, face_a);
    let fb = b
        .face_towards(pose_ab.inverse_transform_vector(-n), face_b)
        .map(|f| pose_ab.transform_vector(f));
    for p in face_b.points_mut() {
        *p = pose_ab.transform_point(*p);
    }
    let scale = [d.point_a, d.point_b]
        .iter()
        .chain(face_a.points())
        .chain(face_b.points())
        .fold(d.distance.abs(), |s, p| s.max(p.abs().max_element()));
    let slack = CONTACT_SLACK_RELATIVE * scale;
    let cos_a = fa.filter(|_| has_area(face_a, scale)).map(|f| f.dot(n));
    let cos_b = fb.filter(|_| has_area(face_b, scale)).map(|f| -f.dot(n));
    let use_a = match (cos_a, cos_b) {
        (Some(ca), Some(cb)) if ca >= FACE_ALIGNMENT || cb >= FACE_ALIGNMENT => Some(ca >= cb),
        (Some(ca), None) if ca >= FACE_ALIGNMENT => Some(true),
        (None, Some(cb)) if cb >= FACE_ALIGNMENT => Some(false),
        _ => None,
    };
    match use_a {
        Some(true) => {
            let f = fa.unwrap_or(n);
            b.feature_towards(pose_ab.inverse_transform_vector(-f), incident);
            for p in incident.points_mut() {
                *p = pose_ab.transform_point(*p);
            }
            let reference = Reference {
                outline: face_a,
                normal: f,
                towards: n,
            };
            let to_surface = |c: DVec3| {
                let local = pose_ab.inverse_transform_point(c);
                let v = pose_ab.inverse_transform_vector(-n);
                pose_ab.transform_point(b.surface_along(local, v))
            };
            reference.clip(incident, &to_surface, true, slack, clip, cands);
        }
        Some(false) => {
            let f = fb.unwrap_or(-n);
            a.feature_towards(-f, incident);
            let reference = Reference {
                outline: face_b,
                normal: f,
                towards: -n,
            };
            reference.clip(
                incident,
                &|c| a.surface_along(c, n),
                false,
                slack,
                clip,
                cands,
            );
        }
        None => {
            let [la, lb] = clip;
            parallel_lines(a, b, pose_ab, d, slack, [la, lb, face_a, face_b], cands);
        }
    }
    let deepest = cands
        .points()
        .iter()
        .map(|p| p.distance)
        .fold(f64::INFINITY, f64::min);
    if d.distance < deepest - slack {
        cands.push(ManifoldPoint {
            point_a: d.point_a,
            point_b: d.point_b,
            distance: d.distance,
        });
    }
    out.push_reduced(cands.points());
}

/// Two line features (a cylinder's side, a capsule's segment, a cone's slant) ⟂ `n` and
/// parallel within [`LINE_PARALLEL`]: B's line clipped to A's extent along it, each end
/// giving the two surface points on the column through it along `n`; one of the shapes must
/// answer [`ContactFeatures::column_top`] (a cylinder or a capsule). Else nothing.
fn parallel_lines<A: ContactFeatures + ?Sized, B: ContactFeatures + ?Sized>(
    a: &A,
    b: &B,
    pose_ab: &Isometry,
    d: &ShapeDistance,
    slack: f64,
    [la, lb, next, seg]: [&mut Polygon; 4],
    out: &mut Candidates,
) {
    let n = d.normal;
    a.feature_towards(n, la);
    b.feature_towards(pose_ab.inverse_transform_vector(-n), lb);
    for p in lb.points_mut() {
        *p = pose_ab.transform_point(*p);
    }
    let ([a0, a1], [b0, b1]) = (la.points(), lb.points()) else {
        return;
    };
    let (da, db) = (*a1 - *a0, *b1 - *b0);
    let (len_a, len_b) = (da.length(), db.length());
    if len_a == 0.0
        || len_b == 0.0
        || da.dot(n).abs() > LINE_PARALLEL * len_a
        || db.dot(n).abs() > LINE_PARALLEL * len_b
        || da.cross(db).length() > LINE_PARALLEL * len_a * len_b
    {
        return;
    }
    let u = da / len_a;
    // The overlap of both lines along u. A column (along n, at most the depth long)
    // drifts along a line not exactly ⟂ n or not exactly parallel to the other: the
    // overlap's ends are pulled in by that drift (and rounding), so no column leaves a
    // line's end, where the side surface stops.
    let tilt =
        da.dot(n).abs() / len_a + db.dot(n).abs() / len_b + da.cross(db).length() / (len_a * len_b);
    let drift = (d.distance.abs() + slack) * tilt + slack;
    let (lo, hi) = (
        a0.dot(u).min(a1.dot(u)).max(b0.dot(u).min(b1.dot(u))) + drift,
        a0.dot(u).max(a1.dot(u)).min(b0.dot(u).max(b1.dot(u))) - drift,
    );
    if lo > hi {
        return;
    }
    lb.clip_plane_into(u, hi, next);
    next.clip_plane_into(-u, -lo, seg);
    // Either B's surface point at q and A's extreme towards B in its column, or (when A
    // answers no column) A's surface point at q's place along A's line and B's extreme
    // towards A in its column.
    let b_local = |p: DVec3| pose_ab.inverse_transform_point(p);
    let towards_a = pose_ab.inverse_transform_vector(-n);
    for q in seg.points() {
        let pair = if a.has_columns() {
            let pb = pose_ab.transform_point(b.surface_along(b_local(*q), towards_a));
            a.column_top(pb, n).map(|s| (pb + n * s, pb))
        } else if b.has_columns() {
            let pa = a.surface_along(*a0 + u * (*q - *a0).dot(u), n);
            b.column_top(b_local(pa), towards_a)
                .map(|s| (pa, pa - n * s))
        } else {
            None
        };
        let Some((point_a, point_b)) = pair else {
            continue;
        };
        let distance = (point_b - point_a).dot(n);
        if distance <= slack {
            out.push(ManifoldPoint {
                point_a,
                point_b,
                distance,
            });
        }
    }
}

/// Whether a face outline has an area above rounding (a zero-size box's face, a cap of
/// radius 0 does not, and cannot bound a clip).
fn has_area(outline: &Polygon, scale: f64) -> bool {
    let pts = outline.points();
    if pts.len() < 3 {
        return false;
    }
    let twice: DVec3 = (0..pts.len())
        .map(|i| (pts[i] - pts[0]).cross(pts[(i + 1) % pts.len()] - pts[0]))
        .sum();
    twice.length() > CONTACT_SLACK_RELATIVE * scale * scale
}

/// A reference face in A's frame.
struct Reference<'p> {
    /// Its outline.
    outline: &'p Polygon,
    /// Its outward unit normal.
    normal: DVec3,
    /// The contact direction from the reference shape to the incident one (`n` when the
    /// reference is A's, `−n` when B's), within [`FACE_ALIGNMENT`] of `normal`.
    towards: DVec3,
}

impl Reference<'_> {
    /// Clips the incident core feature against the side planes and adds the points at most
    /// `slack` above the face (module docs, steps 2–3); `to_surface` takes a core point to
    /// the incident surface along `−towards`.
    fn clip(
        &self,
        incident: &Polygon,
        to_surface: &dyn Fn(DVec3) -> DVec3,
        reference_is_a: bool,
        slack: f64,
        buffers: &mut [Polygon; 2],
        out: &mut Candidates,
    ) {
        let (f, m) = (self.normal, self.towards);
        let ref_pts = self.outline.points();
        let centroid = ref_pts.iter().copied().sum::<DVec3>() / ref_pts.len() as f64;
        let offset = ref_pts
            .iter()
            .map(|p| f.dot(*p))
            .fold(f64::NEG_INFINITY, f64::max);
        // PERF: the two buffers are swapped by reference (`benches/pile.rs`): a polygon is
        // 3 KB, and swapping the values once per side plane was most of a cylinder cap's
        // clip.
        let mut clipped = None;
        for i in 0..ref_pts.len() {
            let (p, q) = (ref_pts[i], ref_pts[(i + 1) % ref_pts.len()]);
            let mut side = (q - p).cross(m);
            if side.dot(centroid - p) > 0.0 {
                side = -side;
            }
            if side.length_squared() > 0.0 {
                let [first, second] = &mut *buffers;
                let (from, to) = match clipped {
                    None => (incident, first),
                    Some(0) => (&*first, second),
                    Some(_) => (&*second, first),
                };
                from.clip_plane_into(side, side.dot(p), to);
                clipped = Some(match clipped {
                    Some(0) => 1,
                    _ => 0,
                });
            }
        }
        let inc = match clipped {
            None => incident,
            Some(k) => &buffers[k],
        };
        let along = f.dot(m);
        for core in inc.points() {
            let on_incident = to_surface(*core);
            let t = (f.dot(on_incident) - offset) / along;
            if t > slack || t.is_nan() {
                continue;
            }
            let on_reference = on_incident - m * t;
            let (point_a, point_b) = if reference_is_a {
                (on_reference, on_incident)
            } else {
                (on_incident, on_reference)
            };
            out.push(ManifoldPoint {
                point_a,
                point_b,
                distance: t,
            });
        }
    }
}

/// Candidate contact points before reduction (fixed capacity).
#[derive(Clone)]
struct Candidates {
    pts: [ManifoldPoint; CANDIDATES],
    len: usize,
}

impl Candidates {
    fn new() -> Self {
        Self {
            pts: [ManifoldPoint {
                point_a: DVec3::ZERO,
                point_b: DVec3::ZERO,
                distance: 0.0,
            }; CANDIDATES],
            len: 0,
        }
    }

    fn clear(&mut self) {
        self.len = 0;
    }

    fn push(&mut self, p: ManifoldPoint) {
        if self.len < CANDIDATES {
            self.pts[self.len] = p;
            self.len += 1;
        }
    }

    fn points(&self) -> &[ManifoldPoint] {
        &self.pts[..self.len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_a_square_by_a_plane_keeps_the_inner_half() {
        let mut sq = Polygon::new();
        for p in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            sq.push(DVec3::new(p.0, p.1, 0.0));
        }
        let mut out = Polygon::new();
        sq.clip_plane_into(DVec3::X, 0.0, &mut out);
        assert_eq!(out.len(), 4);
        assert!(out.points().iter().all(|p| p.x <= 0.0));
        sq.clip_plane_into(DVec3::X, -2.0, &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn reduction_keeps_the_deepest_point_first_and_drops_interior_points() {
        let mut pts = Vec::new();
        for i in 0..8u8 {
            let angle = f64::from(i) * std::f64::consts::FRAC_PI_4;
            let p = DVec3::new(angle.cos(), angle.sin(), 0.0);
            pts.push(ManifoldPoint {
                point_a: p,
                point_b: p,
                distance: if i == 5 { -0.3 } else { -0.1 },
            });
        }
        let mut m = Manifold::new();
        m.reset(DVec3::Z);
        m.push_reduced(&pts);
        assert_eq!(m.len(), 4);
        assert_eq!(m.points()[0].distance, -0.3);
        // A triangle with a point on an edge and one inside: no fourth point adds area.
        let line: Vec<ManifoldPoint> = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (0.0, 1.0), (0.5, 0.2)]
            .iter()
            .map(|&(x, y)| ManifoldPoint {
                point_a: DVec3::new(x, y, 0.0),
                point_b: DVec3::new(x, y, 0.0),
                distance: if x == 0.0 && y == 0.0 { -0.1 } else { 0.0 },
            })
            .collect();
        let mut m = Manifold::new();
        m.reset(DVec3::Z);
        m.push_reduced(&line);
        assert_eq!(m.len(), 3);
    }
}
