//! The pipeline's kept broad phase against a fresh workspace (a full rebuild) every frame.
//!
//! One seeded scene of spheres, boxes and capsules runs 600 frames of coherent motion with
//! teleports, poses re-sent unchanged, added and removed bodies (static ones too), bodies
//! re-filtered, turned static or dynamic and given another margin, frames where nothing
//! changes, changes made after a frame's step (before it ends), frames asking only `TOI`
//! (which do not sync the kept broad phase), and frames stepped twice with a body moved
//! between the two steps. One kept workspace per broad-phase choice, one whose choice
//! changes every 40 frames, and one of each fixed kind on a second scene interleaved with
//! the first (the workspace must notice the other scene): each answers exactly what a
//! fresh workspace answers, frame after frame, and re-reads exactly the bodies that
//! changed (checked against this test's own bookkeeping, not the scene's log). A second
//! scene of spheres sliding at set speeds checks the motion statistics the automatic
//! choice reads, and its pick, against the known motion.

#[path = "support/mod.rs"]
mod support;

use proxima::broad::select::CREEPING;
use proxima::broad::{BroadPhaseChoice, BroadPhaseKind, BroadPhaseStats, choose};
use proxima::geometry::{Capsule, Cuboid, Sphere};
use proxima::math::{DVec3, Pose};
use proxima::narrow::Shape;
use proxima::pipeline::{
    AUTO_REMEASURE_FRAMES, FrameResults, PipelineWorkspace, Query, StepReport, step,
};
use proxima::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits, ShapeId};
use rand::Rng;
use std::collections::BTreeSet;
use support::{TestRng, point_in_cube, rng, rotation};

const FRAMES: u64 = 600;

const CHOICES: [BroadPhaseChoice; 6] = [
    BroadPhaseChoice::Auto,
    BroadPhaseChoice::Fixed(BroadPhaseKind::SortAndSweep),
    BroadPhaseChoice::Fixed(BroadPhaseKind::IncrementalSap),
    BroadPhaseChoice::Fixed(BroadPhaseKind::HashGrid),
    BroadPhaseChoice::Fixed(BroadPhaseKind::ColumnGrid),
    BroadPhaseChoice::Fixed(BroadPhaseKind::SkinGrid),
];

/// The scene under test and this test's own record of what changed in the current frame.
struct World {
    scene: Scene,
    shapes: Vec<ShapeId>,
    live: Vec<BodyId>,
    changed: BTreeSet<u32>,
    spread: f64,
}

impl World {
    fn new(rng: &mut TestRng, spread: f64, bodies: usize) -> Self {
        let mut scene = Scene::try_new(0.05, SceneLimits::STANDARD).unwrap();
        let shapes = vec![
            scene
                .register_shape(Shape::Sphere(Sphere::new(0.4)))
                .unwrap(),
            scene
                .register_shape(Shape::Cuboid(Cuboid::new(DVec3::new(0.3, 0.5, 0.2))))
                .unwrap(),
            scene
                .register_shape(Shape::Capsule(Capsule::new(0.5, 0.2)))
                .unwrap(),
            // A big slab and a point-like ball: zero-ish and huge boxes.
            scene
                .register_shape(Shape::Cuboid(Cuboid::new(DVec3::new(4.0, 4.0, 0.2))))
                .unwrap(),
            scene
                .register_shape(Shape::Sphere(Sphere::new(0.0)))
                .unwrap(),
        ];
        let mut world = Self {
            scene,
            shapes,
            live: Vec::new(),
            changed: BTreeSet::new(),
            spread,
        };
        for _ in 0..bodies {
            world.add(rng);
        }
        world
    }

    fn filter(rng: &mut TestRng) -> CollisionFilter {
        if rng.random_range(0..3) == 0 {
            CollisionFilter {
                group: 1 << rng.random_range(0..3),
                mask: rng.random_range(1..8),
            }
        } else {
            CollisionFilter::ALL
        }
    }

    fn motion(rng: &mut TestRng) -> Motion {
        match rng.random_range(0..6) {
            0 => Motion::Static,
            1 => Motion::Kinematic,
            _ => Motion::Dynamic,
        }
    }

    fn add(&mut self, rng: &mut TestRng) {
        let shape = self.shapes[rng.random_range(0..self.shapes.len())];
        let desc = BodyDesc {
            shape,
            pose: Pose::new(point_in_cube(rng, self.spread), rotation(rng)),
            motion: Self::motion(rng),
            filter: Self::filter(rng),
            margin: (rng.random_range(0..2) == 0).then(|| rng.random_range(0.0..0.3)),
        };
        let id = self.scene.add_body(&desc).unwrap();
        self.live.push(id);
        self.changed.insert(id.0);
    }

    fn remove(&mut self, rng: &mut TestRng) {
        if self.live.is_empty() {
            return;
        }
        let id = self.live.swap_remove(rng.random_range(0..self.live.len()));
        self.scene.remove_body(id).unwrap();
        self.changed.insert(id.0);
    }

    fn update(&mut self, rng: &mut TestRng) {
        if self.live.is_empty() {
            return;
        }
        let id = self.live[rng.random_range(0..self.live.len())];
        let margin = (rng.random_range(0..2) == 0).then(|| rng.random_range(0.0..0.3));
        let (motion, filter) = (Self::motion(rng), Self::filter(rng));
        self.scene.update_body(id, motion, filter, margin).unwrap();
        self.changed.insert(id.0);
    }

    /// Moves about a third of the non-static bodies coherently (some teleport, some are
    /// sent their unchanged pose, which is no change).
    fn move_some(&mut self, rng: &mut TestRng) {
        for &id in &self.live {
            let body = *self.scene.body(id).unwrap();
            if body.motion == Motion::Static || rng.random_range(0..3) != 0 {
                continue;
            }
            let pose = match rng.random_range(0..40) {
                0 => Pose::new(point_in_cube(rng, self.spread), rotation(rng)),
                1..=4 => body.pose,
                _ => Pose::new(
                    body.pose.position + point_in_cube(rng, 0.1),
                    body.pose.rotation,
                ),
            };
            self.scene.set_pose(id, pose).unwrap();
            if pose != body.pose {
                self.changed.insert(id.0);
            }
        }
    }

    /// One frame's worth of random changes; `quiet` frames change nothing.
    fn change(&mut self, rng: &mut TestRng, quiet: bool) {
        if quiet {
            return;
        }
        self.move_some(rng);
        for _ in 0..rng.random_range(0..3) {
            match rng.random_range(0..3) {
                0 => self.add(rng),
                1 => self.remove(rng),
                _ => self.update(rng),
            }
        }
    }

    fn end_frame(&mut self) {
        self.scene.end_frame();
        self.changed.clear();
    }
}

fn run(
    scene: &Scene,
    query: Query,
    workspace: &mut PipelineWorkspace,
) -> (FrameResults, StepReport) {
    let mut results = FrameResults::default();
    let report = step(scene, query, workspace, &mut results);
    (results, report)
}

/// Same answers and counts (timings aside).
fn assert_same(got: &(FrameResults, StepReport), want: &(FrameResults, StepReport), what: &str) {
    assert_eq!(got.0.pairs, want.0.pairs, "{what}: pairs");
    assert_eq!(got.0.contacts, want.0.contacts, "{what}: contacts");
    assert_eq!(got.0.tois, want.0.tois, "{what}: tois");
    let counts = |r: &StepReport| {
        (
            r.completeness,
            r.candidates,
            r.toi_candidates,
            r.pairs,
            r.contacts,
            r.tois,
        )
    };
    assert_eq!(counts(&got.1), counts(&want.1), "{what}: report");
}

#[test]
fn kept_broad_phases_answer_like_a_fresh_workspace_and_reread_only_changed_bodies() {
    let mut rng = rng(6_004);
    let mut world = World::new(&mut rng, 6.0, 90);
    let mut other = World::new(&mut rng, 3.0, 30);
    // One per choice, one whose choice cycles, one per fixed kind shared by both scenes.
    const KEPT: usize = CHOICES.len() + 1;
    let mut kept: Vec<PipelineWorkspace> =
        (0..KEPT).map(|_| PipelineWorkspace::default()).collect();
    let mut shared: Vec<PipelineWorkspace> = BroadPhaseKind::ALL
        .iter()
        .map(|_| PipelineWorkspace::default())
        .collect();
    let cycling = |frame: u64| CHOICES[(frame / 40) as usize % CHOICES.len()];
    // What Auto measured last, and at which frame.
    let mut auto_kind = None;
    let mut auto_measured_at = 0;
    // Whether each kept workspace must rebuild this frame (first frame, after a TOI-only
    // frame, after changes made past the step, after its kind changed).
    let mut must_rebuild = [true; KEPT];
    let mut last_kind: [Option<BroadPhaseKind>; KEPT] = [None; KEPT];
    let mut tally = [0usize; 6]; // quiet, incremental, rebuilt, twice, late edits, toi-only
    for frame in 0..FRAMES {
        let quiet = frame % 11 == 5;
        world.change(&mut rng, quiet);
        other.change(&mut rng, false);
        let toi_only = frame % 97 == 50;
        let query = if toi_only {
            Query::TOI
        } else {
            match frame % 3 {
                0 => Query::CLOSE.union(Query::CONTACTS),
                1 => Query::DISTANCE,
                _ => Query::OVERLAP.union(Query::TOI),
            }
        };
        let fresh = run(&world.scene, query, &mut PipelineWorkspace::default());
        let changed = world.changed.len() as u32;
        for (i, workspace) in kept.iter_mut().enumerate() {
            let choice = if i < CHOICES.len() {
                CHOICES[i]
            } else {
                cycling(frame)
            };
            world.scene.set_broad_phase(choice);
            let got = run(&world.scene, query, workspace);
            let what = format!("frame {frame}, workspace {i} ({choice:?})");
            assert_same(&got, &fresh, &what);
            if toi_only {
                assert_eq!((got.1.broad_kind, got.1.broad_updates), (None, 0), "{what}");
                must_rebuild[i] = true;
                continue;
            }
            let kind = got.1.broad_kind.expect("the broad phase ran");
            match choice {
                BroadPhaseChoice::Fixed(fixed) => assert_eq!(kind, fixed, "{what}"),
                // Measured at the first frame and every AUTO_REMEASURE_FRAMES after it, on
                // the scene as it is then (bodies changed: all of them when the log cannot
                // tell); kept in between.
                BroadPhaseChoice::Auto if i == 0 => {
                    // Measured at the first frame and every AUTO_REMEASURE_FRAMES after it
                    // (the report carries the statistics), on the scene as it is then
                    // (bodies changed: all of them when the log cannot tell); kept in
                    // between, and the pick is `choose` of what was measured.
                    let due =
                        auto_kind.is_none() || frame - auto_measured_at >= AUTO_REMEASURE_FRAMES;
                    assert_eq!(got.1.broad_stats.is_some(), due, "{what}");
                    if let Some(stats) = got.1.broad_stats {
                        let mut proxies = Vec::new();
                        world.scene.proxies(&mut proxies);
                        let moved = if must_rebuild[0] {
                            proxies.len()
                        } else {
                            world.scene.changes().len()
                        };
                        let mut expected = BroadPhaseStats::measure(&proxies, moved);
                        expected.far_move_fraction = stats.far_move_fraction;
                        expected.mean_shift = stats.mean_shift;
                        expected.typical_shift = stats.typical_shift;
                        assert_eq!(stats, expected, "{what}");
                        assert!(stats.typical_shift >= 0.0, "{what}");
                        assert!((0.0..=1.0).contains(&stats.far_move_fraction), "{what}");
                        assert!((0.0..=1.0).contains(&stats.mean_shift), "{what}");
                        assert!(stats.mean_shift >= stats.far_move_fraction, "{what}");
                        auto_kind = Some(choose(&stats));
                        auto_measured_at = frame;
                    }
                    assert_eq!(Some(kind), auto_kind, "{what}");
                }
                BroadPhaseChoice::Auto => {}
            }
            if last_kind[i] != Some(kind) {
                must_rebuild[i] = true;
            }
            last_kind[i] = Some(kind);
            let live = world.scene.body_count() as u32;
            if must_rebuild[i] {
                assert_eq!(got.1.broad_updates, live, "{what}: rebuilt");
                tally[2] += 1;
            } else {
                assert_eq!(got.1.broad_updates, changed, "{what}: re-read");
                tally[1] += 1;
                if quiet {
                    assert_eq!(got.1.broad_updates, 0, "{what}: quiet frame");
                    tally[0] += 1;
                }
            }
            must_rebuild[i] = false;
        }
        // The other scene through the shared workspaces: always another scene than the
        // one they synced to last, so always a rebuild, always exact.
        let other_fresh = run(&other.scene, query, &mut PipelineWorkspace::default());
        for (k, workspace) in shared.iter_mut().enumerate() {
            let kind = BroadPhaseKind::ALL[k];
            for w in [&mut world, &mut other] {
                w.scene.set_broad_phase(BroadPhaseChoice::Fixed(kind));
            }
            let got = run(&world.scene, query, workspace);
            assert_same(
                &got,
                &fresh,
                &format!("frame {frame}, shared {kind:?} on world"),
            );
            let got = run(&other.scene, query, workspace);
            assert_same(
                &got,
                &other_fresh,
                &format!("frame {frame}, shared {kind:?} on other"),
            );
            if !toi_only {
                assert_eq!(got.1.broad_updates as usize, other.scene.body_count());
            }
        }
        // Stepped twice in one frame, a body moved (again) between the two steps: the
        // second step re-reads the whole log and still answers like a fresh workspace.
        if frame % 7 == 3 && !toi_only {
            world.move_some(&mut rng);
            let fresh = run(&world.scene, query, &mut PipelineWorkspace::default());
            for (i, workspace) in kept.iter_mut().enumerate() {
                let choice = if i < CHOICES.len() {
                    CHOICES[i]
                } else {
                    cycling(frame)
                };
                world.scene.set_broad_phase(choice);
                let first = run(&world.scene, query, workspace);
                let second = run(&world.scene, query, workspace);
                let what = format!("frame {frame}, workspace {i}, stepped again");
                assert_same(&first, &fresh, &what);
                assert_same(&second, &first, &what);
                assert_eq!(second.1.broad_updates, world.changed.len() as u32, "{what}");
            }
            tally[3] += 1;
        }
        // Changes after the step, before the frame ends: the log of this frame is gone by
        // the next, so the next frame rebuilds.
        if frame % 13 == 7 {
            world.update(&mut rng);
            world.move_some(&mut rng);
            must_rebuild = [true; KEPT];
            tally[4] += 1;
        }
        tally[5] += usize::from(toi_only);
        world.end_frame();
        other.end_frame();
        assert_eq!(world.scene.validate(), Ok(()));
    }
    assert!(
        tally.iter().all(|&n| n > 4) && tally[1] > 2_000,
        "quiet, incremental, rebuilt, twice, late edits, toi-only: {tally:?}"
    );
    let kinds: BTreeSet<_> = last_kind
        .iter()
        .flatten()
        .map(|k| format!("{k:?}"))
        .collect();
    assert!(kinds.len() >= 3, "{kinds:?}");
}

/// The log the workspaces read: each changed body once per frame, only real changes.
#[test]
fn the_change_log_lists_each_changed_body_once_and_only_real_changes() {
    let mut rng = rng(6_005);
    let mut world = World::new(&mut rng, 5.0, 40);
    assert_eq!(world.scene.changes().len(), 40);
    let uid = world.scene.uid();
    world.end_frame();
    assert!(world.scene.changes().is_empty());
    let mut seen_empty = 0;
    for frame in 0..300 {
        world.change(&mut rng, frame % 5 == 0);
        let logged: BTreeSet<u32> = world.scene.changes().iter().copied().collect();
        assert_eq!(
            logged.len(),
            world.scene.changes().len(),
            "frame {frame}: repeats"
        );
        assert_eq!(logged, world.changed, "frame {frame}");
        seen_empty += usize::from(logged.is_empty());
        assert_eq!(world.scene.validate(), Ok(()));
        world.end_frame();
    }
    assert!(seen_empty >= 50);
    // A clone is another scene: a reader synced to one must rebuild for the other.
    let point = world.scene.sync_point();
    let copy = world.scene.clone();
    assert_ne!(copy.uid(), uid);
    assert_eq!(world.scene.changes_since(point), Some(&[][..]));
    assert_eq!(copy.changes_since(point), None);
}

/// What the automatic choice reads of the motion is measured from the bodies' real moves:
/// spheres that all slide a set fraction of their box each frame report that fraction as
/// the mean shift at the next measurement, with no far moves, and the pick follows
/// [`CREEPING`]: the skin grid for creeping bodies, sort and sweep for fast ones.
#[test]
fn the_measured_mean_shift_is_the_bodies_motion_and_the_pick_follows_it() {
    for (fraction, kind) in [
        (0.4 * CREEPING, BroadPhaseKind::SkinGrid),
        (3.0 * CREEPING, BroadPhaseKind::SortAndSweep),
    ] {
        let mut scene = Scene::try_new(0.05, SceneLimits::STANDARD).unwrap();
        let ball = scene
            .register_shape(Shape::Sphere(Sphere::new(0.5)))
            .unwrap();
        let ids: Vec<BodyId> = (0..40)
            .map(|i| {
                let at = DVec3::new(f64::from(i % 8) * 1.5, f64::from(i / 8) * 1.5, 0.0);
                let desc = BodyDesc {
                    shape: ball,
                    pose: Pose::new(at, rotation(&mut rng(i as u64))),
                    motion: Motion::Dynamic,
                    filter: CollisionFilter::ALL,
                    margin: Some(0.1),
                };
                scene.add_body(&desc).unwrap()
            })
            .collect();
        let edge = {
            let p = scene.proxy(ids[0]).unwrap();
            (p.bounds.max - p.bounds.min).max_element()
        };
        let step_x = DVec3::X * fraction * edge;
        let mut workspace = PipelineWorkspace::default();
        let mut measured = Vec::new();
        for frame in 0..=AUTO_REMEASURE_FRAMES {
            if frame > 0 {
                for &id in &ids {
                    let pose = scene.body(id).unwrap().pose;
                    scene
                        .set_pose(id, Pose::new(pose.position + step_x, pose.rotation))
                        .unwrap();
                }
            }
            let (_, report) = run(&scene, Query::CLOSE, &mut workspace);
            if let Some(stats) = report.broad_stats {
                measured.push((frame, stats, report.broad_kind));
            }
            scene.end_frame();
        }
        // At the first frame every body is new and no move was counted: a scene at rest.
        let (first, last) = (measured[0], measured[measured.len() - 1]);
        assert_eq!((first.0, first.1.mean_shift), (0, 0.0));
        assert_eq!(first.2, Some(BroadPhaseKind::SkinGrid));
        assert_eq!(
            (measured.len(), last.0),
            (2, AUTO_REMEASURE_FRAMES),
            "{measured:?}"
        );
        let stats = last.1;
        assert_eq!(stats.moving_fraction, 1.0);
        assert_eq!(stats.far_move_fraction, 0.0);
        assert!(
            (stats.mean_shift - fraction).abs() < 1e-9 * fraction,
            "{fraction}: measured {}",
            stats.mean_shift
        );
        // One size of box: the shift for the typical box is the same fraction.
        assert!(
            (stats.typical_shift - fraction).abs() < 1e-9 * fraction,
            "{fraction}: typical {}",
            stats.typical_shift
        );
        assert_eq!(last.2, Some(kind), "{fraction}");
    }
}
