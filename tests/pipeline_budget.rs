//! The frame pipeline under a counted budget (`step_within`, issue #7): every mesh–mesh
//! candidate pair goes through one budgeted frontier, and the frame must stay conservative
//! and monotone at every budget, deterministic, and equal to the exact `step` once the
//! budget covers the whole traversal.
//!
//! Oracle: the exact, unbudgeted `step` on a fresh workspace: with `DISTANCE` it gives
//! every candidate pair's exact signed distance (the truth), and with each tested query
//! the records a budgeted frame must cover. (`step` itself is checked against brute force
//! and the narrow-phase oracles in `src/pipeline` and `tests/mesh_mesh_oracle.rs`; the
//! frontier against brute force over all triangle pairs in `tests/frontier_budget.rs`.)
//!
//! Scenes: piles of eight tori of three sizes with two spheres and two boxes at seeded
//! random poses (touching, near and apart pairs, asserted to occur), and the fandisk
//! against a torus (from the data folder, `PROXIMA_DATA`; skipped with a line saying so
//! when absent). Budgets: every visit budget from 0 to the full traversal's visit count (a
//! dense sample when there are more than [`MAX_BUDGETS`]), with the frontier polling the
//! budget after every entry, so each budget is its own interruption point. No test
//! measures time.

#[path = "support/mod.rs"]
mod support;

use proxima::geometry::{Cuboid, Sphere};
use proxima::math::{DVec3, Pose};
use proxima::narrow::{MeshShape, Shape};
use proxima::pipeline::{
    Budget, Completeness, ContactPoint, FrameResults, PairResult, PipelineWorkspace, Query,
    StepReport, Unlimited, VisitBudget, step, step_within,
};
use proxima::scene::{BodyDesc, CollisionFilter, Motion, Scene, SceneLimits};
use rand::Rng;
use std::collections::BTreeMap;
use std::sync::Arc;
use support::{meshes, point_in_cube, rng, rotation};

/// The query flag sets every scene is run with.
const QUERIES: [(&str, Query); 4] = [
    ("CLOSE", Query::CLOSE),
    ("DISTANCE", Query::DISTANCE),
    ("OVERLAP|CONTACTS", Query::OVERLAP.union(Query::CONTACTS)),
    ("CLOSE|CONTACTS", Query::CLOSE.union(Query::CONTACTS)),
];

/// Most budgets tried per scene and query; beyond it, evenly spaced budgets plus the first
/// hundred.
const MAX_BUDGETS: u64 = 700;

/// Slack on "never above the truth", metres (rounding of a distance at these scales).
const ROUNDING: f64 = 1e-12;

/// A frame's records, kept (`FrameResults` is reused by the pipeline).
#[derive(Debug, Clone, PartialEq)]
struct Frame {
    pairs: Vec<PairResult>,
    contacts: Vec<ContactPoint>,
    report: StepReport,
}

impl Frame {
    fn pair(&self, a: u32, b: u32) -> Option<&PairResult> {
        self.pairs.iter().find(|p| (p.a, p.b) == (a, b))
    }

    fn contacts_of(&self, p: &PairResult) -> &[ContactPoint] {
        let first = p.first_contact as usize;
        &self.contacts[first..first + p.contact_count as usize]
    }

    /// The level of a truncated frame, `None` when exact.
    fn level(&self) -> Option<u32> {
        match self.report.completeness {
            Completeness::Exact => None,
            Completeness::Truncated { level } => Some(level),
        }
    }
}

fn run(scene: &Scene, query: Query, budget: &mut dyn Budget) -> Frame {
    let mut workspace = PipelineWorkspace::default().with_frontier_poll_every(1);
    let mut results = FrameResults::default();
    let report = step_within(scene, query, budget, &mut workspace, &mut results);
    Frame {
        pairs: results.pairs,
        contacts: results.contacts,
        report,
    }
}

fn run_exact(scene: &Scene, query: Query) -> Frame {
    let mut results = FrameResults::default();
    let report = step(
        scene,
        query,
        &mut PipelineWorkspace::default(),
        &mut results,
    );
    Frame {
        pairs: results.pairs,
        contacts: results.contacts,
        report,
    }
}

/// Adds a body of `shape` at `pose` with `margin`.
fn add(scene: &mut Scene, shape: Shape, pose: Pose, margin: f64) {
    let shape = scene.register_shape(shape).unwrap();
    scene
        .add_body(&BodyDesc {
            shape,
            pose,
            motion: Motion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: Some(margin),
        })
        .unwrap();
}

/// Eight tori of three sizes around the points of a 4 × 2 grid (neighbours touch or come
/// near, some diagonals too), two spheres and two boxes among them; margins 1–6 cm.
fn pile(seed: u64) -> Scene {
    let mut r = rng(seed);
    let tori = [
        meshes::torus(0.45, 0.12, 16, 8),
        meshes::torus(0.35, 0.1, 12, 6),
        meshes::torus(0.4, 0.14, 20, 10),
    ]
    .map(|m| Arc::new(MeshShape::new(m)));
    let mut scene = Scene::try_new(0.02, SceneLimits::STANDARD).unwrap();
    for k in 0..8 {
        let cell = DVec3::new((k % 4) as f64 - 1.5, (k / 4) as f64 - 0.5, 0.0) * 0.85;
        let pose = Pose::new(cell + point_in_cube(&mut r, 0.2), rotation(&mut r));
        let margin = r.random_range(0.01..0.06);
        add(
            &mut scene,
            Shape::Mesh(Arc::clone(&tori[k % 3])),
            pose,
            margin,
        );
    }
    for k in 0..4 {
        let pose = Pose::new(
            point_in_cube(&mut r, 1.0) * DVec3::new(1.6, 0.8, 0.4),
            rotation(&mut r),
        );
        let shape = if k % 2 == 0 {
            Shape::Sphere(Sphere::new(r.random_range(0.1..0.25)))
        } else {
            Shape::Cuboid(Cuboid::new(DVec3::new(0.2, 0.15, 0.1)))
        };
        let margin = r.random_range(0.01..0.06);
        add(&mut scene, shape, pose, margin);
    }
    scene
}

/// The fandisk (×0.3, about 1.5 m across, 12,946 triangles) and two tori placed against
/// it: one through it, one near it.
fn fandisk_scene(who: &str) -> Option<Scene> {
    let fandisk = meshes::shared_data_mesh(who, "fandisk.obj")?
        .scaled(0.3)
        .centered_on_bounds();
    let mut scene = Scene::try_new(0.03, SceneLimits::STANDARD).unwrap();
    add(
        &mut scene,
        Shape::Mesh(Arc::new(MeshShape::new(fandisk))),
        Pose::IDENTITY,
        0.03,
    );
    let torus = Arc::new(MeshShape::new(meshes::torus(0.3, 0.08, 16, 8)));
    let mut r = rng(91);
    for at in [
        DVec3::new(0.6, 0.1, 0.0),
        DVec3::new(0.0, 0.0, 0.8),
        DVec3::new(-0.2, -1.25, 0.0),
    ] {
        add(
            &mut scene,
            Shape::Mesh(Arc::clone(&torus)),
            Pose::new(at, rotation(&mut r)),
            0.03,
        );
    }
    Some(scene)
}

/// Equal records, contacts included (their `pair` index and `first_contact` depend on the
/// frame's other pairs and are not compared). One exception: the witnesses of a pair at
/// distance `≤ 0` name one intersecting triangle pair of many, and the frontier and the
/// exact query may name different ones: there both must be a single point (`point_a ==
/// point_b`), and the rest of the record equal.
fn same_record(got: (&Frame, &PairResult), want: (&Frame, &PairResult), at: &str) {
    let ((gf, g), (wf, w)) = (got, want);
    let strip = |p: &PairResult| {
        let tied = p.distance <= 0.0 && p.point_a == p.point_b;
        PairResult {
            first_contact: 0,
            point_a: if tied { DVec3::ZERO } else { p.point_a },
            point_b: if tied { DVec3::ZERO } else { p.point_b },
            ..*p
        }
    };
    assert_eq!(strip(g), strip(w), "{at}");
    let strip_all = |cs: &[ContactPoint]| -> Vec<ContactPoint> {
        cs.iter().map(|c| ContactPoint { pair: 0, ..*c }).collect()
    };
    assert_eq!(
        strip_all(gf.contacts_of(g)),
        strip_all(wf.contacts_of(w)),
        "{at}"
    );
}

/// What the checks saw, to assert that every outcome occurred.
#[derive(Debug, Default)]
struct Tally {
    frames: usize,
    truncated_frames: usize,
    exact_frames: usize,
    truncated_records: usize,
    exact_mesh_records_in_truncated_frames: usize,
    may_touch_contacts: usize,
    touching: usize,
    near: usize,
    apart: usize,
}

/// (a) conservative: every pair the exact frame reports is reported, with a distance never
/// above the truth and within its error bound; exact records equal the exact frame's;
/// touching pairs carry contacts when asked. Extra (truncated) pairs are conservative too.
fn check_conservative(
    frame: &Frame,
    exact: &Frame,
    truth: &BTreeMap<(u32, u32), f64>,
    query: Query,
    meshes_below: u32,
    at: &str,
    tally: &mut Tally,
) {
    for want in &exact.pairs {
        let got = frame
            .pair(want.a, want.b)
            .unwrap_or_else(|| panic!("{at}: pair {}–{} missed", want.a, want.b));
        if query.contacts && want.contact_count > 0 {
            assert!(
                got.contact_count > 0,
                "{at}: touching pair without contacts"
            );
        }
    }
    for got in &frame.pairs {
        let t = truth[&(got.a, got.b)];
        let at = format!("{at}, pair {}–{}", got.a, got.b);
        match exact.pair(got.a, got.b) {
            Some(want) if got.exact => same_record((frame, got), (exact, want), &at),
            Some(_) | None => {
                assert!(!got.exact, "{at}: an exact record the exact frame lacks");
                tally.truncated_records += 1;
                assert!(got.distance <= t + ROUNDING, "{at}: {} > {t}", got.distance);
                assert!(
                    (got.distance - t).abs() <= got.error_bound + ROUNDING,
                    "{at}: |{} − {t}| > {}",
                    got.distance,
                    got.error_bound
                );
                let contacts = frame.contacts_of(got);
                if query.contacts && got.distance <= 0.0 {
                    assert_eq!(contacts.len(), 1, "{at}");
                    assert_eq!(contacts[0].distance, 0.0);
                    assert!(contacts[0].error_bound >= -t.min(0.0));
                    tally.may_touch_contacts += 1;
                } else {
                    assert!(contacts.is_empty(), "{at}");
                }
            }
        }
        assert!(got.normal.length() == 0.0 || (got.normal.length() - 1.0).abs() < 1e-12);
    }
    if frame.level().is_some() {
        assert!(frame.report.truncated_pairs > 0, "{at}");
        tally.exact_mesh_records_in_truncated_frames += frame
            .pairs
            .iter()
            .filter(|p| p.exact && meshes_below > p.b)
            .count();
    } else {
        assert_eq!(frame.report.truncated_pairs, 0, "{at}");
        assert!(frame.pairs.iter().all(|p| p.exact), "{at}");
    }
}

/// (b) monotone from the frame at a smaller budget to the next: a reported distance never
/// decreases, an exact record never changes, a pair once left out stays out, and the
/// frame's level never goes shallower (nor back from Exact).
fn check_monotone(prev: &Frame, next: &Frame, at: &str) {
    for p in &prev.pairs {
        let at = format!("{at}, pair {}–{}", p.a, p.b);
        match next.pair(p.a, p.b) {
            Some(n) if p.exact => same_record((next, n), (prev, p), &at),
            Some(n) => assert!(
                n.distance >= p.distance,
                "{at}: {} < {}",
                n.distance,
                p.distance
            ),
            None => assert!(!p.exact, "{at}: an exact record vanished"),
        }
    }
    for n in &next.pairs {
        assert!(
            prev.pair(n.a, n.b).is_some(),
            "{at}: pair {}–{} appeared",
            n.a,
            n.b
        );
    }
    match (prev.level(), next.level()) {
        (None, Some(_)) => panic!("{at}: an exact frame became truncated"),
        (Some(p), Some(n)) => assert!(n >= p, "{at}: level {n} < {p}"),
        _ => {}
    }
}

/// The budgets to try: all of `0 ..= full + 2` when at most `max` (`> 100`), else the
/// first hundred and an even sample, plus `full` itself and one more.
fn budgets(full: u64, max: u64) -> Vec<u64> {
    if full + 3 <= max {
        return (0..=full + 2).collect();
    }
    let stride = full.div_ceil(max - 100);
    let mut list: Vec<u64> = (0..100)
        .chain((100..=full).step_by(stride as usize))
        .collect();
    list.extend([full, full + 1]);
    list.dedup();
    list
}

/// Every check on one scene, for every query, at most `max_budgets` budgets each (bodies
/// `0..meshes_below` are the meshes); returns the full visit counts.
fn check_scene(
    name: &str,
    scene: &Scene,
    meshes_below: u32,
    max_budgets: u64,
    tally: &mut Tally,
) -> Vec<u64> {
    let distances = run_exact(scene, Query::DISTANCE);
    let truth: BTreeMap<(u32, u32), f64> = distances
        .pairs
        .iter()
        .map(|p| ((p.a, p.b), p.distance))
        .collect();
    for p in &distances.pairs {
        let margins = scene.body(proxima::scene::BodyId(p.a)).unwrap().margin
            + scene.body(proxima::scene::BodyId(p.b)).unwrap().margin;
        match p.distance {
            d if d <= 0.0 => tally.touching += 1,
            d if d <= margins => tally.near += 1,
            _ => tally.apart += 1,
        }
    }
    let mut fulls = Vec::new();
    for (qname, query) in QUERIES {
        let exact = run_exact(scene, query);
        assert_eq!(exact.report.completeness, Completeness::Exact);
        // (c) unlimited = exact, through either path.
        let unlimited = run(scene, query, &mut Unlimited);
        assert_eq!(
            (&unlimited.pairs, &unlimited.contacts),
            (&exact.pairs, &exact.contacts),
            "{name} {qname}: Unlimited"
        );
        assert_eq!(unlimited.report.frontier.visits, 0);
        let full_run = run(scene, query, &mut VisitBudget(u64::MAX));
        let full = spent(&full_run.report);
        assert!(full > 0, "{name} {qname}: the frontier ran");
        fulls.push(full);
        let mut prev: Option<Frame> = None;
        for budget in budgets(full, max_budgets) {
            let at = format!("{name} {qname}, budget {budget}");
            let frame = run(scene, query, &mut VisitBudget(budget));
            tally.frames += 1;
            check_conservative(&frame, &exact, &truth, query, meshes_below, &at, tally);
            if let Some(prev) = &prev {
                check_monotone(prev, &frame, &at);
            }
            if budget >= full {
                // (c) a budget covering the traversal gives the exact frame.
                assert_eq!(frame.report.completeness, Completeness::Exact, "{at}");
                assert_eq!(frame.pairs.len(), exact.pairs.len(), "{at}");
                for (g, w) in frame.pairs.iter().zip(&exact.pairs) {
                    same_record((&frame, g), (&exact, w), &at);
                }
            }
            match frame.level() {
                Some(_) => tally.truncated_frames += 1,
                None => tally.exact_frames += 1,
            }
            // (d) same input and budget, same output (every seventh budget).
            if budget % 7 == 3 {
                let again = run(scene, query, &mut VisitBudget(budget));
                let work = |f: &Frame| (f.report.completeness, f.report.frontier);
                assert_eq!(
                    (&again.pairs, &again.contacts, work(&again)),
                    (&frame.pairs, &frame.contacts, work(&frame)),
                    "{at}"
                );
            }
            prev = Some(frame);
        }
    }
    fulls
}

#[test]
fn every_budget_of_tori_piles_is_conservative_monotone_deterministic_and_exact_at_the_end() {
    let mut tally = Tally::default();
    for seed in [1, 2] {
        let fulls = check_scene(
            &format!("pile {seed}"),
            &pile(seed),
            8,
            MAX_BUDGETS,
            &mut tally,
        );
        eprintln!("pile {seed}: full visit counts {fulls:?}");
    }
    eprintln!("{tally:?}");
    assert!(
        tally.truncated_frames > 100 && tally.exact_frames >= 8,
        "{tally:?}"
    );
    assert!(
        tally.touching >= 3 && tally.near >= 2 && tally.apart >= 3,
        "{tally:?}"
    );
    assert!(
        tally.truncated_records > 100 && tally.may_touch_contacts > 10,
        "{tally:?}"
    );
    assert!(
        tally.exact_mesh_records_in_truncated_frames > 10,
        "{tally:?}"
    );
}

#[test]
fn every_sampled_budget_of_the_fandisk_against_tori_is_conservative_and_monotone() {
    let Some(scene) = fandisk_scene(
        "every_sampled_budget_of_the_fandisk_against_tori_is_conservative_and_monotone",
    ) else {
        return;
    };
    let mut tally = Tally::default();
    let fulls = check_scene("fandisk", &scene, 4, 160, &mut tally);
    eprintln!("fandisk: full visit counts {fulls:?}\n{tally:?}");
    assert!(
        tally.truncated_frames > 100 && tally.exact_frames >= 4,
        "{tally:?}"
    );
    assert!(
        tally.touching >= 1 && tally.near >= 1 && tally.apart >= 1,
        "{tally:?}"
    );
}

/// The visits a frame spent of its counted budget: the frontier's, and one per hull test.
fn spent(report: &StepReport) -> u64 {
    report.frontier.visits + u64::from(report.hull_tests)
}

/// Kept answers under a budget: only exact ones are reused, so a truncated pair is answered
/// again next frame; while its bodies rest the frontier resumes where it stopped, so a
/// budget too small for the frame's hardest pairs still reaches the exact frame, after as
/// many visits as one unlimited run. Frames that move bodies in between (fresh frontier)
/// and frames that do not (resumed) stay conservative against the moved scene's truth.
#[test]
fn truncated_answers_are_refined_frame_after_frame_until_the_frame_is_exact() {
    let mut scene = pile(1);
    let query = Query::CLOSE.union(Query::CONTACTS);
    let exact = run_exact(&scene, query);
    let full = spent(&run(&scene, query, &mut VisitBudget(u64::MAX)).report);
    let budget = full / 4;
    let mut workspace = PipelineWorkspace::default();
    let mut results = FrameResults::default();
    let (mut kept, mut truncated, mut visits) = (0, u32::MAX, 0);
    let mut frames = 0;
    loop {
        frames += 1;
        assert!(frames <= 6, "no exact frame after 6 frames");
        let report = step_within(
            &scene,
            query,
            &mut VisitBudget(budget),
            &mut workspace,
            &mut results,
        );
        assert_eq!(report.reused_pairs, kept, "frame {frames}");
        assert!(report.truncated_pairs <= truncated, "frame {frames}");
        (kept, truncated) = (
            report.candidates - report.truncated_pairs,
            report.truncated_pairs,
        );
        visits += spent(&report);
        if report.completeness == Completeness::Exact {
            let frame = Frame {
                pairs: results.pairs.clone(),
                contacts: results.contacts.clone(),
                report,
            };
            assert_eq!(frame.pairs.len(), exact.pairs.len());
            for (g, w) in frame.pairs.iter().zip(&exact.pairs) {
                same_record((&frame, g), (&exact, w), &format!("frame {frames}"));
            }
            break;
        }
        assert!(report.truncated_pairs > 0);
        assert!(spent(&report) >= budget, "frame {frames}");
    }
    assert!(frames >= 3, "the budget was not small: {frames} frames");
    assert_eq!(visits, full, "resumed pieces add up to one unlimited run");

    let mut r = rng(5);
    let mut tally = Tally::default();
    for frame in 0..24 {
        if frame % 3 == 0 {
            let id = proxima::scene::BodyId(r.random_range(0..8));
            let pose = scene.body(id).unwrap().pose;
            let moved = Pose::new(pose.position + point_in_cube(&mut r, 0.05), pose.rotation);
            scene.set_pose(id, moved).unwrap();
        }
        let report = step_within(
            &scene,
            query,
            &mut VisitBudget(budget / 4),
            &mut workspace,
            &mut results,
        );
        let got = Frame {
            pairs: results.pairs.clone(),
            contacts: results.contacts.clone(),
            report,
        };
        let truth: BTreeMap<(u32, u32), f64> = run_exact(&scene, Query::DISTANCE)
            .pairs
            .iter()
            .map(|p| ((p.a, p.b), p.distance))
            .collect();
        let exact = run_exact(&scene, query);
        let at = format!("moving frame {frame}");
        check_conservative(&got, &exact, &truth, query, 8, &at, &mut tally);
    }
    assert!(tally.truncated_records > 10, "{tally:?}");
}

/// A deadline already past (or closer than the reserve) lets the frontier do nothing: every
/// mesh pair is answered at level 0, exactly as a zero visit budget; a deadline an hour
/// away lets it finish: the exact frame. (No timing is measured: both outcomes hold on any
/// machine that answers a frame in less than an hour.)
#[test]
fn a_past_deadline_answers_at_level_0_and_a_distant_one_gives_the_exact_frame() {
    use proxima::pipeline::{Deadline, FRONTIER_RESERVE};
    use std::time::{Duration, Instant};
    let mut scene = pile(2);
    // Bodies 8 and 10 of the pile are spheres, 9 and 11 boxes; beside the pile, sphere 12
    // sinks 5 cm into box 13 and 3 cm into sphere 14.
    let at = |x: f64, y: f64| Pose::from_translation(DVec3::new(x, y, 0.0));
    add(
        &mut scene,
        Shape::Sphere(Sphere::new(0.2)),
        at(10.0, 0.0),
        0.02,
    );
    let block = Cuboid::new(DVec3::new(0.2, 0.15, 0.1));
    add(&mut scene, Shape::Cuboid(block), at(10.35, 0.0), 0.02);
    add(
        &mut scene,
        Shape::Sphere(Sphere::new(0.15)),
        at(9.7, 0.1),
        0.02,
    );
    let sphere = |id: u32| matches!(id, 8 | 10 | 12 | 14);
    let cheap = |p: &PairResult| (sphere(p.a) && p.b >= 8) || (sphere(p.b) && p.a >= 8);
    let mut cheap_pairs = 0;
    let truth: BTreeMap<(u32, u32), f64> = run_exact(&scene, Query::DISTANCE)
        .pairs
        .iter()
        .map(|p| ((p.a, p.b), p.distance))
        .collect();
    let mut tally = Tally::default();
    for (name, query) in QUERIES {
        let zero = run(&scene, query, &mut VisitBudget(0));
        assert_eq!(
            zero.report.completeness,
            Completeness::Truncated { level: 0 }
        );
        let exact = run_exact(&scene, query);
        // Deadlines already past when the frame starts (the frontier keeps back part of any
        // time left, so only these leave it nothing).
        let now = Instant::now();
        for deadline in [now, now.checked_sub(FRONTIER_RESERVE).unwrap_or(now)] {
            let past = run(&scene, query, &mut Deadline(deadline));
            assert_eq!(past.report.frontier.visits, 0);
            assert_eq!(past.report.completeness, zero.report.completeness);
            // The mesh pairs answer as with no visits; the pairs off the frontier take their
            // world boxes' answer instead of their closed forms, except a sphere against a
            // sphere or box, whose closed form costs no more: every record is
            // conservative, and exactly those are exact (the exact frame's records).
            check_conservative(&past, &exact, &truth, query, 8, name, &mut tally);
            for got in &past.pairs {
                if cheap(got) {
                    let want = exact.pair(got.a, got.b).expect("an exact record");
                    same_record((&past, got), (&exact, want), name);
                    cheap_pairs += 1;
                } else {
                    assert!(!got.exact, "{name}: {got:?}");
                }
            }
            for got in past.pairs.iter().filter(|p| p.b < 8) {
                let want = zero.pair(got.a, got.b).expect("the same mesh pairs");
                // Contacts land elsewhere in the list: the primitive pairs' differ.
                let unplaced = |p: &PairResult| PairResult {
                    first_contact: 0,
                    ..*p
                };
                assert_eq!(unplaced(got), unplaced(want), "{name}");
                let unlinked = |f: &Frame, p: &PairResult| -> Vec<ContactPoint> {
                    f.contacts_of(p)
                        .iter()
                        .map(|c| ContactPoint { pair: 0, ..*c })
                        .collect()
                };
                assert_eq!(unlinked(&past, got), unlinked(&zero, want), "{name}");
            }
            assert!(
                past.pairs.iter().any(|p| p.b >= 8) && zero.pairs.iter().any(|p| p.b >= 8),
                "{name}: primitive pairs were asked"
            );
        }
        let distant = run(
            &scene,
            query,
            &mut Deadline(Instant::now() + Duration::from_secs(3600)),
        );
        assert_eq!(distant.report.completeness, Completeness::Exact, "{name}");
        assert!(
            distant.report.frontier.visits > 0,
            "{name}: the frontier ran"
        );
        assert_eq!(distant.pairs.len(), exact.pairs.len());
        for (g, w) in distant.pairs.iter().zip(&exact.pairs) {
            same_record((&distant, g), (&exact, w), name);
        }
    }
    assert!(tally.truncated_records > 0, "{tally:?}");
    assert!(cheap_pairs > 0, "a sphere met a sphere or a box");
}
