//! The real `proximad` binary, started per test with its own service root and iceoryx2
//! prefix, driven over real shared memory by the client library from this process: scene,
//! shape and body control, every kind of bad request, several clients at once.

#[path = "support/daemon.rs"]
mod daemon_harness;

use daemon_harness::{Daemon, body};
use proxima_ipc::client::{BodySpec, Motion, Primitive};
use proxima_ipc::error::ControlError;
use proxima_ipc::wire::{ControlRequest, ErrorCode};

fn rejected(result: Result<impl std::fmt::Debug, ControlError>) -> ErrorCode {
    match result {
        Err(ControlError::Rejected { code, reason }) => {
            assert!(!reason.is_empty());
            code
        }
        other => panic!("expected a rejection, got {other:?}"),
    }
}

const TETRA: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];
const TETRA_FACES: [[u32; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

#[test]
fn a_client_builds_a_scene_of_every_shape_kind_in_a_real_daemon() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let shapes = [
        client
            .register_primitive(scene, Primitive::Sphere { radius: 0.5 })
            .unwrap(),
        client
            .register_primitive(
                scene,
                Primitive::Capsule {
                    radius: 0.1,
                    half_height: 0.4,
                },
            )
            .unwrap(),
        client
            .register_primitive(
                scene,
                Primitive::Cuboid {
                    half_extents: [0.1, 0.2, 0.3],
                },
            )
            .unwrap(),
        client
            .register_primitive(
                scene,
                Primitive::Cylinder {
                    radius: 0.2,
                    half_height: 0.5,
                },
            )
            .unwrap(),
        client
            .register_primitive(
                scene,
                Primitive::Cone {
                    radius: 0.2,
                    half_height: 0.5,
                },
            )
            .unwrap(),
        client.register_convex(scene, &TETRA).unwrap(),
        client.register_mesh(scene, &TETRA, &TETRA_FACES).unwrap(),
    ];
    assert_eq!(
        shapes,
        [0, 1, 2, 3, 4, 5, 6],
        "shape ids count up from 0 in a scene"
    );
    let bodies: Vec<u32> = shapes
        .iter()
        .map(|&s| client.add_body(scene, &body(s, f64::from(s))).unwrap())
        .collect();
    assert_eq!(bodies, [0, 1, 2, 3, 4, 5, 6]);
    client
        .update_body(scene, bodies[0], Motion::Static, 1, 2, Some(0.05))
        .unwrap();
    client.remove_body(scene, bodies[1]).unwrap();
    assert_eq!(
        rejected(client.remove_body(scene, bodies[1])),
        ErrorCode::UnknownBody
    );
    // The removed body's id goes to the next body added.
    assert_eq!(client.add_body(scene, &body(shapes[0], 9.0)).unwrap(), 1);
    client.drop_scene(scene).unwrap();
    assert_eq!(
        rejected(client.add_body(scene, &body(0, 0.0))),
        ErrorCode::UnknownScene
    );
}

#[test]
fn bad_requests_get_their_codes_and_another_client_keeps_being_served() {
    let daemon = Daemon::start();
    let (bad, good) = (daemon.client(), daemon.client());
    let good_scene = good.create_scene().unwrap();
    let good_sphere = good
        .register_primitive(good_scene, Primitive::Sphere { radius: 1.0 })
        .unwrap();
    let mut next_x = 0.0;
    let mut good_client_still_served = || {
        next_x += 1.0;
        good.add_body(good_scene, &body(good_sphere, next_x))
            .expect("the other client is served");
    };
    // The bad client's mistakes are made on its own scene: the other's is not its to touch.
    let scene = bad.create_scene().unwrap();
    let sphere = bad
        .register_primitive(scene, Primitive::Sphere { radius: 1.0 })
        .unwrap();
    let nan_pose = BodySpec {
        position: [f64::NAN, 0.0, 0.0],
        ..body(sphere, 0.0)
    };
    let long_quaternion = BodySpec {
        orientation: [0.0, 0.0, 0.0, 1.1],
        ..body(sphere, 0.0)
    };
    let huge = BodySpec {
        position: [1e12, 0.0, 0.0],
        ..body(sphere, 0.0)
    };
    let cases: Vec<(&str, ErrorCode)> = vec![
        ("NaN position", rejected(bad.add_body(scene, &nan_pose))),
        (
            "non-unit quaternion",
            rejected(bad.add_body(scene, &long_quaternion)),
        ),
        (
            "position beyond the coordinate limit",
            rejected(bad.add_body(scene, &huge)),
        ),
        (
            "unknown shape",
            rejected(bad.add_body(scene, &body(99, 0.0))),
        ),
        ("unknown body", rejected(bad.remove_body(scene, 99))),
        (
            "unknown scene",
            rejected(bad.register_primitive(77, Primitive::Sphere { radius: 1.0 })),
        ),
        (
            "negative radius",
            rejected(bad.register_primitive(scene, Primitive::Sphere { radius: -1.0 })),
        ),
        (
            "mesh index out of range",
            rejected(bad.register_mesh(scene, &TETRA, &[[0, 1, 4]])),
        ),
        (
            "empty mesh",
            rejected(bad.register_mesh(scene, &TETRA, &[])),
        ),
        ("empty convex", rejected(bad.register_convex(scene, &[]))),
        (
            "another client's scene",
            rejected(bad.add_body(good_scene, &body(good_sphere, 9.0))),
        ),
    ];
    let expected = [
        ErrorCode::InvalidPose,
        ErrorCode::InvalidPose,
        ErrorCode::InvalidPose,
        ErrorCode::UnknownShape,
        ErrorCode::UnknownBody,
        ErrorCode::UnknownScene,
        ErrorCode::InvalidShape,
        ErrorCode::MeshIndexOutOfRange,
        ErrorCode::EmptyGeometry,
        ErrorCode::EmptyGeometry,
        ErrorCode::NotOwner,
    ];
    for ((what, got), want) in cases.iter().zip(expected) {
        assert_eq!(*got, want, "{what}");
        good_client_still_served();
    }
    // Raw requests: wrong protocol version, unknown command, a payload that lies about its size.
    let hello = ControlRequest {
        protocol_version: 999,
        ..ControlRequest::default()
    };
    let reply = bad.request(&hello, &[]).unwrap();
    assert_eq!(
        ErrorCode::from_u32(reply.status),
        Some(ErrorCode::ProtocolMismatch)
    );
    let unknown = ControlRequest {
        protocol_version: proxima_ipc::PROTOCOL_VERSION,
        command: 1234,
        ..ControlRequest::default()
    };
    assert_eq!(
        ErrorCode::from_u32(bad.request(&unknown, &[]).unwrap().status),
        Some(ErrorCode::MalformedMessage)
    );
    let lying = ControlRequest {
        protocol_version: proxima_ipc::PROTOCOL_VERSION,
        command: proxima_ipc::wire::Command::RegisterShape as u32,
        scene,
        shape_kind: proxima_ipc::wire::ShapeKindCode::Mesh as u32,
        vertex_count: 1_000_000,
        index_count: 3,
        ..ControlRequest::default()
    };
    assert_eq!(
        ErrorCode::from_u32(bad.request(&lying, &[0; 40]).unwrap().status),
        Some(ErrorCode::MalformedMessage)
    );
    good_client_still_served();
    // The scene limit (3, two taken) holds, and refusing it harms no one.
    bad.create_scene().unwrap();
    assert_eq!(rejected(bad.create_scene()), ErrorCode::LimitExceeded);
    good_client_still_served();
}

/// `SetSceneParams` with every broad-phase code is accepted; an undefined code and an
/// unknown scene are refused with their codes, and the scene keeps being served: bodies are
/// added and its frames answered after.
#[test]
fn every_broad_phase_code_is_accepted_and_a_bad_one_refused_while_the_scene_keeps_serving() {
    use proxima_ipc::wire::{BroadPhaseCode, Command};
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let sphere = client
        .register_primitive(scene, Primitive::Sphere { radius: 0.5 })
        .unwrap();
    for (i, code) in [
        BroadPhaseCode::IncrementalSap,
        BroadPhaseCode::HashGrid,
        BroadPhaseCode::ColumnGrid,
        BroadPhaseCode::SkinGrid,
        BroadPhaseCode::SortAndSweep,
        BroadPhaseCode::Auto,
    ]
    .into_iter()
    .enumerate()
    {
        client.set_broad_phase(scene, code).unwrap();
        client
            .add_body(scene, &body(sphere, i as f64 * 0.75))
            .unwrap();
    }
    let bad = ControlRequest {
        protocol_version: proxima_ipc::PROTOCOL_VERSION,
        command: Command::SetSceneParams as u32,
        scene,
        broad_phase: 6,
        ..ControlRequest::default()
    };
    let reply = client.request(&bad, &[]).unwrap();
    assert_eq!(
        ErrorCode::from_u32(reply.status),
        Some(ErrorCode::MalformedMessage)
    );
    assert!(
        reply.reason().contains("broad phase 6"),
        "{}",
        reply.reason()
    );
    let reply = client
        .request(
            &ControlRequest {
                broad_phase: u32::MAX,
                ..bad
            },
            &[],
        )
        .unwrap();
    assert_eq!(
        ErrorCode::from_u32(reply.status),
        Some(ErrorCode::MalformedMessage)
    );
    assert_eq!(
        rejected(client.set_broad_phase(scene + 9, BroadPhaseCode::HashGrid)),
        ErrorCode::UnknownScene
    );
    // Still served: control, and frames (six spheres 0.75 m apart, radius 0.5, one added
    // under each code: five touching pairs).
    client.add_body(scene, &body(sphere, 10.0)).unwrap();
    let link = client.open_scene(scene).unwrap();
    for frame in 1..=3u64 {
        link.publish_poses(frame, 0, proxima_ipc::wire::query::OVERLAP, &[])
            .unwrap();
        let result = link
            .receive_results_for(frame, std::time::Duration::from_secs(10))
            .unwrap()
            .expect("a result frame");
        assert_eq!(
            ErrorCode::from_u32(result.header().status),
            Some(ErrorCode::Ok)
        );
        assert_eq!(result.header().pair_count, 5, "frame {frame}");
    }
}
