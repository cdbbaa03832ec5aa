"""A ``proximad`` started as a child process under a service root and iceoryx2 prefix of
its own, stopped and cleaned up afterwards; mirrors ``ipc/src/tools/daemon_process.rs``.

**Not part of the protocol**: a helper for tests, examples and tools that bring their own
daemon, so that they never meet another daemon's services and leave no shared-memory
files behind (iceoryx2 removes a crashed process's files only when a later process with
the same prefix starts, and even a clean exit leaves one small segment).
"""

from __future__ import annotations

import itertools
import os
import signal
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Optional, Sequence

#: How long :meth:`DaemonProcess.stop` waits for a clean exit after SIGTERM, seconds.
STOP_GRACE_S: float = 2.0

_NEXT = itertools.count()


@dataclass(frozen=True)
class Isolation:
    """A service root and iceoryx2 prefix no other process of this machine uses:
    ``proxima-<short>-<pid>_<n>`` and ``iox2_<short><pid>_<n>_``."""

    root: str
    prefix: str

    @classmethod
    def unique(cls, short: str) -> "Isolation":
        """A fresh root and prefix tagged with ``short`` (a few lowercase letters)."""
        tag = f"{os.getpid()}_{next(_NEXT)}"
        return cls(root=f"proxima-{short}-{tag}", prefix=f"iox2_{short}{tag}_")


def remove_shared_memory(prefix: str) -> int:
    """Removes every ``/dev/shm`` file whose name starts with ``prefix``; returns how many."""
    if not prefix:
        return 0
    removed = 0
    shm = Path("/dev/shm")
    if shm.is_dir():
        for entry in shm.iterdir():
            if entry.name.startswith(prefix):
                try:
                    entry.unlink()
                    removed += 1
                except FileNotFoundError:
                    pass
    return removed


class DaemonProcess:
    """A running ``proximad`` child with its own root and prefix.

    Stop it with :meth:`stop` (SIGTERM, then SIGKILL after :data:`STOP_GRACE_S`), or use
    it as a context manager; both remove its ``/dev/shm`` files.
    """

    def __init__(self, executable: "str | os.PathLike[str]", isolation: Isolation,
                 extra_args: Sequence[str] = (), log_level: str = "warn",
                 stderr: Optional[int] = None) -> None:
        """Starts ``executable --root ROOT --iceoryx-prefix PREFIX --log-level LEVEL
        EXTRA...``.

        Raises:
            FileNotFoundError: no such executable.
        """
        self.executable = str(executable)
        self.isolation = isolation
        args = [self.executable, "--root", isolation.root, "--iceoryx-prefix", isolation.prefix,
                "--log-level", log_level, *extra_args]
        self.process: Optional[subprocess.Popen[bytes]] = subprocess.Popen(args, stderr=stderr)

    @property
    def root(self) -> str:
        """The daemon's service root."""
        return self.isolation.root

    @property
    def prefix(self) -> str:
        """The daemon's iceoryx2 prefix."""
        return self.isolation.prefix

    @property
    def pid(self) -> Optional[int]:
        """The child's process id, ``None`` once stopped."""
        return None if self.process is None else self.process.pid

    def has_exited(self) -> bool:
        """Whether the child has exited (reaping it if so)."""
        return self.process is None or self.process.poll() is not None

    def stop(self) -> Optional[int]:
        """SIGTERM, a wait of up to :data:`STOP_GRACE_S`, then SIGKILL; removes the
        shared-memory files. Returns the exit status (negative: killed by that signal), or
        ``None`` if already stopped."""
        process, self.process = self.process, None
        status: Optional[int] = None
        if process is not None:
            if process.poll() is None:
                process.send_signal(signal.SIGTERM)
                try:
                    process.wait(STOP_GRACE_S)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.wait()
            status = process.returncode
        remove_shared_memory(self.isolation.prefix)
        return status

    def kill(self) -> None:
        """SIGKILL at once, as a crash would (files stay until :meth:`stop`)."""
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()

    def __enter__(self) -> "DaemonProcess":
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def __del__(self) -> None:
        if getattr(self, "process", None) is not None:
            self.stop()
