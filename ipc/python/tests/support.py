"""Helpers shared by the tests (not fixtures: those are in ``conftest.py``)."""

from __future__ import annotations

from typing import Any

from proxima_client import Client
from proxima_client.daemon_process import DaemonProcess

#: Seconds a test's client waits for a reply (generous: CI machines are loaded).
REPLY_TIMEOUT = 10.0
#: Seconds a test waits for a result frame.
FRAME_TIMEOUT = 10.0


def connect(daemon: DaemonProcess, **kwargs: Any) -> Client:
    """A client of ``daemon``."""
    kwargs.setdefault("reply_timeout", REPLY_TIMEOUT)
    return Client.connect(root=daemon.root, iceoryx_prefix=daemon.prefix, **kwargs)
