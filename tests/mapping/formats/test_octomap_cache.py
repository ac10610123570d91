"""A decoded OctoMap is kept for the next reader, and a rewritten file is decoded again."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from seminspect.mapping.formats.octomap import read_octomap_leaves


def _write(path: Path, points: list[tuple[float, float, float]]) -> Path:
    pyoctomap = pytest.importorskip("pyoctomap")
    tree = pyoctomap.OcTree(0.2)
    for point in points:
        tree.updateNode(np.array(point), True)
    assert tree.writeBinary(str(path))
    return path


def test_a_second_read_shares_the_first_and_cannot_change_it(tmp_path: Path) -> None:
    path = _write(tmp_path / "one.bt", [(0.1, 0.1, 0.1)])
    first = read_octomap_leaves(path)
    assert read_octomap_leaves(path) is first
    with pytest.raises(ValueError, match="read-only"):
        first.centers[0, 0] = 5.0


def test_a_rewritten_file_is_read_again(tmp_path: Path) -> None:
    path = _write(tmp_path / "map.bt", [(0.1, 0.1, 0.1)])
    assert len(read_octomap_leaves(path).sizes) == 1
    _write(path, [(0.1, 0.1, 0.1), (3.1, 0.1, 0.1)])
    os.utime(path, ns=(1, 1))  # another modification time even on a coarse clock
    assert len(read_octomap_leaves(path).sizes) == 2
