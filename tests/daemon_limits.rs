//! The daemon's configured limits, its configuration file and forged pose frames, through
//! the real `proximad` over shared memory: limits set in a `--config` file are enforced
//! exactly (at the limit succeeds, one beyond is `LimitExceeded`) while another client keeps
//! being served; the file's default margin reaches the scenes; a flag beats the file; a bad
//! file stops the daemon at once with the offending key on stderr; and frames whose header
//! lies (protocol, scene, count) or whose poses are not finite or not rotations are answered
//! with their code without touching any scene.

#[path = "support/daemon.rs"]
mod daemon_harness;

use daemon_harness::{ConfigFile, Daemon, body, pose_at};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::{EventId, ipc};
use iceoryx2::service::port_factory::event::PortFactory as EventPortFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSubPortFactory;
use proxima_ipc::client::{Client, Primitive};
use proxima_ipc::error::ControlError;
use proxima_ipc::scene_link::SceneLink;
use proxima_ipc::wire::{Completeness, ErrorCode, PoseFrameHeader, PoseRecord, frame_flags, query};
use proxima_ipc::{EVENT_POSES_SENT, PROTOCOL_VERSION};
use std::io::Read;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

const TIMEOUT: Duration = Duration::from_secs(10);
const RADIUS: f64 = 0.5;

/// The code of a refused control request (panics on success or another failure).
fn refusal<T: std::fmt::Debug>(result: Result<T, ControlError>) -> (ErrorCode, String) {
    match result {
        Err(ControlError::Rejected { code, reason }) => (code, reason),
        other => panic!("expected a refusal, got {other:?}"),
    }
}

/// A triangle strip: `vertices` points along x, zig-zagging in y, and its first `triangles`
/// triangles (`vertices ≥ triangles + 2`); later vertices are left unreferenced.
fn strip(vertices: usize, triangles: usize) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    assert!(vertices >= triangles + 2);
    let points = (0..vertices)
        .map(|i| [i as f64 * 0.1, (i % 2) as f64 * 0.1, 0.0])
        .collect();
    let tris = (0..triangles as u32).map(|i| [i, i + 1, i + 2]).collect();
    (points, tris)
}

/// The eight corners of a cube of half side 0.2, and with `extra` a ninth point outside it.
fn convex_points(extra: bool) -> Vec<[f64; 3]> {
    let mut points: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            let s = |bit: u32| if i & (1 << bit) != 0 { 0.2 } else { -0.2 };
            [s(0), s(1), s(2)]
        })
        .collect();
    if extra {
        points.push([0.0, 0.0, 0.5]);
    }
    points
}

/// A scene of two spheres of radius [`RADIUS`], body 0 at the origin and body 1 at
/// `(x1, 0, 0)`, with the scene's default margin; and a link to it.
struct TwoSpheres {
    scene: u32,
    link: SceneLink<ipc::Service>,
    seq: u64,
}

impl TwoSpheres {
    fn new(client: &Client<ipc::Service>, x1: f64) -> Self {
        let scene = client.create_scene().unwrap();
        let sphere = client
            .register_primitive(scene, Primitive::Sphere { radius: RADIUS })
            .unwrap();
        assert_eq!(client.add_body(scene, &body(sphere, 0.0)).unwrap(), 0);
        assert_eq!(client.add_body(scene, &body(sphere, x1)).unwrap(), 1);
        let link = client.open_scene(scene).unwrap();
        Self {
            scene,
            link,
            seq: 0,
        }
    }

    /// Moves body 1 to `x1` (body 0 stays where it is) and returns the close pairs' distances.
    fn close_pairs_with_body_1_at(&mut self, x1: f64) -> Vec<f64> {
        self.frame(&[pose_at(1, x1)])
    }

    /// Sends a valid CLOSE frame of `records`; asserts it is answered Ok and returns the
    /// reported pairs' distances (pairs must be bodies 0 and 1).
    fn frame(&mut self, records: &[PoseRecord]) -> Vec<f64> {
        self.seq += 1;
        self.link
            .publish_poses(self.seq, 0, query::CLOSE, records)
            .unwrap();
        let answer = self
            .link
            .receive_results_for(self.seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        assert_eq!(
            ErrorCode::from_u32(answer.header().status),
            Some(ErrorCode::Ok),
            "scene {} frame {}",
            self.scene,
            self.seq
        );
        answer
            .pairs()
            .iter()
            .map(|p| {
                assert_eq!((p.body_a, p.body_b), (0, 1));
                p.distance
            })
            .collect()
    }

    /// Asserts that a frame putting body 1 at `x1` yields exactly one close pair at the
    /// analytic sphere–sphere distance `x1 − 2r`.
    fn assert_served(&mut self, x1: f64) {
        let pairs = self.close_pairs_with_body_1_at(x1);
        assert_eq!(pairs.len(), 1, "body 1 at {x1}: {pairs:?}");
        let want = x1 - 2.0 * RADIUS;
        assert!((pairs[0] - want).abs() < 1e-12, "{} vs {want}", pairs[0]);
    }
}

#[test]
fn limits_from_the_config_file_are_enforced_exactly_while_another_client_is_served() {
    let file = ConfigFile::new(
        "[limits]\n\
         max_mesh_triangles = 12\n\
         max_mesh_vertices = 20\n\
         max_bodies_per_scene = 4\n\
         max_shapes_per_scene = 3\n\
         max_convex_points = 8\n\
         [scene]\n\
         default_margin_m = 0.05\n",
    );
    let daemon = Daemon::start_with(&["--config", file.path()]);
    let (client, other) = (daemon.client(), daemon.client());
    let mut served = TwoSpheres::new(&other, 0.95);
    let mut x1 = 0.95;
    // After every refusal the other client's scene answers correctly, body 1 a bit further.
    let mut after_refusal = || {
        x1 += 0.005;
        served.assert_served(x1);
    };
    let scene = client.create_scene().unwrap();

    let (points, triangles) = strip(15, 13);
    let (code, reason) = refusal(client.register_mesh(scene, &points, &triangles));
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
    assert!(reason.contains("13 triangles"), "{reason}");
    after_refusal();
    let (points, triangles) = strip(21, 12);
    let (code, reason) = refusal(client.register_mesh(scene, &points, &triangles));
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
    assert!(reason.contains("21 vertices"), "{reason}");
    after_refusal();
    let (points, triangles) = strip(20, 12);
    let mesh = client.register_mesh(scene, &points, &triangles).unwrap();

    let (code, reason) = refusal(client.register_convex(scene, &convex_points(true)));
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
    after_refusal();
    let convex = client
        .register_convex(scene, &convex_points(false))
        .unwrap();

    let sphere = client
        .register_primitive(scene, Primitive::Sphere { radius: 0.1 })
        .unwrap();
    assert!(mesh != convex && convex != sphere && mesh != sphere);
    let (code, reason) =
        refusal(client.register_primitive(scene, Primitive::Sphere { radius: 0.2 }));
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
    assert!(reason.contains("3 shapes"), "{reason}");
    after_refusal();

    let shapes = [mesh, convex, sphere, sphere];
    let bodies: Vec<u32> = shapes
        .iter()
        .enumerate()
        .map(|(i, &shape)| {
            client
                .add_body(scene, &body(shape, 3.0 * i as f64))
                .unwrap()
        })
        .collect();
    let (code, reason) = refusal(client.add_body(scene, &body(sphere, 20.0)));
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
    assert!(reason.contains("4 bodies"), "{reason}");
    after_refusal();
    // Room again once a body is gone: the limit counts live bodies.
    client.remove_body(scene, bodies[3]).unwrap();
    client.add_body(scene, &body(sphere, 20.0)).unwrap();
    let (code, _) = refusal(client.add_body(scene, &body(sphere, 30.0)));
    assert_eq!(code, ErrorCode::LimitExceeded);
    after_refusal();
}

#[test]
fn the_config_files_default_margin_reaches_new_scenes() {
    let file = ConfigFile::new("[scene]\ndefault_margin_m = 0.05\n");
    let daemon = Daemon::start_with(&["--config", file.path()]);
    let client = daemon.client();
    let mut scene = TwoSpheres::new(&client, 5.0);
    // Surface gap 0.08 ≤ 0.05 + 0.05: a close pair at the analytic distance.
    let pairs = scene.close_pairs_with_body_1_at(1.08);
    assert_eq!(pairs.len(), 1, "{pairs:?}");
    assert!((pairs[0] - 0.08).abs() < 1e-12, "{}", pairs[0]);
    // Gap 0.12 > 0.1: not close.
    assert_eq!(scene.close_pairs_with_body_1_at(1.12), Vec::<f64>::new());
    // And the 0.08 gap is close again (the answer follows the poses, not a stale state).
    assert_eq!(scene.close_pairs_with_body_1_at(1.08).len(), 1);
}

#[test]
fn a_frame_beyond_the_pair_limit_answers_the_limit_and_says_how_many_it_dropped() {
    let file = ConfigFile::new("[limits]\nmax_pairs_per_frame = 10\n");
    let daemon = Daemon::start_with(&["--config", file.path()]);
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let sphere = client
        .register_primitive(scene, Primitive::Sphere { radius: RADIUS })
        .unwrap();
    // Eight spheres at nearly one place: 28 overlapping pairs, 18 over the limit.
    for i in 0..8 {
        client
            .add_body(scene, &body(sphere, 0.001 * f64::from(i)))
            .unwrap();
    }
    let link = client.open_scene(scene).unwrap();
    let records: Vec<PoseRecord> = (0..8).map(|i| pose_at(i, 0.001 * f64::from(i))).collect();
    for (seq, expected_drop) in [(1, 18), (2, 18)] {
        link.publish_poses(seq, 0, query::CLOSE, &records).unwrap();
        let answer = link
            .receive_results_for(seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        let header = answer.header();
        assert_eq!(ErrorCode::from_u32(header.status), Some(ErrorCode::Ok));
        assert_eq!((header.pair_count, answer.pairs().len()), (10, 10));
        assert_eq!(header.dropped_candidates, expected_drop);
        assert_ne!(header.flags & frame_flags::PAIRS_CAPPED, 0);
    }
    // Apart, no pair is found and nothing is dropped.
    let apart: Vec<PoseRecord> = (0..8).map(|i| pose_at(i, 10.0 * f64::from(i))).collect();
    link.publish_poses(3, 0, query::CLOSE, &apart).unwrap();
    let answer = link
        .receive_results_for(3, TIMEOUT)
        .unwrap()
        .expect("an answer");
    assert_eq!(
        (answer.header().dropped_candidates, answer.header().flags),
        (0, 0)
    );
}

#[test]
fn a_frame_whose_budget_cannot_hold_the_broad_phase_and_publishing_says_what_it_needs() {
    let daemon = Daemon::start();
    let client = daemon.client();
    let scene = TwoSpheres::new(&client, 0.5);
    let answer = |seq: u64, budget_ns: u64| {
        scene
            .link
            .publish_poses(seq, budget_ns, query::CLOSE, &[pose_at(1, 0.5)])
            .unwrap();
        let frame = scene
            .link
            .receive_results_for(seq, TIMEOUT)
            .unwrap()
            .expect("an answer");
        (*frame.header(), frame.pairs().len())
    };
    // The first two 1 ns frames run (nothing measured yet: the first builds the broad
    // phase, which is not what later frames cost) and are late; the next is not started.
    for seq in 1..=2 {
        let (unmeasured, pairs) = answer(seq, 1);
        assert_eq!(
            (unmeasured.flags & frame_flags::BUDGET_TOO_SMALL, pairs),
            (0, 1)
        );
        assert_eq!(unmeasured.budget_met, 0);
    }
    let (refused, pairs) = answer(3, 1);
    assert_eq!(ErrorCode::from_u32(refused.status), Some(ErrorCode::Ok));
    assert_ne!(refused.flags & frame_flags::BUDGET_TOO_SMALL, 0);
    assert!(refused.min_budget_ns > 1, "{}", refused.min_budget_ns);
    assert_eq!((refused.pair_count, pairs), (0, 0));
    assert_eq!(refused.completeness, Completeness::Truncated as u32);
    // The budget it names (with room to spare) and no budget at all are answered in full.
    let (served, pairs) = answer(4, 1_000 * refused.min_budget_ns);
    assert_eq!((served.flags, served.min_budget_ns, pairs), (0, 0, 1));
    let (unbudgeted, pairs) = answer(5, 0);
    assert_eq!((unbudgeted.flags, pairs), (0, 1));
    drop(scene);
}

#[test]
fn a_scene_limit_flag_beats_the_config_file() {
    let file = ConfigFile::new("[limits]\nmax_scenes = 3\n");
    let daemon = Daemon::start_plain(&["--config", file.path(), "--max-scenes", "1"]);
    let client = daemon.client();
    client.create_scene().unwrap();
    let (code, reason) = refusal(client.create_scene());
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
}

#[test]
fn the_config_files_scene_limit_applies_without_a_flag() {
    let file = ConfigFile::new("[limits]\nmax_scenes = 2\n");
    let daemon = Daemon::start_plain(&["--config", file.path()]);
    let client = daemon.client();
    client.create_scene().unwrap();
    client.create_scene().unwrap();
    let (code, reason) = refusal(client.create_scene());
    assert_eq!(code, ErrorCode::LimitExceeded, "{reason}");
}

/// Runs `proximad --config` on `text`; asserts it exits non-zero within 10 s and returns its
/// stderr. Never hangs: a daemon still running at the deadline is killed and the test fails.
fn refused_config_stderr(text: &str) -> String {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let file = ConfigFile::new(text);
    let tag = format!(
        "{}_{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    );
    let prefix = format!("iox2_pxbadcfg{tag}_");
    let mut child = Command::new(env!("CARGO_BIN_EXE_proximad"))
        .args(["--config", file.path()])
        .args(["--root", &format!("proxima-badcfg-{tag}")])
        .args(["--iceoryx-prefix", &prefix])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("proximad starts");
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            daemon_harness::remove_shared_memory(&prefix);
            panic!("proximad kept running with the bad configuration {text:?}");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut stderr)
        .unwrap();
    daemon_harness::remove_shared_memory(&prefix);
    assert!(!status.success(), "{text:?} was accepted: {stderr}");
    stderr
}

#[test]
fn a_bad_config_file_stops_the_daemon_at_once_naming_the_key() {
    let cases = [
        ("[limits]\nmax_scene = 3\n", "max_scene"),
        (
            "[limits]\nmax_bodies_per_scene = 0\n",
            "limits.max_bodies_per_scene",
        ),
        (
            "[limits]\nmax_mesh_vertices = 0\n",
            "limits.max_mesh_vertices",
        ),
        (
            "[scene]\ndefault_margin_m = -0.1\n",
            "scene.default_margin_m",
        ),
        (
            "[limits]\nmax_convex_points = \"eight\"\n",
            "max_convex_points",
        ),
        (
            "[limits]\nmax_shapes_per_scene = = 3\n",
            "max_shapes_per_scene",
        ),
        ("spin_us = 50\n", "spin_us"),
    ];
    for (text, key) in cases {
        let stderr = refused_config_stderr(text);
        assert!(
            stderr.contains(key),
            "{text:?}: stderr does not name {key}: {stderr}"
        );
    }
}

/// A raw pose publisher and notifier on one scene's services, to send frames whose header
/// the client library would never write.
struct Forger {
    publisher: Publisher<ipc::Service, [PoseRecord], PoseFrameHeader>,
    notifier: Notifier<ipc::Service>,
    _poses: PubSubPortFactory<ipc::Service, [PoseRecord], PoseFrameHeader>,
    _ready: EventPortFactory<ipc::Service>,
}

impl Forger {
    fn new(client: &Client<ipc::Service>, scene: u32) -> Self {
        let token = client
            .scene_access(scene)
            .expect("the client's scene")
            .token;
        let poses = proxima_ipc::poses_service_builder(client.node(), client.root(), token)
            .unwrap()
            .open()
            .unwrap();
        let ready = proxima_ipc::poses_ready_service_builder(client.node(), client.root(), token)
            .unwrap()
            .open()
            .unwrap();
        let publisher = poses
            .publisher_builder()
            .initial_max_slice_len(16)
            .create()
            .unwrap();
        let notifier = ready.notifier_builder().create().unwrap();
        Self {
            publisher,
            notifier,
            _poses: poses,
            _ready: ready,
        }
    }

    /// Publishes `records` under `header`, verbatim, and notifies the daemon.
    fn send(&self, header: PoseFrameHeader, records: &[PoseRecord]) {
        let mut sample = self.publisher.loan_slice_uninit(records.len()).unwrap();
        *sample.user_header_mut() = header;
        sample.write_from_fn(|i| records[i]).send().unwrap();
        self.notifier
            .notify_with_custom_event_id(EventId::new(EVENT_POSES_SENT))
            .unwrap();
    }
}

#[test]
fn forged_headers_and_unusable_poses_are_answered_with_their_code_and_touch_no_scene() {
    let daemon = Daemon::start();
    let (bad_client, good_client) = (daemon.client(), daemon.client());
    let mut bad = TwoSpheres::new(&bad_client, 0.9);
    let mut good = TwoSpheres::new(&good_client, 0.9);
    let forger = Forger::new(&bad_client, bad.scene);
    let bad_scene = bad.scene;
    let frame_key = bad_client.scene_access(bad_scene).unwrap().frame_key;
    let header = move |seq: u64, count: u32| PoseFrameHeader {
        protocol_version: PROTOCOL_VERSION,
        scene: bad_scene,
        frame_seq: seq,
        budget_ns: 0,
        query_flags: query::CLOSE,
        count,
        frame_key,
    };
    // Every bad frame would move body 0 of a scene away from body 1 if it were applied.
    let away = pose_at(0, -5.0);
    let inf = PoseRecord {
        position: [0.0, f64::INFINITY, 0.0],
        ..pose_at(1, 0.9)
    };
    let zero_rotation = PoseRecord {
        orientation: [0.0; 4],
        ..pose_at(1, 0.9)
    };
    let cases: Vec<(&str, PoseFrameHeader, Vec<PoseRecord>, ErrorCode, u32)> = vec![
        (
            "newer protocol",
            PoseFrameHeader {
                protocol_version: PROTOCOL_VERSION + 1,
                ..header(0, 1)
            },
            vec![away],
            ErrorCode::ProtocolMismatch,
            u32::MAX,
        ),
        (
            "protocol 0",
            PoseFrameHeader {
                protocol_version: 0,
                ..header(0, 1)
            },
            vec![away],
            ErrorCode::ProtocolMismatch,
            u32::MAX,
        ),
        (
            "another live scene's id",
            PoseFrameHeader {
                scene: good.scene,
                ..header(0, 1)
            },
            vec![away],
            ErrorCode::UnknownScene,
            u32::MAX,
        ),
        (
            "count above the payload",
            header(0, 2),
            vec![away],
            ErrorCode::MalformedMessage,
            u32::MAX,
        ),
        (
            "count below the payload",
            header(0, 1),
            vec![away, pose_at(1, 0.9)],
            ErrorCode::MalformedMessage,
            u32::MAX,
        ),
        (
            "count zero, one record",
            header(0, 0),
            vec![away],
            ErrorCode::MalformedMessage,
            u32::MAX,
        ),
        (
            "infinite position",
            header(0, 2),
            vec![away, inf],
            ErrorCode::InvalidPose,
            1,
        ),
        (
            "zero quaternion",
            header(0, 2),
            vec![away, zero_rotation],
            ErrorCode::InvalidPose,
            1,
        ),
    ];
    let mut good_x = 0.9;
    for (what, mut frame_header, records, code, error_body) in cases {
        bad.seq += 1;
        frame_header.frame_seq = bad.seq;
        forger.send(frame_header, &records);
        let answer = bad
            .link
            .receive_results_for(bad.seq, TIMEOUT)
            .unwrap()
            .unwrap_or_else(|| panic!("{what}: no answer"));
        let h = answer.header();
        assert_eq!(ErrorCode::from_u32(h.status), Some(code), "{what}");
        assert_eq!(
            (
                h.error_body,
                h.pair_count,
                h.contact_count,
                h.protocol_version
            ),
            (error_body, 0, 0, PROTOCOL_VERSION),
            "{what}"
        );
        assert!(answer.records().is_empty(), "{what}");
        drop(answer);
        // The other client's next frame is answered, and its body 0 was not moved.
        good_x += 0.005;
        good.assert_served(good_x);
        // The bad client's own scene was not touched either: an empty frame sees body 0 at
        // the origin and body 1 at 0.9.
        let pairs = bad.frame(&[]);
        assert_eq!(pairs.len(), 1, "{what}: {pairs:?}");
        assert!((pairs[0] - (0.9 - 2.0 * RADIUS)).abs() < 1e-12, "{what}");
    }
    // The forged port sends good frames too: the refusals were about content, not the port.
    bad.seq += 1;
    forger.send(
        PoseFrameHeader {
            frame_seq: bad.seq,
            ..header(0, 1)
        },
        &[pose_at(1, 0.95)],
    );
    let answer = bad
        .link
        .receive_results_for(bad.seq, TIMEOUT)
        .unwrap()
        .expect("an answer");
    assert_eq!(
        ErrorCode::from_u32(answer.header().status),
        Some(ErrorCode::Ok)
    );
    assert!((answer.pairs()[0].distance - (0.95 - 2.0 * RADIUS)).abs() < 1e-12);
}
