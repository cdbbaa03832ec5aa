"""Python client of ``proximad``, Proxima's collision daemon, over iceoryx2 shared memory.

Pure Python over the ``iceoryx2`` 0.10.0 bindings and numpy; it mirrors the Rust client
(``ipc/src``) module for module:

- :mod:`~proxima_client.wire`: the ``#[repr(C)]`` records as ctypes structures and numpy
  dtypes with pinned offsets, the codes and bit sets, :data:`PROTOCOL_VERSION`;
- :mod:`~proxima_client.services`: service names (by :class:`SceneToken`), settings and
  builders;
- :mod:`~proxima_client.client`: :class:`Client` (connect, scenes, shapes, bodies);
- :mod:`~proxima_client.scene_link`: :class:`SceneLink`, pose frames out from numpy arrays,
  with the :class:`SceneAccess` the scene's owner holds;
- :mod:`~proxima_client.result_feed`: result frames in as numpy views
  (:class:`ResultFrame`) or copies (:class:`OwnedResultFrame`);
- :mod:`~proxima_client.errors`: typed exceptions carrying the daemon's :class:`ErrorCode`;
- :mod:`~proxima_client.transport`: how waits spin and sleep.

:mod:`~proxima_client.daemon_process` is not part of the protocol: it starts an isolated
``proximad`` for tests and examples.
"""

from .client import (
    BodySpec,
    Capsule,
    Client,
    Cone,
    Cuboid,
    Cylinder,
    Motion,
    Primitive,
    Registration,
    ShapeState,
    Sphere,
)
from .errors import (
    BuildTimeout,
    DaemonError,
    DaemonLost,
    EmptyGeometryError,
    InternalError,
    InvalidPoseError,
    InvalidShapeError,
    LimitExceededError,
    MalformedMessageError,
    MeshIndexOutOfRangeError,
    NoDaemon,
    NoSuchScene,
    NotOwned,
    NotOwnerError,
    ProtocolMismatchError,
    ProximaError,
    ReplyTimeout,
    SceneQuarantinedError,
    SceneReleasedError,
    ShapeNotReadyError,
    TransportError,
    UnexpectedDaemon,
    UnknownBodyError,
    UnknownSceneError,
    UnknownShapeError,
    UnknownStatusError,
    error_class,
    error_for,
)
from .result_feed import OwnedResultFrame, ResultFeed, ResultFrame
from .scene_link import PoseFrame, SceneAccess, SceneLink, pose_array
from .services import DEFAULT_ROOT, SceneToken
from .wire import (
    POSE_DTYPE,
    PROTOCOL_VERSION,
    RESULT_DTYPE,
    BroadPhaseCode,
    Command,
    Completeness,
    ControlReply,
    ControlRequest,
    ErrorCode,
    MotionCode,
    PoseFrameHeader,
    PoseRecord,
    RecordKind,
    ResultFrameHeader,
    ResultRecord,
    ShapeKindCode,
    frame_flags,
    query,
    record_flags,
    reply_flags,
    stage,
)

__version__ = "0.1.0"

__all__ = [name for name in dir() if not name.startswith("_")]
