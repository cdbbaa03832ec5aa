"""The Python client's result frames equal the Rust client's, record for record.

The same seeded script (``script.py``: every shape kind, every query flag, updates, a
removal, broad-phase changes, a budgeted and a refused frame) runs through
``ipc/examples/frame_dump.rs`` and through the Python client, each on a fresh scene of the
same daemon. Every header field but the timings and every record field are compared
exactly (floats by their bits): the daemon is deterministic for the same input, so any
difference is a client bug (a layout, a field, a pose written wrong), or a daemon that
is not deterministic after all. To tell the two apart, a failing comparison runs the Rust
client once more and says whether it disagrees with itself too.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any, Optional

import pytest
import script
from support import connect

from proxima_client.daemon_process import DaemonProcess

Frames = list[dict[str, Any]]


def rust_frames(frame_dump: Path, daemon: DaemonProcess, path: Path) -> Frames:
    done = subprocess.run([str(frame_dump), "dump", daemon.root, daemon.prefix, str(path)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return [json.loads(line) for line in done.stdout.splitlines()]


def first_difference(mine: Frames, theirs: Frames) -> Optional[tuple[int, str]]:
    """The first (frame_seq, what) that differs, or ``None``."""
    if [f["frame_seq"] for f in mine] != [f["frame_seq"] for f in theirs]:
        return -1, "the frame sequence numbers"
    for a, b in zip(mine, theirs):
        seq = a["frame_seq"]
        for name in script.HEADER_FIELDS:
            if a[name] != b[name]:
                return seq, f"header {name}: {a[name]} != {b[name]}"
        if len(a["records"]) != len(b["records"]):
            return seq, f"{len(a['records'])} records != {len(b['records'])}"
        for i, (x, y) in enumerate(zip(a["records"], b["records"])):
            if x != y:
                return seq, f"record {i}:\n  {script.describe(x)}\n  {script.describe(y)}"
    return None


@pytest.mark.parametrize("seed", [1, 2, 3, 4])
def test_python_frames_equal_the_rust_clients_on_the_same_script(
    daemon: DaemonProcess, frame_dump: Path, tmp_path: Path, seed: int
) -> None:
    text = script.generate(seed)
    path = tmp_path / "scene.txt"
    path.write_text(text)
    rust = rust_frames(frame_dump, daemon, path)
    with connect(daemon) as client:
        python = script.run(client, text)
    difference = first_difference(python, rust)
    if difference is not None:
        again = first_difference(rust_frames(frame_dump, daemon, path), rust)
        verdict = ("the Rust client disagrees with itself too: the daemon is not deterministic "
                   f"(frame {again[0]}, {again[1]})" if again else "the Rust client agrees with itself")
        pytest.fail(f"frame {difference[0]}, python vs rust: {difference[1]}\n{verdict}")
    # The script is worth comparing: frames with answers of every kind, and the refused one.
    records = sum(len(f["records"]) for f in python)
    assert records >= 20 and sum(f["pair_count"] > 0 for f in python) >= 4, records
    assert python[-1]["status"] == 5 and python[-1]["error_body"] == 2
    assert {r["kind"] for f in python for r in f["records"]} == {1, 2, 3}
