"""The Python builders' settings are the daemon's: services the Python client creates
before the daemon exists are opened by it, and frames flow through them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import iceoryx2 as iox
from support import FRAME_TIMEOUT, connect

from proxima_client import BodySpec, Sphere, query, services
from proxima_client.daemon_process import DaemonProcess, Isolation


def test_services_created_by_python_first_are_opened_by_the_daemon(proximad: Path) -> None:
    isolation = Isolation.unique("svc")
    node = iox.NodeBuilder.new().config(services.make_config(isolation.prefix)).create(iox.ServiceType.Ipc)
    root = isolation.root
    created: list[Any] = [
        services.open_service(services.control_service_builder(node, root), "control"),
        services.open_service(services.control_events_service_builder(node, root), "control events"),
    ]
    # Scene 0's services too: the daemon opens them when it creates the scene.
    for builder in (services.poses_service_builder, services.results_service_builder,
                    services.poses_ready_service_builder, services.results_ready_service_builder):
        created.append(services.open_service(builder(node, root, 0), builder.__name__))
    with DaemonProcess(proximad, isolation) as daemon:
        with connect(daemon) as client:
            scene = client.create_scene()
            assert scene == 0
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
        assert not daemon.has_exited(), "the daemon refused the services Python created"
    del created, node
