"""The iceoryx2 0.10.0 Python bindings' slice-length bug, pinned so we notice when it goes.

On slice services ``payload()`` builds its ``Slice`` with the sample's length in *bytes*,
not elements, so iterating it runs past the sample. The client never calls it (it reads
``sample.header.number_of_elements``); these tests fail once the bindings report
elements, and then the workaround in ``result_feed.py`` / ``scene_link.py`` can go.
No daemon needed: one process publishes to itself.
"""

from __future__ import annotations

import ctypes
from typing import Iterator

import iceoryx2 as iox
import numpy as np
import pytest

from proxima_client import services
from proxima_client.daemon_process import Isolation, remove_shared_memory
from proxima_client.result_feed import ResultFrame
from proxima_client.wire import RESULT_DTYPE, ResultFrameHeader, ResultRecord

N = 5


@pytest.fixture
def node() -> Iterator[object]:
    isolation = Isolation.unique("bug")
    config = services.make_config(isolation.prefix)
    node = iox.NodeBuilder.new().config(config).create(iox.ServiceType.Ipc)
    yield node
    del node
    remove_shared_memory(isolation.prefix)


def _send_results(node: object, count: int) -> tuple[object, object]:
    """A results service (the daemon's settings, token 0), a frame of ``count`` records
    published to it; returns (publisher, subscriber) with the frame waiting."""
    service = services.results_service_builder(node, "bug", services.SceneToken((0, 0))).open_or_create()
    publisher = service.publisher_builder().initial_max_slice_len(16).allocation_strategy(
        iox.AllocationStrategy.PowerOfTwo).create()
    subscriber = service.subscriber_builder().create()
    sample = publisher.loan_slice_uninit(count)
    header = ResultFrameHeader(frame_seq=7, pair_count=count, error_body=0xFFFF_FFFF)
    ctypes.memmove(sample.user_header_ptr, ctypes.addressof(header), ctypes.sizeof(header))
    records = np.zeros(count, dtype=RESULT_DTYPE)
    records["kind"] = 1
    records["body_a"] = np.arange(count)
    records["distance"] = np.arange(count) * 0.5
    ctypes.memmove(sample.payload_ptr, records.ctypes.data, records.nbytes)
    sample.assume_init().send()
    return publisher, subscriber


def test_bindings_still_report_slice_length_in_bytes(node: object) -> None:
    publisher, subscriber = _send_results(node, N)
    sample = subscriber.receive()
    assert sample is not None
    assert sample.header.number_of_elements == N
    # The bug: bytes, not elements. If this fails, the bindings were fixed: drop the
    # workaround (see this module's doc) and turn this test into a plain length check.
    assert sample.payload().len() == N * ctypes.sizeof(ResultRecord), (
        "iceoryx2's Python payload() no longer reports bytes: the slice-length workaround "
        "in proxima_client can go"
    )
    assert sample.payload().len() != N
    sample.delete()


def test_bindings_report_bytes_on_the_publisher_side_too(node: object) -> None:
    service = services.poses_service_builder(node, "bug", services.SceneToken((0, 1))).open_or_create()
    publisher = service.publisher_builder().initial_max_slice_len(16).allocation_strategy(
        iox.AllocationStrategy.PowerOfTwo).create()
    sample = publisher.loan_slice_uninit(3)
    assert sample.header.number_of_elements == 3
    assert sample.payload().len() == 3 * 64
    sample.delete()


def test_result_frame_counts_elements_despite_the_bug(node: object) -> None:
    publisher, subscriber = _send_results(node, N)
    with ResultFrame(subscriber.receive()) as frame:
        assert len(frame.records) == N
        assert len(frame.pairs) == N
        assert frame.records["body_a"].tolist() == list(range(N))
        assert frame.records["distance"].tolist() == [i * 0.5 for i in range(N)]
        assert frame.frame_seq == 7


def test_an_empty_slice_reads_as_no_records(node: object) -> None:
    publisher, subscriber = _send_results(node, 0)
    with ResultFrame(subscriber.receive()) as frame:
        assert len(frame.records) == 0
        assert frame.records.dtype == RESULT_DTYPE



def test_the_native_loan_and_assume_init_the_client_calls_exist() -> None:
    # transport.py calls these past the bindings' Python wrappers (their per-call type
    # checks cost a tenth of a frame's client work); when a binding release renames them,
    # the client falls back to the public methods, and this test says so.
    from proxima_client import transport

    assert transport._NATIVE_LOAN_SLICE is not None, "Publisher.__loan_slice_uninit is gone"
    assert transport._NATIVE_ASSUME_INIT is not None, "SampleMutUninit.__assume_init is gone"
