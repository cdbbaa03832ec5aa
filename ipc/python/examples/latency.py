"""Round trip of the Python client against the Rust client's, on the same scene of the
same daemon, in the same run.

    python latency.py --spawn-daemon target/release/proximad \\
        --frame-dump target/release/examples/frame_dump --repeats 3

The scene is ``ipc/src/tools/latency_scene.rs``'s (also ``examples/ipc_latency.rs``'s):
``--bodies`` spheres (radius 0.5 m, margin 0.1 m) on a 3 m grid, each moving on a 0.3 m
circle, so every pose changes every frame; frames ask ``CLOSE`` with a 1 ms budget and
are sent back to back. Each repeat runs the Rust client (``frame_dump latency``, a
process of its own) and then this one, each on a fresh scene of the one daemon, and
prints:

- ``round trip``: publish → result frame received (p50, p99);
- ``python side``: the time this process spends in the client per frame: publishing
  (checks, loan, header, one numpy copy per field, send, notify), the receive call that
  returned the frame (iceoryx2 receive, header decode, numpy view of the records) and
  reading it (counts, release), p50. Waiting is not counted. The new positions are
  computed before the clock starts (the Rust client computes them inside its timed
  publish, ~1 µs);
- ``daemon``: the daemon's own time per frame (``elapsed_ns``), p50.

Targets (issue #32): Python round trip ≤ 1.3 × Rust's, Python side ≤ 40 µs p50.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from typing import Any, Optional

import iceoryx2 as iox
import numpy as np

from proxima_client import BodySpec, Client, Motion, Sphere, pose_array, query
from proxima_client.daemon_process import DaemonProcess, Isolation

RADIUS, SPACING, MARGIN = 0.5, 3.0, 0.1


def grid(bodies: int) -> tuple[np.ndarray, np.ndarray]:
    """Each body's grid point and phase offset (as ``grid_position`` in ipc/src/tools/latency_scene.rs)."""
    side = int(np.ceil(np.cbrt(bodies)))
    i = np.arange(bodies)
    points = np.stack([(i % side) * SPACING, ((i // side) % side) * SPACING, (i // (side * side)) * SPACING], 1)
    return points.astype(float), i * 0.37


def positions_at(points: np.ndarray, offsets: np.ndarray, t: float) -> np.ndarray:
    phase = t * 2.0 + offsets
    out = points.copy()
    out[:, 0] += 0.3 * np.cos(phase)
    out[:, 1] += 0.3 * np.sin(phase)
    return out


def measure_python(client: Client, bodies: int, frames: int, warmup: int, budget_ns: int,
                   structured: bool = False) -> dict[str, Any]:
    """The Python client's figures on a fresh scene, in the JSON shape ``frame_dump`` prints.

    With ``structured``, the poses live in one :data:`POSE_DTYPE` array updated in place
    and are published with one ``memmove`` (``publish_poses``); else from separate ``ids``
    and ``positions`` arrays, one numpy copy per field (``publish``)."""
    scene = client.create_scene()
    shape = client.register_primitive(scene, Sphere(RADIUS))
    points, offsets = grid(bodies)
    ids = np.array([client.add_body(scene, BodySpec(shape=shape, position=p, motion=Motion.DYNAMIC,
                                                    group=0xFFFFFFFF, margin=MARGIN)) for p in points],
                   dtype=np.uint32)
    link = client.open_scene(scene)
    clock = time.perf_counter_ns
    rtt, side, daemon = (np.empty(frames, dtype=np.int64) for _ in range(3))
    # The receive call that returns the frame is client work; the polls before it, waiting.
    try_receive = link.feed.try_receive
    last = [0]

    def timed_try_receive() -> Any:
        start = clock()
        frame = try_receive()
        if frame is not None:
            last[0] = clock() - start
        return frame

    link.feed.try_receive = timed_try_receive  # type: ignore[method-assign]
    poses = pose_array(ids, points)
    for seq in range(1, warmup + frames + 1):
        positions = positions_at(points, offsets, seq * 1e-3)
        if structured:
            poses["position"] = positions
        t0 = clock()
        if structured:
            link.publish_poses(seq, budget_ns, query.CLOSE, poses)
        else:
            link.publish(seq, budget_ns, query.CLOSE, ids, positions)
        t1 = clock()
        frame = link.receive_results_for(seq, 10.0)
        t2 = clock()
        if frame is None:
            raise TimeoutError(f"no answer to frame {seq}")
        elapsed = frame.header.elapsed_ns
        _ = len(frame.pairs)
        frame.release()
        t3 = clock()
        k = seq - warmup - 1
        if k >= 0:
            rtt[k], side[k], daemon[k] = t2 - t0, (t1 - t0) + last[0] + (t3 - t2), elapsed
    client.drop_scene(scene)
    link.close()
    return {"client": "python-structured" if structured else "python", "bodies": bodies, "frames": frames,
            "rtt_p50_ns": int(np.percentile(rtt, 50)), "rtt_p99_ns": int(np.percentile(rtt, 99)),
            "rtt_mean_ns": int(rtt.mean()), "daemon_p50_ns": int(np.percentile(daemon, 50)),
            "side_p50_ns": int(np.percentile(side, 50)), "side_p99_ns": int(np.percentile(side, 99))}


def measure_rust(frame_dump: str, root: str, prefix: str, bodies: int, frames: int, warmup: int,
                 budget_ns: int) -> dict[str, Any]:
    done = subprocess.run([frame_dump, "latency", root, prefix, "--bodies", str(bodies), "--frames", str(frames),
                           "--warmup", str(warmup), "--budget-ns", str(budget_ns)],
                          capture_output=True, text=True, timeout=600)
    if done.returncode != 0:
        raise RuntimeError(f"frame_dump latency failed: {done.stderr}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def line(r: dict[str, Any]) -> str:
    us = lambda key: r[key] / 1e3  # noqa: E731
    text = (f"{r['client']:17}  round trip p50 {us('rtt_p50_ns'):7.1f} p99 {us('rtt_p99_ns'):7.1f} µs  "
            f"daemon p50 {us('daemon_p50_ns'):6.1f} µs")
    if "side_p50_ns" in r:
        text += f"  python side p50 {us('side_p50_ns'):5.1f} p99 {us('side_p99_ns'):6.1f} µs"
    return text


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bodies", type=int, default=100)
    parser.add_argument("--frames", type=int, default=3000)
    parser.add_argument("--warmup", type=int, default=300)
    parser.add_argument("--budget-ns", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--frame-dump", metavar="PATH", help="the Rust client (ipc/examples/frame_dump.rs)")
    parser.add_argument("--root", default="proxima")
    parser.add_argument("--iceoryx-prefix", default=None)
    parser.add_argument("--spawn-daemon", metavar="PATH", help="start this proximad privately")
    parser.add_argument("--daemon-args", default="", help="extra arguments of the spawned daemon, e.g. '--spin-us 200'")
    args = parser.parse_args()
    iox.set_log_level_from_env_or(iox.LogLevel.Error)

    daemon: Optional[DaemonProcess] = None
    if args.spawn_daemon:
        daemon = DaemonProcess(args.spawn_daemon, Isolation.unique("lat"), args.daemon_args.split())
    root = daemon.root if daemon else args.root
    prefix = daemon.prefix if daemon else args.iceoryx_prefix
    try:
        client = Client.connect(root=root, iceoryx_prefix=prefix, reply_timeout=10.0)
        print(f"latency.py: {args.bodies} moving spheres, CLOSE, budget {args.budget_ns / 1e3:.0f} µs, "
              f"{args.frames} frames after {args.warmup} warm-up, {args.repeats} repeats")
        results: list[tuple[Optional[dict[str, Any]], dict[str, Any]]] = []
        for repeat in range(1, args.repeats + 1):
            rust = None
            if args.frame_dump:
                if prefix is None:
                    raise SystemExit("--frame-dump needs the daemon's prefix (--iceoryx-prefix or --spawn-daemon)")
                rust = measure_rust(args.frame_dump, root, prefix, args.bodies, args.frames, args.warmup,
                                    args.budget_ns)
                print(f"[{repeat}] {line(rust)}")
            python = measure_python(client, args.bodies, args.frames, args.warmup, args.budget_ns)
            print(f"[{repeat}] {line(python)}")
            structured = measure_python(client, args.bodies, args.frames, args.warmup, args.budget_ns, True)
            print(f"[{repeat}] {line(structured)}")
            if rust:
                for p in (python, structured):
                    print(f"[{repeat}] ratio {p['client']}/rust round trip p50 {p['rtt_p50_ns'] / rust['rtt_p50_ns']:.2f} "
                          f"p99 {p['rtt_p99_ns'] / rust['rtt_p99_ns']:.2f}")
            results.append((rust, python))
            results.append((rust, structured))
        for name in ("python", "python-structured"):
            mine = [(r, p) for r, p in results if p["client"] == name]
            side = ", ".join(f"{p['side_p50_ns'] / 1e3:.1f}" for _, p in mine)
            print(f"{name}: python side p50 per repeat {side} µs (target ≤ 40)")
            ratios = ", ".join(f"{p['rtt_p50_ns'] / r['rtt_p50_ns']:.2f}" for r, p in mine if r)
            if ratios:
                print(f"{name}: round trip p50 ratio to rust per repeat {ratios} (target ≤ 1.3)")
        client.close()
    finally:
        if daemon is not None:
            daemon.stop()
    return 0


if __name__ == "__main__":
    sys.exit(main())
