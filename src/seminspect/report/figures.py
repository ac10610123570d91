"""Figure creation and atomic saving shared by every picture (headless: the Agg backend)."""

from __future__ import annotations

import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure


def new_figure(width_in: float, height_in: float, dpi: int = 110) -> Figure:
    """A figure detached from pyplot's global state (nothing to close, safe in threads)."""
    return Figure(figsize=(width_in, height_in), dpi=dpi)


def save_figure(figure: Figure, path: str | os.PathLike[str]) -> Path:
    """Save a figure atomically; the format follows the file suffix (png, svg, pdf)."""
    from seminspect.core.io import atomic_output  # noqa: PLC0415 - keep the backend first

    target = Path(path)
    with atomic_output(target) as tmp:
        figure.savefig(tmp, format=target.suffix.lstrip(".") or "png")
    return target
