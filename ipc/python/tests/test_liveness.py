"""A Python client killed without a chance to clean up loses its scenes after the daemon's
grace period, while a live client's scenes stay; a killed daemon is told by a scene's
result wait."""

from __future__ import annotations

import select
import subprocess
import sys
import time

import pytest
from support import connect

from proxima_client import BodySpec, DaemonLost, NotOwnerError, Sphere, UnknownSceneError, query
from proxima_client.daemon_process import DaemonProcess
from proxima_client.transport import now

GRACE_MS = 200
#: How long the test waits for the daemon to drop the dead client's scene, s (the grace,
#: the daemon's sweep interval and a loaded machine's delays, with room to spare).
DROP_TIMEOUT = 20.0

CHILD = """
import sys, time
from proxima_client import Client
client = Client.connect(root=sys.argv[1], iceoryx_prefix=sys.argv[2], reply_timeout=10.0)
print(client.create_scene(), flush=True)
time.sleep(600)
"""


def _read_line(process: subprocess.Popen[str], timeout: float) -> str:
    assert process.stdout is not None
    ready, _, _ = select.select([process.stdout], [], [], timeout)
    assert ready, "the child client did not create its scene in time"
    return process.stdout.readline().strip()


def test_a_killed_clients_scene_is_dropped_after_the_grace_and_a_live_ones_is_kept(start_daemon) -> None:  # type: ignore[no-untyped-def]
    daemon = start_daemon(["--grace-ms", str(GRACE_MS)])
    survivor = connect(daemon)
    kept = survivor.create_scene()
    child = subprocess.Popen([sys.executable, "-c", CHILD, daemon.root, daemon.prefix],
                             stdout=subprocess.PIPE, text=True)
    try:
        orphan = int(_read_line(child, 30.0))
        assert orphan != kept
        # Alive while its creator lives: another client is refused as not its owner.
        with pytest.raises(NotOwnerError):
            survivor.register_primitive(orphan, Sphere(1.0))
        child.kill()
        child.wait()
        started = now()
        deadline = started + DROP_TIMEOUT
        while True:
            try:
                survivor.register_primitive(orphan, Sphere(1.0))
            except NotOwnerError:
                pass
            except UnknownSceneError as e:
                assert str(orphan) in e.reason
                break
            if now() > deadline:
                pytest.fail(f"scene {orphan} of the killed client still lives after {DROP_TIMEOUT} s")
            time.sleep(0.02)
        waited = now() - started
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    # The grace has passed for the survivor's scene too: it is kept because its client lives.
    assert waited * 1000 >= GRACE_MS * 0.5
    survivor.register_primitive(kept, Sphere(1.0))
    survivor.close()



def test_a_result_wait_on_a_killed_daemons_scene_raises_daemon_lost(daemon: DaemonProcess) -> None:
    client = connect(daemon)
    scene = client.create_scene()
    body = client.add_body(scene, BodySpec(shape=client.register_primitive(scene, Sphere(0.5))))
    link = client.open_scene(scene)
    link.publish(1, 0, query.CLOSE, [body], [(0.0, 0.0, 0.0)])
    frame = link.receive_results_for(1, 10.0)
    assert frame is not None
    frame.release()
    assert link.receive_results(0.05) is None  # alive: no frame is no error
    daemon.kill()
    with pytest.raises(DaemonLost):
        link.receive_results(0.05)
    link.close()
    client.close()
