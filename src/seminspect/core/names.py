"""Helpers for user-facing names: suggestions for near misses."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from seminspect.core.errors import UnknownNameError


def closest_names(name: str, candidates: Iterable[str], limit: int = 5) -> list[str]:
    """Return up to ``limit`` candidates that look like ``name`` (case-insensitive)."""
    by_lower: dict[str, str] = {}
    for candidate in candidates:
        by_lower.setdefault(candidate.lower(), candidate)
    matches = difflib.get_close_matches(name.lower(), list(by_lower), n=limit, cutoff=0.5)
    return [by_lower[m] for m in matches]


def unknown_name(
    kind: str, name: str, candidates: Iterable[str], where: str = ""
) -> UnknownNameError:
    """Build an :class:`UnknownNameError` that names the closest valid choices.

    ``where`` qualifies the scope: ``unknown feature 'hod-1' in Level-0 of car-1``.
    """
    pool = sorted(set(candidates))
    suggestions = closest_names(name, pool)
    if suggestions:
        hint = "did you mean " + ", ".join(repr(s) for s in suggestions) + "?"
    elif pool:
        shown = ", ".join(pool[:8]) + (", ..." if len(pool) > 8 else "")
        hint = f"valid names: {shown}"
    else:
        hint = f"there are no {kind}s"
    scope = f" {where}" if where else ""
    return UnknownNameError(f"unknown {kind} {name!r}{scope}; {hint}")
