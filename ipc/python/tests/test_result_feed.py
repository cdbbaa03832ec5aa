"""A result feed refuses frames of another daemon instance and tells a scene nobody
publishes any more. No daemon needed: this process creates the scene's services and
plays the daemon's publisher."""

from __future__ import annotations

import ctypes
from typing import Any, Iterator

import iceoryx2 as iox
import pytest

from proxima_client import DaemonLost, NoSuchScene, ResultFeed, SceneToken, services
from proxima_client.daemon_process import Isolation, remove_shared_memory
from proxima_client.wire import ResultFrameHeader

TOKEN = SceneToken((0xFEED, 0xBEEF))
ROOT = "feed"


@pytest.fixture
def node() -> Iterator[Any]:
    isolation = Isolation.unique("feed")
    node = iox.NodeBuilder.new().config(services.make_config(isolation.prefix)).create(iox.ServiceType.Ipc)
    yield node
    del node
    remove_shared_memory(isolation.prefix)


class FakeDaemon:
    """The scene's services, created as the daemon creates them, and its result publisher."""

    def __init__(self, node: Any) -> None:
        self.results = services.results_service_builder(node, ROOT, TOKEN).create()
        self.ready = services.results_ready_service_builder(node, ROOT, TOKEN).create()
        self.publisher: Any = self.results.publisher_builder().initial_max_slice_len(4).allocation_strategy(
            iox.AllocationStrategy.PowerOfTwo).create()

    def publish(self, frame_seq: int, instance: int) -> None:
        sample = self.publisher.loan_slice_uninit(0)
        header = ResultFrameHeader(frame_seq=frame_seq, error_body=0xFFFF_FFFF, instance=instance)
        ctypes.memmove(sample.user_header_ptr, ctypes.addressof(header), ctypes.sizeof(header))
        sample.assume_init().send()


def test_a_frame_of_another_instance_is_daemon_lost(node: Any) -> None:
    daemon = FakeDaemon(node)
    with ResultFeed(node, ROOT, TOKEN) as feed:
        daemon.publish(1, instance=7)
        with feed.receive_for(1, 1.0) as frame:  # type: ignore[union-attr]
            assert frame.header.instance == 7  # any instance until one is expected
        feed.expect_instance(7)
        daemon.publish(2, instance=7)
        with feed.receive_for(2, 1.0) as frame:  # type: ignore[union-attr]
            assert frame.frame_seq == 2
        daemon.publish(3, instance=8)
        with pytest.raises(DaemonLost):
            feed.receive_for(3, 1.0)


def test_a_wait_with_no_publisher_left_is_daemon_lost(node: Any) -> None:
    daemon = FakeDaemon(node)
    with ResultFeed(node, ROOT, TOKEN) as feed:
        assert feed.daemon_is_alive()
        assert feed.receive(0.01) is None
        daemon.publisher.delete()
        assert not feed.daemon_is_alive()
        with pytest.raises(DaemonLost):
            feed.receive(0.01)


def test_a_feed_never_creates_the_scenes_services(node: Any) -> None:
    with pytest.raises(NoSuchScene):
        ResultFeed(node, ROOT, TOKEN)
    assert services.try_open_service(services.results_service_builder(node, ROOT, TOKEN), "results") is None
