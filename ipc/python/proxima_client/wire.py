"""Wire records: every ``#[repr(C)]`` type of ``ipc/src/wire.rs`` that crosses shared memory.

Each record exists twice, with one layout: a :mod:`ctypes` structure (what the iceoryx2
bindings need to open a service: type name, size, alignment) and a numpy structured dtype
with pinned offsets (what frames are read and written with, without a per-record Python
loop). Both are checked against each other and against the Rust sizes when this module is
imported, so a drifted layout fails at once instead of corrupting frames.

Units are SI (metres; times in integer nanoseconds, named ``_ns``); positions and
orientations are in the world frame of the scene; quaternions are ``[x, y, z, w]``.
Changing any layout or meaning requires bumping :data:`PROTOCOL_VERSION`, on both sides.

=====================================================  =====================  =================
service                                                payload                user header
=====================================================  =====================  =================
``<root>/scene-<token>/poses`` (publish–subscribe)     ``[PoseRecord]``       PoseFrameHeader
``<root>/scene-<token>/results`` (publish–subscribe)   ``[ResultRecord]``     ResultFrameHeader
``<root>/control`` (request–response)                  request ``[u8]``,      request:
                                                       response ControlReply  ControlRequest
=====================================================  =====================  =================

A scene belongs to the client port that created it: its ``CreateScene`` reply carries the
scene's ``frame_key`` (every pose frame carries it) and ``scene_token`` (names its
services); every reply and result header carries the daemon's ``instance`` id.
"""

from __future__ import annotations

import ctypes
import enum
import struct
from typing import Any

import numpy as np

#: The protocol version; a client and a daemon whose versions differ refuse to talk.
PROTOCOL_VERSION: int = 11

#: Most contact records per pair (one manifold).
MAX_CONTACTS_PER_PAIR: int = 4

#: Bytes of :attr:`ControlReply.reason`.
REASON_BYTES: int = 112

#: Most parts of a ``COMPOUND`` or ``DECOMPOSED_MESH`` shape.
MAX_COMPOUND_PARTS: int = 1024

#: ``u32::MAX``: the ``id`` of a failure reply, the ``error_body`` of a frame without one.
U32_MAX: int = 0xFFFF_FFFF


class query:  # noqa: N801 (mirrors the Rust module `wire::query`)
    """Bits of :attr:`PoseFrameHeader.query_flags`: what a frame asks for.

    A frame with no flag (``0``) is refused with :attr:`ErrorCode.MALFORMED_MESSAGE`;
    undefined bits are refused too. See ``ipc/src/wire.rs`` for each flag's contract.
    """

    #: Pairs whose shapes touch or intersect (distance ≤ 0).
    OVERLAP: int = 1 << 0
    #: Pairs within the sum of their margins, with signed distance, witnesses, normal A→B.
    CLOSE: int = 1 << 1
    #: The exact signed distance of every candidate pair.
    DISTANCE: int = 1 << 2
    #: A contact manifold (≤ :data:`MAX_CONTACTS_PER_PAIR` points) per touching pair.
    CONTACTS: int = 1 << 3
    #: Time of impact over the motion since the previous frame.
    TOI: int = 1 << 4
    #: Every flag this protocol version defines.
    ALL: int = OVERLAP | CLOSE | DISTANCE | CONTACTS | TOI


class frame_flags:  # noqa: N801 (mirrors `wire::frame_flags`)
    """Bits of :attr:`ResultFrameHeader.flags`."""

    #: More candidate pairs than the daemon answers in one frame; ``dropped_candidates``
    #: counts the rest.
    PAIRS_CAPPED: int = 1 << 0
    #: The budget could not hold the uninterruptible work; nothing was answered and
    #: ``min_budget_ns`` says what budget the frame would need.
    BUDGET_TOO_SMALL: int = 1 << 1
    #: The scene's owner is gone: the frame's work was abandoned (conservative,
    #: ``Truncated`` answers), and the scene is released after the daemon's grace period.
    OWNER_GONE: int = 1 << 2


class record_flags:  # noqa: N801 (mirrors `wire::record_flags`)
    """Bits of :attr:`ResultRecord.flags`."""

    #: A conservative answer: ``distance`` is a lower bound within ``error_bound``.
    APPROXIMATE: int = 1 << 0


class reply_flags:  # noqa: N801 (mirrors `wire::reply_flags`)
    """Bits of :attr:`ControlReply.flags`."""

    #: The shape (the reply's ``id``) is still being built; bodies may not use it yet.
    SHAPE_BUILDING: int = 1 << 0


class stage:  # noqa: N801 (mirrors `wire::stage`)
    """Indices of :attr:`ResultFrameHeader.stage_ns`, in pipeline order."""

    INGEST: int = 0
    PLAN: int = 1
    BROAD: int = 2
    MID: int = 3
    NARROW: int = 4
    PUBLISH: int = 5
    #: Number of stages.
    COUNT: int = 6


class ErrorCode(enum.IntEnum):
    """Outcome of a whole frame or of a control request; ``0`` is success."""

    OK = 0
    PROTOCOL_MISMATCH = 1
    UNKNOWN_SCENE = 2
    UNKNOWN_BODY = 3
    UNKNOWN_SHAPE = 4
    INVALID_POSE = 5
    INVALID_SHAPE = 6
    MESH_INDEX_OUT_OF_RANGE = 7
    EMPTY_GEOMETRY = 8
    LIMIT_EXCEEDED = 9
    MALFORMED_MESSAGE = 10
    INTERNAL = 11
    SHAPE_NOT_READY = 12
    #: The scene belongs to another client port (only its creator may use it).
    NOT_OWNER = 13
    #: The daemon stopped serving the scene after a shared-memory fault; only
    #: ``DropScene`` is accepted.
    SCENE_QUARANTINED = 14
    #: In a result frame only: the daemon let go of the scene; its last frame.
    SCENE_RELEASED = 15


class Command(enum.IntEnum):
    """What a :class:`ControlRequest` asks the daemon to do."""

    HELLO = 0
    CREATE_SCENE = 1
    DROP_SCENE = 2
    REGISTER_SHAPE = 3
    ADD_BODY = 4
    REMOVE_BODY = 5
    UPDATE_BODY = 6
    SET_SCENE_PARAMS = 7
    SHAPE_STATE = 8


class ShapeKindCode(enum.IntEnum):
    """Shape kinds of :attr:`ControlRequest.shape_kind` (dimensions in metres)."""

    #: ``[radius, 0, 0, 0]``.
    SPHERE = 0
    #: Along local Z: ``[radius, half_height, 0, 0]``.
    CAPSULE = 1
    #: ``[half_x, half_y, half_z, 0]``.
    CUBOID = 2
    #: Along local Z: ``[radius, half_height, 0, 0]``.
    CYLINDER = 3
    #: Along local Z, apex at ``+half_height``: ``[radius, half_height, 0, 0]``.
    CONE = 4
    #: The convex hull of ``vertex_count`` points in the payload.
    CONVEX = 5
    #: ``vertex_count`` points, then ``index_count`` u32 indices, in the payload.
    MESH = 6
    #: ``vertex_count`` points, then ``index_count`` u32 part sizes; each part is the
    #: convex hull of its points.
    COMPOUND = 7
    #: A closed mesh (payload as ``MESH``) the daemon decomposes into a compound:
    #: ``[max_concavity, max_parts, method, 0]`` (0 = defaults 0.02 and 64; method 0 cut
    #: search, 1 relaxation).
    DECOMPOSED_MESH = 8


class MotionCode(enum.IntEnum):
    """Motion kinds of :attr:`ControlRequest.motion`; static bodies never pair together."""

    STATIC = 0
    KINEMATIC = 1
    DYNAMIC = 2


class BroadPhaseCode(enum.IntEnum):
    """Broad phases of :attr:`ControlRequest.broad_phase`; results never depend on it."""

    AUTO = 0
    SORT_AND_SWEEP = 1
    INCREMENTAL_SAP = 2
    HASH_GRID = 3
    COLUMN_GRID = 4
    SKIN_GRID = 5


class Completeness(enum.IntEnum):
    """Whether a frame's answer is exact or was cut short by its deadline."""

    EXACT = 0
    TRUNCATED = 1


class RecordKind(enum.IntEnum):
    """What a :class:`ResultRecord` describes."""

    PAIR = 1
    CONTACT = 2
    TOI = 3


# ---------------------------------------------------------------------------------------
# ctypes structures. `type_name` is what iceoryx2 matches services by (with size and
# alignment); it must equal the Rust `#[type_name(...)]`.

_u32 = ctypes.c_uint32
_u64 = ctypes.c_uint64
_f64 = ctypes.c_double


class _Record(ctypes.Structure):
    """A wire record: a ctypes structure with the iceoryx2 type name of its Rust twin."""

    _TYPE_NAME: str = ""

    @classmethod
    def type_name(cls) -> str:
        """The iceoryx2 type name (the Rust ``#[type_name]``)."""
        return cls._TYPE_NAME

    def to_dict(self) -> dict[str, Any]:
        """The fields as plain Python values (arrays as lists)."""
        out: dict[str, Any] = {}
        for field in self._fields_:
            name = field[0]
            value = getattr(self, name)
            out[name] = list(value) if isinstance(value, ctypes.Array) else value
        return out


class PoseFrameHeader(_Record):
    """The user header of one pose frame (a ``[PoseRecord]`` sample), 40 bytes.

    ``frame_key`` is the scene's, from its ``CreateScene`` reply: a frame with another key
    is not answered."""

    _TYPE_NAME = "proxima::PoseFrameHeader"
    _fields_ = [
        ("protocol_version", _u32),
        ("scene", _u32),
        ("frame_seq", _u64),
        ("budget_ns", _u64),
        ("query_flags", _u32),
        ("count", _u32),
        ("frame_key", _u64),
    ]


#: :class:`PoseFrameHeader`'s fields in order, as one ``struct`` layout: a frame's header is
#: written into the loaned sample with one ``pack_into`` (a third of the cost of filling a
#: ctypes header and copying it).
POSE_FRAME_HEADER_LAYOUT = struct.Struct("<IIQQIIQ")


class PoseRecord(_Record):
    """The new pose of one body, 64 bytes; bodies not listed keep their last pose."""

    _TYPE_NAME = "proxima::PoseRecord"
    _fields_ = [
        ("body", _u32),
        ("reserved", _u32),
        ("position", _f64 * 3),
        ("orientation", _f64 * 4),
    ]


class ResultFrameHeader(_Record):
    """The user header of one result frame (a ``[ResultRecord]`` sample), 128 bytes;
    ``instance`` is the daemon's instance id, as in its control replies."""

    _TYPE_NAME = "proxima::ResultFrameHeader"
    _fields_ = [
        ("protocol_version", _u32),
        ("status", _u32),
        ("frame_seq", _u64),
        ("error_body", _u32),
        ("completeness", _u32),
        ("deepest_level", _u32),
        ("budget_met", _u32),
        ("pair_count", _u32),
        ("contact_count", _u32),
        ("candidate_count", _u32),
        ("toi_count", _u32),
        ("elapsed_ns", _u64),
        ("stage_ns", _u64 * stage.COUNT),
        ("flags", _u32),
        ("dropped_candidates", _u32),
        ("min_budget_ns", _u64),
        ("instance", _u64),
    ]


class ResultRecord(_Record):
    """A close pair, one contact point or a time of impact, 120 bytes."""

    _TYPE_NAME = "proxima::ResultRecord"
    _fields_ = [
        ("kind", _u32),
        ("body_a", _u32),
        ("body_b", _u32),
        ("index", _u32),
        ("count", _u32),
        ("flags", _u32),
        ("distance", _f64),
        ("error_bound", _f64),
        ("point_a", _f64 * 3),
        ("point_b", _f64 * 3),
        ("normal", _f64 * 3),
        ("time", _f64),
    ]


class ControlRequest(_Record):
    """A control request (the user header of a ``[u8]`` request), 144 bytes.

    The byte payload carries geometry for ``RegisterShape`` of a convex or mesh shape:
    ``vertex_count × 3`` f64 coordinates, then ``index_count`` u32 indices, native order.
    """

    _TYPE_NAME = "proxima::ControlRequest"
    _fields_ = [
        ("protocol_version", _u32),
        ("command", _u32),
        ("scene", _u32),
        ("target", _u32),
        ("shape_kind", _u32),
        ("motion", _u32),
        ("group", _u32),
        ("mask", _u32),
        ("vertex_count", _u32),
        ("index_count", _u32),
        ("broad_phase", _u32),
        ("reserved", _u32),
        ("margin", _f64),
        ("dimensions", _f64 * 4),
        ("position", _f64 * 3),
        ("orientation", _f64 * 4),
    ]


class ControlReply(_Record):
    """The daemon's answer to one :class:`ControlRequest`, 160 bytes.

    ``instance`` is the daemon's instance id (random per start, never 0, in every reply);
    a ``CreateScene`` reply also carries the new scene's secret ``frame_key`` and its
    ``scene_token`` (two u64 words that name its services), both zero otherwise.
    """

    _TYPE_NAME = "proxima::ControlReply"
    _fields_ = [
        ("protocol_version", _u32),
        ("status", _u32),
        ("id", _u32),
        ("flags", _u32),
        ("instance", _u64),
        ("frame_key", _u64),
        ("scene_token", _u64 * 2),
        ("reason", ctypes.c_uint8 * REASON_BYTES),
    ]

    def reason_text(self) -> str:
        """The reason, up to the first zero byte (invalid UTF-8 replaced)."""
        raw = bytes(self.reason)
        end = raw.find(b"\0")
        return raw[: end if end >= 0 else len(raw)].decode("utf-8", errors="replace")


# ---------------------------------------------------------------------------------------
# numpy dtypes: frames are read and written through these. Each is made from its ctypes
# structure, so the two cannot disagree on a field or an offset.

#: One :class:`PoseRecord`: ``body`` u32, ``reserved`` u32 (always 0), ``position``
#: f64[3], ``orientation`` f64[4].
POSE_DTYPE: np.dtype = np.dtype(PoseRecord)
#: One :class:`ResultRecord`.
RESULT_DTYPE: np.dtype = np.dtype(ResultRecord)
#: One :class:`PoseFrameHeader`.
POSE_FRAME_HEADER_DTYPE: np.dtype = np.dtype(PoseFrameHeader)
#: One :class:`ResultFrameHeader`.
RESULT_FRAME_HEADER_DTYPE: np.dtype = np.dtype(ResultFrameHeader)


def _check_layouts() -> None:
    """Every ctypes structure has its Rust record's size and alignment."""
    expected = {
        PoseFrameHeader: (40, 8),
        PoseRecord: (64, 8),
        ResultFrameHeader: (128, 8),
        ResultRecord: (120, 8),
        ControlRequest: (144, 8),
        ControlReply: (160, 8),
    }
    for record, (size, align) in expected.items():
        if ctypes.sizeof(record) != size or ctypes.alignment(record) != align:
            raise ImportError(f"{record.__name__}: layout differs from the Rust record")
    values = (1, 2, 3 << 40, 4 << 40, 5, 6, 7 << 40)
    names = [name for name, _ in PoseFrameHeader._fields_]
    if POSE_FRAME_HEADER_LAYOUT.pack(*values) != bytes(PoseFrameHeader(**dict(zip(names, values)))):
        raise ImportError("POSE_FRAME_HEADER_LAYOUT differs from PoseFrameHeader")


_check_layouts()
