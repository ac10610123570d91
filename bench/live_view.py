"""What the live view costs a mission: wall time with a browser-like client connected, against
the same mission unwatched, measured in the same run.

Runs the mission unwatched and watched in turn (``--repeats`` pairs, alternating, so drift of
the machine's load falls on both) and prints each pair's wall times, the ratio of the medians
and the share of the watched mission's wall time spent building and sending states (the
figure that holds on a loaded machine), against the 10 % the live view may cost
(``seminspect mission --view``). The
client reads ``/events`` as fast as the server sends, as a browser does; the watched run's
outputs are checked to be the unwatched run's.

Run: ``.venv/bin/python bench/live_view.py [--scenario small] [--repeats 3] [--period 0.5]``
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import threading
import time
import urllib.request
from pathlib import Path

from seminspect.missions.xflie.config import make_config
from seminspect.missions.xflie.live import LiveWatch
from seminspect.missions.xflie.run import run_mission
from seminspect.report.live_mission import MissionFeed, live_page
from seminspect.report.live_server import LiveServer

#: The most the live view may add to a mission's wall time.
TARGET_OVERHEAD = 0.10
#: Files that must not differ between a watched and an unwatched run.
SAME_OUTPUTS = ("graph.json", "trajectory.csv", "events.jsonl")


def _client(server: LiveServer, received: list[int]) -> None:
    """Read the stream as a browser does, counting the bytes, until the server closes it."""
    with urllib.request.urlopen(server.url + "events", timeout=60) as stream:
        while chunk := stream.read1(1 << 16):
            received.append(len(chunk))


def _unwatched(config, out: Path) -> float:
    start = time.perf_counter()
    run_mission(config, out)
    return time.perf_counter() - start


def _watched(config, out: Path, period_s: float) -> tuple[float, _CountingFeed, int]:
    """Wall seconds, the feed (states, time in it) and bytes received with one client
    connected throughout."""
    received: list[int] = []
    with LiveServer(live_page("bench"), port=0, period_s=period_s) as server:
        reader = threading.Thread(target=_client, args=(server, received), daemon=True)
        reader.start()
        if not server.wait_for_client(30):
            raise SystemExit("the bench's client did not connect")
        feed = _CountingFeed(server)
        start = time.perf_counter()
        run_mission(config, out, watch=LiveWatch(feed))
        wall = time.perf_counter() - start
    reader.join(10)
    return wall, feed, sum(received)


class _CountingFeed(MissionFeed):
    """Counts the states and the mission's wall time spent building and sending them: a
    figure that, unlike the difference of two runs, holds on a loaded machine."""

    def __init__(self, server: LiveServer) -> None:
        super().__init__(server)
        self.sent = 0
        self.seconds = 0.0

    def publish(self, state) -> None:
        start = time.perf_counter()
        super().publish(state)
        self.seconds += time.perf_counter() - start
        self.sent += 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", default="city")
    parser.add_argument("--scenario", default="small")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--repeats", type=int, default=3, help="pairs of runs (default 3)")
    parser.add_argument("--period", type=float, default=0.5, help="seconds between states")
    args = parser.parse_args()
    config = make_config({"world": args.world, "scenario": args.scenario, "seed": args.seed})
    plain_walls, watched_walls, shares = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for repeat in range(args.repeats):
            plain, seen = Path(tmp, f"plain-{repeat}"), Path(tmp, f"watched-{repeat}")
            plain_walls.append(_unwatched(config, plain))
            wall, feed, size = _watched(config, seen, args.period)
            watched_walls.append(wall)
            shares.append(feed.seconds / wall)
            same = all((plain / f).read_bytes() == (seen / f).read_bytes() for f in SAME_OUTPUTS)
            print(
                f"pair {repeat + 1}: unwatched {plain_walls[-1]:.2f} s, watched {wall:.2f} s "
                f"({feed.sent} states, {size / 1e6:.1f} MB streamed, {feed.seconds:.2f} s "
                f"building and sending them); same outputs: {same}"
            )
            if not same:
                raise SystemExit("a watched mission wrote different outputs")
    ratio = statistics.median(watched_walls) / statistics.median(plain_walls)
    share = statistics.median(shares)
    print(
        f"{args.world} {args.scenario} seed {args.seed}, medians of {args.repeats}: watched / "
        f"unwatched wall time = {ratio:.3f}; the watched mission's time in the live view = "
        f"{100 * share:.1f} % (target <= {100 * TARGET_OVERHEAD:.0f} %: "
        f"{_verdict(max(ratio - 1, share))})"
    )


def _verdict(overhead: float) -> str:
    return "met" if overhead <= TARGET_OVERHEAD else "missed"


if __name__ == "__main__":
    main()
