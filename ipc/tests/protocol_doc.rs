//! `ipc/PROTOCOL.md` against the code: record sizes, alignments and field offsets, type
//! names, every service setting (read back from services the shared builders create), event
//! ids, codes, bits and constants. A client written from the document alone must meet the
//! daemon, so any drift between the two fails here.

#[path = "support/protocol_doc.rs"]
mod protocol_doc;

use std::collections::BTreeMap;
use std::mem::{align_of, offset_of, size_of};

use iceoryx2::config::Config;
use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::prelude::{FileName, SemanticString as _, ZeroCopySend};
use iceoryx2::service::ipc::Service as Ipc;
use iceoryx2::service::port_factory::PortFactory;
use iceoryx2::service::static_config::message_type_details::TypeDetail;
use iceoryx2::service::static_config::{event, publish_subscribe, request_response};
use protocol_doc::{document, map_under, number, table_under};
use proxima_ipc::tools::daemon_process::{Isolation, remove_shared_memory};
use proxima_ipc::wire::{
    self, BroadPhaseCode, Command, Completeness, ControlReply, ControlRequest, ErrorCode,
    MotionCode, PoseFrameHeader, PoseRecord, RecordKind, ResultFrameHeader, ResultRecord,
    ShapeKindCode,
};

/// One field as the code lays it out: name, offset, size.
type Field = (&'static str, usize, usize);

/// The fields of `$record`, in declaration order, with their offsets and sizes.
macro_rules! fields {
    ($record:ty { $($field:ident),* $(,)? }) => {{
        let zero = <$record>::default();
        vec![$((
            stringify!($field),
            offset_of!($record, $field),
            std::mem::size_of_val(&zero.$field),
        )),*]
    }};
}

/// Every wire record: its type name, size, alignment and fields.
fn records() -> Vec<(&'static str, usize, usize, Vec<Field>)> {
    // SAFETY: `type_name` only returns the `#[type_name]` string; calling it has no
    // precondition beyond the type being a real ZeroCopySend record, which these are.
    let name = |n: unsafe fn() -> &'static str| unsafe { n() };
    let reply_fields = {
        let zero = ControlReply::ok(0);
        vec![
            (
                "protocol_version",
                offset_of!(ControlReply, protocol_version),
                size_of_val(&zero.protocol_version),
            ),
            (
                "status",
                offset_of!(ControlReply, status),
                size_of_val(&zero.status),
            ),
            ("id", offset_of!(ControlReply, id), size_of_val(&zero.id)),
            (
                "flags",
                offset_of!(ControlReply, flags),
                size_of_val(&zero.flags),
            ),
            (
                "instance",
                offset_of!(ControlReply, instance),
                size_of_val(&zero.instance),
            ),
            (
                "frame_key",
                offset_of!(ControlReply, frame_key),
                size_of_val(&zero.frame_key),
            ),
            (
                "scene_token",
                offset_of!(ControlReply, scene_token),
                size_of_val(&zero.scene_token),
            ),
            (
                "reason",
                offset_of!(ControlReply, reason),
                size_of_val(&zero.reason),
            ),
        ]
    };
    vec![
        (
            name(<ControlRequest as ZeroCopySend>::type_name),
            size_of::<ControlRequest>(),
            align_of::<ControlRequest>(),
            fields!(ControlRequest {
                protocol_version,
                command,
                scene,
                target,
                shape_kind,
                motion,
                group,
                mask,
                vertex_count,
                index_count,
                broad_phase,
                reserved,
                margin,
                dimensions,
                position,
                orientation,
            }),
        ),
        (
            name(<ControlReply as ZeroCopySend>::type_name),
            size_of::<ControlReply>(),
            align_of::<ControlReply>(),
            reply_fields,
        ),
        (
            name(<PoseFrameHeader as ZeroCopySend>::type_name),
            size_of::<PoseFrameHeader>(),
            align_of::<PoseFrameHeader>(),
            fields!(PoseFrameHeader {
                protocol_version,
                scene,
                frame_seq,
                budget_ns,
                query_flags,
                count,
                frame_key
            }),
        ),
        (
            name(<PoseRecord as ZeroCopySend>::type_name),
            size_of::<PoseRecord>(),
            align_of::<PoseRecord>(),
            fields!(PoseRecord {
                body,
                reserved,
                position,
                orientation
            }),
        ),
        (
            name(<ResultFrameHeader as ZeroCopySend>::type_name),
            size_of::<ResultFrameHeader>(),
            align_of::<ResultFrameHeader>(),
            fields!(ResultFrameHeader {
                protocol_version,
                status,
                frame_seq,
                error_body,
                completeness,
                deepest_level,
                budget_met,
                pair_count,
                contact_count,
                candidate_count,
                toi_count,
                elapsed_ns,
                stage_ns,
                flags,
                dropped_candidates,
                min_budget_ns,
                instance,
            }),
        ),
        (
            name(<ResultRecord as ZeroCopySend>::type_name),
            size_of::<ResultRecord>(),
            align_of::<ResultRecord>(),
            fields!(ResultRecord {
                kind,
                body_a,
                body_b,
                index,
                count,
                flags,
                distance,
                error_bound,
                point_a,
                point_b,
                normal,
                time,
            }),
        ),
    ]
}

/// Bytes of a field of the document's type `u32`, `f64[3]`, `u8[112]`…
fn type_size(ty: &str) -> usize {
    let (scalar, n) = match ty.split_once('[') {
        Some((scalar, rest)) => (
            scalar,
            rest.trim_end_matches(']').parse().expect("array length"),
        ),
        None => (ty, 1),
    };
    let each = match scalar {
        "u8" => 1,
        "u32" => 4,
        "u64" | "f64" => 8,
        other => panic!("PROTOCOL.md uses an unknown type `{other}`"),
    };
    each * n
}

#[test]
fn every_record_layout_is_the_codes() {
    let doc = document();
    for (type_name, size, align, fields) in records() {
        let heading = doc
            .lines()
            .find(|l| l.starts_with("### 4.") && l.contains(&format!("`{type_name}`")))
            .unwrap_or_else(|| panic!("PROTOCOL.md has no section for {type_name}"));
        assert!(
            heading.contains(&format!("({size} bytes, alignment {align})")),
            "{type_name}: the heading `{heading}` should say {size} bytes, alignment {align}"
        );
        let rows = table_under(doc, heading);
        let listed: Vec<&str> = rows.iter().map(|r| r[3].as_str()).collect();
        let coded: Vec<&str> = fields.iter().map(|f| f.0).collect();
        assert_eq!(
            listed, coded,
            "{type_name}: the document's fields, in order"
        );
        let mut next = 0;
        for (row, &(field, offset, bytes)) in rows.iter().zip(&fields) {
            let (doc_offset, doc_size) = (number(&row[0]) as usize, number(&row[1]) as usize);
            assert_eq!(
                (doc_offset, doc_size),
                (offset, bytes),
                "{type_name}.{field}: offset, size"
            );
            assert_eq!(
                type_size(&row[2]),
                bytes,
                "{type_name}.{field}: type {}",
                row[2]
            );
            assert_eq!(
                offset, next,
                "{type_name}.{field}: the record has a gap before it"
            );
            next = offset + bytes;
        }
        assert_eq!(next, size, "{type_name}: the fields fill the record");
    }
}

/// An iceoryx2 node under a prefix of its own; its files are removed on drop.
struct IsolatedNode {
    node: Node<Ipc>,
    prefix: String,
    root: String,
}

impl IsolatedNode {
    fn new() -> Self {
        let isolation = Isolation::unique("pdoc");
        let mut config = Config::global_config().clone();
        config.global.prefix = FileName::new(isolation.prefix.as_bytes()).expect("prefix");
        let node = NodeBuilder::new()
            .config(&config)
            .create::<Ipc>()
            .expect("node");
        Self {
            node,
            prefix: isolation.prefix,
            root: isolation.root,
        }
    }
}

impl Drop for IsolatedNode {
    fn drop(&mut self) {
        remove_shared_memory(&self.prefix);
    }
}

fn on_off(value: bool) -> String {
    value.to_string()
}

fn event_id(id: Option<iceoryx2::prelude::EventId>) -> String {
    id.map_or_else(|| "none".to_owned(), |id| id.as_value().to_string())
}

fn request_response_settings(c: &request_response::StaticConfig) -> BTreeMap<String, String> {
    [
        ("max_clients", c.max_clients().to_string()),
        ("max_servers", c.max_servers().to_string()),
        ("max_nodes", c.max_nodes().to_string()),
        (
            "max_active_requests_per_client",
            c.max_active_requests_per_client().to_string(),
        ),
        (
            "max_response_buffer_size",
            c.max_response_buffer_size().to_string(),
        ),
        (
            "max_borrowed_responses_per_pending_response",
            c.max_borrowed_responses_per_pending_response().to_string(),
        ),
        ("max_loaned_requests", c.max_loaned_requests().to_string()),
        (
            "safe_overflow_for_requests",
            on_off(c.has_safe_overflow_for_requests()),
        ),
        (
            "safe_overflow_for_responses",
            on_off(c.has_safe_overflow_for_responses()),
        ),
        (
            "fire_and_forget_requests",
            on_off(c.does_support_fire_and_forget_requests()),
        ),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v))
    .collect()
}

fn publish_subscribe_settings(c: &publish_subscribe::StaticConfig) -> BTreeMap<String, String> {
    [
        ("max_publishers", c.max_publishers().to_string()),
        ("max_subscribers", c.max_subscribers().to_string()),
        ("max_nodes", c.max_nodes().to_string()),
        ("history_size", c.history_size().to_string()),
        (
            "subscriber_max_buffer_size",
            c.subscriber_max_buffer_size().to_string(),
        ),
        (
            "subscriber_max_borrowed_samples",
            c.subscriber_max_borrowed_samples().to_string(),
        ),
        ("safe_overflow", on_off(c.has_safe_overflow())),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v))
    .collect()
}

fn event_settings(c: &event::StaticConfig) -> BTreeMap<String, String> {
    [
        ("max_notifiers", c.max_notifiers().to_string()),
        ("max_listeners", c.max_listeners().to_string()),
        ("max_nodes", c.max_nodes().to_string()),
        ("event_id_max_value", c.event_id_max_value().to_string()),
        (
            "deadline",
            c.deadline()
                .map_or_else(|| "none".to_owned(), |d| format!("{d:?}")),
        ),
        (
            "notifier_created_event",
            event_id(c.notifier_created_event()),
        ),
        (
            "notifier_dropped_event",
            event_id(c.notifier_dropped_event()),
        ),
        ("notifier_dead_event", event_id(c.notifier_dead_event())),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_owned(), v))
    .collect()
}

/// A service's type as the document's service table names it: `name` for a fixed-size
/// type, `name slice` for a slice's element.
fn type_cell(detail: &TypeDetail, slice: bool) -> String {
    let name = detail.type_name().to_string();
    if slice { format!("{name} slice") } else { name }
}

/// What one service looks like from the code: its name, pattern, types and settings.
struct CodedService {
    name: String,
    pattern: &'static str,
    types: [String; 3],
    settings: BTreeMap<String, String>,
    type_details: Vec<TypeDetail>,
}

/// The token the scene services of [`coded_services`] are named by.
const TOKEN: proxima_ipc::SceneToken = proxima_ipc::SceneToken([0, 0]);

/// Creates every service with the shared builders (scene token [`TOKEN`]) and reads back
/// what iceoryx2 stored: the settings and types a peer must match.
fn coded_services(n: &IsolatedNode) -> BTreeMap<&'static str, CodedService> {
    let (node, root) = (&n.node, n.root.as_str());
    let control = proxima_ipc::control_service_builder(node, root)
        .unwrap()
        .open_or_create()
        .unwrap();
    let rr = control.static_config();
    let control_events = proxima_ipc::control_events_service_builder(node, root)
        .unwrap()
        .open_or_create()
        .unwrap();
    let poses = proxima_ipc::poses_service_builder(node, root, TOKEN)
        .unwrap()
        .open_or_create()
        .unwrap();
    let results = proxima_ipc::results_service_builder(node, root, TOKEN)
        .unwrap()
        .open_or_create()
        .unwrap();
    let poses_ready = proxima_ipc::poses_ready_service_builder(node, root, TOKEN)
        .unwrap()
        .open_or_create()
        .unwrap();
    let results_ready = proxima_ipc::results_ready_service_builder(node, root, TOKEN)
        .unwrap()
        .open_or_create()
        .unwrap();
    let event = |name: &iceoryx2::prelude::ServiceName, c: &event::StaticConfig| CodedService {
        name: name.to_string(),
        pattern: "event",
        types: Default::default(),
        settings: event_settings(c),
        type_details: Vec::new(),
    };
    let topic = |name: &iceoryx2::prelude::ServiceName, c: &publish_subscribe::StaticConfig| {
        let t = c.message_type_details();
        CodedService {
            name: name.to_string(),
            pattern: "publish–subscribe",
            types: [
                type_cell(&t.payload, true),
                type_cell(&t.user_header, false),
                String::new(),
            ],
            settings: publish_subscribe_settings(c),
            type_details: vec![t.payload, t.user_header],
        }
    };
    let request = rr.request_message_type_details();
    let response = rr.response_message_type_details();
    BTreeMap::from([
        (
            "control",
            CodedService {
                name: control.name().to_string(),
                pattern: "request–response",
                types: [
                    format!("{} (geometry bytes)", type_cell(&request.payload, true)),
                    type_cell(&request.user_header, false),
                    type_cell(&response.payload, false),
                ],
                settings: request_response_settings(rr),
                type_details: vec![request.payload, request.user_header, response.payload],
            },
        ),
        (
            "control events",
            event(control_events.name(), control_events.static_config()),
        ),
        ("poses", topic(poses.name(), poses.static_config())),
        ("results", topic(results.name(), results.static_config())),
        (
            "poses ready",
            event(poses_ready.name(), poses_ready.static_config()),
        ),
        (
            "results ready",
            event(results_ready.name(), results_ready.static_config()),
        ),
    ])
}

#[test]
fn every_service_name_type_and_setting_is_the_codes() {
    let doc = document();
    let node = IsolatedNode::new();
    let coded = coded_services(&node);
    let table = table_under(doc, "## 3. Services");
    assert_eq!(table.len(), coded.len(), "the document's services");
    let mut details = Vec::new();
    for row in &table {
        let service = coded
            .get(row[0].as_str())
            .unwrap_or_else(|| panic!("unknown service `{}`", row[0]));
        let name = row[1]
            .replace("<root>", &node.root)
            .replace("<token>", &TOKEN.to_string());
        assert_eq!(name, service.name, "{}: name", row[0]);
        assert_eq!(row[2], service.pattern, "{}: pattern", row[0]);
        assert_eq!(row[3..6], service.types, "{}: types", row[0]);
        let settings = map_under(doc, &format!("#### {}", row[0]), 1);
        assert_eq!(settings, service.settings, "{}: settings", row[0]);
        details.extend(service.type_details.iter().copied());
    }
    let names = table_under(doc, "### 3.1 Type names");
    for detail in details {
        let name = detail.type_name().to_string();
        let row = names
            .iter()
            .find(|r| r[0] == name)
            .unwrap_or_else(|| panic!("type `{name}` is not in the type-name table"));
        assert_eq!(
            (number(&row[1]) as usize, number(&row[2]) as usize),
            (detail.size(), detail.alignment()),
            "{name}: size, alignment"
        );
    }
    assert_eq!(
        names.len(),
        7,
        "the type-name table lists the seven types services use"
    );
}

#[test]
fn port_settings_event_ids_and_constants_are_the_codes() {
    let doc = document();
    let ports: BTreeMap<String, String> = table_under(doc, "### 3.3 Port settings")
        .into_iter()
        .map(|r| (format!("{}/{}", r[0], r[1]), r[2].clone()))
        .collect();
    let expected = BTreeMap::from([
        (
            "control client/initial_max_slice_len".to_owned(),
            proxima_ipc::CONTROL_INITIAL_MAX_SLICE_LEN.to_string(),
        ),
        (
            "control client/allocation_strategy".to_owned(),
            "PowerOfTwo".to_owned(),
        ),
        (
            "pose publisher/initial_max_slice_len".to_owned(),
            proxima_ipc::scene_link::POSES_INITIAL_MAX_SLICE_LEN.to_string(),
        ),
        (
            "pose publisher/allocation_strategy".to_owned(),
            "PowerOfTwo".to_owned(),
        ),
        (
            "pose publisher/max_loaned_samples".to_owned(),
            proxima_ipc::scene_link::POSES_MAX_LOANED_SAMPLES.to_string(),
        ),
    ]);
    assert_eq!(ports, expected, "port settings");

    let events = map_under(doc, "### 3.4 Event ids", 1);
    let expected = BTreeMap::from([
        (
            "EVENT_POSES_SENT".to_owned(),
            proxima_ipc::EVENT_POSES_SENT.to_string(),
        ),
        (
            "EVENT_RESULTS_READY".to_owned(),
            proxima_ipc::EVENT_RESULTS_READY.to_string(),
        ),
        (
            "EVENT_CONTROL_SENT".to_owned(),
            proxima_ipc::EVENT_CONTROL_SENT.to_string(),
        ),
    ]);
    assert_eq!(events, expected, "event ids");

    let version = map_under(doc, "## 2. Versioning", 1);
    assert_eq!(
        version["PROTOCOL_VERSION"],
        proxima_ipc::PROTOCOL_VERSION.to_string()
    );
    let title = doc.lines().next().unwrap_or_default();
    assert!(
        title.ends_with(&format!("version {}", proxima_ipc::PROTOCOL_VERSION)),
        "the title `{title}` names another version"
    );

    let constants = map_under(doc, "### 5.13 Other constants", 1);
    let expected = BTreeMap::from([
        (
            "MAX_CONTACTS_PER_PAIR".to_owned(),
            wire::MAX_CONTACTS_PER_PAIR.to_string(),
        ),
        ("REASON_BYTES".to_owned(), wire::REASON_BYTES.to_string()),
        (
            "MAX_COMPOUND_PARTS".to_owned(),
            wire::MAX_COMPOUND_PARTS.to_string(),
        ),
    ]);
    assert_eq!(constants, expected, "other constants");
}

/// The values this version defines for a code with `from_u32`, as `value → Debug name`.
fn defined<T: std::fmt::Debug>(from_u32: impl Fn(u32) -> Option<T>) -> BTreeMap<String, String> {
    (0..1024)
        .filter_map(|v| from_u32(v).map(|code| (v.to_string(), format!("{code:?}"))))
        .collect()
}

#[test]
fn every_code_is_the_codes() {
    let doc = document();
    let listed = |heading: &str| map_under(doc, heading, 1);
    assert_eq!(
        listed("### 5.1 ErrorCode"),
        defined(ErrorCode::from_u32),
        "ErrorCode"
    );
    assert_eq!(
        listed("### 5.2 Command"),
        defined(Command::from_u32),
        "Command"
    );
    assert_eq!(
        listed("### 5.3 ShapeKind"),
        defined(ShapeKindCode::from_u32),
        "ShapeKind"
    );
    assert_eq!(
        listed("### 5.4 Motion"),
        defined(MotionCode::from_u32),
        "Motion"
    );
    assert_eq!(
        listed("### 5.5 BroadPhase"),
        defined(BroadPhaseCode::from_u32),
        "BroadPhase"
    );
    let completeness = [Completeness::Exact, Completeness::Truncated];
    let coded = completeness
        .iter()
        .map(|&c| ((c as u32).to_string(), format!("{c:?}")))
        .collect();
    assert_eq!(listed("### 5.7 Completeness"), coded, "Completeness");
    let kinds = [RecordKind::Pair, RecordKind::Contact, RecordKind::Toi];
    let coded = kinds
        .iter()
        .map(|&k| ((k as u32).to_string(), format!("{k:?}")))
        .collect();
    assert_eq!(listed("### 5.11 RecordKind"), coded, "RecordKind");
}

/// A bit table (`bit | value | name | …`) as `name → value`, each value checked against its
/// bit.
fn bits(doc: &str, heading: &str) -> BTreeMap<String, u32> {
    table_under(doc, heading)
        .into_iter()
        .map(|r| {
            let (bit, value) = (number(&r[0]) as u32, number(&r[1]) as u32);
            assert_eq!(value, 1 << bit, "{heading}: {} is bit {bit}", r[2]);
            (r[2].clone(), value)
        })
        .collect()
}

fn named(pairs: &[(&str, u32)]) -> BTreeMap<String, u32> {
    pairs.iter().map(|&(n, v)| (n.to_owned(), v)).collect()
}

#[test]
fn every_bit_and_stage_is_the_codes() {
    use wire::{frame_flags, query, record_flags, reply_flags, stage};
    let doc = document();
    let queries = bits(doc, "### 5.6 query bits");
    assert_eq!(
        queries,
        named(&[
            ("OVERLAP", query::OVERLAP),
            ("CLOSE", query::CLOSE),
            ("DISTANCE", query::DISTANCE),
            ("CONTACTS", query::CONTACTS),
            ("TOI", query::TOI),
        ])
    );
    assert_eq!(
        queries.values().fold(0, |all, v| all | v),
        query::ALL,
        "every query bit is listed"
    );
    assert_eq!(
        bits(doc, "### 5.8 frame_flags bits"),
        named(&[
            ("PAIRS_CAPPED", frame_flags::PAIRS_CAPPED),
            ("BUDGET_TOO_SMALL", frame_flags::BUDGET_TOO_SMALL),
            ("OWNER_GONE", frame_flags::OWNER_GONE),
        ])
    );
    assert_eq!(
        bits(doc, "### 5.9 reply_flags bits"),
        named(&[("SHAPE_BUILDING", reply_flags::SHAPE_BUILDING)])
    );
    assert_eq!(
        bits(doc, "### 5.12 record_flags bits"),
        named(&[("APPROXIMATE", record_flags::APPROXIMATE)])
    );
    let stages: BTreeMap<String, u32> = table_under(doc, "### 5.10 stage indices")
        .into_iter()
        .map(|r| (r[1].clone(), number(&r[0]) as u32))
        .collect();
    let coded = [
        ("INGEST", stage::INGEST),
        ("PLAN", stage::PLAN),
        ("BROAD", stage::BROAD),
        ("MID", stage::MID),
        ("NARROW", stage::NARROW),
        ("PUBLISH", stage::PUBLISH),
    ];
    assert_eq!(stages.len(), stage::COUNT, "every stage is listed");
    assert_eq!(
        stages,
        coded
            .iter()
            .map(|&(n, v)| (n.to_owned(), v as u32))
            .collect()
    );
}
