"""Fixtures: a real ``proximad`` per test, isolated by its own root and iceoryx2 prefix.

``PROXIMAD`` names the daemon (default ``$CARGO_TARGET_DIR/debug/proximad``, else
``<repo>/target/debug/proximad``); ``FRAME_DUMP``
the Rust reference client (default ``<target>/debug/examples/frame_dump``). Without them
the daemon tests are skipped, visibly, unless ``PROXIMA_REQUIRE_DAEMON=1``, which makes
them fail instead (CI sets it).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Iterator, Sequence

import iceoryx2 as iox
import pytest

from proxima_client import Client
from proxima_client.daemon_process import DaemonProcess, Isolation
from support import connect

# iceoryx2's own warnings (e.g. "no config file loaded": the client configures it in code)
# stay quiet unless IOX2_LOG_LEVEL asks for them, as in proximad.
iox.set_log_level_from_env_or(iox.LogLevel.Error)

REPO = Path(__file__).resolve().parents[3]
TARGET = Path(os.environ.get("CARGO_TARGET_DIR") or REPO / "target")

def _required() -> bool:
    return os.environ.get("PROXIMA_REQUIRE_DAEMON") == "1"


def _binary(env: str, default: Path, what: str) -> Path:
    path = Path(os.environ.get(env) or default)
    if not path.is_file():
        message = f"{what} not found at {path} (set {env}, or build it with cargo)"
        if _required():
            pytest.fail(message + "; PROXIMA_REQUIRE_DAEMON=1 makes this a failure")
        pytest.skip(message)
    return path


@pytest.fixture(scope="session")
def proximad() -> Path:
    """The ``proximad`` executable under test."""
    return _binary("PROXIMAD", TARGET / "debug" / "proximad", "proximad")


@pytest.fixture(scope="session")
def frame_dump() -> Path:
    """The Rust reference client ``ipc/examples/frame_dump.rs``."""
    return _binary("FRAME_DUMP", TARGET / "debug" / "examples" / "frame_dump", "frame_dump")


DaemonFactory = Callable[..., DaemonProcess]


@pytest.fixture
def start_daemon(proximad: Path) -> Iterator[DaemonFactory]:
    """Starts daemons with ``extra_args`` (e.g. ``["--max-scenes", "1"]``); every one is
    stopped (SIGTERM, then SIGKILL) and its ``/dev/shm`` files removed after the test."""
    started: list[DaemonProcess] = []

    def start(extra_args: Sequence[str] = (), short: str = "pyt") -> DaemonProcess:
        daemon = DaemonProcess(proximad, Isolation.unique(short), extra_args)
        started.append(daemon)
        return daemon

    yield start
    for daemon in started:
        daemon.stop()


@pytest.fixture
def daemon(start_daemon: DaemonFactory) -> DaemonProcess:
    """A daemon with default settings."""
    return start_daemon()


@pytest.fixture
def client(daemon: DaemonProcess) -> Iterator[Client]:
    """A client connected to :func:`daemon`."""
    c = connect(daemon)
    yield c
    c.close()
