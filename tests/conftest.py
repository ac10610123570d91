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
