"""Load time and memory of a large 3DLSG file (~50 MB of seminspect.lsg JSON).

A synthetic graph of fully inspected vehicles (``graphs.lsg.synthetic``) is saved once; each
way of reading it then runs in a fresh process, which reports its wall time and the growth of
its peak resident memory over the interpreter with seminspect imported:

* ``json.loads``: the standard library's parse alone, the floor of any dict-based reader;
* ``dict + validate``: ``json.loads``, then the whole document model, then the graph (the
  reader before it took the targets one at a time);
* ``load_graph``: what seminspect does now: each target validated and rebuilt in turn, its
  part of the parsed file dropped as it goes.

Run: ``.venv/bin/python bench/graph_io.py`` (``--targets`` sets the size; 3,300 gives ~50 MB).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

WAYS = ("json.loads", "dict + validate", "load_graph")


def _status_mib(field: str) -> float:
    """A memory figure of this process from ``/proc/self/status`` (Linux), in MiB."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(f"{field}:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError(f"no {field} in /proc/self/status")


def _reset_peak() -> None:
    """Start the peak (VmHWM) afresh at the current size, so import-time peaks do not count."""
    Path("/proc/self/clear_refs").write_text("5")


def measure(way: str, path: Path) -> dict[str, float]:
    """Run one way of reading ``path`` in this process; seconds and peak memory growth (MiB)."""
    from seminspect.core.io import read_json
    from seminspect.graphs.lsg.io import GraphDocument, graph_from_document, load_graph

    _reset_peak()
    before = _status_mib("VmRSS")
    start = time.perf_counter()
    if way == "json.loads":
        json.loads(path.read_text())
    elif way == "dict + validate":
        graph_from_document(GraphDocument.model_validate(read_json(path)))
    else:
        load_graph(path)
    seconds = time.perf_counter() - start
    return {"seconds": seconds, "peak_mib": _status_mib("VmHWM") - before}


def in_fresh_process(way: str, path: Path) -> dict[str, float]:
    done = subprocess.run(
        [sys.executable, __file__, "--measure", way, str(path)],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(done.stdout)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--targets", type=int, default=3300, help="vehicles in the graph")
    parser.add_argument("--measure", nargs=2, metavar=("WAY", "FILE"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure:
        print(json.dumps(measure(args.measure[0], Path(args.measure[1]))))
        return
    from seminspect.graphs.lsg.io import save_graph
    from seminspect.graphs.lsg.synthetic import synthetic_graph

    with tempfile.TemporaryDirectory() as folder:
        path = save_graph(synthetic_graph(args.targets, parts_per_pose=4), Path(folder) / "g.json")
        size = path.stat().st_size / 2**20
        print(f"graph of {args.targets} targets: {size:.1f} MiB of JSON")
        print("| way | seconds | peak memory growth (MiB) | x file size | time vs json.loads |")
        print("|---|---|---|---|---|")
        baseline = None
        for way in WAYS:
            figures = in_fresh_process(way, path)
            baseline = baseline or figures["seconds"]
            print(
                f"| {way} | {figures['seconds']:.2f} | {figures['peak_mib']:.0f} "
                f"| {figures['peak_mib'] / size:.1f} | {figures['seconds'] / baseline:.1f} |",
                flush=True,
            )


if __name__ == "__main__":
    main()
