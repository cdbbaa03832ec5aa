//! Pose frames in, result frames out, through the real `proximad` over shared memory:
//! for every combination of query flags the result frame holds exactly what the in-process
//! pipeline returns on the same scene and poses (pairs, then contacts linked by
//! index/count, then time-of-impact records over the motion since the previous frame);
//! bad frames are answered with their code and the offending body while other clients keep
//! being served; undefined and empty flags are refused.

#[path = "support/daemon.rs"]
mod daemon_harness;
mod support;

use daemon_harness::{Daemon, body, register_trimesh};
use iceoryx2::prelude::ipc;
use proxima::geometry::{Cuboid, Sphere};
use proxima::math::{DQuat, DVec3, Pose};
use proxima::narrow::{MeshShape, Shape};
use proxima::pipeline::{FrameResults, PipelineWorkspace, Query, StepReport, step};
use proxima::scene::{
    BodyDesc, BodyId, CollisionFilter, Motion as SceneMotion, Scene, SceneLimits,
};
use proxima_ipc::client::{BodySpec, Client, Primitive};
use proxima_ipc::scene_link::{ResultFrame, SceneLink};
use proxima_ipc::wire::{self, ErrorCode, PoseRecord, RecordKind, ResultRecord, query};
use rand::Rng;
use std::sync::Arc;
use std::time::Duration;

const TIMEOUT: Duration = Duration::from_secs(10);
const MARGIN: f64 = 0.1;

fn pose_record(body: u32, p: DVec3) -> PoseRecord {
    posed_record(body, &Pose::new(p, DQuat::IDENTITY))
}

/// The wire record of `body` at `pose`.
fn posed_record(body: u32, pose: &Pose) -> PoseRecord {
    let r = pose.rotation;
    PoseRecord {
        body,
        reserved: 0,
        position: pose.position.to_array(),
        orientation: [r.x, r.y, r.z, r.w],
    }
}

/// The wire flags of a typed query.
fn flags(q: Query) -> u32 {
    [
        (q.overlap, query::OVERLAP),
        (q.close, query::CLOSE),
        (q.distance, query::DISTANCE),
        (q.contacts, query::CONTACTS),
        (q.toi, query::TOI),
    ]
    .iter()
    .filter(|(on, _)| *on)
    .fold(0, |bits, (_, bit)| bits | bit)
}

/// A scene of spheres, tori (meshes) and boxes (box answers) registered both in the daemon
/// and in process, body for body, with the same ids.
struct TwinScenes {
    scene_id: u32,
    oracle: Scene,
}

fn twin_scenes(client: &Client<ipc::Service>) -> TwinScenes {
    let scene_id = client.create_scene().unwrap();
    let mut oracle = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let torus = support::meshes::torus(0.5, 0.15, 16, 8);
    let torus_id = register_trimesh(client, scene_id, &torus).unwrap();
    let torus_local = oracle
        .register_shape(Shape::Mesh(Arc::new(MeshShape::new(torus))))
        .unwrap();
    let box_id = client
        .register_primitive(
            scene_id,
            Primitive::Cuboid {
                half_extents: [0.2, 0.3, 0.25],
            },
        )
        .unwrap();
    let box_local = oracle
        .register_shape(Shape::Cuboid(Cuboid::new(DVec3::new(0.2, 0.3, 0.25))))
        .unwrap();
    let mut rng = support::rng(83);
    for i in 0..24 {
        let (remote, local) = match i % 6 {
            0 | 1 => (torus_id, torus_local),
            2 => (box_id, box_local),
            _ => {
                let r = rng.random_range(0.1..0.35);
                let remote = client
                    .register_primitive(scene_id, Primitive::Sphere { radius: r })
                    .unwrap();
                let local = oracle
                    .register_shape(Shape::Sphere(Sphere::new(r)))
                    .unwrap();
                (remote, local)
            }
        };
        let spec = BodySpec {
            margin: Some(MARGIN),
            ..body(remote, 0.0)
        };
        let id = client.add_body(scene_id, &spec).unwrap();
        let desc = BodyDesc {
            shape: local,
            pose: Pose::IDENTITY,
            motion: SceneMotion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: Some(MARGIN),
        };
        assert_eq!(oracle.add_body(&desc).unwrap(), BodyId(id));
    }
    TwinScenes { scene_id, oracle }
}

/// The wire flags of an answer that is `exact` or not.
fn approximate_flag(exact: bool) -> u32 {
    if exact {
        0
    } else {
        wire::record_flags::APPROXIMATE
    }
}

/// The records of a result frame equal, field for field, to the in-process `expected`
/// (pairs, then contacts, then times of impact), flags included.
fn assert_same_records(records: &[ResultRecord], expected: &FrameResults, frame: u64) {
    let (pairs, rest) = records.split_at(expected.pairs.len());
    let (contacts, tois) = rest.split_at(expected.contacts.len());
    assert_eq!(tois.len(), expected.tois.len(), "frame {frame}");
    for (got, want) in tois.iter().zip(&expected.tois) {
        let want = ResultRecord {
            kind: RecordKind::Toi as u32,
            body_a: want.a,
            body_b: want.b,
            index: 0,
            count: u32::from(want.reached),
            flags: approximate_flag(want.exact),
            distance: want.distance,
            error_bound: want.error_bound,
            point_a: want.point_a.to_array(),
            point_b: want.point_b.to_array(),
            normal: want.normal.to_array(),
            time: want.time,
        };
        assert_eq!(*got, want, "frame {frame}");
    }
    for (got, want) in pairs.iter().zip(&expected.pairs) {
        let want = ResultRecord {
            kind: RecordKind::Pair as u32,
            body_a: want.a,
            body_b: want.b,
            index: want.first_contact,
            count: want.contact_count,
            flags: approximate_flag(want.exact),
            distance: want.distance,
            error_bound: want.error_bound,
            point_a: want.point_a.to_array(),
            point_b: want.point_b.to_array(),
            normal: want.normal.to_array(),
            time: 0.0,
        };
        assert_eq!(*got, want, "frame {frame}");
    }
    for (got, want) in contacts.iter().zip(&expected.contacts) {
        let pair = &expected.pairs[want.pair as usize];
        let want = ResultRecord {
            kind: RecordKind::Contact as u32,
            body_a: pair.a,
            body_b: pair.b,
            index: want.pair,
            count: 0,
            flags: approximate_flag(pair.exact),
            distance: want.distance,
            error_bound: want.error_bound,
            point_a: want.point_a.to_array(),
            point_b: want.point_b.to_array(),
            normal: want.normal.to_array(),
            time: 0.0,
        };
        assert_eq!(*got, want, "frame {frame}");
    }
}

/// Every pair's `index`/`count` runs over contact records that name it back (what
/// `contacts_of` returns), and together they cover the contacts exactly once, in pair order.
/// Publishes `records` as frame `frame` asking `q`, moves the in-process `oracle` the
/// same way and steps it, then checks the daemon's result frame against it: status, counts,
/// and every record ([`assert_same_records`], [`assert_linked`]). Returns the result frame
/// and the in-process report.
fn publish_and_compare(
    link: &SceneLink<ipc::Service>,
    oracle: &mut Scene,
    (workspace, expected): (&mut PipelineWorkspace, &mut FrameResults),
    frame: u64,
    q: Query,
    records: &[PoseRecord],
) -> (ResultFrame<ipc::Service>, StepReport) {
    link.publish_poses(frame, 0, flags(q), records).unwrap();
    for r in records {
        let [x, y, z, w] = r.orientation;
        let pose = Pose::try_new(DVec3::from(r.position), DQuat::from_xyzw(x, y, z, w)).unwrap();
        oracle.set_pose(BodyId(r.body), pose).unwrap();
    }
    let report = step(oracle, q, workspace, expected);
    oracle.end_frame();
    let result = link
        .receive_results_for(frame, TIMEOUT)
        .unwrap()
        .expect("a result frame");
    let header = result.header();
    assert_eq!(ErrorCode::from_u32(header.status), Some(ErrorCode::Ok));
    assert_eq!(
        (
            header.candidate_count,
            header.pair_count,
            header.contact_count,
            header.toi_count
        ),
        (
            report.candidates.max(report.toi_candidates),
            report.pairs,
            report.contacts,
            report.tois
        ),
        "frame {frame} {q:?}"
    );
    assert_eq!(
        result.records().len(),
        expected.pairs.len() + expected.contacts.len() + expected.tois.len()
    );
    assert_same_records(result.records(), expected, frame);
    assert_linked(&result);
    (result, report)
}

fn assert_linked(frame: &ResultFrame<ipc::Service>) {
    let (pairs, contacts) = (frame.pairs(), frame.contacts());
    let mut next = 0;
    for (i, pair) in pairs.iter().enumerate() {
        assert_eq!(pair.kind, RecordKind::Pair as u32);
        assert!(pair.count <= wire::MAX_CONTACTS_PER_PAIR);
        let linked = frame.contacts_of(pair);
        assert_eq!(linked.len(), pair.count as usize);
        if pair.count == 0 {
            continue;
        }
        assert_eq!(pair.index as usize, next);
        next += linked.len();
        assert_eq!(linked, &contacts[pair.index as usize..next]);
        for c in linked {
            assert_eq!(c.kind, RecordKind::Contact as u32);
            assert_eq!(
                (c.index as usize, c.body_a, c.body_b),
                (i, pair.body_a, pair.body_b)
            );
        }
    }
    assert_eq!(next, contacts.len());
}

/// `pose` turned by a random rotation of up to `turn` radians about each axis, then moved
/// by up to `shift` metres along each (the draws in that order).
fn jittered(pose: &Pose, rng: &mut support::TestRng, turn: f64, shift: f64) -> Pose {
    let turn = DQuat::from_scaled_axis(support::point_in_cube(rng, turn));
    Pose::new(
        pose.position + support::point_in_cube(rng, shift),
        (turn * pose.rotation).normalize(),
    )
}

/// `n` poses scattered over the twin scenes' 3.2 m cube, turned at random.
fn scattered_poses(rng: &mut support::TestRng, n: usize) -> Vec<Pose> {
    (0..n)
        .map(|_| Pose::new(support::point_in_cube(rng, 1.6), support::rotation(rng)))
        .collect()
}

#[test]
fn every_query_combination_gets_the_in_process_pipelines_answer_over_shared_memory() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let TwinScenes {
        scene_id,
        mut oracle,
    } = twin_scenes(&client);
    let link = client.open_scene(scene_id).unwrap();
    let mut rng = support::rng(81);
    let mut workspace = PipelineWorkspace::default();
    let mut expected = FrameResults::default();
    let (mut pairs_seen, mut contacts_seen, mut truncated) = (0, 0, 0);
    let queries: Vec<Query> = (1u32..16)
        .map(|bits| Query {
            overlap: bits & 1 != 0,
            close: bits & 2 != 0,
            distance: bits & 4 != 0,
            contacts: bits & 8 != 0,
            toi: false,
        })
        .collect();
    for frame in 1..=45u64 {
        let q = queries[(frame as usize - 1) % queries.len()];
        let records: Vec<PoseRecord> = (0..oracle.body_count() as u32)
            .map(|i| {
                let at = support::point_in_cube(&mut rng, 1.3);
                posed_record(i, &Pose::new(at, support::rotation(&mut rng)))
            })
            .collect();
        link.publish_poses(frame, 0, flags(q), &records).unwrap();
        for r in &records {
            let [x, y, z, w] = r.orientation;
            let pose =
                Pose::try_new(DVec3::from(r.position), DQuat::from_xyzw(x, y, z, w)).unwrap();
            oracle.set_pose(BodyId(r.body), pose).unwrap();
        }
        let report: StepReport = step(&oracle, q, &mut workspace, &mut expected);
        // The daemon ends the frame once answered: the next one's motion starts here.
        oracle.end_frame();
        let result = link
            .receive_results_for(frame, TIMEOUT)
            .unwrap()
            .expect("a result frame");
        let header = result.header();
        assert_eq!(
            ErrorCode::from_u32(header.status),
            Some(ErrorCode::Ok),
            "frame {frame}"
        );
        assert_eq!(header.budget_met, 1);
        assert_eq!(
            (
                header.candidate_count,
                header.pair_count,
                header.contact_count
            ),
            (report.candidates, report.pairs, report.contacts),
            "frame {frame} {q:?}"
        );
        let completeness = match report.completeness {
            proxima::pipeline::Completeness::Exact => wire::Completeness::Exact,
            proxima::pipeline::Completeness::Truncated { .. } => wire::Completeness::Truncated,
        };
        assert_eq!(header.completeness, completeness as u32);
        assert_eq!(
            result.records().len(),
            expected.pairs.len() + expected.contacts.len()
        );
        assert_same_records(result.records(), &expected, frame);
        assert_linked(&result);
        assert!(header.stage_ns[wire::stage::NARROW] > 0 || report.candidates == 0);
        pairs_seen += expected.pairs.len();
        contacts_seen += expected.contacts.len();
        truncated += usize::from(completeness == wire::Completeness::Truncated);
    }
    // Every pair of shape kinds in the scene has an exact narrow phase: no frame is
    // truncated.
    assert!(
        pairs_seen > 100 && contacts_seen > 30 && truncated == 0,
        "pairs {pairs_seen}, contacts {contacts_seen}, truncated {truncated}"
    );
}

#[test]
fn empty_and_undefined_query_flags_are_refused_and_the_scene_is_untouched() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene_id = client.create_scene().unwrap();
    let sphere = client
        .register_primitive(scene_id, Primitive::Sphere { radius: 0.5 })
        .unwrap();
    for x in [0.0, 0.9] {
        client.add_body(scene_id, &body(sphere, x)).unwrap();
    }
    // A second link of the owner's: its own publisher and subscriber on the scene.
    let access = client.scene_access(scene_id).unwrap();
    let (link, other) = (
        client.open_scene(scene_id).unwrap(),
        SceneLink::open(client.node(), client.root(), &access).unwrap(),
    );
    let mut seq = 0;
    for bad in [0, query::TOI | 1 << 5, 1 << 5, query::CLOSE | 1 << 31] {
        seq += 1;
        // A refused frame must not move body 1 away.
        link.publish_poses(seq, 0, bad, &[pose_record(1, DVec3::new(5.0, 0.0, 0.0))])
            .unwrap();
        let answer = link
            .receive_results_for(seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        let header = answer.header();
        assert_eq!(
            ErrorCode::from_u32(header.status),
            Some(ErrorCode::MalformedMessage),
            "flags {bad:#x}"
        );
        assert_eq!(
            (header.error_body, header.pair_count, header.contact_count),
            (u32::MAX, 0, 0)
        );
        assert!(answer.records().is_empty());
        seq += 1;
        other
            .publish_poses(seq, 0, query::OVERLAP | query::CONTACTS, &[])
            .unwrap();
        let answer = other
            .receive_results_for(seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        assert_eq!(
            ErrorCode::from_u32(answer.header().status),
            Some(ErrorCode::Ok)
        );
        let (pairs, contacts) = (answer.pairs(), answer.contacts());
        assert_eq!((pairs.len(), contacts.len()), (1, 1), "flags {bad:#x}");
        assert!((pairs[0].distance - (0.9 - 1.0)).abs() < 1e-12);
        assert_eq!((pairs[0].index, pairs[0].count), (0, 1));
        assert_eq!(contacts[0].distance, pairs[0].distance);
    }
}

#[test]
fn a_bad_frame_is_answered_with_its_code_and_body_and_another_link_keeps_going() {
    let daemon = Daemon::start();
    let good_client = daemon.client();
    let scene_id = good_client.create_scene().unwrap();
    let sphere = good_client
        .register_primitive(scene_id, Primitive::Sphere { radius: 0.5 })
        .unwrap();
    for x in [0.0, 0.9] {
        let spec = body(sphere, x);
        good_client.add_body(scene_id, &spec).unwrap();
    }
    // The owner's two links to the scene (another client holds no keys to it).
    let access = good_client.scene_access(scene_id).unwrap();
    let (bad, good) = (
        SceneLink::open(good_client.node(), good_client.root(), &access).unwrap(),
        good_client.open_scene(scene_id).unwrap(),
    );
    let nan = PoseRecord {
        position: [f64::NAN, 0.0, 0.0],
        ..pose_record(1, DVec3::ZERO)
    };
    let long = PoseRecord {
        orientation: [0.0, 0.0, 0.0, 1.5],
        ..pose_record(0, DVec3::ZERO)
    };
    let cases = [
        (
            vec![pose_record(0, DVec3::X), nan],
            ErrorCode::InvalidPose,
            1,
        ),
        (vec![long], ErrorCode::InvalidPose, 0),
        (vec![pose_record(7, DVec3::ZERO)], ErrorCode::UnknownBody, 7),
    ];
    let mut seq = 0;
    for (records, code, body) in cases {
        seq += 1;
        bad.publish_poses(seq, 0, query::CLOSE, &records).unwrap();
        let answer = bad
            .receive_results_for(seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        assert_eq!(
            ErrorCode::from_u32(answer.header().status),
            Some(code),
            "frame {seq}"
        );
        assert_eq!(answer.header().error_body, body);
        assert_eq!(answer.header().pair_count, 0);
        // The scene was not touched: the good client's frame sees the bodies where they were.
        seq += 1;
        good.publish_poses(
            seq,
            0,
            query::CLOSE,
            &[pose_record(1, DVec3::new(0.9, 0.0, 0.0))],
        )
        .unwrap();
        let answer = good
            .receive_results_for(seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        assert_eq!(
            ErrorCode::from_u32(answer.header().status),
            Some(ErrorCode::Ok)
        );
        let pairs = answer.pairs();
        assert_eq!(pairs.len(), 1);
        assert!(
            (pairs[0].distance - (0.9 - 1.0)).abs() < 1e-12,
            "{}",
            pairs[0].distance
        );
    }
}

/// Coherent motion frame after frame (some bodies left where they are, so static ones
/// pair with moving ones), queries with `TOI` alone and combined: the daemon's result
/// frames hold record for record what the in-process pipeline gives on the same scene,
/// whose frames end where the daemon's do. Times of impact both at the start (`t = 0`)
/// and during the motion occur.
#[test]
fn toi_frames_over_shared_memory_match_the_in_process_pipeline_record_for_record() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let TwinScenes {
        scene_id,
        mut oracle,
    } = twin_scenes(&client);
    let link = client.open_scene(scene_id).unwrap();
    let mut rng = support::rng(87);
    let mut workspace = PipelineWorkspace::default();
    let mut expected = FrameResults::default();
    let queries = [
        Query::TOI,
        Query::CLOSE.union(Query::TOI),
        Query::TOI.union(Query::CONTACTS).union(Query::DISTANCE),
        Query::OVERLAP.union(Query::TOI),
        Query::CLOSE,
    ];
    let mut poses = scattered_poses(&mut rng, oracle.body_count());
    let (mut at_start, mut during, mut toi_frames) = (0, 0, 0);
    for frame in 1..=15u64 {
        let q = queries[(frame as usize - 1) % queries.len()];
        let mut records = Vec::new();
        for (i, pose) in poses.iter_mut().enumerate() {
            // Every fourth body rests this frame (after the first, which places them all).
            if frame > 1 && (i + frame as usize).is_multiple_of(4) {
                continue;
            }
            if frame > 1 {
                *pose = jittered(pose, &mut rng, 0.3, 0.35);
            }
            records.push(posed_record(i as u32, pose));
        }
        let (result, report) = publish_and_compare(
            &link,
            &mut oracle,
            (&mut workspace, &mut expected),
            frame,
            q,
            &records,
        );
        assert_eq!(result.tois().len(), expected.tois.len());
        assert!(
            result
                .tois()
                .iter()
                .all(|r| r.kind == RecordKind::Toi as u32 && (0.0..=1.0).contains(&r.time))
        );
        if q.toi {
            toi_frames += 1;
            assert!(report.toi_candidates >= report.candidates);
        } else {
            assert!(result.tois().is_empty());
        }
        at_start += expected.tois.iter().filter(|t| t.time == 0.0).count();
        during += expected.tois.iter().filter(|t| t.time > 0.0).count();
    }
    assert!(
        toi_frames == 12 && at_start > 10 && during > 5,
        "TOI frames {toi_frames}, at the start {at_start}, during the motion {during}"
    );
}

/// A `TOI` frame with a 1 ns budget: the deadline has passed before the first search, so
/// every swept candidate comes back unsearched and flagged approximate (`time` 0, `count`
/// 0, the start boxes' conservative distance), record for record what the in-process
/// pipeline gives with a deadline already passed, in a frame the header calls `Truncated`.
#[test]
fn a_toi_frame_past_its_deadline_reports_its_candidates_unsearched_and_flagged() {
    use proxima::pipeline::{Deadline, step_within};
    let daemon = Daemon::start();
    let client = daemon.client();
    let TwinScenes {
        scene_id,
        mut oracle,
    } = twin_scenes(&client);
    let link = client.open_scene(scene_id).unwrap();
    let mut rng = support::rng(89);
    let mut workspace = PipelineWorkspace::default();
    let mut expected = FrameResults::default();
    let mut poses = scattered_poses(&mut rng, oracle.body_count());
    let records: Vec<_> = (0..poses.len())
        .map(|i| posed_record(i as u32, &poses[i]))
        .collect();
    publish_and_compare(
        &link,
        &mut oracle,
        (&mut workspace, &mut expected),
        1,
        Query::CLOSE,
        &records,
    );
    let mut records = Vec::new();
    for (i, pose) in poses.iter_mut().enumerate() {
        *pose = jittered(pose, &mut rng, 0.3, 0.35);
        records.push(posed_record(i as u32, pose));
        oracle.set_pose(BodyId(i as u32), *pose).unwrap();
    }
    link.publish_poses(2, 1, flags(Query::TOI), &records)
        .unwrap();
    let report = step_within(
        &oracle,
        Query::TOI,
        &mut Deadline(std::time::Instant::now()),
        &mut workspace,
        &mut expected,
    );
    oracle.end_frame();
    assert!(report.truncated_tois > 3, "{report:?}");
    let result = link
        .receive_results_for(2, TIMEOUT)
        .unwrap()
        .expect("a result frame");
    let header = result.header();
    assert_eq!(header.completeness, wire::Completeness::Truncated as u32);
    assert_eq!((header.deepest_level, header.budget_met), (0, 0));
    assert_same_records(result.records(), &expected, 2);
    assert_eq!(result.tois().len(), report.truncated_tois as usize);
    assert!(
        result.tois().iter().all(|r| {
            r.flags == wire::record_flags::APPROXIMATE && r.time == 0.0 && r.count == 0
        })
    );
}

/// The scene's broad phase fixed over the wire (`SetSceneParams`): incremental sweep and
/// prune for 20 frames, then the hash grid, then back to automatic, while a third of the
/// bodies move each frame (the rest rest, unlisted) and bodies are removed and added between
/// frames. The daemon's result frames hold record for record what the in-process pipeline
/// gives on the same scene with the same choice.
#[test]
fn frames_with_a_fixed_incremental_sap_or_hash_grid_match_the_in_process_pipeline() {
    use proxima::broad::{BroadPhaseChoice, BroadPhaseKind};
    use proxima_ipc::wire::BroadPhaseCode;
    let daemon = Daemon::start();
    let client = daemon.client();
    let TwinScenes {
        scene_id,
        mut oracle,
    } = twin_scenes(&client);
    // twin_scenes registers the torus, then the box: shape 1 is the box on both sides.
    assert!(matches!(
        oracle.shape(proxima::scene::ShapeId(1)),
        Some(Shape::Cuboid(_))
    ));
    let link = client.open_scene(scene_id).unwrap();
    let mut rng = support::rng(89);
    let mut workspace = PipelineWorkspace::default();
    let mut expected = FrameResults::default();
    let queries = [
        Query::CLOSE.union(Query::CONTACTS),
        Query::DISTANCE,
        Query::OVERLAP.union(Query::TOI),
    ];
    let mut poses: Vec<Option<Pose>> = (0..oracle.body_count())
        .map(|_| {
            Some(Pose::from_translation(support::point_in_cube(
                &mut rng, 1.6,
            )))
        })
        .collect();
    let mut pairs_seen = 0;
    for frame in 1..=60u64 {
        if frame % 20 == 1 {
            let (code, choice) = match frame / 20 {
                0 => (
                    BroadPhaseCode::IncrementalSap,
                    BroadPhaseChoice::Fixed(BroadPhaseKind::IncrementalSap),
                ),
                1 => (
                    BroadPhaseCode::HashGrid,
                    BroadPhaseChoice::Fixed(BroadPhaseKind::HashGrid),
                ),
                _ => (BroadPhaseCode::Auto, BroadPhaseChoice::Auto),
            };
            client.set_broad_phase(scene_id, code).unwrap();
            oracle.set_broad_phase(choice);
        }
        if frame % 5 == 0 {
            let live: Vec<usize> = (0..poses.len()).filter(|&i| poses[i].is_some()).collect();
            let gone = live[rng.random_range(0..live.len())];
            client.remove_body(scene_id, gone as u32).unwrap();
            oracle.remove_body(BodyId(gone as u32)).unwrap();
            poses[gone] = None;
            let at = support::point_in_cube(&mut rng, 1.6);
            let spec = BodySpec {
                margin: Some(MARGIN),
                ..body(1, 0.0)
            };
            let id = client
                .add_body(
                    scene_id,
                    &BodySpec {
                        position: at.to_array(),
                        ..spec
                    },
                )
                .unwrap();
            let desc = BodyDesc {
                shape: proxima::scene::ShapeId(1),
                pose: Pose::from_translation(at),
                motion: SceneMotion::Dynamic,
                filter: CollisionFilter::ALL,
                margin: Some(MARGIN),
            };
            assert_eq!(oracle.add_body(&desc).unwrap(), BodyId(id));
            assert_eq!(id as usize, gone, "the removed body's slot is taken again");
            poses[gone] = Some(desc.pose);
        }
        let q = queries[frame as usize % queries.len()];
        let mut records = Vec::new();
        for (i, pose) in poses.iter_mut().enumerate() {
            let Some(pose) = pose else { continue };
            if frame > 1 && !(i + frame as usize).is_multiple_of(3) {
                continue;
            }
            *pose = jittered(pose, &mut rng, 0.2, 0.2);
            records.push(posed_record(i as u32, pose));
        }
        let (_, report) = publish_and_compare(
            &link,
            &mut oracle,
            (&mut workspace, &mut expected),
            frame,
            q,
            &records,
        );
        if let BroadPhaseChoice::Fixed(kind) = oracle.broad_phase() {
            assert_eq!(report.broad_kind, Some(kind));
        }
        pairs_seen += expected.pairs.len();
    }
    assert!(pairs_seen > 100, "pairs {pairs_seen}");
}

/// Eight tori on a 4 × 2 grid, neighbours touching or near, registered in the daemon and
/// in process body for body; returns the scene ids and the frame's pose records.
fn twin_tori_pile(client: &Client<ipc::Service>) -> (TwinScenes, Vec<PoseRecord>) {
    let scene_id = client.create_scene().unwrap();
    let mut oracle = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let torus = support::meshes::torus(0.45, 0.12, 16, 8);
    let remote = register_trimesh(client, scene_id, &torus).unwrap();
    let local = oracle
        .register_shape(Shape::Mesh(Arc::new(MeshShape::new(torus))))
        .unwrap();
    let mut rng = support::rng(97);
    let mut records = Vec::new();
    for k in 0..8u32 {
        let spec = BodySpec {
            margin: Some(0.03),
            ..body(remote, 0.0)
        };
        let id = client.add_body(scene_id, &spec).unwrap();
        let desc = BodyDesc {
            shape: local,
            pose: Pose::IDENTITY,
            motion: SceneMotion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: Some(0.03),
        };
        assert_eq!(oracle.add_body(&desc).unwrap(), BodyId(id));
        let cell = DVec3::new(f64::from(k % 4) - 1.5, f64::from(k / 4) - 0.5, 0.0) * 0.85;
        let at = cell + support::point_in_cube(&mut rng, 0.2);
        records.push(posed_record(
            id,
            &Pose::new(at, support::rotation(&mut rng)),
        ));
    }
    for r in &records {
        let [x, y, z, w] = r.orientation;
        let pose = Pose::try_new(DVec3::from(r.position), DQuat::from_xyzw(x, y, z, w)).unwrap();
        oracle.set_pose(BodyId(r.body), pose).unwrap();
    }
    (TwinScenes { scene_id, oracle }, records)
}

/// The frame budget over shared memory: a torus pile frame with a 1 ns budget (less than
/// the pipeline's reserve, so the frontier does no work) comes back `Truncated` at level 0
/// with every truly touching pair reported with a contact and every close pair reported,
/// record for record what the in-process pipeline gives with a zero visit budget; the same
/// frame with budget 0 (none) comes back `Exact`, equal to the in-process `step`.
#[test]
fn a_budgeted_torus_pile_frame_is_truncated_and_conservative_and_budget_zero_is_exact() {
    use proxima::pipeline::{Completeness, VisitBudget, step_within};
    let daemon = Daemon::start();
    let client = daemon.client();
    let (
        TwinScenes {
            scene_id,
            mut oracle,
        },
        records,
    ) = twin_tori_pile(&client);
    let link = client.open_scene(scene_id).unwrap();
    let q = Query::CLOSE.union(Query::CONTACTS);
    // The truth: every candidate pair's exact distance.
    let mut truth = FrameResults::default();
    step(
        &oracle,
        Query::DISTANCE,
        &mut PipelineWorkspace::default(),
        &mut truth,
    );
    let touching: Vec<_> = truth.pairs.iter().filter(|p| p.distance <= 0.0).collect();
    let close: Vec<_> = truth.pairs.iter().filter(|p| p.distance <= 0.06).collect();
    assert!(
        touching.len() >= 3 && close.len() > touching.len(),
        "touching {}, close {}",
        touching.len(),
        close.len()
    );
    let mut workspace = PipelineWorkspace::default();
    let mut expected = FrameResults::default();

    link.publish_poses(1, 1, flags(q), &records).unwrap();
    let report = step_within(
        &oracle,
        q,
        &mut VisitBudget(0),
        &mut workspace,
        &mut expected,
    );
    oracle.end_frame();
    assert_eq!(report.completeness, Completeness::Truncated { level: 0 });
    let result = link
        .receive_results_for(1, TIMEOUT)
        .unwrap()
        .expect("a result frame");
    let header = result.header();
    assert_eq!(ErrorCode::from_u32(header.status), Some(ErrorCode::Ok));
    assert_eq!(
        header.completeness,
        wire::Completeness::Truncated as u32,
        "a 1 ns budget cannot be met"
    );
    assert_eq!(header.deepest_level, 0);
    assert_eq!(header.budget_met, 0);
    assert_same_records(result.records(), &expected, 1);
    assert_linked(&result);
    let approximate = |r: &ResultRecord| r.flags & wire::record_flags::APPROXIMATE != 0;
    assert!(
        result.pairs().iter().any(approximate),
        "a truncated frame marks its approximate records"
    );
    for t in &close {
        let got = result
            .pairs()
            .iter()
            .find(|p| (p.body_a, p.body_b) == (t.a, t.b))
            .unwrap_or_else(|| panic!("close pair {}–{} missed", t.a, t.b));
        assert!(got.distance <= t.distance + 1e-12);
        assert!(t.distance - got.distance <= got.error_bound + 1e-12);
        if t.distance <= 0.0 {
            assert!(
                got.count >= 1,
                "touching pair {}–{} without contact",
                t.a,
                t.b
            );
        }
    }

    link.publish_poses(2, 0, flags(q), &records).unwrap();
    for r in &records {
        let [x, y, z, w] = r.orientation;
        let pose = Pose::try_new(DVec3::from(r.position), DQuat::from_xyzw(x, y, z, w)).unwrap();
        oracle.set_pose(BodyId(r.body), pose).unwrap();
    }
    let report = step(&oracle, q, &mut workspace, &mut expected);
    oracle.end_frame();
    assert_eq!(report.completeness, Completeness::Exact);
    let result = link
        .receive_results_for(2, TIMEOUT)
        .unwrap()
        .expect("a result frame");
    let header = result.header();
    assert_eq!(header.completeness, wire::Completeness::Exact as u32);
    assert_eq!((header.deepest_level, header.budget_met), (0, 1));
    assert_eq!(header.stage_ns[wire::stage::MID], 0);
    assert_same_records(result.records(), &expected, 2);
    assert_linked(&result);
    assert_eq!(result.pairs().len(), close.len(), "exactly the close pairs");
    assert!(
        result.records().iter().all(|r| r.flags == 0),
        "an exact frame"
    );
}

/// A frame without a budget that takes longer than the frame thread's slice is finished on
/// the daemon's second thread: still exact and complete, and the scene's next frame follows
/// it in order.
#[test]
fn a_long_frame_without_a_budget_is_answered_exactly_and_in_order() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let sphere = proxima::geometry::TriMesh::uv_sphere(0.5, 48, 24);
    let mesh = register_trimesh(&client, scene, &sphere).unwrap();
    // Six coincident 2,304-triangle spheres: 15 pairs touching all over, far more work than
    // the slice (each pair's contacts are thousands of triangle pairs).
    let bodies: Vec<u32> = (0..6)
        .map(|_| client.add_body(scene, &body(mesh, 0.0)).unwrap())
        .collect();
    let link = client.open_scene(scene).unwrap();
    let at = |x: f64| -> Vec<PoseRecord> {
        (bodies.iter().enumerate())
            .map(|(i, &b)| daemon_harness::pose_at(b, x * i as f64))
            .collect()
    };
    link.publish_poses(1, 0, query::CONTACTS, &at(0.0)).unwrap();
    // The next frame is sent at once: it is answered after the first, never before it.
    link.publish_poses(2, 0, query::CONTACTS, &at(3.0)).unwrap();
    let first = link
        .receive_results_for(1, TIMEOUT)
        .unwrap()
        .expect("frame 1");
    let header = *first.header();
    assert_eq!(ErrorCode::from_u32(header.status), Some(ErrorCode::Ok));
    assert_eq!(header.completeness, wire::Completeness::Exact as u32);
    assert_eq!(
        header.pair_count, 15,
        "every pair of coincident spheres touches"
    );
    assert!(
        first
            .pairs()
            .iter()
            .all(|p| p.count > 0 && p.distance <= 0.0)
    );
    drop(first);
    let second = link
        .receive_results_for(2, TIMEOUT)
        .unwrap()
        .expect("frame 2");
    assert_eq!(
        second.header().completeness,
        wire::Completeness::Exact as u32
    );
    assert_eq!(second.header().pair_count, 0, "3 m apart, nothing touches");
}
