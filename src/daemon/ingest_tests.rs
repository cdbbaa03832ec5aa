use super::*;
use crate::geometry::Sphere;
use crate::narrow::Shape;
use crate::scene::{BodyDesc, CollisionFilter, Motion, SceneLimits};
use proxima_ipc::wire::query;

fn scene_with_bodies(n: usize) -> Scene {
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let shape = scene
        .register_shape(Shape::Sphere(Sphere::new(0.5)))
        .unwrap();
    for _ in 0..n {
        let desc = BodyDesc {
            shape,
            pose: Pose::IDENTITY,
            motion: Motion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: None,
        };
        scene.add_body(&desc).unwrap();
    }
    scene
}

fn header(count: usize) -> PoseFrameHeader {
    PoseFrameHeader {
        protocol_version: PROTOCOL_VERSION,
        scene: 4,
        frame_seq: 1,
        budget_ns: 0,
        query_flags: query::CLOSE,
        count: count as u32,
        frame_key: 0,
    }
}

fn record(body: u32, x: f64) -> PoseRecord {
    PoseRecord {
        body,
        reserved: 0,
        position: [x, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
    }
}

#[test]
fn a_valid_frame_moves_exactly_the_bodies_it_lists() {
    let mut scene = scene_with_bodies(3);
    let mut scratch = Vec::new();
    let records = [record(2, 5.0), record(0, -1.0)];
    apply_pose_frame(4, &mut scene, &header(2), &records, &mut scratch).unwrap();
    let x = |id| scene.body(BodyId(id)).unwrap().pose.position.x;
    assert_eq!((x(0), x(1), x(2)), (-1.0, 0.0, 5.0));
    assert_eq!(scene.validate(), Ok(()));
}

#[test]
fn a_bad_record_anywhere_rejects_the_whole_frame_and_names_its_body() {
    let bad = |records: Vec<PoseRecord>, header: PoseFrameHeader| {
        let mut scene = scene_with_bodies(3);
        let before = format!("{scene:?}");
        let result = apply_pose_frame(4, &mut scene, &header, &records, &mut Vec::new());
        assert_eq!(
            format!("{scene:?}"),
            before,
            "a rejected frame changed the scene"
        );
        let r = result.expect_err("rejected");
        (r.rejection.code, r.body)
    };
    let nan = PoseRecord {
        position: [0.0, f64::NAN, 0.0],
        ..record(1, 0.0)
    };
    let inf = PoseRecord {
        position: [f64::INFINITY, 0.0, 0.0],
        ..record(2, 0.0)
    };
    let long = PoseRecord {
        orientation: [0.0, 0.0, 0.0, 1.01],
        ..record(1, 0.0)
    };
    let zero = PoseRecord {
        orientation: [0.0; 4],
        ..record(1, 0.0)
    };
    assert_eq!(
        bad(vec![record(0, 1.0), nan], header(2)),
        (ErrorCode::InvalidPose, Some(1))
    );
    assert_eq!(
        bad(vec![inf, record(0, 1.0)], header(2)),
        (ErrorCode::InvalidPose, Some(2))
    );
    assert_eq!(
        bad(vec![long], header(1)),
        (ErrorCode::InvalidPose, Some(1))
    );
    assert_eq!(
        bad(vec![zero], header(1)),
        (ErrorCode::InvalidPose, Some(1))
    );
    assert_eq!(
        bad(vec![record(0, 1.0), record(9, 0.0)], header(2)),
        (ErrorCode::UnknownBody, Some(9))
    );
    assert_eq!(
        bad(vec![record(0, 1.0)], header(2)),
        (ErrorCode::MalformedMessage, None)
    );
    assert_eq!(
        bad(
            vec![record(0, 1.0)],
            PoseFrameHeader {
                query_flags: 1 << 20,
                ..header(1)
            }
        ),
        (ErrorCode::MalformedMessage, None)
    );
    for flags in [0, 1 << 5, query::TOI | 1 << 31] {
        assert_eq!(
            bad(
                vec![record(0, 1.0)],
                PoseFrameHeader {
                    query_flags: flags,
                    ..header(1)
                }
            ),
            (ErrorCode::MalformedMessage, None),
            "flags {flags:#x}"
        );
    }
    assert_eq!(
        bad(
            vec![record(0, 1.0)],
            PoseFrameHeader {
                scene: 5,
                ..header(1)
            }
        ),
        (ErrorCode::UnknownScene, None)
    );
    assert_eq!(
        bad(
            vec![record(0, 1.0)],
            PoseFrameHeader {
                protocol_version: 0,
                ..header(1)
            }
        ),
        (ErrorCode::ProtocolMismatch, None)
    );
}

#[test]
fn nearly_unit_quaternions_are_renormalised() {
    let mut scene = scene_with_bodies(1);
    let slightly_long = PoseRecord {
        orientation: [0.0, 0.0, 0.0, 1.0 + 5e-7],
        ..record(0, 0.0)
    };
    apply_pose_frame(4, &mut scene, &header(1), &[slightly_long], &mut Vec::new()).unwrap();
    let q = scene.body(BodyId(0)).unwrap().pose.rotation;
    assert!((q.length() - 1.0).abs() < 1e-15);
}
