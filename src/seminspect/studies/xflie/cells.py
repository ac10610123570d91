"""How the planning study writes a figure in a table cell: times in µs or ms, ratios, shares of
valid segments; a missing or non-finite figure is "-"."""

from __future__ import annotations

import math


def us_cell(seconds: float | None) -> str:
    """Seconds as microseconds, one decimal."""
    return "-" if seconds is None or not math.isfinite(seconds) else f"{seconds * 1e6:.1f}"


def ms_cell(seconds: float | None) -> str:
    """Seconds as milliseconds, two decimals."""
    return "-" if seconds is None or not math.isfinite(seconds) else f"{seconds * 1e3:.2f}"


def num_cell(value: float | None, digits: int = 2) -> str:
    """A figure to ``digits`` decimals."""
    return "-" if value is None or not math.isfinite(value) else f"{value:.{digits}f}"


def ratio_cell(value: float | None) -> str:
    """A ratio: whole and with thousands separators from 10 up, one decimal below."""
    if value is None or not math.isfinite(value):
        return "-"
    return f"{value:,.0f}" if value >= 10 else f"{value:.1f}"


def pct_cell(share: dict[str, int]) -> str:
    """A share of valid segments: ``"97.6% of 41"``."""
    if not share["segments"]:
        return "-"
    return f"{100 * share['valid'] / share['segments']:.1f}% of {share['segments']}"
