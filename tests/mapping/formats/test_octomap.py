import sys

import numpy as np
import pytest

from seminspect.core.errors import FileFormatError, InvalidInputError, SeminspectError
from seminspect.mapping.formats.octomap import (
    OctreeLeaves,
    load_octomap,
    read_octomap_leaves,
    voxel_map_from_leaves,
)
from seminspect.mapping.voxel import FREE, OCCUPIED, UNKNOWN


def _reference_leaves(shared_data) -> OctreeLeaves:
    ref = np.load(shared_data / "octomap" / "geb079_leaves_reference.npz")
    return OctreeLeaves(
        ref["center"].astype(np.float64),
        ref["size"].astype(np.float64),
        ref["occupied"].astype(bool),
        float(ref["resolution"]),
    )


def test_painting_small_leaves_takes_the_highest_state() -> None:
    leaves = OctreeLeaves(
        centers=np.array([[0.2, 0.2, 0.2], [0.05, 0.05, 0.05], [0.65, 0.05, 0.05]]),
        sizes=np.array([0.4, 0.1, 0.1]),
        occupied=np.array([False, True, False]),
        resolution=0.1,
    )
    fine = voxel_map_from_leaves(leaves)
    assert fine.shape == (7, 4, 4)
    assert fine.counts() == {"unknown": 112 - 64 - 1, "free": 63 + 1, "occupied": 1}
    assert fine.states[0, 0, 0] == OCCUPIED and fine.states[6, 0, 0] == FREE
    assert fine.states[5, 0, 0] == UNKNOWN
    coarse = voxel_map_from_leaves(leaves, resolution=0.4)
    assert coarse.shape == (2, 1, 1)
    assert coarse.states[:, 0, 0].tolist() == [OCCUPIED, FREE]  # the obstacle is not lost
    with pytest.raises(InvalidInputError, match="resolution"):
        voxel_map_from_leaves(leaves, resolution=0.0)


def test_reference_leaves_fill_exactly_their_volume(shared_data) -> None:
    leaves = _reference_leaves(shared_data)
    grid_map = voxel_map_from_leaves(leaves)
    cells = np.round((leaves.sizes / leaves.resolution) ** 3).astype(int)
    counts = grid_map.counts()
    assert counts["occupied"] == cells[leaves.occupied].sum()
    assert counts["free"] == cells[~leaves.occupied].sum()
    np.testing.assert_allclose(grid_map.origin, [-8.0, -7.52, -0.32], atol=1e-6)
    np.testing.assert_allclose(grid_map.upper, [30.96, 7.44, 2.8], atol=1e-6)
    coarse = voxel_map_from_leaves(leaves, resolution=0.4)
    occupied_centres = leaves.centers[leaves.occupied]
    assert (coarse.state_at(occupied_centres) == OCCUPIED).all()
    assert (coarse.state_at(leaves.centers[~leaves.occupied]) != UNKNOWN).all()


def test_bt_file_decodes_to_the_reference_leaves(shared_data) -> None:
    pytest.importorskip("pyoctomap")
    leaves = read_octomap_leaves(shared_data / "octomap" / "geb079.bt")
    reference = _reference_leaves(shared_data)
    assert leaves.resolution == pytest.approx(0.08)
    assert len(leaves.sizes) == 428_144 and leaves.occupied.sum() == 143_729
    np.testing.assert_allclose(leaves.centers, reference.centers, atol=1e-5)
    np.testing.assert_allclose(leaves.sizes, reference.sizes, atol=1e-6)
    np.testing.assert_array_equal(leaves.occupied, reference.occupied)
    grid_map = load_octomap(shared_data / "octomap" / "geb079.bt", resolution=0.16)
    assert grid_map.counts() == voxel_map_from_leaves(reference, 0.16).counts()


def test_broken_files_are_refused(tmp_path, shared_data) -> None:
    with pytest.raises(FileFormatError, match="no such file"):
        read_octomap_leaves(tmp_path / "missing.bt")
    garbage = tmp_path / "garbage.bt"
    garbage.write_bytes(b"\x00\x01 definitely not an octree")
    with pytest.raises(FileFormatError, match=r"not an OctoMap binary tree"):
        read_octomap_leaves(garbage)
    headless = tmp_path / "headless.bt"
    headless.write_bytes(b"# Octomap OcTree binary file\nid ColorOcTree\nres 0.1\n")
    with pytest.raises(FileFormatError, match="id OcTree"):
        read_octomap_leaves(headless)
    pytest.importorskip("pyoctomap")
    truncated = tmp_path / "truncated.bt"
    truncated.write_bytes((shared_data / "octomap" / "geb079.bt").read_bytes()[:100_000])
    with pytest.raises(FileFormatError, match="malformed or truncated"):
        read_octomap_leaves(truncated)


def test_missing_extra_is_a_clear_error(tmp_path, monkeypatch) -> None:
    path = tmp_path / "tiny.bt"
    path.write_bytes(b"# Octomap OcTree binary file\nid OcTree\nsize 1\nres 0.1\ndata\n")
    monkeypatch.setitem(sys.modules, "pyoctomap", None)
    with pytest.raises(SeminspectError, match=r"seminspect\[octomap\]"):
        read_octomap_leaves(path)
