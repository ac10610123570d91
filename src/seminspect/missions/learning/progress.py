"""What a training run reports after each update: ``progress.csv`` and TensorBoard events.

:class:`EpisodeStats` gathers the episodes that ended during a rollout; a :class:`ProgressRow`
sums up one update, and :class:`ProgressLog` writes the rows.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from seminspect.core.io import atomic_write_text


@dataclasses.dataclass(frozen=True)
class ProgressRow:
    """One line of ``progress.csv``, written after every update."""

    update: int
    steps: int
    wall_s: float
    steps_per_s: float
    obstacles: int | None
    episodes: int  # episodes that ended during this update's rollout
    mean_return: float  # NaN when none ended
    coverage_pct: float
    crash_pct: float
    timeout_pct: float
    policy_loss: float
    value_loss: float
    entropy: float
    approx_kl: float
    clip_fraction: float
    lr: float


@dataclasses.dataclass
class EpisodeStats:
    """Statistics of the episodes that ended during one rollout (``info["episode"]``)."""

    returns: list[float] = dataclasses.field(default_factory=list)
    coverage: list[float] = dataclasses.field(default_factory=list)
    crashes: list[bool] = dataclasses.field(default_factory=list)
    timeouts: list[bool] = dataclasses.field(default_factory=list)

    def record(self, info: Mapping[str, Any]) -> None:
        if "episode" not in info:
            return
        rows = np.asarray(info["_episode"], dtype=bool)
        episode = info["episode"]
        self.returns.extend(np.asarray(episode["return"], dtype=float)[rows].tolist())
        self.coverage.extend(np.asarray(episode["coverage"], dtype=float)[rows].tolist())
        self.crashes.extend(np.asarray(episode["crash"], dtype=bool)[rows].tolist())
        self.timeouts.extend(np.asarray(episode["timeout"], dtype=bool)[rows].tolist())

    def mean(self, values: list[float] | list[bool], scale: float = 1.0) -> float:
        return scale * float(np.mean(values)) if values else math.nan


class ProgressLog:
    """``progress.csv`` (rewritten atomically after each update) and, when tensorboardX is
    installed, TensorBoard event files in the same folder. A resumed run starts from the
    ``rows`` its saved state logged, so rows written after that state are replaced, not
    repeated."""

    def __init__(self, out_dir: Path, rows: Sequence[ProgressRow] = ()):
        self.path = out_dir / "progress.csv"
        self.rows: list[ProgressRow] = list(rows)
        try:
            from tensorboardX import SummaryWriter  # noqa: PLC0415 - optional ('rl' extra)
        except ImportError:
            self.writer = None
        else:
            self.writer = SummaryWriter(str(out_dir))

    def add(self, row: ProgressRow) -> None:
        self.rows.append(row)
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        names = [field.name for field in dataclasses.fields(ProgressRow)]
        writer.writerow(names)
        for logged in self.rows:
            writer.writerow(_csv_cell(getattr(logged, name)) for name in names)
        atomic_write_text(self.path, buffer.getvalue())
        if self.writer is not None:
            for name, value in dataclasses.asdict(row).items():
                if name not in {"update", "steps"} and value is not None and math.isfinite(value):
                    self.writer.add_scalar(f"train/{name}", value, row.steps)
            self.writer.flush()

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()


def _csv_cell(value: float | int | None) -> str:
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    return f"{value:.6g}" if isinstance(value, float) else str(value)
