"""Bodies falling into a bin, bounced with proximad's contacts; the Python twin of
``examples/falling_bodies.rs``.

    python falling.py --spawn-daemon target/debug/proximad --bodies 200 --seconds 5
    python falling.py --root proxima                      # a daemon already running
    python falling.py --root proxima --token-file /tmp/falling.token   # let monitor.py watch

A static bin (floor and four walls, cuboids) and a mix of spheres, boxes, capsules and
convex hulls dropped above it. Each frame integrates gravity (semi-implicit Euler, numpy,
no per-body loop), publishes every moving body's pose straight into shared memory with
``CLOSE | CONTACTS``, waits for the result frame, and bounces every touching pair along
its normal (restitution 0.4, bodies as unit point masses: no spin response), pushing
them apart by the depth. Once a second it prints the frame's pairs, contacts, round trip
and whether it met its budget; then a summary.

The scene is this client's alone. With ``--token-file`` it writes the scene's token (the
capability to read its results, nothing more) to a file only its user can read, for
``monitor.py`` to follow the frames.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import iceoryx2 as iox
import numpy as np

from proxima_client import BodySpec, Capsule, Client, Cuboid, ErrorCode, Motion, Sphere, frame_flags, query
from proxima_client.daemon_process import DaemonProcess, Isolation

BIN_HALF = 3.0  # half the bin's inner width, m
WALL = 0.2  # half the walls' thickness, m
GRAVITY = 9.81  # m/s², along -Z
RESTITUTION = 0.4
MARGIN = 0.02  # m


def build_bin(client: Client, scene: int) -> list[int]:
    """The floor and four walls, static cuboids; returns their ids."""
    floor = client.register_primitive(scene, Cuboid((BIN_HALF + WALL, BIN_HALF + WALL, WALL)))
    wall_x = client.register_primitive(scene, Cuboid((WALL, BIN_HALF + WALL, 2.0)))
    wall_y = client.register_primitive(scene, Cuboid((BIN_HALF + WALL, WALL, 2.0)))
    d = BIN_HALF + WALL
    pieces = [(floor, (0.0, 0.0, -WALL)), (wall_x, (d, 0.0, 2.0)), (wall_x, (-d, 0.0, 2.0)),
              (wall_y, (0.0, d, 2.0)), (wall_y, (0.0, -d, 2.0))]
    return [client.add_body(scene, BodySpec(shape=s, position=p, motion=Motion.STATIC, margin=MARGIN))
            for s, p in pieces]


def drop_bodies(client: Client, scene: int, count: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``count`` bodies on a jittered grid above the bin; returns ids, positions, orientations."""
    hull = rng.uniform(-0.25, 0.25, (16, 3))
    shapes = [client.register_primitive(scene, Sphere(0.2)), client.register_primitive(scene, Cuboid((0.2, 0.15, 0.1))),
              client.register_primitive(scene, Capsule(0.12, 0.15)), client.register_convex(scene, hull)]
    side = int(np.ceil(np.sqrt(count / 4)))
    cells = np.arange(count)
    positions = np.stack([(cells % side) * 0.7 - (side - 1) * 0.35, ((cells // side) % side) * 0.7 - (side - 1) * 0.35,
                          1.0 + (cells // (side * side)) * 0.7], 1) + rng.uniform(-0.1, 0.1, (count, 3))
    q = rng.normal(size=(count, 4))
    orientations = q / np.linalg.norm(q, axis=1, keepdims=True)
    ids = np.array([client.add_body(scene, BodySpec(shape=shapes[i % len(shapes)], position=positions[i],
                                                    orientation=orientations[i], margin=MARGIN))
                    for i in range(count)], dtype=np.uint32)
    return ids, positions, orientations


def bounce(pairs: np.ndarray, slot: np.ndarray, positions: np.ndarray, velocities: np.ndarray) -> int:
    """Impulses and depth corrections for every touching pair (Jacobi style, vectorised);
    ``slot`` maps a body id to its row, -1 for static bodies. Returns the pairs bounced."""
    touching = pairs[pairs["distance"] <= 0.0]
    if len(touching) == 0:
        return 0
    a, b = slot[touching["body_a"]], slot[touching["body_b"]]
    n = touching["normal"]
    inv_a, inv_b = (a >= 0).astype(float), (b >= 0).astype(float)
    v = lambda i: np.where((i >= 0)[:, None], velocities[np.maximum(i, 0)], 0.0)  # noqa: E731
    approach = np.einsum("ij,ij->i", v(b) - v(a), n)
    total = inv_a + inv_b
    impulse = np.where(approach < 0.0, -(1.0 + RESTITUTION) * approach / total, 0.0)
    correction = (-touching["distance"]) * 0.8 / total
    for rows, inv, sign in ((a, inv_a, -1.0), (b, inv_b, 1.0)):
        moving = rows >= 0
        np.add.at(velocities, rows[moving], sign * (n * (impulse * inv)[:, None])[moving])
        np.add.at(positions, rows[moving], sign * (n * (correction * inv)[:, None])[moving])
    return int(np.count_nonzero(impulse > 0.0))


def write_token(path: str, token: str) -> None:
    """Writes ``token`` to ``path``, readable and writable by this user only."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(token + "\n")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bodies", type=int, default=200)
    parser.add_argument("--seconds", type=float, default=5.0)
    parser.add_argument("--rate-hz", type=int, default=120)
    parser.add_argument("--budget-us", type=int, default=2000)
    parser.add_argument("--root", default="proxima", help="service root of a running daemon")
    parser.add_argument("--iceoryx-prefix", default=None, help="iceoryx2 prefix of a running daemon")
    parser.add_argument("--spawn-daemon", metavar="PATH", help="start this proximad privately instead")
    parser.add_argument("--token-file", metavar="FILE", help="write the scene's token here for monitor.py")
    args = parser.parse_args()
    iox.set_log_level_from_env_or(iox.LogLevel.Error)

    daemon = DaemonProcess(args.spawn_daemon, Isolation.unique("fall")) if args.spawn_daemon else None
    root = daemon.root if daemon else args.root
    prefix = daemon.prefix if daemon else args.iceoryx_prefix
    try:
        with Client.connect(root=root, iceoryx_prefix=prefix, reply_timeout=10.0) as client:
            return simulate(client, args)
    finally:
        if daemon is not None:
            daemon.stop()


def simulate(client: Client, args: argparse.Namespace) -> int:
    rng = np.random.default_rng(1)
    scene = client.create_scene()
    statics = build_bin(client, scene)
    ids, positions, orientations = drop_bodies(client, scene, args.bodies, rng)
    slot = np.full(int(ids.max()) + 1, -1)
    slot[ids] = np.arange(len(ids))
    velocities = np.zeros_like(positions)
    link = client.open_scene(scene)
    if args.token_file:
        write_token(args.token_file, str(link.access.token))
    print(f"falling.py: scene {scene}, {len(ids)} bodies into a {2 * BIN_HALF:.0f} m bin ({len(statics)} static pieces), "
          f"{args.rate_hz} Hz")
    dt = 1.0 / args.rate_hz
    frames = int(np.ceil(args.seconds * args.rate_hz))
    round_trips, truncated, capped, over_budget, lost = [], 0, 0, 0, 0
    start = time.perf_counter()
    for seq in range(1, frames + 1):
        pause = start + seq * dt - time.perf_counter()
        if pause > 0:
            time.sleep(pause)
        velocities[:, 2] -= GRAVITY * dt
        positions += velocities * dt
        sent = time.perf_counter()
        link.publish(seq, args.budget_us * 1000, query.CLOSE | query.CONTACTS, ids, positions, orientations)
        frame = link.receive_results_for(seq, 1.0)
        if frame is None:
            lost += 1
            continue
        with frame:
            round_trips.append(time.perf_counter() - sent)
            if frame.status is not ErrorCode.OK:
                print(f"frame {seq} refused: {frame.status!r}", file=sys.stderr)
                return 1
            truncated += not frame.exact
            capped += bool(frame.header.flags & frame_flags.PAIRS_CAPPED)
            over_budget += not frame.budget_met
            bounced = bounce(frame.pairs, slot, positions, velocities)
            if seq % args.rate_hz == 0:
                resting = int(np.count_nonzero(np.linalg.norm(velocities, axis=1) < 0.2))
                print(f"t {seq * dt:5.1f} s  pairs {len(frame.pairs):4}  contacts {len(frame.contacts):4}  "
                      f"bounced {bounced:4}  resting {resting:4}/{len(ids)}  round trip {round_trips[-1] * 1e6:7.1f} µs "
                      f"(daemon {frame.header.elapsed_ns / 1e3:6.1f})  "
                      f"budget {'met' if frame.budget_met else 'MISSED'}")
    rtt = np.array(round_trips) * 1e6
    if len(rtt):
        print(f"round trip: n={len(rtt)} p50 {np.percentile(rtt, 50):.1f} p99 {np.percentile(rtt, 99):.1f} "
              f"max {rtt.max():.1f} µs")
    inside = np.all(np.abs(positions[:, :2]) < BIN_HALF + 0.5, axis=1) & (positions[:, 2] > -0.5)
    print(f"{frames} frames: {truncated} truncated, {capped} with pairs capped, {over_budget} over budget, {lost} lost; "
          f"{int(inside.sum())} of {len(ids)} bodies inside the bin")
    client.drop_scene(scene)
    link.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
