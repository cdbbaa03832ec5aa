"""How the client waits on iceoryx2, mirroring ``ipc/src/transport.rs``.

Each wait polls for a bounded few tens of µs before it gives up the core: waking a
blocked process costs 60–120 µs on a VM against a few µs for a polled hand-over, and a
longer spin would hold a core the daemon may need. Request–response ports cannot join a
WaitSet, so a control reply is polled: a spin of :data:`CONTROL_REPLY_SPIN_S`, then sleeps
of :data:`CONTROL_REPLY_SLEEP_S`. A result frame is polled for :data:`RESULTS_SPIN_S`,
then waited for on the scene's results-ready listener.
"""

from __future__ import annotations

import time
from typing import Any, Callable, Optional, TypeVar

import iceoryx2 as iox

#: How long a control reply is awaited by spinning before the wait starts sleeping, s.
CONTROL_REPLY_SPIN_S: float = 20e-6
#: One sleep of the control reply wait after the spin, s.
CONTROL_REPLY_SLEEP_S: float = 50e-6
#: The first pause between two ``ShapeState`` asks while waiting for a build, s; doubles.
SHAPE_POLL_FIRST_S: float = 200e-6
#: The longest pause between two ``ShapeState`` asks, s.
SHAPE_POLL_MAX_S: float = 20e-3
#: How long a receive polls the result subscriber before it blocks on the listener, s.
RESULTS_SPIN_S: float = 50e-6

T = TypeVar("T")

#: The clock of every wait: monotonic, nanosecond resolution.
now = time.perf_counter


def poll_until(deadline: float, poll: Callable[[], Optional[T]]) -> Optional[T]:
    """Calls ``poll`` until it returns a value or :func:`now` passes ``deadline``.

    Spins for :data:`CONTROL_REPLY_SPIN_S`, then sleeps :data:`CONTROL_REPLY_SLEEP_S`
    between polls. Polls at least once; ``None`` when the deadline passed first.
    """
    start = now()
    while True:
        value = poll()
        if value is not None:
            return value
        t = now()
        if t >= deadline:
            return None
        if t - start >= CONTROL_REPLY_SPIN_S:
            time.sleep(min(CONTROL_REPLY_SLEEP_S, deadline - t))


def release_ports(owner: Any, *names: str) -> None:
    """Deletes ``owner``'s iceoryx2 ports held in the attributes ``names`` and sets each to
    ``None``, so releasing twice is harmless (the ``close`` of clients, links and feeds)."""
    for name in names:
        port = getattr(owner, name, None)
        if port is not None:
            port.delete()
            setattr(owner, name, None)


# The 0.10.0 bindings wrap `Publisher.loan_slice_uninit` and `SampleMutUninit.assume_init`
# in Python functions that check the payload type on every call (`typing.get_origin`,
# asserts): 0.25 and 0.15 µs of a pose frame's ~3 µs of client work. The native methods
# they call are used directly when the bindings have them (the pinned 0.10.0 does;
# tests/test_binding_bug.py checks it), else the public ones. Both serve only the pose
# service, a slice service, whose checks these are.
_NATIVE_LOAN_SLICE: Optional[Callable[[Any, int], Any]] = getattr(iox.Publisher, "__loan_slice_uninit", None)
_NATIVE_ASSUME_INIT: Optional[Callable[[Any], Any]] = getattr(iox.SampleMutUninit, "__assume_init", None)

#: ``loan_slice_uninit(publisher, count)``: ``publisher.loan_slice_uninit(count)`` for a
#: slice service, without the bindings' per-call checks.
loan_slice_uninit: Callable[[Any, int], Any] = _NATIVE_LOAN_SLICE or iox.Publisher.loan_slice_uninit
#: ``assume_init(sample)``: ``sample.assume_init()`` for a slice sample, without the
#: bindings' per-call checks.
assume_init: Callable[[Any], Any] = _NATIVE_ASSUME_INIT or iox.SampleMutUninit.assume_init
