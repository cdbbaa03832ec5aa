//! Contract: `ipc/c/proxima_wire.h` says what the Rust crate says.
//!
//! A table below pairs every wire item with its C name and takes its value from the Rust
//! compiler (`offset_of!`, `size_of`, `align_of`, the constants, the `ZeroCopySend` type
//! names) or from services the crate's own builders create (names, settings, type
//! details). The test generates a program from the table, compiles it against the header
//! with the system C compiler (C11) and C++ compiler (C++11), runs both, and compares every
//! line with the table. Two completeness checks keep the table whole: every item declared
//! in `wire.rs`, `lib.rs` and `scene_link.rs` must be in it, and every name the header
//! defines must be checked by it.
//!
//! Without a C compiler (`cc`, or `$CC`; `c++`, or `$CXX`) the compiling tests print one
//! line to stderr and pass, unless `PROXIMA_REQUIRE_CC=1`, which makes them fail.

use std::collections::{BTreeMap, BTreeSet};
use std::mem::{align_of, offset_of, size_of, size_of_val};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicU32, Ordering};

use iceoryx2::prelude::*;
use iceoryx2::service::static_config::message_type_details::TypeDetail;
use proxima_ipc::{self as ipc, scene_link, wire};

/// The scene token the generated program formats service names with (its C array is
/// `TOKEN`, declared before `main`).
const TOKEN: ipc::SceneToken = ipc::SceneToken([0x0123_4567_89ab_cdef, 0xfe]);

/// One checked line: the program prints `key\tvalue`, the table expects `expected`.
struct Entry {
    /// The Rust item it stands for, as the source inventory names it (`None`: a value the
    /// header names that the crate has no item for, such as a builder literal).
    rust_item: Option<String>,
    /// The C statement that prints it.
    c_stmt: String,
    key: String,
    expected: String,
}

#[derive(Default)]
struct Table {
    entries: Vec<Entry>,
    /// Names the program uses from the header: records and constants.
    c_names: BTreeSet<String>,
}

impl Table {
    fn push(
        &mut self,
        rust_item: Option<&str>,
        c_name: &str,
        c_stmt: String,
        key: String,
        value: String,
    ) {
        self.c_names.insert(c_name.to_owned());
        self.entries.push(Entry {
            rust_item: rust_item.map(str::to_owned),
            c_stmt,
            key,
            expected: value,
        });
    }

    fn constant(&mut self, rust_item: Option<&str>, c_name: &str, value: u64) {
        self.push(
            rust_item,
            c_name,
            format!("UINT({c_name})"),
            format!("const {c_name}"),
            value.to_string(),
        );
    }

    fn string(&mut self, rust_item: Option<&str>, c_name: &str, value: &str) {
        self.push(
            rust_item,
            c_name,
            format!("STR({c_name})"),
            format!("str {c_name}"),
            value.to_owned(),
        );
    }

    fn service_name(&mut self, c_name: &str, root: &str, name: &str) {
        let args = if c_name.starts_with("PROXIMA_SERVICE_CONTROL") {
            format!("\"{root}\"")
        } else {
            format!("\"{root}\", PROXIMA_SCENE_TOKEN_ARGS(TOKEN)")
        };
        self.push(
            None,
            c_name,
            format!("NAME({c_name}, {args})"),
            format!("name {c_name}"),
            name.to_owned(),
        );
    }

    fn record(&mut self, record: Record) {
        let c_type = format!("proxima_{}", record.rust);
        let mut end = 0;
        for field in &record.fields {
            assert_eq!(
                field.offset, end,
                "wire::{}.{} does not follow the previous field without a gap: the table \
                 misses a field, or the record has hidden padding",
                record.rust, field.name
            );
            end = field.offset + field.size;
            let macro_name = if field.ty.starts_with('[') {
                "ARRAY"
            } else {
                "SCALAR"
            };
            self.push(
                Some(&format!("wire::{}.{}", record.rust, field.name)),
                &c_type,
                format!("{macro_name}({c_type}, {})", field.name),
                format!("field {c_type}.{}", field.name),
                format!(
                    "offset={} size={} type={}",
                    field.offset, field.size, field.ty
                ),
            );
        }
        assert_eq!(
            end, record.size,
            "wire::{}: the table's fields do not fill the record",
            record.rust
        );
        self.push(
            None,
            &c_type,
            format!("RECORD({c_type})"),
            format!("record {c_type}"),
            format!("size={} align={}", record.size, record.align),
        );
        self.string(None, record.type_name_macro, record.type_name);
    }
}

struct Field {
    name: &'static str,
    offset: usize,
    size: usize,
    ty: &'static str,
}

struct Record {
    rust: &'static str,
    type_name_macro: &'static str,
    type_name: &'static str,
    size: usize,
    align: usize,
    fields: Vec<Field>,
}

/// A record of `wire`: its fields in declaration order, read from the compiler.
macro_rules! record {
    ($ty:ident = $value:expr, $macro_name:literal; $($field:ident),+ $(,)?) => {{
        let value: wire::$ty = $value;
        Record {
            rust: stringify!($ty),
            type_name_macro: $macro_name,
            // SAFETY: only reads the name the derive attached; the layout promise it asks
            // for is what this test checks.
            type_name: unsafe { <wire::$ty as ZeroCopySend>::type_name() },
            size: size_of::<wire::$ty>(),
            align: align_of::<wire::$ty>(),
            fields: vec![$(Field {
                name: stringify!($field),
                offset: offset_of!(wire::$ty, $field),
                size: size_of_val(&value.$field),
                ty: std::any::type_name_of_val(&value.$field),
            }),+],
        }
    }};
}

/// The variants of a `wire` enum, each under `<prefix><VARIANT_IN_CAPITALS>`.
macro_rules! codes {
    ($table:ident, $ty:ident, $prefix:literal: $($variant:ident),+ $(,)?) => {
        $($table.constant(
            Some(concat!("wire::", stringify!($ty), "::", stringify!($variant))),
            &format!("{}{}", $prefix, screaming(stringify!($variant))),
            wire::$ty::$variant as u64,
        );)+
    };
}

/// A Rust constant (`ipc::X`, `wire::m::X`, `scene_link::X`) under its C name.
macro_rules! constant {
    ($table:ident, $path:path => $c_name:literal) => {
        $table.constant(Some(&rust_item(stringify!($path))), $c_name, $path as u64)
    };
}

/// The inventory key of a constant's path: `ipc::` stands for the crate root.
fn rust_item(path: &str) -> String {
    let path: String = path.split_whitespace().collect();
    path.strip_prefix("ipc::").unwrap_or(&path).to_owned()
}

/// `ProtocolMismatch` → `PROTOCOL_MISMATCH`.
fn screaming(camel: &str) -> String {
    let mut out = String::new();
    for (i, c) in camel.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}

fn type_detail(detail: &TypeDetail) -> (String, usize, usize) {
    (
        detail.type_name().to_string(),
        detail.size(),
        detail.alignment(),
    )
}

/// The whole table: records, codes, constants, and what the crate's builders create.
fn table() -> Table {
    let mut t = Table::default();

    t.record(record!(PoseFrameHeader = wire::PoseFrameHeader::default(),
        "PROXIMA_TYPE_NAME_POSE_FRAME_HEADER";
        protocol_version, scene, frame_seq, budget_ns, query_flags, count, frame_key));
    t.record(record!(PoseRecord = wire::PoseRecord::default(),
        "PROXIMA_TYPE_NAME_POSE_RECORD";
        body, reserved, position, orientation));
    t.record(
        record!(ResultFrameHeader = wire::ResultFrameHeader::default(),
        "PROXIMA_TYPE_NAME_RESULT_FRAME_HEADER";
        protocol_version, status, frame_seq, error_body, completeness, deepest_level,
        budget_met, pair_count, contact_count, candidate_count, toi_count, elapsed_ns,
        stage_ns, flags, dropped_candidates, min_budget_ns, instance),
    );
    t.record(record!(ResultRecord = wire::ResultRecord::default(),
        "PROXIMA_TYPE_NAME_RESULT_RECORD";
        kind, body_a, body_b, index, count, flags, distance, error_bound, point_a, point_b,
        normal, time));
    t.record(record!(ControlRequest = wire::ControlRequest::default(),
        "PROXIMA_TYPE_NAME_CONTROL_REQUEST";
        protocol_version, command, scene, target, shape_kind, motion, group, mask,
        vertex_count, index_count, broad_phase, reserved, margin, dimensions, position,
        orientation));
    t.record(record!(ControlReply = wire::ControlReply::ok(0),
        "PROXIMA_TYPE_NAME_CONTROL_REPLY";
        protocol_version, status, id, flags, instance, frame_key, scene_token, reason));

    codes!(t, ErrorCode, "PROXIMA_ERROR_": Ok, ProtocolMismatch, UnknownScene, UnknownBody,
        UnknownShape, InvalidPose, InvalidShape, MeshIndexOutOfRange, EmptyGeometry,
        LimitExceeded, MalformedMessage, Internal, ShapeNotReady, NotOwner, SceneQuarantined,
        SceneReleased);
    codes!(t, Command, "PROXIMA_COMMAND_": Hello, CreateScene, DropScene, RegisterShape,
        AddBody, RemoveBody, UpdateBody, SetSceneParams, ShapeState);
    codes!(t, ShapeKindCode, "PROXIMA_SHAPE_KIND_": Sphere, Capsule, Cuboid, Cylinder, Cone,
        Convex, Mesh, Compound, DecomposedMesh);
    codes!(t, MotionCode, "PROXIMA_MOTION_": Static, Kinematic, Dynamic);
    codes!(t, BroadPhaseCode, "PROXIMA_BROAD_PHASE_": Auto, SortAndSweep, IncrementalSap,
        HashGrid, ColumnGrid, SkinGrid);
    codes!(t, Completeness, "PROXIMA_COMPLETENESS_": Exact, Truncated);
    codes!(t, RecordKind, "PROXIMA_RECORD_KIND_": Pair, Contact, Toi);

    constant!(t, wire::query::OVERLAP => "PROXIMA_QUERY_OVERLAP");
    constant!(t, wire::query::CLOSE => "PROXIMA_QUERY_CLOSE");
    constant!(t, wire::query::DISTANCE => "PROXIMA_QUERY_DISTANCE");
    constant!(t, wire::query::CONTACTS => "PROXIMA_QUERY_CONTACTS");
    constant!(t, wire::query::TOI => "PROXIMA_QUERY_TOI");
    constant!(t, wire::query::ALL => "PROXIMA_QUERY_ALL");
    constant!(t, wire::frame_flags::PAIRS_CAPPED => "PROXIMA_FRAME_FLAG_PAIRS_CAPPED");
    constant!(t, wire::frame_flags::BUDGET_TOO_SMALL => "PROXIMA_FRAME_FLAG_BUDGET_TOO_SMALL");
    constant!(t, wire::frame_flags::OWNER_GONE => "PROXIMA_FRAME_FLAG_OWNER_GONE");
    constant!(t, wire::record_flags::APPROXIMATE => "PROXIMA_RECORD_FLAG_APPROXIMATE");
    constant!(t, wire::reply_flags::SHAPE_BUILDING => "PROXIMA_REPLY_FLAG_SHAPE_BUILDING");
    constant!(t, wire::stage::INGEST => "PROXIMA_STAGE_INGEST");
    constant!(t, wire::stage::PLAN => "PROXIMA_STAGE_PLAN");
    constant!(t, wire::stage::BROAD => "PROXIMA_STAGE_BROAD");
    constant!(t, wire::stage::MID => "PROXIMA_STAGE_MID");
    constant!(t, wire::stage::NARROW => "PROXIMA_STAGE_NARROW");
    constant!(t, wire::stage::PUBLISH => "PROXIMA_STAGE_PUBLISH");
    constant!(t, wire::stage::COUNT => "PROXIMA_STAGE_COUNT");
    constant!(t, wire::MAX_CONTACTS_PER_PAIR => "PROXIMA_MAX_CONTACTS_PER_PAIR");
    constant!(t, wire::REASON_BYTES => "PROXIMA_REASON_BYTES");
    constant!(t, wire::MAX_COMPOUND_PARTS => "PROXIMA_MAX_COMPOUND_PARTS");

    constant!(t, ipc::PROTOCOL_VERSION => "PROXIMA_PROTOCOL_VERSION");
    constant!(t, ipc::CONTROL_MAX_CLIENTS => "PROXIMA_CONTROL_MAX_CLIENTS");
    constant!(t, ipc::CONTROL_MAX_SERVERS => "PROXIMA_CONTROL_MAX_SERVERS");
    constant!(t, ipc::CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT
        => "PROXIMA_CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT");
    constant!(t, ipc::CONTROL_MAX_RESPONSE_BUFFER_SIZE
        => "PROXIMA_CONTROL_MAX_RESPONSE_BUFFER_SIZE");
    constant!(t, ipc::CONTROL_INITIAL_MAX_SLICE_LEN => "PROXIMA_CONTROL_INITIAL_MAX_SLICE_LEN");
    constant!(t, ipc::CONTROL_MAX_NODES => "PROXIMA_CONTROL_MAX_NODES");
    constant!(t, ipc::POSES_MAX_PUBLISHERS => "PROXIMA_POSES_MAX_PUBLISHERS");
    constant!(t, ipc::RESULTS_MAX_SUBSCRIBERS => "PROXIMA_RESULTS_MAX_SUBSCRIBERS");
    constant!(t, ipc::FRAME_BUFFER => "PROXIMA_FRAME_BUFFER");
    constant!(t, ipc::EVENT_POSES_SENT => "PROXIMA_EVENT_POSES_SENT");
    constant!(t, ipc::EVENT_RESULTS_READY => "PROXIMA_EVENT_RESULTS_READY");
    constant!(t, ipc::EVENT_CONTROL_SENT => "PROXIMA_EVENT_CONTROL_SENT");
    constant!(t, ipc::DAEMON_EVENT_PORTS => "PROXIMA_DAEMON_EVENT_PORTS");
    constant!(t, scene_link::POSES_INITIAL_MAX_SLICE_LEN
        => "PROXIMA_POSES_INITIAL_MAX_SLICE_LEN");
    constant!(t, scene_link::POSES_MAX_LOANED_SAMPLES
        => "PROXIMA_POSES_MAX_LOANED_SAMPLES");
    t.string(
        Some("DEFAULT_ROOT"),
        "PROXIMA_DEFAULT_ROOT",
        ipc::DEFAULT_ROOT,
    );
    t.constant(
        None,
        "PROXIMA_INVALID_ID",
        u64::from(wire::ControlReply::error(wire::ErrorCode::Internal, "").id),
    );

    services(&mut t);
    t
}

/// Creates every service through the crate's builders (in-process `local` services) and
/// adds what the header must say about them: names, settings and type details.
fn services(t: &mut Table) {
    // Each call its own root: tests run on threads of one process, and `local` services
    // are shared by the whole process.
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let root = format!(
        "c-header-{}-{}",
        std::process::id(),
        NEXT.fetch_add(1, Ordering::Relaxed)
    );
    let node = NodeBuilder::new().create::<local::Service>().unwrap();

    let control = ipc::control_service_builder(&node, &root)
        .unwrap()
        .create()
        .unwrap();
    let config = control.static_config();
    t.service_name(
        "PROXIMA_SERVICE_CONTROL_FORMAT",
        &root,
        control.name().as_str(),
    );
    for (c_name, value) in [
        ("PROXIMA_CONTROL_MAX_CLIENTS", config.max_clients()),
        ("PROXIMA_CONTROL_MAX_SERVERS", config.max_servers()),
        ("PROXIMA_CONTROL_MAX_NODES", config.max_nodes()),
        (
            "PROXIMA_CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT",
            config.max_active_requests_per_client(),
        ),
        (
            "PROXIMA_CONTROL_MAX_RESPONSE_BUFFER_SIZE",
            config.max_response_buffer_size(),
        ),
        (
            "PROXIMA_CONTROL_MAX_BORROWED_RESPONSES_PER_PENDING_RESPONSE",
            config.max_borrowed_responses_per_pending_response(),
        ),
        (
            "PROXIMA_CONTROL_MAX_LOANED_REQUESTS",
            config.max_loaned_requests(),
        ),
        (
            "PROXIMA_SAFE_OVERFLOW",
            usize::from(config.has_safe_overflow_for_requests()),
        ),
        (
            "PROXIMA_SAFE_OVERFLOW",
            usize::from(config.has_safe_overflow_for_responses()),
        ),
        (
            "PROXIMA_CONTROL_FIRE_AND_FORGET",
            usize::from(config.does_support_fire_and_forget_requests()),
        ),
    ] {
        t.constant(None, c_name, value as u64);
    }
    let request = config.request_message_type_details();
    let response = config.response_message_type_details();
    assert_eq!(
        type_detail(&request.user_header),
        (wire_name::<wire::ControlRequest>(), 144, 8),
        "the control request's user header"
    );
    assert_eq!(
        type_detail(&response.payload),
        (wire_name::<wire::ControlReply>(), 160, 8),
        "the control response"
    );
    let (payload_name, payload_size, payload_align) = type_detail(&request.payload);
    assert_eq!(
        (payload_size, payload_align),
        (1, 1),
        "the control request's payload element"
    );
    t.string(None, "PROXIMA_TYPE_NAME_CONTROL_PAYLOAD", &payload_name);
    let (no_header_name, no_header_size, no_header_align) = type_detail(&response.user_header);
    assert_eq!(
        (no_header_size, no_header_align),
        (0, 1),
        "the control response's user header"
    );
    t.string(None, "PROXIMA_TYPE_NAME_NO_HEADER", &no_header_name);

    t.service_name(
        "PROXIMA_SCENE_SERVICES_FORMAT",
        &root,
        &ipc::scene_services_name(&root, TOKEN),
    );
    let poses = ipc::poses_service_builder(&node, &root, TOKEN)
        .unwrap()
        .create()
        .unwrap();
    let results = ipc::results_service_builder(&node, &root, TOKEN)
        .unwrap()
        .create()
        .unwrap();
    t.service_name("PROXIMA_SERVICE_POSES_FORMAT", &root, poses.name().as_str());
    t.service_name(
        "PROXIMA_SERVICE_RESULTS_FORMAT",
        &root,
        results.name().as_str(),
    );
    let config = poses.static_config();
    pub_sub_settings(
        t,
        config,
        "PROXIMA_POSES_MAX_PUBLISHERS",
        "PROXIMA_POSES_MAX_SUBSCRIBERS",
    );
    assert_eq!(
        type_detail(&config.message_type_details().user_header),
        (wire_name::<wire::PoseFrameHeader>(), 40, 8)
    );
    assert_eq!(
        type_detail(&config.message_type_details().payload),
        (wire_name::<wire::PoseRecord>(), 64, 8)
    );
    let config = results.static_config();
    pub_sub_settings(
        t,
        config,
        "PROXIMA_RESULTS_MAX_PUBLISHERS",
        "PROXIMA_RESULTS_MAX_SUBSCRIBERS",
    );
    assert_eq!(
        type_detail(&config.message_type_details().user_header),
        (wire_name::<wire::ResultFrameHeader>(), 128, 8)
    );
    assert_eq!(
        type_detail(&config.message_type_details().payload),
        (wire_name::<wire::ResultRecord>(), 120, 8)
    );

    let events = [
        (
            "CONTROL_EVENTS",
            ipc::control_events_service_builder(&node, &root)
                .unwrap()
                .create()
                .unwrap(),
        ),
        (
            "POSES_READY",
            ipc::poses_ready_service_builder(&node, &root, TOKEN)
                .unwrap()
                .create()
                .unwrap(),
        ),
        (
            "RESULTS_READY",
            ipc::results_ready_service_builder(&node, &root, TOKEN)
                .unwrap()
                .create()
                .unwrap(),
        ),
    ];
    for (short, service) in &events {
        let config = service.static_config();
        t.service_name(
            &format!("PROXIMA_SERVICE_{short}_FORMAT"),
            &root,
            service.name().as_str(),
        );
        t.constant(
            None,
            &format!("PROXIMA_{short}_MAX_NOTIFIERS"),
            config.max_notifiers() as u64,
        );
        t.constant(
            None,
            &format!("PROXIMA_{short}_MAX_LISTENERS"),
            config.max_listeners() as u64,
        );
        let nodes = if *short == "CONTROL_EVENTS" {
            "PROXIMA_CONTROL_EVENTS_MAX_NODES"
        } else {
            "PROXIMA_DEFAULT_EVENT_MAX_NODES"
        };
        t.constant(None, nodes, config.max_nodes() as u64);
        t.constant(
            None,
            "PROXIMA_EVENT_ID_MAX_VALUE",
            config.event_id_max_value() as u64,
        );
        // The header promises none of these (its comment on the event services).
        assert_eq!(config.deadline(), None, "{short}: deadline");
        assert_eq!(
            config.notifier_created_event(),
            None,
            "{short}: notifier_created_event"
        );
        assert_eq!(
            config.notifier_dropped_event(),
            None,
            "{short}: notifier_dropped_event"
        );
        assert_eq!(
            config.notifier_dead_event(),
            None,
            "{short}: notifier_dead_event"
        );
    }
}

fn pub_sub_settings(
    t: &mut Table,
    config: &iceoryx2::service::static_config::publish_subscribe::StaticConfig,
    publishers: &str,
    subscribers: &str,
) {
    t.constant(None, publishers, config.max_publishers() as u64);
    t.constant(None, subscribers, config.max_subscribers() as u64);
    t.constant(None, "PROXIMA_DEFAULT_MAX_NODES", config.max_nodes() as u64);
    t.constant(
        None,
        "PROXIMA_FRAME_HISTORY_SIZE",
        config.history_size() as u64,
    );
    t.constant(
        None,
        "PROXIMA_FRAME_BUFFER",
        config.subscriber_max_buffer_size() as u64,
    );
    t.constant(
        None,
        "PROXIMA_FRAME_MAX_BORROWED_SAMPLES",
        config.subscriber_max_borrowed_samples() as u64,
    );
    t.constant(
        None,
        "PROXIMA_SAFE_OVERFLOW",
        u64::from(config.has_safe_overflow()),
    );
}

fn wire_name<T: ZeroCopySend>() -> String {
    // SAFETY: only reads the name; see `record!`.
    unsafe { <T as ZeroCopySend>::type_name() }.to_owned()
}

// ---------------------------------------------------------------------------------------
// The generated program

const PROGRAM_PRELUDE: &str = r#"#include <stdio.h>
#include <string.h>
#include "proxima_wire.h"

#ifdef __cplusplus
template <typename T> const char *ty(T) { return "?"; }
inline const char *ty(uint8_t) { return "u8"; }
inline const char *ty(uint16_t) { return "u16"; }
inline const char *ty(uint32_t) { return "u32"; }
inline const char *ty(uint64_t) { return "u64"; }
inline const char *ty(int8_t) { return "i8"; }
inline const char *ty(int16_t) { return "i16"; }
inline const char *ty(int32_t) { return "i32"; }
inline const char *ty(int64_t) { return "i64"; }
inline const char *ty(float) { return "f32"; }
inline const char *ty(double) { return "f64"; }
#define TY(x) ty(x)
#define ALIGNOF(T) alignof(T)
#else
#define TY(x) _Generic((x), uint8_t: "u8", uint16_t: "u16", uint32_t: "u32", \
    uint64_t: "u64", int8_t: "i8", int16_t: "i16", int32_t: "i32", int64_t: "i64", \
    float: "f32", double: "f64", default: "?")
#define ALIGNOF(T) _Alignof(T)
#endif

#define RECORD(T) printf("record " #T "\tsize=%zu align=%zu\n", sizeof(T), (size_t)ALIGNOF(T))
#define SCALAR(T, f) do { T v; memset(&v, 0, sizeof v); \
    printf("field " #T "." #f "\toffset=%zu size=%zu type=%s\n", offsetof(T, f), \
        sizeof v.f, TY(v.f)); } while (0)
#define ARRAY(T, f) do { T v; memset(&v, 0, sizeof v); \
    printf("field " #T "." #f "\toffset=%zu size=%zu type=[%s; %zu]\n", offsetof(T, f), \
        sizeof v.f, TY(v.f[0]), sizeof v.f / sizeof v.f[0]); } while (0)
#define UINT(N) printf("const " #N "\t%llu\n", (unsigned long long)(N))
#define STR(N) printf("str " #N "\t%s\n", N)
#define NAME(F, ...) do { char b[256]; snprintf(b, sizeof b, F, __VA_ARGS__); \
    printf("name " #F "\t%s\n", b); } while (0)
"#;

fn program(table: &Table) -> String {
    let mut source = PROGRAM_PRELUDE.to_owned();
    let [high, low] = TOKEN.0;
    source.push_str(&format!(
        "\nstatic const uint64_t TOKEN[2] = {{UINT64_C({high:#x}), UINT64_C({low:#x})}};\n\n\
         int main(void) {{\n"
    ));
    for entry in &table.entries {
        source.push_str("    ");
        source.push_str(&entry.c_stmt);
        source.push_str(";\n");
    }
    source.push_str("    return 0;\n}\n");
    source
}

// ---------------------------------------------------------------------------------------
// Compilers

fn header_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("c")
}

/// The compiler named by `$var`, else `default`, if it runs; `None` (after one line on
/// stderr) when it does not and `PROXIMA_REQUIRE_CC` is not `1`.
fn compiler(var: &str, default: &str) -> Option<String> {
    let program = std::env::var(var).unwrap_or_else(|_| default.to_owned());
    let runs = Command::new(&program)
        .arg("--version")
        .output()
        .is_ok_and(|out| out.status.success());
    if runs {
        return Some(program);
    }
    let required = std::env::var("PROXIMA_REQUIRE_CC").is_ok_and(|v| v == "1");
    assert!(
        !required,
        "PROXIMA_REQUIRE_CC=1 but the compiler `{program}` (${var}) does not run: install \
         gcc/g++ (or set ${var}) to check ipc/c/proxima_wire.h"
    );
    eprintln!(
        "c_header: skipped, `{program}` (${var}) does not run; PROXIMA_REQUIRE_CC=1 makes this fail"
    );
    None
}

/// A scratch directory of this test process, removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("proxima-c-header-{}-{tag}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Compiles `source` into the program `out` with `compiler` and `flags`, `include` on the
/// include path; panics with the compiler's messages when it fails.
fn compile(compiler: &str, flags: &[&str], include: &Path, source: &Path, out: &Path) {
    let output = Command::new(compiler)
        .args(flags)
        .arg("-I")
        .arg(include)
        .arg(source)
        .arg("-o")
        .arg(out)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "`{compiler} {}` failed on {}:\n{}",
        flags.join(" "),
        source.display(),
        String::from_utf8_lossy(&output.stderr)
    );
}

fn run(program: &Path) -> BTreeMap<String, Vec<String>> {
    let output = Command::new(program).output().unwrap();
    assert!(output.status.success(), "{} failed", program.display());
    let mut lines: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for line in String::from_utf8(output.stdout).unwrap().lines() {
        let (key, value) = line.split_once('\t').expect("key<TAB>value");
        lines
            .entry(key.to_owned())
            .or_default()
            .push(value.to_owned());
    }
    lines
}

/// Compiles the table's program against the header in `include` as C11 and as C++11, runs
/// both, and returns every line whose value differs from the table's, as
/// `key: C says …, Rust says …`. Panics when the C and C++ builds disagree.
fn mismatches(
    cc: &str,
    cxx: &str,
    include: &Path,
    table: &Table,
    scratch: &Scratch,
) -> Vec<String> {
    let source = scratch.0.join("print_wire.c");
    std::fs::write(&source, program(table)).unwrap();
    let strict = ["-Wall", "-Wextra", "-pedantic", "-Werror"];
    let c_program = scratch.0.join("print_wire_c");
    compile(
        cc,
        &[&["-std=c11"], &strict[..]].concat(),
        include,
        &source,
        &c_program,
    );
    let cxx_program = scratch.0.join("print_wire_cxx");
    compile(
        cxx,
        &[&["-std=c++11", "-x", "c++"], &strict[..]].concat(),
        include,
        &source,
        &cxx_program,
    );
    let from_c = run(&c_program);
    assert_eq!(
        from_c,
        run(&cxx_program),
        "the header means different layouts in C and C++"
    );

    let mut wrong = Vec::new();
    for entry in &table.entries {
        let said = from_c
            .get(&entry.key)
            .map(Vec::as_slice)
            .unwrap_or_default();
        if !said.iter().all(|value| *value == entry.expected) || said.is_empty() {
            wrong.push(format!(
                "{}: C says {said:?}, Rust says {:?}",
                entry.key, entry.expected
            ));
        }
    }
    wrong
}

#[test]
fn the_header_matches_every_record_code_constant_and_service_setting_of_the_crate() {
    let (Some(cc), Some(cxx)) = (compiler("CC", "cc"), compiler("CXX", "c++")) else {
        return;
    };
    let scratch = Scratch::new("match");
    let table = table();
    let wrong = mismatches(&cc, &cxx, &header_dir(), &table, &scratch);
    assert!(
        wrong.is_empty(),
        "ipc/c/proxima_wire.h disagrees with the crate:\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_header_compiles_cleanly_as_c99_and_as_cxx98_to_cxx20() {
    let (Some(cc), Some(cxx)) = (compiler("CC", "cc"), compiler("CXX", "c++")) else {
        return;
    };
    let scratch = Scratch::new("standards");
    let source = scratch.0.join("use_wire.c");
    // A C and C++ program that uses a record, a code and a flag, and checks them at run time.
    std::fs::write(
        &source,
        format!(
            "#include \"proxima_wire.h\"\n\
             #include \"proxima_wire.h\" /* the include guard holds */\n\
             int main(void) {{\n\
                 proxima_PoseFrameHeader h;\n\
                 h.protocol_version = PROXIMA_PROTOCOL_VERSION;\n\
                 h.query_flags = PROXIMA_QUERY_CLOSE | PROXIMA_QUERY_CONTACTS;\n\
                 return (h.protocol_version == {} && h.query_flags == 10\n\
                         && PROXIMA_ERROR_SCENE_RELEASED == 15) ? 0 : 1;\n\
             }}\n",
            proxima_ipc::PROTOCOL_VERSION
        ),
    )
    .unwrap();
    let strict = ["-Wall", "-Wextra", "-pedantic", "-Werror"];
    let out = scratch.0.join("use_wire");
    for standard in ["-std=c99", "-std=c11", "-std=c17"] {
        compile(
            &cc,
            &[&[standard], &strict[..]].concat(),
            &header_dir(),
            &source,
            &out,
        );
        assert!(
            Command::new(&out).status().unwrap().success(),
            "{standard}: wrong values"
        );
    }
    for standard in ["-std=c++98", "-std=c++11", "-std=c++17", "-std=c++20"] {
        compile(
            &cxx,
            &[&[standard, "-x", "c++"], &strict[..]].concat(),
            &header_dir(),
            &source,
            &out,
        );
        assert!(
            Command::new(&out).status().unwrap().success(),
            "{standard}: wrong values"
        );
    }
}

#[test]
fn a_header_that_drifted_from_the_crate_is_caught() {
    let (Some(cc), Some(cxx)) = (compiler("CC", "cc"), compiler("CXX", "c++")) else {
        return;
    };
    let scratch = Scratch::new("drift");
    let header = std::fs::read_to_string(header_dir().join("proxima_wire.h")).unwrap();
    // Three kinds of drift: two fields swapped, a constant changed, a type name misspelt.
    let drifted = replace_once(
        &header,
        "    uint32_t body_a;\n    /** Body B. */\n    uint32_t body_b;",
        "    uint32_t body_b;\n    /** Body B. */\n    uint32_t body_a;",
    );
    let drifted = replace_once(
        &drifted,
        "PROXIMA_EVENT_CONTROL_SENT 3",
        "PROXIMA_EVENT_CONTROL_SENT 4",
    );
    let drifted = replace_once(&drifted, "\"proxima::PoseRecord\"", "\"proxima::Pose\"");
    std::fs::write(scratch.0.join("proxima_wire.h"), drifted).unwrap();

    let wrong = mismatches(&cc, &cxx, &scratch.0, &table(), &scratch);
    let keys: BTreeSet<&str> = wrong.iter().map(|w| w.split(':').next().unwrap()).collect();
    assert_eq!(
        keys,
        BTreeSet::from([
            "field proxima_ResultRecord.body_a",
            "field proxima_ResultRecord.body_b",
            "const PROXIMA_EVENT_CONTROL_SENT",
            "str PROXIMA_TYPE_NAME_POSE_RECORD",
        ]),
        "{wrong:#?}"
    );
}

fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(
        text.matches(from).count(),
        1,
        "{from:?} is not in the header exactly once"
    );
    text.replacen(from, to, 1)
}

// ---------------------------------------------------------------------------------------
// Completeness

/// Every item the crate declares for the wire: `wire::Record.field`, `wire::Enum::Variant`,
/// `wire::module::CONST`, `wire::CONST`, `CONST` (crate root), `scene_link::CONST`.
fn rust_inventory() -> BTreeSet<String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut items = BTreeSet::new();
    let wire = std::fs::read_to_string(src.join("wire.rs")).unwrap();
    let (mut module, mut record, mut enumeration) =
        (None::<String>, None::<String>, None::<String>);
    for line in wire.lines() {
        let trimmed = line.trim_start();
        if line == "}" {
            (module, record, enumeration) = (None, None, None);
        } else if let Some(rest) = line.strip_prefix("pub mod ") {
            module = Some(rest.trim_end_matches(" {").to_owned());
        } else if let Some(rest) = line.strip_prefix("pub struct ") {
            record = Some(rest.trim_end_matches(" {").to_owned());
        } else if let Some(rest) = line.strip_prefix("pub enum ") {
            enumeration = Some(rest.trim_end_matches(" {").to_owned());
        } else if let Some(rest) = trimmed.strip_prefix("pub const ")
            && !rest.starts_with("fn ")
        {
            let name = rest.split(':').next().unwrap();
            match &module {
                Some(m) => items.insert(format!("wire::{m}::{name}")),
                None => items.insert(format!("wire::{name}")),
            };
        } else if let (Some(r), Some(rest)) = (&record, trimmed.strip_prefix("pub ")) {
            items.insert(format!("wire::{r}.{}", rest.split(':').next().unwrap()));
        } else if let (Some(e), Some((variant, value))) = (&enumeration, trimmed.split_once(" = "))
            && variant.chars().all(|c| c.is_ascii_alphanumeric())
            && value.trim_end_matches(',').parse::<u32>().is_ok()
        {
            items.insert(format!("wire::{e}::{variant}"));
        }
    }
    for (file, prefix) in [("lib.rs", ""), ("scene_link.rs", "scene_link::")] {
        let text = std::fs::read_to_string(src.join(file)).unwrap();
        for line in text.lines() {
            if let Some(rest) = line.strip_prefix("pub const ") {
                items.insert(format!("{prefix}{}", rest.split(':').next().unwrap()));
            }
        }
    }
    items
}

/// Every name `proxima_wire.h` defines: object-like macros, enum constants, record types
/// (less the include guard and the static-assertion helpers).
fn header_names() -> BTreeSet<String> {
    let header = std::fs::read_to_string(header_dir().join("proxima_wire.h")).unwrap();
    let mut names = BTreeSet::new();
    for line in header.lines() {
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix("#define ") {
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let function_like = rest[name.len()..].starts_with('(');
            if !function_like && name != "PROXIMA_WIRE_H" {
                names.insert(name);
            }
        } else if trimmed.starts_with("PROXIMA_") && trimmed.contains(" = ") {
            names.insert(trimmed.split(" = ").next().unwrap().to_owned());
        } else if let Some(rest) = trimmed.strip_prefix("typedef struct ") {
            names.insert(rest.trim_end_matches(" {").to_owned());
        }
    }
    names
}

#[test]
fn every_wire_item_and_every_name_of_the_header_is_in_the_check_table() {
    let table = table();
    let checked: BTreeSet<String> = table
        .entries
        .iter()
        .filter_map(|e| e.rust_item.clone())
        .collect();
    let declared = rust_inventory();
    assert!(
        declared.len() > 100,
        "the inventory parser found only {declared:?}"
    );
    let unchecked: Vec<_> = declared.difference(&checked).collect();
    assert!(
        unchecked.is_empty(),
        "items of the crate with no C counterpart in ipc/tests/c_header.rs (add them to the \
         header and the table): {unchecked:?}"
    );
    let unknown: Vec<_> = checked.difference(&declared).collect();
    assert!(
        unknown.is_empty(),
        "table items the inventory parser did not find: {unknown:?}"
    );

    let defined = header_names();
    let not_checked: Vec<_> = defined.difference(&table.c_names).collect();
    assert!(
        not_checked.is_empty(),
        "names of the header that no check covers: {not_checked:?}"
    );
    let missing: Vec<_> = table.c_names.difference(&defined).collect();
    assert!(
        missing.is_empty(),
        "names the table expects that the header lacks: {missing:?}"
    );
}
