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
//! | `<root>/<scene>/results` (publish–subscribe) | `[ResultRecord]`: pairs, then contacts, then times of impact | [`ResultFrameHeader`] |
//! | `<root>/control` (request–response) | request `[u8]` (geometry, see [`ControlRequest`]), response [`ControlReply`] | request: [`ControlRequest`] |
//!
//! Control commands ([`Command`]): `Hello`, `CreateScene`, `DropScene`, `RegisterShape`,
//! `AddBody`, `RemoveBody`, `UpdateBody`, `SetSceneParams` (the scene's broad phase,
//! [`BroadPhaseCode`]), `ShapeState`.
//!
//! Every command that names a scene is answered only for the client port that created it
//! (others get [`ErrorCode::NotOwner`]); its pose frames must carry the scene's frame key;
//! its services are named by its token, the capability to read its results (since protocol
//! version 9).
//!
//! Shapes are built apart from the frames: a convex or mesh shape's `RegisterShape` is
//! answered as soon as its header is checked, with its id and
//! [`reply_flags::SHAPE_BUILDING`]; the shape becomes usable once built, which `ShapeState`
//! tells. Until then `AddBody` on it is refused with [`ErrorCode::ShapeNotReady`] (nothing is
//! queued: a body exists from the reply that gives its id on). Frames of every scene go on
//! meanwhile.

use iceoryx2::prelude::ZeroCopySend;

/// Bits of [`PoseFrameHeader::query_flags`]: what the frame asks for. A frame pays only for
/// what it asks (DESIGN §4).
///
/// *Candidate pairs* are the broad phase's: bodies whose world boxes, grown by their margins,
/// overlap (never static–static, filtered by group/mask). Each flag selects pairs among them;
/// the frame reports the union, once per pair, in `(body_a, body_b)` order, then the contacts
/// of those pairs. Flags combine (`CLOSE | CONTACTS`: the close pairs, the touching ones with
/// contacts); `OVERLAP` adds nothing to `CLOSE` or `DISTANCE`, whose records already say it
/// (`distance ≤ 0`). [`TOI`](query::TOI) is answered over the frame's motion, with its own
/// candidates and its own records after the contacts; it combines with every other flag.
///
/// A frame with no flag set (`0`) asks for nothing and is refused with
/// [`ErrorCode::MalformedMessage`] (its poses are not applied), so a forgotten flag is an
/// error rather than an empty answer. Undefined bits are refused.
///
/// Pairs answered by the conservative box answer (shape-kind pairs without an exact narrow
/// phase yet; the frame says `Truncated`, level 0) are reported whenever the truth *may*
/// qualify: their distance is a lower bound and "touching" means "the world boxes touch".
pub mod query {
    /// Pairs whose shapes touch or intersect (distance ≤ 0), found by the cheapest proof
    /// (meshes: the first intersecting triangle pair; spheres: closed form). When neither
    /// `CLOSE` nor `DISTANCE` is asked, a mesh pair's record says distance 0 (intersecting
    /// surfaces), error bound 0, and its points and normal are all zero ("not computed")
    /// unless `CONTACTS` supplies them (its first contact). Sphere pair records are always
    /// complete.
    pub const OVERLAP: u32 = 1 << 0;
    /// Pairs whose distance is at most the sum of the two bodies' margins, with signed
    /// distance, witnesses and normal A→B.
    pub const CLOSE: u32 = 1 << 1;
    /// The exact signed distance of every candidate pair (also those beyond the margins),
    /// with witnesses and normal A→B.
    pub const DISTANCE: u32 = 1 << 2;
    /// A contact manifold for each touching or penetrating pair, at most
    /// [`MAX_CONTACTS_PER_PAIR`](super::MAX_CONTACTS_PER_PAIR) points, linked from the pair
    /// record by `index`/`count`:
    /// - sphere–sphere: one point (the witnesses), `distance = −depth`;
    /// - mesh–mesh: points of the intersection curve (segment ends of the intersecting
    ///   triangle pairs) reduced to the extremes: the farthest pair, the point making the
    ///   largest triangle with them, the point adding the most area beyond it. One normal:
    ///   the normalised sum of A's triangle normals at the intersection (A→B). Depth 0 and
    ///   `point_a == point_b`: meshes are surfaces, so intersecting meshes touch along a
    ///   curve and have no penetration depth;
    /// - box-answer pairs: one conservative point (the box witnesses and normal), distance 0
    ///   with the box answer's error bound, which covers the unknown depth.
    pub const CONTACTS: u32 = 1 << 3;
    /// Time of impact over the motion since the previous frame: one
    /// [`Toi`](super::RecordKind::Toi) record for each pair that comes within contact
    /// (distance ≤ the sum of the two margins) during the motion.
    ///
    /// - **Motion:** each body moves from its pose when the scene's previous frame was
    ///   answered to its pose in this frame (bodies not listed, and bodies added since the
    ///   previous frame, are at rest). `time ∈ [0, 1]` is the fraction of that motion:
    ///   position interpolated linearly, orientation by slerp along the shorter arc.
    /// - **Candidates:** pairs whose world boxes swept over the motion, grown by their
    ///   margins, overlap (a superset of the other flags' candidates), so pairs that pass
    ///   through each other between two frames are found.
    /// - **Conservative:** the reported `time` is never later than the first time the pair
    ///   is within its margins, and at `time` the pair is within its margins plus
    ///   `error_bound` (the search tolerance, 1e-6 m). A pair already within contact at
    ///   the start reports `time = 0`; a pair that stays farther apart than its margins
    ///   throughout reports nothing.
    /// - **Record:** `distance`, `point_a`, `point_b` and `normal` (A→B) at the poses of
    ///   `time`, world frame; `count` 1, or 0 when the search stopped at its iteration limit
    ///   (a long grazing motion) or at the frame's deadline (still conservative: no contact
    ///   before `time`).
    /// - **Deadline:** candidates are searched in order while the frame has time left;
    ///   those after the deadline are reported unsearched, flagged
    ///   [`APPROXIMATE`](super::record_flags::APPROXIMATE): `time = 0`, `count` 0, and the
    ///   bodies' boxes at the start of the motion for distance (a lower bound, within
    ///   `error_bound`), witnesses and normal.
    pub const TOI: u32 = 1 << 4;
    /// Every flag defined by this protocol version; other bits are rejected.
    pub const ALL: u32 = OVERLAP | CLOSE | DISTANCE | CONTACTS | TOI;
}

/// Most contact records per pair (one manifold).
pub const MAX_CONTACTS_PER_PAIR: u32 = 4;

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
    /// The scene's frame key, from its `CreateScene` reply ([`ControlReply::frame_key`]):
    /// only the scene's owner knows it. A frame with another key is not answered (since
    /// protocol version 9).
    pub frame_key: u64,
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
    /// A primitive shape's dimensions are NaN, infinite, negative or out of range, or a
    /// convex or mesh point has a NaN, infinite or out-of-range coordinate.
    InvalidShape = 6,
    /// A mesh index points past the vertex list.
    MeshIndexOutOfRange = 7,
    /// A mesh or point cloud has no triangles or points.
    EmptyGeometry = 8,
    /// Geometry, bodies or scenes beyond the daemon's configured limits.
    LimitExceeded = 9,
    /// A header's counts disagree with its payload, a field has an undefined value, or a
    /// `reserved` field is not 0 (checked since protocol version 9).
    MalformedMessage = 10,
    /// The daemon failed internally (logged); the request may be retried.
    Internal = 11,
    /// `AddBody` named a shape that is still being built (its registration was answered
    /// with [`reply_flags::SHAPE_BUILDING`]); nothing changed. Wait until
    /// [`Command::ShapeState`] says it is built, then send the request again (since
    /// protocol version 8).
    ShapeNotReady = 12,
    /// The scene belongs to another client: only the client that created a scene may change
    /// it, drop it, ask about it or send it frames (since protocol version 9).
    NotOwner = 13,
    /// The daemon stopped serving the scene after a fault on its shared-memory services
    /// (the reason says which); its state is gone. Only `DropScene` is accepted, to let go
    /// of the id (since protocol version 9).
    SceneQuarantined = 14,
    /// In a result frame only: the daemon let go of the scene (dropped by its owner, or
    /// released after its owner was gone for the grace period, `OWNER_GONE` then set), and
    /// this is the scene's last frame. No records (since protocol version 10).
    SceneReleased = 15,
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
            12 => Self::ShapeNotReady,
            13 => Self::NotOwner,
            14 => Self::SceneQuarantined,
            15 => Self::SceneReleased,
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
            Self::ShapeNotReady => "shape not built yet",
            Self::NotOwner => "the scene belongs to another client",
            Self::SceneQuarantined => "the scene was quarantined after a shared-memory fault",
            Self::SceneReleased => "the daemon let go of the scene",
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
    /// The deadline cut traversal short, or answering some candidate pair failed (a bug)
    /// and it got the conservative box answer (level 0); answers are conservative (see
    /// DESIGN §4) and [`ResultFrameHeader::deepest_level`] bounds their error.
    Truncated = 1,
}

/// Stage indices of [`ResultFrameHeader::stage_ns`], in pipeline order. A stage the
/// daemon does not run separately yet reports 0.
pub mod stage {
    /// Ingest and validation of the pose frame (header, query flags, every pose).
    pub const INGEST: usize = 0;
    /// Planning: what moved, which stages run (not separate yet: 0).
    pub const PLAN: usize = 1;
    /// Broad phase: margin-grown world boxes to candidate pairs.
    pub const BROAD: usize = 2;
    /// Mid phase: the budgeted breadth-first frontier over every mesh–mesh pair's BVH
    /// node pairs, in frames with a budget (`budget_ns > 0`). Without a budget 0: the exact
    /// mesh queries traverse and test triangles in one pass, counted in `NARROW`.
    pub const MID: usize = 3;
    /// Narrow phase: every candidate pair's answer for the frame's query, BVH traversal
    /// (outside `MID`) and manifold reduction included.
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
    /// Number of candidate pairs the broad phase handed to the narrow phase (pairs whose
    /// margin-grown world boxes overlap), reported or not; with [`query::TOI`], those whose
    /// swept boxes overlap (a superset).
    pub candidate_count: u32,
    /// Number of time-of-impact records after the contacts.
    pub toi_count: u32,
    /// Time from the receipt of the pose frame to the publication of this one, nanoseconds.
    pub elapsed_ns: u64,
    /// Time per pipeline stage, nanoseconds, indexed by [`stage`].
    pub stage_ns: [u64; stage::COUNT],
    /// Bits of [`frame_flags`] (undefined bits 0; since protocol version 8).
    pub flags: u32,
    /// Candidate pairs the broad phase found beyond the daemon's per-frame limit or the
    /// frame's budget and did not answer (with [`frame_flags::PAIRS_CAPPED`]); 0 otherwise.
    pub dropped_candidates: u32,
    /// With [`frame_flags::BUDGET_TOO_SMALL`]: the smallest budget the daemon measured for
    /// this scene's frames, nanoseconds (its ingest plus the typical time of the stages no
    /// deadline can interrupt: the broad phase and publishing). 0 otherwise.
    pub min_budget_ns: u64,
    /// The daemon's instance id ([`ControlReply::instance`]); a frame from another instance
    /// is not an answer to this client (since protocol version 9).
    pub instance: u64,
}

/// Bits of [`ResultFrameHeader::flags`].
pub mod frame_flags {
    /// The broad phase found more candidate pairs than the daemon answers in one frame
    /// (its `max_pairs_per_frame` limit, or more than even their conservative answers fit
    /// in the frame's budget, measured on the scene; at least 256 are always answered):
    /// the frame answers the first of them and counts the rest in `dropped_candidates`.
    /// Its pairs are a sample, and a pair left out may touch.
    pub const PAIRS_CAPPED: u32 = 1 << 0;
    /// The frame's budget could not hold the work no deadline can interrupt, as measured on
    /// this scene: the daemon did not start it and answers nothing (`completeness`
    /// `Truncated`, no records), on time, with the budget it would need in
    /// `min_budget_ns`. The scene's state is unchanged but for the frame's poses.
    pub const BUDGET_TOO_SMALL: u32 = 1 << 1;
    /// The scene's owner is gone (its control client closed, or its process died): the
    /// daemon abandoned the frame's work at its next poll, so its answers are conservative
    /// (`Truncated`) even without a budget, and it releases the scene after its grace period
    /// (since protocol version 10).
    pub const OWNER_GONE: u32 = 1 << 2;
}

/// Bits of [`ResultRecord::flags`]; undefined bits are 0.
pub mod record_flags {
    /// The answer is conservative, not exact: the pair's traversal was cut short by the
    /// frame's deadline (or the pair got the box answer). `distance` is then a lower bound on
    /// the true distance, within `error_bound` of it, and the pair is reported because it
    /// *may* qualify (DESIGN §4). Set on a `Pair` record and on each of its `Contact`
    /// records, and (since protocol version 6) on a `Toi` record whose search the frame's
    /// deadline left no time for: `time` 0, `count` 0, `distance` the lower bound the two
    /// bodies' boxes at the start of the motion give, the pair reported because it may come
    /// within contact. (A search that stopped, at its limit or at the deadline, says so by
    /// `count` 0 with an exact record at `time`.) A frame whose header says `Truncated` has
    /// at least one approximate record or one `Toi` search stopped at the deadline; an
    /// `Exact` frame neither.
    pub const APPROXIMATE: u32 = 1 << 0;
}

/// What a [`ResultRecord`] describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum RecordKind {
    /// A close pair with its signed distance and witness points.
    Pair = 1,
    /// One point of a pair's contact manifold.
    Contact = 2,
    /// A pair's time of impact over the frame's motion (see [`query::TOI`]).
    Toi = 3,
}

/// A close pair or one contact point: both are a pair of points on the two bodies' surfaces,
/// a normal and a signed distance.
///
/// - `Pair`: `body_a < body_b`; `distance` is the signed distance (positive = separation,
///   negative = penetration depth), `point_a`/`point_b` its witnesses, `normal` the unit
///   normal from A to B (all zero when not computed, see [`query::OVERLAP`]);
///   `index`/`count` locate the pair's contacts among the contact records: `index` counts
///   from the first contact record (0 = the record right after the last pair), `count` is
///   at most [`MAX_CONTACTS_PER_PAIR`] (both 0 when none were asked or found).
/// - `Contact`: `body_a`/`body_b` its pair's bodies, `distance = −depth` (≤ 0),
///   `point_a`/`point_b` the contact points on each surface, `normal` from A to B (the same
///   for every contact of a pair), `index` the pair's position among the pair records,
///   `count` 0. See [`query::CONTACTS`] for what each pair kind gives.
/// - `Toi`: `body_a < body_b`; `time` the fraction of the frame's motion at first contact;
///   `distance`, `point_a`/`point_b`, `normal` (A→B) at the poses of `time`;
///   `error_bound` the search tolerance (at `time` the pair is within its margins plus
///   it); `index` 0; `count` 1, or 0 when the search stopped early; with
///   [`record_flags::APPROXIMATE`], not searched for lack of time (see [`query::TOI`]).
///
/// `time` is 0 in `Pair` and `Contact` records.
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
    /// [`record_flags`] bits (since protocol version 5).
    pub flags: u32,
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
    /// `Toi` records: fraction of the frame's motion, in `[0, 1]` (see the type docs).
    pub time: f64,
}

/// What a [`ControlRequest`] asks the daemon to do.
///
/// Not `#[non_exhaustive]`: the set is versioned with [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION),
/// so the daemon matches it exhaustively.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum Command {
    /// Check the protocol version; the reply's `id` is the daemon's version.
    Hello = 0,
    /// Create a scene owned by the requesting client port; the reply's `id` is the new scene
    /// id (random, never `u32::MAX`), with the scene's secret
    /// [`frame_key`](ControlReply::frame_key) and [`scene_token`](ControlReply::scene_token).
    CreateScene = 1,
    /// Drop scene `scene` with all its bodies.
    DropScene = 2,
    /// Register a shape (kind, dimensions, geometry payload) for use in scene `scene`; the
    /// reply's `id` is the shape id. A primitive is usable at once. A convex or mesh shape is
    /// decoded and built after the reply, apart from the frames: the reply comes once the
    /// header is checked (kind, counts against the limits, payload length; such errors
    /// change nothing), with [`reply_flags::SHAPE_BUILDING`] set; errors found in the
    /// geometry itself (an index out of range, empty or degenerate geometry) are the
    /// shape's, told by [`ShapeState`](Self::ShapeState). The builds of all clients queue;
    /// a full queue refuses the registration with [`ErrorCode::LimitExceeded`].
    RegisterShape = 3,
    /// Add a body of shape `target` to scene `scene` with the request's motion, group,
    /// mask, margin and pose; the reply's `id` is the body id. Refused with
    /// [`ErrorCode::ShapeNotReady`] while the shape is being built, with
    /// [`ErrorCode::UnknownShape`] when its build failed.
    AddBody = 4,
    /// Remove body `target` from scene `scene`. The next body added to the scene gets its
    /// id (since protocol version 9: a scene's tables stay as large as its most bodies
    /// alive at once); pose records still naming it then move the new body.
    RemoveBody = 5,
    /// Change body `target`'s motion, group, mask and margin.
    UpdateBody = 6,
    /// Set scene `scene`'s parameters: which broad phase its frames run
    /// ([`ControlRequest::broad_phase`], a [`BroadPhaseCode`]); from the next frame on.
    /// Results do not depend on it, only their cost. The reply's `id` is the scene id.
    SetSceneParams = 7,
    /// Ask whether shape `target` of scene `scene` is built; changes nothing. Success with
    /// `id` = `target`, and [`reply_flags::SHAPE_BUILDING`] set while it is being built,
    /// clear once bodies may use it. A build that failed is answered with its error code
    /// and reason (the same each time); an id never handed out with
    /// [`ErrorCode::UnknownShape`] (since protocol version 8).
    ShapeState = 8,
}

/// Shape kinds of [`ControlRequest::shape_kind`], with the meaning of `dimensions` (metres)
/// and of the geometry payload.
///
/// Versioned with the protocol like [`Command`], so matched exhaustively.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum ShapeKindCode {
    /// `dimensions = [radius, 0, 0, 0]`.
    Sphere = 0,
    /// Along local Z: `[radius, half_height, 0, 0]` (half the segment's length).
    Capsule = 1,
    /// `[half_x, half_y, half_z, 0]`.
    Cuboid = 2,
    /// Along local Z: `[radius, half_height, 0, 0]`.
    Cylinder = 3,
    /// Along local Z, apex at `+half_height`: `[radius, half_height, 0, 0]`.
    Cone = 4,
    /// The convex hull of `vertex_count` points in the payload.
    Convex = 5,
    /// A triangle mesh: `vertex_count` points, then `index_count` vertex indices (three per
    /// triangle) in the payload.
    Mesh = 6,
    /// A solid made of convex parts: `vertex_count` points, then `index_count` part sizes
    /// (points per part, each at least 1, summing to `vertex_count`; at most
    /// [`MAX_COMPOUND_PARTS`] parts) in the payload; each part is the convex hull of its
    /// points. Contacts report true penetration depth (since protocol version 11).
    Compound = 7,
    /// A closed triangle mesh (payload as [`Mesh`](Self::Mesh)) that the daemon decomposes
    /// into convex parts and answers as their [`Compound`](Self::Compound):
    /// `dimensions = [max_concavity, max_parts, method, 0]`, `max_concavity` relative to
    /// the mesh's bounding-box diagonal (0: 0.02), `max_parts` a whole number up to
    /// [`MAX_COMPOUND_PARTS`] (0: 64), `method` 0 for the concavity-driven cut search
    /// (quality first) or 1 for relaxation (faster). A mesh that encloses no volume is
    /// refused with `InvalidShape` (since protocol version 11).
    DecomposedMesh = 8,
}

/// The most parts a [`ShapeKindCode::Compound`] or [`ShapeKindCode::DecomposedMesh`] has.
pub const MAX_COMPOUND_PARTS: u32 = 1024;

impl Command {
    /// The command for a wire value, `None` for values this version does not define.
    #[must_use]
    pub const fn from_u32(value: u32) -> Option<Self> {
        Some(match value {
            0 => Self::Hello,
            1 => Self::CreateScene,
            2 => Self::DropScene,
            3 => Self::RegisterShape,
            4 => Self::AddBody,
            5 => Self::RemoveBody,
            6 => Self::UpdateBody,
            7 => Self::SetSceneParams,
            8 => Self::ShapeState,
            _ => return None,
        })
    }
}

impl ShapeKindCode {
    /// The shape kind for a wire value, `None` for values this version does not define.
    #[must_use]
    pub const fn from_u32(value: u32) -> Option<Self> {
        Some(match value {
            0 => Self::Sphere,
            1 => Self::Capsule,
            2 => Self::Cuboid,
            3 => Self::Cylinder,
            4 => Self::Cone,
            5 => Self::Convex,
            6 => Self::Mesh,
            7 => Self::Compound,
            8 => Self::DecomposedMesh,
            _ => return None,
        })
    }
}

/// Motion kinds of [`ControlRequest::motion`]: static bodies never pair with each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum MotionCode {
    /// Never moves after it is added.
    Static = 0,
    /// Moved by the client, not by physics.
    Kinematic = 1,
    /// Moved by the client's physics.
    Dynamic = 2,
}

impl MotionCode {
    /// The motion kind for a wire value, `None` for values this version does not define.
    #[must_use]
    pub const fn from_u32(value: u32) -> Option<Self> {
        Some(match value {
            0 => Self::Static,
            1 => Self::Kinematic,
            2 => Self::Dynamic,
            _ => return None,
        })
    }
}

/// Broad phases of [`ControlRequest::broad_phase`] ([`Command::SetSceneParams`]). Every one
/// reports the same candidate pairs; they differ in cost per scene class.
///
/// Versioned with the protocol like [`Command`], so matched exhaustively.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum BroadPhaseCode {
    /// The daemon chooses from the scene's measured statistics (body count, size spread,
    /// clustering, fraction moving), re-measured as the scene runs. The default.
    Auto = 0,
    /// One-axis sort and sweep over every body each frame.
    SortAndSweep = 1,
    /// Incremental three-axis sweep and prune: a body that did not move costs nothing.
    IncrementalSap = 2,
    /// Hierarchical hash grid: a body that did not move costs nothing.
    HashGrid = 3,
    /// Hierarchical grid of columns sorted along one axis: a body that did not move costs
    /// nothing (since protocol version 5).
    ColumnGrid = 4,
    /// The column grid over boxes grown by a skin, each body's neighbours listed: a body
    /// that moves within its skin re-tests only those (since protocol version 7).
    SkinGrid = 5,
}

impl BroadPhaseCode {
    /// The broad phase for a wire value, `None` for values this version does not define.
    #[must_use]
    pub const fn from_u32(value: u32) -> Option<Self> {
        Some(match value {
            0 => Self::Auto,
            1 => Self::SortAndSweep,
            2 => Self::IncrementalSap,
            3 => Self::HashGrid,
            4 => Self::ColumnGrid,
            5 => Self::SkinGrid,
            _ => return None,
        })
    }
}

/// A control request (the user header of a `[u8]` request on `<root>/control`).
///
/// The byte payload carries geometry for [`Command::RegisterShape`] of a convex or mesh
/// shape, in native byte order: `vertex_count × 3` `f64` coordinates (metres, the shape's
/// local frame), then `index_count` `u32` vertex indices; its length must be exactly
/// `24·vertex_count + 4·index_count` bytes. Other requests send an empty payload.
#[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("proxima::ControlRequest")]
pub struct ControlRequest {
    /// [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION) of the client.
    pub protocol_version: u32,
    /// [`Command`] as `u32`.
    pub command: u32,
    /// The scene the command acts on (ignored by `Hello`, `CreateScene`).
    pub scene: u32,
    /// The shape (`AddBody`, `ShapeState`) or body (`RemoveBody`, `UpdateBody`) the command
    /// acts on.
    pub target: u32,
    /// [`ShapeKindCode`] as `u32` (`RegisterShape`).
    pub shape_kind: u32,
    /// [`MotionCode`] as `u32` (`AddBody`, `UpdateBody`).
    pub motion: u32,
    /// Collision group bits: a pair is tested when each body's group meets the other's mask.
    pub group: u32,
    /// Collision mask bits (see `group`).
    pub mask: u32,
    /// Number of points in the geometry payload.
    pub vertex_count: u32,
    /// Number of `u32` indices in the geometry payload (a multiple of 3).
    pub index_count: u32,
    /// [`BroadPhaseCode`] as `u32` (`SetSceneParams`); an undefined value is refused with
    /// [`ErrorCode::MalformedMessage`] and changes nothing.
    pub broad_phase: u32,
    /// Always 0 (keeps `margin` 8-byte aligned without hidden padding).
    pub reserved: u32,
    /// Close-pair margin of the body, metres, `≥ 0`; negative = the scene's default.
    pub margin: f64,
    /// Primitive dimensions, metres (see [`ShapeKindCode`]).
    pub dimensions: [f64; 4],
    /// Initial position, metres, world frame (`AddBody`).
    pub position: [f64; 3],
    /// Initial orientation, unit quaternion `[x, y, z, w]` (`AddBody`).
    pub orientation: [f64; 4],
}

/// Bits of [`ControlReply::flags`]; undefined bits are 0.
pub mod reply_flags {
    /// `RegisterShape` and `ShapeState` of a convex or mesh shape: the shape (the reply's
    /// `id`) is still being built; bodies may not use it yet. Ask again with
    /// [`Command::ShapeState`](super::Command::ShapeState) (since protocol version 8).
    pub const SHAPE_BUILDING: u32 = 1 << 0;
}

/// Bytes of [`ControlReply::reason`].
pub const REASON_BYTES: usize = 112;

/// The daemon's answer to one [`ControlRequest`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, ZeroCopySend)]
#[repr(C)]
#[type_name("proxima::ControlReply")]
pub struct ControlReply {
    /// [`PROTOCOL_VERSION`](crate::PROTOCOL_VERSION) of the daemon.
    pub protocol_version: u32,
    /// [`ErrorCode`] as `u32`.
    pub status: u32,
    /// The new scene, shape or body id (see [`Command`]); `u32::MAX` on error.
    pub id: u32,
    /// [`reply_flags`] bits; 0 on error (since protocol version 8; before, reserved and 0).
    pub flags: u32,
    /// The daemon's instance id: random, never 0, the same in every reply and result
    /// header of one daemon run and different after a restart (since protocol version 9).
    pub instance: u64,
    /// `CreateScene`: the scene's frame key, for [`PoseFrameHeader::frame_key`]; 0 otherwise.
    /// Secret: whoever knows it may send the scene frames.
    pub frame_key: u64,
    /// `CreateScene`: the scene's token, which names its services
    /// ([`scene_services_name`](crate::scene_services_name)); all zero otherwise. It is the
    /// capability to read the scene's results: share it only with a monitor that may.
    pub scene_token: [u64; 2],
    /// Why the request failed: UTF-8, padded with zero bytes (empty on success).
    pub reason: [u8; REASON_BYTES],
}

impl ControlReply {
    /// A success reply carrying `id`.
    #[must_use]
    pub fn ok(id: u32) -> Self {
        Self {
            protocol_version: crate::PROTOCOL_VERSION,
            status: ErrorCode::Ok as u32,
            id,
            flags: 0,
            instance: 0,
            frame_key: 0,
            scene_token: [0; 2],
            reason: [0; REASON_BYTES],
        }
    }

    /// A success reply carrying `id` and the [`reply_flags`] bits `flags`.
    #[must_use]
    pub fn ok_with(id: u32, flags: u32) -> Self {
        Self {
            flags,
            ..Self::ok(id)
        }
    }

    /// A failure reply; `reason` is cut at a character boundary to fit.
    #[must_use]
    pub fn error(code: ErrorCode, reason: &str) -> Self {
        let mut bytes = [0; REASON_BYTES];
        let mut end = reason.len().min(REASON_BYTES);
        while !reason.is_char_boundary(end) {
            end -= 1;
        }
        bytes[..end].copy_from_slice(&reason.as_bytes()[..end]);
        Self {
            status: code as u32,
            id: u32::MAX,
            reason: bytes,
            ..Self::ok(0)
        }
    }

    /// The reason text (up to the first zero byte; invalid UTF-8 is replaced).
    #[must_use]
    pub fn reason(&self) -> String {
        let end = self
            .reason
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(REASON_BYTES);
        String::from_utf8_lossy(&self.reason[..end]).into_owned()
    }
}

const _: () = assert!(size_of::<ControlRequest>() == 144);
const _: () = assert!(size_of::<ControlReply>() == 160);
const _: () = assert!(size_of::<PoseFrameHeader>() == 40);
const _: () = assert!(size_of::<PoseRecord>() == 64);
const _: () = assert!(size_of::<ResultFrameHeader>() == 128);
const _: () = assert!(size_of::<ResultRecord>() == 120);
