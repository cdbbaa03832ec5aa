//! Control requests and shape builds run apart from the frames: `proximad`'s real threads
//! run in this process, with test hooks that hold every shape build, or every control
//! request, at a gate, and clients drive them over real iceoryx2 shared memory. While a
//! registration is held in its build, other scenes' frames and cheap control requests are
//! answered; the shape becomes usable once built; a body on it before then is refused with
//! `ShapeNotReady`. While a control request is held, frames are answered. Nothing here
//! measures time: each test holds the work for as long as it needs.

#[path = "support/daemon.rs"]
mod daemon_harness;
mod support;

use daemon_harness::{body, pose_at};
use iceoryx2::prelude::ipc;
use proxima::daemon::log::Level;
use proxima::daemon::{Daemon, DaemonConfig, DaemonRunError, Gate, StopHandle};
use proxima_ipc::client::{Client, ClientBuilder, Primitive, Registration, ShapeState};
use proxima_ipc::error::ControlError;
use proxima_ipc::scene_link::SceneLink;
use proxima_ipc::tools::daemon_process::{Isolation, remove_shared_memory};
use proxima_ipc::wire::{ErrorCode, PoseRecord, query};
use std::thread::JoinHandle;
use std::time::Duration;

/// Generous: only a broken daemon takes this long.
const TIMEOUT: Duration = Duration::from_secs(20);

/// The daemon on a thread of this process, its builds held at `gate` (closed at the
/// start), its control requests at `control` (open at the start); stopped and its shared
/// memory removed on drop (the gates opened first).
struct InProcessDaemon {
    isolation: Isolation,
    gate: Gate,
    control: Gate,
    stop: StopHandle,
    thread: Option<JoinHandle<Result<(), DaemonRunError>>>,
}

impl InProcessDaemon {
    fn start(max_queued_builds: usize) -> Self {
        let isolation = Isolation::unique("blds");
        let config = DaemonConfig {
            root: isolation.root.clone(),
            iceoryx_prefix: Some(isolation.prefix.clone()),
            sweep_interval: Duration::from_millis(10),
            log_level: Level::Error,
            max_queued_builds,
            ..DaemonConfig::default()
        };
        let (gate, control) = (Gate::closed(), Gate::opened());
        let (stop_tx, stop_rx) = std::sync::mpsc::channel();
        let (builds, requests) = (gate.clone(), control.clone());
        let thread = std::thread::spawn(move || {
            let mut daemon = Daemon::new(config).expect("the daemon starts");
            daemon.set_build_gate(builds);
            daemon.set_control_gate(requests);
            stop_tx.send(daemon.stop_handle()).expect("the test waits");
            daemon.run()
        });
        let stop = stop_rx.recv_timeout(TIMEOUT).expect("the daemon started");
        Self {
            isolation,
            gate,
            control,
            stop,
            thread: Some(thread),
        }
    }

    fn client(&self) -> Client<ipc::Service> {
        ClientBuilder::new()
            .root(&self.isolation.root)
            .iceoryx_prefix(&self.isolation.prefix)
            .reply_timeout(TIMEOUT)
            .build_timeout(TIMEOUT)
            .connect::<ipc::Service>()
            .expect("the daemon answers Hello")
    }
}

impl Drop for InProcessDaemon {
    fn drop(&mut self) {
        self.gate.open();
        self.control.open();
        self.stop.stop();
        if let Some(thread) = self.thread.take() {
            let stopped = thread.join();
            if !std::thread::panicking() {
                stopped
                    .expect("the daemon thread does not panic")
                    .expect("the daemon stops cleanly");
            }
        }
        remove_shared_memory(&self.isolation.prefix);
    }
}

/// A flat grid (`[-4, 4]²` in the plane z = 0, `2 n²` triangles) as wire arrays.
fn grid(n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mesh = support::meshes::grid(4.0, n);
    let vertices = mesh.vertices().iter().map(|v| v.to_array()).collect();
    (vertices, mesh.triangles().to_vec())
}

/// Publishes frame `seq` with body `i` at `(x[i], 0, 0)`, and returns the close pairs of
/// its answer.
fn close_pairs(link: &SceneLink<ipc::Service>, seq: u64, x: &[f64]) -> Vec<(u32, u32)> {
    let poses: Vec<PoseRecord> = (0..).zip(x).map(|(i, &x)| pose_at(i, x)).collect();
    link.publish_poses(seq, 0, query::CLOSE, &poses).unwrap();
    let frame = link
        .receive_results_for(seq, TIMEOUT)
        .unwrap()
        .expect("the frame is answered");
    assert_eq!(
        ErrorCode::from_u32(frame.header().status),
        Some(ErrorCode::Ok)
    );
    frame.pairs().iter().map(|p| (p.body_a, p.body_b)).collect()
}

/// A scene of two balls of radius 0.5, its sphere shape and its link; its first frame,
/// with the balls touching, answered.
struct TwoBalls {
    scene: u32,
    ball: u32,
    link: SceneLink<ipc::Service>,
}

impl TwoBalls {
    fn new(client: &Client<ipc::Service>) -> Self {
        let scene = client.create_scene().unwrap();
        let ball = client
            .register_primitive(scene, Primitive::Sphere { radius: 0.5 })
            .unwrap();
        for x in [0.0, 0.9] {
            client.add_body(scene, &body(ball, x)).unwrap();
        }
        let link = client.open_scene(scene).unwrap();
        assert_eq!(close_pairs(&link, 1, &[0.0, 0.9]), [(0, 1)]);
        Self { scene, ball, link }
    }
}

/// Frames 2 to 39 of a [`TwoBalls`] scene, the balls apart and touching by turns: each is
/// answered right, and answered while work is still held at `gate`.
fn frames_are_answered_while_held(link: &SceneLink<ipc::Service>, gate: &Gate) {
    for seq in 2..40u64 {
        let apart = 0.9 + if seq % 2 == 0 { 0.5 } else { 0.0 };
        let pairs = close_pairs(link, seq, &[0.0, apart]);
        assert_eq!(pairs.len(), usize::from(seq % 2 == 1), "frame {seq}");
        assert!(
            gate.is_holding(),
            "frame {seq} was answered while work was held"
        );
    }
}

fn refusal<T: std::fmt::Debug>(result: Result<T, ControlError>) -> ErrorCode {
    match result {
        Err(ControlError::Rejected { code, reason }) => {
            assert!(!reason.is_empty());
            code
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn frames_and_control_requests_are_answered_while_another_scenes_build_is_held() {
    let daemon = InProcessDaemon::start(4);
    let (framed, builder) = (daemon.client(), daemon.client());
    let TwoBalls { scene, ball, link } = TwoBalls::new(&framed);

    let other = builder.create_scene().unwrap();
    let (vertices, triangles) = grid(16);
    let registration = builder
        .register_mesh_no_wait(other, &vertices, &triangles)
        .unwrap();
    assert!(!registration.ready);
    assert!(
        daemon.gate.wait_until_holding(TIMEOUT),
        "the builder took the build"
    );

    // The build is held: the other scene's frames are answered all the same.
    frames_are_answered_while_held(&link, &daemon.gate);
    // So are control requests, of this client and of the one whose shape is building.
    assert_eq!(
        builder.shape_state(other, registration.shape),
        Ok(ShapeState::Building)
    );
    assert_eq!(
        refusal(builder.add_body(other, &body(registration.shape, 0.0))),
        ErrorCode::ShapeNotReady
    );
    let pebble = builder
        .register_primitive(other, Primitive::Sphere { radius: 0.25 })
        .unwrap();
    let pebble = builder.add_body(other, &body(pebble, 0.5)).unwrap();
    framed.add_body(scene, &body(ball, 5.0)).unwrap();
    assert!(daemon.gate.is_holding());

    // Once built, the shape takes bodies and its frames see it.
    daemon.gate.open();
    builder.wait_shape(other, registration.shape).unwrap();
    assert_eq!(
        builder.shape_state(other, registration.shape),
        Ok(ShapeState::Ready)
    );
    let floor = builder
        .add_body(other, &body(registration.shape, 0.0))
        .unwrap();
    assert_eq!((pebble, floor), (0, 1));
    // The pebble lies half sunk in the grid's plane.
    let other_link = builder.open_scene(other).unwrap();
    assert_eq!(close_pairs(&other_link, 1, &[0.5, 0.0]), [(0, 1)]);
}

#[test]
fn the_build_queue_is_bounded_and_a_dropped_scenes_held_build_changes_nothing() {
    let daemon = InProcessDaemon::start(1);
    let client = daemon.client();
    let scene = client.create_scene().unwrap();
    let (vertices, triangles) = grid(4);
    let register = || client.register_mesh_no_wait(scene, &vertices, &triangles);
    let held = register().unwrap();
    assert!(daemon.gate.wait_until_holding(TIMEOUT));
    let queued = register().unwrap();
    assert_eq!(
        (held, queued),
        (
            Registration {
                shape: 0,
                ready: false
            },
            Registration {
                shape: 1,
                ready: false
            }
        )
    );
    // One build held, one queued: the queue of one is full.
    assert_eq!(refusal(register()), ErrorCode::LimitExceeded);
    assert_eq!(
        refusal(client.shape_state(scene, 2)),
        ErrorCode::UnknownShape
    );

    client.drop_scene(scene).unwrap();
    assert_eq!(
        refusal(client.shape_state(scene, 0)),
        ErrorCode::UnknownScene
    );
    daemon.gate.open();
    // The daemon goes on: a new scene's mesh is built and used as if nothing happened.
    let fresh = client.create_scene().unwrap();
    let mesh = client.register_mesh(fresh, &vertices, &triangles).unwrap();
    assert_eq!(mesh, 0);
    assert_eq!(client.add_body(fresh, &body(mesh, 0.0)), Ok(0));
}

#[test]
fn frames_are_answered_while_a_control_request_is_held() {
    let daemon = InProcessDaemon::start(4);
    let framed = daemon.client();
    let TwoBalls { scene, link, .. } = TwoBalls::new(&framed);

    let (ready_tx, ready) = std::sync::mpsc::channel();
    let (go, go_rx) = std::sync::mpsc::channel();
    let (done_tx, done) = std::sync::mpsc::channel();
    std::thread::scope(|s| {
        let (isolation, ready_tx, done_tx) = (&daemon.isolation, ready_tx, done_tx);
        s.spawn(move || {
            let other = ClientBuilder::new()
                .root(&isolation.root)
                .iceoryx_prefix(&isolation.prefix)
                .reply_timeout(TIMEOUT)
                .connect::<ipc::Service>()
                .expect("the daemon answers Hello");
            ready_tx.send(()).unwrap();
            go_rx.recv().unwrap();
            done_tx.send(other.create_scene()).unwrap();
        });
        ready
            .recv_timeout(TIMEOUT)
            .expect("the other client connected");
        daemon.control.close();
        go.send(()).unwrap();
        assert!(
            daemon.control.wait_until_holding(TIMEOUT),
            "the request is held"
        );
        frames_are_answered_while_held(&link, &daemon.control);
        assert!(
            done.try_recv().is_err(),
            "the held request is not answered yet"
        );
        daemon.control.open();
        let created = done.recv_timeout(TIMEOUT).expect("the request is answered");
        let created = created.expect("a new scene");
        assert_ne!(created, scene, "a fresh id");
    });
}
