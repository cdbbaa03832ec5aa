use super::*;
use crate::bounding::{BoundingVolume, Obb, Rss};
use crate::budget::{Deadline, Unlimited, VisitBudget};
use crate::bvh::{BuildParams, Bvh};
use crate::geometry::TriMesh;
use crate::math::Isometry;
use crate::math::{DQuat, Pose};
use crate::narrow::distance_triangle_triangle;
use crate::narrow::mesh_mesh::{
    DistanceCache, DistanceParams, MeshDistance, MeshMeshWorkspace, distance_mesh_mesh,
};
use std::time::Instant;

fn entry(bound: f64, pair: u32, a: u32, b: u32) -> Entry {
    Entry {
        bound,
        pair,
        a,
        b,
        depth: 1,
    }
}

/// Two tori (leaf size 4) at three poses: touching, a little apart, far apart.
fn scene<B: BoundingVolume>() -> (Bvh<B>, Bvh<B>, Vec<Pose>) {
    let params = BuildParams::BINNED_SAH.with_leaf_size(4);
    let a = Bvh::from_mesh(&TriMesh::torus(1.0, 0.3, 16, 8), &params);
    let b = Bvh::from_mesh(&TriMesh::torus(0.8, 0.25, 12, 6), &params);
    let turn = DQuat::from_rotation_x(1.2);
    let poses = [0.9, 2.5, 6.0]
        .map(|x| Pose::new(DVec3::new(x, 0.1, 0.05), turn))
        .to_vec();
    (a, b, poses)
}

fn pairs<'a, B>(a: &'a Bvh<B>, b: &'a Bvh<B>, poses: &[Pose]) -> Vec<FrontierPair<'a, B>> {
    poses
        .iter()
        .map(|pose| FrontierPair {
            a,
            b,
            pose_ab: pose.to_isometry(),
            threshold: 0.3,
            seed: None,
        })
        .collect()
}

/// Records the visit counts it was polled at, and refuses from `limit` on.
struct Recorder {
    limit: u64,
    polled_at: Vec<u64>,
}

impl Budget for Recorder {
    fn allows(&mut self, visits: u64) -> bool {
        self.polled_at.push(visits);
        visits < self.limit
    }
}

#[test]
fn entries_are_ordered_by_smallest_bound_then_pair_then_nodes() {
    let mut entries = [
        entry(0.5, 0, 1, 1),
        entry(0.1, 2, 3, 4),
        entry(0.1, 1, 9, 9),
        entry(0.1, 1, 2, 7),
        entry(0.1, 1, 2, 5),
        entry(0.0, 3, 0, 0),
    ];
    entries.sort_unstable_by(entry_order);
    let keys: Vec<_> = entries.iter().map(|e| (e.pair, e.a, e.b)).collect();
    assert_eq!(
        keys,
        [
            (3, 0, 0),
            (1, 2, 5),
            (1, 2, 7),
            (1, 9, 9),
            (2, 3, 4),
            (0, 1, 1)
        ]
    );
}

#[test]
fn every_round_is_processed_in_entry_order() {
    let (a, b, poses) = scene::<Obb>();
    let pairs = pairs(&a, &b, &poses);
    let mut ws = FrontierWorkspace::with_poll_every(1);
    ws.start(&pairs);
    let mut rounds_seen = 0;
    for limit in 1.. {
        let done = ws.run(&pairs, &mut VisitBudget(limit));
        if ws.cursor == 0 || done {
            assert!(ws.current.is_sorted_by(|x, y| entry_order(x, y).is_le()));
            rounds_seen += 1;
        }
        if done {
            break;
        }
    }
    assert!(rounds_seen >= 3, "{rounds_seen}");
}

#[test]
fn the_budget_is_polled_between_batches_and_never_inside_a_leaf_pair() {
    let (a, b, poses) = scene::<Rss>();
    let pairs = pairs(&a, &b, &poses);
    let unlimited = {
        let mut ws = FrontierWorkspace::new();
        ws.start(&pairs);
        assert!(ws.run(&pairs, &mut Unlimited));
        ws.stats().visits
    };
    // The most one entry or probe step costs: a root's bound and seed test (and, were
    // the root a leaf pair, its tests), two child bounds, or a leaf pair's 4 × 4
    // triangle tests (leaf size 4).
    let entry_cost = 2 + 16;
    for poll_every in [1, 5, 32] {
        for limit in (0..unlimited + 40).step_by(7) {
            let mut ws = FrontierWorkspace::with_poll_every(poll_every);
            let mut budget = Recorder {
                limit,
                polled_at: Vec::new(),
            };
            ws.start(&pairs);
            let done = ws.run(&pairs, &mut budget);
            let visits = ws.stats().visits;
            assert_eq!(
                budget.polled_at[0], 0,
                "the first poll comes before any work"
            );
            for w in budget.polled_at.windows(2) {
                assert!(w[1] >= w[0] + poll_every, "{poll_every}: {w:?}");
                assert!(w[1] < w[0] + poll_every + entry_cost, "{poll_every}: {w:?}");
            }
            assert_eq!(ws.stats().polls, budget.polled_at.len() as u64);
            if done {
                assert_eq!(visits, unlimited);
            } else {
                assert!(visits >= limit, "stopped early: {visits} < {limit}");
                assert_eq!(*budget.polled_at.last().unwrap(), visits);
                assert!(visits < limit.max(1) + poll_every + entry_cost);
            }
        }
    }
}

#[test]
fn a_zero_budget_or_a_past_deadline_does_no_work_and_answers_maybe_close() {
    let (a, b, poses) = scene::<Obb>();
    let pairs = pairs(&a, &b, &poses);
    let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
    let past = Instant::now();
    for finished in [
        query_frontier(&pairs, &mut VisitBudget(0), &mut ws, &mut out),
        query_frontier(&pairs, &mut Deadline(past), &mut ws, &mut out),
    ] {
        assert!(!finished);
        assert_eq!(ws.stats().visits, 0);
        assert_eq!(ws.entries_per_round(), [3]);
        for answer in &out {
            assert_eq!(answer.completeness, Completeness::Truncated { level: 0 });
            assert!(answer.maybe_close);
            assert_eq!(answer.distance_lower, 0.0);
            assert_eq!(answer.distance_upper, None);
            assert!(answer.error_bound.is_finite() && answer.error_bound > 0.0);
        }
    }
}

/// The exact mesh–mesh distance query's answer, cold.
fn exact_distance(a: &Bvh<Rss>, b: &Bvh<Rss>, pose: &Pose) -> MeshDistance {
    distance_mesh_mesh(
        a,
        b,
        pose,
        &DistanceParams::EXACT,
        &mut DistanceCache::new(),
        &mut MeshMeshWorkspace::new(),
    )
}

#[test]
fn an_unlimited_run_gives_the_exact_distance_query_answers() {
    let (a, b, poses) = scene::<Rss>();
    let pairs = pairs(&a, &b, &poses);
    let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
    assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut out));
    assert!(ws.is_finished());
    assert_eq!(ws.waiting(), 0);
    let stats = *ws.stats();
    assert_eq!(stats.visits, stats.bv_tests + stats.triangle_tests);
    assert_eq!(stats.rounds, ws.entries_per_round().len() as u64);
    let mut close = 0;
    for ((p, pose), answer) in pairs.iter().zip(&poses).zip(&out) {
        assert!(answer.is_exact());
        let exact = exact_distance(&a, &b, pose);
        assert_eq!(answer.maybe_close, exact.distance <= p.threshold);
        if answer.maybe_close {
            close += 1;
            assert_eq!(answer.distance_lower, exact.distance);
            assert_eq!(answer.distance_upper, Some(exact.distance));
            let w = answer.witnesses.unwrap();
            assert_eq!(w.point_a.distance(w.point_b), exact.distance);
        } else {
            assert!(answer.distance_lower > p.threshold);
            assert!(answer.distance_lower <= exact.distance);
            assert!(exact.distance <= answer.distance_lower + answer.error_bound);
        }
    }
    assert_eq!(
        close, 2,
        "touching and near pairs are close, the far one is not"
    );
}

#[test]
fn an_infinite_threshold_gives_every_pairs_exact_distance() {
    let (a, b, poses) = scene::<Rss>();
    let mut pairs = pairs(&a, &b, &poses);
    for p in &mut pairs {
        p.threshold = f64::INFINITY;
    }
    let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
    assert!(!query_frontier(
        &pairs,
        &mut VisitBudget(30),
        &mut ws,
        &mut out
    ));
    assert!(
        out.iter()
            .all(|x| x.maybe_close && x.error_bound.is_finite())
    );
    assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut out));
    for (pose, answer) in poses.iter().zip(&out) {
        let exact = exact_distance(&a, &b, pose);
        assert!(answer.is_exact() && answer.maybe_close);
        assert_eq!(answer.distance_lower, exact.distance);
        assert_eq!(answer.clamped_error_bound(), answer.error_bound);
    }
    assert!(out[2].distance_lower > 1.0, "the far pair is far");
}

#[test]
fn a_resumed_run_reaches_the_state_of_a_fresh_run_with_the_larger_budget() {
    let (a, b, poses) = scene::<Obb>();
    let pairs = pairs(&a, &b, &poses);
    let mut resumed = FrontierWorkspace::new();
    resumed.start(&pairs);
    let (mut fresh_out, mut resumed_out) = (Vec::new(), Vec::new());
    let mut fresh = FrontierWorkspace::new();
    for limit in (0..2000).step_by(13) {
        resumed.run(&pairs, &mut VisitBudget(limit));
        resumed.answers(&pairs, &mut resumed_out);
        query_frontier(&pairs, &mut VisitBudget(limit), &mut fresh, &mut fresh_out);
        // Polls differ (a refused poll is repeated on resuming); the work does not.
        let work = |s: &FrontierStats| FrontierStats { polls: 0, ..*s };
        assert_eq!(work(resumed.stats()), work(fresh.stats()), "{limit}");
        assert_eq!(resumed.entries_per_round(), fresh.entries_per_round());
        assert_eq!(resumed_out, fresh_out, "{limit}");
    }
}

/// Visits after which each pair's answer is first Exact, one visit a budget, and the
/// final answers.
fn settled_after(
    pairs: &[FrontierPair<'_, Obb>],
    order: RoundOrder,
) -> (Vec<u64>, Vec<FrontierAnswer>) {
    let mut ws = FrontierWorkspace::with_poll_every(1).with_order(order);
    ws.start(pairs);
    let (mut settled, mut out) = (vec![u64::MAX; pairs.len()], Vec::new());
    for limit in 0.. {
        let done = ws.run(pairs, &mut VisitBudget(limit));
        ws.answers(pairs, &mut out);
        for (at, answer) in settled.iter_mut().zip(&out) {
            if *at == u64::MAX && answer.is_exact() {
                *at = ws.stats().visits;
            }
        }
        if done {
            break;
        }
    }
    (settled, out)
}

/// Visits after which `done` first holds of the answers, one visit a budget (and
/// the final answers).
fn visits_until(
    pairs: &[FrontierPair<'_, Obb>],
    done: impl Fn(&[FrontierAnswer]) -> bool,
) -> (u64, Vec<FrontierAnswer>) {
    let mut ws = FrontierWorkspace::with_poll_every(1);
    ws.start(pairs);
    let mut out = Vec::new();
    let mut at = None;
    for limit in 0.. {
        let finished = ws.run(pairs, &mut VisitBudget(limit));
        ws.answers(pairs, &mut out);
        if at.is_none() && done(&out) {
            at = Some(ws.stats().visits);
        }
        if finished {
            break;
        }
    }
    (at.expect("holds once every answer is exact"), out)
}

/// The exact answer of one pair on its own (its closest triangles, when within the
/// threshold).
fn alone(pair: &FrontierPair<'_, Obb>) -> FrontierAnswer {
    let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
    assert!(query_frontier(&[*pair], &mut Unlimited, &mut ws, &mut out));
    out[0]
}

/// A pair proven close by its seed, or expected close because it has one (seed no
/// longer within the threshold), waits while an undecided pair is settled: that pair
/// is answered exactly after its own visits plus the waiting root's bound and seed
/// test, where without a seed the touching pair's probe comes first. The final answers
/// are each pair's own.
#[test]
fn pairs_proven_or_expected_close_wait_while_an_undecided_pair_is_settled() {
    let (a, b, poses) = scene::<Obb>();
    let [touching, near] = pairs(&a, &b, &[poses[0], poses[1]])
        .try_into()
        .expect("two pairs");
    // The tori a little apart, 0.17 m, beyond a threshold of 0.1 m.
    let apart = FrontierPair {
        threshold: 0.1,
        ..near
    };
    assert!(!alone(&apart).maybe_close);
    let (undecided_alone, _) = visits_until(&[apart], |x| x[0].is_exact());
    let closest = alone(&touching).witnesses.expect("close").triangles;
    // A triangle pair of the touching tori farther apart than the threshold.
    let stale = [0, 0];
    let stale_distance = distance_triangle_triangle(
        &a.triangles()[a.slot_of(0).expect("id 0")],
        &b.triangles()[b.slot_of(0).expect("id 0")].transformed(&touching.pose_ab),
    )
    .distance;
    assert!(stale_distance > touching.threshold, "{stale_distance}");
    for seed in [closest, stale] {
        let seeded = FrontierPair {
            seed: Some(seed),
            ..touching
        };
        let both = [seeded, apart];
        let (settled, answers) = visits_until(&both, |x| x[1].is_exact());
        assert_eq!(settled, undecided_alone + 2, "seed {seed:?}");
        assert_eq!(answers[0].distance_lower, alone(&seeded).distance_lower);
        assert_eq!(answers[1], alone(&apart), "seed {seed:?}");
    }
    let (unseeded, _) = visits_until(&[touching, apart], |x| x[1].is_exact());
    assert!(
        unseeded > undecided_alone + 2,
        "{unseeded} {undecided_alone}"
    );
}

/// A pair expected close waits only until the stages reach [`EXPECTED_JOIN_CAP`]: beside
/// a wide undecided pair (a small torus inside a large one, in its plane, apart all
/// around the ring by a little more than the threshold), the touching pair with a
/// stale seed is proven close before the wide pair is settled, where it would otherwise
/// wait for it. The final answers are each pair's own.
#[test]
fn an_expected_pair_joins_the_deciding_phase_once_the_stages_reach_the_join_cap() {
    let (a, b, poses) = scene::<Obb>();
    let params = BuildParams::BINNED_SAH.with_leaf_size(4);
    let inner = Bvh::from_mesh(&TriMesh::torus(0.5, 0.15, 16, 8), &params);
    let wide = FrontierPair {
        a: &a,
        b: &inner,
        pose_ab: Isometry::IDENTITY,
        threshold: 0.02,
        seed: None,
    };
    let wide_alone = alone(&wide);
    assert!(!wide_alone.maybe_close);
    let widest = {
        let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
        query_frontier(&[wide], &mut Unlimited, &mut ws, &mut out);
        ws.entries_per_round().iter().copied().max()
    };
    assert!(
        widest > Some(u64::from(EXPECTED_JOIN_CAP)),
        "widest round {widest:?}"
    );
    let touching = FrontierPair {
        seed: Some([0, 0]),
        ..pairs(&a, &b, &poses[..1])[0]
    };
    let (seed_distance, _) = touching.seed_distance().expect("a seed");
    assert!(seed_distance > touching.threshold, "{seed_distance}");
    let both = [touching, wide];
    let proven = |x: &[FrontierAnswer]| x[0].distance_upper.is_some_and(|d| d <= x[0].threshold);
    let (first_visit, _) = visits_until(&both, |x| x[0].distance_upper.is_some());
    let (proven_at, _) = visits_until(&both, proven);
    let (settled, answers) = visits_until(&both, |x| x[1].is_exact());
    assert_eq!(first_visit, 2, "the root's bound and the stale seed's test");
    assert!(proven_at > first_visit, "proven by its probe, not its seed");
    assert!(
        proven_at < settled,
        "proven at {proven_at}, settled at {settled}"
    );
    assert_eq!(answers[0].distance_lower, alone(&touching).distance_lower);
    assert_eq!(answers[1], wide_alone);
}

/// The probe proves touching tori close (a triangle pair within the threshold) within
/// its visits, where the rounds alone would first reach a leaf pair much later.
#[test]
fn the_probe_proves_a_touching_pair_close_within_its_visits() {
    let (a, b, poses) = scene::<Obb>();
    let touching = pairs(&a, &b, &poses[..1]);
    let proven = |x: &[FrontierAnswer]| x[0].distance_upper.is_some_and(|d| d <= x[0].threshold);
    let (at, answers) = visits_until(&touching, proven);
    // The root's bound, the probe, and the leaf pair it was testing when it ended.
    assert!(at <= 1 + PROBE_VISITS + 16, "{at}");
    assert!(answers[0].is_exact() && answers[0].maybe_close);
    let total = {
        let (mut ws, mut out) = (FrontierWorkspace::new(), Vec::new());
        query_frontier(&touching, &mut Unlimited, &mut ws, &mut out);
        ws.stats().visits
    };
    assert!(4 * at < total, "proven after {at} of {total} visits");
}

/// In stages, a pair that a few levels settle is not kept waiting by a wide one: the
/// tori a little apart (pair 1) are answered exactly after under half the visits they
/// wait in plain rounds, no pair later, and the final answers are the same.
#[test]
fn in_stages_a_narrow_pair_is_settled_before_a_wide_one_finishes() {
    let (a, b, poses) = scene::<Obb>();
    let pairs = pairs(&a, &b, &poses);
    let (plain, plain_answers) = settled_after(&pairs, RoundOrder::SmallestBound);
    let (staged, staged_answers) = settled_after(&pairs, RoundOrder::CheapestPairsFirst);
    assert!(
        2 * staged[1] < plain[1],
        "staged {staged:?}, plain {plain:?}"
    );
    assert!(
        staged.iter().zip(&plain).all(|(s, p)| s <= p),
        "{staged:?} {plain:?}"
    );
    assert_eq!(staged_answers, plain_answers);
}

#[test]
fn an_empty_frame_finishes_at_once() {
    let pairs: [FrontierPair<'_, Obb>; 0] = [];
    let (mut ws, mut out) = (FrontierWorkspace::new(), vec![]);
    assert!(query_frontier(
        &pairs,
        &mut VisitBudget(0),
        &mut ws,
        &mut out
    ));
    assert!(out.is_empty() && ws.is_finished());
    assert_eq!(ws.stats().visits, 0);
}

#[test]
fn single_triangle_meshes_are_answered_from_their_root_pair() {
    use crate::geometry::Triangle;
    let tri = Triangle::new(DVec3::ZERO, DVec3::X, DVec3::Y);
    let t = Bvh::<Obb>::from_triangles(&[tri], &BuildParams::MEDIAN);
    let pairs = [0.5, 2.0].map(|z| FrontierPair {
        a: &t,
        b: &t,
        pose_ab: Isometry::from_translation(DVec3::new(0.0, 0.0, z)),
        threshold: 1.0,
        seed: None,
    });
    let (mut ws, mut out) = (FrontierWorkspace::new(), vec![]);
    assert!(query_frontier(&pairs, &mut Unlimited, &mut ws, &mut out));
    // One bound per root, then one triangle test for the pair within threshold.
    assert_eq!(ws.stats().bv_tests, 2);
    assert_eq!(ws.stats().triangle_tests, 1);
    assert_eq!(ws.stats().rounds, 1);
    assert!(out[0].maybe_close && out[0].is_exact());
    let exact = distance_triangle_triangle(&tri, &tri.transformed(&pairs[0].pose_ab));
    assert_eq!(out[0].distance_lower, exact.distance);
    assert!((exact.distance - 0.5).abs() <= out[0].error_bound);
    assert!(!out[1].maybe_close && out[1].is_exact());
    assert!(out[1].distance_lower > 1.0 && out[1].distance_lower <= 2.0);
    assert_eq!(out[1].distance_upper, None);
    assert!(2.0 <= out[1].distance_lower + out[1].error_bound);
}

/// Allows work while at most `cap` entries would be left waiting; records the most seen.
struct PendingCap {
    cap: u64,
    most_seen: u64,
}

impl Budget for PendingCap {
    fn allows(&mut self, _visits: u64) -> bool {
        true
    }

    fn allows_pending(&mut self, _visits: u64, pending: u64) -> bool {
        self.most_seen = self.most_seen.max(pending);
        pending <= self.cap
    }
}

#[test]
fn every_poll_tells_the_budget_the_waiting_entries_so_it_can_stop_the_frontier_growing() {
    let (a, b, poses) = scene::<Obb>();
    let pairs = pairs(&a, &b, &poses);
    let poll_every = 1;
    let peak = {
        let mut ws = FrontierWorkspace::with_poll_every(poll_every);
        let mut budget = PendingCap {
            cap: u64::MAX,
            most_seen: 0,
        };
        ws.start(&pairs);
        assert!(ws.run(&pairs, &mut budget));
        budget.most_seen
    };
    // Between two polls one entry is processed, adding at most its 4 children (or a probe
    // step's): the cap holds to within that growth.
    let growth = 4;
    assert!(peak > 8 * growth, "the scene's frontier grows: peak {peak}");
    for cap in [8, peak / 4, peak / 2] {
        let mut ws = FrontierWorkspace::with_poll_every(poll_every);
        let mut budget = PendingCap { cap, most_seen: 0 };
        ws.start(&pairs);
        assert!(
            !ws.run(&pairs, &mut budget),
            "cap {cap} of peak {peak} stops the run"
        );
        assert!(
            ws.waiting() as u64 > cap && ws.waiting() as u64 <= cap + growth,
            "cap {cap}: {} waiting",
            ws.waiting()
        );
        let mut answers = Vec::new();
        ws.answers(&pairs, &mut answers);
        assert!(
            answers.iter().any(|a| !a.is_exact()),
            "cap {cap}: cut short"
        );
    }
}
