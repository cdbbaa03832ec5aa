//! Unit tests of the crate root: service settings, names and the wire over real iceoryx2.

use super::*;
use iceoryx2::prelude::*;
use wire::{
    ErrorCode, PoseFrameHeader, PoseRecord, RecordKind, ResultFrameHeader, ResultRecord, query,
};

#[test]
fn reply_reasons_are_cut_at_a_character_boundary_and_read_back() {
    let reply = wire::ControlReply::error(ErrorCode::UnknownBody, "body 7 is not in scene 2");
    assert_eq!(reply.status, ErrorCode::UnknownBody as u32);
    assert_eq!(reply.id, u32::MAX);
    assert_eq!(reply.reason(), "body 7 is not in scene 2");
    let long = "é".repeat(100); // 200 bytes, two per character
    let cut = wire::ControlReply::error(ErrorCode::Internal, &long).reason();
    assert_eq!(cut, "é".repeat(wire::REASON_BYTES / 2));
    assert_eq!(wire::ControlReply::ok(5).reason(), "");
}

#[test]
fn a_control_request_with_geometry_gets_its_reply_over_a_real_service() {
    let node = NodeBuilder::new().create::<local::Service>().unwrap();
    let name = control_service_name(&format!("wire-test-{}", std::process::id()));
    let control = node
        .service_builder(&name.as_str().try_into().unwrap())
        .request_response::<[u8], wire::ControlReply>()
        .request_user_header::<wire::ControlRequest>()
        .open_or_create()
        .unwrap();
    let (vertices, indices) = (
        [0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0],
        [0u32, 1, 2],
    );
    let mut bytes: Vec<u8> = vertices.iter().flat_map(|v| v.to_ne_bytes()).collect();
    bytes.extend(indices.iter().flat_map(|i| i.to_ne_bytes()));
    let header = wire::ControlRequest {
        protocol_version: PROTOCOL_VERSION,
        command: wire::Command::RegisterShape as u32,
        shape_kind: wire::ShapeKindCode::Mesh as u32,
        vertex_count: 3,
        index_count: 3,
        ..wire::ControlRequest::default()
    };
    let client = control
        .client_builder()
        .initial_max_slice_len(bytes.len())
        .create()
        .unwrap();
    let server = control.server_builder().create().unwrap();
    let mut request = client.loan_slice_uninit(bytes.len()).unwrap();
    *request.user_header_mut() = header;
    let pending = request.write_from_slice(&bytes).send().unwrap();
    let active = server.receive().unwrap().expect("a request");
    assert_eq!(*active.user_header(), header);
    assert_eq!(active.payload(), bytes.as_slice());
    active.send_copy(wire::ControlReply::ok(9)).unwrap();
    let reply = pending.receive().unwrap().expect("a reply");
    assert_eq!(*reply.payload(), wire::ControlReply::ok(9));
}

#[test]
fn scene_services_live_under_the_root_and_the_scene_token() {
    let token = SceneToken([0x0123_4567_89ab_cdef, 0xfe]);
    assert_eq!(
        poses_service_name("proxima", token),
        "proxima/scene-0123456789abcdef00000000000000fe/poses"
    );
    assert_eq!(
        results_service_name("t-1", token),
        "t-1/scene-0123456789abcdef00000000000000fe/results"
    );
    assert_eq!(
        format!("{token:?}"),
        "SceneToken(…)",
        "tokens stay out of logs"
    );
    assert_eq!(token.to_string().parse::<SceneToken>(), Ok(token));
    for bad in [
        "",
        "0123",
        &"g".repeat(32),
        &"0".repeat(33),
        &"é".repeat(16),
    ] {
        assert!(bad.parse::<SceneToken>().is_err(), "{bad:?} parsed");
    }
}

#[test]
fn every_error_code_survives_the_wire_and_unknown_values_are_refused() {
    let mut known = 0;
    for value in 0..64u32 {
        if let Some(code) = ErrorCode::from_u32(value) {
            assert_eq!(code as u32, value);
            assert!(!code.to_string().is_empty());
            known += 1;
        }
    }
    assert_eq!(known, 16);
    assert_eq!(ErrorCode::from_u32(u32::MAX), None);
}

#[test]
fn every_command_shape_kind_and_motion_survives_the_wire_and_unknown_values_are_refused() {
    let count = |known: &dyn Fn(u32) -> Option<u32>| {
        (0..64u32)
            .filter(|&v| known(v).inspect(|&back| assert_eq!(back, v)).is_some())
            .count()
    };
    assert_eq!(count(&|v| wire::Command::from_u32(v).map(|c| c as u32)), 9);
    assert_eq!(
        count(&|v| wire::BroadPhaseCode::from_u32(v).map(|c| c as u32)),
        6
    );
    assert_eq!(
        count(&|v| wire::ShapeKindCode::from_u32(v).map(|c| c as u32)),
        9
    );
    assert_eq!(
        count(&|v| wire::MotionCode::from_u32(v).map(|c| c as u32)),
        3
    );
    assert_eq!(wire::Command::from_u32(u32::MAX), None);
}

#[test]
fn a_pose_frame_and_a_result_frame_cross_a_real_service_unchanged() {
    let node = NodeBuilder::new().create::<local::Service>().unwrap();
    let root = format!("wire-test-{}", std::process::id());
    let poses = node
        .service_builder(
            &poses_service_name(&root, SceneToken([1, 2]))
                .as_str()
                .try_into()
                .unwrap(),
        )
        .publish_subscribe::<[PoseRecord]>()
        .user_header::<PoseFrameHeader>()
        .open_or_create()
        .unwrap();
    let publisher = poses
        .publisher_builder()
        .initial_max_slice_len(3)
        .create()
        .unwrap();
    let subscriber = poses.subscriber_builder().create().unwrap();
    let record = |i: usize| PoseRecord {
        body: i as u32,
        reserved: 0,
        position: [i as f64, -1.5, 1e6],
        orientation: [0.0, 0.0, 0.0, 1.0],
    };
    let header = PoseFrameHeader {
        protocol_version: PROTOCOL_VERSION,
        scene: 1,
        frame_seq: 42,
        budget_ns: 1_000_000,
        query_flags: query::CLOSE | query::CONTACTS,
        count: 3,
        frame_key: 0,
    };
    let mut sample = publisher.loan_slice_uninit(3).unwrap();
    *sample.user_header_mut() = header;
    sample.write_from_fn(record).send().unwrap();
    let received = subscriber.receive().unwrap().expect("a pose frame");
    assert_eq!(*received.user_header(), header);
    assert_eq!(received.payload(), &[record(0), record(1), record(2)]);

    let results = node
        .service_builder(
            &results_service_name(&root, SceneToken([1, 2]))
                .as_str()
                .try_into()
                .unwrap(),
        )
        .publish_subscribe::<[ResultRecord]>()
        .user_header::<ResultFrameHeader>()
        .open_or_create()
        .unwrap();
    let publisher = results
        .publisher_builder()
        .initial_max_slice_len(2)
        .create()
        .unwrap();
    let subscriber = results.subscriber_builder().create().unwrap();
    let pair = ResultRecord {
        kind: RecordKind::Pair as u32,
        body_a: 0,
        body_b: 2,
        index: 0,
        count: 1,
        distance: -0.01,
        error_bound: 1e-12,
        point_a: [0.0, 0.0, 0.5],
        point_b: [0.0, 0.0, 0.49],
        normal: [0.0, 0.0, -1.0],
        ..ResultRecord::default()
    };
    let contact = ResultRecord {
        kind: RecordKind::Contact as u32,
        count: 0,
        ..pair
    };
    let mut sample = publisher.loan_slice_uninit(2).unwrap();
    sample.user_header_mut().frame_seq = 42;
    sample.user_header_mut().pair_count = 1;
    sample.user_header_mut().contact_count = 1;
    sample.user_header_mut().flags = wire::frame_flags::PAIRS_CAPPED;
    sample.user_header_mut().dropped_candidates = 7;
    let sent = *sample.user_header();
    sample.write_from_slice(&[pair, contact]).send().unwrap();
    let received = subscriber.receive().unwrap().expect("a result frame");
    assert_eq!(*received.user_header(), sent);
    assert_eq!(received.payload(), &[pair, contact]);
}

#[test]
fn each_direction_of_scene_events_has_its_own_service_so_no_side_hears_itself() {
    let node = NodeBuilder::new().create::<local::Service>().unwrap();
    let root = format!("events-test-{}", std::process::id());
    let poses_ready = poses_ready_service_builder(&node, &root, SceneToken([4, 4]))
        .unwrap()
        .open_or_create()
        .unwrap();
    let results_ready = results_ready_service_builder(&node, &root, SceneToken([4, 4]))
        .unwrap()
        .open_or_create()
        .unwrap();
    let daemon_listener = poses_ready.listener_builder().create().unwrap();
    let client_listener = results_ready.listener_builder().create().unwrap();
    let ids = |listener: &iceoryx2::port::listener::Listener<local::Service>| {
        let mut ids = Vec::new();
        listener.try_wait(|e| ids.push(e.id.as_value())).unwrap();
        ids
    };
    poses_ready
        .notifier_builder()
        .create()
        .unwrap()
        .notify_with_custom_event_id(EventId::new(EVENT_POSES_SENT))
        .unwrap();
    assert_eq!(ids(&client_listener), Vec::<usize>::new());
    assert_eq!(ids(&daemon_listener), [EVENT_POSES_SENT]);
    // The daemon's frame path opens the result events under their older name.
    events_service_builder(&node, &root, SceneToken([4, 4]))
        .unwrap()
        .open_or_create()
        .unwrap()
        .notifier_builder()
        .create()
        .unwrap()
        .notify_with_custom_event_id(EventId::new(EVENT_RESULTS_READY))
        .unwrap();
    assert_eq!(ids(&daemon_listener), Vec::<usize>::new());
    assert_eq!(ids(&client_listener), [EVENT_RESULTS_READY]);
}

#[test]
fn control_service_lives_under_the_root() {
    assert_eq!(control_service_name("proxima"), "proxima/control");
    assert_eq!(control_service_name("test-7"), "test-7/control");
}
