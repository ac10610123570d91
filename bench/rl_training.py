"""Training curves of 004 policies side by side: coverage and crashes per window of steps.

Reads the ``progress.csv`` of each run directory (one row per PPO update, written by
``missions.learning.progress.ProgressLog``) and sums the episodes that ended in each window
of ``--window`` environment steps: lenient coverage and crash share, weighted by the episodes
of each update, with the curriculum's obstacle count. These are training figures (stochastic
actions, the training rooms), the ones docs/learning.md quotes per 250,000 steps; the
protocol's evaluation is ``bench/rl_reproduction.py``.

Run (a second; ``--window 500000`` for coarser rows)::

    .venv/bin/python bench/rl_training.py bench/checkpoints/rl/v3-main bench/checkpoints/rl/v4-main
"""

from __future__ import annotations

import argparse
import csv
import math
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Window:
    """The episodes that ended in one window of a run's steps."""

    obstacles: str  # the curriculum's counts in the window, e.g. "4" or "4-9"
    episodes: int
    coverage_pct: float
    crash_pct: float


def read_rows(run_dir: Path) -> list[dict[str, str]]:
    """The rows of a run's ``progress.csv`` (a clear error when there is none)."""
    path = run_dir / "progress.csv"
    if not path.is_file():
        raise SystemExit(f"error: {path} does not exist (is {run_dir} a training run?)")
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def windows(rows: list[dict[str, str]], size: int) -> dict[int, Window]:
    """Episode-weighted figures per window, keyed by the window's first step."""
    grouped: dict[int, list[dict[str, str]]] = {}
    for row in rows:
        grouped.setdefault((int(row["steps"]) - 1) // size * size, []).append(row)
    return {start: _summed(group) for start, group in grouped.items()}


def _summed(rows: list[dict[str, str]]) -> Window:
    counts = sorted({int(r["obstacles"]) for r in rows if r["obstacles"]})
    if not counts:
        obstacles = "-"
    else:
        obstacles = str(counts[0]) if len(counts) == 1 else f"{counts[0]}-{counts[-1]}"
    ended = [r for r in rows if int(r["episodes"]) > 0 and r["coverage_pct"]]
    total = sum(int(r["episodes"]) for r in ended)

    def weighted(name: str) -> float:
        if not total:
            return math.nan
        return sum(float(r[name]) * int(r["episodes"]) for r in ended) / total

    return Window(obstacles, total, weighted("coverage_pct"), weighted("crash_pct"))


def table(runs: dict[str, dict[int, Window]], size: int) -> list[str]:
    """A Markdown table: one row per window, coverage / crash % (episodes) per run."""
    names = list(runs)
    lines = [
        "| steps | "
        + " | ".join(f"{n}: obstacles, coverage %, crash % (episodes)" for n in names)
        + " |",
        "|---|" + "---|" * len(names),
    ]
    for start in sorted({s for run in runs.values() for s in run}):
        cells = [_cell(runs[name].get(start)) for name in names]
        lines.append(
            f"| {start / 1e6:.2f}-{(start + size) / 1e6:.2f} M | " + " | ".join(cells) + " |"
        )
    return lines


def _cell(window: Window | None) -> str:
    if window is None:
        return ""
    if not window.episodes:
        return f"{window.obstacles}, no episode ended"
    figures = f"{window.coverage_pct:.1f}, {window.crash_pct:.1f}"
    return f"{window.obstacles}, {figures} ({window.episodes:,})"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="training run directories")
    parser.add_argument("--window", type=int, default=250_000, help="steps per row")
    args = parser.parse_args()
    if args.window < 1:
        parser.error(f"--window must be at least 1, got {args.window}")
    runs = {run.name: windows(read_rows(run), args.window) for run in args.runs}
    print("\n".join(table(runs, args.window)))


if __name__ == "__main__":
    main()
