//! Separations kept between frames: a mesh pair proven farther apart than its margins stays
//! proven, with no traversal, while the relative motion since the proof has moved no point
//! of one body, relative to the other, by more than the slack of the proof.
//!
//! Why it holds: for any point `x` of A and `y` of B, `|x − y_now| ≥ |x − y_then| −
//! |y_now − y_then|`, so the distance now is at least the distance then less the largest
//! displacement of a point of B in A's frame ([`relative_drift`]). The answer it gives
//! ("apart") is the exact answer of a query that does not ask the distance, so frames that
//! use it are as exact as frames that traverse.

use super::{PipelineWorkspace, Query, body, mesh_pair};
use crate::budget::Budget;
use crate::math::{DVec3, Pose, conservative_slack};
use crate::scene::{Body, Scene, ShapeId};

/// A proof that two shapes were at least `lower_bound` metres apart at relative pose
/// `pose_ab` (B's frame in A's), in one scene.
#[derive(Debug, Clone, Copy)]
pub(super) struct Separation {
    scene: u64,
    shapes: [ShapeId; 2],
    pose_ab: Pose,
    lower_bound: f64,
}

impl Separation {
    /// The proof that bodies `a` and `b` of `scene`, at their current poses, are at least
    /// `lower_bound` metres apart (a true lower bound, rounding included).
    pub fn new(scene: &Scene, (a, b): (&Body, &Body), lower_bound: f64) -> Self {
        Self {
            scene: scene.uid(),
            shapes: [a.shape, b.shape],
            pose_ab: Pose::relative(&a.pose, &b.pose),
            lower_bound,
        }
    }

    /// A lower bound of the distance between `a` and `b` now, metres: the proof's bound less
    /// the [`relative_drift`] since; `None` when the proof was about other shapes or
    /// another scene (the pair's ids were reused).
    pub fn lower_bound_now(&self, scene: &Scene, (a, b): (&Body, &Body)) -> Option<f64> {
        if self.scene != scene.uid() || self.shapes != [a.shape, b.shape] {
            return None;
        }
        let now = Pose::relative(&a.pose, &b.pose);
        let drift = relative_drift(&self.pose_ab, &now, scene.reach(a), scene.reach(b));
        Some(self.lower_bound - drift)
    }
}

/// The largest distance any point of one body can have moved relative to the other between
/// relative poses `then` and `now` (B's frame in A's), metres, for bodies whose points lie
/// within `reach_a` and `reach_b` of their local origins: the smaller of the two views'
/// bounds, padded for rounding.
///
/// Seen from A, a point `y` of B moves from `R₀y + t₀` to `R₁y + t₁`, by at most
/// `|t₁ − t₀| + ‖R₁ − R₀‖·reach_b`, where `‖R₁ − R₀‖ = 2 sin(θ/2)` for `θ` the angle of
/// `R₁R₀ᵀ` (`sin(θ/2)` is the length of the vector part of the unit quaternion `q₁q₀⁻¹`).
/// Seen from B, a point of A moves by at most `|R₁ᵀt₁ − R₀ᵀt₀| + 2 sin(θ/2)·reach_a`.
#[must_use]
pub(super) fn relative_drift(then: &Pose, now: &Pose, reach_a: f64, reach_b: f64) -> f64 {
    let turn = now.rotation * then.rotation.conjugate();
    let chord = 2.0 * DVec3::new(turn.x, turn.y, turn.z).length() / turn.length();
    let seen_from_a = (now.position - then.position).length() + chord * reach_b;
    let seen_from_b = (now.rotation.conjugate() * now.position
        - then.rotation.conjugate() * then.position)
        .length()
        + chord * reach_a;
    let scale = then.position.length() + now.position.length() + reach_a + reach_b;
    seen_from_a.min(seen_from_b) + 4.0 * conservative_slack(scale)
}

/// Marks in `workspace.separated` the candidates answered "apart" with no traversal:
/// mesh–mesh pairs no kept answer covers, under a query that does not ask the distance,
/// whose separation's bound, less the relative motion since, still exceeds their margins,
/// or, failing that, whose meshes' hulls are apart by more than the margins (a new
/// separation; module docs, "Separations proved by the hulls"). Hull tests stop once
/// `budget` (a budgeted frame's frontier budget) refuses the tests made so far. Returns
/// how many it made. Forgets the separations and hull memories of pairs that are no
/// longer candidates.
pub(super) fn mark_separated(
    scene: &Scene,
    query: Query,
    mut budget: Option<&mut dyn Budget>,
    workspace: &mut PipelineWorkspace,
) -> u64 {
    let PipelineWorkspace {
        candidates,
        memory,
        separated,
        ..
    } = workspace;
    let (mut tests, mut refused) = (0u64, false);
    separated.clear();
    if query.distance || !scene.has_mesh_shapes() {
        separated.resize(candidates.len(), false);
        return 0;
    }
    separated.extend(candidates.iter().map(|pair| {
        // Only mesh pairs have separations and hulls: any other pair is done without a
        // look-up of its memory (a pile of primitives pays nothing here).
        let Some((ma, mb)) = mesh_pair(scene, pair) else {
            return false;
        };
        let (a, b) = (body(scene, pair.a), body(scene, pair.b));
        if memory.kept_answer(scene, pair, query).is_some() {
            return false;
        }
        let margins = a.margin + b.margin;
        if let Some(separation) = memory.get(pair).and_then(|m| m.separation.as_ref())
            && separation
                .lower_bound_now(scene, (a, b))
                .is_some_and(|bound| bound > margins)
        {
            return true;
        }
        let (Some(ha), Some(hb)) = (&ma.hull, &mb.hull) else {
            return false;
        };
        let pose = Pose::relative(&a.pose, &b.pose);
        let kept = memory.entry(pair);
        let cache = &mut kept.hull;
        if cache.met_at == Some(pose) {
            // Tested at this very pose (a resting pair, a resumed frame): no proof.
            return false;
        }
        if let Some(budget) = budget.as_deref_mut()
            && (refused || (tests % HULL_TESTS_PER_POLL == 0 && !budget.allows(tests)))
        {
            refused = true;
            return false;
        }
        tests += 1;
        match ha.gap(hb, &pose.to_isometry(), &mut cache.gjk) {
            Some(gap) if gap > margins => {
                cache.met_at = None;
                kept.separation = Some(Separation::new(scene, (a, b), gap));
                true
            }
            _ => {
                cache.met_at = Some(pose);
                false
            }
        }
    }));
    tests
}

/// Hull tests between two polls of a budgeted frame's budget (a test costs 0.2–1 µs).
const HULL_TESTS_PER_POLL: u64 = 2;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DQuat;
    use crate::test_support::{TestRng, point_in_cube, rng};
    use rand::Rng;

    /// A pose within `half` of the origin, turned by up to `max_angle` about a random axis.
    fn pose(rng: &mut TestRng, half: f64, max_angle: f64) -> Pose {
        let axis = point_in_cube(rng, 1.0).normalize_or(DVec3::Z);
        let angle = rng.random_range(0.0..max_angle);
        Pose::new(
            point_in_cube(rng, half),
            DQuat::from_axis_angle(axis, angle),
        )
    }

    /// A point within `reach` of the origin, on the sphere of that radius half of the time
    /// (where the bound is reached).
    fn point_within(rng: &mut TestRng, reach: f64) -> DVec3 {
        let v = point_in_cube(rng, 1.0).clamp_length_max(1.0);
        reach
            * if rng.random_bool(0.5) {
                v.normalize_or(DVec3::X)
            } else {
                v
            }
    }

    /// The distance between any point of A and any point of B (within their reaches)
    /// shrinks by at most the drift, over random relative motions small and large; and the
    /// bound is not loose: in most cases some sampled point pair shrinks by half of it.
    #[test]
    fn no_two_points_come_closer_than_the_drift_allows() {
        let mut rng = rng(7);
        let mut tight = 0;
        for case in 0..3000 {
            let (reach_a, reach_b) = (rng.random_range(0.0..2.0), rng.random_range(0.0..2.0));
            let then = pose(&mut rng, 3.0, 3.0);
            let (half, angle) = if case % 2 == 0 {
                (0.05, 0.05)
            } else {
                (1.0, 3.0)
            };
            let now = then.compose(&pose(&mut rng, half, angle));
            let drift = relative_drift(&then, &now, reach_a, reach_b);
            let mut largest: f64 = 0.0;
            for _ in 0..200 {
                // A point of A (A's frame) and one of B (B's frame).
                let (x, y) = (
                    point_within(&mut rng, reach_a),
                    point_within(&mut rng, reach_b),
                );
                let shrink =
                    (x - then.transform_point(y)).length() - (x - now.transform_point(y)).length();
                assert!(shrink <= drift, "case {case}: {shrink} beyond {drift}");
                largest = largest.max(shrink);
            }
            tight += usize::from(largest >= 0.5 * drift);
        }
        assert!(
            tight > 1500,
            "only {tight} of 3000 cases within 2× of the bound"
        );
    }

    /// No motion, no drift (to the rounding pad).
    #[test]
    fn a_pair_that_did_not_move_relative_to_each_other_has_no_drift() {
        let mut rng = rng(3);
        for _ in 0..100 {
            let pose = pose(&mut rng, 5.0, 3.0);
            let drift = relative_drift(&pose, &pose, 1.0, 2.0);
            assert!((0.0..1e-9).contains(&drift), "{drift}");
        }
    }
}
