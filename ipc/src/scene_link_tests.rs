//! Unit tests of the frame link against an in-process responder that stands in for the
//! daemon on a scene's pose, result and event services.

use super::*;
use crate::EVENT_RESULTS_READY;
use crate::SceneToken;
use crate::wire::{RecordKind, ResultFrameHeader, ResultRecord, query};
use iceoryx2::node::NodeBuilder;
use iceoryx2::prelude::local;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Instant;

/// The keys of test scene `scene`, as a daemon would hand them out.
fn access(scene: u32) -> SceneAccess {
    SceneAccess {
        scene,
        token: SceneToken([u64::from(scene) + 1, 0x5eed]),
        frame_key: 0xfeed_0000 + u64::from(scene),
        instance: 0,
    }
}

/// How the test responder answers one pose frame; `None` leaves it unanswered.
type Answer = fn(&PoseFrameHeader, &[PoseRecord]) -> Option<(ResultFrameHeader, Vec<ResultRecord>)>;

/// Stands in for the daemon: opens a scene's services as the daemon does (pose
/// subscriber, result publisher growing by powers of two, notifier and listener), answers
/// every pose frame with `answer`, notifies [`EVENT_RESULTS_READY`], and reports each
/// answered `frame_seq` through a channel.
struct Responder {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    answered: mpsc::Receiver<u64>,
}

impl Responder {
    fn start(root: &str, scene: u32, answer: Answer) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let (sent, answered) = mpsc::channel();
        let (ready_tx, ready_rx) = mpsc::channel();
        let (root, flag) = (root.to_owned(), stop.clone());
        let thread = std::thread::spawn(move || {
            let node = NodeBuilder::new().create::<local::Service>().unwrap();
            let token = access(scene).token;
            let poses = crate::poses_service_builder(&node, &root, token)
                .unwrap()
                .create()
                .unwrap();
            let results = crate::results_service_builder(&node, &root, token)
                .unwrap()
                .create()
                .unwrap();
            let poses_ready = crate::poses_ready_service_builder(&node, &root, token)
                .unwrap()
                .create()
                .unwrap();
            let results_ready = crate::results_ready_service_builder(&node, &root, token)
                .unwrap()
                .create()
                .unwrap();
            let subscriber = poses.subscriber_builder().create().unwrap();
            let publisher = results
                .publisher_builder()
                .initial_max_slice_len(1024)
                .allocation_strategy(AllocationStrategy::PowerOfTwo)
                .max_loaned_samples(1)
                .create()
                .unwrap();
            let notifier = results_ready.notifier_builder().create().unwrap();
            let listener = poses_ready.listener_builder().create().unwrap();
            ready_tx.send(()).unwrap();
            while !flag.load(Ordering::Relaxed) {
                while let Some(frame) = subscriber.receive().unwrap() {
                    let header = *frame.user_header();
                    if let Some((reply, records)) = answer(&header, frame.payload()) {
                        let mut sample = publisher.loan_slice_uninit(records.len()).unwrap();
                        *sample.user_header_mut() = reply;
                        sample.write_from_slice(&records).send().unwrap();
                        notifier
                            .notify_with_custom_event_id(EventId::new(EVENT_RESULTS_READY))
                            .unwrap();
                    }
                    sent.send(header.frame_seq).unwrap();
                }
                listener
                    .timed_wait(|_| {}, Duration::from_millis(5))
                    .unwrap();
            }
        });
        ready_rx.recv().unwrap();
        Self {
            stop,
            thread: Some(thread),
            answered,
        }
    }

    /// The `frame_seq` of the next pose frame the responder handled.
    fn next(&self) -> u64 {
        self.answered
            .recv_timeout(Duration::from_secs(5))
            .expect("the responder handled a pose frame")
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

/// The echo answer: `frame_seq` back, one pair record per pose (`body_a = body`,
/// `distance = position[0]`, the rest of the pose in the other fields), and the pose
/// header's other fields in spare header fields so tests can check them.
fn echo(
    header: &PoseFrameHeader,
    poses: &[PoseRecord],
) -> Option<(ResultFrameHeader, Vec<ResultRecord>)> {
    let records = poses
        .iter()
        .enumerate()
        .map(|(i, pose)| ResultRecord {
            kind: RecordKind::Pair as u32,
            body_a: pose.body,
            body_b: pose.reserved,
            index: i as u32,
            distance: pose.position[0],
            point_a: pose.position,
            point_b: [
                pose.orientation[0],
                pose.orientation[1],
                pose.orientation[2],
            ],
            error_bound: pose.orientation[3],
            ..ResultRecord::default()
        })
        .collect::<Vec<_>>();
    let mut stage_ns = [0; crate::wire::stage::COUNT];
    stage_ns[0] = u64::from(header.count);
    stage_ns[1] = header.budget_ns;
    Some((
        ResultFrameHeader {
            protocol_version: header.protocol_version,
            frame_seq: header.frame_seq,
            error_body: header.scene,
            deepest_level: header.query_flags,
            pair_count: records.len() as u32,
            stage_ns,
            min_budget_ns: header.frame_key,
            ..ResultFrameHeader::default()
        },
        records,
    ))
}

/// Echoes, but with the counts a lying header would carry: `pair_count` is the low and
/// `contact_count` the high half of the frame's `budget_ns`.
fn liar(
    header: &PoseFrameHeader,
    poses: &[PoseRecord],
) -> Option<(ResultFrameHeader, Vec<ResultRecord>)> {
    let (mut reply, records) = echo(header, poses)?;
    reply.pair_count = header.budget_ns as u32;
    reply.contact_count = (header.budget_ns >> 32) as u32;
    Some((reply, records))
}

fn root(tag: &str) -> String {
    format!("scene-link-test-{}-{tag}", std::process::id())
}

fn node() -> Node<local::Service> {
    NodeBuilder::new().create::<local::Service>().unwrap()
}

/// Pose `i` of a seeded pseudo-random frame: every field distinct and checkable.
fn pose(seed: u64, i: usize) -> PoseRecord {
    let x = (seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ i as u64) as f64 * 1e-9;
    PoseRecord {
        body: (i as u32).wrapping_mul(2_654_435_761) ^ seed as u32,
        reserved: 0,
        position: [x, -(i as f64), 1e6 + i as f64],
        orientation: [0.5, -0.5, 0.5, -(i as f64) * 1e-3],
    }
}

/// Checks that `frame` is the echo of frame `seq` with `poses`.
fn assert_echo(frame: &ResultFrame<local::Service>, seq: u64, poses: &[PoseRecord]) {
    let header = frame.header();
    assert_eq!(header.frame_seq, seq);
    assert_eq!(header.protocol_version, PROTOCOL_VERSION);
    assert_eq!(header.stage_ns[0], poses.len() as u64);
    assert_eq!(frame.records().len(), poses.len());
    assert_eq!(frame.pairs().len(), poses.len());
    assert!(frame.contacts().is_empty());
    for (i, (record, pose)) in frame.records().iter().zip(poses).enumerate() {
        assert_eq!(record.index, i as u32);
        assert_eq!(record.body_a, pose.body);
        assert_eq!(record.body_b, pose.reserved);
        assert_eq!(record.distance.to_bits(), pose.position[0].to_bits());
        assert_eq!(record.point_a, pose.position);
        assert_eq!(
            record.point_b,
            [
                pose.orientation[0],
                pose.orientation[1],
                pose.orientation[2]
            ]
        );
        assert_eq!(record.error_bound, pose.orientation[3]);
    }
}

const WAIT: Duration = Duration::from_secs(5);

#[test]
fn a_frame_of_three_poses_round_trips_with_its_header() {
    let root = root("three");
    let responder = Responder::start(&root, 4, echo);
    let link = SceneLink::open(&node(), &root, &access(4)).unwrap();
    assert_eq!(link.scene(), 4);
    let poses: Vec<_> = (0..3).map(|i| pose(1, i)).collect();
    link.publish_poses(17, 250_000, query::CLOSE | query::CONTACTS, &poses)
        .unwrap();
    let frame = link.receive_results(WAIT).unwrap().expect("a result frame");
    assert_echo(&frame, 17, &poses);
    let header = frame.header();
    assert_eq!(header.error_body, 4, "the pose header carries the scene");
    assert_eq!(
        header.min_budget_ns,
        access(4).frame_key,
        "and its frame key"
    );
    assert_eq!(header.deepest_level, query::CLOSE | query::CONTACTS);
    assert_eq!(header.stage_ns[1], 250_000);
    assert_eq!(responder.next(), 17);
    drop(frame);
    assert!(link.try_receive_results().unwrap().is_none());
}

#[test]
fn a_scene_nobody_serves_is_refused_and_empty_frames_round_trip() {
    let root = root("first");
    let refused = SceneLink::open(&node(), &root, &access(0)).unwrap_err();
    assert_eq!(refused, SceneOpenError::NoSuchScene);
    let responder = Responder::start(&root, 0, echo);
    let link = SceneLink::open(&node(), &root, &access(0)).unwrap();
    link.publish_poses(1, 0, 0, &[]).unwrap();
    let frame = link.receive_results(WAIT).unwrap().expect("a result frame");
    assert_echo(&frame, 1, &[]);
    assert_eq!(responder.next(), 1);
}

#[test]
fn frames_beyond_the_initial_slice_grow_both_directions() {
    let root = root("large");
    let _responder = Responder::start(&root, 2, echo);
    let link = SceneLink::open(&node(), &root, &access(2)).unwrap();
    for (seq, count) in [
        (1u64, 10usize),
        (2, 1024),
        (3, 1025),
        (4, 5_000),
        (5, 7),
        (6, 5_000),
    ] {
        let poses: Vec<_> = (0..count).map(|i| pose(seq, i)).collect();
        link.publish_poses(seq, 0, query::DISTANCE, &poses).unwrap();
        let frame = link
            .receive_results_for(seq, WAIT)
            .unwrap()
            .expect("a result frame");
        assert_echo(&frame, seq, &poses);
    }
}

#[test]
fn publish_with_writes_exactly_what_fill_returns_in_index_order() {
    let root = root("fill");
    let _responder = Responder::start(&root, 3, echo);
    let link = SceneLink::open(&node(), &root, &access(3)).unwrap();
    for (seq, count) in [(10u64, 1usize), (11, 3), (12, 2_000)] {
        let mut calls = Vec::new();
        link.publish_poses_with(seq, 5, query::OVERLAP, count, |i| {
            calls.push(i);
            pose(seq, i)
        })
        .unwrap();
        assert_eq!(calls, (0..count).collect::<Vec<_>>());
        let frame = link.receive_results(WAIT).unwrap().expect("a result frame");
        let expected: Vec<_> = (0..count).map(|i| pose(seq, i)).collect();
        assert_echo(&frame, seq, &expected);
        assert_eq!(frame.header().deepest_level, query::OVERLAP);
        assert_eq!(frame.header().stage_ns[1], 5);
    }
}

#[test]
fn receive_times_out_with_none_when_nobody_answers() {
    let root = root("silent");
    let _responder = Responder::start(&root, 1, |_, _| None);
    let link = SceneLink::open(&node(), &root, &access(1)).unwrap();
    // Nobody answers: the wait must last its whole timeout and then give up.
    link.publish_poses(1, 0, 0, &[pose(1, 0)]).unwrap();
    for timeout in [
        Duration::ZERO,
        Duration::from_micros(30),
        Duration::from_millis(60),
    ] {
        let start = Instant::now();
        assert!(link.receive_results(timeout).unwrap().is_none());
        let elapsed = start.elapsed();
        assert!(elapsed >= timeout, "{elapsed:?} < {timeout:?}");
        assert!(
            elapsed < timeout + Duration::from_millis(500),
            "{elapsed:?}"
        );
    }
    let start = Instant::now();
    assert!(
        link.receive_results_for(1, Duration::from_millis(40))
            .unwrap()
            .is_none()
    );
    assert!(start.elapsed() >= Duration::from_millis(40));
}

#[test]
fn a_late_answer_is_caught_by_the_blocking_wait() {
    fn slow(
        header: &PoseFrameHeader,
        poses: &[PoseRecord],
    ) -> Option<(ResultFrameHeader, Vec<ResultRecord>)> {
        std::thread::sleep(Duration::from_millis(30));
        echo(header, poses)
    }
    let root = root("slow");
    let _responder = Responder::start(&root, 6, slow);
    let link = SceneLink::open(&node(), &root, &access(6)).unwrap();
    let poses = [pose(9, 0), pose(9, 1)];
    let start = Instant::now();
    link.publish_poses(9, 0, 0, &poses).unwrap();
    let frame = link.receive_results(WAIT).unwrap().expect("a result frame");
    assert!(start.elapsed() >= Duration::from_millis(30));
    assert_echo(&frame, 9, &poses);
}

#[test]
fn receive_for_skips_a_stale_frame() {
    let root = root("stale");
    let responder = Responder::start(&root, 5, echo);
    let link = SceneLink::open(&node(), &root, &access(5)).unwrap();
    let (old, new) = ([pose(1, 0)], [pose(2, 0), pose(2, 1)]);
    link.publish_poses(1, 0, 0, &old).unwrap();
    assert_eq!(responder.next(), 1);
    link.publish_poses(2, 0, 0, &new).unwrap();
    assert_eq!(responder.next(), 2);
    // Both answers now wait in the subscriber's queue, the stale one first.
    let frame = link.receive_results_for(2, WAIT).unwrap().expect("frame 2");
    assert_echo(&frame, 2, &new);
    drop(frame);
    assert!(
        link.try_receive_results().unwrap().is_none(),
        "frame 1 was dropped"
    );
    // Without the filter the stale frame comes first.
    link.publish_poses(3, 0, 0, &old).unwrap();
    assert_eq!(responder.next(), 3);
    link.publish_poses(4, 0, 0, &new).unwrap();
    assert_eq!(responder.next(), 4);
    assert_eq!(
        link.receive_results(WAIT)
            .unwrap()
            .unwrap()
            .header()
            .frame_seq,
        3
    );
    assert_eq!(
        link.receive_results(WAIT)
            .unwrap()
            .unwrap()
            .header()
            .frame_seq,
        4
    );
}

#[test]
fn pairs_and_contacts_clamp_to_the_payload_when_the_header_lies() {
    let root = root("liar");
    let _responder = Responder::start(&root, 7, liar);
    let link = SceneLink::open(&node(), &root, &access(7)).unwrap();
    let poses: Vec<_> = (0..3).map(|i| pose(7, i)).collect();
    // (pair_count, contact_count) → (pairs, contacts) over 3 records.
    let cases = [
        ((2u64, 1u64), (2usize, 1usize)),
        ((2, 5), (2, 1)),
        ((0, 3), (0, 3)),
        ((5, 5), (3, 0)),
        ((u32::MAX as u64, u32::MAX as u64), (3, 0)),
        ((1, 0), (1, 0)),
        ((0, 0), (0, 0)),
    ];
    for (seq, ((pair_count, contact_count), (pairs, contacts))) in cases.into_iter().enumerate() {
        let seq = seq as u64;
        link.publish_poses(seq, pair_count | contact_count << 32, 0, &poses)
            .unwrap();
        let frame = link
            .receive_results_for(seq, WAIT)
            .unwrap()
            .expect("a result frame");
        assert_eq!(frame.records().len(), 3);
        assert_eq!(frame.pairs(), &frame.records()[..pairs]);
        assert_eq!(frame.contacts(), &frame.records()[pairs..pairs + contacts]);
    }
}

#[test]
fn a_root_that_makes_no_service_name_is_refused() {
    let too_long = "r".repeat(300);
    let error = SceneLink::open(&node(), &too_long, &access(0)).unwrap_err();
    assert_eq!(error, SceneOpenError::InvalidRoot(too_long));
    assert!(error.to_string().contains("does not make valid"));
}

#[test]
fn too_many_poses_for_the_wire_count_are_refused_before_loaning() {
    let root = root("count");
    let _responder = Responder::start(&root, 0, echo);
    let link = SceneLink::open(&node(), &root, &access(0)).unwrap();
    let count = u32::MAX as usize + 1;
    let error = link
        .publish_poses_with(1, 0, 0, count, |_| unreachable!("nothing is loaned"))
        .unwrap_err();
    assert_eq!(error, FrameSendError::TooLarge(count));
    assert!(error.to_string().contains("4294967296"));
}

#[test]
fn a_connected_client_opens_the_scene_under_its_root() {
    let root = root("client");
    let stop = Arc::new(AtomicBool::new(false));
    let (ready_tx, ready_rx) = mpsc::channel();
    let (control_root, flag) = (root.clone(), stop.clone());
    // A control server that answers Hello, and CreateScene with scene 8's keys.
    let control = std::thread::spawn(move || {
        let node = node();
        let service = crate::control_service_builder(&node, &control_root)
            .unwrap()
            .create()
            .unwrap();
        let _events = crate::control_events_service_builder(&node, &control_root)
            .unwrap()
            .create()
            .unwrap();
        let server = service.server_builder().create().unwrap();
        ready_tx.send(()).unwrap();
        while !flag.load(Ordering::Relaxed) {
            while let Some(active) = server.receive().unwrap() {
                let command = active.user_header().command;
                let mut reply = crate::wire::ControlReply::ok(PROTOCOL_VERSION);
                if command == crate::wire::Command::CreateScene as u32 {
                    let keys = access(8);
                    reply.id = keys.scene;
                    reply.scene_token = keys.token.0;
                    reply.frame_key = keys.frame_key;
                }
                active.send_copy(reply).unwrap();
            }
            std::thread::sleep(Duration::from_micros(50));
        }
    });
    ready_rx.recv().unwrap();
    let _responder = Responder::start(&root, 8, echo);
    let client = crate::client::ClientBuilder::new()
        .root(&root)
        .connect::<local::Service>()
        .unwrap();
    assert_eq!(
        client.open_scene(8).unwrap_err(),
        SceneOpenError::NotOwned(8)
    );
    assert_eq!(client.create_scene().unwrap(), 8);
    assert_eq!(client.scene_access(8), Some(access(8)));
    let link = client.open_scene(8).unwrap();
    drop(client); // the link's ports keep what they need alive
    assert_eq!(link.scene(), 8);
    let poses = [pose(8, 0), pose(8, 1), pose(8, 2)];
    link.publish_poses(80, 0, 0, &poses).unwrap();
    let frame = link
        .receive_results_for(80, WAIT)
        .unwrap()
        .expect("a result frame");
    assert_echo(&frame, 80, &poses);
    stop.store(true, Ordering::Relaxed);
    control.join().unwrap();
}
