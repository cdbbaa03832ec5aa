"""Follows another client's scene by the token its owner shared: reads its result frames,
never drives it.

    python falling.py --root proxima --token-file /tmp/falling.token     # terminal 1
    python monitor.py --root proxima --token-file /tmp/falling.token     # terminal 2

Connects to the daemon (to learn its instance id, so a frame of a restarted daemon is
refused), opens the scene's results and results-ready services by the token
(``Client.open_result_feed``) and prints, once a second, the newest frame's sequence
number, pairs, contacts and the daemon's time. The token reads results only: the scene's
commands and frames stay its owner's. Stops after ``--seconds``, or when the scene or the
daemon is gone.
"""

from __future__ import annotations

import argparse
import sys
import time
from typing import Optional

import iceoryx2 as iox

from proxima_client import Client, DaemonLost, OwnedResultFrame, ResultFeed, SceneToken

CYCLE_TIME = 1.0  # s between two reports


def newest_frame(feed: ResultFeed) -> Optional[OwnedResultFrame]:
    """The newest frame waiting (copied; the subscriber keeps the last two), older ones
    released; ``None`` when none came.

    Raises:
        DaemonLost: none came and no live daemon publishes the scene (dropped, or gone).
    """
    newest = None
    frame = feed.receive(0.0)
    while frame is not None:
        with frame:
            newest = frame.copy()
        frame = feed.try_receive()
    return newest


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default="proxima", help="service root of the daemon")
    parser.add_argument("--iceoryx-prefix", default=None, help="iceoryx2 prefix of the daemon")
    parser.add_argument("--token-file", required=True, metavar="FILE", help="the scene's token, as its owner wrote it")
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args()
    iox.set_log_level_from_env_or(iox.LogLevel.Error)

    with open(args.token_file) as f:
        token = SceneToken.from_hex(f.read())
    with Client.connect(root=args.root, iceoryx_prefix=args.iceoryx_prefix, reply_timeout=10.0) as client, \
            client.open_result_feed(token) as feed:
        print(f"monitor.py: following a scene of daemon {client.daemon_instance:#018x}")
        end = time.perf_counter() + args.seconds
        while time.perf_counter() < end:
            time.sleep(CYCLE_TIME)
            try:
                frame = newest_frame(feed)
            except DaemonLost:
                print("monitor.py: the scene or its daemon is gone")
                return 0
            if frame is not None:
                print(f"frame {frame.frame_seq:6}  pairs {len(frame.pairs):4}  contacts {len(frame.contacts):4}  "
                      f"daemon {frame.header.elapsed_ns / 1e3:6.1f} µs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
