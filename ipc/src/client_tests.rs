//! Unit tests of the control client against an in-process responder that stands in for the
//! daemon on the control service.

use super::*;
use crate::wire::REASON_BYTES;
use iceoryx2::prelude::local;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;

/// How the test responder answers one request; `None` leaves it unanswered.
type Answer = fn(&ControlRequest, &[u8]) -> Option<ControlReply>;

/// A protocol-conformance responder: serves the control service from a thread, reports
/// every request it receives through a channel and answers with `answer`.
struct Responder {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    received: mpsc::Receiver<(ControlRequest, Vec<u8>)>,
}

impl Responder {
    fn start<S: Service>(root: &str, prefix: Option<&str>, answer: Answer) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let (sent, received) = mpsc::channel();
        let (ready_tx, ready_rx) = mpsc::channel();
        let (root, prefix, flag) = (root.to_owned(), prefix.map(str::to_owned), stop.clone());
        let thread = std::thread::spawn(move || {
            let mut config = Config::global_config().clone();
            if let Some(prefix) = prefix {
                config.global.prefix = FileName::new(prefix.as_bytes()).unwrap();
            }
            let node = NodeBuilder::new().config(&config).create::<S>().unwrap();
            let service = crate::control_service_builder(&node, &root)
                .unwrap()
                .open_or_create()
                .unwrap();
            let _events = crate::control_events_service_builder(&node, &root)
                .unwrap()
                .open_or_create()
                .unwrap();
            let server = service.server_builder().create().unwrap();
            ready_tx.send(()).unwrap();
            while !flag.load(Ordering::Relaxed) {
                while let Some(active) = server.receive().unwrap() {
                    let header = *active.user_header();
                    let payload = active.payload().to_vec();
                    if let Some(reply) = answer(&header, &payload) {
                        active.send_copy(reply).unwrap();
                    }
                    sent.send((header, payload)).unwrap();
                }
                std::thread::sleep(Duration::from_micros(20));
            }
        });
        ready_rx.recv().unwrap();
        Self {
            stop,
            thread: Some(thread),
            received,
        }
    }

    /// The next request the responder received.
    fn next(&self) -> (ControlRequest, Vec<u8>) {
        self.received
            .recv_timeout(Duration::from_secs(5))
            .expect("the responder received a request")
    }
}

impl Drop for Responder {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            thread.join().unwrap();
        }
    }
}

/// FNV-1a of the header's fields (their exact Debug text) and the payload, below
/// `u32::MAX`: the reply id by which the responder proves what it received.
fn fingerprint(header: &ControlRequest, payload: &[u8]) -> u32 {
    let text = format!("{header:?}");
    let mut hash: u32 = 0x811c_9dc5;
    for &byte in text.as_bytes().iter().chain(payload) {
        hash = (hash ^ u32::from(byte)).wrapping_mul(0x0100_0193);
    }
    hash.min(u32::MAX - 1)
}

fn conformance(header: &ControlRequest, payload: &[u8]) -> Option<ControlReply> {
    Some(if header.command == Command::Hello as u32 {
        ControlReply::ok(PROTOCOL_VERSION)
    } else {
        ControlReply::ok(fingerprint(header, payload))
    })
}

fn root(tag: &str) -> String {
    format!("client-test-{}-{tag}", std::process::id())
}

fn connect(root: &str) -> Client<local::Service> {
    ClientBuilder::new()
        .root(root)
        .reply_timeout(Duration::from_secs(2))
        .connect::<local::Service>()
        .unwrap()
}

/// The header every typed request starts from.
fn base(command: Command, scene: u32) -> ControlRequest {
    ControlRequest {
        protocol_version: PROTOCOL_VERSION,
        command: command as u32,
        scene,
        ..ControlRequest::default()
    }
}

/// Checks that the responder received exactly `header` and `payload`, and that `id` is
/// the fingerprint it answered with.
fn assert_received(
    responder: &Responder,
    id: Result<u32, ControlError>,
    header: ControlRequest,
    payload: &[u8],
) {
    let (got_header, got_payload) = responder.next();
    assert_eq!(got_header, header);
    assert_eq!(got_payload, payload);
    assert_eq!(id, Ok(fingerprint(&header, payload)));
}

#[test]
fn connect_says_hello_with_the_protocol_version() {
    let root = root("hello");
    let responder = Responder::start::<local::Service>(&root, None, conformance);
    let client = connect(&root);
    let (header, payload) = responder.next();
    assert_eq!(header, base(Command::Hello, 0));
    assert!(payload.is_empty());
    assert_eq!(client.root(), root);
    assert_eq!(client.reply_timeout(), Duration::from_secs(2));
}

#[test]
fn a_daemon_of_another_version_is_refused_either_way_it_says_so() {
    let root = root("mismatch-id");
    let _responder = Responder::start::<local::Service>(&root, None, |_, _| {
        Some(ControlReply::ok(PROTOCOL_VERSION + 1))
    });
    let error = ClientBuilder::new().root(&root).connect::<local::Service>();
    assert_eq!(
        error.unwrap_err(),
        ClientConnectError::ProtocolMismatch {
            daemon: PROTOCOL_VERSION + 1
        }
    );

    let root = self::root("mismatch-status");
    let _responder = Responder::start::<local::Service>(&root, None, |_, _| {
        let mut reply = ControlReply::error(ErrorCode::ProtocolMismatch, "version 1 only");
        reply.protocol_version = 7;
        Some(reply)
    });
    let error = ClientBuilder::new().root(&root).connect::<local::Service>();
    assert_eq!(
        error.unwrap_err(),
        ClientConnectError::ProtocolMismatch { daemon: 7 }
    );
}

#[test]
fn hello_refused_for_another_reason_is_reported_with_its_reason() {
    let root = root("hello-refused");
    let _responder = Responder::start::<local::Service>(&root, None, |_, _| {
        Some(ControlReply::error(ErrorCode::LimitExceeded, "64 clients"))
    });
    let error = ClientBuilder::new().root(&root).connect::<local::Service>();
    assert_eq!(
        error.unwrap_err(),
        ClientConnectError::Rejected {
            code: ErrorCode::LimitExceeded,
            reason: "64 clients".into()
        }
    );
}

#[test]
fn scene_and_body_commands_encode_every_field() {
    let root = root("commands");
    let responder = Responder::start::<local::Service>(&root, None, conformance);
    let client = connect(&root);
    responder.next(); // Hello

    assert_received(
        &responder,
        client.create_scene(),
        base(Command::CreateScene, 0),
        &[],
    );
    let dropped = client.drop_scene(7).map(|()| 0);
    let (header, payload) = responder.next();
    assert_eq!((header, payload.len()), (base(Command::DropScene, 7), 0));
    assert_eq!(dropped, Ok(0));

    for (margin, wire_margin) in [(None, -1.0), (Some(0.025), 0.025), (Some(0.0), 0.0)] {
        let spec = BodySpec {
            shape: 11,
            position: [1.5, -2.25, 1e6],
            orientation: [0.0, 0.6, 0.0, 0.8],
            motion: Motion::Kinematic,
            group: 0b1010,
            mask: 0xdead_beef,
            margin,
        };
        let expected = ControlRequest {
            target: 11,
            motion: MotionCode::Kinematic as u32,
            group: 0b1010,
            mask: 0xdead_beef,
            margin: wire_margin,
            position: [1.5, -2.25, 1e6],
            orientation: [0.0, 0.6, 0.0, 0.8],
            ..base(Command::AddBody, 3)
        };
        assert_received(&responder, client.add_body(3, &spec), expected, &[]);
    }

    client.remove_body(3, 42).unwrap();
    let (header, _) = responder.next();
    assert_eq!(
        header,
        ControlRequest {
            target: 42,
            ..base(Command::RemoveBody, 3)
        }
    );

    for (motion, code) in [
        (Motion::Static, MotionCode::Static),
        (Motion::Kinematic, MotionCode::Kinematic),
        (Motion::Dynamic, MotionCode::Dynamic),
    ] {
        client.update_body(4, 9, motion, 1, 2, Some(0.5)).unwrap();
        let (header, payload) = responder.next();
        let expected = ControlRequest {
            target: 9,
            motion: code as u32,
            group: 1,
            mask: 2,
            margin: 0.5,
            ..base(Command::UpdateBody, 4)
        };
        assert_eq!((header, payload.len()), (expected, 0));
    }
    client
        .update_body(4, 9, Motion::Dynamic, 0, 0, None)
        .unwrap();
    assert_eq!(responder.next().0.margin, -1.0);

    for code in [
        BroadPhaseCode::Auto,
        BroadPhaseCode::SortAndSweep,
        BroadPhaseCode::IncrementalSap,
        BroadPhaseCode::HashGrid,
        BroadPhaseCode::ColumnGrid,
        BroadPhaseCode::SkinGrid,
    ] {
        client.set_broad_phase(6, code).unwrap();
        let (header, payload) = responder.next();
        let expected = ControlRequest {
            broad_phase: code as u32,
            ..base(Command::SetSceneParams, 6)
        };
        assert_eq!((header, payload.len()), (expected, 0));
    }
}

#[test]
fn every_primitive_encodes_its_kind_and_dimensions() {
    let root = root("primitives");
    let responder = Responder::start::<local::Service>(&root, None, conformance);
    let client = connect(&root);
    responder.next(); // Hello
    let cases = [
        (
            Primitive::Sphere { radius: 0.5 },
            ShapeKindCode::Sphere,
            [0.5, 0.0, 0.0, 0.0],
        ),
        (
            Primitive::Capsule {
                radius: 0.1,
                half_height: 0.7,
            },
            ShapeKindCode::Capsule,
            [0.1, 0.7, 0.0, 0.0],
        ),
        (
            Primitive::Cuboid {
                half_extents: [1.0, 2.0, 3.0],
            },
            ShapeKindCode::Cuboid,
            [1.0, 2.0, 3.0, 0.0],
        ),
        (
            Primitive::Cylinder {
                radius: 0.3,
                half_height: 0.4,
            },
            ShapeKindCode::Cylinder,
            [0.3, 0.4, 0.0, 0.0],
        ),
        (
            Primitive::Cone {
                radius: 0.6,
                half_height: 0.9,
            },
            ShapeKindCode::Cone,
            [0.6, 0.9, 0.0, 0.0],
        ),
        // Bad dimensions are the daemon's to refuse; the client sends them unchanged.
        (
            Primitive::Sphere { radius: f64::NAN },
            ShapeKindCode::Sphere,
            [f64::NAN, 0.0, 0.0, 0.0],
        ),
    ];
    for (primitive, kind, dimensions) in cases {
        let expected = ControlRequest {
            shape_kind: kind as u32,
            dimensions,
            ..base(Command::RegisterShape, 5)
        };
        let id = client.register_primitive(5, primitive);
        let (header, payload) = responder.next();
        assert!(payload.is_empty());
        assert_eq!(header.shape_kind, kind as u32);
        assert_eq!(
            header.dimensions.map(f64::to_bits),
            dimensions.map(f64::to_bits)
        );
        assert_eq!(id, Ok(fingerprint(&expected, &[])));
    }
}

/// The geometry payload written independently of the client's encoder.
fn expected_geometry(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Vec<u8> {
    let mut bytes = Vec::new();
    for v in vertices {
        for x in v {
            bytes.extend_from_slice(&x.to_ne_bytes());
        }
    }
    for t in triangles {
        for i in t {
            bytes.extend_from_slice(&i.to_ne_bytes());
        }
    }
    bytes
}

/// A seeded pseudo-random coordinate in [−10, 10).
fn coordinate(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1);
    (*state >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 10.0
}

#[test]
fn convex_and_mesh_geometry_arrive_byte_exact_at_every_size() {
    let root = root("geometry");
    let responder = Responder::start::<local::Service>(&root, None, conformance);
    let client = connect(&root);
    responder.next(); // Hello
    let mut state = 7;
    // Empty, tiny, around the 4096-byte initial slice, then past it twice (grows).
    for vertex_count in [0usize, 1, 3, 170, 171, 2_000, 50_000] {
        let vertices: Vec<[f64; 3]> = (0..vertex_count)
            .map(|_| [0; 3].map(|_| coordinate(&mut state)))
            .collect();
        let triangles: Vec<[u32; 3]> = (0..vertex_count as u32 / 2)
            .map(|i| [i, (i * 7 + 1) % vertex_count as u32, u32::MAX - i])
            .collect();

        let payload = expected_geometry(&vertices, &[]);
        let header = ControlRequest {
            shape_kind: ShapeKindCode::Convex as u32,
            vertex_count: vertex_count as u32,
            ..base(Command::RegisterShape, 2)
        };
        assert_received(
            &responder,
            client.register_convex(2, &vertices),
            header,
            &payload,
        );

        let payload = expected_geometry(&vertices, &triangles);
        assert_eq!(payload.len(), 24 * vertex_count + 12 * triangles.len());
        let header = ControlRequest {
            shape_kind: ShapeKindCode::Mesh as u32,
            vertex_count: vertex_count as u32,
            index_count: 3 * triangles.len() as u32,
            ..base(Command::RegisterShape, 2)
        };
        let id = client.register_mesh(2, &vertices, &triangles);
        assert_received(&responder, id, header, &payload);
    }
}

#[test]
fn rejected_replies_carry_their_code_and_reason_and_unknown_statuses_are_kept() {
    let root = root("rejected");
    let responder = Responder::start::<local::Service>(&root, None, |header, _| {
        Some(match header.command {
            c if c == Command::Hello as u32 => ControlReply::ok(PROTOCOL_VERSION),
            c if c == Command::RemoveBody as u32 => {
                ControlReply::error(ErrorCode::UnknownBody, "body 7 is not in scene 2")
            }
            c if c == Command::CreateScene as u32 => {
                let long = "x".repeat(REASON_BYTES + 10);
                ControlReply::error(ErrorCode::LimitExceeded, &long)
            }
            _ => ControlReply {
                status: 99,
                ..ControlReply::ok(3)
            },
        })
    });
    let client = connect(&root);
    assert_eq!(
        client.remove_body(2, 7),
        Err(ControlError::Rejected {
            code: ErrorCode::UnknownBody,
            reason: "body 7 is not in scene 2".into()
        })
    );
    assert_eq!(
        client.create_scene(),
        Err(ControlError::Rejected {
            code: ErrorCode::LimitExceeded,
            reason: "x".repeat(REASON_BYTES)
        })
    );
    assert_eq!(client.drop_scene(1), Err(ControlError::UnknownStatus(99)));
    // The raw request hands back the reply without judging its status.
    let raw = client
        .request(&base(Command::RemoveBody, 2), &[1, 2, 3])
        .unwrap();
    assert_eq!(raw.status, ErrorCode::UnknownBody as u32);
    assert_eq!(raw.reason(), "body 7 is not in scene 2");
    let error = client.remove_body(2, 7).unwrap_err().to_string();
    assert!(
        error.contains("unknown body") && error.contains("scene 2"),
        "{error}"
    );
    responder.next(); // Hello
    responder.next(); // RemoveBody
    responder.next(); // CreateScene
    responder.next(); // DropScene
    assert_eq!(responder.next().1, [1, 2, 3]);
}

#[test]
fn the_raw_request_sends_any_header_and_payload_unchanged() {
    let root = root("raw");
    let responder = Responder::start::<local::Service>(&root, None, conformance);
    let client = connect(&root);
    responder.next(); // Hello
    let header = ControlRequest {
        protocol_version: 999,
        command: 12345,
        vertex_count: 1000,
        index_count: 1,
        ..ControlRequest::default()
    };
    let payload: Vec<u8> = (0..=255).cycle().take(5000).collect();
    let reply = client.request(&header, &payload).unwrap();
    assert_eq!(reply, ControlReply::ok(fingerprint(&header, &payload)));
    assert_eq!(responder.next(), (header, payload));
}

#[test]
fn an_unanswered_hello_is_sent_again_from_a_fresh_port() {
    /// Ignores the first Hello it sees (as a daemon whose connection to the client
    /// failed would), then conforms.
    fn deaf_to_the_first_hello(header: &ControlRequest, payload: &[u8]) -> Option<ControlReply> {
        static HELLOS: AtomicU32 = AtomicU32::new(0);
        let is_hello = header.command == Command::Hello as u32;
        if is_hello && HELLOS.fetch_add(1, Ordering::Relaxed) == 0 {
            return None;
        }
        conformance(header, payload)
    }
    let root = root("deaf");
    let responder = Responder::start::<local::Service>(&root, None, deaf_to_the_first_hello);
    let client = connect(&root);
    let (first, second) = (responder.next().0, responder.next().0);
    assert_eq!(first.command, Command::Hello as u32);
    assert_eq!(second.command, Command::Hello as u32);
    assert!(client.create_scene().is_ok());
    assert_eq!(responder.next().0.command, Command::CreateScene as u32);
}

#[test]
fn no_daemon_is_reported_once_the_timeout_has_passed() {
    let timeout = Duration::from_millis(150);
    let start = Instant::now();
    let error = ClientBuilder::new()
        .root(&root("nobody"))
        .reply_timeout(timeout)
        .connect::<local::Service>()
        .unwrap_err();
    let elapsed = start.elapsed();
    assert_eq!(error, ClientConnectError::NoDaemon);
    assert!(elapsed >= timeout, "{elapsed:?}");
    assert!(
        elapsed < timeout + Duration::from_millis(500),
        "{elapsed:?}"
    );
}

#[test]
fn a_daemon_that_stops_answering_times_out_each_request() {
    let root = root("silent");
    let responder = Responder::start::<local::Service>(&root, None, |header, _| {
        (header.command == Command::Hello as u32).then(|| ControlReply::ok(PROTOCOL_VERSION))
    });
    let timeout = Duration::from_millis(100);
    let client = ClientBuilder::new()
        .root(&root)
        .reply_timeout(timeout)
        .connect::<local::Service>()
        .unwrap();
    for _ in 0..6 {
        // More than max_active_requests_per_client: each timed-out request is released.
        let start = Instant::now();
        assert_eq!(client.create_scene(), Err(ControlError::Timeout));
        assert!(start.elapsed() >= timeout);
    }
    assert_eq!(responder.next().0.command, Command::Hello as u32);
    assert_eq!(responder.next().0.command, Command::CreateScene as u32);
}

#[test]
fn every_request_notifies_the_control_event_service_so_a_blocked_daemon_wakes() {
    let root = root("events");
    let _responder = Responder::start::<local::Service>(&root, None, conformance);
    let node = NodeBuilder::new().create::<local::Service>().unwrap();
    let listener = crate::control_events_service_builder(&node, &root)
        .unwrap()
        .open_or_create()
        .unwrap()
        .listener_builder()
        .create()
        .unwrap();
    let client = ClientBuilder::new()
        .root(&root)
        .connect::<local::Service>()
        .unwrap();
    let drain = || {
        let mut ids = Vec::new();
        listener.try_wait(|e| ids.push(e.id.as_value())).unwrap();
        ids
    };
    assert_eq!(drain(), [EVENT_CONTROL_SENT]); // Hello
    assert_eq!(drain(), Vec::<usize>::new());
    client.create_scene().unwrap();
    client.drop_scene(0).unwrap();
    assert_eq!(drain(), [EVENT_CONTROL_SENT]);
}

#[test]
fn a_daemon_that_went_away_or_was_replaced_is_reported_as_lost_without_waiting() {
    let root = root("replaced");
    let first = Responder::start::<local::Service>(&root, None, conformance);
    let timeout = Duration::from_secs(5);
    let client = ClientBuilder::new()
        .root(&root)
        .reply_timeout(timeout)
        .connect::<local::Service>()
        .unwrap();
    assert!(client.create_scene().is_ok());
    assert!(client.daemon_is_alive());
    drop(first); // its server port is gone
    let start = Instant::now();
    assert_eq!(client.create_scene(), Err(ControlError::DaemonLost));
    assert!(start.elapsed() < timeout, "{:?}", start.elapsed());
    assert!(!client.daemon_is_alive());
    // Another daemon serves the root now: still not the one this client said Hello to.
    let second = Responder::start::<local::Service>(&root, None, conformance);
    let start = Instant::now();
    assert_eq!(client.drop_scene(0), Err(ControlError::DaemonLost));
    assert!(start.elapsed() < timeout, "{:?}", start.elapsed());
    assert!(!client.daemon_is_alive());
    // A client that connects again is served by it.
    let rejoined = ClientBuilder::new()
        .root(&root)
        .connect::<local::Service>()
        .unwrap();
    assert!(rejoined.create_scene().is_ok());
    assert_eq!(second.next().0.command, Command::Hello as u32);
    assert_eq!(second.next().0.command, Command::CreateScene as u32);
    assert!(ControlError::DaemonLost.to_string().contains("reconnect"));
}

#[test]
fn a_daemon_under_another_iceoryx_prefix_is_invisible() {
    let root = root("prefix");
    let prefix = format!("proxima_client_test_{}_", std::process::id());
    let responder =
        Responder::start::<iceoryx2::prelude::ipc::Service>(&root, Some(&prefix), conformance);
    let other = ClientBuilder::new()
        .root(&root)
        .iceoryx_prefix(&format!("{prefix}other_"))
        .reply_timeout(Duration::from_millis(100))
        .connect::<iceoryx2::prelude::ipc::Service>();
    assert_eq!(other.unwrap_err(), ClientConnectError::NoDaemon);
    let client = ClientBuilder::new()
        .root(&root)
        .iceoryx_prefix(&prefix)
        .connect::<iceoryx2::prelude::ipc::Service>()
        .unwrap();
    assert!(client.create_scene().is_ok());
    drop((client, responder));
    // iceoryx2 leaves one small global-management segment per prefix behind.
    crate::tools::daemon_process::remove_shared_memory(&prefix);
}

#[test]
fn bad_roots_and_prefixes_are_refused_before_anything_is_sent() {
    let too_long = "r".repeat(300); // service names end at 255 characters
    let error = ClientBuilder::new()
        .root(&too_long)
        .reply_timeout(Duration::from_millis(50))
        .connect::<local::Service>();
    assert!(
        matches!(error, Err(ClientConnectError::InvalidRoot(_))),
        "{error:?}"
    );
    let error = ClientBuilder::new()
        .iceoryx_prefix("a/b")
        .connect::<local::Service>();
    assert_eq!(
        error.unwrap_err(),
        ClientConnectError::InvalidPrefix("a/b".into())
    );
}

/// Answers a geometry registration with shape 5, still building, and `ShapeState` with
/// "building" twice, then "ready".
fn builds_after_two_asks(header: &ControlRequest, _: &[u8]) -> Option<ControlReply> {
    static ASKED: AtomicU32 = AtomicU32::new(0);
    let building = ControlReply::ok_with(5, reply_flags::SHAPE_BUILDING);
    Some(match Command::from_u32(header.command) {
        Some(Command::Hello) => ControlReply::ok(PROTOCOL_VERSION),
        Some(Command::RegisterShape) => building,
        Some(Command::ShapeState) if ASKED.fetch_add(1, Ordering::SeqCst) < 2 => building,
        Some(Command::ShapeState) => ControlReply::ok(5),
        _ => ControlReply::error(ErrorCode::MalformedMessage, "not in this test"),
    })
}

#[test]
fn a_registration_waits_for_its_shape_to_be_built_unless_told_not_to() {
    let root = root("build-wait");
    let responder = Responder::start::<local::Service>(&root, None, builds_after_two_asks);
    let client = connect(&root);
    responder.next(); // Hello
    let triangle = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert_eq!(
        client.register_mesh_no_wait(2, &triangle, &[[0, 1, 2]]),
        Ok(Registration {
            shape: 5,
            ready: false
        })
    );
    assert_eq!(responder.next().0.command, Command::RegisterShape as u32);
    // Waiting asks until the shape is built: two "building" answers, then "ready".
    assert_eq!(client.register_mesh(2, &triangle, &[[0, 1, 2]]), Ok(5));
    assert_eq!(responder.next().0.command, Command::RegisterShape as u32);
    for _ in 0..3 {
        let (header, payload) = responder.next();
        let expected = ControlRequest {
            target: 5,
            ..base(Command::ShapeState, 2)
        };
        assert_eq!((header, payload.len()), (expected, 0));
    }
    assert_eq!(client.shape_state(2, 5), Ok(ShapeState::Ready));
    // A shape ready in the registration's reply is not asked about.
    let ready = ControlReply::ok(5);
    assert_eq!((ready.flags, accepted(&ready)), (0, Ok((5, 0))));
}

#[test]
fn a_failed_build_reaches_the_waiting_registration_with_its_code() {
    let root = root("build-fails");
    let _responder = Responder::start::<local::Service>(&root, None, |header, _| {
        Some(match Command::from_u32(header.command) {
            Some(Command::Hello) => ControlReply::ok(PROTOCOL_VERSION),
            Some(Command::RegisterShape) => ControlReply::ok_with(3, reply_flags::SHAPE_BUILDING),
            _ => ControlReply::error(ErrorCode::MeshIndexOutOfRange, "index 7 of 3 vertices"),
        })
    });
    let client = connect(&root);
    let triangle = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    assert_eq!(
        client.register_mesh(1, &triangle, &[[0, 1, 7]]),
        Err(ControlError::Rejected {
            code: ErrorCode::MeshIndexOutOfRange,
            reason: "index 7 of 3 vertices".into()
        })
    );
}

#[test]
fn a_shape_still_building_at_the_build_timeout_is_a_build_timeout() {
    let root = root("build-timeout");
    let _responder = Responder::start::<local::Service>(&root, None, |header, _| {
        Some(if header.command == Command::Hello as u32 {
            ControlReply::ok(PROTOCOL_VERSION)
        } else {
            ControlReply::ok_with(4, reply_flags::SHAPE_BUILDING)
        })
    });
    let client = ClientBuilder::new()
        .root(&root)
        .build_timeout(Duration::from_millis(5))
        .connect::<local::Service>()
        .unwrap();
    assert_eq!(client.build_timeout(), Duration::from_millis(5));
    let points = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    assert_eq!(
        client.register_convex(1, &points),
        Err(ControlError::BuildTimeout { shape: 4 })
    );
    assert_eq!(client.shape_state(1, 4), Ok(ShapeState::Building));
    assert!(
        client
            .wait_shape(1, 4)
            .unwrap_err()
            .to_string()
            .contains("shape 4")
    );
}

/// The instance id the [`instanced`] responder gives in `Hello`'s reply.
const INSTANCE: u64 = 0x5eed_0001;

/// Answers `Hello` as instance [`INSTANCE`], and every later request as another instance
/// (a restarted daemon behind the same server port, as far as replies tell).
fn instanced(header: &ControlRequest, _: &[u8]) -> Option<ControlReply> {
    let mut reply = ControlReply::ok(PROTOCOL_VERSION);
    reply.instance = if header.command == Command::Hello as u32 {
        INSTANCE
    } else {
        INSTANCE + 1
    };
    Some(reply)
}

#[test]
fn a_daemon_of_another_instance_is_refused_and_a_reply_of_another_is_a_lost_daemon() {
    let root = root("instance");
    let _responder = Responder::start::<local::Service>(&root, None, instanced);
    let builder = ClientBuilder::new()
        .root(&root)
        .reply_timeout(Duration::from_secs(2));
    let refused = builder
        .clone()
        .expect_instance(INSTANCE + 7)
        .connect::<local::Service>()
        .unwrap_err();
    assert_eq!(
        refused,
        ClientConnectError::UnexpectedDaemon { instance: INSTANCE }
    );
    let client = builder
        .expect_instance(INSTANCE)
        .connect::<local::Service>()
        .unwrap();
    assert_eq!(client.daemon_instance(), INSTANCE);
    assert_eq!(client.create_scene(), Err(ControlError::DaemonLost));
    assert_eq!(client.scene_access(PROTOCOL_VERSION), None, "nothing kept");
}
