"""The daemon creates every service and clients only open them: the Python builders open
each service the daemon created, a client that starts first waits for the daemon, and
one that gives up leaves no service behind."""

from __future__ import annotations

import threading
from pathlib import Path

import iceoryx2 as iox
import pytest
from support import FRAME_TIMEOUT, REPLY_TIMEOUT

from proxima_client import BodySpec, Client, NoDaemon, Sphere, query, services
from proxima_client.daemon_process import DaemonProcess, Isolation

#: How long the daemon starts after the client began to connect, s.
LATE_START = 0.3


def test_a_client_that_starts_first_waits_for_the_daemon(proximad: Path) -> None:
    isolation = Isolation.unique("svc")
    started: list[DaemonProcess] = []
    # Only the daemon starts on the timer thread; every iceoryx2 object stays on this one.
    timer = threading.Timer(LATE_START, lambda: started.append(DaemonProcess(proximad, isolation)))
    timer.start()
    try:
        with Client.connect(root=isolation.root, iceoryx_prefix=isolation.prefix, reply_timeout=REPLY_TIMEOUT) as client:
            scene = client.create_scene()
            shape = client.register_primitive(scene, Sphere(0.5))
            bodies = [client.add_body(scene, BodySpec(shape=shape, position=(x, 0.0, 0.0), margin=0.1))
                      for x in (0.0, 1.1)]
            with client.open_scene(scene) as link:
                link.publish(1, 0, query.CLOSE, bodies, [(0.0, 0.0, 0.0), (1.1, 0.0, 0.0)])
                frame = link.receive_results_for(1, FRAME_TIMEOUT)
                assert frame is not None
                with frame:
                    frame.raise_for_status()
                    assert len(frame.pairs) == 1
        assert started and not started[0].has_exited()
    finally:
        timer.cancel()
        timer.join()
        for daemon in started:
            daemon.stop()


def test_a_client_without_a_daemon_gives_up_and_creates_nothing(proximad: Path) -> None:
    isolation = Isolation.unique("none")
    with pytest.raises(NoDaemon):
        Client.connect(root=isolation.root, iceoryx_prefix=isolation.prefix, reply_timeout=0.2)
    node = iox.NodeBuilder.new().config(services.make_config(isolation.prefix)).create(iox.ServiceType.Ipc)
    for builder in (services.control_service_builder, services.control_events_service_builder):
        assert services.try_open_service(builder(node, isolation.root), builder.__name__) is None
    # The daemon then starts on a root nobody set up.
    with DaemonProcess(proximad, isolation) as daemon:
        with Client.connect(root=daemon.root, iceoryx_prefix=daemon.prefix, reply_timeout=REPLY_TIMEOUT):
            pass
    del node


def test_the_python_builders_open_every_service_the_daemon_creates(client: Client) -> None:
    node, root = client.node, client.root
    control = services.try_open_service(services.control_service_builder(node, root), "control")
    events = services.try_open_service(services.control_events_service_builder(node, root), "control events")
    assert control is not None and events is not None
    assert control.static_config.max_nodes == services.CONTROL_MAX_NODES == 66
    assert events.static_config.max_nodes == services.CONTROL_MAX_NODES
    scene = client.create_scene()
    access = client.scene_access(scene)
    assert access is not None
    opened = {
        builder.__name__: services.try_open_service(builder(node, root, access.token), builder.__name__)
        for builder in (services.poses_service_builder, services.results_service_builder,
                        services.poses_ready_service_builder, services.results_ready_service_builder)
    }
    assert all(service is not None for service in opened.values()), opened
    results, poses = opened["results_service_builder"], opened["poses_service_builder"]
    assert results is not None and poses is not None
    assert results.static_config.has_safe_overflow
    assert results.static_config.max_subscribers == services.RESULTS_MAX_SUBSCRIBERS
    assert poses.static_config.max_publishers == services.POSES_MAX_PUBLISHERS
    # The names carry the token, not the scene id.
    assert str(access.token) in poses.name.to_string()
