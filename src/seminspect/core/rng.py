"""Seeded randomness.

Every random choice in seminspect draws from a generator made here. Independent components ask
for their own named stream, so adding a random draw in one component does not shift the numbers
another component sees: the same seed gives the same run, component by component.
"""

from __future__ import annotations

import hashlib

import numpy as np

from seminspect.core.errors import InvalidInputError


def stream_key(name: str) -> int:
    """A stable 64-bit key for a stream name (Python's ``hash`` is salted per process)."""
    return int.from_bytes(hashlib.blake2b(name.encode("utf-8"), digest_size=8).digest(), "little")


def make_rng(seed: int, *streams: str) -> np.random.Generator:
    """Generator for ``seed`` and a named stream, e.g. ``make_rng(0, "sensors", "camera")``."""
    if seed < 0:
        raise InvalidInputError(f"seed must be non-negative, got {seed}")
    keys = [stream_key(name) for name in streams]
    return np.random.default_rng(np.random.SeedSequence([int(seed), *keys]))
