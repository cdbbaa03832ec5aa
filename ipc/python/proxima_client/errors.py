"""Errors of the Python client, mirroring ``ipc/src/error.rs``.

Everything raised derives from :class:`ProximaError`:

- :class:`DaemonError` and one subclass per :class:`~proxima_client.wire.ErrorCode`: the
  daemon refused a control request (or a pose frame, see
  :meth:`~proxima_client.result_feed.ResultFrame.raise_for_status`). Each carries
  ``.code``, the daemon's ``.reason`` text and, for frames, the offending ``.body``.
  Catch ``UnknownSceneError`` for one code, ``DaemonError`` for all of them.
- :class:`ReplyTimeout`, :class:`BuildTimeout`: nothing came back in time (both are also
  :class:`TimeoutError`).
- :class:`DaemonLost`: the daemon this client said ``Hello`` to is gone (crashed, or a
  restart now serves the root), told by a control reply or a result frame; connect again
  and register everything anew.
- :class:`NoDaemon`: connecting found no daemon answering in time;
  :class:`UnexpectedDaemon`: another daemon than the one expected answered.
- :class:`NotOwned`: this client did not create the scene it asked to open;
  :class:`NoSuchScene`: no daemon serves a scene with the token given.
- :class:`TransportError`: iceoryx2 failed (opening services, loaning, sending); carries the
  binding's error text.
"""

from __future__ import annotations

from typing import Optional

from .wire import ErrorCode


class ProximaError(Exception):
    """The base of every error this package raises."""


class TransportError(ProximaError):
    """iceoryx2 failed: ``what`` was being done, ``cause`` is the binding's exception."""

    def __init__(self, what: str, cause: Optional[BaseException] = None) -> None:
        """Keeps the failure's details and composes the message."""
        self.what = what
        self.cause = cause
        text = what if cause is None else f"{what}: {type(cause).__name__}: {cause}"
        super().__init__(text)


class NoDaemon(ProximaError):
    """No daemon served the control service, or none answered ``Hello`` in time."""


class DaemonLost(ProximaError):
    """The daemon this client connected to is gone; its scenes, shapes and bodies too.

    Raised for a control reply of another daemon (another server port or instance id), a
    result frame of another daemon instance, or a wait that ended while no live daemon
    serves (the control service, or the scene's results)."""


class UnexpectedDaemon(ProximaError):
    """The daemon that answered ``Hello`` is not the one expected
    (``Client.connect(expect_instance=...)``): another process serves the control service.

    Attributes:
        instance: the instance id the answering daemon gave.
    """

    def __init__(self, instance: int) -> None:
        """Keeps the instance id and composes the message."""
        self.instance = instance
        super().__init__(f"the process serving the control service (instance {instance:#018x}) "
                         "is not the daemon expected")


class NotOwned(ProximaError):
    """This client did not create the scene (or dropped it), so it holds no keys to it; a
    monitor opens a scene's results with the token its owner shares
    (``Client.open_result_feed``).

    Attributes:
        scene: the scene id.
    """

    def __init__(self, scene: int) -> None:
        """Keeps the scene id and composes the message."""
        self.scene = scene
        super().__init__(f"scene {scene} was not created by this client, which holds no keys to it")


class NoSuchScene(ProximaError):
    """No daemon serves a scene with this token (it was dropped, or never created)."""


class ReplyTimeout(ProximaError, TimeoutError):
    """No reply arrived within the reply timeout, though a daemon still serves."""


class BuildTimeout(ProximaError, TimeoutError):
    """A convex or mesh shape was still being built at the build timeout."""

    def __init__(self, shape: int) -> None:
        """Keeps the failure's details and composes the message."""
        self.shape = shape
        super().__init__(f"shape {shape} is still being built")


class DaemonError(ProximaError):
    """The daemon refused a request or a frame with a non-zero :class:`ErrorCode`.

    Attributes:
        code: the daemon's code (an :class:`ErrorCode`, or the raw int when this protocol
            version does not define it, see :class:`UnknownStatusError`).
        reason: the daemon's reason text ("" for frames: their header carries none).
        body: the body a frame was refused for, or ``None``.
    """

    #: The code this class stands for (``None`` on the base class).
    CODE: Optional[ErrorCode] = None

    def __init__(self, code: "ErrorCode | int", reason: str = "", body: Optional[int] = None) -> None:
        """Keeps the failure's details and composes the message."""
        self.code = code
        self.reason = reason
        self.body = body
        name = code.name if isinstance(code, ErrorCode) else f"status {code}"
        text = f"{name}: {reason}" if reason else name
        if body is not None:
            text += f" (body {body})"
        super().__init__(text)


class ProtocolMismatchError(DaemonError):
    """The sender speaks another protocol version."""

    CODE = ErrorCode.PROTOCOL_MISMATCH


class UnknownSceneError(DaemonError):
    """No scene with this id."""

    CODE = ErrorCode.UNKNOWN_SCENE


class UnknownBodyError(DaemonError):
    """No body with this id in the scene."""

    CODE = ErrorCode.UNKNOWN_BODY


class UnknownShapeError(DaemonError):
    """No shape with this id (or its build failed)."""

    CODE = ErrorCode.UNKNOWN_SHAPE


class InvalidPoseError(DaemonError):
    """A pose is NaN, infinite, out of range, or its quaternion is not unit length."""

    CODE = ErrorCode.INVALID_POSE


class InvalidShapeError(DaemonError):
    """A shape's dimensions or geometry are invalid."""

    CODE = ErrorCode.INVALID_SHAPE


class MeshIndexOutOfRangeError(DaemonError):
    """A mesh index points past the vertex list."""

    CODE = ErrorCode.MESH_INDEX_OUT_OF_RANGE


class EmptyGeometryError(DaemonError):
    """A mesh or point cloud has no triangles or points."""

    CODE = ErrorCode.EMPTY_GEOMETRY


class LimitExceededError(DaemonError):
    """Geometry, bodies, scenes or queued builds beyond the daemon's limits."""

    CODE = ErrorCode.LIMIT_EXCEEDED


class MalformedMessageError(DaemonError):
    """Counts disagree with the payload, or a field has an undefined value."""

    CODE = ErrorCode.MALFORMED_MESSAGE


class InternalError(DaemonError):
    """The daemon failed internally; the request may be retried."""

    CODE = ErrorCode.INTERNAL


class ShapeNotReadyError(DaemonError):
    """``AddBody`` named a shape still being built; wait for it, then ask again."""

    CODE = ErrorCode.SHAPE_NOT_READY


class NotOwnerError(DaemonError):
    """The scene belongs to another client port: only the one that created it may change it,
    drop it, ask about it or send it frames."""

    CODE = ErrorCode.NOT_OWNER


class SceneQuarantinedError(DaemonError):
    """The daemon stopped serving the scene after a fault on its shared-memory services (the
    reason says which); only dropping it is accepted."""

    CODE = ErrorCode.SCENE_QUARANTINED


class SceneReleasedError(DaemonError):
    """The scene's last result frame: the daemon let go of it (its owner dropped it, or its
    owner was gone for the daemon's grace period, ``owner_gone``). Raised by result
    receives; a monitor learns from it that the scene is over."""

    CODE = ErrorCode.SCENE_RELEASED

    @property
    def owner_gone(self) -> bool:
        """Whether the owner's absence was why."""
        return self.reason == OWNER_GONE_REASON


#: The reason of a :class:`SceneReleasedError` whose frame says ``OWNER_GONE``.
OWNER_GONE_REASON = "its owner is gone"


class UnknownStatusError(DaemonError):
    """The status is a value this protocol version does not define."""


_BY_CODE: dict[ErrorCode, type[DaemonError]] = {
    cls.CODE: cls
    for cls in (
        ProtocolMismatchError,
        UnknownSceneError,
        UnknownBodyError,
        UnknownShapeError,
        InvalidPoseError,
        InvalidShapeError,
        MeshIndexOutOfRangeError,
        EmptyGeometryError,
        LimitExceededError,
        MalformedMessageError,
        InternalError,
        ShapeNotReadyError,
        NotOwnerError,
        SceneQuarantinedError,
        SceneReleasedError,
    )
    if cls.CODE is not None
}


def error_for(status: int, reason: str = "", body: Optional[int] = None) -> DaemonError:
    """The exception for a non-zero daemon status.

    Raises:
        ValueError: ``status`` is 0 (success is no error).
    """
    if status == ErrorCode.OK:
        raise ValueError("status 0 is success, not an error")
    try:
        code = ErrorCode(status)
    except ValueError:
        return UnknownStatusError(status, reason, body)
    return _BY_CODE[code](code, reason, body)


def error_class(code: ErrorCode) -> type[DaemonError]:
    """The exception class raised for ``code`` (not ``OK``)."""
    return _BY_CODE[code]
