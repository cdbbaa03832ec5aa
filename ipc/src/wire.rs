//! Wire records: every `#[repr(C)]` type that crosses shared memory, with its size pinned at
//! compile time.
//!
//! Units are SI (metres; times in integer nanoseconds, named `_ns`); positions and
//! orientations are in the **world frame** of the scene; quaternions are `[x, y, z, w]`.
//! Every record has an explicit `reserved` field wherever `repr(C)` would otherwise leave
//! padding, so no byte on the wire is uninitialised. Each type carries a stable
//! `#[type_name]`, so services opened by any client (Rust, C, Python) match by name, size
//! and alignment. Changing any layout or meaning here requires bumping
//! [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION).
//!
//! | service | payload | user header |
//! |---|---|---|
//! | `<root>/<scene>/poses` (publish–subscribe) | `[PoseRecord]` | [`PoseFrameHeader`] |
//! | `<root>/<scene>/results` (publish–subscribe) | `[ResultRecord]`: pairs, then contacts | [`ResultFrameHeader`] |

use iceoryx2::prelude::ZeroCopySend;

/// Bits of [`PoseFrameHeader::query_flags`]: what the frame asks for. A frame pays only for
/// what it asks.
pub mod query {
    /// Yes/no overlap per close pair.
    pub const OVERLAP: u32 = 1 << 0;
    /// Pairs within the sum of their margins, with a distance.
    pub const CLOSE: u32 = 1 << 1;
    /// The exact signed distance of every candidate pair, with witnesses and normal.
    pub const DISTANCE: u32 = 1 << 2;
    /// Contact manifolds of touching pairs.
    pub const CONTACTS: u32 = 1 << 3;
    /// Time of impact over the motion since the previous frame.
    pub const TOI: u32 = 1 << 4;
    /// Every flag defined by this protocol version; other bits are rejected.
    pub const ALL: u32 = OVERLAP | CLOSE | DISTANCE | CONTACTS | TOI;
}

/// The header of one pose frame (the user header of a `[PoseRecord]` sample).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("proxima::PoseFrameHeader")]
pub struct PoseFrameHeader {
    /// [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION) of the sender.
    pub protocol_version: u32,
    /// The scene id the poses belong to.
    pub scene: u32,
    /// Sequence number chosen by the client; the matching result frame carries it back.
    pub frame_seq: u64,
    /// Time budget for this frame, nanoseconds from the daemon's receipt of the frame to its
    /// publication of the result; 0 = no deadline (exact answers).
    pub budget_ns: u64,
    /// Bit set of [`query`] flags.
    pub query_flags: u32,
    /// Number of [`PoseRecord`]s in the payload (must equal the slice length).
    pub count: u32,
}

/// The new pose of one body. Bodies not listed in a frame keep their last pose.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("proxima::PoseRecord")]
pub struct PoseRecord {
    /// Body id (as returned when the body was added).
    pub body: u32,
    /// Always 0 (keeps `position` 8-byte aligned without hidden padding).
    pub reserved: u32,
    /// Position of the body's local origin, metres, world frame.
    pub position: [f64; 3],
    /// Orientation of the body's local frame in the world, unit quaternion `[x, y, z, w]`
    /// (renormalised by the daemon when within 1e-6 of unit length, rejected otherwise).
    pub orientation: [f64; 4],
}

/// Outcome of a whole frame or of a control request. `0` is success; every other value names
/// what was wrong, and the record that carries it says which body or request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
#[non_exhaustive]
pub enum ErrorCode {
    /// Success.
    Ok = 0,
    /// The sender speaks another protocol version.
    ProtocolMismatch = 1,
    /// No scene with this id.
    UnknownScene = 2,
    /// No body with this id in the scene.
    UnknownBody = 3,
    /// No shape with this id.
    UnknownShape = 4,
    /// A pose has a NaN or infinite coordinate, a coordinate beyond the limit, or a
    /// quaternion that is not unit length.
    InvalidPose = 5,
    /// A primitive shape's dimensions are NaN, infinite, negative or out of range.
    InvalidShape = 6,
    /// A mesh index points past the vertex list.
    MeshIndexOutOfRange = 7,
    /// A mesh or point cloud has no triangles or points.
    EmptyGeometry = 8,
    /// Geometry, bodies or scenes beyond the daemon's configured limits.
    LimitExceeded = 9,
    /// A header's counts disagree with its payload, or a field has an undefined value.
    MalformedMessage = 10,
    /// The daemon failed internally (logged); the request may be retried.
    Internal = 11,
}

impl ErrorCode {
    /// The code for a wire value, `None` for values this version does not define.
    #[must_use]
    pub const fn from_u32(value: u32) -> Option<Self> {
        Some(match value {
            0 => Self::Ok,
            1 => Self::ProtocolMismatch,
            2 => Self::UnknownScene,
            3 => Self::UnknownBody,
            4 => Self::UnknownShape,
            5 => Self::InvalidPose,
            6 => Self::InvalidShape,
            7 => Self::MeshIndexOutOfRange,
            8 => Self::EmptyGeometry,
            9 => Self::LimitExceeded,
            10 => Self::MalformedMessage,
            11 => Self::Internal,
            _ => return None,
        })
    }
}

impl std::fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let text = match self {
            Self::Ok => "ok",
            Self::ProtocolMismatch => "protocol version mismatch",
            Self::UnknownScene => "unknown scene",
            Self::UnknownBody => "unknown body",
            Self::UnknownShape => "unknown shape",
            Self::InvalidPose => "invalid pose (NaN, infinite, out of range or non-unit rotation)",
            Self::InvalidShape => "invalid shape dimensions",
            Self::MeshIndexOutOfRange => "mesh index out of range",
            Self::EmptyGeometry => "empty geometry",
            Self::LimitExceeded => "configured limit exceeded",
            Self::MalformedMessage => "malformed message",
            Self::Internal => "internal error",
        };
        f.write_str(text)
    }
}

/// Whether a frame's answer is exact or was cut short by its deadline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Completeness {
    /// Every pair answered exactly.
    Exact = 0,
    /// The deadline cut traversal short; answers are conservative (see DESIGN §4) and
    /// [`ResultFrameHeader::deepest_level`] bounds their error.
    Truncated = 1,
}

/// Stage indices of [`ResultFrameHeader::stage_ns`], in pipeline order.
pub mod stage {
    /// Ingest and validation of the pose frame.
    pub const INGEST: usize = 0;
    /// Planning: what moved, which stages run.
    pub const PLAN: usize = 1;
    /// Broad phase.
    pub const BROAD: usize = 2;
    /// Mid phase: BVH traversal.
    pub const MID: usize = 3;
    /// Narrow phase: exact primitive tests and manifolds.
    pub const NARROW: usize = 4;
    /// Writing and publishing the result frame.
    pub const PUBLISH: usize = 5;
    /// Number of stages.
    pub const COUNT: usize = 6;
}

/// The header of one result frame (the user header of a `[ResultRecord]` sample).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("proxima::ResultFrameHeader")]
pub struct ResultFrameHeader {
    /// [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION) of the daemon.
    pub protocol_version: u32,
    /// [`ErrorCode`] of the frame as a whole (`0`: the frame was processed; otherwise it was
    /// rejected and the payload is empty).
    pub status: u32,
    /// The `frame_seq` of the pose frame this answers.
    pub frame_seq: u64,
    /// The body that caused a non-zero `status`, or `u32::MAX`.
    pub error_body: u32,
    /// [`Completeness`] as `u32`.
    pub completeness: u32,
    /// With `Truncated`: the shallowest BVH level at which some pair's traversal stopped
    /// (0 = roots); its bounding volumes' stand-off bounds the error. With `Exact`: 0.
    pub deepest_level: u32,
    /// 1 when the result was published within the frame's budget (or it had none), else 0.
    pub budget_met: u32,
    /// Number of pair records at the start of the payload.
    pub pair_count: u32,
    /// Number of contact records after the pairs.
    pub contact_count: u32,
    /// Time from the receipt of the pose frame to the publication of this one, nanoseconds.
    pub elapsed_ns: u64,
    /// Time per pipeline stage, nanoseconds, indexed by [`stage`].
    pub stage_ns: [u64; stage::COUNT],
}

/// What a [`ResultRecord`] describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum RecordKind {
    /// A close pair with its signed distance and witness points.
    Pair = 1,
    /// One point of a pair's contact manifold.
    Contact = 2,
}

/// A close pair or one contact point: both are a pair of points on the two bodies' surfaces,
/// a normal and a signed distance.
///
/// - `Pair`: `body_a < body_b`; `distance` is the signed distance (positive = separation,
///   negative = penetration depth), `point_a`/`point_b` its witnesses, `normal` the unit
///   normal from A to B; `index`/`count` locate the pair's contacts among the contact
///   records (`count` 0 when none were asked or found).
/// - `Contact`: `distance = −depth` (≤ 0 when touching or penetrating), `point_a`/`point_b`
///   the contact points on each surface, `normal` from A to B, `index` the pair's position
///   among the pair records.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("proxima::ResultRecord")]
pub struct ResultRecord {
    /// [`RecordKind`] as `u32`.
    pub kind: u32,
    /// Body A (the smaller id).
    pub body_a: u32,
    /// Body B.
    pub body_b: u32,
    /// See the type docs.
    pub index: u32,
    /// See the type docs.
    pub count: u32,
    /// Always 0.
    pub reserved: u32,
    /// Signed distance, metres (see the type docs).
    pub distance: f64,
    /// `|distance − true distance| ≤ error_bound`, metres.
    pub error_bound: f64,
    /// Point on A's surface, metres, world frame.
    pub point_a: [f64; 3],
    /// Point on B's surface, metres, world frame.
    pub point_b: [f64; 3],
    /// Unit normal from A to B, world frame.
    pub normal: [f64; 3],
}

const _: () = assert!(size_of::<PoseFrameHeader>() == 32);
const _: () = assert!(size_of::<PoseRecord>() == 64);
const _: () = assert!(size_of::<ResultFrameHeader>() == 96);
const _: () = assert!(size_of::<ResultRecord>() == 112);
