use super::super::builder::{self, BuildJob};
use super::super::log::{Level, Logger};
use super::super::quota::ClientQuota;
use super::*;
use crossbeam::channel::Receiver;
use proxima_ipc::wire::{MotionCode, ShapeKindCode};

/// The client every test request comes from, unless a test says otherwise.
const OWNER: Origin = Origin {
    port: 0x0A,
    process: 100,
};

/// Another client, in another process.
fn other(n: u32) -> Origin {
    Origin {
        port: OWNER.port + u128::from(n),
        process: OWNER.process + n,
    }
}
/// The daemon instance id of the tests' states.
const INSTANCE: u64 = 0x1234_5678;

/// A control state whose builds wait in a queue of `queued` for [`build_all`].
fn state_with(config: DaemonConfig, queued: usize) -> (ControlState, Receiver<BuildJob>) {
    let (builds, jobs) = BuildQueue::bounded(queued);
    (ControlState::new(config, builds, INSTANCE), jobs)
}

/// Builds every queued shape as the builder thread does; returns how many.
fn build_all(jobs: &Receiver<BuildJob>) -> usize {
    let mut log = Logger::in_memory(Level::Debug);
    let limits = DaemonConfig::default().mesh_limits;
    jobs.try_iter()
        .map(|job| builder::build(job, &limits, &mut log))
        .count()
}

fn shape_state(state: &mut ControlState, scene: u32, shape: u32) -> ControlReply {
    let ask = ControlRequest {
        scene,
        target: shape,
        ..request(Command::ShapeState)
    };
    state.handle(OWNER, &ask, &[])
}

fn request(command: Command) -> ControlRequest {
    ControlRequest {
        protocol_version: PROTOCOL_VERSION,
        command: command as u32,
        orientation: [0.0, 0.0, 0.0, 1.0],
        motion: MotionCode::Dynamic as u32,
        group: u32::MAX,
        mask: u32::MAX,
        margin: -1.0,
        ..ControlRequest::default()
    }
}

fn mesh_payload(vertices: &[[f64; 3]], indices: &[u32]) -> Vec<u8> {
    let mut bytes: Vec<u8> = vertices
        .iter()
        .flatten()
        .flat_map(|v| v.to_ne_bytes())
        .collect();
    bytes.extend(indices.iter().flat_map(|i| i.to_ne_bytes()));
    bytes
}

fn mesh_request(scene: u32, vertices: usize, indices: usize) -> ControlRequest {
    ControlRequest {
        scene,
        shape_kind: ShapeKindCode::Mesh as u32,
        vertex_count: vertices as u32,
        index_count: indices as u32,
        ..request(Command::RegisterShape)
    }
}

/// A `RegisterShape` request of a sphere of radius 0.5 in `scene`.
fn sphere_request(scene: u32) -> ControlRequest {
    ControlRequest {
        scene,
        shape_kind: ShapeKindCode::Sphere as u32,
        dimensions: [0.5, 0.0, 0.0, 0.0],
        ..request(Command::RegisterShape)
    }
}

fn code(reply: &ControlReply) -> ErrorCode {
    ErrorCode::from_u32(reply.status).expect("a defined code")
}

const TETRA: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];
const TETRA_INDICES: [u32; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];

#[test]
fn a_scene_takes_shapes_and_bodies_and_lets_them_go() {
    let (mut state, jobs) = state_with(DaemonConfig::default(), 4);
    assert_eq!(
        state.handle(OWNER, &request(Command::Hello), &[]).id,
        PROTOCOL_VERSION
    );
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let sphere = state.handle(OWNER, &sphere_request(scene), &[]);
    assert_eq!(code(&sphere), ErrorCode::Ok, "{}", sphere.reason());
    let mesh = state.handle(
        OWNER,
        &mesh_request(scene, 4, 12),
        &mesh_payload(&TETRA, &TETRA_INDICES),
    );
    assert_eq!(code(&mesh), ErrorCode::Ok, "{}", mesh.reason());
    assert_eq!(build_all(&jobs), 1);
    let add = |state: &mut ControlState, shape: u32, x: f64| {
        state.handle(
            OWNER,
            &ControlRequest {
                scene,
                target: shape,
                position: [x, 0.0, 0.0],
                ..request(Command::AddBody)
            },
            &[],
        )
    };
    let a = add(&mut state, sphere.id, 0.0);
    let b = add(&mut state, mesh.id, 2.0);
    assert_eq!((code(&a), code(&b)), (ErrorCode::Ok, ErrorCode::Ok));
    {
        let s = &lock(state.scene(scene).unwrap()).scene;
        assert_eq!(s.body_count(), 2);
        assert_eq!(s.body(BodyId(b.id)).unwrap().pose.position.x, 2.0);
    }
    let update = ControlRequest {
        scene,
        target: a.id,
        motion: MotionCode::Static as u32,
        margin: 0.25,
        ..request(Command::UpdateBody)
    };
    assert_eq!(code(&state.handle(OWNER, &update, &[])), ErrorCode::Ok);
    assert_eq!(
        lock(state.scene(scene).unwrap())
            .scene
            .body(BodyId(a.id))
            .unwrap()
            .margin,
        0.25
    );
    let remove = ControlRequest {
        scene,
        target: a.id,
        ..request(Command::RemoveBody)
    };
    assert_eq!(code(&state.handle(OWNER, &remove, &[])), ErrorCode::Ok);
    assert_eq!(
        code(&state.handle(OWNER, &remove, &[])),
        ErrorCode::UnknownBody
    );
    for (wire_code, choice) in [
        (5, BroadPhaseChoice::Fixed(BroadPhaseKind::SkinGrid)),
        (4, BroadPhaseChoice::Fixed(BroadPhaseKind::ColumnGrid)),
        (3, BroadPhaseChoice::Fixed(BroadPhaseKind::HashGrid)),
        (2, BroadPhaseChoice::Fixed(BroadPhaseKind::IncrementalSap)),
        (1, BroadPhaseChoice::Fixed(BroadPhaseKind::SortAndSweep)),
        (0, BroadPhaseChoice::Auto),
    ] {
        let params = ControlRequest {
            scene,
            broad_phase: wire_code,
            ..request(Command::SetSceneParams)
        };
        let reply = state.handle(OWNER, &params, &[]);
        assert_eq!((code(&reply), reply.id), (ErrorCode::Ok, scene));
        assert_eq!(
            lock(state.scene(scene).unwrap()).scene.broad_phase(),
            choice
        );
    }
    let drop = ControlRequest {
        scene,
        ..request(Command::DropScene)
    };
    assert_eq!(code(&state.handle(OWNER, &drop, &[])), ErrorCode::Ok);
    assert!(state.scene(scene).is_none());
    assert_eq!(
        code(&state.handle(OWNER, &drop, &[])),
        ErrorCode::UnknownScene
    );
}

#[test]
fn every_bad_request_gets_its_code_and_changes_nothing() {
    let config = DaemonConfig {
        max_scenes: 2,
        mesh_limits: crate::geometry::MeshLimits {
            max_vertices: 8,
            max_triangles: 8,
        },
        ..DaemonConfig::default()
    };
    let (mut state, _jobs) = state_with(config, 4);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let sphere = ControlRequest {
        scene,
        shape_kind: ShapeKindCode::Sphere as u32,
        dimensions: [1.0; 4],
        ..request(Command::RegisterShape)
    };
    let shape = state.handle(OWNER, &sphere, &[]).id;
    let body = state
        .handle(
            OWNER,
            &ControlRequest {
                scene,
                target: shape,
                ..request(Command::AddBody)
            },
            &[],
        )
        .id;
    let snapshot = format!("{:?}", state.scene(scene));
    let big: Vec<[f64; 3]> = (0..9).map(|i| [f64::from(i), 0.0, 0.0]).collect();
    let cases: Vec<(ControlRequest, Vec<u8>, ErrorCode)> = vec![
        (
            ControlRequest {
                protocol_version: 99,
                ..request(Command::Hello)
            },
            vec![],
            ErrorCode::ProtocolMismatch,
        ),
        (
            ControlRequest {
                command: 77,
                ..request(Command::Hello)
            },
            vec![],
            ErrorCode::MalformedMessage,
        ),
        (
            ControlRequest { scene: 5, ..sphere },
            vec![],
            ErrorCode::UnknownScene,
        ),
        (
            ControlRequest {
                shape_kind: 42,
                ..sphere
            },
            vec![],
            ErrorCode::MalformedMessage,
        ),
        (
            ControlRequest {
                dimensions: [f64::NAN; 4],
                ..sphere
            },
            vec![],
            ErrorCode::InvalidShape,
        ),
        (
            ControlRequest {
                dimensions: [-1.0; 4],
                ..sphere
            },
            vec![],
            ErrorCode::InvalidShape,
        ),
        (sphere, vec![1, 2, 3], ErrorCode::MalformedMessage),
        (
            mesh_request(scene, 4, 12),
            mesh_payload(&TETRA, &TETRA_INDICES)[..50].to_vec(),
            ErrorCode::MalformedMessage,
        ),
        (
            mesh_request(scene, 4, 4),
            mesh_payload(&TETRA, &[0, 1, 2, 3]),
            ErrorCode::MalformedMessage,
        ),
        (
            mesh_request(scene, 9, 3),
            mesh_payload(&big, &[0, 1, 2]),
            ErrorCode::LimitExceeded,
        ),
        (
            ControlRequest {
                scene,
                target: 9,
                ..request(Command::AddBody)
            },
            vec![],
            ErrorCode::UnknownShape,
        ),
        (
            ControlRequest {
                scene,
                target: shape,
                position: [f64::NAN, 0.0, 0.0],
                ..request(Command::AddBody)
            },
            vec![],
            ErrorCode::InvalidPose,
        ),
        (
            ControlRequest {
                scene,
                target: shape,
                orientation: [0.0, 0.0, 0.0, 2.0],
                ..request(Command::AddBody)
            },
            vec![],
            ErrorCode::InvalidPose,
        ),
        (
            ControlRequest {
                scene,
                target: shape,
                motion: 9,
                ..request(Command::AddBody)
            },
            vec![],
            ErrorCode::MalformedMessage,
        ),
        (
            ControlRequest {
                scene,
                target: shape,
                margin: f64::INFINITY,
                ..request(Command::AddBody)
            },
            vec![],
            ErrorCode::MalformedMessage,
        ),
        (
            ControlRequest {
                scene,
                broad_phase: 6,
                ..request(Command::SetSceneParams)
            },
            vec![],
            ErrorCode::MalformedMessage,
        ),
        (
            ControlRequest {
                scene: 5,
                broad_phase: 2,
                ..request(Command::SetSceneParams)
            },
            vec![],
            ErrorCode::UnknownScene,
        ),
        (
            ControlRequest {
                scene,
                broad_phase: 2,
                ..request(Command::SetSceneParams)
            },
            vec![1],
            ErrorCode::MalformedMessage,
        ),
        (
            ControlRequest {
                scene,
                target: 9,
                ..request(Command::RemoveBody)
            },
            vec![],
            ErrorCode::UnknownBody,
        ),
        (
            ControlRequest {
                scene,
                target: body,
                margin: f64::NAN,
                ..request(Command::UpdateBody)
            },
            vec![],
            ErrorCode::MalformedMessage,
        ),
    ];
    for (i, (req, payload, expected)) in cases.iter().enumerate() {
        let reply = state.handle(OWNER, req, payload);
        assert_eq!(code(&reply), *expected, "case {i}: {}", reply.reason());
        assert_eq!(reply.id, u32::MAX, "case {i}");
        assert!(!reply.reason().is_empty(), "case {i}");
        assert_eq!(
            format!("{:?}", state.scene(scene)),
            snapshot,
            "case {i} changed the scene"
        );
    }
    // The scene limit, and the scene still serves after all of it.
    assert_eq!(
        code(&state.handle(OWNER, &request(Command::CreateScene), &[])),
        ErrorCode::Ok
    );
    assert_eq!(
        code(&state.handle(OWNER, &request(Command::CreateScene), &[])),
        ErrorCode::LimitExceeded
    );
    let again = state.handle(
        OWNER,
        &ControlRequest {
            scene,
            target: shape,
            ..request(Command::AddBody)
        },
        &[],
    );
    assert_eq!(code(&again), ErrorCode::Ok);
}

#[test]
fn geometry_refused_while_building_is_the_shapes_answer_and_adds_nothing() {
    let (mut state, jobs) = state_with(DaemonConfig::default(), 8);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let infinite = [[0.0, f64::INFINITY, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let no_points = ControlRequest {
        scene,
        shape_kind: ShapeKindCode::Convex as u32,
        ..request(Command::RegisterShape)
    };
    let cases = [
        (
            mesh_request(scene, 4, 3),
            mesh_payload(&TETRA, &[0, 1, 9]),
            ErrorCode::MeshIndexOutOfRange,
        ),
        (mesh_request(scene, 0, 0), vec![], ErrorCode::EmptyGeometry),
        (
            mesh_request(scene, 3, 3),
            mesh_payload(&infinite, &[0, 1, 2]),
            ErrorCode::InvalidShape,
        ),
        (no_points, vec![], ErrorCode::EmptyGeometry),
    ];
    let mut ids = Vec::new();
    for (registration, payload, _) in &cases {
        let accepted = state.handle(OWNER, registration, payload);
        assert_eq!(code(&accepted), ErrorCode::Ok, "{}", accepted.reason());
        assert_eq!(accepted.flags, reply_flags::SHAPE_BUILDING);
        ids.push(accepted.id);
    }
    assert_eq!(ids, [0, 1, 2, 3]);
    assert_eq!(build_all(&jobs), cases.len());
    for ((_, _, expected), id) in cases.iter().zip(ids) {
        // Asked twice, the same answer.
        for _ in 0..2 {
            let answer = shape_state(&mut state, scene, id);
            assert_eq!(code(&answer), *expected, "shape {id}: {}", answer.reason());
        }
        let body = state.handle(
            OWNER,
            &ControlRequest {
                scene,
                target: id,
                ..request(Command::AddBody)
            },
            &[],
        );
        assert_eq!(code(&body), ErrorCode::UnknownShape);
        assert!(
            body.reason().contains("failed to build"),
            "{}",
            body.reason()
        );
    }
    let cell = lock(state.scene(scene).unwrap());
    assert_eq!(cell.scene.body_count(), 0);
    assert!(cell.scene.shape(crate::scene::ShapeId(0)).is_none());
}

#[test]
fn a_full_build_queue_refuses_a_registration_and_a_dropped_scenes_builds_change_nothing() {
    let (mut state, jobs) = state_with(DaemonConfig::default(), 1);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let (tetra, payload) = (
        mesh_request(scene, 4, 12),
        mesh_payload(&TETRA, &TETRA_INDICES),
    );
    let first = state.handle(OWNER, &tetra, &payload);
    assert_eq!((code(&first), first.id), (ErrorCode::Ok, 0));
    let refused = state.handle(OWNER, &tetra, &payload);
    assert_eq!(
        code(&refused),
        ErrorCode::LimitExceeded,
        "{}",
        refused.reason()
    );
    // No id was handed out for it.
    assert_eq!(
        code(&shape_state(&mut state, scene, 1)),
        ErrorCode::UnknownShape
    );
    // Once the builder has taken a job, there is room again.
    let taken = jobs.try_recv().unwrap();
    let second = state.handle(OWNER, &tetra, &payload);
    assert_eq!((code(&second), second.id), (ErrorCode::Ok, 1));

    let cell = Arc::clone(state.scene(scene).unwrap());
    let dropping = ControlRequest {
        scene,
        ..request(Command::DropScene)
    };
    assert_eq!(code(&state.handle(OWNER, &dropping, &[])), ErrorCode::Ok);
    let mut log = Logger::in_memory(Level::Debug);
    builder::build(taken, &DaemonConfig::default().mesh_limits, &mut log);
    assert_eq!(build_all(&jobs), 1);
    let left = lock(&cell);
    assert!(left.dropped && left.scene.shape(crate::scene::ShapeId(0)).is_none());
    assert_eq!(left.shapes.state(0), Ok(ShapeState::Building));
    drop(left);

    // With the builder gone (the daemon stopping), a registration fails inside.
    drop(jobs);
    let other = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let stranded = state.handle(OWNER, &mesh_request(other, 4, 12), &payload);
    assert_eq!(
        code(&stranded),
        ErrorCode::Internal,
        "{}",
        stranded.reason()
    );
}

#[test]
fn a_mesh_refuses_bodies_until_it_is_built_and_a_primitive_is_ready_at_once() {
    let (mut state, jobs) = state_with(DaemonConfig::default(), 4);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let sphere = state.handle(OWNER, &sphere_request(scene), &[]);
    let mesh = state.handle(
        OWNER,
        &mesh_request(scene, 4, 12),
        &mesh_payload(&TETRA, &TETRA_INDICES),
    );
    assert_eq!((code(&sphere), sphere.flags), (ErrorCode::Ok, 0));
    assert_eq!(
        (code(&mesh), mesh.flags),
        (ErrorCode::Ok, reply_flags::SHAPE_BUILDING)
    );
    let ready = shape_state(&mut state, scene, sphere.id);
    assert_eq!(
        (code(&ready), ready.id, ready.flags),
        (ErrorCode::Ok, sphere.id, 0)
    );
    let add = |state: &mut ControlState| {
        let body = ControlRequest {
            scene,
            target: mesh.id,
            ..request(Command::AddBody)
        };
        state.handle(OWNER, &body, &[])
    };
    let early = add(&mut state);
    assert_eq!(code(&early), ErrorCode::ShapeNotReady, "{}", early.reason());
    let building = shape_state(&mut state, scene, mesh.id);
    assert_eq!((code(&building), building.id), (ErrorCode::Ok, mesh.id));
    assert_eq!(building.flags, reply_flags::SHAPE_BUILDING);
    assert_eq!(lock(state.scene(scene).unwrap()).scene.body_count(), 0);

    assert_eq!(build_all(&jobs), 1);
    let built = shape_state(&mut state, scene, mesh.id);
    assert_eq!((code(&built), built.flags), (ErrorCode::Ok, 0));
    assert_eq!(code(&add(&mut state)), ErrorCode::Ok);
    assert_eq!(
        code(&shape_state(&mut state, scene, 7)),
        ErrorCode::UnknownShape
    );
}

/// A compound of convex parts and a decomposed closed mesh build like meshes; part sizes
/// that do not add up, an empty part, a mesh with no volume and undefined decomposition
/// options are refused with their codes, the first two and the last at once.
#[test]
fn compounds_and_decomposed_meshes_build_or_say_why_not() {
    let (mut state, jobs) = state_with(DaemonConfig::default(), 8);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let shifted: Vec<[f64; 3]> = TETRA.iter().map(|p| [p[0] + 2.0, p[1], p[2]]).collect();
    let points = [TETRA.to_vec(), shifted].concat();
    let register = |state: &mut ControlState, kind: ShapeKindCode, dims, sizes: &[u32]| {
        let header = ControlRequest {
            shape_kind: kind as u32,
            dimensions: dims,
            ..mesh_request(scene, points.len(), sizes.len())
        };
        state.handle(OWNER, &header, &mesh_payload(&points, sizes))
    };
    let compound = register(&mut state, ShapeKindCode::Compound, [0.0; 4], &[4, 4]);
    let uneven = register(&mut state, ShapeKindCode::Compound, [0.0; 4], &[3, 4]);
    let empty_part = register(&mut state, ShapeKindCode::Compound, [0.0; 4], &[8, 0]);
    let decompose = |state: &mut ControlState, dims: [f64; 4], indices: &[u32]| {
        let header = ControlRequest {
            shape_kind: ShapeKindCode::DecomposedMesh as u32,
            dimensions: dims,
            ..mesh_request(scene, 4, indices.len())
        };
        state.handle(OWNER, &header, &mesh_payload(&TETRA, indices))
    };
    let decomposed = decompose(&mut state, [0.05, 8.0, 1.0, 0.0], &TETRA_INDICES);
    let flat = decompose(&mut state, [0.0; 4], &TETRA_INDICES[..3]);
    for (reply, what) in [
        (&compound, "compound"),
        (&uneven, "uneven"),
        (&empty_part, "empty part"),
        (&decomposed, "decomposed"),
        (&flat, "flat"),
    ] {
        assert_eq!(
            (code(reply), reply.flags),
            (ErrorCode::Ok, reply_flags::SHAPE_BUILDING),
            "{what}: {}",
            reply.reason()
        );
    }
    for dims in [
        [-0.1, 0.0, 0.0, 0.0],
        [f64::NAN, 0.0, 0.0, 0.0],
        [0.0, 2.5, 0.0, 0.0],
        [0.0, 2000.0, 0.0, 0.0],
        [0.0, 0.0, 2.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ] {
        let refused = decompose(&mut state, dims, &TETRA_INDICES);
        assert_eq!(code(&refused), ErrorCode::InvalidShape, "{dims:?}");
    }
    // The wire's limit is the library's.
    assert_eq!(
        proxima_ipc::wire::MAX_COMPOUND_PARTS as usize,
        crate::narrow::compound::MAX_PARTS
    );
    let too_many = register(
        &mut state,
        ShapeKindCode::Compound,
        [0.0; 4],
        &[1; 1025][..],
    );
    assert_eq!(
        code(&too_many),
        ErrorCode::LimitExceeded,
        "{}",
        too_many.reason()
    );

    assert_eq!(build_all(&jobs), 5);
    for (reply, expected) in [
        (&compound, ErrorCode::Ok),
        (&uneven, ErrorCode::MalformedMessage),
        (&empty_part, ErrorCode::MalformedMessage),
        (&decomposed, ErrorCode::Ok),
        (&flat, ErrorCode::InvalidShape),
    ] {
        let built = shape_state(&mut state, scene, reply.id);
        assert_eq!(code(&built), expected, "{}", built.reason());
    }
    let cell = lock(state.scene(scene).unwrap());
    let parts = |id: u32| match cell.scene.shape(cell.shapes.usable(id).unwrap()) {
        Some(crate::narrow::Shape::Compound(c)) => c.parts().len(),
        other => panic!("shape {id}: {other:?}"),
    };
    assert_eq!((parts(compound.id), parts(decomposed.id)), (2, 1));
}

/// Every command that names a scene, as a request on `scene` (shape or body 0).
fn scene_commands(scene: u32) -> Vec<ControlRequest> {
    [
        Command::DropScene,
        Command::RegisterShape,
        Command::AddBody,
        Command::RemoveBody,
        Command::UpdateBody,
        Command::SetSceneParams,
        Command::ShapeState,
    ]
    .into_iter()
    .map(|command| match command {
        Command::RegisterShape => sphere_request(scene),
        command => ControlRequest {
            scene,
            ..request(command)
        },
    })
    .collect()
}

#[test]
fn only_the_creating_client_port_may_use_a_scene_and_the_reply_hands_it_the_keys() {
    let (mut state, _jobs) = state_with(DaemonConfig::default(), 4);
    let created = state.handle(OWNER, &request(Command::CreateScene), &[]);
    assert_eq!(code(&created), ErrorCode::Ok);
    assert_eq!(created.instance, INSTANCE);
    assert_ne!(created.frame_key, 0);
    assert_ne!(created.scene_token, [0, 0]);
    let scene = created.id;
    let shape = state.handle(OWNER, &sphere_request(scene), &[]).id;
    let add = ControlRequest {
        scene,
        target: shape,
        ..request(Command::AddBody)
    };
    assert_eq!(state.handle(OWNER, &add, &[]).id, 0);
    let intruder = other(1);
    for command in scene_commands(scene) {
        let reply = state.handle(intruder, &command, &[]);
        assert_eq!(code(&reply), ErrorCode::NotOwner, "{command:?}");
        assert_eq!(reply.instance, INSTANCE);
        assert_eq!((reply.frame_key, reply.scene_token), (0, [0, 0]));
    }
    // Nothing changed: the owner's body and shape are there, the scene lives.
    let cell = lock(state.scene(scene).unwrap());
    assert_eq!(cell.scene.body_count(), 1);
    drop(cell);
    // An id never handed out is unknown, whoever asks.
    for command in scene_commands(scene.wrapping_add(1)) {
        let reply = state.handle(intruder, &command, &[]);
        assert_eq!(code(&reply), ErrorCode::UnknownScene, "{command:?}");
    }
    let drop = ControlRequest {
        scene,
        ..request(Command::DropScene)
    };
    assert_eq!(code(&state.handle(OWNER, &drop, &[])), ErrorCode::Ok);
}

#[test]
fn scene_ids_and_keys_are_random_and_never_repeat_among_live_scenes() {
    let config = DaemonConfig {
        max_scenes: 200,
        client_quota: ClientQuota {
            scenes: 200,
            ..ClientQuota::STANDARD
        },
        ..DaemonConfig::default()
    };
    let (mut state, _jobs) = state_with(config, 4);
    let replies: Vec<ControlReply> = (0..200)
        .map(|_| state.handle(OWNER, &request(Command::CreateScene), &[]))
        .collect();
    let ids: std::collections::HashSet<u32> = replies.iter().map(|r| r.id).collect();
    let keys: std::collections::HashSet<u64> = replies.iter().map(|r| r.frame_key).collect();
    let tokens: std::collections::HashSet<[u64; 2]> =
        replies.iter().map(|r| r.scene_token).collect();
    assert_eq!((ids.len(), keys.len(), tokens.len()), (200, 200, 200));
    assert!(!ids.contains(&u32::MAX));
    // Not sequential: 200 consecutive ids from random draws would be a 2^-6000 event.
    let (low, high) = (ids.iter().min().unwrap(), ids.iter().max().unwrap());
    assert!(high - low > 200, "ids {low}..{high} look sequential");
}

#[test]
fn a_quarantined_scene_tells_its_owner_why_until_dropped_and_frees_its_slot() {
    let config = DaemonConfig {
        max_scenes: 1,
        ..DaemonConfig::default()
    };
    let (mut state, _jobs) = state_with(config, 4);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let shared = Arc::clone(state.scene(scene).unwrap());
    assert!(state.quarantine(scene, "results send: ConnectionBroken".to_owned()));
    assert!(!state.quarantine(scene, "again".to_owned()), "once only");
    assert!(
        lock(&shared).dropped,
        "a frame still holding it leaves it alone"
    );
    assert!(state.scene(scene).is_none());
    for command in scene_commands(scene) {
        if command.command == Command::DropScene as u32 {
            continue;
        }
        let reply = state.handle(OWNER, &command, &[]);
        assert_eq!(code(&reply), ErrorCode::SceneQuarantined, "{command:?}");
        assert!(
            reply.reason().contains("ConnectionBroken"),
            "{}",
            reply.reason()
        );
        let other = state.handle(other(1), &command, &[]);
        assert_eq!(code(&other), ErrorCode::NotOwner, "{command:?}");
    }
    // It still counts against the limit until its owner lets go of the id.
    let refused = state.handle(OWNER, &request(Command::CreateScene), &[]);
    assert_eq!(code(&refused), ErrorCode::LimitExceeded);
    let drop = ControlRequest {
        scene,
        ..request(Command::DropScene)
    };
    assert_eq!(code(&state.handle(OWNER, &drop, &[])), ErrorCode::Ok);
    assert_eq!(
        code(&state.handle(OWNER, &drop, &[])),
        ErrorCode::UnknownScene
    );
    let again = state.handle(OWNER, &request(Command::CreateScene), &[]);
    assert_eq!(code(&again), ErrorCode::Ok);
}

#[test]
fn shapes_are_charged_against_the_memory_budget_before_anything_is_copied_and_scenes_give_it_back()
{
    use super::super::budget_memory::{MESH_BYTES_PER_TRIANGLE, readable};
    // Room for one 4-triangle tetrahedron mesh, not two.
    let one_mesh = 4 * MESH_BYTES_PER_TRIANGLE + 4 * 64;
    let config_limit = one_mesh + one_mesh / 2;
    let config = DaemonConfig {
        max_memory_bytes: config_limit,
        ..DaemonConfig::default()
    };
    let (mut state, jobs) = state_with(config, 4);
    let payload = mesh_payload(&TETRA, &TETRA_INDICES);
    let first = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let second = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    assert_eq!(
        code(&state.handle(OWNER, &mesh_request(first, 4, 12), &payload)),
        ErrorCode::Ok
    );
    let refused = state.handle(OWNER, &mesh_request(second, 4, 12), &payload);
    assert_eq!(code(&refused), ErrorCode::LimitExceeded);
    let (limit, left) = (readable(config_limit), readable(config_limit - one_mesh));
    assert!(
        refused.reason().contains(&format!(
            "the daemon's {limit} for shapes and bodies has {left} left"
        )),
        "{}",
        refused.reason()
    );
    assert_eq!(build_all(&jobs), 1, "the refused one was never queued");
    // Primitives cost nothing against it.
    assert_eq!(
        code(&state.handle(OWNER, &sphere_request(second), &[])),
        ErrorCode::Ok
    );
    // Dropping the first scene gives its charge back; quarantining does too.
    let drop = ControlRequest {
        scene: first,
        ..request(Command::DropScene)
    };
    assert_eq!(code(&state.handle(OWNER, &drop, &[])), ErrorCode::Ok);
    assert_eq!(
        code(&state.handle(OWNER, &mesh_request(second, 4, 12), &payload)),
        ErrorCode::Ok
    );
    assert!(state.quarantine(second, "test fault".to_owned()));
    let third = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    assert_eq!(
        code(&state.handle(OWNER, &mesh_request(third, 4, 12), &payload)),
        ErrorCode::Ok
    );
}

/// Another port of [`OWNER`]'s process.
const OWNER_SECOND_PORT: Origin = Origin {
    port: 0x0B,
    process: OWNER.process,
};

#[test]
fn one_client_process_holds_at_most_its_quota_of_scenes_over_all_its_ports() {
    let config = DaemonConfig {
        max_scenes: 5,
        client_quota: ClientQuota {
            scenes: 2,
            ..ClientQuota::STANDARD
        },
        ..DaemonConfig::default()
    };
    let (mut state, _jobs) = state_with(config, 4);
    let create = request(Command::CreateScene);
    let first = state.handle(OWNER, &create, &[]).id;
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &create, &[])),
        ErrorCode::Ok
    );
    // A third port of the same process gets nothing more.
    for port in [OWNER, OWNER_SECOND_PORT] {
        let refused = state.handle(port, &create, &[]);
        assert_eq!(code(&refused), ErrorCode::LimitExceeded);
        assert!(
            refused
                .reason()
                .contains("this client process holds its limit of 2 scenes"),
            "{}",
            refused.reason()
        );
    }
    for client in [other(1), other(2)] {
        assert_eq!(code(&state.handle(client, &create, &[])), ErrorCode::Ok);
    }
    // The daemon-wide limit (5) still holds, and a dropped scene frees the quota.
    assert_eq!(code(&state.handle(other(3), &create, &[])), ErrorCode::Ok);
    assert_eq!(
        code(&state.handle(other(4), &create, &[])),
        ErrorCode::LimitExceeded
    );
    let drop = ControlRequest {
        scene: first,
        ..request(Command::DropScene)
    };
    assert_eq!(code(&state.handle(OWNER, &drop, &[])), ErrorCode::Ok);
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &create, &[])),
        ErrorCode::Ok
    );
    assert!(state.accounts_balance());
}

/// Shapes and bodies are counted over all of a process's scenes, whichever port made them;
/// removing a body or dropping a scene gives its share back; others are not touched.
#[test]
fn one_client_process_holds_at_most_its_quota_of_shapes_and_bodies() {
    let config = DaemonConfig {
        client_quota: ClientQuota {
            shapes: 3,
            bodies: 4,
            ..ClientQuota::STANDARD
        },
        ..DaemonConfig::default()
    };
    let (mut state, _jobs) = state_with(config, 4);
    let create = request(Command::CreateScene);
    let scenes = [
        state.handle(OWNER, &create, &[]).id,
        state.handle(OWNER_SECOND_PORT, &create, &[]).id,
    ];
    let ports = [OWNER, OWNER_SECOND_PORT];
    let mut spheres = Vec::new();
    for i in 0..3 {
        let reply = state.handle(ports[i % 2], &sphere_request(scenes[i % 2]), &[]);
        assert_eq!(code(&reply), ErrorCode::Ok);
        spheres.push(reply.id);
    }
    let refused = state.handle(OWNER, &sphere_request(scenes[0]), &[]);
    assert_eq!(code(&refused), ErrorCode::LimitExceeded);
    assert!(
        refused.reason().contains("3 shapes"),
        "{}",
        refused.reason()
    );
    let add = |i: usize| ControlRequest {
        scene: scenes[i % 2],
        target: spheres[i % 2],
        ..request(Command::AddBody)
    };
    let mut bodies = Vec::new();
    for i in 0..4 {
        let reply = state.handle(ports[i % 2], &add(i), &[]);
        assert_eq!(code(&reply), ErrorCode::Ok);
        bodies.push(reply.id);
    }
    let refused = state.handle(OWNER_SECOND_PORT, &add(1), &[]);
    assert_eq!(code(&refused), ErrorCode::LimitExceeded);
    assert!(
        refused.reason().contains("4 bodies"),
        "{}",
        refused.reason()
    );
    // Another process has its own quota.
    let theirs = state.handle(other(1), &create, &[]).id;
    let sphere = state.handle(other(1), &sphere_request(theirs), &[]).id;
    let their_body = ControlRequest {
        scene: theirs,
        target: sphere,
        ..request(Command::AddBody)
    };
    assert_eq!(
        code(&state.handle(other(1), &their_body, &[])),
        ErrorCode::Ok
    );
    // A removed body makes room for one more.
    let remove = ControlRequest {
        scene: scenes[0],
        target: bodies[0],
        ..request(Command::RemoveBody)
    };
    assert_eq!(code(&state.handle(OWNER, &remove, &[])), ErrorCode::Ok);
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &add(1), &[])),
        ErrorCode::Ok
    );
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &add(1), &[])),
        ErrorCode::LimitExceeded
    );
    assert!(state.accounts_balance());
    // A dropped scene gives back its shapes and bodies.
    let drop = ControlRequest {
        scene: scenes[1],
        ..request(Command::DropScene)
    };
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &drop, &[])),
        ErrorCode::Ok
    );
    assert_eq!(
        code(&state.handle(OWNER, &sphere_request(scenes[0]), &[])),
        ErrorCode::Ok
    );
    assert_eq!(code(&state.handle(OWNER, &add(0), &[])), ErrorCode::Ok);
    assert!(state.accounts_balance());
}

/// Bodies are charged to the daemon's memory budget too: whoever adds the body past it is
/// refused, and a removed body makes room again.
#[test]
fn bodies_are_charged_against_the_daemons_memory_budget() {
    use super::super::budget_memory::BODY_BYTES;
    let config = DaemonConfig {
        max_memory_bytes: 3 * BODY_BYTES,
        ..DaemonConfig::default()
    };
    let (mut state, _jobs) = state_with(config, 4);
    let create = request(Command::CreateScene);
    let [mine, theirs] = [OWNER, other(1)].map(|client| {
        let scene = state.handle(client, &create, &[]).id;
        let sphere = state.handle(client, &sphere_request(scene), &[]).id;
        ControlRequest {
            scene,
            target: sphere,
            ..request(Command::AddBody)
        }
    });
    let first = state.handle(OWNER, &mine, &[]).id;
    for _ in 0..2 {
        assert_eq!(code(&state.handle(other(1), &theirs, &[])), ErrorCode::Ok);
    }
    for (client, add) in [(OWNER, &mine), (other(1), &theirs)] {
        let refused = state.handle(client, add, &[]);
        assert_eq!(code(&refused), ErrorCode::LimitExceeded);
        assert!(
            refused.reason().contains(
                "it needs about 4 KiB; the daemon's 12 KiB for shapes and bodies has 0 KiB left"
            ),
            "{}",
            refused.reason()
        );
    }
    let remove = ControlRequest {
        scene: mine.scene,
        target: first,
        ..request(Command::RemoveBody)
    };
    assert_eq!(code(&state.handle(OWNER, &remove, &[])), ErrorCode::Ok);
    assert_eq!(code(&state.handle(other(1), &theirs, &[])), ErrorCode::Ok);
    assert!(state.accounts_balance());
}

/// Shape memory is counted per process besides the daemon-wide budget; a quarantined scene
/// gives its shapes back but still counts as a scene.
#[test]
fn one_client_process_holds_at_most_its_quota_of_shape_memory() {
    use super::super::budget_memory::MESH_BYTES_PER_TRIANGLE;
    let one_mesh = 4 * MESH_BYTES_PER_TRIANGLE + 4 * 64;
    let config = DaemonConfig {
        client_quota: ClientQuota {
            scenes: 2,
            memory_bytes: one_mesh + one_mesh / 2,
            ..ClientQuota::STANDARD
        },
        ..DaemonConfig::default()
    };
    let (mut state, jobs) = state_with(config, 4);
    let payload = mesh_payload(&TETRA, &TETRA_INDICES);
    let create = request(Command::CreateScene);
    let mine = state.handle(OWNER, &create, &[]).id;
    let second = state.handle(OWNER_SECOND_PORT, &create, &[]).id;
    let theirs = state.handle(other(1), &create, &[]).id;
    assert_eq!(
        code(&state.handle(OWNER, &mesh_request(mine, 4, 12), &payload)),
        ErrorCode::Ok
    );
    let refused = state.handle(OWNER_SECOND_PORT, &mesh_request(second, 4, 12), &payload);
    assert_eq!(code(&refused), ErrorCode::LimitExceeded);
    assert!(
        refused.reason().contains("this client process's"),
        "{}",
        refused.reason()
    );
    assert_eq!(
        code(&state.handle(other(1), &mesh_request(theirs, 4, 12), &payload)),
        ErrorCode::Ok,
        "another process has its own shape memory"
    );
    assert_eq!(build_all(&jobs), 2, "the refused one was never queued");
    assert!(state.quarantine(mine, "test fault".to_owned()));
    assert!(state.accounts_balance());
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &mesh_request(second, 4, 12), &payload)),
        ErrorCode::Ok,
        "the quarantined scene's shapes were given back"
    );
    assert_eq!(
        code(&state.handle(OWNER_SECOND_PORT, &create, &[])),
        ErrorCode::LimitExceeded,
        "the quarantined scene still counts as one"
    );
    assert!(state.accounts_balance());
}

/// While a frame holds a scene's lock, every request that needs it is given back unanswered
/// and changes nothing (no shape id, no memory charge, no body); other clients' requests and
/// requests that need no scene are answered; once the lock is free, the same request is.
#[test]
fn a_request_whose_scene_is_busy_waits_for_nothing_and_changes_nothing() {
    let (mut state, jobs) = state_with(DaemonConfig::default(), 4);
    let scene = state.handle(OWNER, &request(Command::CreateScene), &[]).id;
    let sphere = state.handle(OWNER, &sphere_request(scene), &[]).id;
    let shared = Arc::clone(state.scene(scene).unwrap());
    let add = ControlRequest {
        scene,
        target: sphere,
        ..request(Command::AddBody)
    };
    let mesh = mesh_request(scene, 4, 12);
    let payload = mesh_payload(&TETRA, &TETRA_INDICES);
    let busy_requests = [
        (add, Vec::new()),
        (mesh, payload.clone()),
        (sphere_request(scene), Vec::new()),
        (
            ControlRequest {
                scene,
                target: sphere,
                ..request(Command::ShapeState)
            },
            Vec::new(),
        ),
    ];
    {
        let _frame = lock(&shared);
        for (busy, payload) in &busy_requests {
            assert_eq!(state.handle_unless_busy(OWNER, busy, payload), None);
        }
        assert_eq!(state.memory_bytes, 0, "no memory charged");
        assert_eq!(jobs.len(), 0, "no build queued");
        let created = state.handle_unless_busy(other(1), &request(Command::CreateScene), &[]);
        assert_eq!(created.map(|r| code(&r)), Some(ErrorCode::Ok));
        let hello = state.handle_unless_busy(OWNER, &request(Command::Hello), &[]);
        assert_eq!(hello.map(|r| r.id), Some(PROTOCOL_VERSION));
        // Another client naming the busy scene is refused without its lock.
        let trespass = state.handle_unless_busy(other(1), &add, &[]);
        assert_eq!(trespass.map(|r| code(&r)), Some(ErrorCode::NotOwner));
    }
    let added = state
        .handle_unless_busy(OWNER, &add, &[])
        .expect("answered");
    assert_eq!((code(&added), added.id), (ErrorCode::Ok, 0));
    let registered = state
        .handle_unless_busy(OWNER, &mesh, &payload)
        .expect("answered");
    assert_eq!(
        (code(&registered), registered.id),
        (ErrorCode::Ok, 1),
        "the next shape id"
    );
    assert_eq!(build_all(&jobs), 1);
    assert_eq!(lock(&shared).scene.body_count(), 1);
}
