"""Shared fixtures."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]


def _shared_data_dir() -> Path | None:
    candidates = [os.environ.get("SEMINSPECT_SHARED_DATA"), REPO.parent / "shared" / "data"]
    for candidate in candidates:
        if candidate and Path(candidate).is_dir():
            return Path(candidate)
    return None


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The external test data of ``../shared/data``; tests using it skip when it is absent."""
    found = _shared_data_dir()
    if found is None:
        pytest.skip("external test data (../shared/data or $SEMINSPECT_SHARED_DATA) not present")
    return found


class HashingTextEncoder:
    """A tiny deterministic bag-of-words text encoder for tests of the encoder seam.

    Each word maps to a fixed random unit vector (seeded by its bytes); a text embeds as the
    normalised sum of its words, ignoring filler words, so "image of a car" is close to the
    caption "car, automobile, vehicle" and far from "sidewalk".
    """

    name = "hashing-test"
    dim = 256
    _FILLER = frozenset({"a", "an", "the", "of", "image", "photo"})

    def encode_text(self, texts):
        import re

        import numpy as np

        rows = []
        for text in texts:
            total = np.zeros(self.dim)
            for word in re.findall(r"[a-z]+", text.lower()):
                if word not in self._FILLER:
                    seed = int.from_bytes(word.encode()[:8].ljust(8, b"\0"), "little")
                    vector = np.random.default_rng([seed, len(word)]).normal(size=self.dim)
                    total += vector / np.linalg.norm(vector)
            rows.append(total / (np.linalg.norm(total) or 1.0))
        return np.asarray(rows, dtype=np.float32).reshape(len(rows), self.dim)


@pytest.fixture
def fake_encoder():
    """A caption encoder over :class:`HashingTextEncoder`, registered as ``hashing-test``."""
    from seminspect.perception.encoders import Calibration, CaptionEncoder, register_encoder

    calibration = Calibration(terrain=0.45, objects=0.45, null_task=0.3)
    register_encoder("hashing-test", lambda: CaptionEncoder(HashingTextEncoder()), calibration)
    return CaptionEncoder(HashingTextEncoder())
