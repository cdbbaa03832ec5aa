"""The receiving half of a scene's frame path, mirroring ``ipc/src/result_feed.rs``.

A :class:`ResultFeed` subscribes to a scene's result frames and waits for them (hybrid: a
spin, then a blocking wait on the scene's results-ready listener, event id 2). Each
arrives as a :class:`ResultFrame`: its header decoded, its records a numpy structured
array (:data:`~proxima_client.wire.RESULT_DTYPE`) viewing the sample in shared memory, no
copy. The view is valid while the frame is held: :meth:`ResultFrame.release` (or leaving
its ``with`` block) hands the memory back to the daemon, after which earlier views must
not be read. :meth:`ResultFrame.copy` gives an :class:`OwnedResultFrame` that lives on.

A subscriber lends at most two frames at once (iceoryx2's default borrow limit): release
a frame before receiving the third.

A feed is opened by the scene's token (:class:`~proxima_client.services.SceneToken`), the
capability its owner shares with monitors. A frame of another daemon instance than the one
expected (:meth:`ResultFeed.expect_instance`), or a wait that times out while no live
process publishes the scene's results, raises
:class:`~proxima_client.errors.DaemonLost`.

**iceoryx2 0.10.0 binding bug.** On slice services the Python bindings' ``payload()``
reports the slice length in *bytes* instead of elements, so reading it runs past the
sample. This module never calls it: the record count comes from the sample's iceoryx2
header (``number_of_elements``), and the pair, contact and time-of-impact counts from the
frame header are clamped to it. ``tests/test_binding_bug.py`` fails once the bindings
change, so the workaround can then go.
"""

from __future__ import annotations

import ctypes
from typing import Any, Callable, Optional

import iceoryx2 as iox
import numpy as np

from . import services
from .errors import (
    OWNER_GONE_REASON,
    DaemonLost,
    NoSuchScene,
    SceneReleasedError,
    TransportError,
    error_for,
)
from .services import SceneToken
from .transport import RESULTS_SPIN_S, now, release_ports
from .wire import RESULT_DTYPE, Completeness, ErrorCode, ResultFrameHeader, frame_flags

_RECORD_BYTES = RESULT_DTYPE.itemsize
_HEADER_BYTES = ctypes.sizeof(ResultFrameHeader)
#: The bytes of a received sample's header, to copy it out.
_HEADER_BUFFER = ctypes.c_char * _HEADER_BYTES
#: The records of an empty or released frame (read-only, shared).
_NO_RECORDS = np.empty(0, dtype=RESULT_DTYPE)
_NO_RECORDS.flags.writeable = False


def records_view(address: int, count: int, owner: Any = None) -> np.ndarray:
    """A read-only numpy array of ``count`` :data:`RESULT_DTYPE` records at ``address``, no copy.

    The array references ``owner`` (the sample), so the memory stays lent while any view
    of it lives; an explicit release of the owner still ends its validity.
    """
    if count == 0:
        return _NO_RECORDS
    buffer = _byte_array(count * _RECORD_BYTES).from_address(address)
    buffer._owner = owner  # type: ignore[attr-defined]
    array = np.frombuffer(buffer, RESULT_DTYPE)  # type: ignore[call-overload]  # ctypes arrays are buffers
    array.setflags(write=False)
    return array


#: ``ctypes.c_char * size`` by size, for the sizes frames have had (at most
#: :data:`_BYTE_ARRAY_TYPES_KEPT` of them): a look-up here costs half of ctypes' own.
_BYTE_ARRAY_TYPES: dict[int, Any] = {}
_BYTE_ARRAY_TYPES_KEPT = 1024


def _byte_array(size: int) -> Any:
    """The ctypes array type of ``size`` bytes."""
    kind = _BYTE_ARRAY_TYPES.get(size)
    if kind is None:
        kind = ctypes.c_char * size
        if len(_BYTE_ARRAY_TYPES) < _BYTE_ARRAY_TYPES_KEPT:
            _BYTE_ARRAY_TYPES[size] = kind
    return kind


def _clamp(count: int, length: int) -> int:
    """``count``, at most ``length``."""
    return count if count < length else length


class _Frame:
    """What every result frame offers, held or copied: the header and the records split
    into pairs, contacts and times of impact (each count clamped to the records, so a
    header that lies cannot index past them)."""

    header: ResultFrameHeader
    records: np.ndarray

    @property
    def frame_seq(self) -> int:
        """The ``frame_seq`` of the pose frame this answers."""
        return self.header.frame_seq

    @property
    def status(self) -> "ErrorCode | int":
        """The frame's status (an :class:`ErrorCode`; the raw int if undefined)."""
        try:
            return ErrorCode(self.header.status)
        except ValueError:
            return self.header.status

    @property
    def ok(self) -> bool:
        """Whether the frame was processed (status ``OK``)."""
        return self.header.status == ErrorCode.OK

    @property
    def exact(self) -> bool:
        """Whether every pair was answered exactly (not truncated by the deadline)."""
        return self.header.completeness == Completeness.EXACT

    @property
    def budget_met(self) -> bool:
        """Whether the daemon published the result within the frame's budget."""
        return self.header.budget_met != 0

    def raise_for_status(self) -> None:
        """Raises the :class:`~proxima_client.errors.DaemonError` subclass of the frame's
        status (with ``.body`` the offending body, if any); does nothing on ``OK``."""
        status = self.header.status
        if status != ErrorCode.OK:
            body = self.header.error_body
            raise error_for(status, body=None if body == 0xFFFF_FFFF else body)

    def _bounds(self) -> tuple[int, int, int, int]:
        """Record count and the ends of the pairs, contacts and times of impact, clamped."""
        n = len(self.records)
        h = self.header
        p = _clamp(h.pair_count, n)
        c = p + _clamp(h.contact_count, n - p)
        t = c + _clamp(h.toi_count, n - c)
        return n, p, c, t

    @property
    def pairs(self) -> np.ndarray:
        """The pair records: the first ``pair_count``."""
        _, p, _, _ = self._bounds()
        return self.records[:p]

    @property
    def contacts(self) -> np.ndarray:
        """The contact records: the ``contact_count`` after the pairs."""
        _, p, c, _ = self._bounds()
        return self.records[p:c]

    @property
    def tois(self) -> np.ndarray:
        """The time-of-impact records: the ``toi_count`` after the contacts."""
        _, _, c, t = self._bounds()
        return self.records[c:t]

    def contacts_of(self, pair: Any) -> np.ndarray:
        """The contacts of ``pair`` (a record of :attr:`pairs`): ``count`` from ``index``
        on, counted from the first contact record, clamped to :attr:`contacts`."""
        contacts = self.contacts
        start = min(int(pair["index"]), len(contacts))
        return contacts[start:start + int(pair["count"])]


class OwnedResultFrame(_Frame):
    """A result frame copied out of shared memory: it holds no sample and lives on."""

    def __init__(self, header: ResultFrameHeader, records: np.ndarray) -> None:
        """Wraps a received sample (or a copied header and records)."""
        self.header = header
        self.records = records

    def __repr__(self) -> str:
        return f"OwnedResultFrame(frame_seq={self.frame_seq}, status={self.status!r}, records={len(self.records)})"


class ResultFrame(_Frame):
    """A received result frame, read in place in shared memory.

    :attr:`records` (and :attr:`pairs`, :attr:`contacts`, :attr:`tois`) are read-only
    numpy views on the sample; :attr:`header` is a decoded copy. Release the frame
    (:meth:`release`, or use it as a context manager) to hand the memory back; views taken
    before must not be read afterwards (use :meth:`copy` for data that must live on).
    """

    def __init__(self, sample: Any) -> None:
        """Wraps a received sample (or a copied header and records)."""
        self._sample: Any = sample
        header_bytes = _HEADER_BUFFER.from_address(sample.user_header_ptr)
        self.header = ResultFrameHeader.from_buffer_copy(header_bytes)
        # NOTE: not `sample.payload().len()`: the 0.10.0 bindings report bytes there.
        count = sample.header.number_of_elements
        self.records = records_view(sample.payload_ptr, count, sample)

    @property
    def held(self) -> bool:
        """Whether the sample is still held (the views are valid)."""
        return self._sample is not None

    def copy(self) -> OwnedResultFrame:
        """A copy of the header and records that outlives the sample."""
        header = ResultFrameHeader.from_buffer_copy(self.header)
        return OwnedResultFrame(header, self.records.copy())

    def release(self) -> None:
        """Hands the sample back to the daemon's publisher (idempotent)."""
        sample, self._sample = self._sample, None
        if sample is not None:
            self.records = _NO_RECORDS
            sample.delete()

    def __enter__(self) -> "ResultFrame":
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()

    def __repr__(self) -> str:
        return f"ResultFrame(frame_seq={self.frame_seq}, status={self.status!r}, records={len(self.records)}, held={self.held})"


def open_scene_service(builder: Any, what: str) -> Any:
    """Opens one of a scene's services (the daemon created them with the scene).

    Raises:
        NoSuchScene: the service does not exist; TransportError: iceoryx2 failed.
    """
    service = services.try_open_service(builder, what)
    if service is None:
        raise NoSuchScene(f"no daemon serves a scene with this token (its {what} does not exist)")
    return service


class ResultFeed:
    """A subscription to one scene's result frames, with the scene's results-ready
    listener to sleep on. Frames published before it was opened are not seen."""

    def __init__(self, node: Any, root: str, token: SceneToken) -> None:
        """Opens the result and results-ready services of the scene with token ``token``
        (the capability its owner shares) under ``root`` on ``node``, and subscribes. The
        daemon creates a scene's services with the scene; this only opens them. Frames of
        any daemon instance are accepted until :meth:`expect_instance`.

        Raises:
            NoSuchScene: no daemon serves a scene with this token.
            TransportError: iceoryx2 failed (e.g. too many subscribers).
        """
        self._results_service = open_scene_service(
            services.results_service_builder(node, root, token), "result service")
        self._ready_service = open_scene_service(
            services.results_ready_service_builder(node, root, token), "results-ready event service")
        try:
            self._subscriber = self._results_service.subscriber_builder().create()
            self._listener = self._ready_service.listener_builder().create()
        except Exception as e:
            raise TransportError("creating the result subscriber or its listener", e) from e
        self.spin = RESULTS_SPIN_S
        self._instance = 0

    def expect_instance(self, instance: int) -> None:
        """Accepts only frames of daemon instance ``instance`` (from the scene's
        ``CreateScene`` reply, or the monitoring client's ``daemon_instance``); a frame of
        another raises :class:`~proxima_client.errors.DaemonLost`. 0 accepts any."""
        self._instance = instance

    def set_spin(self, seconds: float) -> None:
        """Sets how long a receive polls before it blocks (:data:`RESULTS_SPIN_S` by
        default). A longer spin saves a wake-up when answers come later, at the price of
        a busy core: worth it only when this process has a core of its own."""
        self.spin = seconds

    def try_receive(self) -> Optional[ResultFrame]:
        """The next result frame if one has arrived, without waiting.

        Raises:
            DaemonLost: the frame comes from another daemon instance than the one expected.
            SceneReleasedError: the scene's last frame: the daemon let go of it.
            TransportError: iceoryx2 failed (e.g. two frames are still held).
        """
        try:
            sample = self._subscriber.receive()
        except Exception as e:
            raise TransportError("receiving a result frame", e) from e
        if sample is None:
            return None
        frame = ResultFrame(sample)
        if self._instance and frame.header.instance != self._instance:
            frame.release()
            raise DaemonLost("a result frame came from another daemon instance (a restart)")
        header = frame.header
        if header.status == ErrorCode.SCENE_RELEASED:
            owner_gone = bool(header.flags & frame_flags.OWNER_GONE)
            frame.release()
            reason = OWNER_GONE_REASON if owner_gone else "its owner dropped it"
            raise SceneReleasedError(ErrorCode.SCENE_RELEASED, reason)
        return frame

    def daemon_is_alive(self) -> bool:
        """Whether a live process (the daemon) still publishes the scene's results, after
        removing the ports of crashed processes from the service (so a daemon killed
        without cleaning up counts as gone). A dropped scene has no publisher either."""
        try:
            self._results_service.try_cleanup_dead_nodes()
        except Exception:  # cleanup is best effort; the count below decides
            pass
        return self._results_service.dynamic_config.number_of_publishers > 0

    def receive(self, timeout: float) -> Optional[ResultFrame]:
        """The next result frame, waiting up to ``timeout`` seconds; ``None`` if none came.

        Raises:
            DaemonLost: a frame of another daemon instance, or none came and no live
                process publishes the scene's results.
        """
        return self._receive_until(now() + timeout, lambda header: True)

    def receive_for(self, frame_seq: int, timeout: float) -> Optional[ResultFrame]:
        """The result frame answering pose frame ``frame_seq``, waiting up to ``timeout``
        seconds; frames received meanwhile for other sequence numbers are released.
        ``None`` when it did not arrive in time; raises like :meth:`receive`."""
        return self._receive_until(now() + timeout, lambda header: header.frame_seq == frame_seq)

    def _receive_until(self, deadline: float, accept: Callable[[ResultFrameHeader], bool]) -> Optional[ResultFrame]:
        """The first received frame whose header ``accept`` s, waiting until ``deadline``.

        A notification that arrives between a poll and the blocking wait stays pending in
        the listener, so the wait returns at once and the loop polls again. The listener
        may also wake with nothing new, so the deadline is always judged by the clock. At
        the deadline, a scene no live process publishes raises :class:`DaemonLost`.
        """
        spin_end = now() + self.spin
        while True:
            frame = self.try_receive()
            while frame is not None:
                if accept(frame.header):
                    return frame
                frame.release()
                frame = self.try_receive()
            t = now()
            if t >= deadline:
                if not self.daemon_is_alive():
                    raise DaemonLost("no live daemon publishes the scene's results")
                return None
            if t < spin_end:
                continue
            try:
                self._listener.timed_wait(iox.Duration.from_secs_f64(deadline - t))
            except Exception as e:
                raise TransportError("waiting on the scene's results-ready listener", e) from e

    def close(self) -> None:
        """Releases the subscriber and listener (idempotent)."""
        release_ports(self, "_subscriber", "_listener")

    def __enter__(self) -> "ResultFeed":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
