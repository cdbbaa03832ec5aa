//! A mesh pair proven apart stays proven while its relative motion is smaller than the
//! proof's slack (issue #7, "skip what the scene does not need"): frames that answer pairs
//! from kept separations are record for record the frames a fresh workspace computes by
//! traversal, under every query that does not ask the distance; a `DISTANCE` frame never
//! uses them; budgeted frames stay conservative (no truly close pair left out) while the
//! separations take pairs off their frontier.

#[path = "support/mod.rs"]
mod support;

use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::{MeshShape, Shape};
use proxima::pipeline::{FrameResults, PipelineWorkspace, Query, VisitBudget, step, step_within};
use proxima::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits};
use rand::Rng;
use std::collections::BTreeSet;
use std::sync::Arc;
use support::{meshes, point_in_cube, rng, rotation};

const FRAMES: usize = 240;
/// Half-size of the region the bodies drift in, metres.
const HALF: f64 = 1.6;

/// A body drifting on a straight line and turning steadily: a few millimetres and
/// milliradians per frame, as a fast control loop sees a moving scene.
struct Drifter {
    id: BodyId,
    start: Pose,
    velocity: DVec3,
    axis: DVec3,
    spin: f64,
}

impl Drifter {
    fn pose_at(&self, frame: usize) -> Pose {
        let t = frame as f64;
        // Bounce inside the region so that pairs keep meeting and parting.
        let p = self.start.position + self.velocity * t;
        let fold = |x: f64| {
            let period = 4.0 * HALF;
            let y = (x + HALF).rem_euclid(period);
            if y < 2.0 * HALF {
                y - HALF
            } else {
                3.0 * HALF - y
            }
        };
        Pose::new(
            DVec3::new(fold(p.x), fold(p.y), fold(p.z)),
            DQuat::from_axis_angle(self.axis, self.spin * t) * self.start.rotation,
        )
    }
}

fn scene_of_meshes(seed: u64) -> (Scene, Vec<Drifter>) {
    let mut rng = rng(seed);
    let mut scene = Scene::try_new(0.05, SceneLimits::STANDARD).unwrap();
    let torus = scene
        .register_shape(Shape::Mesh(Arc::new(MeshShape::new(meshes::torus(
            0.45, 0.12, 16, 8,
        )))))
        .unwrap();
    let ball = scene
        .register_shape(Shape::Mesh(Arc::new(MeshShape::new(meshes::uv_sphere(
            0.3, 12, 8,
        )))))
        .unwrap();
    let mut drifters = Vec::new();
    for i in 0..14 {
        let start = Pose::new(point_in_cube(&mut rng, HALF), rotation(&mut rng));
        let id = scene
            .add_body(&BodyDesc {
                shape: if i % 3 == 2 { ball } else { torus },
                pose: start,
                motion: Motion::Dynamic,
                filter: CollisionFilter::ALL,
                margin: Some(rng.random_range(0.02..0.08)),
            })
            .unwrap();
        drifters.push(Drifter {
            id,
            start,
            velocity: point_in_cube(&mut rng, 0.006),
            axis: point_in_cube(&mut rng, 1.0).normalize_or(DVec3::Z),
            spin: rng.random_range(0.0..0.01),
        });
    }
    (scene, drifters)
}

#[test]
fn frames_answered_from_kept_separations_equal_fresh_frames() {
    let queries = [
        Query::CLOSE,
        Query::CLOSE.union(Query::CONTACTS),
        Query::OVERLAP.union(Query::CONTACTS),
        Query::DISTANCE,
    ];
    let (mut separated_total, mut traversed_total, mut frames_with_both) = (0, 0, 0);
    let mut kept_total = 0;
    for (q, &query) in queries.iter().enumerate() {
        let (mut scene, drifters) = scene_of_meshes(0x5e9 + q as u64);
        let mut kept = PipelineWorkspace::default();
        let (mut got, mut want) = (FrameResults::default(), FrameResults::default());
        for frame in 0..FRAMES {
            for d in &drifters {
                scene.set_pose(d.id, d.pose_at(frame)).unwrap();
            }
            let report = step(&scene, query, &mut kept, &mut got);
            let fresh = step(&scene, query, &mut PipelineWorkspace::default(), &mut want);
            same_answers(&got, &want, &format!("{query:?} frame {frame}"));
            // A fresh workspace keeps no separation: its pairs answered apart without a
            // traversal were proven so by their hulls, a test each.
            assert!(
                fresh.separated_pairs <= fresh.hull_tests,
                "{query:?} frame {frame}: {} separated, {} hull tests in a fresh workspace",
                fresh.separated_pairs,
                fresh.hull_tests
            );
            assert!(report.separated_pairs <= report.candidates);
            scene.end_frame();
            // Every candidate here is a mesh pair: each is answered by reuse, by a kept
            // separation or by a query on its path.
            let traversed = report.paths.mesh_mesh;
            assert_eq!(
                report.reused_pairs + report.separated_pairs + traversed,
                report.candidates,
                "{query:?} frame {frame}"
            );
            if query.distance {
                assert_eq!(report.separated_pairs, 0, "{query:?} frame {frame}");
                continue;
            }
            separated_total += report.separated_pairs;
            // At least this many were answered by a separation kept from an earlier frame.
            kept_total += report.separated_pairs.saturating_sub(report.hull_tests);
            traversed_total += traversed;
            frames_with_both += usize::from(report.separated_pairs > 0 && traversed > 0);
        }
    }
    assert!(
        separated_total > 1_000 && kept_total > 2_000 && traversed_total > 1_000,
        "{separated_total} separated ({kept_total} at least by kept separations), \
         {traversed_total} traversed"
    );
    assert!(frames_with_both > 300, "{frames_with_both}");
}

/// The same pairs with the same answers, to the records' error bounds, and the same
/// contacts. Witnesses may differ where several triangle pairs share the minimum
/// (intersecting meshes, at 0): a pair a separation answered skips its query, so the warm
/// start of its next query differs from the fresh workspace's.
fn same_answers(got: &FrameResults, want: &FrameResults, context: &str) {
    let key = |r: &FrameResults| r.pairs.iter().map(|p| (p.a, p.b)).collect::<Vec<_>>();
    assert_eq!(key(got), key(want), "{context}");
    for (g, w) in got.pairs.iter().zip(&want.pairs) {
        assert!(
            (g.distance - w.distance).abs() <= g.error_bound + w.error_bound,
            "{context}: {g:?} against {w:?}"
        );
        assert_eq!(
            (g.exact, g.contact_count, g.first_contact),
            (w.exact, w.contact_count, w.first_contact),
            "{context}"
        );
    }
    assert_eq!(got.contacts, want.contacts, "{context}");
}

/// Under a small counted budget, kept separations answer pairs before the frontier runs,
/// and the frame stays conservative: every pair truly within its margins (the exact frame)
/// is reported, and every pair reported exactly is reported by the exact frame too.
#[test]
fn budgeted_frames_with_kept_separations_stay_conservative() {
    let (mut scene, drifters) = scene_of_meshes(0xb0d);
    let mut budgeted = PipelineWorkspace::default();
    let mut exact_ws = PipelineWorkspace::default();
    let (mut got, mut exact) = (FrameResults::default(), FrameResults::default());
    let (mut separated_total, mut truncated_total, mut close_total) = (0, 0, 0);
    for frame in 0..FRAMES {
        for d in &drifters {
            scene.set_pose(d.id, d.pose_at(frame)).unwrap();
        }
        let report = step_within(
            &scene,
            Query::CLOSE,
            &mut VisitBudget(150),
            &mut budgeted,
            &mut got,
        );
        step(&scene, Query::CLOSE, &mut exact_ws, &mut exact);
        let reported: BTreeSet<(u32, u32)> = got.pairs.iter().map(|p| (p.a, p.b)).collect();
        let close: BTreeSet<(u32, u32)> = exact.pairs.iter().map(|p| (p.a, p.b)).collect();
        assert!(
            close.is_subset(&reported),
            "frame {frame}: close {close:?} not all in {reported:?}"
        );
        for p in got.pairs.iter().filter(|p| p.exact) {
            assert!(close.contains(&(p.a, p.b)), "frame {frame}: exact {p:?}");
        }
        separated_total += report.separated_pairs;
        truncated_total += report.truncated_pairs;
        close_total += close.len();
        scene.end_frame();
    }
    assert!(
        separated_total > 200 && truncated_total > 50 && close_total > 50,
        "{separated_total} separated, {truncated_total} truncated, {close_total} close"
    );
}
