"""The frame half of the client, mirroring ``ipc/src/scene_link.rs``: a :class:`SceneLink`
publishes a scene's pose frames, written straight into a loaned shared-memory sample from
numpy arrays (one numpy copy per field, no per-body Python loop), and receives its result
frames as numpy views (:class:`~proxima_client.result_feed.ResultFrame`).

.. code-block:: python

    link = client.open_scene(scene)
    link.publish(1, 0, query.CLOSE, ids, positions, orientations)
    with link.receive_results_for(1, timeout=0.01) as frame:
        for pair in frame.pairs:
            print(pair["body_a"], pair["body_b"], pair["distance"])

After each pose frame the link notifies the scene's poses-ready service (event id 1), so
a daemon asleep in its WaitSet wakes. The daemon creates a scene's services and ports
before it answers ``CreateScene``, so a link opened after that reply loses no frame. Only
the scene's owner holds its :class:`SceneAccess` (the
:class:`~proxima_client.client.Client` that created it keeps it): every frame carries the
scene's frame key, and a frame with another key is not answered.
"""

from __future__ import annotations

import ctypes
import struct
import warnings
from dataclasses import dataclass, field
from typing import Any, Optional

import iceoryx2 as iox
import numpy as np

from . import services
from .errors import TransportError
from .result_feed import OwnedResultFrame, ResultFeed, ResultFrame, open_scene_service
from .services import SceneToken
from .transport import assume_init, loan_slice_uninit, release_ports
from .wire import POSE_DTYPE, POSE_FRAME_HEADER_LAYOUT, PROTOCOL_VERSION, U32_MAX, PoseFrameHeader

#: Pose records the publisher's first shared-memory segment holds; a larger frame makes it
#: allocate a segment of the next power of two (a one-off cost, for the daemon too).
POSES_INITIAL_MAX_SLICE_LEN: int = 1024



@dataclass(frozen=True)
class SceneAccess:
    """What the owner of a scene holds, from the scene's ``CreateScene`` reply: everything
    a :class:`SceneLink` needs. ``repr()`` shows only the id (the rest is secret).

    Attributes:
        scene: the scene's id, for control requests and pose frame headers.
        token: the token that names its services; also the capability to read its results
            (:class:`~proxima_client.result_feed.ResultFeed`), which the owner may share
            with a monitor.
        frame_key: the secret every pose frame carries.
        instance: the daemon instance that created the scene; result frames of another
            raise :class:`~proxima_client.errors.DaemonLost`.
    """

    scene: int
    token: SceneToken = field(repr=False)
    frame_key: int = field(repr=False)
    instance: int = field(repr=False)


_POSE_BYTES = POSE_DTYPE.itemsize
_HEADER_BYTES = ctypes.sizeof(PoseFrameHeader)
#: The bytes of a loaned sample's header, to pack it in place.
_HEADER_BUFFER = ctypes.c_char * _HEADER_BYTES
_IDENTITY = np.array([0.0, 0.0, 0.0, 1.0])


def _data_pointer_is_fixed() -> bool:
    """Whether this numpy refuses to re-point an array (assigning ``ndarray.data``, which
    older releases allow with a deprecation warning): then an array's data address stays
    what it was while it is referenced (``resize`` refuses a referenced array)."""
    probe = np.zeros(1)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            probe.data = np.ones(1).data  # type: ignore[misc]
    except (AttributeError, TypeError):
        return True
    return False


#: See :func:`_data_pointer_is_fixed`.
_DATA_FIXED = _data_pointer_is_fixed()


def poses_view(address: int, count: int) -> np.ndarray:
    """A writeable numpy array of ``count`` :data:`POSE_DTYPE` records at ``address``."""
    if count == 0:
        return np.empty(0, dtype=POSE_DTYPE)
    buffer = (ctypes.c_char * (count * _POSE_BYTES)).from_address(address)
    return np.frombuffer(buffer, POSE_DTYPE)  # type: ignore[call-overload]  # ctypes arrays are buffers


def pose_array(ids: Any, positions: Any, orientations: Any = None) -> np.ndarray:
    """A :data:`POSE_DTYPE` array from ``ids`` (``(n,)``), ``positions`` (``(n, 3)``) and
    ``orientations`` (``(n, 4)``, ``[x, y, z, w]``; ``None``: identity). Handy to build a
    frame once and publish it with :meth:`SceneLink.publish_poses`."""
    ids, positions, orientations = _check_fields(ids, positions, orientations)
    out = np.zeros(len(ids), dtype=POSE_DTYPE)
    _write_fields(out, ids, positions, orientations)
    return out


def _check_fields(ids: Any, positions: Any, orientations: Any) -> tuple[np.ndarray, np.ndarray, Optional[np.ndarray]]:
    """The pose arrays as numpy arrays of the right shapes.

    Raises:
        ValueError: shapes that do not fit ``(n,)``, ``(n, 3)``, ``(n, 4)``, or non-integer ids.
    """
    ids = np.asarray(ids)
    positions = np.asarray(positions, dtype=np.float64)
    n = ids.shape[0] if ids.ndim == 1 else -1
    if n < 0 or positions.shape != (n, 3):
        raise ValueError(f"ids must be (n,) and positions (n, 3); got {ids.shape} and {positions.shape}")
    if ids.dtype.kind not in "ui":
        raise ValueError(f"body ids must be integers, not {ids.dtype}")
    if orientations is not None:
        orientations = np.asarray(orientations, dtype=np.float64)
        if orientations.shape != (n, 4):
            raise ValueError(f"orientations must be ({n}, 4), not {orientations.shape}")
    return ids, positions, orientations


def _write_fields(out: np.ndarray, ids: np.ndarray, positions: np.ndarray, orientations: Optional[np.ndarray]) -> None:
    """Writes the pose fields into ``out`` (a :data:`POSE_DTYPE` array), one numpy copy each."""
    out["body"] = ids
    out["reserved"] = 0
    out["position"] = positions
    out["orientation"] = _IDENTITY if orientations is None else orientations


#: Largest frame :meth:`SceneLink.publish` gathers in a :class:`_PoseStaging` first; a
#: larger one is written straight into the sample (its copies cost more than numpy's
#: per-call overhead saved).
_STAGED_MAX_POSES = 4096


class _PoseStaging:
    """A :data:`POSE_DTYPE` array of ``count`` records that :meth:`SceneLink.publish`
    gathers separate fields in, then copies into the loaned sample with one ``memmove``.

    For small frames this costs less than writing the fields into the sample: the field
    views and the data address are made once, not per frame (numpy views on a fresh
    sample cost about 1 µs a frame), ``reserved`` stays zero, and an identity orientation
    is written only when the last frame had another (measured, 100 poses: 1.6 µs against
    2.9 µs). The link holds the array, so its address stays valid.
    """

    def __init__(self, count: int) -> None:
        self.count = count
        self._poses = np.zeros(count, dtype=POSE_DTYPE)
        self._body = self._poses["body"]
        self._position = self._poses["position"]
        self._orientation = self._poses["orientation"]
        self._orientation[...] = _IDENTITY
        # Whether every orientation holds the identity.
        self._identity = True
        self.address: int = self._poses.ctypes.data

    def gather(self, ids: np.ndarray, positions: np.ndarray, orientations: Optional[np.ndarray]) -> None:
        """Writes the fields (shapes checked by :func:`_check_fields`), one numpy copy each."""
        self._body[...] = ids
        self._position[...] = positions
        if orientations is not None:
            self._identity = False
            self._orientation[...] = orientations
        elif not self._identity:
            self._orientation[...] = _IDENTITY
            self._identity = True


class PoseFrame:
    """A loaned pose frame being written in place (see :meth:`SceneLink.loan_frame`).

    :attr:`poses` is a writeable :data:`POSE_DTYPE` view on the sample: fill it (every
    record: the memory is not initialised), then :meth:`send`. Dropping it unsent hands
    the memory back.
    """

    def __init__(self, link: "SceneLink", sample: Any, poses: np.ndarray) -> None:
        """Wraps a loaned sample and the view of its records (see :meth:`SceneLink.loan_frame`)."""
        self._link = link
        self._sample: Any = sample
        self.poses: np.ndarray = poses

    def send(self) -> None:
        """Publishes the frame and notifies the daemon (once; later calls fail)."""
        sample, self._sample = self._sample, None
        if sample is None:
            raise TransportError("the pose frame was sent already")
        self.poses = np.empty(0, dtype=POSE_DTYPE)
        self._link._send(sample)

    def __enter__(self) -> "PoseFrame":
        return self

    def __exit__(self, exc_type: Optional[type], *rest: object) -> None:
        if exc_type is None and self._sample is not None:
            self.send()
        elif self._sample is not None:
            self._sample.delete()
            self._sample = None


class SceneLink:
    """One client's link to one scene: pose publisher, poses-ready notifier and the
    result feed (subscriber and results-ready listener).

    Not thread-safe. A result subscriber lends at most two frames at once: release a
    :class:`ResultFrame` before receiving the third.
    """

    def __init__(self, node: Any, root: str, access: SceneAccess) -> None:
        """Opens the pose, result and event services of the scene ``access`` names (the
        daemon created them with the scene) under ``root`` on ``node`` and creates this
        link's ports; its result feed accepts only frames of ``access.instance``.

        Raises:
            NoSuchScene: no daemon serves the scene.
            TransportError: iceoryx2 failed (e.g. too many ports).
        """
        self._access = access
        self._poses_service = open_scene_service(
            services.poses_service_builder(node, root, access.token), "pose service")
        self._ready_service = open_scene_service(
            services.poses_ready_service_builder(node, root, access.token), "poses-ready event service")
        try:
            self._publisher = (
                self._poses_service.publisher_builder()
                .initial_max_slice_len(POSES_INITIAL_MAX_SLICE_LEN)
                .allocation_strategy(iox.AllocationStrategy.PowerOfTwo)
                .max_loaned_samples(1)
                .create()
            )
            self._notifier = self._ready_service.notifier_builder().create()
        except Exception as e:
            raise TransportError("creating the pose publisher or its notifier", e) from e
        self.feed = ResultFeed(node, root, access.token)
        self.feed.expect_instance(access.instance)
        self._event_id = iox.EventId.new(services.EVENT_POSES_SENT)
        # The array `publish_poses` sent last and its data's address (`_address_of`).
        self._last_poses: Optional[np.ndarray] = None
        self._last_address = 0
        # Where `publish` gathers a small frame's fields (`_PoseStaging`).
        self._staging: Optional[_PoseStaging] = None

    @property
    def scene(self) -> int:
        """The scene id this link publishes to."""
        return self._access.scene

    @property
    def access(self) -> SceneAccess:
        """The scene's keys this link publishes with."""
        return self._access

    # -- publishing --------------------------------------------------------------------

    def publish(self, frame_seq: int, budget_ns: int, query_flags: int, ids: Any, positions: Any,
                orientations: Any = None) -> None:
        """Publishes pose frame ``frame_seq`` from arrays: body ``ids`` (``(n,)``
        integers), ``positions`` (``(n, 3)`` metres, world frame) and ``orientations``
        (``(n, 4)`` unit quaternions ``[x, y, z, w]``; ``None``: identity), one numpy copy
        per field: into a staging array the link keeps, then one ``memmove`` into the loaned
        sample, or straight into the sample for frames over :data:`_STAGED_MAX_POSES` poses.
        ``budget_ns`` 0 = no deadline; ``query_flags`` a set of
        :class:`~proxima_client.wire.query` bits.

        Raises:
            ValueError: mismatched shapes; TransportError: iceoryx2 failed.
        """
        ids, positions, orientations = _check_fields(ids, positions, orientations)
        n = len(ids)
        if n > _STAGED_MAX_POSES:
            self._publish_fields(frame_seq, budget_ns, query_flags, ids, positions, orientations)
            return
        staging = self._staging
        if staging is None or staging.count != n:
            staging = self._staging = _PoseStaging(n)
        staging.gather(ids, positions, orientations)
        self._publish_copy(frame_seq, budget_ns, query_flags, staging.address, n)

    def publish_poses(self, frame_seq: int, budget_ns: int, query_flags: int, poses: np.ndarray) -> None:
        """Publishes pose frame ``frame_seq`` from a structured array. With
        :data:`POSE_DTYPE` (C-contiguous) it is one ``memmove`` into the sample; any other
        structured array with fields ``body``, ``position`` and ``orientation`` is copied
        field by field.

        Raises:
            ValueError: not a usable structured array; TransportError: iceoryx2 failed.
        """
        if (poses is self._last_poses and poses.dtype is POSE_DTYPE and poses.ndim == 1
                and poses.flags.c_contiguous):
            # The hot path, one array updated in place and sent every frame: its address is
            # known (`_address_of`), and what could change since it was first sent is
            # checked again above.
            self._publish_copy(frame_seq, budget_ns, query_flags, self._last_address, poses.shape[0])
            return
        poses = np.asarray(poses)
        if poses.ndim != 1:
            raise ValueError(f"poses must be one-dimensional, not {poses.shape}")
        n = poses.shape[0]
        if poses.dtype == POSE_DTYPE and poses.flags.c_contiguous:
            self._publish_copy(frame_seq, budget_ns, query_flags, self._address_of(poses), n)
            return
        names = poses.dtype.names or ()
        if not {"body", "position", "orientation"} <= set(names):
            raise ValueError(f"poses need fields body, position, orientation; got {names}")
        self._publish_fields(frame_seq, budget_ns, query_flags, poses["body"], poses["position"],
                             poses["orientation"])

    def loan_frame(self, frame_seq: int, budget_ns: int, query_flags: int, count: int) -> PoseFrame:
        """Loans pose frame ``frame_seq`` of ``count`` records to be written in place
        (:attr:`PoseFrame.poses`), then sent with :meth:`PoseFrame.send` or by leaving its
        ``with`` block; the analogue of the Rust ``publish_poses_with``."""
        sample, poses = self._loan(frame_seq, budget_ns, query_flags, count)
        return PoseFrame(self, sample, poses)

    def publish_raw(self, header: PoseFrameHeader, poses: np.ndarray) -> None:
        """Publishes ``poses`` (:data:`POSE_DTYPE`) under ``header`` exactly as given (its
        version, scene, count and frame key unchecked): for tests of the daemon's frame
        checks."""
        poses = np.ascontiguousarray(poses, dtype=POSE_DTYPE)
        sample = self._loan_sample(len(poses))
        ctypes.memmove(sample.user_header_ptr, ctypes.addressof(header), _HEADER_BYTES)
        if len(poses):
            ctypes.memmove(sample.payload_ptr, poses.ctypes.data, poses.nbytes)
        self._send(sample)

    def _address_of(self, poses: np.ndarray) -> int:
        """The address of ``poses``' data: ``poses.ctypes.data`` (1–2 µs), remembered for
        the array last published, which a client publishing one array updated in place
        sends every frame. Safe because this link holds that array: numpy refuses to
        ``resize`` an array others reference, and a numpy that refuses to reassign an
        array's ``data`` (2.x; older ones allow it, and then nothing is remembered)."""
        if poses is self._last_poses:
            return self._last_address
        address: int = poses.ctypes.data
        if _DATA_FIXED:
            self._last_poses, self._last_address = poses, address
        return address

    def _publish_copy(self, frame_seq: int, budget_ns: int, query_flags: int, address: int, count: int) -> None:
        """Publishes the ``count`` :data:`POSE_DTYPE` records at ``address``, copied into a
        loaned sample with one ``memmove``.

        Raises:
            ValueError: more records than a frame holds, or a header field out of range;
            TransportError: iceoryx2 failed.
        """
        sample = self._loan_sample(count)
        self._write_header(sample, frame_seq, budget_ns, query_flags, count)
        if count:
            ctypes.memmove(sample.payload_ptr, address, count * _POSE_BYTES)
        self._send(sample)

    def _publish_fields(self, frame_seq: int, budget_ns: int, query_flags: int, ids: np.ndarray,
                        positions: np.ndarray, orientations: Optional[np.ndarray]) -> None:
        """Publishes the pose fields (shapes checked), each written straight into a loaned
        sample by one numpy copy."""
        sample, view = self._loan(frame_seq, budget_ns, query_flags, len(ids))
        _write_fields(view, ids, positions, orientations)
        self._send(sample)

    def _loan_sample(self, count: int) -> Any:
        """A loaned, uninitialised sample of ``count`` pose records.

        Raises:
            ValueError: more records than a frame holds; TransportError: iceoryx2 failed.
        """
        if count > U32_MAX:
            raise ValueError(f"{count} poses do not fit a frame")
        try:
            return loan_slice_uninit(self._publisher, count)
        except Exception as e:
            raise TransportError(f"loaning {count} pose records", e) from e

    def _loan(self, frame_seq: int, budget_ns: int, query_flags: int, count: int) -> tuple[Any, np.ndarray]:
        """A loaned sample with the frame header written, and a numpy view of its records."""
        sample = self._loan_sample(count)
        self._write_header(sample, frame_seq, budget_ns, query_flags, count)
        return sample, poses_view(sample.payload_ptr, count)

    def _write_header(self, sample: Any, frame_seq: int, budget_ns: int, query_flags: int, count: int) -> None:
        """Writes the frame header into loaned ``sample``, in place.

        Raises:
            ValueError: a value that does not fit its field (the sample, unsent, goes back
                when dropped).
        """
        access = self._access
        try:
            POSE_FRAME_HEADER_LAYOUT.pack_into(
                _HEADER_BUFFER.from_address(sample.user_header_ptr), 0, PROTOCOL_VERSION, access.scene,
                frame_seq, budget_ns, query_flags, count, access.frame_key)
        except struct.error as e:
            raise ValueError(f"frame_seq, budget_ns and query_flags must fit u64, u64, u32: {e}") from e

    def _send(self, sample: Any) -> None:
        """Sends ``sample`` and notifies the poses-ready service (event id 1)."""
        try:
            assume_init(sample).send()
        except Exception as e:
            raise TransportError("sending the pose frame", e) from e
        try:
            self._notifier.notify_with_custom_event_id(self._event_id)
        except Exception as e:
            raise TransportError("notifying the daemon", e) from e

    # -- receiving ---------------------------------------------------------------------

    def set_result_spin(self, seconds: float) -> None:
        """Sets how long receiving polls before it blocks (see :meth:`ResultFeed.set_spin`)."""
        self.feed.set_spin(seconds)

    def try_receive_results(self) -> Optional[ResultFrame]:
        """The next result frame if one has arrived, without waiting."""
        return self.feed.try_receive()

    def receive_results(self, timeout: float) -> Optional[ResultFrame]:
        """The next result frame, waiting up to ``timeout`` seconds; ``None`` if none came."""
        return self.feed.receive(timeout)

    def receive_results_for(self, frame_seq: int, timeout: float) -> Optional[ResultFrame]:
        """The result frame answering pose frame ``frame_seq``, waiting up to ``timeout``
        seconds (others received meanwhile are released); ``None`` if it did not come."""
        return self.feed.receive_for(frame_seq, timeout)

    def receive_copy_for(self, frame_seq: int, timeout: float) -> Optional[OwnedResultFrame]:
        """Like :meth:`receive_results_for`, but copies the frame out and releases the
        sample at once: the copying variant."""
        frame = self.feed.receive_for(frame_seq, timeout)
        if frame is None:
            return None
        with frame:
            return frame.copy()

    def close(self) -> None:
        """Releases the link's ports (idempotent) and the array it last published."""
        self.feed.close()
        release_ports(self, "_publisher", "_notifier")
        self._last_poses = None

    def __enter__(self) -> "SceneLink":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

