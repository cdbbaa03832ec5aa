//! Fuzzing on stable Rust (issue #31): a million random and mutated control requests, and a
//! million random and mutated pose frames, through the daemon's own decode and apply
//! functions ([`ControlState::handle`], [`builder::build`], [`apply_pose_frame`]) from a
//! fixed seed. No input may panic; every reply carries a code the protocol defines (and
//! never `Internal`, which only a daemon bug gives, a build that panicked included); a
//! refused frame leaves every pose as it was; an applied one leaves only finite poses with
//! unit rotations.
//!
//! Inputs start from well-formed requests and frames (so deep paths are reached) and have
//! zero to three fields, or payload bytes, replaced by edge values: 0, 1, `u32::MAX`, NaN,
//! ±∞, ±1e300, subnormals, random bits.

use super::builder::{self, BuildJob, BuildQueue};
use super::config::DaemonConfig;
use super::control::{ControlState, Origin};
use super::ingest::apply_pose_frame;
use super::log::{Level, Logger};
use crate::geometry::MeshLimits;
use crate::math::{DQuat, DVec3, Pose};
use crate::scene::{BodyDesc, BodyId, CollisionFilter, Motion, Scene, SceneLimits};
use crossbeam::channel::Receiver;
use proxima_ipc::PROTOCOL_VERSION;
use proxima_ipc::wire::{
    Command, ControlReply, ControlRequest, ErrorCode, PoseFrameHeader, PoseRecord, ShapeKindCode,
    query,
};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64Mcg;

/// Inputs per record kind.
const CASES: usize = 1_000_000;
/// The daemon instance id of the fuzzed state.
const INSTANCE: u64 = 0xf022;
/// The clients requests come from: two ports of one process, and another process.
const OWNERS: [Origin; 3] = [
    Origin {
        port: 11,
        process: 1,
    },
    Origin {
        port: 12,
        process: 1,
    },
    Origin {
        port: 13,
        process: 2,
    },
];

fn edge_u32(rng: &mut Pcg64Mcg) -> u32 {
    const EDGES: [u32; 8] = [0, 1, 2, 3, 7, 1 << 31, u32::MAX - 1, u32::MAX];
    if rng.random_bool(0.5) {
        EDGES[rng.random_range(0..EDGES.len())]
    } else {
        rng.random()
    }
}

fn edge_f64(rng: &mut Pcg64Mcg) -> f64 {
    const EDGES: [f64; 13] = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.5,
        1e-300,
        1e300,
        -1e300,
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::MAX,
        f64::MIN_POSITIVE,
    ];
    match rng.random_range(0..3) {
        0 => EDGES[rng.random_range(0..EDGES.len())],
        1 => rng.random_range(-10.0..10.0),
        _ => f64::from_bits(rng.random()),
    }
}

/// A well-formed request of a random command on `scene`, with its payload.
fn well_formed(rng: &mut Pcg64Mcg, scene: u32) -> (ControlRequest, Vec<u8>) {
    let command = Command::from_u32(rng.random_range(0..9)).expect("a command");
    let kind = ShapeKindCode::from_u32(rng.random_range(0..7)).expect("a kind");
    let mut request = ControlRequest {
        protocol_version: PROTOCOL_VERSION,
        command: command as u32,
        scene,
        target: rng.random_range(0..4),
        shape_kind: kind as u32,
        motion: rng.random_range(0..3),
        group: rng.random(),
        mask: rng.random(),
        broad_phase: rng.random_range(0..6),
        margin: rng.random_range(-0.1..0.1),
        dimensions: [0.5, 0.25, 0.125, 0.0],
        position: [rng.random_range(-2.0..2.0), 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
        ..ControlRequest::default()
    };
    let mut payload = Vec::new();
    if command == Command::RegisterShape
        && matches!(kind, ShapeKindCode::Convex | ShapeKindCode::Mesh)
    {
        let points = rng.random_range(0..10u32);
        let triangles = if kind == ShapeKindCode::Mesh {
            rng.random_range(0..6u32)
        } else {
            0
        };
        request.vertex_count = points;
        request.index_count = triangles * 3;
        for _ in 0..points * 3 {
            payload.extend(rng.random_range(-1.0..1.0f64).to_ne_bytes());
        }
        for _ in 0..triangles * 3 {
            payload.extend(rng.random_range(0..points.max(1)).to_ne_bytes());
        }
    }
    (request, payload)
}

/// Replaces zero to three fields of `request`, or bytes of `payload`, by edge values.
fn mutate(rng: &mut Pcg64Mcg, request: &mut ControlRequest, payload: &mut Vec<u8>) {
    for _ in 0..rng.random_range(0..4) {
        match rng.random_range(0..16) {
            0 => request.protocol_version = edge_u32(rng),
            1 => request.command = edge_u32(rng),
            2 => request.scene = edge_u32(rng),
            3 => request.target = edge_u32(rng),
            4 => request.shape_kind = edge_u32(rng),
            5 => request.motion = edge_u32(rng),
            6 => request.vertex_count = edge_u32(rng),
            7 => request.index_count = edge_u32(rng),
            8 => request.broad_phase = edge_u32(rng),
            9 => request.reserved = edge_u32(rng),
            10 => request.margin = edge_f64(rng),
            11 => request.dimensions[rng.random_range(0..4)] = edge_f64(rng),
            12 => request.position[rng.random_range(0..3)] = edge_f64(rng),
            13 => request.orientation[rng.random_range(0..4)] = edge_f64(rng),
            14 => payload.truncate(rng.random_range(0..=payload.len())),
            _ if payload.is_empty() => payload.extend(edge_f64(rng).to_ne_bytes()),
            _ => {
                let at = rng
                    .random_range(0..payload.len() / 8 * 8 + 1)
                    .min(payload.len() - 1);
                let value = edge_f64(rng).to_ne_bytes();
                let end = (at + 8).min(payload.len());
                payload[at..end].copy_from_slice(&value[..end - at]);
            }
        }
    }
}

/// Builds every queued shape as the builder thread does.
fn build_queued(jobs: &Receiver<BuildJob>, limits: &MeshLimits, log: &mut Logger) {
    for job in jobs.try_iter() {
        builder::build(job, limits, log);
    }
}

/// Checks a reply's code and instance; a scene's code `Internal` is a daemon bug.
fn check_reply(reply: &ControlReply, request: &ControlRequest) {
    let code = ErrorCode::from_u32(reply.status);
    assert!(
        code.is_some_and(|c| c != ErrorCode::Internal),
        "{request:?} → status {} ({})",
        reply.status,
        reply.reason()
    );
    assert_eq!(reply.instance, INSTANCE);
}

#[test]
fn a_million_mutated_control_requests_get_defined_codes_and_never_panic() {
    let config = DaemonConfig {
        max_scenes: 4,
        max_convex_points: 64,
        mesh_limits: MeshLimits {
            max_vertices: 64,
            max_triangles: 64,
        },
        scene_limits: SceneLimits {
            max_bodies: 32,
            max_shapes: 16,
            ..SceneLimits::STANDARD
        },
        ..DaemonConfig::default()
    };
    let limits = config.mesh_limits;
    let (builds, jobs) = BuildQueue::bounded(config.max_queued_builds);
    let mut state = ControlState::new(config, builds, INSTANCE);
    let mut log = Logger::in_memory(Level::Error);
    let mut rng = Pcg64Mcg::seed_from_u64(31);
    let mut scenes: Vec<(u32, Origin)> = Vec::new();
    let mut outcomes = [0usize; 16];
    for case in 0..CASES {
        if case % 10_000 == 0 {
            assert!(
                state.accounts_balance(),
                "quota charges balance at case {case}"
            );
        }
        let (scene, owner) = match scenes.get(rng.random_range(0..scenes.len() + 1)) {
            Some(&known) if rng.random_bool(0.9) => known,
            _ => (edge_u32(&mut rng), OWNERS[0]),
        };
        let origin = if rng.random_bool(0.9) {
            owner
        } else {
            OWNERS[rng.random_range(0..OWNERS.len())]
        };
        let (mut request, mut payload) = well_formed(&mut rng, scene);
        if rng.random_bool(0.05) {
            request.command = Command::CreateScene as u32;
        }
        mutate(&mut rng, &mut request, &mut payload);
        let reply = state.handle(origin, &request, &payload);
        check_reply(&reply, &request);
        outcomes[reply.status as usize] += 1;
        if reply.status == ErrorCode::Ok as u32 {
            match Command::from_u32(request.command) {
                Some(Command::CreateScene) => scenes.push((reply.id, origin)),
                Some(Command::DropScene) => scenes.retain(|&(id, _)| id != request.scene),
                _ => {}
            }
        }
        // Builds finish at random later points, so requests also meet shapes in the build.
        if rng.random_bool(0.5) {
            build_queued(&jobs, &limits, &mut log);
        }
    }
    build_queued(&jobs, &limits, &mut log);
    assert!(
        state.accounts_balance(),
        "every quota charge is where it belongs"
    );
    // Every built shape's state is a defined code, never a caught panic (Internal).
    for &(scene, owner) in &scenes {
        for shape in 0..16 {
            let ask = ControlRequest {
                protocol_version: PROTOCOL_VERSION,
                command: Command::ShapeState as u32,
                scene,
                target: shape,
                ..ControlRequest::default()
            };
            check_reply(&state.handle(owner, &ask, &[]), &ask);
        }
    }
    // The fuzz reached both sides of the deep paths: successes and every kind of refusal.
    for code in [
        ErrorCode::Ok,
        ErrorCode::ProtocolMismatch,
        ErrorCode::UnknownScene,
        ErrorCode::UnknownBody,
        ErrorCode::UnknownShape,
        ErrorCode::InvalidPose,
        ErrorCode::InvalidShape,
        ErrorCode::LimitExceeded,
        ErrorCode::MalformedMessage,
        ErrorCode::ShapeNotReady,
        ErrorCode::NotOwner,
    ] {
        assert!(outcomes[code as usize] > 10, "{code:?}: {outcomes:?}");
    }
}

/// A scene of four unit spheres in a row.
fn four_spheres() -> Scene {
    let mut scene = Scene::try_new(0.0, SceneLimits::STANDARD).unwrap();
    let sphere = scene
        .register_shape(crate::narrow::Shape::Sphere(
            crate::geometry::Sphere::try_new(0.5).unwrap(),
        ))
        .unwrap();
    for i in 0..4 {
        let desc = BodyDesc {
            shape: sphere,
            pose: Pose::new(DVec3::new(f64::from(i), 0.0, 0.0), DQuat::IDENTITY),
            motion: Motion::Dynamic,
            filter: CollisionFilter::ALL,
            margin: None,
        };
        scene.add_body(&desc).unwrap();
    }
    scene
}

/// Every body's pose in `scene`'s four.
fn poses(scene: &Scene) -> Vec<Pose> {
    (0..4)
        .map(|i| scene.body(BodyId(i)).unwrap().pose)
        .collect()
}

#[test]
fn a_million_mutated_pose_frames_are_applied_or_refused_whole_and_never_panic() {
    let mut scene = four_spheres();
    let mut validated = Vec::new();
    let mut rng = Pcg64Mcg::seed_from_u64(9);
    let (mut applied, mut refused) = (0usize, [0usize; 16]);
    for seq in 0..CASES as u64 {
        let count = rng.random_range(0..6usize);
        let mut records: Vec<PoseRecord> = (0..count)
            .map(|_| {
                let axis = DVec3::new(rng.random(), rng.random(), rng.random()) + DVec3::X;
                let rotation = DQuat::from_axis_angle(axis.normalize(), rng.random());
                PoseRecord {
                    body: rng.random_range(0..4),
                    reserved: 0,
                    position: [rng.random_range(-5.0..5.0), 0.0, 0.0],
                    orientation: rotation.to_array(),
                }
            })
            .collect();
        let mut header = PoseFrameHeader {
            protocol_version: PROTOCOL_VERSION,
            scene: 5,
            frame_seq: seq,
            budget_ns: 0,
            query_flags: query::CLOSE,
            count: count as u32,
            frame_key: 0,
        };
        for _ in 0..rng.random_range(0..4) {
            match rng.random_range(0..9) {
                0 => header.protocol_version = edge_u32(&mut rng),
                1 => header.scene = edge_u32(&mut rng),
                2 => header.query_flags = edge_u32(&mut rng),
                3 => header.count = edge_u32(&mut rng),
                _ if records.is_empty() => {}
                4 => records[0].body = edge_u32(&mut rng),
                5 => records[0].reserved = edge_u32(&mut rng),
                6 => {
                    let last = records.len() - 1;
                    records[last].position[rng.random_range(0..3)] = edge_f64(&mut rng);
                }
                7 => records[0].orientation[rng.random_range(0..4)] = edge_f64(&mut rng),
                _ => records[0].orientation = [0.0; 4],
            }
        }
        let before = poses(&scene);
        match apply_pose_frame(5, &mut scene, &header, &records, &mut validated) {
            Ok(_) => {
                applied += 1;
                for pose in poses(&scene) {
                    assert!(pose.position.is_finite(), "frame {seq}: {pose:?}");
                    let norm = pose.rotation.length();
                    assert!((norm - 1.0).abs() < 1e-9, "frame {seq}: {pose:?}");
                }
                scene.end_frame();
            }
            Err(rejection) => {
                let code = rejection.rejection.code;
                assert_ne!(code, ErrorCode::Internal, "frame {seq}");
                refused[code as usize] += 1;
                assert_eq!(poses(&scene), before, "frame {seq} refused but applied");
            }
        }
    }
    assert!(applied > CASES / 10, "{applied} applied");
    for code in [
        ErrorCode::ProtocolMismatch,
        ErrorCode::UnknownScene,
        ErrorCode::UnknownBody,
        ErrorCode::InvalidPose,
        ErrorCode::MalformedMessage,
    ] {
        assert!(refused[code as usize] > 100, "{code:?}: {refused:?}");
    }
}
