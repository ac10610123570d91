"""Small maps for the planning tests."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from seminspect.mapping.voxel import FREE, VoxelMap

MakeMap = Callable[..., VoxelMap]


def _free_map(shape: tuple[int, int, int], resolution: float = 0.5) -> VoxelMap:
    """An all-free map of ``shape`` cells with its corner at the origin."""
    states = np.full(shape, FREE, dtype=np.uint8)
    return VoxelMap(np.zeros(3), resolution, states)


@pytest.fixture
def free_map() -> MakeMap:
    return _free_map
