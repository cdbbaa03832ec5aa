//! Pose frames in, result frames out, through the real `proximad` over shared memory:
//! results equal the in-process pipeline's on the same scene, bad frames are answered with
//! their code and the offending body while other clients keep being served.

#[path = "support/daemon.rs"]
mod daemon_harness;
mod support;

use daemon_harness::{Daemon, body};
use proxima::geometry::Sphere;
use proxima::math::{DQuat, DVec3, Pose};
use proxima::pipeline::{PipelineWorkspace, step};
use proxima::scene::{BodyDesc, CollisionFilter, Motion as SceneMotion, Scene, SceneLimits, Shape};
use proxima_ipc::client::{BodySpec, Primitive};
use proxima_ipc::wire::{ErrorCode, PoseRecord, RecordKind, query};
use rand::Rng;
use std::time::Duration;

const TIMEOUT: Duration = Duration::from_secs(10);

fn pose_record(body: u32, p: DVec3) -> PoseRecord {
    PoseRecord {
        body,
        reserved: 0,
        position: p.to_array(),
        orientation: [0.0, 0.0, 0.0, 1.0],
    }
}

#[test]
fn frames_of_moving_spheres_get_the_in_process_pipelines_answer() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene_id = client.create_scene().unwrap();
    let link = client.open_scene(scene_id).unwrap();
    let mut rng = support::rng(81);
    let radii: Vec<f64> = (0..40).map(|_| rng.random_range(0.05..0.4)).collect();
    // The same scene in process, as the oracle.
    let mut oracle = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    for &r in &radii {
        let shape = client
            .register_primitive(scene_id, Primitive::Sphere { radius: r })
            .unwrap();
        let spec = BodySpec {
            margin: Some(0.05),
            ..body(shape, 0.0)
        };
        client.add_body(scene_id, &spec).unwrap();
        let local = oracle
            .register_shape(Shape::Sphere(Sphere::new(r)))
            .unwrap();
        let desc = BodyDesc {
            shape: local,
            pose: Pose::IDENTITY,
            motion: SceneMotion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: Some(0.05),
        };
        oracle.add_body(&desc).unwrap();
    }
    let mut workspace = PipelineWorkspace::default();
    let (mut total_pairs, mut empty_frames) = (0, 0);
    for frame in 1..=50u64 {
        let positions: Vec<DVec3> = radii
            .iter()
            .map(|_| support::point_in_cube(&mut rng, 1.5))
            .collect();
        let records: Vec<PoseRecord> = positions
            .iter()
            .enumerate()
            .map(|(i, &p)| pose_record(i as u32, p))
            .collect();
        link.publish_poses(frame, 0, query::CLOSE, &records)
            .unwrap();
        for (i, &p) in positions.iter().enumerate() {
            oracle
                .set_pose(
                    proxima::scene::BodyId(i as u32),
                    Pose::new(p, DQuat::IDENTITY),
                )
                .unwrap();
        }
        let mut expected = Vec::new();
        step(&oracle, &mut workspace, |r| expected.push(*r));
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
        assert_eq!(header.pair_count as usize, expected.len(), "frame {frame}");
        for (got, want) in result.pairs().iter().zip(&expected) {
            assert_eq!(got.kind, RecordKind::Pair as u32);
            assert_eq!((got.body_a, got.body_b), (want.a, want.b));
            assert_eq!(got.distance, want.distance);
            assert_eq!(got.normal, want.normal.to_array());
            assert_eq!(
                (got.point_a, got.point_b),
                (want.point_a.to_array(), want.point_b.to_array())
            );
        }
        total_pairs += expected.len();
        empty_frames += usize::from(expected.is_empty());
    }
    assert!(
        total_pairs > 100 && empty_frames < 50,
        "pairs {total_pairs}"
    );
}

#[test]
fn a_bad_frame_is_answered_with_its_code_and_body_and_another_client_keeps_going() {
    let daemon = Daemon::start();
    let (bad_client, good_client) = (daemon.client(), daemon.client());
    let scene_id = good_client.create_scene().unwrap();
    let sphere = good_client
        .register_primitive(scene_id, Primitive::Sphere { radius: 0.5 })
        .unwrap();
    for x in [0.0, 0.9] {
        let spec = body(sphere, x);
        good_client.add_body(scene_id, &spec).unwrap();
    }
    let (bad, good) = (
        bad_client.open_scene(scene_id).unwrap(),
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
