/*
 * proxima_wire.h: Proxima's wire protocol for C and C++ clients of proximad.
 *
 * The records that cross iceoryx2 0.10 shared memory, their iceoryx2 type names, every code,
 * bit set, event id and service setting, and the protocol version. The rules around them
 * (sequences, what each field means in each command, limits) are in ipc/PROTOCOL.md; the
 * Rust definitions are ipc/src/wire.rs and ipc/src/lib.rs. ipc/tests/c_header.rs compiles
 * this header as C and C++ and checks every size, offset, type, name and value below
 * against the Rust crate, so the two cannot drift apart.
 *
 * Conventions: units are SI (metres, radians; times are integer nanoseconds, named *_ns);
 * positions, points and normals are in the scene's world frame; quaternions are unit,
 * ordered [x, y, z, w]; byte order is the host's. Every record fills its size exactly:
 * where C would pad, there is a `reserved` field, always 0. Enumerated fields are carried
 * as uint32_t; the enums below name their values.
 *
 * Plain C99 (plus C11/C++11 static assertions where available); needs only <stdint.h>,
 * <stddef.h> and <inttypes.h>. Declares no functions, so it links against nothing.
 */
#ifndef PROXIMA_WIRE_H
#define PROXIMA_WIRE_H

#include <inttypes.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------------------------
 * Version, type names, service names
 * ------------------------------------------------------------------------------------- */

/** Protocol version. A client and a daemon whose versions differ refuse to talk (Hello
 *  answers ProtocolMismatch); every record carries it. */
#define PROXIMA_PROTOCOL_VERSION UINT32_C(11)

/* iceoryx2 matches services by name and by each type's name, size and alignment: declare
 * the types with exactly these names (C: the *_type_details setters; C++: IOX2_TYPE_NAME). */

/** Type name of the control request's payload element (a byte slice of geometry). */
#define PROXIMA_TYPE_NAME_CONTROL_PAYLOAD "u8"
/** Type name of the control response's user header: none, iceoryx2's unit type
 *  (size 0, alignment 1). */
#define PROXIMA_TYPE_NAME_NO_HEADER "()"
#define PROXIMA_TYPE_NAME_CONTROL_REQUEST "proxima::ControlRequest"
#define PROXIMA_TYPE_NAME_CONTROL_REPLY "proxima::ControlReply"
#define PROXIMA_TYPE_NAME_POSE_FRAME_HEADER "proxima::PoseFrameHeader"
#define PROXIMA_TYPE_NAME_POSE_RECORD "proxima::PoseRecord"
#define PROXIMA_TYPE_NAME_RESULT_FRAME_HEADER "proxima::ResultFrameHeader"
#define PROXIMA_TYPE_NAME_RESULT_RECORD "proxima::ResultRecord"

/** Default root of every service name (a daemon started with --root R uses R). */
#define PROXIMA_DEFAULT_ROOT "proxima"

/* Service names, as printf formats: the root (const char *), then for scene services the
 * two words of the scene's token (uint64_t, ControlReply.scene_token of its CreateScene),
 * printed as 32 lowercase hex digits. Example:
 *   snprintf(buf, n, PROXIMA_SERVICE_POSES_FORMAT, root,
 *            PROXIMA_SCENE_TOKEN_ARGS(reply.scene_token));
 * The token is the capability to read the scene's results: keep it out of logs. */

/** The two printf arguments of a scene token (a uint64_t[2]), for the scene formats. */
#define PROXIMA_SCENE_TOKEN_ARGS(token) (token)[0], (token)[1]
/** The common prefix of a scene's services: "<root>/scene-<token>". */
#define PROXIMA_SCENE_SERVICES_FORMAT "%s/scene-%016" PRIx64 "%016" PRIx64

/** Request-response: request user header ControlRequest with a u8 payload slice (geometry),
 *  response ControlReply. */
#define PROXIMA_SERVICE_CONTROL_FORMAT "%s/control"
/** Event: clients notify PROXIMA_EVENT_CONTROL_SENT after each control request. */
#define PROXIMA_SERVICE_CONTROL_EVENTS_FORMAT "%s/control-events"
/** Publish-subscribe: PoseRecord slices with a PoseFrameHeader user header. */
#define PROXIMA_SERVICE_POSES_FORMAT PROXIMA_SCENE_SERVICES_FORMAT "/poses"
/** Event: clients notify PROXIMA_EVENT_POSES_SENT after each pose frame. */
#define PROXIMA_SERVICE_POSES_READY_FORMAT PROXIMA_SCENE_SERVICES_FORMAT "/poses-ready"
/** Publish-subscribe: ResultRecord slices with a ResultFrameHeader user header. */
#define PROXIMA_SERVICE_RESULTS_FORMAT PROXIMA_SCENE_SERVICES_FORMAT "/results"
/** Event: the daemon notifies PROXIMA_EVENT_RESULTS_READY after each result frame. */
#define PROXIMA_SERVICE_RESULTS_READY_FORMAT PROXIMA_SCENE_SERVICES_FORMAT "/results-ready"

/* ---------------------------------------------------------------------------------------
 * Service settings. The daemon creates every service with exactly these settings; a client
 * only opens them (never creates: a control service that does not exist means the daemon
 * is not up yet, a scene service that does not exist means no such scene), with the same
 * settings (when opening, iceoryx2 treats each as a minimum). Values equal to iceoryx2's
 * defaults are listed too, so that a binding whose defaults differ can set them. See
 * PROTOCOL.md.
 * ------------------------------------------------------------------------------------- */

/** iceoryx2's default max_nodes of publish-subscribe services, used by poses and results
 *  (control sets its own). */
#define PROXIMA_DEFAULT_MAX_NODES 20
/** iceoryx2's default max_nodes of event services, used by poses ready and results ready
 *  (control events sets its own). */
#define PROXIMA_DEFAULT_EVENT_MAX_NODES 36
/** iceoryx2's default event_id_max_value, used by every event service. Event services
 *  set no deadline and no notifier created/dropped/dead events. */
#define PROXIMA_EVENT_ID_MAX_VALUE 255
/** Safe overflow (the default, which the results builder states) on every
 *  publish-subscribe service and on both directions of control: a full queue drops its
 *  oldest entry, the sender never blocks. */
#define PROXIMA_SAFE_OVERFLOW 1

/* control (request-response). */
/** Fire-and-forget requests: supported (iceoryx2's default, so the service is created with
 *  it); the daemon still answers every request with exactly one reply. */
#define PROXIMA_CONTROL_FIRE_AND_FORGET 1
#define PROXIMA_CONTROL_MAX_CLIENTS 64
#define PROXIMA_CONTROL_MAX_SERVERS 1
#define PROXIMA_CONTROL_MAX_ACTIVE_REQUESTS_PER_CLIENT 4
#define PROXIMA_CONTROL_MAX_RESPONSE_BUFFER_SIZE 4
#define PROXIMA_CONTROL_MAX_BORROWED_RESPONSES_PER_PENDING_RESPONSE 2
#define PROXIMA_CONTROL_MAX_LOANED_REQUESTS 2
/** Nodes that may hold control and control events at once: one per client, plus the
 *  daemon's ports. */
#define PROXIMA_CONTROL_MAX_NODES (PROXIMA_CONTROL_MAX_CLIENTS + PROXIMA_DAEMON_EVENT_PORTS)
/** Client port: initial byte capacity of a request slice, with the PowerOfTwo allocation
 *  strategy so geometry of any size fits. */
#define PROXIMA_CONTROL_INITIAL_MAX_SLICE_LEN 4096

/* control events (event). */
#define PROXIMA_CONTROL_EVENTS_MAX_NOTIFIERS PROXIMA_CONTROL_MAX_CLIENTS
#define PROXIMA_CONTROL_EVENTS_MAX_LISTENERS PROXIMA_DAEMON_EVENT_PORTS
#define PROXIMA_CONTROL_EVENTS_MAX_NODES PROXIMA_CONTROL_MAX_NODES

/** Daemon ports on a daemon-side event service: the running daemon plus one slot for a
 *  crashed predecessor not yet cleaned up. */
#define PROXIMA_DAEMON_EVENT_PORTS 2

/** Frames a subscriber keeps before the oldest is overwritten (subscriber_max_buffer_size
 *  of poses and results; safe overflow on: the newest frame wins). */
#define PROXIMA_FRAME_BUFFER 2
/** history_size of poses and results: no history, so subscribe before the frame is sent. */
#define PROXIMA_FRAME_HISTORY_SIZE 0
/** subscriber_max_borrowed_samples of poses and results (default): release a frame before
 *  receiving the third. */
#define PROXIMA_FRAME_MAX_BORROWED_SAMPLES 2

/* poses (publish-subscribe) and poses ready (event). */
#define PROXIMA_POSES_MAX_PUBLISHERS 4
#define PROXIMA_POSES_MAX_SUBSCRIBERS 1
/** Pose publisher port: initial slice length in records, with the PowerOfTwo allocation
 *  strategy and PROXIMA_POSES_MAX_LOANED_SAMPLES. */
#define PROXIMA_POSES_INITIAL_MAX_SLICE_LEN 1024
/** Pose publisher port: frames on loan at once. */
#define PROXIMA_POSES_MAX_LOANED_SAMPLES 1
#define PROXIMA_POSES_READY_MAX_NOTIFIERS PROXIMA_POSES_MAX_PUBLISHERS
#define PROXIMA_POSES_READY_MAX_LISTENERS PROXIMA_DAEMON_EVENT_PORTS

/* results (publish-subscribe) and results ready (event). */
#define PROXIMA_RESULTS_MAX_PUBLISHERS 1
#define PROXIMA_RESULTS_MAX_SUBSCRIBERS 8
#define PROXIMA_RESULTS_READY_MAX_NOTIFIERS PROXIMA_DAEMON_EVENT_PORTS
#define PROXIMA_RESULTS_READY_MAX_LISTENERS PROXIMA_RESULTS_MAX_SUBSCRIBERS

/* Event ids. */

/** Sent by a client on <root>/scene-<token>/poses-ready after publishing a pose frame. */
#define PROXIMA_EVENT_POSES_SENT 1
/** Sent by the daemon on <root>/scene-<token>/results-ready after publishing a result
 *  frame. */
#define PROXIMA_EVENT_RESULTS_READY 2
/** Sent by a client on <root>/control-events after sending a control request. */
#define PROXIMA_EVENT_CONTROL_SENT 3

/* ---------------------------------------------------------------------------------------
 * Codes
 * ------------------------------------------------------------------------------------- */

/** "No id": ControlReply.id on error, ResultFrameHeader.error_body when no body is to
 *  blame. */
#define PROXIMA_INVALID_ID UINT32_MAX
/** Most Contact records per pair (one manifold). */
#define PROXIMA_MAX_CONTACTS_PER_PAIR 4
/** Bytes of ControlReply.reason. */
#define PROXIMA_REASON_BYTES 112
/** Most parts of a Compound or DecomposedMesh shape. */
#define PROXIMA_MAX_COMPOUND_PARTS 1024

/** Outcome of a frame (ResultFrameHeader.status) or a request (ControlReply.status). */
typedef enum proxima_ErrorCode {
    PROXIMA_ERROR_OK = 0,
    /** The sender speaks another protocol version. */
    PROXIMA_ERROR_PROTOCOL_MISMATCH = 1,
    PROXIMA_ERROR_UNKNOWN_SCENE = 2,
    PROXIMA_ERROR_UNKNOWN_BODY = 3,
    PROXIMA_ERROR_UNKNOWN_SHAPE = 4,
    /** NaN, infinite or out-of-range coordinate, or a non-unit quaternion. */
    PROXIMA_ERROR_INVALID_POSE = 5,
    /** Primitive dimensions NaN, infinite, negative or out of range. */
    PROXIMA_ERROR_INVALID_SHAPE = 6,
    PROXIMA_ERROR_MESH_INDEX_OUT_OF_RANGE = 7,
    /** A mesh or point cloud without triangles or points. */
    PROXIMA_ERROR_EMPTY_GEOMETRY = 8,
    /** Beyond the daemon's configured limits. */
    PROXIMA_ERROR_LIMIT_EXCEEDED = 9,
    /** Counts disagree with the payload, or a field has an undefined value. */
    PROXIMA_ERROR_MALFORMED_MESSAGE = 10,
    /** The daemon failed internally (logged); the request may be retried. */
    PROXIMA_ERROR_INTERNAL = 11,
    /** AddBody on a shape still being built; nothing changed: ask ShapeState, retry. */
    PROXIMA_ERROR_SHAPE_NOT_READY = 12,
    /** The scene belongs to another client port: only the port that created it may change
     *  it, drop it, ask ShapeState of it or send it frames. */
    PROXIMA_ERROR_NOT_OWNER = 13,
    /** The daemon stopped serving the scene after a fault on its shared-memory services
     *  (the reason says which); only DropScene is accepted. */
    PROXIMA_ERROR_SCENE_QUARANTINED = 14,
    /** In a result frame only: the daemon let go of the scene; its last frame, no
     *  records. */
    PROXIMA_ERROR_SCENE_RELEASED = 15
} proxima_ErrorCode;

/** ControlRequest.command. The reply's id is given where it means something. A command
 *  naming a scene from another client port than its creator's gets
 *  PROXIMA_ERROR_NOT_OWNER. */
typedef enum proxima_Command {
    /** Check the protocol version; id = the daemon's version. */
    PROXIMA_COMMAND_HELLO = 0,
    /** id = the new scene (random, owned by the requesting client port); the reply also
     *  carries its frame_key and scene_token. */
    PROXIMA_COMMAND_CREATE_SCENE = 1,
    /** Drop `scene` with all its bodies and services (or a quarantined scene's id). */
    PROXIMA_COMMAND_DROP_SCENE = 2,
    /** shape_kind, dimensions, geometry payload; id = the shape. Convex and mesh shapes are
     *  built after the reply, which then carries PROXIMA_REPLY_FLAG_SHAPE_BUILDING. */
    PROXIMA_COMMAND_REGISTER_SHAPE = 3,
    /** Body of shape `target` in `scene` with motion, group, mask, margin, pose; id = the
     *  body. */
    PROXIMA_COMMAND_ADD_BODY = 4,
    /** Remove body `target` from `scene`. */
    PROXIMA_COMMAND_REMOVE_BODY = 5,
    /** Change body `target`'s motion, group, mask and margin. */
    PROXIMA_COMMAND_UPDATE_BODY = 6,
    /** Set `scene`'s broad_phase from the next frame on; id = the scene. */
    PROXIMA_COMMAND_SET_SCENE_PARAMS = 7,
    /** Is shape `target` built? id = target; SHAPE_BUILDING while it is being built. */
    PROXIMA_COMMAND_SHAPE_STATE = 8
} proxima_Command;

/** ControlRequest.shape_kind, with the meaning of `dimensions` (metres, local frame). */
typedef enum proxima_ShapeKindCode {
    /** [radius, 0, 0, 0]. */
    PROXIMA_SHAPE_KIND_SPHERE = 0,
    /** Along local Z: [radius, half_height, 0, 0]. */
    PROXIMA_SHAPE_KIND_CAPSULE = 1,
    /** [half_x, half_y, half_z, 0]. */
    PROXIMA_SHAPE_KIND_CUBOID = 2,
    /** Along local Z: [radius, half_height, 0, 0]. */
    PROXIMA_SHAPE_KIND_CYLINDER = 3,
    /** Along local Z, apex at +half_height: [radius, half_height, 0, 0]. */
    PROXIMA_SHAPE_KIND_CONE = 4,
    /** Convex hull of vertex_count points in the payload. */
    PROXIMA_SHAPE_KIND_CONVEX = 5,
    /** vertex_count points, then index_count indices (three per triangle). */
    PROXIMA_SHAPE_KIND_MESH = 6,
    /** vertex_count points, then index_count part sizes; each part the hull of its points. */
    PROXIMA_SHAPE_KIND_COMPOUND = 7,
    /** A closed mesh (payload as MESH) the daemon decomposes into a compound:
        [max_concavity, max_parts, method, 0]. */
    PROXIMA_SHAPE_KIND_DECOMPOSED_MESH = 8
} proxima_ShapeKindCode;

/** ControlRequest.motion. Static bodies never pair with each other. */
typedef enum proxima_MotionCode {
    PROXIMA_MOTION_STATIC = 0,
    /** Moved by the client, not by physics. */
    PROXIMA_MOTION_KINEMATIC = 1,
    /** Moved by the client's physics. */
    PROXIMA_MOTION_DYNAMIC = 2
} proxima_MotionCode;

/** ControlRequest.broad_phase (SetSceneParams). All report the same pairs; cost differs. */
typedef enum proxima_BroadPhaseCode {
    /** The daemon chooses from the scene's statistics (the default). */
    PROXIMA_BROAD_PHASE_AUTO = 0,
    PROXIMA_BROAD_PHASE_SORT_AND_SWEEP = 1,
    PROXIMA_BROAD_PHASE_INCREMENTAL_SAP = 2,
    PROXIMA_BROAD_PHASE_HASH_GRID = 3,
    PROXIMA_BROAD_PHASE_COLUMN_GRID = 4,
    PROXIMA_BROAD_PHASE_SKIN_GRID = 5
} proxima_BroadPhaseCode;

/** ResultFrameHeader.completeness. */
typedef enum proxima_Completeness {
    /** Every pair answered exactly. */
    PROXIMA_COMPLETENESS_EXACT = 0,
    /** Cut short by the deadline: answers are conservative, deepest_level bounds the error. */
    PROXIMA_COMPLETENESS_TRUNCATED = 1
} proxima_Completeness;

/** ResultRecord.kind. */
typedef enum proxima_RecordKind {
    /** A reported pair: signed distance and witness points. */
    PROXIMA_RECORD_KIND_PAIR = 1,
    /** One point of a pair's contact manifold. */
    PROXIMA_RECORD_KIND_CONTACT = 2,
    /** A pair's time of impact over the frame's motion. */
    PROXIMA_RECORD_KIND_TOI = 3
} proxima_RecordKind;

/* PoseFrameHeader.query_flags: what a frame asks for (at least one; undefined bits are
 * refused). See PROTOCOL.md for what each answers. */

/** Pairs that touch or intersect (distance <= 0). */
#define PROXIMA_QUERY_OVERLAP (UINT32_C(1) << 0)
/** Pairs within the sum of their margins, with signed distance, witnesses, normal A->B. */
#define PROXIMA_QUERY_CLOSE (UINT32_C(1) << 1)
/** The signed distance of every candidate pair. */
#define PROXIMA_QUERY_DISTANCE (UINT32_C(1) << 2)
/** A contact manifold (at most PROXIMA_MAX_CONTACTS_PER_PAIR points) per touching pair. */
#define PROXIMA_QUERY_CONTACTS (UINT32_C(1) << 3)
/** Time of impact over the motion since the previous frame. */
#define PROXIMA_QUERY_TOI (UINT32_C(1) << 4)
/** Every flag this protocol version defines. */
#define PROXIMA_QUERY_ALL                                                                  \
    (PROXIMA_QUERY_OVERLAP | PROXIMA_QUERY_CLOSE | PROXIMA_QUERY_DISTANCE |                \
     PROXIMA_QUERY_CONTACTS | PROXIMA_QUERY_TOI)

/* ResultFrameHeader.flags. */

/** More candidate pairs than one frame answers: the rest are counted in
 *  dropped_candidates, and a pair left out may touch. */
#define PROXIMA_FRAME_FLAG_PAIRS_CAPPED (UINT32_C(1) << 0)
/** The budget cannot hold the uninterruptible work: nothing answered, min_budget_ns says
 *  what would do. */
#define PROXIMA_FRAME_FLAG_BUDGET_TOO_SMALL (UINT32_C(1) << 1)
/** The scene's owner is gone: the frame's work was abandoned (Truncated answers), and the
 *  scene is released after the daemon's grace period. */
#define PROXIMA_FRAME_FLAG_OWNER_GONE (UINT32_C(1) << 2)

/** ResultRecord.flags: the answer is conservative (distance a lower bound within
 *  error_bound), not exact. */
#define PROXIMA_RECORD_FLAG_APPROXIMATE (UINT32_C(1) << 0)

/** ControlReply.flags: the convex or mesh shape (the reply's id) is still being built. */
#define PROXIMA_REPLY_FLAG_SHAPE_BUILDING (UINT32_C(1) << 0)

/* Indices of ResultFrameHeader.stage_ns, in pipeline order. */
#define PROXIMA_STAGE_INGEST 0
#define PROXIMA_STAGE_PLAN 1
#define PROXIMA_STAGE_BROAD 2
#define PROXIMA_STAGE_MID 3
#define PROXIMA_STAGE_NARROW 4
#define PROXIMA_STAGE_PUBLISH 5
/** Number of stages (length of stage_ns). */
#define PROXIMA_STAGE_COUNT 6

/* ---------------------------------------------------------------------------------------
 * Records
 * ------------------------------------------------------------------------------------- */

/** User header of a pose frame (a PoseRecord slice). 40 bytes, alignment 8. */
typedef struct proxima_PoseFrameHeader {
    /** PROXIMA_PROTOCOL_VERSION of the sender. */
    uint32_t protocol_version;
    /** Scene id the poses belong to. */
    uint32_t scene;
    /** Chosen by the client; the matching result frame carries it back. */
    uint64_t frame_seq;
    /** Nanoseconds from the daemon's receipt of the frame to its result's publication;
     *  0 = no deadline (exact answers). */
    uint64_t budget_ns;
    /** PROXIMA_QUERY_* bits. */
    uint32_t query_flags;
    /** Number of PoseRecords in the slice (must equal its length). */
    uint32_t count;
    /** The scene's frame key (ControlReply.frame_key of its CreateScene); a frame with
     *  another key is not answered. */
    uint64_t frame_key;
} proxima_PoseFrameHeader;

/** The new pose of one body; bodies not listed keep their last pose. 64 bytes, alignment 8. */
typedef struct proxima_PoseRecord {
    /** Body id. */
    uint32_t body;
    /** Always 0. */
    uint32_t reserved;
    /** Position of the body's local origin, metres, world frame. */
    double position[3];
    /** Orientation, unit quaternion [x, y, z, w], world frame. */
    double orientation[4];
} proxima_PoseRecord;

/** User header of a result frame (a ResultRecord slice: pairs, then contacts, then times of
 *  impact). 128 bytes, alignment 8. */
typedef struct proxima_ResultFrameHeader {
    /** PROXIMA_PROTOCOL_VERSION of the daemon. */
    uint32_t protocol_version;
    /** proxima_ErrorCode of the frame; non-zero: rejected, empty payload. */
    uint32_t status;
    /** frame_seq of the pose frame this answers. */
    uint64_t frame_seq;
    /** The body that caused a non-zero status, or PROXIMA_INVALID_ID. */
    uint32_t error_body;
    /** proxima_Completeness. */
    uint32_t completeness;
    /** Truncated: the shallowest BVH level (0 = roots) where a traversal stopped. Exact: 0. */
    uint32_t deepest_level;
    /** 1 when published within the budget (or there was none), else 0. */
    uint32_t budget_met;
    /** Pair records at the start of the payload. */
    uint32_t pair_count;
    /** Contact records after the pairs. */
    uint32_t contact_count;
    /** Candidate pairs the broad phase found, reported or not. */
    uint32_t candidate_count;
    /** Time-of-impact records after the contacts. */
    uint32_t toi_count;
    /** Nanoseconds from receipt of the pose frame to publication of this one. */
    uint64_t elapsed_ns;
    /** Nanoseconds per pipeline stage, indexed by PROXIMA_STAGE_*. */
    uint64_t stage_ns[PROXIMA_STAGE_COUNT];
    /** PROXIMA_FRAME_FLAG_* bits. */
    uint32_t flags;
    /** Candidate pairs not answered (with PROXIMA_FRAME_FLAG_PAIRS_CAPPED), else 0. */
    uint32_t dropped_candidates;
    /** With PROXIMA_FRAME_FLAG_BUDGET_TOO_SMALL: the smallest workable budget, ns; else 0. */
    uint64_t min_budget_ns;
    /** The daemon's instance id (as ControlReply.instance); another than the scene's means
     *  another daemon. */
    uint64_t instance;
} proxima_ResultFrameHeader;

/** A pair, a contact point or a time of impact (see `kind`; PROTOCOL.md for each
 *  field per kind). 120 bytes, alignment 8. */
typedef struct proxima_ResultRecord {
    /** proxima_RecordKind. */
    uint32_t kind;
    /** Body A (the smaller id). */
    uint32_t body_a;
    /** Body B. */
    uint32_t body_b;
    /** Pair: first contact, counted from the first contact record. Contact: its pair's
     *  position among the pairs. Toi: 0. */
    uint32_t index;
    /** Pair: its contacts (<= PROXIMA_MAX_CONTACTS_PER_PAIR). Contact: 0. Toi: 1, or 0 if
     *  the search stopped early. */
    uint32_t count;
    /** PROXIMA_RECORD_FLAG_* bits. */
    uint32_t flags;
    /** Signed distance, metres: positive = separation, negative = penetration depth. */
    double distance;
    /** |distance - true distance| <= error_bound, metres. */
    double error_bound;
    /** Point on A's surface, metres, world frame. */
    double point_a[3];
    /** Point on B's surface, metres, world frame. */
    double point_b[3];
    /** Unit normal from A to B, world frame (all zero when not computed). */
    double normal[3];
    /** Toi: fraction of the frame's motion in [0, 1]. Pair, Contact: 0. */
    double time;
} proxima_ResultRecord;

/** User header of a control request (payload: geometry bytes for RegisterShape of a convex
 *  or mesh shape, vertex_count * 3 doubles then index_count uint32_t, native byte order;
 *  empty otherwise). Fields a command does not use are 0. 144 bytes, alignment 8. */
typedef struct proxima_ControlRequest {
    /** PROXIMA_PROTOCOL_VERSION of the client. */
    uint32_t protocol_version;
    /** proxima_Command. */
    uint32_t command;
    /** Scene the command acts on (ignored by Hello, CreateScene). */
    uint32_t scene;
    /** Shape (AddBody, ShapeState) or body (RemoveBody, UpdateBody). */
    uint32_t target;
    /** proxima_ShapeKindCode (RegisterShape). */
    uint32_t shape_kind;
    /** proxima_MotionCode (AddBody, UpdateBody). */
    uint32_t motion;
    /** Collision group bits: a pair is tested when each group meets the other's mask. */
    uint32_t group;
    /** Collision mask bits. */
    uint32_t mask;
    /** Points in the geometry payload. */
    uint32_t vertex_count;
    /** uint32_t indices in the geometry payload (a multiple of 3). */
    uint32_t index_count;
    /** proxima_BroadPhaseCode (SetSceneParams). */
    uint32_t broad_phase;
    /** Always 0. */
    uint32_t reserved;
    /** Close-pair margin, metres, >= 0; negative = the scene's default. */
    double margin;
    /** Primitive dimensions, metres (see proxima_ShapeKindCode). */
    double dimensions[4];
    /** Initial position, metres, world frame (AddBody). */
    double position[3];
    /** Initial orientation, unit quaternion [x, y, z, w] (AddBody). */
    double orientation[4];
} proxima_ControlRequest;

/** The daemon's answer to one ControlRequest. 160 bytes, alignment 8. */
typedef struct proxima_ControlReply {
    /** PROXIMA_PROTOCOL_VERSION of the daemon. */
    uint32_t protocol_version;
    /** proxima_ErrorCode. */
    uint32_t status;
    /** New scene, shape or body id (see proxima_Command); PROXIMA_INVALID_ID on error. */
    uint32_t id;
    /** PROXIMA_REPLY_FLAG_* bits; 0 on error. */
    uint32_t flags;
    /** The daemon's instance id: random per daemon start, never 0, the same in every reply
     *  and result header of one run (a change means another daemon). */
    uint64_t instance;
    /** CreateScene: the scene's secret frame key, for PoseFrameHeader.frame_key; else 0. */
    uint64_t frame_key;
    /** CreateScene: the scene's token, which names its services (see
     *  PROXIMA_SCENE_SERVICES_FORMAT) and lets whoever holds it read its results; share it
     *  only with a monitor that may. All zero otherwise. */
    uint64_t scene_token[2];
    /** Why the request failed: UTF-8, zero-padded, not necessarily zero-terminated. */
    uint8_t reason[PROXIMA_REASON_BYTES];
} proxima_ControlReply;

/* ---------------------------------------------------------------------------------------
 * Layout pins (the full check, field by field, is ipc/tests/c_header.rs)
 * ------------------------------------------------------------------------------------- */

#if defined(__cplusplus) && __cplusplus >= 201103L
#define PROXIMA_STATIC_ASSERT(cond, msg) static_assert(cond, msg)
#elif defined(__STDC_VERSION__) && __STDC_VERSION__ >= 201112L
#define PROXIMA_STATIC_ASSERT(cond, msg) _Static_assert(cond, msg)
#else
/* C99: a negative array size stops the build. */
#define PROXIMA_STATIC_ASSERT_JOIN2(a, b) a##b
#define PROXIMA_STATIC_ASSERT_JOIN(a, b) PROXIMA_STATIC_ASSERT_JOIN2(a, b)
#define PROXIMA_STATIC_ASSERT(cond, msg)                                                   \
    typedef char PROXIMA_STATIC_ASSERT_JOIN(proxima_static_assert_, __LINE__)[(cond) ? 1 : -1]
#endif

PROXIMA_STATIC_ASSERT(sizeof(proxima_PoseFrameHeader) == 40, "PoseFrameHeader is 40 bytes");
PROXIMA_STATIC_ASSERT(offsetof(proxima_PoseFrameHeader, frame_seq) == 8, "frame_seq at 8");
PROXIMA_STATIC_ASSERT(offsetof(proxima_PoseFrameHeader, count) == 28, "count at 28");
PROXIMA_STATIC_ASSERT(offsetof(proxima_PoseFrameHeader, frame_key) == 32, "frame_key at 32");
PROXIMA_STATIC_ASSERT(sizeof(proxima_PoseRecord) == 64, "PoseRecord is 64 bytes");
PROXIMA_STATIC_ASSERT(offsetof(proxima_PoseRecord, position) == 8, "position at 8");
PROXIMA_STATIC_ASSERT(offsetof(proxima_PoseRecord, orientation) == 32, "orientation at 32");
PROXIMA_STATIC_ASSERT(sizeof(proxima_ResultFrameHeader) == 128, "ResultFrameHeader is 128 bytes");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultFrameHeader, elapsed_ns) == 48, "elapsed_ns at 48");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultFrameHeader, stage_ns) == 56, "stage_ns at 56");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultFrameHeader, min_budget_ns) == 112,
                      "min_budget_ns at 112");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultFrameHeader, instance) == 120, "instance at 120");
PROXIMA_STATIC_ASSERT(sizeof(proxima_ResultRecord) == 120, "ResultRecord is 120 bytes");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultRecord, distance) == 24, "distance at 24");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultRecord, normal) == 88, "normal at 88");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ResultRecord, time) == 112, "time at 112");
PROXIMA_STATIC_ASSERT(sizeof(proxima_ControlRequest) == 144, "ControlRequest is 144 bytes");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ControlRequest, margin) == 48, "margin at 48");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ControlRequest, orientation) == 112,
                      "orientation at 112");
PROXIMA_STATIC_ASSERT(sizeof(proxima_ControlReply) == 160, "ControlReply is 160 bytes");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ControlReply, instance) == 16, "instance at 16");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ControlReply, frame_key) == 24, "frame_key at 24");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ControlReply, scene_token) == 32, "scene_token at 32");
PROXIMA_STATIC_ASSERT(offsetof(proxima_ControlReply, reason) == 48, "reason at 48");

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* PROXIMA_WIRE_H */
