"""The Python client's result frames equal the Rust client's, record for record.

The same seeded script (``script.py``: every shape kind, every query flag, updates, a
removal, broad-phase changes, a budgeted and a refused frame) runs through
``ipc/examples/frame_dump.rs`` and through the Python client, each on a fresh scene of the
same daemon. Every header field but the timings and every record field are compared
exactly (floats by their bits): the daemon is deterministic for the same input, so any
difference is a client bug (a layout, a field, a pose written wrong).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
import script
from support import connect

from proxima_client.daemon_process import DaemonProcess


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_python_frames_equal_the_rust_clients_on_the_same_script(
    daemon: DaemonProcess, frame_dump: Path, tmp_path: Path, seed: int
) -> None:
    text = script.generate(seed)
    path = tmp_path / "scene.txt"
    path.write_text(text)
    done = subprocess.run([str(frame_dump), "dump", daemon.root, daemon.prefix, str(path)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    rust = [json.loads(line) for line in done.stdout.splitlines()]
    with connect(daemon) as client:
        python = script.run(client, text)
    assert [f["frame_seq"] for f in python] == [f["frame_seq"] for f in rust]
    records = hits = 0
    for mine, theirs in zip(python, rust):
        seq = mine["frame_seq"]
        for name in script.HEADER_FIELDS:
            assert mine[name] == theirs[name], f"frame {seq}: header {name}"
        assert len(mine["records"]) == len(theirs["records"]), f"frame {seq}: record count"
        for i, (a, b) in enumerate(zip(mine["records"], theirs["records"])):
            assert a == b, f"frame {seq} record {i}:\n python {script.describe(a)}\n rust   {script.describe(b)}"
        records += len(mine["records"])
        hits += mine["pair_count"] > 0
    # The script is worth comparing: frames with answers, and the refused one.
    assert records >= 20 and hits >= 4, (records, hits)
    assert python[-1]["status"] == 5 and python[-1]["error_body"] == 2
    kinds = {r["kind"] for f in python for r in f["records"]}
    assert kinds == {1, 2, 3}, kinds
